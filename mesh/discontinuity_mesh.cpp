// SPDX-License-Identifier: MIT
#include "mesh/discontinuity_mesh.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <map>
#include <sstream>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "mesh/polygon.h"
#include "mesh/surface_tree.h"

namespace bounce {
namespace {

using V = glm::dvec3;
using P2 = glm::dvec2;

/// A surface's plane with an orthonormal frame: e1, e2, normal right-handed, so counter-clockwise
/// in (e1, e2) is counter-clockwise seen from the front.
struct Frame {
    V origin{0.0}, e1{0.0}, e2{0.0}, normal{0.0};
    double area = 0.0;
    bool valid = false;
    double height(const V& x) const { return glm::dot(normal, x - origin); }
    P2 to2(const V& x) const { return {glm::dot(x - origin, e1), glm::dot(x - origin, e2)}; }
    V to3(const P2& p) const { return origin + p.x * e1 + p.y * e2; }
};

Frame frame_of(const std::vector<V>& poly) {
    Frame f;
    if (poly.size() < 3) return f;
    const V n = newell_normal(poly);
    const double len = glm::length(n);
    if (!(len > 0)) return f;
    f.normal = n / len;
    f.area = 0.5 * len;
    f.origin = polygon_centroid(poly);
    // The longest edge as e1: well defined for slivers too.
    std::size_t best = 0;
    double longest = -1;
    for (std::size_t k = 0; k < poly.size(); ++k)
        if (const double l = glm::length(poly[(k + 1) % poly.size()] - poly[k]); l > longest) {
            longest = l;
            best = k;
        }
    V e1 = poly[(best + 1) % poly.size()] - poly[best];
    e1 -= glm::dot(e1, f.normal) * f.normal;
    if (!(glm::length(e1) > 0)) return f;
    f.e1 = glm::normalize(e1);
    f.e2 = glm::cross(f.normal, f.e1);
    f.valid = true;
    return f;
}

double cross2(const P2& a, const P2& b) { return a.x * b.y - a.y * b.x; }

template <class Point>
P2 to_p2(const Point& p) {
    return {CGAL::to_double(p.x()), CGAL::to_double(p.y())};
}

bool inside_polygon(const P2& p, const std::vector<P2>& poly) {
    bool in = false;
    for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
        const P2& a = poly[i];
        const P2& b = poly[j];
        if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) in = !in;
    }
    return in;
}

/// The parameter intervals of segment a + t (b - a), t in [0, 1], inside `poly` (any simple
/// polygon): the segment is cut where it crosses an edge and each piece is classified by its
/// midpoint.
std::vector<std::pair<double, double>> inside_intervals(const P2& a, const P2& b, const std::vector<P2>& poly) {
    std::vector<double> ts = {0.0, 1.0};
    const P2 d = b - a;
    for (std::size_t k = 0; k < poly.size(); ++k) {
        const P2& p = poly[k];
        const P2 e = poly[(k + 1) % poly.size()] - p;
        const double den = cross2(d, e);
        if (den == 0) continue;
        const double t = cross2(p - a, e) / den, u = cross2(p - a, d) / den;
        if (t > 0 && t < 1 && u >= 0 && u <= 1) ts.push_back(t);
    }
    std::sort(ts.begin(), ts.end());
    std::vector<std::pair<double, double>> out;
    for (std::size_t k = 0; k + 1 < ts.size(); ++k) {
        if (!(ts[k + 1] - ts[k] > 1e-12)) continue;
        if (!inside_polygon(a + 0.5 * (ts[k] + ts[k + 1]) * d, poly)) continue;
        if (!out.empty() && std::abs(out.back().second - ts[k]) <= 1e-12)
            out.back().second = ts[k + 1];
        else
            out.emplace_back(ts[k], ts[k + 1]);
    }
    return out;
}

/// Removes from `intervals` the part of the segment inside convex `hole` (counter-clockwise).
void subtract_convex_interval(std::vector<std::pair<double, double>>& intervals, const P2& a, const P2& b,
                              const std::vector<P2>& hole) {
    // Cyrus-Beck: the segment's part inside every edge's left half-plane.
    double lo = 0.0, hi = 1.0;
    const P2 d = b - a;
    for (std::size_t k = 0; k < hole.size() && lo < hi; ++k) {
        const P2& p = hole[k];
        const P2 e = hole[(k + 1) % hole.size()] - p;
        const double f0 = cross2(e, a - p), fd = cross2(e, d);  // f(t) = f0 + t fd >= 0 inside
        if (fd == 0) {
            if (f0 < 0) hi = lo;
        } else if (fd > 0) {
            lo = std::max(lo, -f0 / fd);
        } else {
            hi = std::min(hi, -f0 / fd);
        }
    }
    if (!(hi - lo > 1e-12)) return;
    std::vector<std::pair<double, double>> out;
    for (const auto& [s, e] : intervals) {
        if (e <= lo || s >= hi) {
            out.emplace_back(s, e);
            continue;
        }
        if (lo - s > 1e-12) out.emplace_back(s, lo);
        if (e - hi > 1e-12) out.emplace_back(hi, e);
    }
    intervals = std::move(out);
}

