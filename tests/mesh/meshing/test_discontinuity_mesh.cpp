// SPDX-License-Identifier: MIT
// Discontinuity meshing: the traced umbra and penumbra boundaries of a square light over a square
// blocker lie where similar triangles put them, the constrained triangulation contains them, the
// Cornell box meshed this way has no T-vertices or cracks and emits what it emitted, and
// degenerate input is handled without a crash or a crack.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include <glm/geometric.hpp>

#include "mesh/geometry/contact_cuts.h"
#include "mesh/geometry/geometry_check.h"
#include "mesh/meshing/discontinuity_mesh.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/polygon.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

// A square light (half side a, height H, facing down) above a square blocker (half side b,
// height h) above the plane z = 0 (half side 4, facing up), all centred on the z axis.
constexpr double kA = 0.5, kB = 1.0, kH = 3.0, kh = 1.0;

Scene light_blocker_plane(double h = kh, double b = kB) {
    Scene s;
    s.name = "light over blocker over plane";
    s.materials = {{"white", Rgb::gray(0.5), Rgb()}, {"lamp", Rgb(), Rgb::gray(10.0)}};
    s.surfaces.push_back({{{-4, -4, 0}, {4, -4, 0}, {4, 4, 0}, {-4, 4, 0}}, 0, "plane", {"test", 0}});
    s.surfaces.push_back({{{-b, -b, h}, {b, -b, h}, {b, b, h}, {-b, b, h}}, 0, "blocker", {"test", 0}});
    s.surfaces.push_back({{{-kA, -kA, kH}, {-kA, kA, kH}, {kA, kA, kH}, {kA, -kA, kH}}, 1, "lamp", {"test", 0}});
    return s;
}

// Similar triangles: the ray from the light's edge at x = +a (resp. -a) through the blocker's
// edge at x = b meets the plane at x = b + (b - a) h / (H - h) (resp. b + (b + a) h / (H - h)):
// the umbra's edge (every ray to the light blocked beyond it) and the penumbra's outer edge.
const double kUmbra = kB + (kB - kA) * kh / (kH - kh);     // 1.25
const double kPenumbra = kB + (kB + kA) * kh / (kH - kh);  // 1.75

/// The union of intervals, merged where they touch within tol.
std::vector<std::pair<double, double>> merged(std::vector<std::pair<double, double>> v, double tol) {
    std::sort(v.begin(), v.end());
    std::vector<std::pair<double, double>> out;
    for (const auto& [a, b] : v) {
        if (!out.empty() && a <= out.back().second + tol)
            out.back().second = std::max(out.back().second, b);
        else
            out.emplace_back(a, b);
    }
    return out;
}

/// Which of the 8 analytic lines (axis 0: x = c, axis 1: y = c) a segment lies on, or -1.
int analytic_line(const V& a, const V& b, double tol) {
    const double lines[4] = {-kPenumbra, -kUmbra, kUmbra, kPenumbra};
    for (int axis = 0; axis < 2; ++axis)
        for (int k = 0; k < 4; ++k)
            if (std::abs(a[axis] - lines[k]) <= tol && std::abs(b[axis] - lines[k]) <= tol) return axis * 4 + k;
    return -1;
}

/// The union of [along-line extent] of segments on each analytic line.
std::map<int, std::vector<std::pair<double, double>>> cover(const std::vector<std::pair<V, V>>& segments, double tol) {
    std::map<int, std::vector<std::pair<double, double>>> on;
    for (const auto& [a, b] : segments) {
        const int line = analytic_line(a, b, tol);
        if (line < 0) continue;
        const int along = line < 4 ? 1 : 0;
        on[line].emplace_back(std::min(a[along], b[along]), std::max(a[along], b[along]));
    }
    for (auto& [line, v] : on) v = merged(v, tol);
    return on;
}

/// Open edges, vertices on other faces' open edges (T-vertices), per surface, of a patch mesh.
struct Conformity {
    std::size_t t_vertices = 0;
    double boundary_length = 0;
};

