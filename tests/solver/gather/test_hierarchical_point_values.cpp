// SPDX-License-Identifier: MIT
// Point data of hierarchical solutions gathered through their links (issue 17): the links of
// a vertex's element and its ancestors must cover every source exactly once, so the gather
// reproduces Lambert's formula under a lamp and E / (1 - rho) in a furnace, with cluster links
// carried by the irradiance the solve computed.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/counting_visibility.h"
#include "solver/form_factors/patch_sampling.h"
#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/gather/hierarchical_point_values.h"
#include "solver/reference/probe_score.h"
#include "solver/refinement/hierarchical_radiosity.h"

using namespace bounce;

// The lamps reflect nothing, so a vertex of the plane gets 0.5 E F(x -> lamps) exactly: the
// lamps' elements its path is linked with must tile them once. Missing an ancestor's links
// (or counting a source twice) would be off by the share of the lamps those links hold.
TEST(HierarchicalPointValues, LampOverPlaneVerticesGetLambertsFormulaThroughTheLinks) {
    Scene s = lamp_over_plane();
    // A second, small lamp, lower than the first (nothing hides it): the plane's elements take
    // it at a coarser level than the first (links at the leaves' ancestors).
    s.surfaces.push_back(
        {{{2.6, 2.6, 0.9}, {2.6, 2.7, 0.9}, {2.7, 2.7, 0.9}, {2.7, 2.6, 0.9}}, 1, "small lamp", {"test", 0}});
    MeshingOptions o;
    o.subdivide = false;
    const PatchMesh m(s, o);
    const auto vis = make_visibility("embree", m.patches());
    // With a power epsilon the leaves are re-gathered first: the lamps' leaves and the nodes
    // above them must come back at E (a leaf given another's value, or a parent pulled up
    // wrongly, would light the plane by the wrong amount).
    for (const double power_epsilon : {0.0, 1e-3}) {
        SCOPED_TRACE("power epsilon " + std::to_string(power_epsilon));
        HierarchicalOptions h;
        h.link_epsilon = 0.3;
        h.power_epsilon = power_epsilon;
        const HierarchicalSolution sol = solve_hierarchical(m.patches(), *vis, h);
        ASSERT_GT(sol.leaves.size(), 100u);  // refined: links at several levels
        const PatchMesh elements = sol.tree.conforming_mesh(sol.leaves);
        const auto element_vis = make_visibility("embree", elements.patches());
        SolveResult res = sol.result;
        ASSERT_EQ(gather_hierarchical_point_values(sol, elements, *element_vis, res, "vertices"),
                  GatherOutcome::gathered);
        const auto points = vertex_gather_points(elements);
        ASSERT_EQ(res.point_radiosity.size(), points.size());
        std::size_t checked = 0;
        double worst = 0.0;
        for (std::size_t v = 0; v < points.size(); ++v) {
            if (points[v].surface != 0) continue;
            const double F = point_polygon_form_factor(points[v].position, {0, 0, 1}, s.surfaces[1].vertices) +
                             point_polygon_form_factor(points[v].position, {0, 0, 1}, s.surfaces[2].vertices);
            for (int c = 0; c < 3; ++c) {
                const double want = 0.5 * Rgb(3, 2, 1)[c] * F;
                // The gather takes far sources by the Gauss rule to a relative 1e-4 each (point_value_options).
                ASSERT_NEAR(res.point_radiosity[v][c], want, 5e-4 * want + 1e-12) << "vertex " << v;
                worst = std::max(worst, std::abs(res.point_radiosity[v][c] / want - 1));
            }
            ++checked;
        }
        EXPECT_GT(checked, 100u);
        // Cheaper than gathering from every leaf.
        const double pairs = hierarchical_gather_pairs(sol, elements);
        EXPECT_LT(pairs, 0.5 * double(points.size()) * double(sol.leaves.size()));
        std::cout << "lamp over plane: " << sol.leaves.size() << " elements, " << checked
                  << " plane vertices, largest relative error " << worst << ", " << pairs << " vertex-source pairs ("
                  << pairs / (double(points.size()) * double(sol.leaves.size())) << " of every vertex x leaf)\n";
    }
}

