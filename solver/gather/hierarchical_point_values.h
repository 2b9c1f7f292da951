// SPDX-License-Identifier: MIT
// The point data of a hierarchical solution, gathered through its links: a vertex gathers
// from the elements its element and that element's ancestors are linked with, which cover the
// scene once, instead of from every leaf (Hanrahan, Salzman and Aupperle 1991 evaluate the
// kernel at the vertices for display the same way).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "mesh/meshing/patch_mesh.h"
#include "solver/gather/point_values.h"
#include "solver/linear/solve_result.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

namespace bounce {

/// Jacobi steps of the re-gather at the leaves' centres that a solution refined with a power
/// epsilon takes before its vertices gather (each step gathers every leaf's centre through its
/// links from the last step's radiosity, then sets every parent to its children's area-weighted
/// mean): a link accepted for its small power hands all of a coarse element one irradiance,
/// and the step gives each leaf its own view of its sources. One step: since the links' ends
/// send and take by where they see each other (HierarchicalOptions::weighted_ends), the leaves
/// no longer hold the links' excess that a second step took out of the neighbours
/// (docs/measurements/2026-12-07-weighted-ends.md), and a second step moved the point data
/// away from the path tracer.
inline constexpr int kRegatherSteps = 1;

/// The point-source pairs gathering through the links costs: for every vertex of `elements`,
/// the element links along its leaf's path to the root; with a power epsilon, the same for
/// every leaf's centre too (gathered first).
double hierarchical_gather_pairs(const HierarchicalSolution& solution, const PatchMesh& elements);

/// As gather_point_values, for the conforming mesh of a hierarchical solution's leaves
/// (`elements`, from solution.tree.conforming_mesh(solution.leaves)): each vertex gathers,
/// with the exact point kernel and visibility, from the other ends of the element links of
/// the leaf it lies on and of that leaf's ancestors (those whose form factor's rays were all
/// blocked too: the vertex traces its own; none over a link a shaft test proves unblocked,
/// ShaftCuller::unblocked), at their radiosity, going down to a near source's
/// children where their values differ (GatherSources::descend); what came over links with a
/// cluster end is added as the solve computed it (solution.cluster_irradiance). Its cost is
/// at least vertices x links per path, not vertices x leaves; over kMaxGatherPairs of those
/// (not counting the children gone down to) it returns over_budget. `visibility` may be over
/// the elements or over the input patches, which the elements tile: the same answers, and the
/// patches' fewer triangles trace faster (on the Cornell box at power epsilon 1e-6, 90 patches
/// against 11,472 elements: the gather 0.74 s instead of 1.01 s, the point data the same to
/// the digit). A solution refined with a power epsilon first
/// re-gathers every leaf at its centre the same way, `regather_steps` times (kRegatherSteps),
/// and the vertices gather from those values: its links may hand a whole coarse element one
/// mean (on the box, power epsilon 3e-6: point data 1.48% -> 0.99% RMS off the 0.1% probes,
/// for about twice the gather; progress stage "gathering: element centres"). Mode "centres"
/// then reports the last step's centre values, with no progress of its own. The cells (res's
/// radiosity and irradiance per leaf) then take those centre values, their reflected part
/// scaled within each input patch to the reflected power the solve gave it. The gather's budget
/// (kMaxGatherPairs) counts the centres' pairs once, though each step gathers them.
GatherOutcome gather_hierarchical_point_values(
    const HierarchicalSolution& solution, const PatchMesh& elements, const Visibility& visibility, SolveResult& res,
    const std::string& mode, const std::atomic<bool>* cancel = nullptr,
    const std::function<void(const char*, std::size_t, std::size_t)>& progress = {},
    int regather_steps = kRegatherSteps);

/// Display refinement of a hierarchical solution's point data. A point value between the
/// vertices is their linear interpolation (as ParaView shows it), which misses where the
/// light curves within an element: across a penumbra, into a corner. On the Cornell box at
/// power epsilon 2e-7, level 4, the vertex values gathered over every leaf and interpolated
/// were 0.31% RMS off the 0.1% probes, the same gather at the probes themselves 0.14%.
struct DisplayRefinement {
    /// A leaf is split for display (its four children take its radiosity and gather through
    /// its links, and its new vertices are gathered) where the interpolation between its
    /// vertices would miss its centre value by more than this share of it. The miss is
    /// estimated from the centre values of the leaf and of those that share a vertex with it:
    /// a quarter of the leaf's distance from their least-squares plane (a second difference).
    /// 0: off.
    double tolerance = 0.0;
    /// What the splits' new vertices may gather over in all passes, in vertex-link pairs (five
    /// new vertices a split leaf, each over its path of links): a pass that would pass it
    /// splits the leaves that miss most (or, in the step passes, whose corners differ most)
    /// first, and is the last. 0: hierarchical_display_budget.
    double max_pairs = 0.0;
};

/// The default budget of display refinement for a solution whose element links have
/// `link_ends` ends (each link is held at both its ends; cluster links not counted): 60
/// vertex-link pairs an end, at most kMaxGatherPairs. The passes then cost a few times the
/// solve's own link work, however many leaves of a cluttered scene bend the light (at a 0.25%
/// tolerance most of them can).
inline double hierarchical_display_budget(std::size_t link_ends) {
    return std::min(kMaxGatherPairs, 60.0 * double(link_ends));
}

/// The display tolerance `--adaptive` gathers with unless one is given (`--display-tolerance`,
/// 0 turns it off): a quarter of a percent of the leaf's value is below what a colour map
/// shows, and finer tolerances split most leaves of a cluttered scene for no visible gain.
/// Where light bends across a penumbra, linear interpolation between the vertices of an
/// element left coarse by the power bound misses it; the split vertices follow it. The plain
/// hierarchical solver keeps it off (0) by default.
inline constexpr double kSuggestedDisplayTolerance = 0.0025;

/// The display tolerance an adaptive solve gathers with: `given` when set (0: off), else
/// kSuggestedDisplayTolerance.
inline double adaptive_display_tolerance(std::optional<double> given) {
    return given ? *given : kSuggestedDisplayTolerance;
}

/// gather_hierarchical_point_values, then, in mode "vertices" with a positive tolerance,
/// display refinement: splits leaves of `solution` (its tree, leaves, node radiosity and
/// cluster irradiance grow; the links stay), replaces `elements` by the new leaves' conforming
/// mesh and spreads the per-leaf arrays of `res` and of solution.result (radiosity,
/// irradiance, unshot, display) to the new leaves; `res` must hold one radiosity per leaf. The
/// old vertices keep their values. The links and the energy account are unchanged: a split
/// leaf's children tile it with its radiosity. The passes share DisplayRefinement::max_pairs
/// vertex-source pairs (hierarchical_display_budget): a pass that would pass it splits the
/// leaves that miss most first, and is the last.
GatherOutcome gather_hierarchical_point_values(
    HierarchicalSolution& solution, PatchMesh& elements, const Visibility& visibility, SolveResult& res,
    const std::string& mode, const DisplayRefinement& display, const std::atomic<bool>* cancel = nullptr,
    const std::function<void(const char*, std::size_t, std::size_t)>& progress = {});

}  // namespace bounce
