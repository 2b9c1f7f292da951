// SPDX-License-Identifier: MIT
// The point data a solve exports: gathered at the vertices (and optionally the patch centres),
// as the command line and the Python module both ask for it.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "solver/gather/final_gather.h"
#include "solver/gather/patch_display_refinement.h"
#include "solver/linear/solve_result.h"
#include "solver/visibility/visibility.h"

namespace bounce {

/// Gather modes: "vertices" (the default), "centres" (vertices and patch centres), "none"
/// (point data averaged from the patches around each vertex).
std::vector<std::string> gather_modes();

/// The options gather_point_values passes to final_gather: the defaults, with far patches by
/// the Gauss rule to a relative 1e-4 (kernel_tolerance), far below the probes' own 0.5% noise
/// and the one-ray visibility of far pairs, for a kernel that then costs a fraction.
GatherOptions point_value_options();

/// Point-to-patch pairs above which the gather is skipped: its cost is vertices x patches,
/// which a hierarchy of patches would cut (about 20 s on 2 cores for a uniform mesh; a
/// hierarchy's pairs, through its links, cost about twice as much: the 10k office at power
/// epsilon 3e-6 gathered 1.29e8 of them in 31 s, its point data 1.7% off the probes at the
/// median against 4.8% averaged).
inline constexpr double kMaxGatherPairs = 2e8;

/// The vertex-patch pairs display refinement (refine_patch_display) gathers over at most by
/// default, for a mesh of n patches: 30 n^2, about the form factors' own time (n^2 / 2 pairs,
/// each traced with several rays, where a gathered pair takes one or a few), and never less
/// than the point gather's budget: a cluttered room's shadow lines ask for several levels of
/// new points where most of its patches bend the light.
inline double display_pairs_budget(std::size_t patches) {
    return std::max(kMaxGatherPairs, 30.0 * double(patches) * double(patches));
}

enum class GatherOutcome {
    gathered,     // res.point_radiosity (and for "centres" res.gathered_centres) filled
    not_asked,    // mode "none"
    over_budget,  // more than kMaxGatherPairs vertex-patch pairs
    interrupted,  // `cancel` was set; nothing kept
};

/// The frame both point gathers share (this one and hierarchical_point_values.h): `vertices`
/// fills res.point_radiosity and, for mode "centres", `centres` res.gathered_centres, each
/// given its stage's progress callback; their time is added to res.seconds, and both are
/// cleared when `cancel` was set. Throws std::invalid_argument on an unknown mode.
using GatherStage = std::function<void(const std::function<void(std::size_t, std::size_t)>& progress)>;
GatherOutcome run_point_gather(const std::string& mode, SolveResult& res, const std::atomic<bool>* cancel,
                               const std::function<void(const char*, std::size_t, std::size_t)>& progress,
                               const GatherStage& vertices, const GatherStage& centres);

/// Throws std::invalid_argument unless `mode` is one of gather_modes().
void check_gather_mode(const std::string& mode);

/// Fills res.point_radiosity (and res.gathered_centres for "centres") by final gather from the
/// solved patches and adds the time to res.seconds. Leaves them empty (the averaged point data
/// is written) unless it returns `gathered`. `progress(stage, done, total)` is called from
/// worker threads; stage is "gathering: vertices" or "gathering: centres" (the hierarchical
/// gather also reports "gathering: element centres"). Throws
/// std::invalid_argument on an unknown mode, listing the valid ones.
GatherOutcome gather_point_values(const PatchMesh& mesh, const Visibility& visibility, SolveResult& res,
                                  const std::string& mode, const std::atomic<bool>* cancel = nullptr,
                                  const std::function<void(const char*, std::size_t, std::size_t)>& progress = {});

/// gather_point_values, then, in mode "vertices" with a positive tolerance, display
/// refinement (refine_patch_display: `mesh` may become a finer mesh of display cells, and the
/// per-patch arrays of `res` follow it; progress stage "gathering: display refinement").
GatherOutcome gather_point_values(PatchMesh& mesh, const Visibility& visibility, SolveResult& res,
                                  const std::string& mode, const PatchDisplayRefinement& display,
                                  const std::atomic<bool>* cancel = nullptr,
                                  const std::function<void(const char*, std::size_t, std::size_t)>& progress = {});

}  // namespace bounce
