// SPDX-License-Identifier: MIT
// Point values by final gather: the radiosity at a point computed from the solved patches with
// the exact point-to-polygon kernel and visibility, instead of averaged from the cells around
// it (Lischinski, Tampieri and Greenberg 1992; Heckbert 1992 call it gathering).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/meshing/patch.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/rgb.h"
#include "solver/visibility/visibility.h"

namespace bounce {

/// A point to gather at: on the front of input surface `surface`, with its material.
struct GatherPoint {
    glm::dvec3 position{0.0};
    glm::dvec3 normal{0.0};  // unit
    int surface = -1;        // patches of the same (planar) surface are never gathered from
    Rgb reflectance, emission;
    int cell = -1;  // the patch it lies in (vertex_gather_points: the last around its vertex that covers it)
};

struct GatherOptions {
    double rays_per_unit_factor = 64;  // visibility rays to a patch: ceil(F * this), at least 1
    int max_rays = 16;                 // and at most this
    /// Rays to each patch of an emitter, at least (rounded to a square grid): the direct light
    /// is most of a lit point's value, and its penumbrae are where the point data errs. On the
    /// default Cornell box the lamp is 20 patches, each well under 1/64 of a point's factor, so
    /// one ray each left the point data 2.11% RMS / 10.4% max off the path-traced probes; a
    /// 4 x 4 grid on every lamp patch gives 1.47% / 6.8%, for 16% more rays (3.3 million).
    int emitter_rays = 16;
    std::uint64_t seed = 1;  // stratified ray targets; same seed, same values
    /// 0: every unoccluded factor by Lambert's formula (four arc tangents per patch). > 0: a
    /// patch wholly above the point's horizon and far enough away takes the n x n
    /// Gauss-Legendre rule of the point-to-point kernel instead, n = 1..4 the smallest order
    /// the Bernstein bound of separation_rho predicts for this relative tolerance; no
    /// trigonometry, so several times cheaper. gather_point_values uses 1e-4.
    double kernel_tolerance = 0.0;
    /// Optional, 4 per patch (patch j's corners at 4 j .. 4 j + 3, in its vertex order; a
    /// triangle's fourth unused): the radiosity at each patch's corners, such as its vertices'
    /// gathered values. A source nearer a point than `shape_within` times its circumradius
    /// then sends B_j shaped by the interpolation of its corners (each ray's sample weighted
    /// by the interpolated value over the corners' mean, so the patch's power is unchanged):
    /// beside a contact the near strip of a wall is darker than the wall patch's mean, and a
    /// point there sees mostly that strip. Empty: every source sends its mean.
    std::span<const Rgb> source_corners = {};
    double shape_within = 2.0;
};

/// B(x) = E(x) + rho(x) * sum_j F(x -> j) B_j for every point, with
/// F(x -> j) = F0 * sum_s V_s K_s / sum_s K_s: the unoccluded factor F0 (Lambert's formula,
/// or within options.kernel_tolerance the Gauss rule for far patches) times the visible share of the kernel K = cos
/// cos' / r^2 at stratified points of patch j (a kernel-weighted, not a plain, fraction of open rays). Patches facing
/// away, behind the point, or on the point's own surface give nothing. Parallel over points (TBB); `cancel` stops early
/// (the remaining points keep E).
std::vector<Rgb> final_gather(const std::vector<Patch>& patches, std::span<const Rgb> radiosity,
                              const Visibility& visibility, std::span<const GatherPoint> points,
                              const GatherOptions& options = {}, const std::atomic<bool>* cancel = nullptr,
                              const std::function<void(std::size_t, std::size_t)>& progress = {});

/// final_gather over every patch that also gives, per point, the part of its value that its
/// shaped sources sent (those within GatherOptions::shape_within of their circumradius:
/// rho(x) times their irradiance; zero without source_corners), so that near field can be
/// gathered again from finer sources while the rest is kept (refine_patch_display).
std::vector<Rgb> final_gather_with_near_part(const std::vector<Patch>& patches, std::span<const Rgb> radiosity,
                                             const Visibility& visibility, std::span<const GatherPoint> points,
                                             const GatherOptions& options, std::vector<Rgb>& near_part,
                                             const std::atomic<bool>* cancel = nullptr,
                                             const std::function<void(std::size_t, std::size_t)>& progress = {});

/// What each point gathers from, when not every patch (a hierarchy's links, which cover the
/// scene once from every element: hierarchical_point_values.h). Point i gathers from the
/// patches of list `list[i]`, patches[offsets[k] .. offsets[k + 1]) for list k, and adds the
/// irradiance irradiance[k] (arrived by other means, such as cluster links; may be empty).
struct GatherSources {
    std::span<const std::uint32_t> list;     // per point
    std::span<const std::size_t> offsets;    // per list, and one past the last
    std::span<const std::uint32_t> patches;  // indices into the patches gathered from
    std::span<const Rgb> irradiance;         // per list, or empty
    /// Optional, per list: the list whose sources follow this one's for the same point (-1:
    /// none), always one of a lower index (so the chain ends). A hierarchy's lists are its
    /// nodes' links, and a point gathers over those of its element and every ancestor, so no
    /// list is stored per element. `irradiance` is still taken from the point's own list only.
    std::span<const std::int64_t> list_parent = {};
    /// Optional, a hierarchy's (`descend` > 0): per patch, the first of its four children
    /// (consecutive, tiling it) or -1, and the spread (max - min luminance) of the radiosity of
    /// the leaves under it. A source whose min(1, r / d) spread exceeds `descend` times its own
    /// luminance (r: its circumradius, d: its centre's distance from the point) is replaced by
    /// its children, recursively: its mean B would be weighted by a kernel that varies over
    /// children that differ. 0: every listed source is gathered as it is.
    std::span<const std::int32_t> first_child = {};
    std::span<const double> spread = {};
    double descend = 0.0;
    /// Optional, per entry of this struct's `patches` span (as long as it): 1 where a shaft test
    /// proved the source wholly visible from every point of the list's element (for a chained
    /// list, the element of the list it was reached through, an ancestor's), which the
    /// list's points must lie in (ShaftCuller::unblocked, Haines and Wallace 1991):
    /// it takes its unoccluded factor whole and no rays. Children gone down to keep the mark
    /// (their shafts lie inside their parent's).
    std::span<const std::uint8_t> unblocked = {};
};

/// final_gather over the patches `sources` names for each point, not over all of them.
std::vector<Rgb> final_gather(const std::vector<Patch>& patches, std::span<const Rgb> radiosity,
                              const Visibility& visibility, std::span<const GatherPoint> points,
                              const GatherSources& sources, const GatherOptions& options = {},
                              const std::atomic<bool>* cancel = nullptr,
                              const std::function<void(std::size_t, std::size_t)>& progress = {});

/// The mesh's vertices as gather points: each on its surface (vertices are shared only within
/// a surface), moved a tenth of the way towards the mean of the centres of the patches around
/// it, or, where the point so moved lies in none of them (a hole's corner), towards the centre
/// of one of them. A vertex on a contact
/// edge (a lamp 0.1 mm below the ceiling, a block on the floor) then takes the value inside its
/// cells rather than the value on the edge, where a layer thinner than any patch halves it and
/// linear interpolation would spread that over whole cells; and a vertex at a corner of the
/// room is not evaluated on another surface's edge, where the kernel is singular.
std::vector<GatherPoint> vertex_gather_points(const PatchMesh& mesh);

/// The patches' centres as gather points.
std::vector<GatherPoint> centre_gather_points(const std::vector<Patch>& patches);

}  // namespace bounce
