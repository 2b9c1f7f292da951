// SPDX-License-Identifier: MIT
#include "mesh/meshing/element_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "mesh/scene/polygon.h"

namespace bounce {

ElementTree::ElementTree(std::vector<Patch> roots) : m_roots(std::move(roots)) {
    m_nodes.reserve(m_roots.size());
    m_geometry.reserve(m_roots.size());
    for (std::uint32_t r = 0; r < m_roots.size(); ++r) {
        Node n;
        n.root = r;
        n.corner_count = m_roots[r].vertex_count;
        if (n.corner_count == 4)
            n.corners = {glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(1, 1), glm::dvec2(0, 1)};
        else if (n.corner_count == 3)
            n.corners = {glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(0, 1), glm::dvec2(0, 0)};
        else
            throw std::invalid_argument("element tree: a root patch must be a triangle or a quad");
        m_nodes.push_back(n);
        m_geometry.push_back(m_roots[r]);  // the root itself, bit for bit
    }
}

glm::dvec3 ElementTree::point(std::uint32_t r, const glm::dvec2& uv) const {
    const Patch& p = m_roots[r];
    const auto& c = p.vertices;
    const double u = uv.x, v = uv.y;
    if (p.vertex_count == 4) return (1 - u) * (1 - v) * c[0] + u * (1 - v) * c[1] + u * v * c[2] + (1 - u) * v * c[3];
    return c[0] + u * (c[1] - c[0]) + v * (c[2] - c[0]);
}

Patch ElementTree::make_geometry(std::uint32_t root, int count, const std::array<glm::dvec2, 4>& corners) const {
    const Patch& r = m_roots[root];
    Patch p = r;
    p.vertex_count = count;
    for (int k = 0; k < count; ++k) p.vertices[k] = point(root, corners[k]);
    const glm::dvec3 n = newell_normal(p.polygon());
    p.area = 0.5 * glm::length(n);
    p.normal = r.normal;  // the root's plane: children stay exactly coplanar with it
    p.centre = polygon_centroid(p.polygon());
    return p;
}

std::size_t ElementTree::split(std::size_t i) {
    if (i >= m_nodes.size() || !m_nodes[i].leaf()) throw std::invalid_argument("element tree: split a leaf");
    const Node parent = m_nodes[i];
    const auto& c = parent.corners;
    auto mid = [](const glm::dvec2& a, const glm::dvec2& b) { return 0.5 * (a + b); };
    std::array<std::array<glm::dvec2, 4>, 4> kids;
    if (parent.corner_count == 4) {
        const glm::dvec2 m01 = mid(c[0], c[1]), m12 = mid(c[1], c[2]), m23 = mid(c[2], c[3]), m30 = mid(c[3], c[0]);
        const glm::dvec2 centre = mid(m01, m23);
        kids = {
            {{c[0], m01, centre, m30}, {m01, c[1], m12, centre}, {centre, m12, c[2], m23}, {m30, centre, m23, c[3]}}};
    } else {
        const glm::dvec2 m01 = mid(c[0], c[1]), m12 = mid(c[1], c[2]), m20 = mid(c[2], c[0]);
        kids = {{{c[0], m01, m20, {}}, {m01, c[1], m12, {}}, {m20, m12, c[2], {}}, {m12, m20, m01, {}}}};
    }
    const std::size_t first = m_nodes.size();
    for (int k = 0; k < 4; ++k) {
        Node n;
        n.root = parent.root;
        n.parent = std::int32_t(i);
        n.level = parent.level + 1;
        n.corner_count = parent.corner_count;
        n.corners = kids[k];
        m_nodes.push_back(n);
        m_geometry.push_back(make_geometry(n.root, n.corner_count, n.corners));
    }
    m_nodes[i].first_child = std::int32_t(first);
    return first;
}

std::vector<std::uint32_t> ElementTree::leaves() const {
    std::vector<std::uint32_t> out, stack;
    for (std::uint32_t r = m_roots.size(); r-- > 0;) stack.push_back(r);
    while (!stack.empty()) {
        const std::uint32_t i = stack.back();
        stack.pop_back();
        if (m_nodes[i].leaf()) {
            out.push_back(i);
        } else {
            for (int k = 3; k >= 0; --k) stack.push_back(std::uint32_t(m_nodes[i].first_child + k));
        }
    }
    return out;
}

bool ElementTree::contains(const Node& n, const glm::dvec2& uv) {
    // Convex polygon in parameter space: uv is left of (or on) every edge.
    for (int k = 0; k < n.corner_count; ++k) {
        const glm::dvec2 a = n.corners[k], b = n.corners[(k + 1) % n.corner_count];
        if ((b.x - a.x) * (uv.y - a.y) - (b.y - a.y) * (uv.x - a.x) < -1e-15) return false;
    }
    return true;
}

std::uint32_t ElementTree::locate(std::uint32_t r, const glm::dvec2& uv) const {
    std::uint32_t i = r;
    while (!m_nodes[i].leaf()) {
        std::uint32_t next = std::uint32_t(m_nodes[i].first_child);
        bool found = false;
        for (int k = 0; k < 4 && !found; ++k)
            if (contains(m_nodes[std::size_t(m_nodes[i].first_child + k)], uv)) {
                next = std::uint32_t(m_nodes[i].first_child + k);
                found = true;
            }
        i = next;
    }
    return i;
}

double ElementTree::weld() const {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const auto& p : m_roots)
        for (int k = 0; k < p.vertex_count; ++k) lo = glm::min(lo, p.vertices[k]), hi = glm::max(hi, p.vertices[k]);
    return 1e-9 * (m_roots.empty() ? 1.0 : glm::length(hi - lo));
}

