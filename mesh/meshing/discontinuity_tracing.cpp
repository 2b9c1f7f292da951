// SPDX-License-Identifier: MIT
// Tracing the EV and VE critical surfaces of discontinuity meshing (discontinuity_mesh.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <map>
#include <sstream>

#include <glm/geometric.hpp>

#include "mesh/geometry/surface_tree.h"
#include "mesh/meshing/discontinuity_mesh.h"
#include "mesh/scene/polygon.h"
#include "mesh/scene/surface_frame.h"

namespace bounce {
namespace {

using namespace discontinuity;

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

/// The tracing of one scene: each emitter's critical surfaces with the occluders onto each
/// receiver, then the overlap warning and the cap (trace_discontinuities).
class Tracer {
public:
    /// `diag`: the diagonal of the scene's box (> 0), the scale of every tolerance.
    Tracer(const Scene& scene, double diag);
    TracedDiscontinuities run(std::size_t max_per_surface);

private:
    /// EV: the plane through an emitter edge and an occluder vertex, onto receiver r.
    void trace_ev(std::size_t e, std::size_t r);
    /// VE: the plane through an emitter vertex and an occluder edge, onto receiver r.
    void trace_ve(std::size_t e, std::size_t r);
    /// Whether the segment from q to `to` meets no surface but those in `ignore` (sorted).
    bool line_open(const V& q, const V& to, const std::vector<int>& ignore) const;
    /// The visible parts of [t0, t1] of a + t (b - a): visibility at kSamples interior points,
    /// each change of answer located by bisection; the ends keep the answer of their nearest
    /// sample (a point on the receiver's outline would ask about the wall beside it).
    template <class OpenAt>
    std::vector<std::pair<double, double>> visible_parts(double t0, double t1, const OpenAt& open_at) const;
    /// Adds the trace pa-pb on receiver r where it is inside r's outline, outside its covered
    /// regions and open_from(point) says the critical line from that point is unobstructed.
    template <class OpenFrom>
    void add(std::size_t r, const V& pa, const V& pb, DiscontinuitySegment::Kind kind, int emitter, int occluder,
             const OpenFrom& open_from);
    /// The receiver, the emitter and every face at the given welded points, sorted.
    std::vector<int> ignored(std::size_t r, std::size_t e, std::initializer_list<std::size_t> points) const;
    /// One warning line for coplanar overlapping faces.
    void warn_overlaps();
    /// Keeps the longest max_per_surface boundaries per surface, with one warning line.
    void cap(std::size_t max_per_surface);

    static constexpr int kSamples = 16;

