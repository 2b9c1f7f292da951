// SPDX-License-Identifier: MIT
// The path-traced reference: paths per second on the Cornell box, per core (1 thread) and on
// 2 threads, and the time to estimate 100 probes to 1% relative standard error on 2 threads
// (the anchor: a production path tracer does about 150k paths/s per core on this scene).
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/cornell_box.h"
#include "mesh/readers/scene_loader.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/gather/final_gather.h"
#include "solver/gather/point_values.h"
#include "solver/linear/shooting_solver.h"
#include "solver/reference/path_tracer.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

const Scene& cornell_scene() {
    static const Scene s = make_cornell_box();
    return s;
}

void BM_ReferencePaths(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(0)));
    const PathTracer tracer(cornell_scene());
    const auto probes = tracer.probes(64, 1);
    ReferenceOptions o;
    o.target_error = 0;  // a fixed budget: every point runs max_paths
    o.max_paths = 4096;
    for (auto _ : state) benchmark::DoNotOptimize(tracer.estimate_all(probes, o));
    state.SetItemsProcessed(std::int64_t(tracer.paths_traced()));  // paths
    state.counters["threads"] = double(state.range(0));
}

void BM_Reference100ProbesTo1Percent(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    const PathTracer tracer(cornell_scene());
    const auto probes = tracer.probes(100, 1);
    ReferenceOptions o;
    o.target_error = 0.01;
    for (auto _ : state) benchmark::DoNotOptimize(tracer.estimate_all(probes, o));
    state.counters["paths_per_probe"] = double(tracer.paths_traced()) / double(state.iterations()) / 100.0;
}

/// The point data of the default run: final gather at every vertex of the default (contact-cut)
/// Cornell mesh from its solved patches, on 2 threads; compare with BM_CornellSolve in
/// bench_shooting for what it adds to a solve.
void BM_GatherVertices(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    static const Scene scene = load_scene("cornell");
    static const PatchMesh mesh(scene, MeshingOptions{});
    const auto vis = make_visibility("embree", mesh.patches());
    static const std::vector<Rgb> B = [&] {
        const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
        return ShootingSolver(mesh.patches(), *ff, {}).solve().radiosity;
    }();
    const auto points = vertex_gather_points(mesh);
    for (auto _ : state) benchmark::DoNotOptimize(final_gather(mesh.patches(), B, *vis, points, point_value_options()));
    state.counters["vertices"] = double(points.size());
    state.counters["patches"] = double(mesh.size());
}

/// The default run, `bounce solve` on the built-in Cornell box, on 2 threads: meshing with
/// contact cuts, the Embree scene, ray-cast form factors computed as shooting asks for them,
/// shooting to 1e-3 unshot, and the point data gathered at the vertices: all of it but reading
/// the command line and writing the .vtu. Issue 16's goal for the run is 1.5 s on 2 cores.
void BM_DefaultRun(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    std::size_t patches = 0, shots = 0;
    for (auto _ : state) {
        const PatchMesh mesh(load_scene("cornell"), MeshingOptions{});
        const auto vis = make_visibility("embree", mesh.patches());
        const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
        SolveResult res = ShootingSolver(mesh.patches(), *ff, {}).solve();
        if (gather_point_values(mesh, *vis, res, "vertices") != GatherOutcome::gathered)
            state.SkipWithError("the gather did not run");
        patches = mesh.size();
        shots = res.steps;
    }
    state.counters["patches"] = double(patches);
    state.counters["shots"] = double(shots);
}

}  // namespace

BENCHMARK(BM_DefaultRun)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_GatherVertices)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReferencePaths)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Reference100ProbesTo1Percent)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