PatchMesh ElementTree::conforming_mesh(const std::vector<std::uint32_t>& leaves) const {
    // Weld points within each surface (weld()).
    const double weld = this->weld();
    using Cell = std::tuple<int, std::int64_t, std::int64_t, std::int64_t>;
    std::map<Cell, std::vector<std::uint32_t>> weld_grid;
    std::vector<glm::dvec3> points;
    std::vector<int> point_surface;
    auto cell_of = [&](int s, const glm::dvec3& p, double h) {
        return Cell{s, std::int64_t(std::floor(p.x / h)), std::int64_t(std::floor(p.y / h)),
                    std::int64_t(std::floor(p.z / h))};
    };
    auto weld_point = [&](int s, const glm::dvec3& p) {
        const Cell c = cell_of(s, p, weld);
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dz = -1; dz <= 1; ++dz) {
                    auto it = weld_grid.find(Cell{s, std::get<1>(c) + dx, std::get<2>(c) + dy, std::get<3>(c) + dz});
                    if (it == weld_grid.end()) continue;
                    for (const std::uint32_t q : it->second)
                        if (glm::length(points[q] - p) <= weld) return q;
                }
        const auto id = std::uint32_t(points.size());
        points.push_back(p);
        point_surface.push_back(s);
        weld_grid[c].push_back(id);
        return id;
    };
    std::vector<std::vector<std::uint32_t>> corner_ids(leaves.size());
    std::vector<double> edge_lengths;
    for (std::size_t i = 0; i < leaves.size(); ++i) {
        const Patch& g = m_geometry[leaves[i]];
        for (int k = 0; k < g.vertex_count; ++k) {
            corner_ids[i].push_back(weld_point(g.surface, g.vertices[k]));
            edge_lengths.push_back(glm::length(g.vertices[(k + 1) % g.vertex_count] - g.vertices[k]));
        }
    }
    // T-vertices: points of a surface lying strictly inside an edge of one of its leaves. The
    // grid's cell is the median leaf edge (at least 16 weld, so a point near an edge is in a
    // neighbour of a cell the edge crosses): cells of the shortest edge made the long edges of
    // coarse leaves search millions of cells at --max-level 4.
    double h = 16 * weld;
    if (!edge_lengths.empty()) {
        auto mid = edge_lengths.begin() + std::ptrdiff_t(edge_lengths.size() / 2);
        std::nth_element(edge_lengths.begin(), mid, edge_lengths.end());
        h = std::max(h, *mid);
    }
    std::map<Cell, std::vector<std::uint32_t>> grid;
    for (std::uint32_t q = 0; q < points.size(); ++q) grid[cell_of(point_surface[q], points[q], h)].push_back(q);
    std::vector<std::vector<std::uint32_t>> polygon_ids(leaves.size());
    std::vector<Cell> cells;
    for (std::size_t i = 0; i < leaves.size(); ++i) {
        const Patch& g = m_geometry[leaves[i]];
        for (int k = 0; k < g.vertex_count; ++k) {
            const std::uint32_t ia = corner_ids[i][k], ib = corner_ids[i][(k + 1) % g.vertex_count];
            const glm::dvec3 a = points[ia], b = points[ib];
            polygon_ids[i].push_back(ia);
            const double len = glm::length(b - a);
            std::vector<std::pair<double, std::uint32_t>> on_edge;
            // The cells to search: those of the edge's bounding box when few, else the cells
            // around points every h/2 along the edge. A point within 4 weld (< h/4) of the edge
            // lies in a neighbour of a cell the edge passes through; the box of a long slanted
            // edge holds (length / h)^2 cells.
            cells.clear();
            const Cell c0 = cell_of(g.surface, glm::min(a, b) - weld, h),
                       c1 = cell_of(g.surface, glm::max(a, b) + weld, h);
            const double box = double(std::get<1>(c1) - std::get<1>(c0) + 1) *
                               double(std::get<2>(c1) - std::get<2>(c0) + 1) *
                               double(std::get<3>(c1) - std::get<3>(c0) + 1);
            const auto steps = std::int64_t(std::ceil(2.0 * len / h));
            if (box <= 27.0 * double(steps + 1)) {
                for (auto x = std::get<1>(c0); x <= std::get<1>(c1); ++x)
                    for (auto y = std::get<2>(c0); y <= std::get<2>(c1); ++y)
                        for (auto z = std::get<3>(c0); z <= std::get<3>(c1); ++z)
                            cells.emplace_back(g.surface, x, y, z);
            } else {
                for (std::int64_t s = 0; s <= steps; ++s) {
                    const Cell c = cell_of(g.surface, a + (double(s) / double(steps)) * (b - a), h);
                    for (std::int64_t dx = -1; dx <= 1; ++dx)
                        for (std::int64_t dy = -1; dy <= 1; ++dy)
                            for (std::int64_t dz = -1; dz <= 1; ++dz)
                                cells.emplace_back(g.surface, std::get<1>(c) + dx, std::get<2>(c) + dy,
                                                   std::get<3>(c) + dz);
                }
                std::sort(cells.begin(), cells.end());
                cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
            }
            for (const Cell& cell : cells) {
                auto it = grid.find(cell);
                if (it == grid.end()) continue;
                for (const std::uint32_t q : it->second) {
                    if (q == ia || q == ib) continue;
                    const double t = glm::dot(points[q] - a, b - a) / (len * len);
                    if (t <= 1e-9 || t >= 1 - 1e-9) continue;
                    if (glm::length(a + t * (b - a) - points[q]) <= 4 * weld) on_edge.emplace_back(t, q);
                }
            }
            std::sort(on_edge.begin(), on_edge.end());
            for (const auto& e : on_edge) polygon_ids[i].push_back(e.second);
        }
    }
    std::vector<Patch> patches;
    patches.reserve(leaves.size());
    for (const std::uint32_t l : leaves) patches.push_back(m_geometry[l]);
    return PatchMesh(std::move(patches), points, polygon_ids);
}

std::vector<double> ElementTree::leaf_luminance_spread(std::span<const Rgb> values) const {
    const std::size_t n = size();
    std::vector<double> lo(n), hi(n);
    for (std::size_t i = n; i-- > 0;) {  // children follow their parent in the node order
        const Node& node = m_nodes[i];
        if (node.leaf()) {
            lo[i] = hi[i] = values[i].luminance();
            continue;
        }
        lo[i] = std::numeric_limits<double>::infinity();
        hi[i] = -lo[i];
        for (int c = 0; c < 4; ++c) {
            lo[i] = std::min(lo[i], lo[std::size_t(node.first_child + c)]);
            hi[i] = std::max(hi[i], hi[std::size_t(node.first_child + c)]);
        }
    }
    for (std::size_t i = 0; i < n; ++i) hi[i] -= lo[i];
    return hi;
}

}  // namespace bounce
