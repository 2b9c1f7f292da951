// SPDX-License-Identifier: MIT
#include "app/point_values.h"

#include <iostream>

#include "app/progress_line.h"
#include "app/signals.h"
#include "solver/gather/hierarchical_point_values.h"

namespace bounce::app {

bool gather_point_values(const PatchMesh& mesh, const Visibility& visibility, SolveResult& res, const std::string& mode,
                         bool quiet) {
    if (mode == "none") return false;
    ProgressLine progress(!quiet);
    const GatherOutcome outcome = bounce::gather_point_values(
        mesh, visibility, res, mode, &g_interrupted,
        [&](const char* stage, std::size_t d, std::size_t t) { progress.items(stage, d, t); });
    progress.finish();
    if (outcome == GatherOutcome::over_budget && !quiet)
        std::cerr << "note: point data averaged, not gathered: " << mesh.mesh().n_vertices() << " vertices x "
                  << mesh.size() << " patches is beyond the gather's budget of " << kMaxGatherPairs << " pairs\n";
    return outcome == GatherOutcome::gathered;
}

bool gather_point_values(const HierarchicalSolution& solution, const PatchMesh& elements, const Visibility& visibility,
                         SolveResult& res, const std::string& mode, bool quiet) {
    if (mode == "none") return false;
    ProgressLine progress(!quiet);
    const GatherOutcome outcome = bounce::gather_hierarchical_point_values(
        solution, elements, visibility, res, mode, &g_interrupted,
        [&](const char* stage, std::size_t d, std::size_t t) { progress.items(stage, d, t); });
    progress.finish();
    if (outcome == GatherOutcome::over_budget && !quiet)
        std::cerr << "note: point data averaged, not gathered: " << elements.mesh().n_vertices()
                  << " vertices x the links along their elements' paths is beyond the gather's budget of "
                  << kMaxGatherPairs << " pairs\n";
    return outcome == GatherOutcome::gathered;
}

}  // namespace bounce::app
