// SPDX-License-Identifier: MIT
// Triangulating a surface along its traced discontinuities (discontinuity_mesh.h): CGAL's
// constrained Delaunay triangulation and Delaunay mesher.
#include <algorithm>
#include <cmath>
#include <map>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <glm/geometric.hpp>

#include "mesh/meshing/discontinuity_mesh.h"
#include "mesh/scene/surface_frame.h"

namespace bounce {
namespace {

using namespace discontinuity;

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

template <class Point>
P2 to_p2(const Point& p) {
    return {CGAL::to_double(p.x()), CGAL::to_double(p.y())};
}

/// A surface's outline, covered regions and traced segments in its frame, as the points
/// (anchors) and constraints of its triangulation.
struct Constraints {
    const Frame& f;
    // Points closer than this are one point: rounding in the tracing must not leave slivers
    // that the Delaunay refinement would chase down to their width.
    double snap = 0.0;
    std::vector<P2> anchors;
    std::vector<V> anchor3;  // the 3D point of each anchor (corners keep their own coordinates)
    std::vector<P2> outline;
    std::vector<std::vector<P2>> holes;                      // covered regions
    std::vector<std::pair<std::size_t, std::size_t>> edges;  // between anchors

    /// The anchor at p (an existing one within snap), added with 3D point p3 when new.
    std::size_t anchor(const P2& p, const V& p3) {
        for (std::size_t k = 0; k < anchors.size(); ++k)
            if (glm::length(anchors[k] - p) <= snap) return k;
        anchors.push_back(p);
        anchor3.push_back(p3);
        return anchors.size() - 1;
    }
};

/// The outline of surface `surface`, the covered outlines where they lie on it, and the segments.
void add_constraints(const Scene& scene, int surface, const std::vector<DiscontinuitySegment>& segments,
                     Constraints& c) {
    const Frame& f = c.f;
    const auto& poly = scene.surfaces[std::size_t(surface)].vertices;
    auto anchor = [&](const P2& p, const V& p3) { return c.anchor(p, p3); };
    auto& outline = c.outline;
    auto& constraints = c.edges;
    for (const V& p : poly) outline.push_back(f.to2(p));
    std::vector<std::size_t> corner;
    for (std::size_t k = 0; k < poly.size(); ++k) corner.push_back(anchor(outline[k], poly[k]));
    for (std::size_t k = 0; k < corner.size(); ++k)
        if (corner[k] != corner[(k + 1) % corner.size()])
            constraints.emplace_back(corner[k], corner[(k + 1) % corner.size()]);

    // Covered outlines, only where they lie on the surface.
    for (const auto& covered : scene.covered) {
        if (covered.surface != surface) continue;
        std::vector<P2> h;
        for (const V& p : covered.polygon) h.push_back(f.to2(p));
        for (std::size_t k = 0; k < h.size(); ++k) {
            const P2 a = h[k], b = h[(k + 1) % h.size()];
            for (const auto& [t0, t1] : inside_intervals(a, b, outline)) {
                const P2 qa = a + t0 * (b - a), qb = a + t1 * (b - a);
                const std::size_t ia = anchor(qa, f.to3(qa)), ib = anchor(qb, f.to3(qb));
                if (ia != ib) constraints.emplace_back(ia, ib);
            }
        }
        c.holes.push_back(std::move(h));
    }
    for (const auto& s : segments) {
        const P2 a = f.to2(s.a), b = f.to2(s.b);
        const std::size_t ia = anchor(a, f.to3(a)), ib = anchor(b, f.to3(b));
        if (ia != ib) constraints.emplace_back(ia, ib);
    }
}

/// The constraints with each passing within the snapping distance of an anchor made to go
/// through it, so no anchor sits a rounding error off a constraint (a feature of that size,
/// which the refinement would resolve with ever smaller triangles).
std::vector<std::pair<std::size_t, std::size_t>> chained_constraints(const Constraints& c) {
    const auto& anchors = c.anchors;
    const double snap = c.snap;
    std::vector<std::pair<std::size_t, std::size_t>> chained;
    for (const auto& [ia, ib] : c.edges) {
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
    return chained;
}

// The domain: inside the outline, outside every covered region. Marked per region between
// constraints (traced constraints cut the surface into many regions, so seeds would not do),
// each by the centroid of its largest triangle: a mark must agree with the constraints (an
// outline bent by a hair at a chained point puts a needle on the other side of the straight
// outline, and a needle marked apart from its neighbours is refined without end). Regions
// of no area (between constraints a rounding error apart) are left out.
void mark_domain(CDT& cdt, const Constraints& cons) {
    const double f_area = cons.f.area;
    auto in_domain = [&](const P2& p) {
        if (!inside_polygon(p, cons.outline)) return false;
        for (const auto& h : cons.holes)
            if (inside_polygon(p, h)) return false;
        return true;
    };
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
        const bool in = !infinite && area > 1e-9 * f_area && in_domain(representative);
        for (const auto& fh : faces) fh->set_in_domain(in);
    }
}

// The neighbours' points on the shared outline, each put into the outline edge it lies on
// (forced: a rounding error off the edge must still split it), after the refinement so the
// seam is not split again (refining both sides in turn would chase each other's points).
// Flips may then leave a triangle next to the seam above the area limit: such triangles get
// their centroid (an interior point, so the seam stays as it is).
void insert_outline_points(CDT& cdt, Constraints& cons, const std::vector<V>& outline_points, double max_area) {
    const Frame& f = cons.f;
    const double snap = cons.snap;
    for (const V& p3 : outline_points) {
        const P2 q = f.to2(p3);
        for (auto e = cdt.finite_edges_begin(); e != cdt.finite_edges_end(); ++e) {
            if (!cdt.is_constrained(*e)) continue;
            const P2 a = to_p2(e->first->vertex(CDT::cw(e->second))->point());
            const P2 d = to_p2(e->first->vertex(CDT::ccw(e->second))->point()) - a;
            const double t = glm::dot(q - a, d) / glm::dot(d, d);
            if (t <= 1e-9 || t >= 1 - 1e-9 || glm::length(a + t * d - q) > snap) continue;
            cdt.insert(K::Point_2(q.x, q.y), CDT::EDGE, e->first, e->second);
            cons.anchors.push_back(q);
            cons.anchor3.push_back(p3);
            break;
        }
    }
    mark_domain(cdt, cons);
    for (int round = 0; round < 16 && max_area > 0; ++round) {
        std::vector<K::Point_2> centroids;
        for (auto fit = cdt.finite_faces_begin(); fit != cdt.finite_faces_end(); ++fit)
            if (fit->is_in_domain() &&
                CGAL::area(fit->vertex(0)->point(), fit->vertex(1)->point(), fit->vertex(2)->point()) > max_area)
                centroids.push_back(
                    CGAL::centroid(fit->vertex(0)->point(), fit->vertex(1)->point(), fit->vertex(2)->point()));
        if (centroids.empty()) break;
        for (const auto& c : centroids) cdt.insert(c);
        mark_domain(cdt, cons);
    }
}

/// The triangles in the domain, with the points they use (anchors at their 3D points).
void collect_triangles(const CDT& cdt, const Constraints& c, SurfaceTriangulation& out) {
    const auto& anchors = c.anchors;
    const auto& anchor3 = c.anchor3;
    const Frame& f = c.f;
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
}

}  // namespace

SurfaceTriangulation triangulate_surface(const Scene& scene, int surface,
                                         const std::vector<DiscontinuitySegment>& segments, double max_area,
                                         double aspect_bound, const std::vector<glm::dvec3>& outline_points) {
    SurfaceTriangulation out;
    const auto& poly = scene.surfaces[std::size_t(surface)].vertices;
    const Frame f = frame_of(poly);
    if (!f.valid) return out;
    const double size = std::sqrt(f.area);
    Constraints c{f, 1e-6 * size, {}, {}, {}, {}, {}};
    add_constraints(scene, surface, segments, c);
    const std::vector<std::pair<std::size_t, std::size_t>> chained = chained_constraints(c);

    CDT cdt;
    std::vector<CDT::Vertex_handle> handle;
    for (const P2& p : c.anchors) handle.push_back(cdt.insert(K::Point_2(p.x, p.y)));
    for (const auto& [ia, ib] : chained)
        if (handle[ia] != handle[ib]) cdt.insert_constraint(handle[ia], handle[ib]);
    if (cdt.dimension() < 2) return out;

    mark_domain(cdt, c);
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
    if (!outline_points.empty()) insert_outline_points(cdt, c, outline_points, max_area);
    collect_triangles(cdt, c, out);
    return out;
}

}  // namespace bounce
