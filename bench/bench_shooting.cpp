// SPDX-License-Identifier: MIT
// Shooting: shots per second once the rows are known (the O(N) update alone), and the whole
// Cornell-box solve to 1e-3 unshot on 1 and 2 threads (rows computed on demand, borrowed by
// reciprocity), which bench/run.py turns into the 2-thread/1-thread speed-up.
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include "bench/bench_scene.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/linear/shooting_solver.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

void BM_ShotsFromKnownRows(benchmark::State& state) {
    const auto& P = bench::cornell().patches();
    const auto vis = make_visibility("embree", P);
    const auto ff = make_form_factor_estimator("raycast", P, vis.get(), {});
    static const FormFactorMatrix F = FormFactorMatrix::build(*ff, P.size(), std::size_t(4) << 30);
    const MatrixFormFactor rows(F, "raycast");
    std::size_t shots = 0;
    for (auto _ : state) {
        SolverOptions o;
        o.tolerance = 1e-3;
        const SolveResult r = ShootingSolver(P, rows, o).solve();
        shots += r.steps;
    }
    state.SetItemsProcessed(std::int64_t(shots));  // shots
    state.counters["patches"] = double(P.size());
}

void BM_CornellSolve(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(0)));
    const auto& P = bench::cornell().patches();
    std::size_t shots = 0;
    for (auto _ : state) {
        const auto vis = make_visibility("embree", P);
        const auto ff = make_form_factor_estimator("raycast", P, vis.get(), {});
        SolverOptions o;
        o.tolerance = 1e-3;
        shots = ShootingSolver(P, *ff, o).solve().steps;
    }
    state.counters["shots"] = double(shots);
    state.counters["patches"] = double(P.size());
    state.counters["threads"] = double(state.range(0));
}

}  // namespace

BENCHMARK(BM_ShotsFromKnownRows)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CornellSolve)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
