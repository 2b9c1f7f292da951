// SPDX-License-Identifier: MIT
#pragma once

#include <array>

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/meshing/patch.h"

namespace bounce {

/// A point on a patch with its share of the patch's area (weights sum to 1).
struct AreaSample {
    glm::dvec3 point;
    double weight;
};

/// n x n Gauss-Legendre points over a patch (n <= 16; n = 1 gives the centroid): the
/// bilinear map of the unit square for quads, the collapsed square (Duffy) for triangles,
/// weighted by the map's Jacobian. Exponential convergence for smooth integrands.
void patch_quadrature(const Patch& patch, int n, std::vector<AreaSample>& out);

/// Gauss-Legendre nodes and weights on [0,1], n = 1..16 (weights sum to 1).
void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w);

/// The point of a patch at unit-square coordinates (u, v): bilinear for quads, the
/// area-uniform square-root warp for triangles.
glm::dvec3 patch_point(const Patch& patch, double u, double v);

/// The weights of the patch's corners at patch_point(patch, u, v): the bilinear weights of a
/// quad, the barycentric ones of a triangle through the square-root warp (the fourth 0). A
/// value given at the corners interpolates there with the same weights.
std::array<double, 4> patch_point_weights(const Patch& patch, double u, double v);

/// Small, fast, seedable generator (SplitMix64, Steele et al. 2014) so every patch pair gets
/// its own reproducible stream whatever the thread schedule.
struct SplitMix64 {
    std::uint64_t state;
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }
};

}  // namespace bounce
