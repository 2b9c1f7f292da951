// SPDX-License-Identifier: MIT
// The point data a solve exports, with the command line's progress line and note
// (solver/gather/point_values.h does the work).
#pragma once

#include <string>

#include "mesh/meshing/patch_mesh.h"
#include "solver/gather/hierarchical_point_values.h"
#include "solver/gather/point_values.h"
#include "solver/linear/solve_result.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

namespace bounce::app {

/// bounce::gather_point_values with a progress line, cancelled by a signal. Returns false,
/// leaving the gathered values empty (the averaged point data is written), when interrupted or
/// when the mesh has more than kMaxGatherPairs vertex-patch pairs (said on stderr unless quiet).
bool gather_point_values(const PatchMesh& mesh, const Visibility& visibility, SolveResult& res, const std::string& mode,
                         bool quiet);

/// The same with display refinement of a patch solution (bounce::PatchDisplayRefinement):
/// `mesh` may become a finer mesh of display cells, and res's per-patch arrays follow it.
bool gather_point_values(PatchMesh& mesh, const Visibility& visibility, SolveResult& res, const std::string& mode,
                         const PatchDisplayRefinement& display, bool quiet);

/// The same for a hierarchical solution's conforming mesh, gathered through its links
/// (bounce::gather_hierarchical_point_values).
bool gather_point_values(const HierarchicalSolution& solution, const PatchMesh& elements, const Visibility& visibility,
                         SolveResult& res, const std::string& mode, bool quiet);

/// The same with display refinement (bounce::DisplayRefinement): `solution` and `elements`
/// may gain display leaves, and res's per-leaf arrays follow them.
bool gather_point_values(HierarchicalSolution& solution, PatchMesh& elements, const Visibility& visibility,
                         SolveResult& res, const std::string& mode, const DisplayRefinement& display, bool quiet);

}  // namespace bounce::app
