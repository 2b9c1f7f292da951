// SPDX-License-Identifier: MIT
// Hierarchical radiosity on the Cornell box as `bounce solve --solver hierarchical` starts it
// (faces cut to 1/30 of the scene's area, contact cuts on): the whole solve (refinement,
// link form factors, gather and push-pull) on 1 and 2 threads, which bench/run.py turns into
// the 2-thread/1-thread speed-up. Refinement judges each generation of pairs in parallel and
// the gather runs per receiver, so both counts must give the same elements and links. Then the
// point data of one solve, with and without display refinement.
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include "bench/bench_scene.h"
#include "solver/gather/hierarchical_point_values.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

const PatchMesh& coarse_cornell() {
    static const PatchMesh mesh = [] {
        MeshingOptions o;
        o.target_patches = 30;
        return PatchMesh(load_scene("cornell"), o);
    }();
    return mesh;
}

void BM_HierarchicalCornell(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(0)));
    const auto& P = coarse_cornell().patches();
    const auto vis = make_visibility("embree", P);
    HierarchicalOptions h;
    h.link_epsilon = 0.2;
    // Short mode (bench/run.py --short meshes its other scenes to 300 patches): a shallower tree.
    h.max_level = bench::patch_target() >= 2000 ? 3 : 2;
    std::size_t elements = 0, links = 0;
    for (auto _ : state) {
        const HierarchicalSolution s = solve_hierarchical(P, *vis, h);
        elements = s.leaves.size();
        links = s.links.size();
    }
    state.counters["patches"] = double(P.size());
    state.counters["elements"] = double(elements);
    state.counters["links"] = double(links);
    state.counters["max_level"] = double(h.max_level);
}

// The point data of one solve (power epsilon 3e-7, level 4; short mode 3e-6, level 3): the
// re-gathered centres and the vertices through the links, without display refinement (arg 0)
// and with the suggested tolerance (arg 1), whose ratio is what display refinement costs.
void BM_HierarchicalPointData(benchmark::State& state) {
    const auto& P = coarse_cornell().patches();
    const auto vis = make_visibility("embree", P);
    HierarchicalOptions h;
    const bool full = bench::patch_target() >= 2000;
    h.power_epsilon = full ? 3e-7 : 3e-6;
    h.max_level = full ? 4 : 3;
    static const HierarchicalSolution solved = solve_hierarchical(P, *vis, h);
    const DisplayRefinement display{state.range(0) ? kSuggestedDisplayTolerance : 0.0};
    std::size_t cells = 0, vertices = 0;
    for (auto _ : state) {
        state.PauseTiming();
        HierarchicalSolution s = solved;
        PatchMesh elements = s.tree.conforming_mesh(s.leaves);
        SolveResult res = s.result;
        state.ResumeTiming();
        gather_hierarchical_point_values(s, elements, *vis, res, "vertices", display);
        cells = elements.size();
        vertices = res.point_radiosity.size();
    }
    state.counters["elements"] = double(solved.leaves.size());
    state.counters["cells"] = double(cells);
    state.counters["vertices"] = double(vertices);
}

}  // namespace

BENCHMARK(BM_HierarchicalCornell)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_HierarchicalPointData)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
