// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <span>
#include <vector>

#include "mesh/patch.h"
#include "solver/form_factors/patch_sampling.h"

namespace bounce {

/// The unoccluded form factor between two patches of a list, to a relative tolerance: the
/// product Gauss-Legendre rule of the point-to-point kernel at the orders the pair's separation
/// predicts (separation_rho, separated_form_factor) when the pair is well separated and
/// each is wholly in front of the other, else polygon_form_factor (the point-to-polygon kernel,
/// or the contour integral for touching pairs; it clips straddling pairs). The one-point rule it
/// replaced erred with one sign on every far pair: rows of a closed box summed to 1.001-1.003.
/// Used by the ray-cast method (times a visible fraction) and the improved hemicube.
class UnoccludedFormFactor {
public:
    /// `patches` must outlive this; patches appended later (refinement) are handled, uncached.
    UnoccludedFormFactor(const std::vector<Patch>& patches, double tolerance);
    /// F from patch `from` to patch `to`, unoccluded (0 when either is behind the other).
    double operator()(std::size_t from, std::size_t to) const;

private:
    /// Gauss points of order n <= kCachedOrders (weights: fractions of the area) on a patch:
    /// from the cache, or computed into `scratch` for patches added after construction.
    std::span<const AreaSample> gauss_points(std::size_t patch, int n, std::vector<AreaSample>& scratch) const;
    /// Orders above this go to polygon_form_factor: near pairs, where the point-to-polygon
    /// kernel needs fewer points than the product rule (n^2 against n^4).
    static constexpr int kCachedOrders = 4;
    static constexpr std::size_t kCachedPoints = 1 + 4 + 9 + 16;

    /// The smallest Gauss order n with separation_rho^(2n) >= 1/tol, capped at kCachedOrders +
    /// 1 (0 when the pair is not separated), from thresholds computed once, not a logarithm.
    int cached_order(double gap, double radius) const;

    const std::vector<Patch>& m_patches;
    double m_tolerance;
    std::vector<AreaSample> m_points;                      // kCachedPoints per patch: orders 1, 2, .. kCachedOrders
    std::vector<double> m_radius;                          // circumradius per cached patch
    std::array<double, kCachedOrders + 1> m_rho_needed{};  // [n]: the smallest rho order n serves
};

}  // namespace bounce