/// The occluding faces with their vertices welded, so the faces around a vertex or an edge can
/// be asked whether they lie on one side of a critical plane.
struct Occluders {
    std::vector<V> points;
    struct Face {
        int surface = -1;
        std::vector<int> idx;
        V normal{0.0};
    };
    std::vector<Face> faces;
    std::vector<std::vector<std::pair<int, int>>> around;                   // per point: (face, corner)
    std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> edges;  // (lo, hi) -> (face, corner of edge start)
};

Occluders weld_occluders(const Scene& scene, const std::vector<bool>& is_emitter, double tol) {
    Occluders o;
    std::map<std::array<long long, 3>, int> grid;
    auto id = [&](const V& p) {
        const std::array<long long, 3> key = {std::llround(p.x / tol), std::llround(p.y / tol),
                                              std::llround(p.z / tol)};
        const auto [it, fresh] = grid.emplace(key, int(o.points.size()));
        if (fresh) {
            o.points.push_back(p);
            o.around.emplace_back();
        }
        return it->second;
    };
    for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
        if (is_emitter[s]) continue;
        const auto& poly = scene.surfaces[s].vertices;
        const V n = newell_normal(poly);
        if (!(glm::length(n) > 0)) continue;
        Occluders::Face f{int(s), {}, glm::normalize(n)};
        for (const V& p : poly) {
            const int i = id(p);
            if (f.idx.empty() || f.idx.back() != i) f.idx.push_back(i);
        }
        while (f.idx.size() > 1 && f.idx.front() == f.idx.back()) f.idx.pop_back();
        if (f.idx.size() < 3) continue;
        const int fi = int(o.faces.size());
        for (std::size_t k = 0; k < f.idx.size(); ++k) {
            o.around[std::size_t(f.idx[k])].emplace_back(fi, int(k));
            const int a = f.idx[k], b = f.idx[(k + 1) % f.idx.size()];
            o.edges[{std::min(a, b), std::max(a, b)}].emplace_back(fi, int(k));
        }
        o.faces.push_back(std::move(f));
    }
    return o;
}

/// The interval of t in [lo, hi] where f0 + t * fd > 0.
void keep_positive(double& lo, double& hi, double f0, double fd) {
    if (fd == 0) {
        if (!(f0 > 0)) hi = lo;
        return;
    }
    const double t = -f0 / fd;
    if (fd > 0)
        lo = std::max(lo, t);
    else
        hi = std::min(hi, t);
}

}  // namespace

