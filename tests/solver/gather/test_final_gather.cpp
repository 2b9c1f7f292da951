// SPDX-License-Identifier: MIT
// Final gather against known answers: the furnace (sum of exact factors in a closed box is 1,
// no false occlusion at corners), direct light under a lamp (Lambert's formula), and a blocker
// that hides exactly half of the lamp; a hierarchy's near source gathered through its children.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <string>

#include "mesh/meshing/element_tree.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/readers/validation_scenes.h"
#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/gather/final_gather.h"

using namespace bounce;
using V = glm::dvec3;

TEST(FinalGather, FurnaceVerticesGatherExactlyEOverOneMinusRho) {
    const Scene box = closed_box({1.0, 1.5, 2.0}, {"furnace", Rgb::gray(0.5), Rgb::gray(1.0)});
    MeshingOptions o;
    o.target_patches = 200;
    const PatchMesh m(box, o);
    const auto vis = make_visibility("embree", m.patches());
    const std::vector<Rgb> B(m.size(), Rgb::gray(2.0));  // the exact solution
    const auto points = vertex_gather_points(m);
    const auto g = final_gather(m.patches(), B, *vis, points);
    for (std::size_t v = 0; v < g.size(); ++v)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(g[v][c], 2.0, 1e-9) << "vertex " << v;
    const auto centres = final_gather(m.patches(), B, *vis, centre_gather_points(m.patches()));
    for (const auto& b : centres) EXPECT_NEAR(b.g, 2.0, 1e-9);
}

TEST(FinalGather, DirectLightAtEveryVertexIsLambertsFormula) {
    const Scene s = lamp_over_plane();
    MeshingOptions o;
    o.max_edge = 0.25;
    const PatchMesh m(s, o);
    const auto vis = make_visibility("embree", m.patches());
    std::vector<Rgb> B;
    for (const auto& p : m.patches()) B.push_back(p.emission);  // nothing returns to the lamp
    const auto points = vertex_gather_points(m);
    const auto g = final_gather(m.patches(), B, *vis, points);
    std::size_t checked = 0;
    for (std::size_t v = 0; v < points.size(); ++v) {
        if (points[v].surface != 0) continue;
        const double F = point_polygon_form_factor(points[v].position, {0, 0, 1}, s.surfaces[1].vertices);
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(g[v][c], 0.5 * Rgb(3, 2, 1)[c] * F, 1e-12) << "vertex " << v;
        ++checked;
    }
    EXPECT_GT(checked, 300u);
}

TEST(FinalGather, KernelWeightedVisibilityUnderAHalfBlocker) {
    Scene s = lamp_over_plane();
    // Seen from (0.5, 0.5, 0) this black strip at z = 0.5 hides exactly the half x > 0.5 of the lamp.
    s.surfaces.push_back({{{0.5, -1, 0.5}, {1.0, -1, 0.5}, {1.0, 2, 0.5}, {0.5, 2, 0.5}}, 2, "blocker", {"test", 0}});
    MeshingOptions o;
    o.max_edge = 0.125;
    const PatchMesh m(s, o);
    const auto vis = make_visibility("embree", m.patches());
    std::vector<Rgb> B;
    for (const auto& p : m.patches()) B.push_back(p.emission);
    const GatherPoint x{{0.5, 0.5, 0}, {0, 0, 1}, 0, Rgb::gray(0.5), Rgb()};
    const auto g = final_gather(m.patches(), B, *vis, std::vector<GatherPoint>{x});
    const std::vector<V> visible = {{0, 0, 1}, {0, 1, 1}, {0.5, 1, 1}, {0.5, 0, 1}};
    const double exact = 0.5 * 2.0 * point_polygon_form_factor(x.position, x.normal, visible);
    // Lamp patches straddle the shadow line only at its edge x = 0.5, where the kernel-weighted
    // rays split them; the rest are wholly seen or wholly hidden.
    EXPECT_NEAR(g[0].g / exact, 1.0, 0.01);
}

