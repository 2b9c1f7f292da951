// SPDX-License-Identifier: MIT
// Form-factor rows per second of each method on the Cornell box, whole rows (every pair
// computed), on all threads. Rows cycle through the patches so near and far pairs both count.
#include <benchmark/benchmark.h>

#include <cmath>

#include <tbb/global_control.h>

#include "bench/bench_scene.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/polygon_form_factor.h"
#include "solver/form_factors/surface_form_factor.h"
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

/// The whole matrix of an empty unit cube, each face cut 20 x 20 (2400 patches), on one thread:
/// the case the issue compares with View3D (0.28-0.42 s single-threaded, rows within 1e-6).
/// Reports the worst |row sum - 1|.
void BM_EmptyCube20(benchmark::State& state, const std::string& method) {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    MeshingOptions o;
    o.max_edge = 1.0 / 20 * (1 + 1e-9);
    const PatchMesh mesh(closed_box({1, 1, 1}, {"w", Rgb::gray(0.5), Rgb::gray(0)}), o);
    const auto& P = mesh.patches();
    const auto vis = make_visibility("embree", P);
    double worst = 0;
    for (auto _ : state) {
        const auto ff = make_form_factor_estimator(method, P, vis.get(), {});
        const auto F = FormFactorMatrix::build(*ff, P.size(), std::size_t(1) << 31);
        worst = 0;
        for (const double s : F.row_sums()) worst = std::max(worst, std::abs(s - 1));
    }
    state.counters["worst_row_error"] = worst;
    state.counters["patches"] = double(P.size());
}

/// Unit squares 1 apart, the blocker [0.1,0.6]x[0.2,0.55] at z = 0.4, all cut 16 x 16: the
/// surface factor F12 (exact 0.140126989, VALIDATION.md) on all threads; View3D took 3.6 s.
void BM_AsymmetricBlocker16(benchmark::State& state, const std::string& method) {
    Scene s = parallel_pair(1, 1, 1);
    s.surfaces.push_back(
        {{{0.1, 0.2, 0.4}, {0.6, 0.2, 0.4}, {0.6, 0.55, 0.4}, {0.1, 0.55, 0.4}}, 0, "blocker", {"bench", 0}});
    MeshingOptions o;
    o.max_edge = 1.0 / 16 * (1 + 1e-9);
    const PatchMesh mesh(s, o);
    const auto vis = make_visibility("embree", mesh.patches());
    double f = 0;
    for (auto _ : state) {
        const auto ff = make_form_factor_estimator(method, mesh.patches(), vis.get(), {});
        f = surface_form_factor(mesh.patches(), *ff, 0, 1);
    }
    state.counters["error"] = std::abs(f - 0.140126989);
}

/// The unoccluded factor (at the ray-cast method's tolerance) from a unit wall whose top edge
/// rises h = 0.5 x 10^-Arg above a unit floor's plane to that floor: the strip that sees the
/// floor is h high. Slivers (Arg 11) arise where crossing objects and contact cuts leave a
/// corner grazing another patch's plane; compare their time per pair with Arg 0 in one run.
void BM_GrazingWall(benchmark::State& state) {
    const double h = 0.5 * std::pow(10.0, -double(state.range(0)));
    const std::vector<glm::dvec3> wall = {{0, 0, h - 1}, {0, 1, h - 1}, {0, 1, h}, {0, 0, h}};
    const std::vector<glm::dvec3> floor = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const double tolerance = FormFactorOptions{}.unoccluded_tolerance;
    double f = 0;
    for (auto _ : state) {
        f = polygon_form_factor(wall, {1, 0, 0}, floor, {0, 0, 1}, tolerance);
        benchmark::DoNotOptimize(f);
    }
    state.counters["F"] = f;
}

}  // namespace

BENCHMARK_CAPTURE(BM_EmptyCube20, raycast, std::string("raycast"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_EmptyCube20, exact, std::string("exact"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_AsymmetricBlocker16, raycast, std::string("raycast"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_AsymmetricBlocker16, exact, std::string("exact"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_Rows, raycast_embree, std::string("raycast"), std::string("embree"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Rows, raycast_cgal, std::string("raycast"), std::string("cgal"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Rows, analytic, std::string("analytic"), std::string("embree"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Rows, hemicube, std::string("hemicube"), std::string("embree"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK(BM_GrazingWall)->Arg(0)->Arg(11)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