TracedDiscontinuities trace_discontinuities(const Scene& scene, std::size_t max_per_surface) {
    const std::size_t n = scene.surfaces.size();
    TracedDiscontinuities out;
    out.per_surface.resize(n);
    V lo(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const auto& s : scene.surfaces)
        for (const V& p : s.vertices) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    const double diag = n ? glm::length(hi - lo) : 0.0;
    if (!(diag > 0) || !std::isfinite(diag)) return out;
    const double eps = 1e-9 * diag;
    // A vertex or a whole edge this close to a receiver rests on it (the contact tolerance of
    // mesh/contact_cuts.h): its shadow there is the contact outline, which the contact cut
    // already follows, and a trace of it would run a hair beside that outline (a sliver the
    // refinement would have to fill with needle-sized triangles).
    const double contact = 5e-4 * diag;

    std::vector<Frame> frames(n);
    std::vector<bool> is_emitter(n, false);
    for (std::size_t s = 0; s < n; ++s) {
        frames[s] = frame_of(scene.surfaces[s].vertices);
        const int m = scene.surfaces[s].material;
        is_emitter[s] = m >= 0 && std::size_t(m) < scene.materials.size() &&
                        scene.materials[std::size_t(m)].emission.max() > 0 && frames[s].valid;
    }
    const Occluders occ = weld_occluders(scene, is_emitter, 1e-7 * diag);

    // Receivers' outlines and covered regions in their own frames.
    std::vector<std::vector<P2>> outline(n);
    std::vector<std::vector<std::vector<P2>>> holes(n);
    for (std::size_t s = 0; s < n; ++s)
        if (frames[s].valid)
            for (const V& p : scene.surfaces[s].vertices) outline[s].push_back(frames[s].to2(p));
    for (const auto& c : scene.covered)
        if (c.surface >= 0 && std::size_t(c.surface) < n && frames[std::size_t(c.surface)].valid) {
            std::vector<P2> h;
            for (const V& p : c.polygon) h.push_back(frames[std::size_t(c.surface)].to2(p));
            holes[std::size_t(c.surface)].push_back(std::move(h));
        }

    // A boundary exists only where its critical line, from the receiver through the occluder's
    // vertex or edge to the emitter, is itself unobstructed (Lischinski et al. 1992 clip their
    // wedges by the scene the same way): behind a third object the emitter is hidden anyway.
    // `ignore` holds the surfaces the line may touch: the receiver, the emitter and the faces
    // at the generating vertex or edge (the line grazes them there).
    const SurfaceTree tree(scene);
    const double shift = 1e-6 * diag;  // off the receiver and the emitter at the line's ends
    auto line_open = [&](const V& q, const V& to, const std::vector<int>& ignore) {
        const V d = to - q;
        const double len = glm::length(d);
        if (!(len > 2 * shift)) return true;
        for (const int hit : tree.on_segment(q + d * (shift / len), to - d * (shift / len)))
            if (!std::binary_search(ignore.begin(), ignore.end(), hit)) return false;
        return true;
    };
    // The visible parts of [t0, t1] of a + t (b - a): visibility at kSamples interior points,
    // each change of answer located by bisection; the ends keep the answer of their nearest
    // sample (a point on the receiver's outline would ask about the wall beside it).
    constexpr int kSamples = 16;
    auto visible_parts = [&](double t0, double t1, const auto& open_at) {
        std::vector<std::pair<double, double>> parts;
        const auto at = [&](int k) { return t0 + (k + 0.5) / kSamples * (t1 - t0); };
        bool open = open_at(at(0));
        double start = t0;
        for (int k = 1; k < kSamples; ++k) {
            const bool next = open_at(at(k));
            if (next == open) continue;
            double lo = at(k - 1), hi = at(k);
            while (hi - lo > 1e-9 * (t1 - t0)) {
                const double mid = 0.5 * (lo + hi);
                (open_at(mid) == open ? lo : hi) = mid;
            }
            if (open) parts.emplace_back(start, 0.5 * (lo + hi));
            start = 0.5 * (lo + hi);
            open = next;
        }
        if (open) parts.emplace_back(start, t1);
        return parts;
    };

    auto add = [&](std::size_t r, const V& pa, const V& pb, DiscontinuitySegment::Kind kind, int emitter,
                   int occluder, const auto& open_from) {
        const Frame& f = frames[r];
        const P2 a = f.to2(pa), b = f.to2(pb);
        if (!(glm::length(b - a) > eps)) return;
        auto inside = inside_intervals(a, b, outline[r]);
        for (const auto& h : holes[r]) subtract_convex_interval(inside, a, b, h);
        std::vector<std::pair<double, double>> intervals;
        for (const auto& [t0, t1] : inside)
            for (const auto& part : visible_parts(t0, t1, [&](double t) { return open_from(f.to3(a + t * (b - a))); }))
                intervals.push_back(part);
        for (const auto& [t0, t1] : intervals) {
            const V qa = f.to3(a + t0 * (b - a)), qb = f.to3(a + t1 * (b - a));
            if (!(glm::length(qb - qa) > 1e-6 * diag)) continue;
            auto& list = out.per_surface[r];
            bool repeated = false;
            for (const auto& d : list)
                if ((glm::length(d.a - qa) <= eps && glm::length(d.b - qb) <= eps) ||
                    (glm::length(d.a - qb) <= eps && glm::length(d.b - qa) <= eps)) {
                    repeated = true;
                    break;
                }
            if (!repeated) list.push_back({qa, qb, kind, emitter, occluder});
        }
    };

    // The receiver, the emitter and every face at the given welded points, sorted.
    auto ignored = [&](std::size_t r, std::size_t e, std::initializer_list<std::size_t> points) {
        std::vector<int> out_ids = {int(r), int(e)};
        for (const std::size_t p : points)
            for (const auto& [fi, c] : occ.around[p]) out_ids.push_back(occ.faces[std::size_t(fi)].surface);
        std::sort(out_ids.begin(), out_ids.end());
        return out_ids;
    };

    for (std::size_t e = 0; e < n; ++e) {
        if (!is_emitter[e]) continue;
        const Frame& E = frames[e];
        const auto& light = scene.surfaces[e].vertices;
        for (std::size_t r = 0; r < n; ++r) {
            if (r == e || !frames[r].valid) continue;
            const Frame& R = frames[r];
            // The receiver must face the emitter and lie (partly) in front of it.
            bool sees = false, seen = false;
            for (const V& p : light) sees = sees || R.height(p) > eps;
            for (const V& p : scene.surfaces[r].vertices) seen = seen || E.height(p) > eps;
            if (!sees || !seen) continue;

            // EV: the plane through an emitter edge and an occluder vertex. Its trace is the
            // central projection of the edge through the vertex (Heckbert 1992, sec. 3).
            for (std::size_t v = 0; v < occ.points.size(); ++v) {
                const V& x = occ.points[v];
                const double hx = R.height(x);
                if (!(hx > contact) || !(E.height(x) > eps)) continue;
                int owner = -1;
                for (const auto& [fi, k] : occ.around[v])
                    if (occ.faces[std::size_t(fi)].surface != int(r)) owner = occ.faces[std::size_t(fi)].surface;
                if (owner < 0) continue;
                const std::vector<int> ignore_v = ignored(r, e, {v});
                for (std::size_t k = 0; k < light.size(); ++k) {
                    const V& l0 = light[k];
                    const V& l1 = light[(k + 1) % light.size()];
                    const V np = glm::cross(l1 - l0, x - l0);
                    const double scale = glm::length(np);
                    if (!(scale > eps * diag)) continue;
                    // A silhouette vertex only: every face around it on one side of the plane
                    // (else the plane cuts through the occluder and bounds nothing).
                    double lo_side = 0, hi_side = 0;
                    for (const auto& [fi, c] : occ.around[v]) {
                        const auto& f = occ.faces[std::size_t(fi)];
                        const std::size_t m = f.idx.size();
                        for (const int q : {f.idx[(std::size_t(c) + 1) % m], f.idx[(std::size_t(c) + m - 1) % m]}) {
                            const V d = occ.points[std::size_t(q)] - x;
                            const double s = glm::dot(np, d) / (scale * std::max(glm::length(d), 1e-300));
                            lo_side = std::min(lo_side, s);
                            hi_side = std::max(hi_side, s);
                        }
                    }
                    if (lo_side < -1e-9 && hi_side > 1e-9) continue;
                    // Only the part of the emitter edge higher above the receiver than the vertex
                    // throws the vertex's shadow onto it.
                    double t0 = 0, t1 = 1;
                    const double h0 = R.height(l0) - hx, h1 = R.height(l1) - hx;
                    // (A margin keeps the projection within 10^4 edge lengths of the vertex.)
                    keep_positive(t0, t1, h0 - std::max(eps, 1e-4 * hx), h1 - h0);
                    if (!(t1 > t0)) continue;
                    auto project = [&](double t) {
                        const V l = l0 + t * (l1 - l0);
                        return x + (x - l) * (hx / (R.height(l) - hx));
                    };
                    ++out.traced;
                    add(r, project(t0), project(t1), DiscontinuitySegment::Kind::EV, int(e), owner, [&](const V& q) {
                        // On to the emitter's plane, through x: the emitter edge's point.
                        const double hq = E.height(q), hv = E.height(x);
                        return !(hq > hv) || line_open(q, q + (x - q) * (hq / (hq - hv)), ignore_v);
                    });
                }
            }
            // VE: the plane through an emitter vertex and an occluder edge; the trace is the edge
            // projected from the vertex.
            for (const auto& [key, faces] : occ.edges) {
                const V& a = occ.points[std::size_t(key.first)];
                const V& b = occ.points[std::size_t(key.second)];
                int owner = -1;
                for (const auto& [fi, c] : faces)
                    if (occ.faces[std::size_t(fi)].surface != int(r)) owner = occ.faces[std::size_t(fi)].surface;
                if (owner < 0 || (R.height(a) <= contact && R.height(b) <= contact)) continue;
                const std::vector<int> ignore_edge = ignored(r, e, {std::size_t(key.first), std::size_t(key.second)});
                for (const V& u : light) {
                    const double hu = R.height(u);
                    if (!(hu > eps)) continue;
                    const V np = glm::cross(b - a, u - a);
                    const double scale = glm::length(np);
                    if (!(scale > eps * diag)) continue;
                    // A silhouette edge only: the faces sharing it on one side of the plane.
                    int sign = 0;
                    bool silhouette = true;
                    for (const auto& [fi, c] : faces) {
                        const auto& f = occ.faces[std::size_t(fi)];
                        const V fa = occ.points[std::size_t(f.idx[std::size_t(c)])];
                        const V fb = occ.points[std::size_t(f.idx[(std::size_t(c) + 1) % f.idx.size()])];
                        const V inward = glm::cross(f.normal, fb - fa);  // into the face (counter-clockwise)
                        const double s = glm::dot(np, inward) / (scale * glm::length(inward));
                        const int side = s > 1e-9 ? 1 : (s < -1e-9 ? -1 : 0);
                        if (side == 0 || (sign != 0 && side != sign)) silhouette = false;
                        sign = side;
                    }
                    if (!silhouette) continue;
                    // The part of the edge in front of the emitter and of the receiver and below
                    // the emitter vertex (seen from the receiver).
                    double t0 = 0, t1 = 1;
                    const double ra = R.height(a), rb = R.height(b);
                    keep_positive(t0, t1, ra - eps, rb - ra);
                    keep_positive(t0, t1, hu - ra - std::max(eps, 1e-4 * hu), ra - rb);
                    keep_positive(t0, t1, E.height(a) - eps, E.height(b) - E.height(a));
                    if (!(t1 > t0)) continue;
                    auto project = [&](double t) {
                        const V x = a + t * (b - a);
                        const double hx = R.height(x);
                        return x + (x - u) * (hx / (hu - hx));
                    };
                    ++out.traced;
                    add(r, project(t0), project(t1), DiscontinuitySegment::Kind::VE, int(e), owner,
                        [&](const V& q) { return line_open(q, u, ignore_edge); });
                }
            }
        }
    }

    // Coplanar overlapping faces facing the same way: each casts and receives boundaries of its
    // own, and the overlap is meshed (and lit) twice. Not an error (a decal on a wall), but worth
    // one line.
    std::size_t overlaps = 0;
    std::pair<std::size_t, std::size_t> first_overlap;
    auto strictly_inside = [&](const P2& p, const std::vector<P2>& poly) {
        if (!inside_polygon(p, poly)) return false;
        for (std::size_t k = 0; k < poly.size(); ++k) {
            const P2 a = poly[k], d = poly[(k + 1) % poly.size()] - a;
            const double t = std::clamp(glm::dot(p - a, d) / glm::dot(d, d), 0.0, 1.0);
            if (glm::length(a + t * d - p) <= 1e3 * eps) return false;
        }
        return true;
    };
    for (std::size_t a = 0; a < n; ++a) {
        if (!frames[a].valid) continue;
        for (std::size_t b = a + 1; b < n; ++b) {
            // Facing the same way: a face against its back (a block's bottom on the floor) is a
            // contact, which the contact cuts handle.
            if (!frames[b].valid || glm::dot(frames[a].normal, frames[b].normal) < 1 - 1e-9) continue;
            bool coplanar = true;
            for (const V& p : scene.surfaces[b].vertices)
                coplanar = coplanar && std::abs(frames[a].height(p)) <= 1e3 * eps;
            if (!coplanar) continue;
            std::vector<P2> pb;
            for (const V& p : scene.surfaces[b].vertices) pb.push_back(frames[a].to2(p));
            bool overlap = strictly_inside(frames[a].to2(polygon_centroid(scene.surfaces[b].vertices)), outline[a]) ||
                           strictly_inside(P2(0.0), pb);  // a's centroid is its frame's origin
            for (const P2& p : pb) overlap = overlap || strictly_inside(p, outline[a]);
            for (const V& p : scene.surfaces[a].vertices) overlap = overlap || strictly_inside(frames[a].to2(p), pb);
            if (!overlap) continue;
            if (overlaps++ == 0) first_overlap = {a, b};
        }
    }
    if (overlaps) {
        const auto& [a, b] = first_overlap;
        std::ostringstream msg;
        msg << "discontinuity meshing: " << describe(scene.surfaces[a].where, scene.surfaces[a].object) << " and "
            << describe(scene.surfaces[b].where, scene.surfaces[b].object) << " overlap in one plane";
        if (overlaps > 1) msg << " (and " << overlaps - 1 << " more pair" << (overlaps > 2 ? "s" : "") << ")";
        msg << "; each is meshed and lit on its own, the overlap twice";
        out.warnings.push_back(msg.str());
    }

    // The cap: the longest boundaries are kept (they carry the most shadow edge).
    std::size_t capped = 0, worst = 0, worst_count = 0;
    for (std::size_t s = 0; s < n; ++s) {
        auto& list = out.per_surface[s];
        if (list.size() <= max_per_surface) continue;
        if (list.size() > worst_count) {
            worst = s;
            worst_count = list.size();
        }
        ++capped;
        std::stable_sort(list.begin(), list.end(),
                         [](const auto& x, const auto& y) { return glm::length(x.b - x.a) > glm::length(y.b - y.a); });
        list.resize(max_per_surface);
    }
    if (capped) {
        std::ostringstream msg;
        msg << "discontinuity meshing: kept the " << max_per_surface << " longest shadow boundaries of " << worst_count
            << " on " << describe(scene.surfaces[worst].where, scene.surfaces[worst].object);
        if (capped > 1) msg << " and at most as many on " << capped - 1 << " more surface" << (capped > 2 ? "s" : "");
        msg << " (raise --max-discontinuities)";
        out.warnings.push_back(msg.str());
    }
    return out;
}

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Delaunay_mesh_vertex_base_2<K>;
using Fb = CGAL::Delaunay_mesh_face_base_2<K>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// Exact_predicates_tag: traced boundaries cross each other; CGAL splits them at the crossings.
using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;