// kernel_tolerance: far patches by the Gauss rule of the point-to-point kernel instead of
// Lambert's formula. With the same seed the rays are the same, so every vertex of the Cornell
// box (all its pairs: near, far, straddling the horizon) must stay within the tolerance of the
// exact gather, and the rule must actually be taken.
TEST(FinalGather, GaussRuleForFarPatchesWithinItsTolerance) {
    const Scene scene = load_scene("cornell");
    MeshingOptions o;
    o.target_patches = 500;
    const PatchMesh m(scene, o);
    const auto vis = make_visibility("embree", m.patches());
    std::vector<Rgb> B;
    for (std::size_t j = 0; j < m.size(); ++j) B.push_back(m.patches()[j].emission + Rgb(1, 2, 3) * double(1 + j % 7));
    const auto points = vertex_gather_points(m);
    const auto exact = final_gather(m.patches(), B, *vis, points);
    GatherOptions fast;
    fast.kernel_tolerance = 1e-4;
    const auto g = final_gather(m.patches(), B, *vis, points, fast);
    double worst = 0.0;
    for (std::size_t v = 0; v < g.size(); ++v)
        for (int c = 0; c < 3; ++c) {
            const double reflected = exact[v][c] - points[v].emission[c];  // the gathered part
            if (reflected > 0) worst = std::max(worst, std::abs(g[v][c] - exact[v][c]) / reflected);
        }
    std::cout << "largest relative change of a vertex's gathered light: " << worst << "\n";
    EXPECT_LE(worst, 1e-4);
    EXPECT_GT(worst, 1e-9);  // the rule was used
}

// The furnace with the rule: every factor within 1e-4 of Lambert's, so within 1e-4 of E/(1-rho).
TEST(FinalGather, FurnaceWithTheGaussRuleWithinItsTolerance) {
    const Scene box = closed_box({1.0, 1.5, 2.0}, {"furnace", Rgb::gray(0.5), Rgb::gray(1.0)});
    MeshingOptions o;
    o.target_patches = 200;
    const PatchMesh m(box, o);
    const auto vis = make_visibility("embree", m.patches());
    const std::vector<Rgb> B(m.size(), Rgb::gray(2.0));
    GatherOptions fast;
    fast.kernel_tolerance = 1e-4;
    const auto g = final_gather(m.patches(), B, *vis, vertex_gather_points(m), fast);
    double worst = 0.0;
    for (const Rgb& b : g) worst = std::max(worst, std::abs(b.g - 2.0));
    std::cout << "furnace: largest |B - 2| " << worst << "\n";
    EXPECT_LE(worst, 2.0 * 1e-4);
}

