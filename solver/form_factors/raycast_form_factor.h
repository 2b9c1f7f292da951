// SPDX-License-Identifier: MIT
#pragma once

#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "solver/form_factors/unoccluded_form_factor.h"

#include "solver/form_factors/form_factor_estimator.h"
#include "solver/visibility/visibility.h"

namespace bounce {

class ExactFormFactor;
class ShaftCuller;

/// Ray-cast form factors in the manner of Wallace, Elmquist and Haines (1989): the unoccluded
/// factor between the two patches times the fraction of stratified rays between them that no
/// other patch blocks. Each unordered pair is computed once, with the smaller patch as
/// receiver, and F_ij = (A_j / A_i) F_ji, so reciprocity holds to rounding and a row may borrow
/// entries from rows computed before (compute_row with `known`), halving a full solve's work.
///
/// The unoccluded factor is computed to `unoccluded_tolerance` (relative): a product
/// Gauss-Legendre rule of the point-to-point kernel at the order the pair's separation
/// predicts, or, for near pairs, polygon_form_factor (the point-to-polygon kernel, or the
/// contour integral for touching pairs). In a closed convex room every row then sums to 1
/// within about the tolerance. With `receiver_samples` > 0, n x n points on the receiver each
/// take the point-to-polygon kernel instead (a fixed rule, for studies of sampling error).
/// The rays of a pair depend only on (seed, min(i,j), max(i,j)), so the visible fraction is
/// the same both ways round. With no visibility (the "analytic" method) rays are skipped.
/// Before any ray, a shaft test (ShaftCuller) lists the pair's candidate blockers; a pair with
/// none is wholly visible and casts no rays (in an empty convex room, no pair does).
class RaycastFormFactor final : public FormFactorEstimator {
public:
    RaycastFormFactor(const std::vector<Patch>& patches, const Visibility* visibility,
                      const FormFactorOptions& options);
    ~RaycastFormFactor() override;
    std::string name() const override { return m_visibility ? "raycast" : "analytic"; }
    void compute_row(std::size_t i, std::span<float> row) const override;
    void compute_row(std::size_t i, std::span<float> row, std::span<const std::uint8_t> known) const override;
    bool reciprocal() const override { return true; }
    double patch_area(std::size_t i) const override { return m_patches[i].area; }
    /// F_ij for one pair (0 when i == j).
    double pair(std::size_t i, std::size_t j) const;
    /// F_ij with the pair's visible fraction already known (traced by visible_fraction with
    /// more rays, say): no rays. With receiver samples, which trace their own, as pair().
    double pair(std::size_t i, std::size_t j, double visible) const;
    /// Fraction of the pair's rays that arrive unblocked (1 without visibility).
    double visible_fraction(std::size_t i, std::size_t j) const;
    /// The same with `ray_count` rays (stratified alike) instead of the options' count.
    double visible_fraction(std::size_t i, std::size_t j, int ray_count) const;
    /// One of a pair's rays: its ends on i and on j (on the patches, not lifted off them), its
    /// kernel weight and whether it arrived.
    struct PairRay {
        glm::dvec3 on_i, on_j;
        double weight = 0.0;
        bool open = false;
    };
    /// The rays visible_fraction(i, j, ray_count) would trace without its pilot (the same
    /// strata and stream), each with its fate: where on each patch a partly visible pair
    /// sees the other. Rays from behind either patch are left out, as there.
    void pair_rays(std::size_t i, std::size_t j, int ray_count, std::vector<PairRay>& out) const;
    /// F(dA at x with normal n -> patch j): the exact kernel times the fraction of stratified
    /// rays from x to j that arrive; `stream` seeds the rays (the same stream, the same rays).
    /// Radiosity at a point, B(x) = E + rho sum_j F(x -> j) B_j, is what adaptive
    /// subdivision compares with an element's mean.
    double point_factor(const glm::dvec3& x, const glm::dvec3& n, std::size_t j, std::uint64_t stream) const;
    /// The shaft culler over the patches the estimator was built with (null without
    /// visibility); patches appended later are not among its blockers.
    const ShaftCuller* culler() const { return m_culler.get(); }

private:
    /// The kernel-weighted share of `ray_count` stratified rays that arrive; `salt` picks an
    /// independent set of rays for the same pair.
    double traced_fraction(std::size_t i, std::size_t j, int ray_count, std::uint64_t salt) const;
    /// The stratified rays of the pair lo < hi (traced_fraction's), lifted off the patches, with
    /// their kernel weights; `ends`, if given, gets each ray's unlifted ends.
    void stratified_rays(std::size_t lo, std::size_t hi, int ray_count, std::uint64_t salt,
                         std::vector<Visibility::Segment>& rays, std::vector<double>& weight,
                         std::vector<std::pair<glm::dvec3, glm::dvec3>>* ends) const;

    /// F_ij: with receiver_samples 0, the unoccluded factor to unoccluded_tolerance times the
    /// visible fraction; otherwise n x n receiver points on j (the exact kernel covers i).
    double directed(std::size_t i, std::size_t j, double visible = -1.0) const;
    const std::vector<Patch>& m_patches;
    const Visibility* m_visibility;
    FormFactorOptions m_options;
    UnoccludedFormFactor m_unoccluded;
    std::unique_ptr<ShaftCuller> m_culler;       // with visibility that has no occluders only
    std::size_t m_clip_count = 0;                // patches when built: pairs beyond (appended later) take rays
    std::unique_ptr<ExactFormFactor> m_clipper;  // pairs above options.clip_above (with m_culler only)
};

/// Rows from patches to elements, for shooting with an ElementHierarchy: row i holds
/// F(patch i -> element j) for every element j, from the same kernel and rays as
/// RaycastFormFactor applied to the joint list (patches, then elements), rays for every pair
/// (with_rays_only: the elements lie on the patches).
class PatchToElementFormFactor final : public FormFactorEstimator {
public:
    PatchToElementFormFactor(const std::vector<Patch>& patches, const std::vector<Patch>& elements,
                             const Visibility* visibility, const FormFactorOptions& options);
    std::string name() const override { return m_inner.name(); }
    void compute_row(std::size_t i, std::span<float> row) const override;

private:
    std::vector<Patch> m_all;  // patches, then elements; declared before m_inner, which refers to it
    std::size_t m_first_element;
    RaycastFormFactor m_inner;
};

}  // namespace bounce
