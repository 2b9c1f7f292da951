// SPDX-License-Identifier: MIT
#include "mesh/geometry/solid_cuts.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>

#include <CGAL/Bbox_3.h>
#include <CGAL/box_intersection_d.h>
#include <glm/geometric.hpp>

#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

using V = glm::dvec3;

constexpr std::size_t kMinFaces = 4;   // a tetrahedron
constexpr std::size_t kMaxFaces = 64;  // larger objects are meshes, rarely convex

struct Box3 {
    V lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
    void add(const V& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
};

/// Sutherland-Hodgman: the part of convex `poly` where dot(n, x) - d <= 0 (`keep_behind`) or
/// >= 0. Clipping keeps the polygon's winding.
std::vector<V> clip(const std::vector<V>& poly, const V& n, double d, bool keep_behind) {
    std::vector<V> out;
    const std::size_t m = poly.size();
    out.reserve(m + 1);
    for (std::size_t k = 0; k < m; ++k) {
        const V& a = poly[k];
        const V& b = poly[(k + 1) % m];
        double ha = glm::dot(n, a) - d, hb = glm::dot(n, b) - d;
        if (!keep_behind) {
            ha = -ha;
            hb = -hb;
        }
        if (ha <= 0) out.push_back(a);
        if ((ha < 0 && hb > 0) || (ha > 0 && hb < 0)) out.push_back(a + (ha / (ha - hb)) * (b - a));
    }
    return out;
}

bool is_convex(const std::vector<V>& poly, const V& normal) {
    const std::size_t m = poly.size();
    for (std::size_t k = 0; k < m; ++k) {
        const V e1 = poly[(k + 1) % m] - poly[k], e2 = poly[(k + 2) % m] - poly[(k + 1) % m];
        if (glm::dot(glm::cross(e1, e2), normal) < 0) return false;
    }
    return true;
}

/// True when each directed edge of the faces (corners snapped to a grid of `cell`) is matched
/// by the same edge the other way: a closed, consistently wound surface without T-junctions.
bool edges_pair_up(const Scene& scene, const std::vector<int>& faces, double cell) {
    using Key = std::array<long long, 3>;
    const auto key = [&](const V& p) {
        return Key{std::llround(p.x / cell), std::llround(p.y / cell), std::llround(p.z / cell)};
    };
    std::map<std::pair<Key, Key>, int> count;
    for (const int f : faces) {
        const auto& poly = scene.surfaces[std::size_t(f)].vertices;
        for (std::size_t k = 0; k < poly.size(); ++k) {
            const Key a = key(poly[k]), b = key(poly[(k + 1) % poly.size()]);
            if (a == b) continue;
            ++count[{a, b}];
            --count[{b, a}];
        }
    }
    return std::all_of(count.begin(), count.end(), [](const auto& e) { return e.second == 0; });
}

}  // namespace

std::vector<ConvexSolid> find_convex_solids(const Scene& scene) {
    std::map<std::pair<std::string, std::string>, std::vector<int>> objects;
    for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
        const Surface& f = scene.surfaces[s];
        objects[{f.where.file, f.object}].push_back(int(s));
    }
    std::vector<ConvexSolid> out;
    for (const auto& [key, members] : objects) {
        if (members.size() < kMinFaces || members.size() > kMaxFaces) continue;
        Box3 box;
        double total_area = 0.0;
        V area_sum(0.0);
        ConvexSolid solid;
        solid.surfaces = members;
        bool ok = true;
        for (const int s : members) {
            const auto& poly = scene.surfaces[std::size_t(s)].vertices;
            for (const V& p : poly) box.add(p);
            const V nn = newell_normal(poly);
            const double len = glm::length(nn);
            if (!(len > 0)) {
                ok = false;
                break;
            }
            area_sum += nn;
            total_area += 0.5 * len;
            solid.normals.push_back(nn / len);
            solid.offsets.push_back(glm::dot(nn / len, polygon_centroid(poly)));
        }
        if (!ok) continue;
        const double size = glm::length(box.hi - box.lo);
        // Closed: the area vectors of a closed surface sum to zero, and every edge is met once
        // each way (a tube's area vectors sum to zero too).
        if (!(size > 0) || glm::length(0.5 * area_sum) > 1e-6 * total_area) continue;
        if (!edges_pair_up(scene, members, 1e-9 * size)) continue;
        const double eps = 1e-7 * size;
        int behind = 0, in_front = 0;
        for (std::size_t f = 0; f < members.size(); ++f)
            for (const int s : members)
                for (const V& p : scene.surfaces[std::size_t(s)].vertices) {
                    const double h = glm::dot(solid.normals[f], p) - solid.offsets[f];
                    behind += h > eps;
                    in_front += h < -eps;
                }
        if (behind && in_front) continue;    // not convex
        if (!behind && !in_front) continue;  // flat
        solid.inward = in_front == 0;        // every vertex in front of every face: seen from inside
        out.push_back(std::move(solid));
    }
    return out;
}