// The box's ceiling meshed whole (one patch per piece, as the hierarchical solver's coarse
// patches are) has long triangles fanned from the lamp hole's corners, where the ceiling fills
// three quarters of a turn. Every vertex's gather point must stay on its surface, within one
// of its own cells (the mean of the cells' centres was over the lamp there), and the hole's
// corners, lit by the same room as the ceiling beside them, must gather alike: the lamp's back
// 0.1 below the ceiling shades only a layer of that width, not the corner's cells.
TEST(FinalGather, VerticesAtTheLampHolesCornersStayOnTheCeiling) {
    const Scene scene = load_scene("cornell");
    for (const std::size_t target : {0, 30, 60}) {
        SCOPED_TRACE("target patches " + std::to_string(target));
        MeshingOptions o;
        o.subdivide = target > 0;
        o.target_patches = target;
        const PatchMesh m(scene, o);
        const auto vis = make_visibility("embree", m.patches());
        const auto points = vertex_gather_points(m);
        auto within = [](const Patch& p, const V& x) {
            for (int k = 0; k < p.vertex_count; ++k) {
                const V u = p.vertices[k], w = p.vertices[(k + 1) % p.vertex_count];
                if (glm::dot(glm::cross(w - u, x - u), p.normal) < -1e-9 * p.area) return false;
            }
            return std::abs(p.height(x)) < 1e-9 * std::sqrt(p.area);
        };
        std::vector<char> on_a_cell(points.size(), 0);
        for (std::size_t i = 0; i < m.size(); ++i)
            for (const int v : m.patch_vertex_indices(i))
                if (within(m.patches()[i], points[std::size_t(v)].position)) on_a_cell[std::size_t(v)] = 1;
        std::vector<char> used(points.size(), 0);  // a vertex no cell uses (under a block) gathers nothing
        for (std::size_t i = 0; i < m.size(); ++i)
            for (const int v : m.patch_vertex_indices(i)) used[std::size_t(v)] = 1;
        for (std::size_t v = 0; v < points.size(); ++v) ASSERT_TRUE(on_a_cell[v] || !used[v]) << "vertex " << v;

        // Every surface alike: only what each point sees counts. Each corner of the hole against
        // a point of the ceiling 20 mm out from it diagonally, beyond the lamp's shade.
        std::vector<Rgb> B(m.size(), Rgb::gray(1.0));
        std::vector<GatherPoint> at;
        const auto& om = m.mesh();
        for (std::size_t v = 0; v < points.size(); ++v) {
            const auto q = om.point(OpenMesh::VertexHandle(int(v)));
            const bool corner = std::abs(q[1] - 548.8) < 1e-6 && used[v] && points[v].emission.max() == 0 &&
                                (std::abs(q[0] - 213) < 1e-6 || std::abs(q[0] - 343) < 1e-6) &&
                                (std::abs(q[2] - 227) < 1e-6 || std::abs(q[2] - 332) < 1e-6);
            if (!corner) continue;
            at.push_back(points[v]);
            GatherPoint out = points[v];
            out.position = V(q[0] + (q[0] > 278 ? 20 : -20), q[1], q[2] + (q[2] > 279.5 ? 20 : -20));
            at.push_back(out);
        }
        ASSERT_EQ(at.size(), 8u);
        const auto g = final_gather(m.patches(), B, *vis, at);
        for (std::size_t k = 0; k < at.size(); k += 2) {
            std::cout << "corner " << at[k].position.x << ", " << at[k].position.z << ": " << g[k].g << " against "
                      << g[k + 1].g << " 20 mm out\n";
            EXPECT_NEAR(g[k].g / g[k + 1].g, 1.0, 0.1) << "corner " << k / 2;
        }
    }
}

