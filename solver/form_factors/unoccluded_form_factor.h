// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <span>
#include <vector>

#include "mesh/meshing/patch.h"
#include "solver/form_factors/patch_sampling.h"

namespace bounce {

/// Gauss-Legendre points of orders 1..kCachedOrders on every patch of a list (weights:
/// fractions of the area), the patches' circumradii, and the order the product rule needs at a
/// separation: what far pairs need, kept once for the unoccluded patch-to-patch factor and the
/// final gather's point-to-patch factor alike.
class GaussPointCache {
public:
    /// Orders kept per patch: what far pairs need, at 30 points (960 bytes) a patch.
    static constexpr int kCachedOrders = 4;
    static constexpr int kMaxOrder = 6;  // the largest order `order` may answer

    /// `patches` must outlive this; patches appended later are handled, uncached.
    GaussPointCache(const std::vector<Patch>& patches, double tolerance);
    /// The circumradius of a patch.
    double radius(std::size_t patch) const {
        return patch < m_radius.size() ? m_radius[patch] : circumradius(m_patches[patch]);
    }
    /// The smallest Gauss order n <= max_order with separation_rho(gap, radius)^(2n) >= 1/tol,
    /// max_order + 1 when none is enough, 0 when the pair is not separated; from gap thresholds
    /// computed once: no logarithm or root per pair.
    int order(double gap, double radius, int max_order) const;
    /// Gauss points of order n on a patch: from the cache (n <= kCachedOrders), or computed
    /// into `scratch` (higher orders, and patches added after construction).
    std::span<const AreaSample> points(std::size_t patch, int n, std::vector<AreaSample>& scratch) const;

private:
    static constexpr std::size_t kCachedPoints = 1 + 4 + 9 + 16;
    const std::vector<Patch>& m_patches;
    std::vector<AreaSample> m_points;                  // kCachedPoints per patch: orders 1, 2, .. kCachedOrders
    std::vector<double> m_radius;                      // circumradius per cached patch
    std::array<double, kMaxOrder + 1> m_gap_needed{};  // [n]: the smallest gap / radius order n serves
};

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
    /// Orders above this go to polygon_form_factor: near pairs, where the point-to-polygon
    /// kernel needs fewer points than the product rule (n^2 against n^4). At 6 the product
    /// rule's n^4 = 1296 vectorised kernels still cost less than the point-to-polygon rule's
    /// trigonometry at the orders it takes (measured on the empty 20 x 20 cube).
    static constexpr int kProductOrders = 6;

    const std::vector<Patch>& m_patches;
    double m_tolerance;
    GaussPointCache m_gauss;
};

}  // namespace bounce