Conformity conformity(const PatchMesh& m, int surface) {
    Conformity c;
    const auto& om = m.mesh();
    std::vector<std::pair<V, V>> edges;
    std::vector<V> points;
    for (std::size_t i = 0; i < m.size(); ++i) {
        const Patch& p = m.patches()[i];
        if (p.surface != surface) continue;
        for (int k = 0; k < p.vertex_count; ++k) {
            edges.emplace_back(p.vertices[k], p.vertices[(k + 1) % p.vertex_count]);
            points.push_back(p.vertices[k]);
        }
        const auto f = om.face_handle(int(i));
        for (auto h = om.cfh_iter(f); h.is_valid(); ++h)
            if (om.is_boundary(om.opposite_halfedge_handle(*h))) c.boundary_length += om.calc_edge_length(*h);
    }
    std::sort(points.begin(), points.end(),
              [](const V& x, const V& y) { return std::tie(x.x, x.y, x.z) < std::tie(y.x, y.y, y.z); });
    points.erase(std::unique(points.begin(), points.end()), points.end());
    for (const V& q : points)
        for (const auto& [a, b] : edges) {
            const V d = b - a;
            const double len = glm::length(d);
            const double t = glm::dot(q - a, d) / (len * len);
            if (t <= 1e-9 || t >= 1 - 1e-9) continue;
            if (glm::length(a + t * d - q) <= 1e-9 * len) ++c.t_vertices;
        }
    return c;
}

/// Exported vertices lying on the open edge of a patch of another surface within a degree of
/// its own (the seams a T-vertex would show on; at creases each surface has its own vertices,
/// in the uniform mesh too).
std::size_t seam_t_vertices(const PatchMesh& m) {
    std::size_t count = 0;
    const auto& P = m.patches();
    for (std::size_t i = 0; i < P.size(); ++i)
        for (std::size_t j = 0; j < P.size(); ++j) {
            if (P[i].surface == P[j].surface || glm::dot(P[i].normal, P[j].normal) < std::cos(0.02)) continue;
            for (int e = 0; e < P[j].vertex_count; ++e) {
                const V a = P[j].vertices[e], d = P[j].vertices[(e + 1) % P[j].vertex_count] - a;
                const double len = glm::length(d);
                for (int k = 0; k < P[i].vertex_count; ++k) {
                    const V q = P[i].vertices[k];
                    const double t = glm::dot(q - a, d) / (len * len);
                    if (t > 1e-9 && t < 1 - 1e-9 && glm::length(a + t * d - q) <= 1e-9 * len) ++count;
                }
            }
        }
    return count;
}

double perimeter(const std::vector<V>& poly) {
    double p = 0;
    for (std::size_t k = 0; k < poly.size(); ++k) p += glm::length(poly[(k + 1) % poly.size()] - poly[k]);
    return p;
}

MeshingOptions discontinuity(double max_area = 0.0) {
    MeshingOptions o;
    o.kind = MeshingOptions::Kind::discontinuity;
    o.max_area = max_area;
    return o;
}

/// Every surface of the mesh: no T-vertex, and the open edges are exactly the surface's outline
/// and its covered regions' outlines (a crack would add open edges on both of its sides).
void expect_conforming(const Scene& s, const PatchMesh& m) {
    for (std::size_t surface = 0; surface < s.surfaces.size(); ++surface) {
        const Conformity c = conformity(m, int(surface));
        EXPECT_EQ(c.t_vertices, 0u) << s.surfaces[surface].object;
        if (c.boundary_length == 0) continue;  // not meshed (degenerate, dropped)
        double outlines = perimeter(s.surfaces[surface].vertices);
        for (const auto& r : s.covered)
            if (r.surface == int(surface)) outlines += perimeter(r.polygon);
        EXPECT_NEAR(c.boundary_length / outlines, 1.0, 1e-9) << s.surfaces[surface].object;
    }
}

}  // namespace

