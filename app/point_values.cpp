// SPDX-License-Identifier: MIT
#include "app/point_values.h"

#include <functional>
#include <iostream>
#include <string>

#include "app/progress_line.h"
#include "app/signals.h"
#include "solver/gather/hierarchical_point_values.h"

namespace bounce::app {

namespace {

using StageProgress = std::function<void(const char*, std::size_t, std::size_t)>;

/// Runs a gather with a progress line and says on stderr (unless quiet) when it was over
/// budget; `pairs` names what the budget counted.
bool with_progress(const std::string& mode, bool quiet,
                   const std::function<GatherOutcome(const StageProgress&)>& gather, const std::string& pairs) {
    if (mode == "none") return false;
    ProgressLine progress(!quiet);
    const GatherOutcome outcome =
        gather([&](const char* stage, std::size_t d, std::size_t t) { progress.items(stage, d, t); });
    progress.finish();
    if (outcome == GatherOutcome::over_budget && !quiet)
        std::cerr << "note: point data averaged, not gathered: " << pairs << " is beyond the gather's budget of "
                  << kMaxGatherPairs << " pairs\n";
    return outcome == GatherOutcome::gathered;
}

}  // namespace

bool gather_point_values(const PatchMesh& mesh, const Visibility& visibility, SolveResult& res, const std::string& mode,
                         bool quiet) {
    return with_progress(
        mode, quiet,
        [&](const StageProgress& p) {
            return bounce::gather_point_values(mesh, visibility, res, mode, &g_interrupted, p);
        },
        std::to_string(mesh.mesh().n_vertices()) + " vertices x " + std::to_string(mesh.size()) + " patches");
}

bool gather_point_values(PatchMesh& mesh, const Visibility& visibility, SolveResult& res, const std::string& mode,
                         const PatchDisplayRefinement& display, bool quiet) {
    const std::string pairs =
        std::to_string(mesh.mesh().n_vertices()) + " vertices x " + std::to_string(mesh.size()) + " patches";
    return with_progress(
        mode, quiet,
        [&](const StageProgress& p) {
            return bounce::gather_point_values(mesh, visibility, res, mode, display, &g_interrupted, p);
        },
        pairs);
}

bool gather_point_values(const HierarchicalSolution& solution, const PatchMesh& elements, const Visibility& visibility,
                         SolveResult& res, const std::string& mode, bool quiet) {
    return with_progress(
        mode, quiet,
        [&](const StageProgress& p) {
            return bounce::gather_hierarchical_point_values(solution, elements, visibility, res, mode, &g_interrupted,
                                                            p);
        },
        std::to_string(elements.mesh().n_vertices()) +
            " vertices (and, with a power epsilon, the elements' centres) x the links along their elements' paths");
}

bool gather_point_values(HierarchicalSolution& solution, PatchMesh& elements, const Visibility& visibility,
                         SolveResult& res, const std::string& mode, const DisplayRefinement& display, bool quiet) {
    const std::string pairs =
        std::to_string(elements.mesh().n_vertices()) +
        " vertices (and, with a power epsilon, the elements' centres) x the links along their elements' paths";
    return with_progress(
        mode, quiet,
        [&](const StageProgress& p) {
            return bounce::gather_hierarchical_point_values(solution, elements, visibility, res, mode, display,
                                                            &g_interrupted, p);
        },
        pairs);
}

}  // namespace bounce::app
