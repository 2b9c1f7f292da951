// SPDX-License-Identifier: MIT
#include "mesh/geometry/contact_cuts.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "mesh/geometry/solid_cuts.h"
#include "mesh/geometry/surface_rays.h"
#include "mesh/geometry/surface_tree.h"
#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

using V = glm::dvec3;
/// The part of convex `poly` on the side of the line through `a` (in the plane) where
/// dot(m, x - a) * side >= 0. Vertices within `eps` of the line belong to both sides. Crossing
/// points are computed from the edge's endpoints in a fixed (lexicographic) order, so the two
/// patches that share an edge get bit-identical points.
std::vector<V> clip_half_plane(const std::vector<V>& poly, const V& a, const V& m, double side, double eps) {
    std::vector<V> out;
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
        const V& cur = poly[i];
        const V& nxt = poly[(i + 1) % n];
        const double dc = glm::dot(m, cur - a) * side, dn = glm::dot(m, nxt - a) * side;
        if (dc >= -eps) out.push_back(cur);
        if ((dc > eps && dn < -eps) || (dc < -eps && dn > eps)) {
            const bool swap = std::tie(nxt.x, nxt.y, nxt.z) < std::tie(cur.x, cur.y, cur.z);
            const V& p0 = swap ? nxt : cur;
            const V& p1 = swap ? cur : nxt;
            const double d0 = glm::dot(m, p0 - a), d1 = glm::dot(m, p1 - a);
            out.push_back(p0 + (d0 / (d0 - d1)) * (p1 - p0));
        }
    }
    return out;
}

double area_of(const std::vector<V>& poly) { return poly.size() < 3 ? 0.0 : polygon_area(poly); }

struct SurfaceFrame {
    V normal{0.0}, origin{0.0};
    double area = 0.0;
};

/// Cosine-distributed directions about n on a stratified 8 x 8 grid (Malley's method).
std::vector<V> hemisphere_directions(const V& n, int side = 8) {
    const V t = glm::normalize(std::abs(n.x) < 0.9 ? glm::cross(n, V(1, 0, 0)) : glm::cross(n, V(0, 1, 0)));
    const V b = glm::cross(n, t);
    std::vector<V> out;
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) {
            const double u = (i + 0.5) / side, v = (j + 0.5) / side;
            const double r = std::sqrt(u), phi = 2 * std::numbers::pi * v;
            out.push_back(glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(1 - u) * n));
        }
    return out;
}

}  // namespace

