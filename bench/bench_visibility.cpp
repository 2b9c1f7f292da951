// SPDX-License-Identifier: MIT
// Shadow rays per second of each visibility backend on the same rays: four rays between
// random points on each of 16384 random pairs of Cornell-box patches, lifted by the offset,
// as the ray-cast form factors trace them (a pair's rays go as one packet).
#include <benchmark/benchmark.h>

#include <random>

#include "bench/bench_scene.h"
#include "solver/form_factors/patch_sampling.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

const std::vector<Visibility::Segment>& rays(double eps) {
    static const std::vector<Visibility::Segment> r = [eps] {
        const auto& P = bench::cornell().patches();
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<double> U(0.0, 1.0);
        std::vector<Visibility::Segment> out;
        for (int k = 0; k < 1 << 14; ++k) {
            const Patch& a = P[rng() % P.size()];
            const Patch& b = P[rng() % P.size()];
            for (int r = 0; r < 4; ++r)
                out.push_back(
                    {patch_point(a, U(rng), U(rng)) + eps * a.normal, patch_point(b, U(rng), U(rng)) + eps * b.normal});
        }
        return out;
    }();
    return r;
}

void BM_Rays(benchmark::State& state, const std::string& backend, bool packets) {
    const auto vis = make_visibility(backend, bench::cornell().patches());
    const auto& R = rays(vis->offset());
    std::vector<std::uint8_t> blocked(R.size());
    std::size_t hits = 0;
    for (auto _ : state) {
        if (packets) {
            for (std::size_t k = 0; k < R.size(); k += 4)
                vis->occluded(std::span(R).subspan(k, 4), std::span(blocked).subspan(k, 4));
        } else {
            for (std::size_t k = 0; k < R.size(); ++k) blocked[k] = vis->occluded(R[k].a, R[k].b);
        }
        benchmark::DoNotOptimize(blocked.data());
    }
    for (const auto b : blocked) hits += b;
    state.SetItemsProcessed(std::int64_t(state.iterations() * R.size()));
    state.counters["blocked_fraction"] = double(hits) / double(R.size());
    state.counters["patches"] = double(bench::cornell().size());
}

}  // namespace

BENCHMARK_CAPTURE(BM_Rays, cgal, std::string("cgal"), false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rays, embree, std::string("embree"), false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rays, embree_packets, std::string("embree"), true)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
