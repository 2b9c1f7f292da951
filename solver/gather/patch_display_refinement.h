// SPDX-License-Identifier: MIT
// Display refinement of a patch solution's point data: where linear interpolation between a
// patch's gathered vertices misses the light inside it (a shadow line through it, a corner
// darkening towards a contact), the patch is cut into display cells whose new vertices are
// gathered too, as adaptive sampling of B(x) for display (the patch solvers' counterpart of
// DisplayRefinement in hierarchical_point_values.h).
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>

#include "mesh/meshing/patch_mesh.h"
#include "solver/linear/solve_result.h"
#include "solver/visibility/visibility.h"

namespace bounce {

struct PatchDisplayRefinement {
    /// A cell is kept split where the value gathered at one of its new points (an edge's
    /// midpoint, a quad's centre) differs from the linear interpolation between its corners by
    /// more than this share of the larger of the two (or of a hundredth of the scene's mean
    /// radiosity, where both are darker). 0: off.
    double tolerance = 0.0;
    /// Splits below each patch: each halves the cells' edges.
    int max_depth = 2;
    /// Further splits, below max_depth, of the cells whose corners still differ by more than
    /// corner_spread (a step: a hard shadow line at a contact, where the penumbra narrows to
    /// nothing and a probe a millimetre from the line takes its far side's light from a corner
    /// across it). Four halve a 30 mm patch's cells to 2 mm along such lines only.
    int step_depth = 4;
    /// A patch is also tried split where its corners' values differ by more than this share
    /// of the brightest (a shadow line crossing it): its mean can match the corners' mean by
    /// chance while the light inside it bends, and whether it did would then depend on the
    /// rays' noise. Values above 1: never.
    double corner_spread = 0.3;
    /// The vertex-patch pairs the new points may gather over in all (at most five new points
    /// a split, each over every patch). A level that would pass it takes the cells that miss
    /// most (the largest relative miss or corner step first), and is the last: in a cluttered
    /// scene, where most patches bend the light, the sharpest shadow lines get the splits.
    double max_pairs = 0.0;  // 0: display_pairs_budget(patches), point_values.h
    /// Passes of the near field over the display cells: beside a contact (a block on a floor,
    /// two boxes crossing at an acute angle) a point sees mostly the near strip of the other
    /// surface, whose light and its own darken together towards the contact line, each by what
    /// the other sends. One gather from the solved patches sends each near patch's mean shaped
    /// by its corners, which cannot follow that; each pass gathers the part of a vertex's value
    /// that came from near sources (GatherOptions::shape_within) again from those sources'
    /// display cells, at their point data, keeping the rest (a Jacobi step of the near field
    /// at the cells' resolution). 0: off.
    int near_field_passes = 3;
};

/// The display tolerance the patch solvers gather with unless one is given.
inline constexpr double kPatchDisplayTolerance = 0.02;

/// A hundredth of the scene's mean radiosity (area-weighted luminance): display refinement's
/// misses and steps are relative to it where both values are darker, so the darkest corners
/// do not split for noise.
double dark_floor(const std::vector<Patch>& patches, const std::vector<Rgb>& radiosity);

/// After gather_point_values in mode "vertices" (res.point_radiosity per vertex of `mesh`):
/// tries a split of every patch whose radiosity (its mean, from the solve) differs from the
/// mean of its vertices' values by more than the tolerance (interpolation misrepresents it),
/// or whose vertices' values spread by more than corner_spread,
/// gathers the split's new vertices from the solved patches, keeps the split where one of them
/// misses the interpolation by more than the tolerance and tries the kept cells again, down to
/// max_depth, and below it, down to max_depth + step_depth, the kept cells whose corners
/// differ by more than corner_spread; a level the budget (max_pairs) cannot take whole takes
/// the candidates that miss most, and is the last. Then replaces `mesh` by the cells' conforming mesh
/// (ElementTree::conforming_mesh) and spreads the per-patch arrays of `res` (radiosity, irradiance, unshot, display) to
/// the cells: a split patch's reflected radiosity B - E (and H, and the display value) is shared among its cells in
/// proportion to the point data over each, so each patch keeps its power (sum_k A_k B_k = A B) and the energy account
/// is the solve's, while the cells' values follow a shadow line through the patch. Vertices beside near sources with a
/// shape (GatherOptions::source_corners) are gathered again first, also when nothing is split. Returns the cells added;
/// 0, with `mesh` unchanged, when the tolerance is 0, nothing misses, `cancel` was set (the point data then as it was
/// or partly gathered again), or the budget cannot take one split. `progress` receives each gather.
std::size_t refine_patch_display(PatchMesh& mesh, SolveResult& res, const Visibility& visibility,
                                 const PatchDisplayRefinement& options, const std::atomic<bool>* cancel = nullptr,
                                 const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace bounce
