// SPDX-License-Identifier: MIT
// Shadow rays per second of each visibility backend on the same rays: four rays between
// random points on each of 16384 random pairs of Cornell-box patches, lifted by the offset,
// as the ray-cast form factors trace them (a pair's rays go as one packet). And the contact
// cuts' enclosure rays on the input surfaces, through the exact CGAL tree and through Embree.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include <glm/geometric.hpp>

#include "bench/bench_scene.h"
#include "mesh/geometry/surface_rays.h"
#include "mesh/geometry/surface_tree.h"
#include "mesh/scene/polygon.h"
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

/// 4096 enclosure rays on the Cornell box's input surfaces: from points 1e-6 of the diagonal in
/// front of a surface, cosine-distributed about its normal (find_covered_regions' rays).
struct EnclosureRays {
    Scene scene = load_scene("cornell");
    std::vector<std::pair<glm::dvec3, glm::dvec3>> rays;  // from, direction
    double slack = 0.0;
    EnclosureRays() {
        glm::dvec3 lo(1e300), hi(-1e300);
        for (const auto& f : scene.surfaces)
            for (const auto& v : f.vertices) {
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
        const double diag = glm::length(hi - lo);
        slack = 5e-4 * diag;
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<double> U(0.0, 1.0);
        for (int k = 0; k < 1 << 12; ++k) {
            const auto& f = scene.surfaces[rng() % scene.surfaces.size()];
            const glm::dvec3 n = glm::normalize(newell_normal(f.vertices));
            const glm::dvec3 t =
                glm::normalize(glm::cross(n, std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
            const glm::dvec3 b = glm::cross(n, t);
            double u = U(rng), v = U(rng);
            if (u + v > 1) u = 1 - u, v = 1 - v;
            const glm::dvec3 x =
                f.vertices[0] + u * (f.vertices[1] - f.vertices[0]) + v * (f.vertices[2] - f.vertices[0]);
            const double phi = 2 * M_PI * U(rng), s = std::sqrt(U(rng));
            rays.push_back(
                {x + 1e-6 * diag * n, std::cos(phi) * s * t + std::sin(phi) * s * b + std::sqrt(1 - s * s) * n});
        }
    }
};

template <class Tree>
void BM_FirstHits(benchmark::State& state) {
    static const EnclosureRays e;
    const Tree tree(e.scene);
    std::size_t met = 0;
    for (auto _ : state) {
        met = 0;
        for (const auto& [from, d] : e.rays) met += !tree.first_hits(from, d, e.slack).empty();
        benchmark::DoNotOptimize(met);
    }
    state.SetItemsProcessed(std::int64_t(state.iterations() * e.rays.size()));
    state.counters["met_fraction"] = double(met) / double(e.rays.size());
}

}  // namespace

BENCHMARK_TEMPLATE(BM_FirstHits, SurfaceTree)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_FirstHits, SurfaceRays)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rays, cgal, std::string("cgal"), false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rays, embree, std::string("embree"), false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rays, embree_packets, std::string("embree"), true)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