/// Bounds on the smallest angle (B: its squared sine, CGAL's convention) and on the area. CGAL
/// 5.5's Delaunay_mesh_area_criteria_2 cannot be used: it stores the squared area where the
/// mesher expects a size normalised to 1 (so it re-rates every triangle of area above 1 as
/// imperatively bad whatever the bound, and refines without end), and its sine is a quarter of
/// the squared sine. Here the size is area / max_area, as the mesher expects.
class Criteria : public CGAL::Delaunay_mesh_size_criteria_2<CDT> {
    using Base = CGAL::Delaunay_mesh_size_criteria_2<CDT>;

public:
    using Quality = Base::Quality;
    Criteria(double aspect_bound, double max_area)
        : CGAL::Delaunay_mesh_criteria_2<CDT>(aspect_bound), Base(aspect_bound, 0.0), m_area(max_area) {}

    class Is_bad : public Base::Is_bad {
    public:
        Is_bad(double aspect_bound, double max_area, const Geom_traits& traits)
            : Base::Is_bad(aspect_bound, 0.0, traits), m_area(max_area) {}
        CGAL::Mesh_2::Face_badness operator()(const Quality q) const { return Base::Is_bad::operator()(q); }
        CGAL::Mesh_2::Face_badness operator()(const CDT::Face_handle& fh, Quality& q) const {
            const K::Point_2& a = fh->vertex(0)->point();
            const K::Point_2& b = fh->vertex(1)->point();
            const K::Point_2& c = fh->vertex(2)->point();
            double l[3] = {CGAL::to_double(CGAL::squared_distance(b, c)), CGAL::to_double(CGAL::squared_distance(c, a)),
                           CGAL::to_double(CGAL::squared_distance(a, b))};
            std::sort(l, l + 3);
            const double area = CGAL::to_double(CGAL::area(a, b, c));
            // The smallest angle is opposite the shortest edge: sin = 2 A / (product of the other two).
            q.first = 4 * area * area / (l[2] * l[1]);
            q.second = m_area > 0 ? area / m_area : 0.0;
            if (q.size() > 1) return CGAL::Mesh_2::IMPERATIVELY_BAD;
            return q.sine() < this->B ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
        }

