// SPDX-License-Identifier: MIT
// Form-factor rows per second of each method on the Cornell box, whole rows (every pair
// computed), on all threads. Rows cycle through the patches so near and far pairs both count.
#include <benchmark/benchmark.h>

#include "bench/bench_scene.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

void BM_Rows(benchmark::State& state, const std::string& method, const std::string& backend) {
    const auto& P = bench::cornell().patches();
    const auto vis = make_visibility(backend, P);
    const auto ff = make_form_factor_estimator(method, P, vis.get(), {});
    std::vector<float> row(P.size());
    std::size_t i = 0;
    for (auto _ : state) {
        ff->compute_row(i, row);
        benchmark::DoNotOptimize(row.data());
        i = (i + 97) % P.size();
    }
    state.SetItemsProcessed(state.iterations());  // rows
    state.counters["pairs_per_second"] =
        benchmark::Counter(double(state.iterations()) * double(P.size()), benchmark::Counter::kIsRate);
    state.counters["patches"] = double(P.size());
}

}  // namespace

BENCHMARK_CAPTURE(BM_Rows, raycast_embree, std::string("raycast"), std::string("embree"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rows, raycast_cgal, std::string("raycast"), std::string("cgal"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rows, analytic, std::string("analytic"), std::string("embree"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rows, hemicube, std::string("hemicube"), std::string("embree"))->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