namespace {

/// Per solid, the surfaces (of positive area) whose bounds meet its box, sorted; none for a
/// room (inward), which looks at every surface.
std::vector<std::vector<int>> near_surfaces(const Scene& scene, const std::vector<ConvexSolid>& solids,
                                            const std::vector<Box3>& bound, const std::vector<double>& area) {
    const std::size_t n = scene.surfaces.size();
    // CGAL's box intersection (Zomorodian and Edelsbrunner 2000): n log^3 n rather than solids x
    // surfaces.
    using IdBox =
        CGAL::Box_intersection_d::Box_with_handle_d<double, 3, std::size_t, CGAL::Box_intersection_d::ID_EXPLICIT>;
    const auto to_box = [](const Box3& b, double pad, std::size_t id) {
        return IdBox(CGAL::Bbox_3(b.lo.x - pad, b.lo.y - pad, b.lo.z - pad, b.hi.x + pad, b.hi.y + pad, b.hi.z + pad),
                     id);
    };
    std::vector<IdBox> solid_boxes, surface_boxes;
    for (std::size_t k = 0; k < solids.size(); ++k) {
        if (solids[k].inward) continue;
        Box3 sb;
        for (const int s : solids[k].surfaces)
            for (const V& p : scene.surfaces[std::size_t(s)].vertices) sb.add(p);
        solid_boxes.push_back(to_box(sb, 1e-7 * glm::length(sb.hi - sb.lo), k));
    }
    for (std::size_t s = 0; s < n; ++s)
        if (area[s] > 0) surface_boxes.push_back(to_box(bound[s], 0.0, s));
    std::vector<std::vector<int>> near(solids.size());
    if (!solid_boxes.empty() && !surface_boxes.empty())
        CGAL::box_intersection_d(solid_boxes.begin(), solid_boxes.end(), surface_boxes.begin(), surface_boxes.end(),
                                 [&](const IdBox& a, const IdBox& b) { near[a.handle()].push_back(int(b.handle())); });
    for (auto& v : near) std::sort(v.begin(), v.end());
    return near;
}

}  // namespace

std::vector<CoveredRegion> find_solid_cuts(const Scene& scene) {
    return find_solid_cuts(scene, find_convex_solids(scene));
}

