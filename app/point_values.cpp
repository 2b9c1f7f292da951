// SPDX-License-Identifier: MIT
#include "app/point_values.h"

#include <chrono>
#include <iostream>

#include "app/progress_line.h"
#include "app/signals.h"
#include "solver/gather/final_gather.h"

namespace bounce::app {

std::vector<std::string> gather_modes() { return {"vertices", "centres", "none"}; }

bool gather_point_values(const PatchMesh& mesh, const Visibility& visibility, SolveResult& res, const std::string& mode,
                         bool quiet) {
    if (mode == "none") return false;
    const double pairs = double(mesh.mesh().n_vertices()) * double(mesh.size());
    if (pairs > kMaxGatherPairs) {
        if (!quiet)
            std::cerr << "note: point data averaged, not gathered: " << mesh.mesh().n_vertices() << " vertices x "
                      << mesh.size() << " patches is beyond the gather's budget of " << kMaxGatherPairs << " pairs\n";
        return false;
    }
    const auto start = std::chrono::steady_clock::now();
    ProgressLine progress(!quiet);
    const auto vertices = vertex_gather_points(mesh);
    res.point_radiosity =
        final_gather(mesh.patches(), res.radiosity, visibility, vertices, {}, &g_interrupted,
                     [&](std::size_t d, std::size_t t) { progress.items("gathering: vertices", d, t); });
    if (mode == "centres" && !g_interrupted.load()) {
        const auto centres = centre_gather_points(mesh.patches());
        res.gathered_centres =
            final_gather(mesh.patches(), res.radiosity, visibility, centres, {}, &g_interrupted,
                         [&](std::size_t d, std::size_t t) { progress.items("gathering: centres", d, t); });
    }
    progress.finish();
    res.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (g_interrupted.load()) {
        res.point_radiosity.clear();
        res.gathered_centres.clear();
        return false;
    }
    return true;
}

}  // namespace bounce::app