// A listed source whose children differ (one quarter lit, and in it one sixteenth) is gathered
// through them, down to the level where min(1, r / d) spread no longer passes `descend` times a
// node's luminance: near it, the exact factor to the lit part instead of the factor to the
// whole times the mean; far from it, or with descend 0, the whole at its mean.
TEST(FinalGather, NearSourceWhoseChildrenDifferIsGatheredThroughTheChildren) {
    Scene s = lamp_over_plane();  // the plane (rho 0.5) under a unit square at z = 1
    s.materials[1].emission = Rgb();
    MeshingOptions o;
    o.subdivide = false;
    const PatchMesh m(s, o);
    ElementTree tree(m.patches());
    const std::size_t quarter = tree.split(1);          // the square's quarters
    const std::size_t sixteenth = tree.split(quarter);  // the first quarter's quarters
    const auto& nodes = tree.geometry();
    std::vector<Rgb> B(nodes.size(), Rgb());  // a parent holds its children's mean
    B[sixteenth] = Rgb::gray(16.0);
    B[quarter] = Rgb::gray(4.0);
    B[1] = Rgb::gray(1.0);
    std::vector<std::int32_t> first_child(nodes.size(), -1);
    first_child[1] = std::int32_t(quarter);
    first_child[quarter] = std::int32_t(sixteenth);
    std::vector<double> spread(nodes.size(), 0.0);  // max - min over the leaves below
    spread[1] = spread[quarter] = 16.0;
    const auto vis = make_visibility("embree", nodes);
    const std::vector<glm::dvec3> at{{0.25, 0.25, 0}, {-0.5, -0.5, 0}, {1.5, 0.25, 0}, {2.9, 2.9, 0}};
    std::vector<GatherPoint> points;
    for (const glm::dvec3& x : at) points.push_back({x, {0, 0, 1}, 0, Rgb::gray(0.5), Rgb()});
    const std::vector<std::uint32_t> list(points.size(), 0), patches{1};
    const std::vector<std::size_t> offsets{0, 1};
    GatherSources sources{list, offsets, patches, {}};
    sources.first_child = first_child;
    sources.spread = spread;
    auto gathered = [&](double descend) {
        sources.descend = descend;
        return final_gather(nodes, B, *vis, points, sources);
    };
    auto from = [&](std::size_t node, std::size_t i) {
        return 0.5 * B[node].g * point_polygon_form_factor(at[i], {0, 0, 1}, nodes[node].polygon());
    };
    const auto down = gathered(0.1), part = gathered(4.0), whole = gathered(0.0);
    for (std::size_t i = 0; i < at.size(); ++i)
        std::cout << "(" << at[i].x << ", " << at[i].y << "): descend 0.1 " << down[i].g << ", 4 " << part[i].g
                  << ", 0 " << whole[i].g << "; the lit sixteenth " << from(sixteenth, i) << ", quarter "
                  << from(quarter, i) << ", whole " << from(1, i) << "\n";
    for (std::size_t i = 0; i < 3; ++i) {  // near: min(1, r / d) 16 > 0.1 at both levels
        EXPECT_NEAR(down[i].g, from(sixteenth, i), 1e-9 * from(sixteenth, i));
        EXPECT_GT(std::abs(whole[i].g / down[i].g - 1), 0.1);  // the mean is not the answer here
    }
    // descend 4: near the square its quarters (at (-0.5, -0.5), 0.41 x 16 > 4 x 1), not the
    // lit quarter's (0.24 x 16 < 4 x 4); far away (0.2 x 16 < 4 x 1) the whole square.
    EXPECT_NEAR(part[1].g, from(quarter, 1), 1e-9 * from(quarter, 1));
    EXPECT_GT(std::abs(part[1].g / down[1].g - 1), 0.1);
    EXPECT_NEAR(part[3].g, from(1, 3), 1e-9 * from(1, 3));
    for (std::size_t i = 0; i < at.size(); ++i) EXPECT_NEAR(whole[i].g, from(1, i), 1e-9 * from(1, i));
}

