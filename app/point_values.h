// SPDX-License-Identifier: MIT
// The point data a solve exports: gathered at the vertices (and optionally the patch centres).
#pragma once

#include <string>
#include <vector>

#include "mesh/patch_mesh.h"
#include "solver/linear/solve_result.h"
#include "solver/visibility/visibility.h"

namespace bounce::app {

/// --gather values: "vertices" (the default), "centres" (vertices and patch centres), "none"
/// (point data averaged from the patches around each vertex).
std::vector<std::string> gather_modes();

/// Point-to-patch pairs above which the gather is skipped (about 10 s on 2 cores): its cost is
/// vertices x patches, which a hierarchy of patches would cut.
inline constexpr double kMaxGatherPairs = 1e8;

/// Fills res.point_radiosity (and res.gathered_centres for "centres") by final gather from the
/// solved patches, with a progress line; adds the time to res.seconds. Returns false, leaving
/// them empty (the averaged point data is written), when interrupted or when the mesh has more
/// than kMaxGatherPairs vertex-patch pairs (said on stderr unless quiet).
bool gather_point_values(const PatchMesh& mesh, const Visibility& visibility, SolveResult& res, const std::string& mode,
                         bool quiet);

}  // namespace bounce::app