std::vector<std::vector<V>> subtract_convex(const std::vector<V>& poly, const std::vector<V>& hole, const V& normal,
                                            double min_area) {
    double scale = 0.0;
    for (const auto& p : poly) scale = std::max(scale, glm::length(p - poly[0]));
    const double eps = 1e-12 * std::max(scale, 1e-300);
    // Q = P cut by every half-plane of the hole: the part to remove (convex).
    std::vector<V> q = poly;
    for (std::size_t k = 0; k < hole.size() && q.size() >= 3; ++k) {
        const V& a = hole[k];
        const V m = glm::cross(normal, hole[(k + 1) % hole.size()] - a);  // towards the hole's inside
        if (glm::length(m) > 0) q = clip_half_plane(q, a, m, 1.0, eps);
    }
    const double removed = area_of(q), total = area_of(poly);
    if (!(removed > min_area)) return {poly};
    if (total - removed <= min_area) return {};
    // Drop repeated points the clipping may leave.
    std::vector<V> inner;
    for (const V& v : q)
        if (inner.empty() || glm::length(v - inner.back()) > eps) inner.push_back(v);
    while (inner.size() > 1 && glm::length(inner.front() - inner.back()) <= eps) inner.pop_back();

    // The outer cycle: P's corners with Q's points on P's edges inserted in order, so the pieces
    // use no point that is not on P's outline or on the hole's (a neighbour sharing the edge makes
    // the same points, and no T-vertex appears).
    const double on_edge = 1e-9 * scale;
    std::vector<V> outer;
    for (std::size_t k = 0; k < poly.size(); ++k) {
        const V& a = poly[k];
        const V& b = poly[(k + 1) % poly.size()];
        outer.push_back(a);
        std::vector<std::pair<double, V>> on;
        const V ab = b - a;
        const double len2 = glm::dot(ab, ab);
        for (const V& v : inner) {
            const double t = glm::dot(v - a, ab) / len2;
            if (t <= 1e-12 || t >= 1 - 1e-12) continue;
            if (glm::length(a + t * ab - v) <= on_edge) on.emplace_back(t, v);
        }
        std::sort(on.begin(), on.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
        for (const auto& [t, v] : on) outer.push_back(v);
    }
    // Triangulate the ring between the outer cycle and Q by merging both by angle around Q's
    // centroid (both are star-shaped from it, Q being convex inside convex P); triangles between
    // points where Q touches P's outline have no area and are dropped.
    const V c = polygon_centroid(inner);
    const V e1 = glm::normalize(poly[1] - poly[0]), e2 = glm::cross(normal, e1);
    auto angle = [&](const V& v) {
        const double t = std::atan2(glm::dot(v - c, e2), glm::dot(v - c, e1));
        return t < 0 ? t + 2 * std::numbers::pi : t;
    };
    auto rotate_to_smallest = [&](std::vector<V>& cycle) {
        std::size_t k0 = 0;
        for (std::size_t k = 1; k < cycle.size(); ++k)
            if (angle(cycle[k]) < angle(cycle[k0])) k0 = k;
        std::rotate(cycle.begin(), cycle.begin() + std::ptrdiff_t(k0), cycle.end());
    };
    rotate_to_smallest(outer);
    rotate_to_smallest(inner);
    std::vector<std::vector<V>> pieces;
    auto emit = [&](const V& a, const V& b, const V& d) {
        if (glm::dot(glm::cross(b - a, d - a), normal) * 0.5 > min_area) pieces.push_back({a, b, d});
    };
    const std::size_t no = outer.size(), ni = inner.size();
    std::size_t i = 0, j = 0;
    while (i < no || j < ni) {
        const V& oi = outer[i % no];
        const V& ij = inner[j % ni];
        const double next_outer = i < no ? angle(outer[(i + 1) % no]) + (i + 1 == no ? 2 * std::numbers::pi : 0.0)
                                         : std::numeric_limits<double>::infinity();
        const double next_inner = j < ni ? angle(inner[(j + 1) % ni]) + (j + 1 == ni ? 2 * std::numbers::pi : 0.0)
                                         : std::numeric_limits<double>::infinity();
        if (next_outer <= next_inner) {
            emit(oi, outer[(i + 1) % no], ij);
            ++i;
        } else {
            emit(oi, inner[(j + 1) % ni], ij);
            ++j;
        }
    }
    return pieces;
}

std::vector<CoveredRegion> find_covered_regions(const Scene& scene) {
    if (scene.surfaces.size() < 2) return {};
    return find_covered_regions(scene, SurfaceTree(scene));
}

namespace {

// A surface hung parallel in front of another, its back towards it (a lamp just below a
// ceiling), hides the part behind it when the gap is small against its own size: the gap
// lets light in only within a few gap widths of the outline (a cosine ray at 75 degrees runs
// 3.9 gaps sideways), and a patch straddling the outline would average that dark part into
// the lit ceiling beside it. kNearGap bounds the gap against the cover's side, sqrt(area);
// the enclosed test is what decides (at points half-way to the outline, so 1/20 of the side
// keeps them about 5 gaps in).
constexpr double kNearGap = 0.05;

/// What the search for one surface's covered regions reads of the whole scene.
struct CoverSearch {
    const Scene& scene;
    const SurfaceTree& tree;
    const SurfaceRays& rays;          // the enclosure rays (tree's surfaces, at Embree's speed)
    std::vector<SurfaceFrame> frame;  // per surface; area 0 where it is degenerate
    std::vector<char> in_solid;       // 1 for the surfaces of closed convex objects
    double diag = 0.0;                // the scene's bounding-box diagonal
    double tol = 0.0;                 // "resting on": a gap below this is contact
    double reach = 0.0;               // how far from a surface's box another may hang and cover it

    /// Enclosed: every ray from just above x meets the back of some surface first.
    /// `side` x `side` stratified cosine directions: 64 where one point decides, 16 a point
    /// where eight spread over a loop must all agree (128 rays, as two points of 64).
    /// Where a back face lies flush with a front face (a cupboard's side against a wall), the
    /// ray meets the back: no light passes between them.
    bool enclosed(const V& x, const V& normal, int side = 8) const {
        const V from = x + 1e-6 * diag * normal;
        for (const V& d : hemisphere_directions(normal, side)) {
            const std::vector<int> first = rays.first_hits(from, d, tol);
            if (std::none_of(first.begin(), first.end(),
                             [&](int t) { return glm::dot(frame[std::size_t(t)].normal, d) > 0; }))
                return false;  // nothing, or only front faces: light can come from there
        }
        return true;
    }
};

/// Every surface's plane frame (area 0 where it is degenerate), widening [lo, hi] by every vertex.
std::vector<SurfaceFrame> surface_frames(const Scene& scene, V& lo, V& hi) {
    const std::size_t n = scene.surfaces.size();
    std::vector<SurfaceFrame> frame(n);
    for (std::size_t s = 0; s < n; ++s) {
        const auto& poly = scene.surfaces[s].vertices;
        for (const auto& v : poly) {
            lo = glm::min(lo, v);
            hi = glm::max(hi, v);
        }
        const V nn = newell_normal(poly);
        const double len = glm::length(nn);
        if (!(len > 0)) continue;
        frame[s] = {nn / len, poly[0], 0.5 * len};
    }
    return frame;
}

/// What other surfaces leave on one surface's plane, projected onto it: the outlines of
/// parallel covers in front of it, and the segments where others touch or cross it.
struct PlaneTraces {
    std::vector<std::vector<V>> candidates;  // polygons that may cover part of the surface
    std::vector<double> gap;                 // per candidate: the gap of a parallel cover in front (0: a contact)
    std::vector<std::pair<V, V>> segments;   // to chain into loops (chain_loops)
};

/// The covers and segments that the surfaces near surface s's slab leave on its plane.
PlaneTraces plane_traces(const CoverSearch& cs, std::size_t s) {
    const Scene& scene = cs.scene;
    const double tol = cs.tol;
    const SurfaceFrame& S = cs.frame[s];
    const int sm = scene.surfaces[s].material;
    const bool emits =
        sm >= 0 && std::size_t(sm) < scene.materials.size() && scene.materials[std::size_t(sm)].emission.max() > 0;
    const auto& spoly = scene.surfaces[s].vertices;
    auto height = [&](const V& p) { return glm::dot(S.normal, p - S.origin); };
    auto project = [&](const V& p) { return p - height(p) * S.normal; };
    PlaneTraces out;

    // Other surfaces near this one's slab.
    V slo(std::numeric_limits<double>::infinity()), shi = -slo;
    for (const auto& v : spoly) {
        slo = glm::min(slo, v);
        shi = glm::max(shi, v);
    }
    const std::vector<int> others = cs.tree.in_box(slo - V(cs.reach), shi + V(cs.reach));
    // A surface parallel in front of this one, its back towards it, projected onto it.
    const auto add_cover = [&](const std::vector<V>& poly, double gap) {
        std::vector<V> c;
        for (const auto& v : poly) c.push_back(project(v));
        out.candidates.push_back(std::move(c));
        out.gap.push_back(gap);
    };

    for (const int t : others) {
        if (t == int(s) || !(cs.frame[std::size_t(t)].area > 0)) continue;
        const auto& tpoly = scene.surfaces[std::size_t(t)].vertices;
        double hmin = std::numeric_limits<double>::infinity(), hmax = -hmin;
        for (const auto& v : tpoly) {
            hmin = std::min(hmin, height(v));
            hmax = std::max(hmax, height(v));
        }
        const bool same_facing = glm::dot(cs.frame[std::size_t(t)].normal, S.normal) > 0.999;
        // An emitter is never hidden by a surface hung at a gap in front of it: that is a
        // scene wound the wrong way (the lamp facing the ceiling's back), which the winding
        // check names, not a lamp in a slot.
        if (hmin > tol && same_facing && hmax - hmin <= tol && !emits &&
            hmin <= kNearGap * std::sqrt(cs.frame[std::size_t(t)].area)) {
            // Hung in front at a small gap, its back towards this surface.
            add_cover(tpoly, 0.5 * (hmin + hmax));
            continue;
        }
        if (hmin > tol || hmax < -tol) continue;  // apart
        // A closed convex object crossing the plane is cut exactly (find_solid_cuts); its
        // segments here would only chain with others' into loops that are partly open.
        if (cs.in_solid[std::size_t(t)] && hmin < -tol && hmax > tol) continue;
        if (hmin >= -tol && hmax <= tol) {
            // Flush with this surface: it covers it when it faces the same way and lies in
            // front (its back towards this surface's front), like a lamp under a ceiling.
            if (same_facing && hmin + hmax >= 0) add_cover(tpoly, 0.5 * (hmin + hmax));
            continue;
        }
        // Touches or crosses the plane: the segment it leaves there.
        std::vector<V> pts;
        for (std::size_t k = 0; k < tpoly.size(); ++k) {
            const V& a = tpoly[k];
            const V& b = tpoly[(k + 1) % tpoly.size()];
            const double ha = height(a), hb = height(b);
            if (std::abs(ha) <= tol) pts.push_back(project(a));
            if ((ha > tol && hb < -tol) || (ha < -tol && hb > tol))
                pts.push_back(project(a + (ha / (ha - hb)) * (b - a)));
        }
        if (pts.size() < 2) continue;
        std::size_t i0 = 0, i1 = 1;
        double best = -1;
        for (std::size_t i = 0; i < pts.size(); ++i)
            for (std::size_t j = i + 1; j < pts.size(); ++j)
                if (const double d = glm::length(pts[i] - pts[j]); d > best) {
                    best = d;
                    i0 = i;
                    i1 = j;
                }
        if (best > tol) out.segments.emplace_back(pts[i0], pts[i1]);
    }
    return out;
}

/// The closed loops the segments chain into (endpoints meet within `tol`), in the order of
/// their first segments.
std::vector<std::vector<V>> chain_loops(const std::vector<std::pair<V, V>>& segments, double tol) {
    std::vector<std::vector<V>> loops;
    std::vector<bool> used(segments.size(), false);
    for (std::size_t first = 0; first < segments.size(); ++first) {
        if (used[first]) continue;
        used[first] = true;
        std::vector<V> loop = {segments[first].first, segments[first].second};
        bool closed = false;
        for (std::size_t guard = 0; guard < segments.size() && !closed; ++guard) {
            bool extended = false;
            for (std::size_t k = 0; k < segments.size(); ++k) {
                if (used[k]) continue;
                const auto& [a, b] = segments[k];
                if (glm::length(a - loop.back()) <= tol) {
                    loop.push_back(b);
                } else if (glm::length(b - loop.back()) <= tol) {
                    loop.push_back(a);
                } else {
                    continue;
                }
                used[k] = true;
                extended = true;
                break;
            }
            if (glm::length(loop.back() - loop.front()) <= tol && loop.size() > 3) {
                loop.pop_back();
                closed = true;
            }
            if (!extended) break;
        }
        if (closed) loops.push_back(std::move(loop));
    }
    return loops;
}

/// Whether candidate `c` (counter-clockwise about `normal`, triangulated as `tri`) is enclosed:
/// a hung cover (gap above the tolerance) at its centre and half-way to its corners, a loop at
/// the centres of its two largest triangles and half-way to their corners.
bool candidate_enclosed(const CoverSearch& cs, const std::vector<V>& c, const std::vector<std::array<int, 3>>& tri,
                        double gap, const V& normal) {
    bool covered = !tri.empty();
    if (gap > cs.tol) {
        // A hung cover is convex in practice (a lamp panel); its centre and the points
        // half-way to its corners must all be enclosed.
        const V centre = polygon_centroid(c);
        covered = covered && cs.enclosed(centre, normal);
        for (std::size_t k = 0; k < c.size() && covered; ++k) covered = cs.enclosed(0.5 * (centre + c[k]), normal);
    }
    // A loop is judged at the centres of its two largest triangles and half-way from
    // there to their corners: a point or two can both fall inside objects that merely
    // cross this surface, and a room's own outline would then hide the whole surface.
    std::vector<std::size_t> order(tri.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    const auto tri_area = [&](std::size_t k) {
        return glm::length(glm::cross(c[tri[k][1]] - c[tri[k][0]], c[tri[k][2]] - c[tri[k][0]]));
    };
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return tri_area(a) > tri_area(b); });
    for (std::size_t j = 0; j < order.size() && j < 2 && covered && !(gap > cs.tol); ++j) {
        const auto& t = tri[order[j]];
        const V centre = (c[t[0]] + c[t[1]] + c[t[2]]) / 3.0;
        covered = cs.enclosed(centre, normal, 8);
        for (int corner = 0; corner < 3 && covered; ++corner)
            covered = cs.enclosed(0.5 * (centre + c[t[corner]]), normal, 8);
    }
    return covered;
}

/// The covered regions of surface s: its plane's candidates that are enclosed, convex ones
/// whole, others as their (convex) triangles.
std::vector<CoveredRegion> covered_regions_of(const CoverSearch& cs, std::size_t s) {
    std::vector<CoveredRegion> out;
    const SurfaceFrame& S = cs.frame[s];
    if (!(S.area > 0)) return out;
    const double tol = cs.tol;
    PlaneTraces traces = plane_traces(cs, s);
    for (auto& loop : chain_loops(traces.segments, tol)) {
        traces.candidates.push_back(std::move(loop));
        traces.gap.push_back(0.0);
    }
    for (std::size_t ci = 0; ci < traces.candidates.size(); ++ci) {
        auto& c = traces.candidates[ci];
        const double gap = traces.gap[ci];
        if (c.size() < 3) continue;
        if (glm::dot(newell_normal(c), S.normal) < 0) std::reverse(c.begin(), c.end());
        if (!(area_of(c) > tol * tol)) continue;
        const auto tri = triangulate_polygon(c);
        if (!candidate_enclosed(cs, c, tri, gap, S.normal)) continue;
        // Convex loops stay whole; others go as their (convex) triangles.
        bool convex = true;
        for (std::size_t k = 0; k < c.size() && convex; ++k)
            convex = glm::dot(glm::cross(c[(k + 1) % c.size()] - c[k], c[(k + 2) % c.size()] - c[(k + 1) % c.size()]),
                              S.normal) >= -1e-12 * cs.diag * cs.diag;
        if (convex) {
            out.push_back({int(s), c, gap});
        } else {
            for (const auto& t : tri) out.push_back({int(s), {c[t[0]], c[t[1]], c[t[2]]}, gap});
        }
    }
    return out;
}

}  // namespace

