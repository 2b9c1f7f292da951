// SPDX-License-Identifier: MIT
// The path tracer's random numbers, strata, direction sampling and batch statistics (internal to
// bounce::reference).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "mesh/scene/rgb.h"

namespace bounce::path_tracing {

inline constexpr double kPi = std::numbers::pi;
inline constexpr int kStrataSide = 8;
inline constexpr int kBatch = kStrataSide * kStrataSide;  // paths per stratified batch
inline constexpr int kStratifiedEmitters = 8;             // first-vertex samples of further emitters are plain random
// Russian roulette ends every path with probability >= 1 - max(rho) per bounce; only a closed
// scene of reflectance exactly 1 could run on, and this cap stops it (a bias of rho^cap).
inline constexpr int kMaxDepth = 100000;
// Mirror and glass bounces between two diffuse vertices (or after the eye): light trapped by
// total internal reflection in a non-spherical glass object is dropped after this many.
inline constexpr int kMaxSpecularBounces = 1000;

/// Uniform doubles in [0,1) from the standard 64-bit Mersenne twister.
class Random {
public:
    Random(std::uint64_t seed, std::uint64_t stream) {
        std::seed_seq seq{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(stream),
                          std::uint32_t(stream >> 32), 0x62u /* 'b' */};
        m_engine.seed(seq);
    }
    double uniform() { return double(m_engine() >> 11) * 0x1.0p-53; }
    std::mt19937_64& engine() { return m_engine; }

private:
    std::mt19937_64 m_engine;
};

/// Orthonormal basis around a unit normal (Duff et al. 2017, "Building an orthonormal basis,
/// revisited"): tangents t, b with t x b = n.
inline void orthonormal_basis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    t = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = glm::dvec3(c, sign + n.y * n.y * a, -n.y);
}

/// Cosine-weighted direction about n (pdf cos/pi) by Malley's method on Shirley and Chiu's
/// concentric disk map, which keeps the strata of (u1, u2) compact on the hemisphere.
inline glm::dvec3 cosine_direction(const glm::dvec3& n, double u1, double u2) {
    const double a = 2 * u1 - 1, b = 2 * u2 - 1;
    double r = 0, phi = 0;
    if (a != 0 || b != 0) {
        if (std::abs(a) > std::abs(b)) {
            r = a;
            phi = (kPi / 4) * (b / a);
        } else {
            r = b;
            phi = kPi / 2 - (kPi / 4) * (a / b);
        }
    }
    const double x = r * std::cos(phi), y = r * std::sin(phi);
    const double z = std::sqrt(std::max(0.0, 1 - x * x - y * y));
    glm::dvec3 t, bt;
    orthonormal_basis(n, t, bt);
    return glm::normalize(x * t + y * bt + z * n);
}

/// Running mean and variance (Welford) of the batch means of r, g, b and luminance.
struct BatchStatistics {
    std::uint64_t count = 0;
    std::array<double, 4> mean{}, m2{};
    void add(const Rgb& v) {
        const std::array<double, 4> x{v.r, v.g, v.b, v.luminance()};
        ++count;
        for (int c = 0; c < 4; ++c) {
            const double d = x[c] - mean[c];
            mean[c] += d / double(count);
            m2[c] += d * (x[c] - mean[c]);
        }
    }
    /// Standard error of the mean of channel c (0-2 RGB, 3 luminance).
    double standard_error(int c) const {
        return count > 1 ? std::sqrt(m2[c] / double(count - 1) / double(count)) : 0.0;
    }
};

}  // namespace bounce::path_tracing