// A hierarchy's points gather over the links of their element and of every ancestor: chained
// lists (GatherSources::list_parent) must give what one flat list per point, the rows laid one
// after another, gives, to the bit (the same sources in the same order, the same rays), with
// each list's irradiance and each entry's shaft mark, and with sources gone down to. Under a
// lamp cut into a tree, with a blocker between, so rays and their streams count.
TEST(FinalGather, ChainedListsGatherAsTheirRowsLaidEndToEnd) {
    Scene s = lamp_over_plane();  // the plane (rho 0.5) under a unit square lamp at z = 1
    s.surfaces.push_back(
        {{{0.2, -0.5, 0.5}, {1.2, -0.5, 0.5}, {1.2, 1.5, 0.5}, {0.2, 1.5, 0.5}}, 2, "blocker", {"test", 0}});
    MeshingOptions o;
    o.subdivide = false;
    const PatchMesh m(s, o);
    ElementTree tree(m.patches());
    // Lists are nodes: the lamp's and blocker's roots, and children that hold rows of their own.
    std::size_t lamp = 0, plane = 0;
    for (std::size_t r = 0; r < m.size(); ++r) {
        if (m.patches()[r].emission.max() > 0) lamp = r;
        if (m.patches()[r].area > m.patches()[plane].area) plane = r;
    }
    const std::size_t quarter = tree.split(plane), sixteenth = tree.split(quarter + 3);
    const std::size_t lamp_quarter = tree.split(lamp);
    const auto& nodes = tree.geometry();
    std::vector<Rgb> B(nodes.size(), Rgb::gray(0.3));
    for (std::size_t c = 0; c < 4; ++c) B[lamp_quarter + c] = Rgb::gray(1.0 + double(c));
    // Rows: the plane's root sees the lamp whole, the quarter 3 sees two lamp quarters, its
    // sixteenths the other two and the blocker.
    std::vector<std::vector<std::uint32_t>> rows(nodes.size());
    rows[plane] = {std::uint32_t(lamp)};
    rows[quarter + 3] = {std::uint32_t(lamp_quarter), std::uint32_t(lamp_quarter + 1)};
    for (std::size_t c = 0; c < 4; ++c) {
        rows[sixteenth + c] = {std::uint32_t(lamp_quarter + 2), std::uint32_t(lamp_quarter + 3)};
        for (std::size_t r = 0; r < m.size(); ++r)
            if (r != plane && r != lamp) rows[sixteenth + c].push_back(std::uint32_t(r));
    }
    std::vector<std::size_t> offsets{0};
    std::vector<std::uint32_t> entries;
    std::vector<std::int64_t> parent(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        entries.insert(entries.end(), rows[i].begin(), rows[i].end());
        offsets.push_back(entries.size());
        parent[i] = tree.node(i).parent;
    }
    // Points on the sixteenths and on the other quarters, each on its own leaf.
    std::vector<GatherPoint> points;
    std::vector<std::uint32_t> leaf;
    for (const std::size_t first : {sixteenth, quarter})
        for (std::size_t c = 0; c < 4; ++c) {
            const std::size_t node = first + c;
            if (!tree.node(node).leaf()) continue;
            for (const double t : {0.25, 0.5, 0.75}) {
                const Patch& p = nodes[node];
                points.push_back(
                    {p.centre + t * (p.vertices[0] - p.centre), p.normal, p.surface, Rgb::gray(0.5), Rgb()});
                leaf.push_back(std::uint32_t(node));
            }
        }
    ASSERT_EQ(points.size(), 21u);
    const auto vis = make_visibility("embree", m.patches());
    // Irradiance on the leaves' lists only, a shaft mark on every other entry, and (second
    // pass) a source gone down to: the lamp's root, whose quarters differ.
    std::vector<Rgb> node_irradiance(nodes.size());
    for (const std::uint32_t l : leaf) node_irradiance[l] = Rgb::gray(0.01 * double(l));
    std::vector<std::uint8_t> marks(entries.size());
    for (std::size_t e = 0; e < marks.size(); e += 2) marks[e] = 1;
    std::vector<std::int32_t> first_child(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) first_child[i] = tree.node(i).first_child;
    B[lamp] = Rgb::gray(2.5);  // its quarters' mean
    const std::vector<double> spread = tree.leaf_luminance_spread(B);
    GatherSources chained{leaf, offsets, entries, node_irradiance};
    chained.list_parent = parent;
    chained.unblocked = marks;
    chained.first_child = first_child;
    chained.spread = spread;
    // The same sources laid out flat, a list per point, each entry with its row's mark.
    std::vector<std::size_t> flat_offsets{0};
    std::vector<std::uint32_t> flat, own;
    std::vector<std::uint8_t> flat_marks;
    std::vector<Rgb> flat_irradiance;
    for (std::size_t k = 0; k < points.size(); ++k) {
        for (std::int64_t a = leaf[k]; a >= 0; a = parent[std::size_t(a)])
            for (std::size_t e = offsets[std::size_t(a)]; e < offsets[std::size_t(a) + 1]; ++e) {
                flat.push_back(entries[e]);
                flat_marks.push_back(marks[e]);
            }
        flat_offsets.push_back(flat.size());
        flat_irradiance.push_back(node_irradiance[leaf[k]]);
        own.push_back(std::uint32_t(k));
    }
    GatherSources listed{own, flat_offsets, flat, flat_irradiance};
    listed.unblocked = flat_marks;
    listed.first_child = first_child;
    listed.spread = spread;
    for (const double descend : {0.0, 0.1}) {
        chained.descend = listed.descend = descend;
        const std::vector<Rgb> by_chain = final_gather(nodes, B, *vis, points, chained);
        const std::vector<Rgb> by_list = final_gather(nodes, B, *vis, points, listed);
        std::size_t lit = 0;
        bool differ = false;
        for (std::size_t k = 0; k < points.size(); ++k) {
            EXPECT_EQ(by_chain[k].g, by_list[k].g) << "point " << k << ", descend " << descend;
            lit += by_chain[k].g > 0.5 * 0.01 * double(leaf[k]);  // more than its irradiance
            differ |= by_chain[k].g != by_chain[k - k % 3].g;
        }
        EXPECT_GE(lit, 15u);  // all but one leaf lit (one lies in the blocker's umbra)
        EXPECT_TRUE(differ);  // the points of a leaf differ: the sums are not trivially alike
    }
    // A parent list for every list, or none.
    chained.list_parent = std::span<const std::int64_t>(parent).first(parent.size() - 1);
    EXPECT_THROW(final_gather(nodes, B, *vis, points, chained), std::invalid_argument);
}