TEST(DiscontinuityMesh, UmbraAndPenumbraBoundariesLieWhereSimilarTrianglesPutThem) {
    const Scene s = light_blocker_plane();
    const TracedDiscontinuities t = trace_discontinuities(s, 100000);
    ASSERT_EQ(t.per_surface.size(), 3u);
    EXPECT_TRUE(t.warnings.empty());
    const auto& on_plane = t.per_surface[0];
    ASSERT_FALSE(on_plane.empty());
    std::vector<std::pair<V, V>> segments;
    bool ev = false, ve = false;
    for (const auto& d : on_plane) {
        // In the plane, and on one of the lines x or y = +-umbra, +-penumbra: with axis-aligned
        // squares every EV and VE trace is such a line (the silhouette test removes nothing
        // here, the blocker being one face).
        EXPECT_NEAR(d.a.z, 0.0, 1e-12);
        EXPECT_NEAR(d.b.z, 0.0, 1e-12);
        EXPECT_GE(analytic_line(d.a, d.b, 1e-9), 0) << d.a.x << "," << d.a.y << " - " << d.b.x << "," << d.b.y;
        EXPECT_EQ(d.emitter, 2);
        EXPECT_EQ(d.occluder, 1);
        ev = ev || d.kind == DiscontinuitySegment::Kind::EV;
        ve = ve || d.kind == DiscontinuitySegment::Kind::VE;
        segments.emplace_back(d.a, d.b);
    }
    EXPECT_TRUE(ev);
    EXPECT_TRUE(ve);
    // Each of the 8 lines is traced over exactly [-penumbra, +penumbra]: the umbra's edge is
    // the part inside |.| <= umbra (a D1 boundary), its continuation through the penumbra and the
    // penumbra's outer edge are the VE/EV traces of the light's corners (Heckbert 1992).
    const auto on = cover(segments, 1e-9);
    ASSERT_EQ(on.size(), 8u);
    for (const auto& [line, v] : on) {
        ASSERT_EQ(v.size(), 1u) << "line " << line;
        EXPECT_NEAR(v[0].first, -kPenumbra, 1e-9) << "line " << line;
        EXPECT_NEAR(v[0].second, kPenumbra, 1e-9) << "line " << line;
    }
    // Nothing is traced onto the blocker (the light is all in front of it) or the light itself.
    EXPECT_TRUE(t.per_surface[1].empty());
    EXPECT_TRUE(t.per_surface[2].empty());
}

TEST(DiscontinuityMesh, BoundariesBehindAThirdObjectAreClippedAway) {
    // A low shelf at z = c over x >= 1.5 hides part of the blocker's shadow boundaries on the
    // plane. The critical lines of the line x = +penumbra all run to the blocker's edge x = 1 at
    // z = 1, crossing z = c at x = 1.75 - 0.75 c = 1.6 (c = 0.2): under the shelf, so that line
    // is gone. Those of x = +umbra cross at 1.25 - 0.25 c = 1.2, beside it: kept whole, as is
    // everything at negative x. On the line y = +penumbra two events overlap near x = 1.5: the
    // corner (1, 1, 1) with the light's edge (EV, lines crossing z = c at x + c (1 - x), hidden
    // beyond x = 1.625) and the edge y = 1 with the light's corner (-a, -a, H) (VE: q =
    // 1.5 e + 0.25 from the edge point e, crossing z = c at q + c (e - q), hidden beyond
    // q = (1.5 + c / 6) / (1 - c / 3) = 1.642857); the union ends at the later one.
    Scene s = light_blocker_plane();
    const double c = 0.2;
    s.surfaces.push_back({{{1.5, -4, c}, {4, -4, c}, {4, 4, c}, {1.5, 4, c}}, 0, "shelf", {"test", 0}});
    const TracedDiscontinuities t = trace_discontinuities(s, 100000);
    std::vector<std::pair<V, V>> from_blocker;
    for (const auto& d : t.per_surface[0])
        if (d.occluder == 1) from_blocker.emplace_back(d.a, d.b);
    const auto on = cover(from_blocker, 1e-9);
    EXPECT_EQ(on.count(3), 0u) << "x = +penumbra lies wholly behind the shelf";
    for (const int line : {0, 1, 2}) {  // x = -penumbra, -umbra, +umbra
        ASSERT_EQ(on.count(line), 1u) << "line " << line;
        ASSERT_EQ(on.at(line).size(), 1u) << "line " << line;
        EXPECT_NEAR(on.at(line)[0].first, -kPenumbra, 1e-9) << "line " << line;
        EXPECT_NEAR(on.at(line)[0].second, kPenumbra, 1e-9) << "line " << line;
    }
    for (const int line : {4, 7}) {  // y = -penumbra, +penumbra: clipped where the corner's lines meet the shelf
        ASSERT_EQ(on.count(line), 1u) << "line " << line;
        EXPECT_NEAR(on.at(line).front().first, -kPenumbra, 1e-9) << "line " << line;
        EXPECT_NEAR(on.at(line).back().second, (1.5 + c / 6) / (1 - c / 3), 1e-6) << "line " << line;
    }
    // Unclipped, the same lines run to +penumbra (the trace without the shelf's shadow test).
    const TracedDiscontinuities bare = trace_discontinuities(light_blocker_plane(), 100000);
    std::vector<std::pair<V, V>> all;
    for (const auto& d : bare.per_surface[0]) all.emplace_back(d.a, d.b);
    EXPECT_NEAR(cover(all, 1e-9).at(7).back().second, kPenumbra, 1e-9);
}