    private:
        double m_area;
    };
    Is_bad is_bad_object() const { return Is_bad(this->bound(), m_area, this->traits); }

private:
    double m_area;
};

}  // namespace

SurfaceTriangulation triangulate_surface(const Scene& scene, int surface,
                                         const std::vector<DiscontinuitySegment>& segments, double max_area,
                                         double aspect_bound, const std::vector<glm::dvec3>& outline_points) {
    SurfaceTriangulation out;
    const auto& poly = scene.surfaces[std::size_t(surface)].vertices;
    const Frame f = frame_of(poly);
    if (!f.valid) return out;
    const double size = std::sqrt(f.area);
    // Points closer than this are one point: rounding in the tracing must not leave slivers that
    // the Delaunay refinement would chase down to their width.
    const double snap = 1e-6 * size;

    std::vector<P2> anchors;
    std::vector<V> anchor3;  // the 3D point of each anchor (corners keep their own coordinates)
    auto anchor = [&](const P2& p, const V& p3) {
        for (std::size_t k = 0; k < anchors.size(); ++k)
            if (glm::length(anchors[k] - p) <= snap) return k;
        anchors.push_back(p);
        anchor3.push_back(p3);
        return anchors.size() - 1;
    };
    std::vector<P2> outline;
    std::vector<std::pair<std::size_t, std::size_t>> constraints;
    for (const V& p : poly) outline.push_back(f.to2(p));
    std::vector<std::size_t> corner;
    for (std::size_t k = 0; k < poly.size(); ++k) corner.push_back(anchor(outline[k], poly[k]));
    for (std::size_t k = 0; k < corner.size(); ++k)
        if (corner[k] != corner[(k + 1) % corner.size()])
            constraints.emplace_back(corner[k], corner[(k + 1) % corner.size()]);

    // Covered outlines, only where they lie on the surface.
    std::vector<std::vector<P2>> holes;
    for (const auto& c : scene.covered) {
        if (c.surface != surface) continue;
        std::vector<P2> h;
        for (const V& p : c.polygon) h.push_back(f.to2(p));
        for (std::size_t k = 0; k < h.size(); ++k) {
            const P2 a = h[k], b = h[(k + 1) % h.size()];
            for (const auto& [t0, t1] : inside_intervals(a, b, outline)) {
                const P2 qa = a + t0 * (b - a), qb = a + t1 * (b - a);
                const std::size_t ia = anchor(qa, f.to3(qa)), ib = anchor(qb, f.to3(qb));
                if (ia != ib) constraints.emplace_back(ia, ib);
            }
        }
        holes.push_back(std::move(h));
    }
    for (const auto& s : segments) {
        const P2 a = f.to2(s.a), b = f.to2(s.b);
        const std::size_t ia = anchor(a, f.to3(a)), ib = anchor(b, f.to3(b));
        if (ia != ib) constraints.emplace_back(ia, ib);
    }
    // A constraint passing within the snapping distance of an anchor goes through it, so no
    // anchor sits a rounding error off a constraint (a feature of that size, which the
    // refinement would resolve with ever smaller triangles).
    std::vector<std::pair<std::size_t, std::size_t>> chained;
    for (const auto& [ia, ib] : constraints) {
        const P2 a = anchors[ia], d = anchors[ib] - a;
        const double len2 = glm::dot(d, d);
        std::vector<std::pair<double, std::size_t>> on = {{0.0, ia}, {1.0, ib}};
        for (std::size_t k = 0; k < anchors.size(); ++k) {
            if (k == ia || k == ib) continue;
            const double t = glm::dot(anchors[k] - a, d) / len2;
            if (t <= 0 || t >= 1) continue;
            if (glm::length(a + t * d - anchors[k]) <= snap) on.emplace_back(t, k);
        }
        std::sort(on.begin(), on.end());
        for (std::size_t k = 0; k + 1 < on.size(); ++k)
            if (on[k].second != on[k + 1].second) chained.emplace_back(on[k].second, on[k + 1].second);
    }

    CDT cdt;
    std::vector<CDT::Vertex_handle> handle;
    for (const P2& p : anchors) handle.push_back(cdt.insert(K::Point_2(p.x, p.y)));
    for (const auto& [ia, ib] : chained)
        if (handle[ia] != handle[ib]) cdt.insert_constraint(handle[ia], handle[ib]);
    if (cdt.dimension() < 2) return out;

    // The domain: inside the outline, outside every covered region. Marked per region between
    // constraints (traced constraints cut the surface into many regions, so seeds would not do),
    // each by the centroid of its largest triangle: a mark must agree with the constraints (an
    // outline bent by a hair at a chained point puts a needle on the other side of the straight
    // outline, and a needle marked apart from its neighbours is refined without end). Regions
    // of no area (between constraints a rounding error apart) are left out.
    auto in_domain = [&](const P2& c) {
        if (!inside_polygon(c, outline)) return false;
        for (const auto& h : holes)
            if (inside_polygon(c, h)) return false;
        return true;
    };
    auto mark_domain = [&] {
        std::map<CDT::Face_handle, int> region;
        for (auto fit = cdt.all_faces_begin(); fit != cdt.all_faces_end(); ++fit) {
            const CDT::Face_handle start = fit;
            if (region.count(start)) continue;
            std::vector<CDT::Face_handle> faces = {start};
            region[start] = 1;
            bool infinite = false;
            double area = 0, best = -1;
            P2 representative(0.0);
            for (std::size_t k = 0; k < faces.size(); ++k) {
                const CDT::Face_handle fh = faces[k];
                if (cdt.is_infinite(fh)) {
                    infinite = true;
                } else {
                    const P2 a = to_p2(fh->vertex(0)->point()), b = to_p2(fh->vertex(1)->point()),
                             c = to_p2(fh->vertex(2)->point());
                    const double t = 0.5 * std::abs(cross2(b - a, c - a));
                    area += t;
                    if (t > best) {
                        best = t;
                        representative = (a + b + c) / 3.0;
                    }
                }
                for (int i = 0; i < 3; ++i)
                    if (!fh->is_constrained(i) && !region.count(fh->neighbor(i))) {
                        region[fh->neighbor(i)] = 1;
                        faces.push_back(fh->neighbor(i));
                    }
            }
            const bool in = !infinite && area > 1e-9 * f.area && in_domain(representative);
            for (const auto& fh : faces) fh->set_in_domain(in);
        }
    };
    mark_domain();
    CGAL::Delaunay_mesher_2<CDT, Criteria> mesher(cdt, Criteria(aspect_bound, max_area));
    mesher.init(true);
    // Constraints a hair apart over a long stretch (input the tracing did not foresee) would ask
    // for needles without end: past the budget the surface is given up (the caller meshes it
    // with its grid and says so).
    const double planned = max_area > 0 ? f.area / max_area : 0.0;
    const std::size_t budget = std::size_t(std::min(1e7, 20 * planned + 50.0 * double(chained.size()) + 1000));
    while (!mesher.is_refinement_done()) {
        mesher.step_by_step_refine_mesh();
        if (cdt.number_of_vertices() > budget) {
            out.over_budget = true;
            return out;
        }
    }

    // The neighbours' points on the shared outline, each put into the outline edge it lies on
    // (forced: a rounding error off the edge must still split it), after the refinement so the
    // seam is not split again (refining both sides in turn would chase each other's points).
    // Flips may then leave a triangle next to the seam above the area limit: such triangles get
    // their centroid (an interior point, so the seam stays as it is).
    if (!outline_points.empty()) {
        for (const V& p3 : outline_points) {
            const P2 q = f.to2(p3);
            for (auto e = cdt.finite_edges_begin(); e != cdt.finite_edges_end(); ++e) {
                if (!cdt.is_constrained(*e)) continue;
                const P2 a = to_p2(e->first->vertex(CDT::cw(e->second))->point());
                const P2 d = to_p2(e->first->vertex(CDT::ccw(e->second))->point()) - a;
                const double t = glm::dot(q - a, d) / glm::dot(d, d);
                if (t <= 1e-9 || t >= 1 - 1e-9 || glm::length(a + t * d - q) > snap) continue;
                cdt.insert(K::Point_2(q.x, q.y), CDT::EDGE, e->first, e->second);
                anchors.push_back(q);
                anchor3.push_back(p3);
                break;
            }
        }
        mark_domain();
        for (int round = 0; round < 16 && max_area > 0; ++round) {
            std::vector<K::Point_2> centroids;
            for (auto fit = cdt.finite_faces_begin(); fit != cdt.finite_faces_end(); ++fit)
                if (fit->is_in_domain() &&
                    CGAL::area(fit->vertex(0)->point(), fit->vertex(1)->point(), fit->vertex(2)->point()) > max_area)
                    centroids.push_back(
                        CGAL::centroid(fit->vertex(0)->point(), fit->vertex(1)->point(), fit->vertex(2)->point()));
            if (centroids.empty()) break;
            for (const auto& c : centroids) cdt.insert(c);
            mark_domain();
        }
    }
    std::map<std::pair<double, double>, std::size_t> anchor_at;
    for (std::size_t k = 0; k < anchors.size(); ++k) anchor_at[{anchors[k].x, anchors[k].y}] = k;
    std::map<CDT::Vertex_handle, std::uint32_t> index;
    auto point_index = [&](CDT::Vertex_handle v) {
        const auto [it, fresh] = index.emplace(v, std::uint32_t(out.points.size()));
        if (fresh) {
            const P2 p = to_p2(v->point());
            const auto a = anchor_at.find({p.x, p.y});
            out.points.push_back(a != anchor_at.end() ? anchor3[a->second] : f.to3(p));
        }
        return it->second;
    };
    for (auto fit = cdt.finite_faces_begin(); fit != cdt.finite_faces_end(); ++fit) {
        if (!fit->is_in_domain()) continue;
        out.triangles.push_back(
            {point_index(fit->vertex(0)), point_index(fit->vertex(1)), point_index(fit->vertex(2))});
    }
    return out;
}

}  // namespace bounce