TEST(FinalGather, ANearSourceSendsItsShapeWithoutSamplingNoise) {
    // A unit square 0.1 above x, its corners' values rising from 1 to 4 across it (mean 2.5):
    // x gathers the kernel-weighted mean of that ramp, which the patch's 16 jittered samples of
    // a kernel this peaked would estimate to a few percent. Wholly visible, the shape is
    // integrated by Lambert's formula on cells, so every seed gives the same value, within
    // 2e-3 of a 200 x 200 cell integration of the ramp.
    const double h = 0.1;
    for (const int corners : {4, 3}) {
        Patch p;
        p.vertex_count = corners;
        p.vertices = {V{0, 0, h}, V{0, 1, h}, V{1, 1, h}, V{1, 0, h}};  // counter-clockwise seen from below
        if (corners == 3) p.vertices[3] = V{0.0};
        p.normal = {0, 0, -1};
        p.area = corners == 4 ? 1.0 : 0.5;
        p.centre = corners == 4 ? V{0.5, 0.5, h} : V{1.0 / 3, 2.0 / 3, h};
        p.reflectance = Rgb::gray(0.5);
        p.surface = 1;
        std::vector<Rgb> corner_values(4);
        for (int k = 0; k < corners; ++k) corner_values[std::size_t(k)] = Rgb::gray(1.0 + 3.0 * p.vertices[k].x);
        Rgb mean;
        for (int k = 0; k < corners; ++k) mean += corner_values[std::size_t(k)] * (1.0 / corners);
        const std::vector<Patch> patches = {p};
        const std::vector<Rgb> B = {mean};
        const auto vis = make_visibility("embree", patches);
        const GatherPoint x{{0.2, 0.3, 0}, {0, 0, 1}, 0, Rgb::gray(1.0), Rgb()};
        // The ramp integrated on fine cells (the triangle: the cells' parts left of x = y).
        double exact = 0.0;
        const int n = 200;
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
                const double x0 = double(a) / n, y0 = double(b) / n, s = 1.0 / n;
                if (corners == 3 && x0 + s > y0 + 1e-12) {
                    if (a != b) continue;  // below the diagonal; its own cells: their upper halves
                    const std::vector<V> half = {{x0, y0, h}, {x0, y0 + s, h}, {x0 + s, y0 + s, h}};
                    exact += point_polygon_form_factor(x.position, x.normal, half) * (1 + 3 * (x0 + s / 3));
                    continue;
                }
                const std::vector<V> cell = {{x0, y0, h}, {x0, y0 + s, h}, {x0 + s, y0 + s, h}, {x0 + s, y0, h}};
                exact += point_polygon_form_factor(x.position, x.normal, cell) * (1 + 3 * (x0 + s / 2));
            }
        double lo = 1e300, hi = 0;
        for (std::uint64_t seed = 1; seed <= 8; ++seed) {
            GatherOptions o;
            o.seed = seed;
            o.source_corners = corner_values;
            const double g = final_gather(patches, B, *vis, std::vector<GatherPoint>{x}, o)[0].g;
            lo = std::min(lo, g);
            hi = std::max(hi, g);
        }
        std::printf("%d corners: gathered %.6f to %.6f over 8 seeds, cells %.6f\n", corners, lo, hi, exact);
        EXPECT_LT(hi / lo - 1, 1e-12);
        EXPECT_NEAR(lo / exact, 1.0, 2e-3);
    }
}