TEST(DiscontinuityMesh, TheConstrainedTriangulationContainsTheBoundaries) {
    const Scene s = light_blocker_plane();
    const TracedDiscontinuities t = trace_discontinuities(s, 100000);
    const double max_area = 0.5;
    const SurfaceTriangulation tri = triangulate_surface(s, 0, t.per_surface[0], max_area);
    ASSERT_FALSE(tri.triangles.empty());
    double area = 0;
    std::vector<std::pair<V, V>> edges;
    for (const auto& f : tri.triangles) {
        const V a = tri.points[f[0]], b = tri.points[f[1]], c = tri.points[f[2]];
        const double signed_area = 0.5 * glm::dot(glm::cross(b - a, c - a), V(0, 0, 1));
        EXPECT_GT(signed_area, 0.0);  // counter-clockwise seen from the front (+z)
        EXPECT_LE(signed_area, max_area * (1 + 1e-9));
        area += signed_area;
        edges.emplace_back(a, b);
        edges.emplace_back(b, c);
        edges.emplace_back(c, a);
    }
    EXPECT_NEAR(area / 64.0, 1.0, 1e-9);
    // Every traced boundary is a union of triangle edges: the edges on each analytic line cover
    // exactly what was traced there.
    const auto on = cover(edges, 1e-9);
    ASSERT_EQ(on.size(), 8u);
    for (const auto& [line, v] : on) {
        ASSERT_EQ(v.size(), 1u) << "line " << line;
        EXPECT_NEAR(v[0].first, -kPenumbra, 1e-9) << "line " << line;
        EXPECT_NEAR(v[0].second, kPenumbra, 1e-9) << "line " << line;
    }
    // The triangulation's corners are the plane's own.
    for (const V& corner : s.surfaces[0].vertices)
        EXPECT_NE(std::find(tri.points.begin(), tri.points.end(), corner), tri.points.end());
}

TEST(DiscontinuityMesh, TheCapKeepsTheLongestAndSaysSoOnce) {
    const Scene s = light_blocker_plane();
    const TracedDiscontinuities all = trace_discontinuities(s, 100000);
    const TracedDiscontinuities capped = trace_discontinuities(s, 5);
    ASSERT_GT(all.per_surface[0].size(), 5u);
    EXPECT_EQ(capped.per_surface[0].size(), 5u);
    ASSERT_EQ(capped.warnings.size(), 1u);
    EXPECT_NE(capped.warnings[0].find("kept the 5 longest"), std::string::npos) << capped.warnings[0];
    double longest_dropped = 0, shortest_kept = 1e300;
    for (const auto& d : capped.per_surface[0]) shortest_kept = std::min(shortest_kept, glm::length(d.b - d.a));
    for (const auto& d : all.per_surface[0]) {
        const double l = glm::length(d.b - d.a);
        if (l > shortest_kept + 1e-12) continue;
        bool kept = false;
        for (const auto& k : capped.per_surface[0]) kept = kept || (k.a == d.a && k.b == d.b);
        if (!kept) longest_dropped = std::max(longest_dropped, l);
    }
    EXPECT_LE(longest_dropped, shortest_kept + 1e-12);
}

TEST(DiscontinuityMesh, ConstraintsAHairApartAreGivenUpNotRefinedWithoutEnd) {
    // Two boundaries 1e-4 apart over 6 units: a sliver needing some 10^5 triangles at any
    // quality bound, far beyond the 64 / 0.5 the area limit asks for.
    const Scene s = light_blocker_plane();
    DiscontinuitySegment a, b;
    a.a = V(0, -3, 0);
    a.b = V(0, 3, 0);
    b.a = V(1e-4, -3, 0);
    b.b = V(1e-4, 3, 0);
    const SurfaceTriangulation t = triangulate_surface(s, 0, {a, b}, 0.5);
    EXPECT_TRUE(t.over_budget);
    EXPECT_TRUE(t.triangles.empty());
}

