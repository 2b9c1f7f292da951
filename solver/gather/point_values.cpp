// SPDX-License-Identifier: MIT
#include "solver/gather/point_values.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <utility>

namespace bounce {

std::vector<std::string> gather_modes() { return {"vertices", "centres", "none"}; }

GatherOptions point_value_options() {
    GatherOptions o;
    o.kernel_tolerance = 1e-4;
    return o;
}

void check_gather_mode(const std::string& mode) {
    const auto modes = gather_modes();
    if (std::find(modes.begin(), modes.end(), mode) == modes.end())
        throw std::invalid_argument("gather: unknown mode, got '" + mode + "' (expected vertices, centres or none)");
}

GatherOutcome run_point_gather(const std::string& mode, SolveResult& res, const std::atomic<bool>* cancel,
                               const std::function<void(const char*, std::size_t, std::size_t)>& progress,
                               const GatherStage& vertices, const GatherStage& centres) {
    auto stopped = [&] { return cancel && cancel->load(); };
    auto report = [&](const char* stage) {
        return [&progress, stage](std::size_t d, std::size_t t) {
            if (progress) progress(stage, d, t);
        };
    };
    const auto start = std::chrono::steady_clock::now();
    vertices(report("gathering: vertices"));
    if (mode == "centres" && !stopped()) centres(report("gathering: centres"));
    res.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (stopped()) {
        res.point_radiosity.clear();
        res.gathered_centres.clear();
        return GatherOutcome::interrupted;
    }
    return GatherOutcome::gathered;
}

GatherOutcome gather_point_values(const PatchMesh& mesh, const Visibility& visibility, SolveResult& res,
                                  const std::string& mode, const std::atomic<bool>* cancel,
                                  const std::function<void(const char*, std::size_t, std::size_t)>& progress) {
    check_gather_mode(mode);
    if (mode == "none") return GatherOutcome::not_asked;
    const double pairs = double(mesh.mesh().n_vertices()) * double(mesh.size());
    if (pairs > kMaxGatherPairs) return GatherOutcome::over_budget;
    const GatherOptions options = point_value_options();
    return run_point_gather(
        mode, res, cancel, progress,
        [&](const auto& report) {
            res.point_radiosity = final_gather(mesh.patches(), res.radiosity, visibility, vertex_gather_points(mesh),
                                               options, cancel, report);
        },
        [&](const auto& report) {
            res.gathered_centres = final_gather(mesh.patches(), res.radiosity, visibility,
                                                centre_gather_points(mesh.patches()), options, cancel, report);
        });
}

GatherOutcome gather_point_values(PatchMesh& mesh, const Visibility& visibility, SolveResult& res,
                                  const std::string& mode, const PatchDisplayRefinement& display,
                                  const std::atomic<bool>* cancel,
                                  const std::function<void(const char*, std::size_t, std::size_t)>& progress) {
    const GatherOutcome outcome = gather_point_values(std::as_const(mesh), visibility, res, mode, cancel, progress);
    if (outcome != GatherOutcome::gathered || mode != "vertices" || !(display.tolerance > 0)) return outcome;
    const auto start = std::chrono::steady_clock::now();
    refine_patch_display(mesh, res, visibility, display, cancel, [&](std::size_t d, std::size_t t) {
        if (progress) progress("gathering: display refinement", d, t);
    });
    res.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (cancel && cancel->load()) {
        res.point_radiosity.clear();
        return GatherOutcome::interrupted;
    }
    return outcome;
}

}  // namespace bounce
