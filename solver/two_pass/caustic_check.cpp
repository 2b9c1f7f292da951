// SPDX-License-Identifier: MIT
#include "solver/two_pass/caustic_check.h"

#include <cmath>
#include <numbers>
#include <random>
#include <unordered_map>
#include <vector>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "mesh/readers/cornell_box.h"
#include "solver/reference/path_tracer.h"
#include "solver/two_pass/caustic_map.h"

namespace bounce {
namespace {

constexpr double kPi = std::numbers::pi;

/// Uniform doubles in [0, 1) from stream `stream` of `seed`.
class Uniform {
public:
    Uniform(std::uint64_t seed, std::uint64_t stream) {
        std::seed_seq seq{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(stream),
                          std::uint32_t(stream >> 32), 0x63u /* 'c' */};
        m_engine.seed(seq);
    }
    double operator()() { return double(m_engine() >> 11) * 0x1.0p-53; }

private:
    std::mt19937_64 m_engine;
};

/// The camera's pixel rays met with the region's plane.
struct Footprints {
    glm::dvec3 origin, w, u, v;
    double half_w = 0, half_h = 0;
    int width = 0, height = 0;
    CausticRegion region;

    Footprints(const CausticView& view, const CausticRegion& r) : width(view.width), height(view.height), region(r) {
        const PinholeCamera& c = view.camera;
        origin = c.position;
        w = glm::normalize(c.target - c.position);
        u = glm::normalize(glm::cross(w, c.up));
        v = glm::cross(u, w);
        half_h = std::tan(0.5 * c.vertical_fov * kPi / 180.0);
        half_w = half_h * double(width) / double(height);
    }
    /// The plane's point seen at (col + a, row + b), a and b in [0, 1); false when the ray
    /// runs parallel to the plane or away from it.
    bool point(int col, int row, double a, double b, glm::dvec3& p) const {
        const double px = (col + a) / width, py = (row + b) / height;
        const glm::dvec3 d = w + (2 * px - 1) * half_w * u + (1 - 2 * py) * half_h * v;
        const double dn = glm::dot(d, region.normal);
        if (dn == 0) return false;
        const double t = glm::dot(region.centre - origin, region.normal) / dn;
        if (!(t > 0)) return false;
        p = origin + t * d;
        return true;
    }
    bool inside(const glm::dvec3& p) const { return glm::length(p - region.centre) <= region.radius; }
    /// The pixels whose centre ray meets the plane inside the region, as row * width + col.
    std::vector<int> pixels() const {
        std::vector<int> out;
        glm::dvec3 p;
        for (int row = 0; row < height; ++row)
            for (int col = 0; col < width; ++col)
                if (point(col, row, 0.5, 0.5, p) && inside(p)) out.push_back(row * width + col);
        return out;
    }
};

/// Mean and standard error of the mean of luminance samples, and of their RGB.
struct Spread {
    Rgb sum, sum2;
    std::size_t n = 0;
    void add(const Rgb& x) {
        sum += x;
        sum2 += x * x;
        ++n;
    }
    Rgb mean() const { return n ? sum * (1.0 / double(n)) : Rgb(); }
    Rgb standard_error() const {
        if (n < 2) return {};
        const Rgb m = mean();
        Rgb out;
        for (int c = 0; c < 3; ++c)
            out[c] = std::sqrt(std::max(0.0, (sum2[c] / double(n) - m[c] * m[c]) / double(n - 1)));
        return out;
    }
};

/// The peak of per-pixel means: the largest luminance among `values` once smoothed by a
/// Gaussian of sigma one pixel over the searched pixels (weights renormalised over them). A
/// caustic's brightest part is a ridge along which the pixels differ by less than either
/// estimate's noise (a density estimate of tens of photons; the path tracer's paths), so the
/// bare largest pixel wanders along it; smoothed, both find its middle.
void take_peak(CausticMeasure& m, const std::vector<int>& pixels, const std::vector<Rgb>& values,
               const std::vector<Rgb>& errors, int width) {
    constexpr double kSigma = 1.0;  // pixels
    constexpr int kReach = 3;       // pixels either side
    m.pixels = pixels.size();
    m.searched = pixels;
    for (const Rgb& x : values) m.irradiance.push_back(x.luminance());
    std::unordered_map<int, std::size_t> at;
    for (std::size_t i = 0; i < pixels.size(); ++i) at.emplace(pixels[i], i);
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const int col = pixels[i] % width, row = pixels[i] / width;
        double sum = 0, weights = 0, variance = 0;
        for (int dr = -kReach; dr <= kReach; ++dr)
            for (int dc = -kReach; dc <= kReach; ++dc) {
                if (col + dc < 0 || col + dc >= width) continue;
                const auto it = at.find(pixels[i] + dr * width + dc);
                if (it == at.end()) continue;
                const double w = std::exp(-0.5 * (dr * dr + dc * dc) / (kSigma * kSigma));
                sum += w * m.irradiance[it->second];
                const double se = errors[it->second].luminance();
                variance += w * w * se * se;
                weights += w;
            }
        const double y = sum / weights;
        if (m.peak_col < 0 || y > m.peak) {
            m.peak = y;
            m.peak_se = std::sqrt(variance) / weights;
            m.peak_col = col;
            m.peak_row = row;
        }
    }
}

}  // namespace

