// SPDX-License-Identifier: MIT
// Hierarchical radiosity on the Cornell box as `bounce solve --solver hierarchical` starts it
// (faces cut to 1/30 of the scene's area, contact cuts on): the whole solve (refinement,
// link form factors, gather and push-pull) on 1 and 2 threads, which bench/run.py turns into
// the 2-thread/1-thread speed-up. Refinement judges each generation of pairs in parallel and
// the gather runs per receiver, so both counts must give the same elements and links.
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include "bench/bench_scene.h"
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

}  // namespace

BENCHMARK(BM_HierarchicalCornell)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