// A closed furnace of small patches, one element each, clustered: part of every vertex's light
// comes over cluster links (the solve's irradiance) and part through element links (gathered
// with the exact kernel). Every point is E / (1 - rho) = 2; losing either part would leave it
// near 1 + the other part.
TEST(HierarchicalPointValues, ClusteredFurnaceVerticesGatherEOverOneMinusRho) {
    const Scene box = closed_box({1.0, 1.5, 2.0}, {"furnace", Rgb::gray(0.5), Rgb::gray(1.0)});
    MeshingOptions o;
    o.target_patches = 600;
    const PatchMesh m(box, o);
    const auto vis = make_visibility("embree", m.patches());
    HierarchicalOptions h;
    h.max_level = 0;
    h.link_epsilon = 0.2;
    const HierarchicalSolution sol = solve_hierarchical(m.patches(), *vis, h);
    ASSERT_GT(sol.cluster_links, 0u);
    const PatchMesh elements = sol.tree.conforming_mesh(sol.leaves);
    const auto element_vis = make_visibility("embree", elements.patches());
    SolveResult res = sol.result;
    ASSERT_EQ(gather_hierarchical_point_values(sol, elements, *element_vis, res, "centres"), GatherOutcome::gathered);
    // The cluster links' point-to-point transfer is approximate (the solve's leaves are 2 within
    // a few %): the gather redoes the element links with the exact kernel but keeps each
    // element's cluster irradiance, so it may err about as much as the solve, not more.
    auto deviation = [](const std::vector<Rgb>& values) {
        double sum = 0.0, worst = 0.0;
        for (const Rgb& b : values) {
            sum += (b.g - 2.0) * (b.g - 2.0);
            worst = std::max(worst, std::abs(b.g - 2.0));
        }
        return std::pair(std::sqrt(sum / double(values.size())), worst);
    };
    const auto [solve_rms, solve_worst] = deviation(sol.result.radiosity);
    const auto [vertex_rms, vertex_worst] = deviation(res.point_radiosity);
    const auto [centre_rms, centre_worst] = deviation(res.gathered_centres);
    double from_clusters = 0.0;
    for (const Rgb& e : sol.cluster_irradiance) from_clusters = std::max(from_clusters, e.g);
    std::cout << "furnace: " << sol.leaves.size() << " elements, " << sol.links.size() << " links ("
              << sol.cluster_links << " with a cluster), largest cluster irradiance " << from_clusters
              << " of 2; |B - 2| RMS / worst: solve " << solve_rms << " / " << solve_worst << ", vertices "
              << vertex_rms << " / " << vertex_worst << ", centres " << centre_rms << " / " << centre_worst << "\n";
    EXPECT_GT(from_clusters, 0.1);  // the cluster part is tested, not absent
    EXPECT_LT(vertex_rms, 2.0 * solve_rms);
    EXPECT_LT(vertex_worst, 2.0 * solve_worst);
    EXPECT_LT(centre_rms, 1.5 * solve_rms);
}