std::vector<CoveredRegion> find_covered_regions(const Scene& scene, const SurfaceTree& tree,
                                                const CoverProgress& progress) {
    const std::size_t n = scene.surfaces.size();
    std::vector<CoveredRegion> out;
    if (n < 2) return out;
    if (tree.empty()) return out;
    V lo(std::numeric_limits<double>::infinity()), hi = -lo;
    const SurfaceRays rays(scene);
    CoverSearch cs{scene, tree, rays, surface_frames(scene, lo, hi), std::vector<char>(n, 0), 0.0, 0.0, 0.0};
    const auto solids = find_convex_solids(scene);
    for (const auto& solid : solids)
        for (const int t : solid.surfaces) cs.in_solid[std::size_t(t)] = 1;
    cs.diag = glm::length(hi - lo);
    cs.tol = 5e-4 * cs.diag;
    double largest_side = 0.0;
    for (const SurfaceFrame& f : cs.frame) largest_side = std::max(largest_side, std::sqrt(f.area));
    cs.reach = std::max(cs.tol, std::min(kNearGap * largest_side, 0.05 * cs.diag));

    // Surfaces are independent (the tree is only read): in parallel, each into its own list,
    // joined in surface order so the cuts do not depend on the thread count.
    std::vector<std::vector<CoveredRegion>> found(n);
    std::atomic<std::size_t> done{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64), [&](const auto& range) {
        for (std::size_t s = range.begin(); s != range.end(); ++s) found[s] = covered_regions_of(cs, s);
        const std::size_t now = done += range.size();
        if (progress) progress(now, n);
    });
    for (auto& f : found) out.insert(out.end(), std::make_move_iterator(f.begin()), std::make_move_iterator(f.end()));
    for (auto& c : find_solid_cuts(scene, solids)) out.push_back(std::move(c));
    return out;
}

}  // namespace bounce
