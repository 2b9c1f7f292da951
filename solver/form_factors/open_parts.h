// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/meshing/patch.h"
#include "mesh/scene/scene.h"

namespace bounce {

class FormFactorMatrix;
class Visibility;

/// The share of a patch's or element's area that receives and holds radiosity in the solve,
/// given its open share: the open part, or the whole where no part is open (a buried patch:
/// light that reaches it through a narrow gap is absorbed there, and it sends none).
inline double receiving_share(double open_share) { return open_share > 0.0 ? open_share : 1.0; }

/// What a patch's open part sees. A patch may lie partly under or inside another object (a
/// floor under a cabinet with an open underside, a wall pierced by a box): rays to its buried
/// part are blocked, so the form factors to the patch count only its open part, and rays from
/// the buried part never leave. The solve then works on the open part alone: its area
/// a_i A_i emits and receives, and its radiosity is the open part's. Row sums show the rest:
/// sum_j F_ij = a_i (share reaching fronts), so each shot is divided by a_i.
///
/// Found by rays: stratified points on the patch, each casting cosine-distributed rays over
/// its front hemisphere. A point is open when at least a quarter of its rays leave without
/// meeting a back side first (the path tracer's test for its probes); the rays of the open
/// points say whether the open part sees only patches' fronts (closed: in a closed scene every
/// row must sum to one) and how much of what it misses is black back sides (one-sided faces,
/// which absorb) rather than openings (which let light escape).
struct OpenPart {
    double area_share = 1.0;  // a_i: share of the patch's area open to the scene, in [0, 1]
    bool closed = true;       // every ray from the open part met a patch's front
    double back_share = 0.0;  // of those rays that met no front: the share that met a back side (1 when buried)

    /// The share of the patch's area that receives and holds radiosity in the solve
    /// (bounce::receiving_share; a buried patch's shot_scale is 0).
    double receiving_share() const { return bounce::receiving_share(area_share); }

    /// The factor patch i's shot is multiplied by, given its row sum sum_j F_ij (patch to
    /// patch, whole areas): a_i / sum for a closed part, so its light all lands (the rows of a
    /// closed scene sum to one; sampling leaves them a little off); otherwise 1, or less where
    /// the sum over a_i would pass one.
    double shot_scale(double row_sum) const;
};

/// One OpenPart per patch. `points` per side (points^2 on each patch, (2 points)^2 on a patch
/// whose points disagree) and `rays` per point; reproducible from `seed`. When `cancel`
/// becomes true, throws Interrupted.
///
/// `covered`: the regions the contact and solid cuts left out of the mesh (Scene::covered). A
/// ray that meets no patch but passes through one went into the gap under a cover (the ceiling
/// behind a lamp hung just below it): the light is absorbed there, not escaped, and the ray
/// counts as meeting a back side.
std::vector<OpenPart> open_parts(const std::vector<Patch>& patches, const Visibility& visibility, int points = 4,
                                 int rays = 16, std::uint64_t seed = 1, const std::atomic<bool>* cancel = nullptr,
                                 std::span<const CoveredRegion> covered = {});

/// The same for parts of patches (the elements of a hierarchical solve): element i lies on
/// patches[patch_of[i]], the patches being what `visibility` traces against.
std::vector<OpenPart> element_open_parts(const std::vector<Patch>& elements, std::span<const std::uint32_t> patch_of,
                                         const std::vector<Patch>& patches, const Visibility& visibility,
                                         int points = 4, int rays = 16, std::uint64_t seed = 1,
                                         const std::atomic<bool>* cancel = nullptr,
                                         std::span<const CoveredRegion> covered = {});

/// The patches with the areas that receive in the solve (OpenPart::receiving_share), for the
/// matrix solvers and the energy account.
std::vector<Patch> open_part_patches(const std::vector<Patch>& patches, const std::vector<OpenPart>& open);

/// The gathering matrix between open parts, from the whole patches' reciprocal matrix F:
/// F'_ij = F_ij s_j / a_i, with s_j = OpenPart::shot_scale(sum_k F_jk): what j's open part
/// sends (its row scaled) over what i's open part receives it on (a buried i: the whole patch).
FormFactorMatrix open_part_matrix(const FormFactorMatrix& whole, const std::vector<OpenPart>& open);

}  // namespace bounce