namespace {

// A unit square lamp [0,1]^2 high over a plane (z = kLampZ, E = (3, 2, 1), facing down, black),
// and a black square blocker [0.2, 1.2] x [-0.5, 1.5] low over it (z = kBlockerZ, facing up):
// the plane z = 0 ([-2,3]^2, rho 0.5) gets a sharp shadow whose penumbra is 0.14 wide, and far
// from the lamp the unoccluded factor hardly varies across an element. Lamp and blocker are
// axis-aligned in parallel planes, so from a point x of the plane the blocker hides the
// rectangle of the lamp its central projection covers, and the light at x is exactly
// 0.5 E (F(x -> lamp) - F(x -> lamp within that rectangle)).
constexpr double kLampZ = 4.0, kBlockerZ = 0.5, kBx0 = 0.2, kBx1 = 1.2, kBy0 = -0.5, kBy1 = 1.5;
const std::vector<glm::dvec3> kLamp{{0, 0, kLampZ}, {0, 1, kLampZ}, {1, 1, kLampZ}, {1, 0, kLampZ}};

Scene lamp_blocker_plane() {
    Scene s = lamp_over_plane();
    s.surfaces[1].vertices = kLamp;
    s.surfaces.push_back(
        {{{kBx0, kBy0, kBlockerZ}, {kBx1, kBy0, kBlockerZ}, {kBx1, kBy1, kBlockerZ}, {kBx0, kBy1, kBlockerZ}},
         2,
         "blocker",
         {"test", 0}});
    return s;
}

// F from (x, y, 0), facing up, to the lamp's unhidden part (to all of it with `hidden` false).
double visible_lamp_factor(double x, double y, bool hidden = true) {
    const glm::dvec3 p(x, y, 0), up(0, 0, 1);
    double F = point_polygon_form_factor(p, up, kLamp);
    // The blocker's rectangle projected from p onto the lamp's plane, clipped to the lamp.
    const double s = kLampZ / kBlockerZ;
    const double x0 = std::max(0.0, x + (kBx0 - x) * s), x1 = std::min(1.0, x + (kBx1 - x) * s);
    const double y0 = std::max(0.0, y + (kBy0 - y) * s), y1 = std::min(1.0, y + (kBy1 - y) * s);
    if (hidden && x0 < x1 && y0 < y1) {
        const std::vector<glm::dvec3> rect{{x0, y0, kLampZ}, {x0, y1, kLampZ}, {x1, y1, kLampZ}, {x1, y0, kLampZ}};
        F -= point_polygon_form_factor(p, up, rect);
    }
    return F;
}

}  // namespace

// The blocker's penumbra crosses the plane's coarse elements. A link to the lamp gives an
// element one visible fraction, and the unoccluded factor varies little across it, so without
// HierarchicalOptions::refine_partial_visibility the elements stay coarse across the shadow's
// edge and the point data, linear between their vertices, blurs it. Scored at points in the
// penumbra against the exact light of the lamp's visible part.
TEST(HierarchicalPointValues, PartlyVisibleLinksRefineThePenumbra) {
    const Scene s = lamp_blocker_plane();
    MeshingOptions o;
    o.subdivide = false;
    const PatchMesh m(s, o);
    const auto vis = make_visibility("embree", m.patches());
    // Probes on a 0.01 grid of the plane where 5-95% of the lamp is hidden.
    std::vector<ReferencePoint> probes;
    for (double x = -1.995; x < 3; x += 0.01)
        for (double y = -1.995; y < 3; y += 0.01) {
            const double F = visible_lamp_factor(x, y), full = visible_lamp_factor(x, y, false);
            if (F < 0.05 * full || F > 0.95 * full) continue;
            ReferencePoint p;
            p.position = {x, y, 0};
            p.normal = {0, 0, 1};
            p.radiosity = Rgb(3, 2, 1) * (0.5 * F);
            p.has_value = true;
            p.status = "converged";
            p.surface = "plane";
            probes.push_back(p);
        }
    ASSERT_GT(probes.size(), 500u);
    auto score = [&](bool refine_partial_visibility) {
        HierarchicalOptions h;
        h.link_epsilon = 0.3;
        h.power_epsilon = 0.0;
        h.max_level = 8;
        h.refine_partial_visibility = refine_partial_visibility;
        const HierarchicalSolution sol = solve_hierarchical(m.patches(), *vis, h);
        const PatchMesh elements = sol.tree.conforming_mesh(sol.leaves);
        const auto element_vis = make_visibility("embree", elements.patches());
        SolveResult res = sol.result;
        EXPECT_EQ(gather_hierarchical_point_values(sol, elements, *element_vis, res, "vertices"),
                  GatherOutcome::gathered);
        const ProbeScore score = score_at_probes(elements, res.radiosity, probes, res.point_radiosity);
        EXPECT_EQ(score.scored, probes.size());
        std::cout << "penumbra, partly visible links " << (refine_partial_visibility ? "refined" : "kept") << ": "
                  << sol.leaves.size() << " elements, point data " << score.rms_smooth << " RMS (" << score.max_smooth
                  << " max), patch values " << score.rms_patch << " at " << score.scored << " probes\n";
        return score;
    };
    const ProbeScore refined = score(true), kept = score(false);
    // Measured 7.4% against 154% (2,340 elements against 189; 5.0% with 6,855 elements after
    // three refinement rounds): refined to the depth limit along the shadow's edge. Without
    // the vertices gathering through the links whose rays were all blocked, 17%. With 4 rays
    // instead of 16 judging the pairs (three rounds), 33%: an element a third in shadow kept
    // all 4 lit one time in five and stayed whole.
    EXPECT_LT(refined.rms_smooth, 0.1);
    EXPECT_LT(refined.rms_smooth, 0.2 * kept.rms_smooth);
}

