// SPDX-License-Identifier: MIT
// The path-traced reference: paths per second on the Cornell box, per core (1 thread) and on
// 2 threads, and the time to estimate 100 probes to 1% relative standard error on 2 threads
// (the anchor: a production path tracer does about 150k paths/s per core on this scene).
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include "mesh/cornell_box.h"
#include "solver/reference/path_tracer.h"

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

}  // namespace

BENCHMARK(BM_ReferencePaths)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Reference100ProbesTo1Percent)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