TEST(DiscontinuityMesh, CornellBoxConformsAndEmitsWhatItEmitted) {
    const Scene s = load_scene("cornell");
    const PatchMesh uniform(s, MeshingOptions{});
    const PatchMesh m(s, discontinuity());
    EXPECT_TRUE(m.warnings().empty());
    // The floor is triangulated (it receives the blocks' shadows), the light keeps its grid.
    std::size_t floor_triangles = 0;
    for (const auto& p : m.patches())
        if (s.surfaces[std::size_t(p.surface)].object == "floor") floor_triangles += p.vertex_count == 3;
    EXPECT_GT(floor_triangles, 100u);
    expect_conforming(s, m);
    // The red wall's two triangles (0.2 degrees apart) share their seam's vertices.
    EXPECT_EQ(seam_t_vertices(uniform), 0u);
    EXPECT_EQ(seam_t_vertices(m), 0u);
    // The energy account: emitted power and total area are those of the uniform mesh.
    const Rgb eu = uniform.emitted_power(), ed = m.emitted_power();
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(ed[c] / eu[c], 1.0, 1e-12);
    EXPECT_NEAR(m.total_area() / uniform.total_area(), 1.0, 1e-9);
    // Every patch obeys the area limit the uniform mesher uses.
    const double max_area = [&] {
        double a = 0;
        for (const auto& surface : s.surfaces) a += polygon_area(surface.vertices);
        return a / double(MeshingOptions{}.target_patches);
    }();
    for (const auto& p : m.patches()) EXPECT_LE(p.area, max_area * (1 + 1e-9)) << p.to_string();
}

TEST(DiscontinuityMesh, AZeroHeightBlockerIsDroppedWithAWarning) {
    // The blocker lies in the plane: its sides have no area and its top overlaps the plane.
    Scene s = light_blocker_plane(0.0);
    const V base[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    for (int k = 0; k < 4; ++k)
        s.surfaces.push_back({{base[k], base[(k + 1) % 4], base[(k + 1) % 4], base[k]}, 0, "side", {"test", 10 + k}});
    check_geometry(s, "test");
    s.covered = find_covered_regions(s);
    EXPECT_EQ(s.warnings.size(), 4u);  // the degenerate sides, named and dropped
    const PatchMesh m(s, discontinuity(0.5));
    // The flat blocker lies on the plane, facing the same way: an overlap in one plane.
    ASSERT_EQ(m.warnings().size(), 1u);
    EXPECT_NE(m.warnings()[0].find("overlap in one plane"), std::string::npos) << m.warnings()[0];
    expect_conforming(s, m);
    EXPECT_NEAR(m.emitted_power().r, 10.0 * 1.0, 1e-9);
}

TEST(DiscontinuityMesh, CoplanarOverlappingFacesAreReportedAndMeshedWithoutCracks) {
    Scene s = light_blocker_plane();
    // A second blocker overlapping the first in its plane.
    s.surfaces.push_back({{{0, 0, kh}, {1.5, 0, kh}, {1.5, 1.5, kh}, {0, 1.5, kh}}, 0, "overlap", {"test", 20}});
    check_geometry(s, "test");
    s.covered = find_covered_regions(s);
    const PatchMesh m(s, discontinuity(0.5));
    ASSERT_EQ(m.warnings().size(), 1u);
    EXPECT_NE(m.warnings()[0].find("test (blocker) and test:20 (overlap) overlap in one plane"), std::string::npos)
        << m.warnings()[0];
    expect_conforming(s, m);
    EXPECT_NEAR(m.emitted_power().r, 10.0, 1e-9);
}

TEST(DiscontinuityMesh, ABlockSunkIntoTheFloorIsCutAtTheFloorWithoutCracks) {
    Scene s = light_blocker_plane(0.5);  // its top at 0.5
    // Sides from z = -0.5 (below the plane) to the top, facing out.
    const double b = kB;
    const V c[4] = {{-b, -b, 0}, {b, -b, 0}, {b, b, 0}, {-b, b, 0}};
    for (int k = 0; k < 4; ++k) {
        const V p = c[k], q = c[(k + 1) % 4];
        s.surfaces.push_back(
            {{p + V(0, 0, -0.5), q + V(0, 0, -0.5), q + V(0, 0, 0.5), p + V(0, 0, 0.5)}, 0, "side", {"test", 30 + k}});
    }
    check_geometry(s, "test");
    s.covered = find_covered_regions(s);
    // The sides cross the plane: reported, and the plane is cut along the footprint.
    ASSERT_FALSE(s.warnings.empty());
    EXPECT_NE(s.warnings[0].find("a self-intersection"), std::string::npos) << s.warnings[0];
    const PatchMesh m(s, discontinuity(0.5));
    expect_conforming(s, m);
    // The plane loses the footprint, and the boundaries traced onto it start at the footprint.
    double plane_area = 0;
    for (const auto& p : m.patches())
        if (p.surface == 0) plane_area += p.area;
    EXPECT_NEAR(plane_area, 64.0 - 4.0 * b * b, 1e-9);
    EXPECT_NEAR(m.emitted_power().r, 10.0, 1e-9);
}