// Links a shaft test proves unblocked (nothing of the scene between their two ends) are
// gathered without rays, at their whole unoccluded factor. Over a plane lit by a lamp with
// nothing in between, every link is so proved: the gather traces no ray at all and still gives
// Lambert's formula at every vertex. Add a blocker and the links across it trace their rays
// again (the penumbra test above scores what they find).
TEST(HierarchicalPointValues, ShaftTestedLinksAreGatheredWithoutRays) {
    for (const bool blocker : {false, true}) {
        SCOPED_TRACE(blocker ? "with a blocker" : "nothing in between");
        const Scene s = blocker ? lamp_blocker_plane() : lamp_over_plane();
        MeshingOptions o;
        o.subdivide = false;
        const PatchMesh m(s, o);
        const auto vis = make_visibility("embree", m.patches());
        HierarchicalOptions h;
        h.link_epsilon = 0.3;
        h.power_epsilon = 1e-3;  // the leaves' centres are gathered too
        const HierarchicalSolution sol = solve_hierarchical(m.patches(), *vis, h);
        const PatchMesh elements = sol.tree.conforming_mesh(sol.leaves);
        const CountingVisibility counted(make_visibility("embree", elements.patches()));
        SolveResult res = sol.result;
        ASSERT_EQ(gather_hierarchical_point_values(sol, elements, counted, res, "vertices"), GatherOutcome::gathered);
        const auto points = vertex_gather_points(elements);
        if (blocker) {
            // The links across the blocker trace rays, and no vertex is lit through it: the
            // lamp reflects nothing and the blocker is black, so a vertex of the plane gets
            // exactly 0.5 E F(x -> the lamp's unhidden part). Where all of the lamp is in view
            // or none of it, every ray agrees and the gather is exact (a link wrongly marked
            // unblocked would light the umbra); in the penumbra the rays estimate the share.
            EXPECT_GT(counted.segments.load(), points.size());
            std::size_t lit = 0, umbra = 0;
            for (std::size_t v = 0; v < points.size(); ++v) {
                if (points[v].surface != 0) continue;
                const glm::dvec3 x = points[v].position;
                const double F = visible_lamp_factor(x.x, x.y), full = visible_lamp_factor(x.x, x.y, false);
                const double want = 0.5 * 3.0 * F, got = res.point_radiosity[v].r;
                if (F >= full * (1 - 1e-12)) {
                    ASSERT_NEAR(got, want, 5e-4 * want + 1e-12) << "lit vertex " << v;
                    ++lit;
                } else if (F <= 0) {
                    ASSERT_EQ(got, 0.0) << "umbra vertex " << v;
                    ++umbra;
                }
            }
            EXPECT_GT(lit, 20u);
            EXPECT_GT(umbra, 5u);
            continue;
        }
        EXPECT_EQ(counted.segments.load(), 0u);
        std::size_t checked = 0;
        for (std::size_t v = 0; v < points.size(); ++v) {
            if (points[v].surface != 0) continue;
            const double F = point_polygon_form_factor(points[v].position, {0, 0, 1}, s.surfaces[1].vertices);
            for (int c = 0; c < 3; ++c) {
                const double want = 0.5 * Rgb(3, 2, 1)[c] * F;
                ASSERT_NEAR(res.point_radiosity[v][c], want, 5e-4 * want + 1e-12) << "vertex " << v;
            }
            ++checked;
        }
        EXPECT_GT(checked, 50u);
    }
}