std::vector<CoveredRegion> find_solid_cuts(const Scene& scene, const std::vector<ConvexSolid>& solids) {
    std::vector<CoveredRegion> out;
    if (solids.empty()) return out;
    const std::size_t n = scene.surfaces.size();
    std::vector<Box3> bound(n);
    std::vector<V> normal(n, V(0.0));
    std::vector<double> area(n, 0.0);
    std::vector<int> owner(n, -1);
    for (std::size_t s = 0; s < n; ++s) {
        for (const V& p : scene.surfaces[s].vertices) bound[s].add(p);
        const V nn = newell_normal(scene.surfaces[s].vertices);
        area[s] = 0.5 * glm::length(nn);
        if (area[s] > 0) normal[s] = nn / (2 * area[s]);
    }
    for (std::size_t k = 0; k < solids.size(); ++k)
        for (const int s : solids[k].surfaces) owner[std::size_t(s)] = int(k);

    const std::vector<std::vector<int>> near = near_surfaces(scene, solids, bound, area);

    // Objects by source and name, so a surface wholly outside a room counts as outside only
    // when another surface of its object reaches into the room.
    std::map<std::pair<std::string, std::string>, int> object_id;
    std::vector<int> object_of(n);
    for (std::size_t s = 0; s < n; ++s) {
        const Surface& f = scene.surfaces[s];
        object_of[s] = object_id.emplace(std::make_pair(f.where.file, f.object), int(object_id.size())).first->second;
    }

    for (std::size_t k = 0; k < solids.size(); ++k) {
        const ConvexSolid& solid = solids[k];
        Box3 sb;
        for (const int s : solid.surfaces)
            for (const V& p : scene.surfaces[std::size_t(s)].vertices) sb.add(p);
        const double size = glm::length(sb.hi - sb.lo);
        const double eps = 1e-7 * size;
        const auto clip_all = [&](std::vector<V> c, bool keep_behind) {
            for (std::size_t f = 0; f < solid.normals.size() && c.size() >= 3; ++f)
                c = clip(c, solid.normals[f], solid.offsets[f], keep_behind);
            return c;
        };
        // Convex pieces of each candidate surface (most are triangles or convex quads already);
        // empty for surfaces of the solid itself, degenerate ones, and those lying in one of
        // its planes (a floor under a box, a picture on a wall: the contact cuts' case).
        std::vector<std::vector<std::vector<V>>> pieces;  // per entry of looked_at
        std::vector<char> reaches_in(solid.inward ? object_id.size() : 0, 0);
        std::vector<int> all;
        if (solid.inward) {
            all.resize(n);
            for (std::size_t s = 0; s < n; ++s) all[s] = int(s);
        }
        std::vector<std::size_t> looked_at;
        for (const int si : solid.inward ? all : near[k]) {
            const auto s = std::size_t(si);
            if (owner[s] == int(k) || !(area[s] > 0)) continue;
            const auto& poly = scene.surfaces[s].vertices;
            bool in_plane = false;
            for (std::size_t f = 0; f < solid.normals.size() && !in_plane; ++f) {
                in_plane = true;
                for (const V& p : poly)
                    if (std::abs(glm::dot(solid.normals[f], p) - solid.offsets[f]) > eps) {
                        in_plane = false;
                        break;
                    }
            }
            if (in_plane) continue;
            looked_at.push_back(s);
            auto& mine = pieces.emplace_back();
            if (is_convex(poly, normal[s])) {
                mine.push_back(poly);
            } else {
                for (const auto& t : triangulate_polygon(poly)) mine.push_back({poly[t[0]], poly[t[1]], poly[t[2]]});
            }
            if (solid.inward)
                for (const auto& piece : mine) {
                    const auto inside = clip_all(piece, false);
                    if (inside.size() >= 3 && polygon_area(inside) > 1e-9 * area[s])
                        reaches_in[std::size_t(object_of[s])] = 1;
                }
        }
        for (std::size_t e = 0; e < looked_at.size(); ++e) {
            const std::size_t s = looked_at[e];
            const double min_area = 1e-9 * area[s];
            const auto keep = [&](std::vector<V>&& c) {
                if (c.size() >= 3 && polygon_area(c) > min_area) out.push_back({int(s), std::move(c), 0.0});
            };
            for (const auto& piece : pieces[e]) {
                if (!solid.inward) {
                    // Inside a box: behind every one of its (outward) face planes.
                    keep(clip_all(piece, true));
                } else if (reaches_in[std::size_t(object_of[s])]) {
                    // Outside a room: behind any one of its (inward) face planes. Overlapping
                    // pieces (beyond a corner) are subtracted one after the other.
                    for (std::size_t f = 0; f < solid.normals.size(); ++f)
                        keep(clip(piece, solid.normals[f], solid.offsets[f], true));
                }
            }
        }
    }
    return out;
}

}  // namespace bounce
