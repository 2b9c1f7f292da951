// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "solver/form_factors/form_factor_estimator.h"

namespace bounce {

class ConvexBlockers;
class ShaftCuller;
class Visibility;

/// How the pairs of an exact estimator were classified, and the error it estimates for the
/// partially visible ones (the unoccluded ones are exact to about 1e-10).
struct PairTally {
    std::uint64_t unoccluded = 0;      // no candidate blocker: exact factor, no visibility work
    std::uint64_t partial = 0;         // candidates found: shadow-clipped quadrature
    std::uint64_t hidden = 0;          // candidates hide the whole pair: 0
    double partial_area_factor = 0.0;  // sum over partial pairs of A_i F_ij (both ways)
    double partial_area_error = 0.0;   // sum over partial pairs of A_i |error of F_ij| (both ways)
};

/// Form factors with exact visibility for convex planar patches (the "exact" method).
///
/// Every pair is classified first by a shaft test (ShaftCuller, Haines and Wallace 1991):
/// - no candidate blocker: the exact unoccluded polygon-to-polygon factor
///   (polygon_form_factor, to `exact_tolerance`), and no visibility work;
/// - candidates: the receiver (the smaller patch) is integrated with Gauss-Legendre points and,
///   at each point x, the blockers' shadows are projected from x onto the source's plane and
///   cut out of the source, so the exact point-to-polygon kernel is taken over the part of the
///   source that x sees (shadow-polygon clipping, as in View3D, Walton 2002). What is
///   integrated numerically is only the blocked part, F = F_unoccluded - (1/A) int blocked(x),
///   with orders 2, 4, 8 per cell of 4 x 4 cells, then 8 per cell of 8 x 8 and 16 x 16 cells,
///   until two agree within `visibility_tolerance` of F_unoccluded (the last difference is the
///   pair's error estimate). A pair whose source is hidden from every point is 0. Candidates that belong
///   to one convex solid (ConvexBlockers: a block, a box, a tiled convex surface) cast that solid's single convex
///   shadow, and a solid holding either end of the pair is dropped (both face out of it).
///   Pairs with more than kMaxClippedBlockers shadows (solids and loose patches) use
///   kernel-weighted rays instead (weighted_rays).
/// No row is normalised. Each unordered pair is computed once, so reciprocity holds to rounding.
/// With `occlusion` false every pair is taken as unoccluded (no culler is built).
class ExactFormFactor final : public FormFactorEstimator {
public:
    /// `rays` (may be null) traces the kernel-weighted rays of pairs with more than
    /// kMaxClippedBlockers candidates; without it every partial pair is shadow-clipped.
    ExactFormFactor(const std::vector<Patch>& patches, bool occlusion, const FormFactorOptions& options,
                    const Visibility* rays = nullptr);
    /// Pairs with more candidate blockers than this use kernel-weighted rays (when a
    /// visibility backend was given): clipping many tiling shadows fragments the source.
    static constexpr std::size_t kMaxClippedBlockers = 2;
    ~ExactFormFactor() override;
    std::string name() const override { return "exact"; }
    void compute_row(std::size_t i, std::span<float> row) const override;
    void compute_row(std::size_t i, std::span<float> row, std::span<const std::uint8_t> known) const override;
    bool reciprocal() const override { return true; }
    double patch_area(std::size_t i) const override { return m_patches[i].area; }
    /// F_ij (0 when i == j); `error` (optional) gets the estimated error of F_ij.
    double pair(std::size_t i, std::size_t j, double* error = nullptr) const;
    /// Classification counts and partial-pair error so far (every pair computed is counted).
    PairTally tally() const;

private:
    /// F from r to s by kernel-weighted rays: n x n Gauss points on r, n x n on s, each ray
    /// weighted by cos cos / (pi d^2); at each point of r the unoccluded point factor times the
    /// weighted visible fraction. Orders 2, 3, 4 until two agree (the last difference is the
    /// error estimate; a visibility edge makes these converge only like 1/n).
    double weighted_rays(const Patch& r, const Patch& s, double unoccluded, double& error) const;
    /// F from r to s, the blocked part integrated over r with shadows of `blockers` (patches)
    /// and of `solids` (indices into m_solids: one convex shadow each).
    double partial(const Patch& r, const Patch& s, std::span<const std::uint32_t> blockers,
                   std::span<const std::uint32_t> solids, double unoccluded, double& error) const;

    const std::vector<Patch>& m_patches;
    std::unique_ptr<ShaftCuller> m_culler;
    std::unique_ptr<ConvexBlockers> m_solids;  // candidates of one convex solid cast one shadow
    const Visibility* m_rays;
    FormFactorOptions m_options;
    mutable std::atomic<std::uint64_t> m_unoccluded{0}, m_partial{0}, m_hidden{0};
    mutable std::atomic<double> m_partial_af{0.0}, m_partial_err{0.0};
};

/// The form factor from a differential area at x (normal n) to the part of `source` (normal
/// n_source) not hidden by `blockers` (convex polygons): each blocker's shadow, projected from
/// x onto the source's plane, is cut out of the source, and Lambert's formula is summed over
/// the visible pieces. Exact for any number of convex blockers.
double shadowed_point_factor(const glm::dvec3& x, const glm::dvec3& n, std::span<const glm::dvec3> source,
                             const glm::dvec3& n_source, std::span<const std::span<const glm::dvec3>> blockers);
/// The same with convex solids among the blockers: each solid's shadow is one convex polygon
/// (convex_shadow), however many patches it has.
double shadowed_point_factor(const glm::dvec3& x, const glm::dvec3& n, std::span<const glm::dvec3> source,
                             const glm::dvec3& n_source, std::span<const std::span<const glm::dvec3>> blockers,
                             const ConvexBlockers* solids, std::span<const std::uint32_t> which);

}  // namespace bounce