// Refinement decides each generation's pairs in parallel, splits in order and writes the links
// and the next pairs in parallel; the gather runs over the points in parallel, each summing its
// own sources in list order. On the Cornell box (coarse patches as solve makes them, power
// epsilon 3e-6, depth 3: element splits, inherited shaft proofs, partial visibility) every
// link, element and point value must be the same on one thread as on two.
TEST(HierarchicalPointValues, SameLinksElementsAndPointDataOnAnyThreadCount) {
    MeshingOptions o;
    o.target_patches = 30;
    const PatchMesh patches(load_scene("cornell"), o);
    const auto vis = make_visibility("embree", patches.patches());
    HierarchicalOptions h;
    h.max_level = 3;
    h.power_epsilon = 3e-6;
    struct Run {
        std::vector<HierarchicalLink> links;
        std::size_t nodes = 0;
        std::vector<Rgb> points;
    };
    std::vector<Run> runs;
    for (const int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        const HierarchicalSolution s = solve_hierarchical(patches.patches(), *vis, h);
        const PatchMesh elements = s.tree.conforming_mesh(s.leaves);
        SolveResult res = s.result;
        ASSERT_EQ(gather_hierarchical_point_values(s, elements, *vis, res, "vertices"), GatherOutcome::gathered);
        runs.push_back({s.links, s.tree.size(), res.point_radiosity});
    }
    std::size_t open = 0;
    for (const auto& l : runs[0].links) open += l.shaft == HierarchicalLink::kShaftOpen;
    std::cout << runs[0].links.size() << " links (" << open << " proved open), " << runs[0].nodes << " nodes, "
              << runs[0].points.size() << " points\n";
    EXPECT_GT(open, 10000u);
    ASSERT_EQ(runs[1].nodes, runs[0].nodes);
    ASSERT_EQ(runs[1].links.size(), runs[0].links.size());
    for (std::size_t k = 0; k < runs[0].links.size(); ++k) {
        const HierarchicalLink &a = runs[0].links[k], &b = runs[1].links[k];
        ASSERT_TRUE(a.a == b.a && a.b == b.b && a.fab == b.fab && a.visible == b.visible && a.shaft == b.shaft)
            << "link " << k;
    }
    ASSERT_EQ(runs[1].points.size(), runs[0].points.size());
    for (std::size_t v = 0; v < runs[0].points.size(); ++v)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(runs[1].points[v][c], runs[0].points[v][c]) << "vertex " << v;
}