    const Scene& scene;
    const std::size_t n;
    const double diag, eps;
    // A vertex or a whole edge this close to a receiver rests on it (the contact tolerance of
    // mesh/geometry/contact_cuts.h): its shadow there is the contact outline, which the contact cut
    // already follows, and a trace of it would run a hair beside that outline (a sliver the
    // refinement would have to fill with needle-sized triangles).
    const double contact;
    const double shift;  // off the receiver and the emitter at a critical line's ends
    std::vector<Frame> frames;
    std::vector<bool> is_emitter;
    Occluders occ;
    std::vector<std::vector<P2>> outline;             // per receiver, in its frame
    std::vector<std::vector<std::vector<P2>>> holes;  // per receiver: its covered regions
    // A boundary exists only where its critical line, from the receiver through the occluder's
    // vertex or edge to the emitter, is itself unobstructed (Lischinski et al. 1992 clip their
    // wedges by the scene the same way): behind a third object the emitter is hidden anyway.
    const SurfaceTree tree;
    TracedDiscontinuities out;
};

Tracer::Tracer(const Scene& scene_, double diag_)
    : scene(scene_),
      n(scene_.surfaces.size()),
      diag(diag_),
      eps(1e-9 * diag_),
      contact(5e-4 * diag_),
      shift(1e-6 * diag_),
      frames(n),
      is_emitter(n, false),
      outline(n),
      holes(n),
      tree(scene_) {
    out.per_surface.resize(n);
    for (std::size_t s = 0; s < n; ++s) {
        frames[s] = frame_of(scene.surfaces[s].vertices);
        const int m = scene.surfaces[s].material;
        is_emitter[s] = m >= 0 && std::size_t(m) < scene.materials.size() &&
                        scene.materials[std::size_t(m)].emission.max() > 0 && frames[s].valid;
    }
    occ = weld_occluders(scene, is_emitter, 1e-7 * diag);
    // Receivers' outlines and covered regions in their own frames.
    for (std::size_t s = 0; s < n; ++s)
        if (frames[s].valid)
            for (const V& p : scene.surfaces[s].vertices) outline[s].push_back(frames[s].to2(p));
    for (const auto& c : scene.covered)
        if (c.surface >= 0 && std::size_t(c.surface) < n && frames[std::size_t(c.surface)].valid) {
            std::vector<P2> h;
            for (const V& p : c.polygon) h.push_back(frames[std::size_t(c.surface)].to2(p));
            holes[std::size_t(c.surface)].push_back(std::move(h));
        }
}

bool Tracer::line_open(const V& q, const V& to, const std::vector<int>& ignore) const {
    const V d = to - q;
    const double len = glm::length(d);
    if (!(len > 2 * shift)) return true;
    for (const int hit : tree.on_segment(q + d * (shift / len), to - d * (shift / len)))
        if (!std::binary_search(ignore.begin(), ignore.end(), hit)) return false;
    return true;
}

template <class OpenAt>
std::vector<std::pair<double, double>> Tracer::visible_parts(double t0, double t1, const OpenAt& open_at) const {
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
}

template <class OpenFrom>
void Tracer::add(std::size_t r, const V& pa, const V& pb, DiscontinuitySegment::Kind kind, int emitter, int occluder,
                 const OpenFrom& open_from) {
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
}

std::vector<int> Tracer::ignored(std::size_t r, std::size_t e, std::initializer_list<std::size_t> points) const {
    std::vector<int> out_ids = {int(r), int(e)};
    for (const std::size_t p : points)
        for (const auto& [fi, c] : occ.around[p]) out_ids.push_back(occ.faces[std::size_t(fi)].surface);
    std::sort(out_ids.begin(), out_ids.end());
    return out_ids;
}

TracedDiscontinuities Tracer::run(std::size_t max_per_surface) {
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
            trace_ev(e, r);
            trace_ve(e, r);
        }
    }
    warn_overlaps();
    cap(max_per_surface);
    return std::move(out);
}

void Tracer::trace_ev(std::size_t e, std::size_t r) {
    const Frame& E = frames[e];
    const Frame& R = frames[r];
    const auto& light = scene.surfaces[e].vertices;
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
}

void Tracer::trace_ve(std::size_t e, std::size_t r) {
    const Frame& E = frames[e];
    const Frame& R = frames[r];
    const auto& light = scene.surfaces[e].vertices;
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

// Coplanar overlapping faces facing the same way: each casts and receives boundaries of its
// own, and the overlap is meshed (and lit) twice. Not an error (a decal on a wall), but worth
// one line.
void Tracer::warn_overlaps() {
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
}

// The longest boundaries are kept (they carry the most shadow edge).
void Tracer::cap(std::size_t max_per_surface) {
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
}

}  // namespace

TracedDiscontinuities trace_discontinuities(const Scene& scene, std::size_t max_per_surface) {
    const std::size_t n = scene.surfaces.size();
    V lo(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const auto& s : scene.surfaces)
        for (const V& p : s.vertices) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    const double diag = n ? glm::length(hi - lo) : 0.0;
    if (!(diag > 0) || !std::isfinite(diag)) {
        TracedDiscontinuities none;
        none.per_surface.resize(n);
        return none;
    }
    return Tracer(scene, diag).run(max_per_surface);
}

}  // namespace bounce