CausticRegion cornell_spheres_caustic_region() {
    const glm::dvec3 lamp = kCornellSpheres.lamp_centre, ball = kCornellSpheres.glass_centre;
    const glm::dvec3 towards = ball - lamp;
    const glm::dvec3 centre = ball + towards * (ball.y / -towards.y);
    return {glm::dvec3(centre.x, 0, centre.z), glm::dvec3(0, 1, 0), 50.0};
}

CausticMeasure measure_caustic(const CausticMap& map, const CausticRegion& region, const CausticView& view,
                               int samples_per_pixel) {
    CausticMeasure m;
    const glm::dvec3 n = glm::normalize(region.normal);
    const double on_plane = 1e-6 * std::max(1.0, region.radius);
    for (const CausticPhoton& ph : map.photons())
        if (glm::dot(ph.normal, n) >= 0.9 && std::abs(glm::dot(ph.position - region.centre, n)) <= on_plane &&
            glm::length(ph.position - region.centre) <= region.radius)
            m.power += ph.power;
    const Footprints fp(view, region);
    const std::vector<int> pixels = fp.pixels();
    std::vector<Rgb> values(pixels.size()), errors(pixels.size());
    const int k = std::max(1, int(std::lround(std::sqrt(double(samples_per_pixel)))));
    tbb::parallel_for(std::size_t(0), pixels.size(), [&](std::size_t i) {
        const int col = pixels[i] % view.width, row = pixels[i] / view.width;
        Rgb sum;
        int count = 0;
        glm::dvec3 p;
        for (int s = 0; s < k * k; ++s)
            if (fp.point(col, row, (s % k + 0.5) / k, (s / k + 0.5) / k, p)) {
                sum += map.irradiance(p, n);
                ++count;
            }
        values[i] = count ? sum * (1.0 / count) : Rgb();
    });
    take_peak(m, pixels, values, errors, view.width);
    return m;
}

CausticMeasure measure_caustic(const PathTracer& tracer, const CausticRegion& region, const CausticView& view,
                               const TracedCausticOptions& o) {
    CausticMeasure m;
    const glm::dvec3 n = glm::normalize(region.normal);
    const glm::dvec3 t = glm::normalize(glm::cross(std::abs(n.x) > 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0), n));
    const glm::dvec3 b = glm::cross(n, t);
    // The region: its area times the mean irradiance at points uniform over the disc.
    std::vector<Rgb> at(o.region_points);
    tbb::parallel_for(std::uint64_t(0), o.region_points, [&](std::uint64_t i) {
        Uniform rng(o.seed, i);
        const double r = region.radius * std::sqrt(rng()), phi = 2 * kPi * rng();
        const auto x = tracer.locate(region.centre + r * std::cos(phi) * t + r * std::sin(phi) * b, n);
        if (x) at[i] = tracer.specular_irradiance(*x, 64, o.emitted_only, o.seed, (1ull << 40) + i).irradiance;
    });
    Spread region_spread;
    for (const Rgb& e : at) region_spread.add(e);
    const double area = kPi * region.radius * region.radius;
    m.power = region_spread.mean() * area;
    m.power_se = region_spread.standard_error() * area;

    // The pixels: the mean irradiance over each footprint, from points uniform over it.
    const Footprints fp(view, region);
    const std::vector<int> pixels = fp.pixels();
    std::vector<Rgb> values(pixels.size()), errors(pixels.size());
    tbb::parallel_for(std::size_t(0), pixels.size(), [&](std::size_t i) {
        const int col = pixels[i] % view.width, row = pixels[i] / view.width;
        const std::uint64_t stream = (2ull << 40) + std::uint64_t(pixels[i]) * o.pixel_points;
        Uniform rng(o.seed, stream);
        Spread s;
        glm::dvec3 p;
        for (std::uint64_t k = 0; k < o.pixel_points; ++k) {
            Rgb e;
            if (fp.point(col, row, rng(), rng(), p))
                if (const auto x = tracer.locate(p, n))
                    e = tracer.specular_irradiance(*x, 64, o.emitted_only, o.seed, (3ull << 40) + stream + k)
                            .irradiance;
            s.add(e);
        }
        values[i] = s.mean();
        errors[i] = s.standard_error();
    });
    take_peak(m, pixels, values, errors, view.width);
    return m;
}

}  // namespace bounce