// Display refinement against the closed form under a lamp: the plane's point data between
// the vertices (interpolated as score_at_probes and ParaView do) is Lambert's formula at
// every point, and that curves most right under the lamp's edges. The split elements' new
// vertices must gather through their leaf's links to the formula (as every vertex does), the
// old vertices keep their values, the cells their power, and the interpolated field comes
// closer to the formula.
TEST(HierarchicalPointValues, DisplayRefinementInterpolatesLambertsFormulaCloser) {
    const Scene s = lamp_over_plane();
    MeshingOptions o;
    o.subdivide = false;
    const PatchMesh m(s, o);
    const auto vis = make_visibility("embree", m.patches());
    HierarchicalOptions h;
    h.link_epsilon = 0.3;
    h.power_epsilon = 1e-3;
    h.max_level = 5;
    const HierarchicalSolution sol = solve_hierarchical(m.patches(), *vis, h);
    const PatchMesh elements = sol.tree.conforming_mesh(sol.leaves);
    auto lambert = [&](const glm::dvec3& x) {
        return 0.5 * Rgb(3, 2, 1) * point_polygon_form_factor(x, {0, 0, 1}, s.surfaces[1].vertices);
    };
    // Probes on a 40 x 40 grid over the plane, their truth the formula.
    std::vector<ReferencePoint> truth;
    for (int i = 0; i < 40; ++i)
        for (int j = 0; j < 40; ++j) {
            ReferencePoint r;
            r.position = {-2 + 5 * (i + 0.5) / 40, -2 + 5 * (j + 0.5) / 40, 0};
            r.normal = {0, 0, 1};
            r.radiosity = lambert(r.position);
            r.surface = "plane";
            r.status = "converged";
            r.has_value = true;
            truth.push_back(r);
        }
    SolveResult plain = sol.result;
    ASSERT_EQ(gather_hierarchical_point_values(sol, elements, *vis, plain, "vertices"), GatherOutcome::gathered);
    HierarchicalSolution shown = sol;
    PatchMesh cells = elements;
    SolveResult res = sol.result;
    ASSERT_EQ(gather_hierarchical_point_values(shown, cells, *vis, res, "vertices",
                                               DisplayRefinement{kSuggestedDisplayTolerance}),
              GatherOutcome::gathered);
    // The solution's leaves display refinement split (some of them again, across steps).
    std::size_t split = 0;
    for (const auto leaf : sol.leaves)
        split += std::find(shown.leaves.begin(), shown.leaves.end(), leaf) == shown.leaves.end() ? 1 : 0;
    ASSERT_GT(split, 0u);
    ASSERT_LT(split, sol.leaves.size());
    ASSERT_EQ(cells.size(), shown.leaves.size());
    ASSERT_EQ(res.radiosity.size(), shown.leaves.size());
    ASSERT_EQ(shown.result.radiosity.size(), shown.leaves.size());  // the solution's own result follows
    ASSERT_EQ(shown.node_radiosity.size(), shown.tree.size());
    // An old vertex keeps its value (gathered where it lay among the old cells); every new
    // one of the plane gets the formula through its leaf's links, as every vertex does.
    const auto points = vertex_gather_points(cells);
    ASSERT_EQ(res.point_radiosity.size(), points.size());
    const auto old_points = vertex_gather_points(elements);
    std::size_t kept = 0, added = 0;
    for (std::size_t w = 0; w < points.size(); ++w) {
        const auto r = cells.mesh().point(OpenMesh::VertexHandle(int(w)));
        bool old = false;
        for (std::size_t v = 0; v < old_points.size() && !old; ++v) {
            const auto q = elements.mesh().point(OpenMesh::VertexHandle(int(v)));
            if ((q - r).norm() > 1e-12 || points[w].surface != old_points[v].surface) continue;
            EXPECT_EQ(res.point_radiosity[w].luminance(), plain.point_radiosity[v].luminance()) << "vertex " << w;
            old = true;
        }
        kept += old ? 1 : 0;
        if (old || points[w].surface != 0) continue;
        const Rgb want = lambert(points[w].position);
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(res.point_radiosity[w][c], want[c], 5e-4 * want[c] + 1e-12) << "vertex " << w;
        ++added;
    }
    EXPECT_EQ(kept, old_points.size());
    EXPECT_GT(added, 3 * split / 2);
    // The cells tile the leaves with their values: the same power.
    double before = 0.0, after = 0.0;
    for (std::size_t k = 0; k < elements.size(); ++k)
        before += elements.patches()[k].area * sol.result.radiosity[k].luminance();
    for (std::size_t k = 0; k < cells.size(); ++k) after += cells.patches()[k].area * res.radiosity[k].luminance();
    EXPECT_NEAR(after, before, 1e-12 * before);
    const ProbeScore coarse = score_at_probes(elements, sol.result.radiosity, truth, plain.point_radiosity);
    const ProbeScore fine = score_at_probes(cells, res.radiosity, truth, res.point_radiosity);
    std::cout << "display refinement under a lamp: " << split << " of " << sol.leaves.size()
              << " elements split; interpolated point data " << coarse.rms_smooth << " RMS (" << coarse.max_smooth
              << " max) off Lambert's formula -> " << fine.rms_smooth << " (" << fine.max_smooth << ")\n";
    EXPECT_EQ(fine.scored, truth.size());
    EXPECT_LE(fine.rms_smooth, 0.7 * coarse.rms_smooth);
    EXPECT_LE(fine.max_smooth, coarse.max_smooth);
}
