// SPDX-License-Identifier: MIT
// Shadow rays per second of each visibility backend on the same rays: four rays between
// random points on each of 16384 random pairs of Cornell-box patches, lifted by the offset,
// as the ray-cast form factors trace them (a pair's rays go as one packet). And the contact
// cuts' enclosure rays on the input surfaces, through the exact CGAL tree and through Embree;
// and their box queries in a cloud of small triangles, CGAL's listing of every triangle by its
// exact test against SurfaceTree's, which lets bounding boxes decide where they can.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <random>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

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

/// A furnished room's worth of small triangles (2-8 cm, any orientation, 20,000 in a 10 x 3 x
/// 10 m room) and 256 queries: the box of a triangle widened by 0.5 m, as the contact search
/// asks for what may cover or touch a face.
struct BoxQueries {
    Scene scene;
    std::vector<std::pair<glm::dvec3, glm::dvec3>> boxes;
    BoxQueries() {
        std::mt19937_64 rng(5);
        std::uniform_real_distribution<double> U(0.0, 1.0);
        scene.materials.resize(1);
        const auto unit = [&] {
            const glm::dvec3 v(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5);
            return glm::normalize(v);
        };
        for (int k = 0; k < 20000; ++k) {
            const glm::dvec3 c(10 * U(rng), 3 * U(rng), 10 * U(rng));
            const double size = 0.02 + 0.06 * U(rng);
            scene.surfaces.push_back({{c, c + size * unit(), c + size * unit()}, 0, "t", {}});
        }
        for (int k = 0; k < 256; ++k) {
            const auto& v = scene.surfaces[rng() % scene.surfaces.size()].vertices;
            glm::dvec3 lo(1e300), hi(-1e300);
            for (const auto& p : v) {
                lo = glm::min(lo, p);
                hi = glm::max(hi, p);
            }
            boxes.emplace_back(lo - glm::dvec3(0.5), hi + glm::dvec3(0.5));
        }
    }
};

/// The baseline: CGAL's own listing, every triangle near the box through the exact test.
class ExactBoxTree {
    using K = CGAL::Exact_predicates_inexact_constructions_kernel;
    using Triangles = std::vector<K::Triangle_3>;
    using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
    Triangles m_triangles;
    CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>> m_tree;

public:
    explicit ExactBoxTree(const Scene& scene) {
        for (const auto& f : scene.surfaces)
            m_triangles.emplace_back(K::Point_3(f.vertices[0].x, f.vertices[0].y, f.vertices[0].z),
                                     K::Point_3(f.vertices[1].x, f.vertices[1].y, f.vertices[1].z),
                                     K::Point_3(f.vertices[2].x, f.vertices[2].y, f.vertices[2].z));
        m_tree.insert(m_triangles.cbegin(), m_triangles.cend());
        m_tree.build();
    }
    std::vector<int> in_box(const glm::dvec3& lo, const glm::dvec3& hi) const {
        std::vector<Primitive::Id> ids;
        m_tree.all_intersected_primitives(K::Iso_cuboid_3(lo.x, lo.y, lo.z, hi.x, hi.y, hi.z), std::back_inserter(ids));
        std::vector<int> out;
        for (const auto& id : ids) out.push_back(int(id - m_triangles.cbegin()));
        std::sort(out.begin(), out.end());
        return out;
    }
};

template <class Tree>
void BM_BoxQueries(benchmark::State& state) {
    static const BoxQueries q;
    const Tree tree(q.scene);
    std::size_t found = 0;
    for (auto _ : state) {
        found = 0;
        for (const auto& [lo, hi] : q.boxes) found += tree.in_box(lo, hi).size();
        benchmark::DoNotOptimize(found);
    }
    state.SetItemsProcessed(std::int64_t(state.iterations() * q.boxes.size()));
    state.counters["found"] = double(found);
}

}  // namespace

BENCHMARK_TEMPLATE(BM_BoxQueries, ExactBoxTree)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_BoxQueries, SurfaceTree)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_FirstHits, SurfaceTree)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_FirstHits, SurfaceRays)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rays, cgal, std::string("cgal"), false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rays, embree, std::string("embree"), false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Rays, embree_packets, std::string("embree"), true)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
