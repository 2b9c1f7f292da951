// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh/meshing/patch.h"

namespace bounce {

class Visibility;

/// Visibility rays per pair when FormFactorOptions::visibility_rays is 0. Patch pairs: 2, since
/// on a uniform mesh the patch size rather than the rays' noise limits the error, and the rays
/// are most of the run's time. Adaptive and hierarchical refinement: 4, since refinement reads
/// differences between neighbouring elements, which the rays' noise inflates (with 2 it can
/// stall above its target). The study is in docs/measurements/2026-12-03-defaults.md.
inline constexpr int kPatchPairRays = 2;
inline constexpr int kRefinementRays = 4;

/// Settings shared by the form-factor methods.
struct FormFactorOptions {
    int visibility_rays = 0;             // rays per pair for the visible fraction (stratified);
                                         // 0: kPatchPairRays, or kRefinementRays for refinement
    int receiver_samples = 0;            // fixed points per side of a receiver; 0: the unoccluded
                                         // factor to unoccluded_tolerance (below)
    double unoccluded_tolerance = 1e-6;  // relative error of the unoccluded factor (raycast, analytic)
    std::uint64_t seed = 1;              // rays depend only on (seed, i, j): thread-count independent
    int hemicube_resolution = 256;       // pixels per side of the hemicube's top face (even)
    bool hemicube_jitter = false;        // rotate each hemicube randomly about the normal (seeded)
    bool hemicube_exact_kernel = false;  // hemicube: pixels give the seen share, not F (Baum et al.)
    double exact_tolerance = 1e-8;       // exact method: relative error of unoccluded pairs
    double visibility_tolerance = 1e-3;  // exact method: partial pairs stop when two orders agree
                                         // within this fraction of the unoccluded factor
    int visibility_levels = 5;           // exact method: most quadrature levels of a partial pair
                                         // (1-5; kernel-weighted rays take at most 3 orders)
    bool flat_shadows = true;            // exact method: a surface's patches that tile a convex
                                         // polygon cast one shadow (ConvexBlockers)
    /// Raycast: a pilot of visibility_rays rays picks the partly blocked pairs, which are then
    /// traced with this many fresh rays (the others with visibility_rays fresh ones); 0 or no
    /// more than visibility_rays: no pilot. Two rays can only say 0, 1/2 or 1; more rays on
    /// the partial pairs lower the noise in shadows and at contacts, for about half again the
    /// ray-casting time on the Cornell box, where the mesh rather than the rays limits the error.
    int partial_rays = 0;
    /// Raycast: a pair whose unoccluded factor from its smaller patch is at least this, and
    /// which the shaft's plane test does not clear, takes the exact method's visibility
    /// instead of rays (its candidate blockers' shadows clipped out of the source,
    /// ExactFormFactor): a few rays can only say 0, 1/2 or 1, and on large near pairs that is
    /// most of the factor. 0 or above 1: rays for every pair. These pairs take the first two
    /// quadrature levels (visibility_levels 2): the clipped shadow is exact at every point, so
    /// the coarse levels already hold the ray noise far below the rays', and deeper levels
    /// cost a multiple of the whole solve on furnished rooms of large triangles. For the same
    /// reason they keep loose patches' shadows (flat_shadows false): a tiled surface's one shadow
    /// would move pairs from the kernel-weighted rays to the dearer clipping.
    double clip_above = 0.1;
};

/// `o` with visibility_rays 0 (the default) replaced by `rays`.
inline FormFactorOptions with_default_rays(FormFactorOptions o, int rays) {
    if (o.visibility_rays == 0) o.visibility_rays = rays;
    return o;
}

/// `o` with clip_above 0, so every raycast pair takes rays: for lists that are no single mesh,
/// such as elements appended as they split or lying on the patches they refine, where the
/// exact shadows would see a fixed list of blockers and overlapping coplanar candidates.
inline FormFactorOptions with_rays_only(FormFactorOptions o) {
    o.clip_above = 0;
    return o;
}

/// Computes rows of the form-factor matrix. F_ij is the fraction of power leaving patch i
/// (diffusely, from its front) that arrives at patch j; rows sum to 1 in a closed enclosure
/// and A_i F_ij = A_j F_ji (reciprocity).
class FormFactorEstimator {
public:
    virtual ~FormFactorEstimator() = default;
    virtual std::string name() const = 0;
    /// row[j] = F_ij for every patch j (row.size() == patch count); row[i] = 0 (planar patches
    /// do not see themselves). Safe to call concurrently for different rows.
    virtual void compute_row(std::size_t i, std::span<float> row) const = 0;
    /// True when each unordered pair is estimated once, so that A_i F_ij = A_j F_ji holds to
    /// rounding and a caller may take F_ij = F_ji A_j / A_i from a row it already has.
    virtual bool reciprocal() const { return false; }
    /// A_i, for callers applying reciprocity (reciprocal() estimators only).
    virtual double patch_area(std::size_t i) const {
        (void)i;
        throw std::logic_error(name() + " form factors are not reciprocal: no areas");
    }
    /// compute_row that leaves row[j] as the caller filled it wherever known[j] != 0 (the
    /// caller took it from reciprocity). Only reciprocal() estimators honour `known`.
    virtual void compute_row(std::size_t i, std::span<float> row, std::span<const std::uint8_t> known) const {
        (void)known;
        compute_row(i, row);
    }
};

/// The methods by name: "raycast" (exact point-to-polygon kernel at receiver points times a
/// ray-traced visible fraction), "analytic" (the same kernel, no occlusion) and "hemicube"
/// (item buffer at the shooter's centre; visibility comes from its depth test). Throws
/// std::invalid_argument on an unknown name, listing the valid ones. `visibility` must
/// outlive the estimator; it may be null for "analytic".
std::unique_ptr<FormFactorEstimator> make_form_factor_estimator(const std::string& method,
                                                                const std::vector<Patch>& patches,
                                                                const Visibility* visibility,
                                                                const FormFactorOptions& options);

/// The method names make_form_factor_estimator accepts.
std::vector<std::string> form_factor_methods();

}  // namespace bounce
