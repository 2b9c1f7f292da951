// SPDX-License-Identifier: MIT
#include "mesh/meshing/open_mesh_faces.h"

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

namespace bounce {

ManifoldFaces manifold_faces(std::size_t point_count, const std::vector<std::vector<std::uint32_t>>& faces) {
    std::vector<std::size_t> first(faces.size() + 1, 0);  // corner index of face f's corner 0
    for (std::size_t f = 0; f < faces.size(); ++f) first[f + 1] = first[f] + faces[f].size();
    std::vector<std::size_t> root(first.back());
    for (std::size_t c = 0; c < root.size(); ++c) root[c] = c;
    auto find = [&](std::size_t c) {
        while (root[c] != c) c = root[c] = root[root[c]];
        return c;
    };
    auto join = [&](std::size_t a, std::size_t b) { root[find(a)] = find(b); };
    struct Side {
        std::uint64_t key;   // the edge's points, smaller first
        std::size_t corner;  // the corner the side leaves from
        bool forward;        // runs from the smaller point to the larger
    };
    // A face that names a point twice (corners of a sliver welded together) takes copies of
    // all its points: it joins nothing.
    std::vector<bool> alone(faces.size(), false);
    for (std::size_t f = 0; f < faces.size(); ++f) {
        std::vector<std::uint32_t> ids = faces[f];
        std::sort(ids.begin(), ids.end());
        alone[f] = std::adjacent_find(ids.begin(), ids.end()) != ids.end();
    }
    std::vector<Side> sides;
    sides.reserve(root.size());
    for (std::size_t f = 0; f < faces.size(); ++f)
        for (std::size_t k = 0; k < faces[f].size() && !alone[f]; ++k) {
            const std::uint32_t u = faces[f][k], w = faces[f][(k + 1) % faces[f].size()];
            sides.push_back({std::uint64_t(std::min(u, w)) << 32 | std::max(u, w), first[f] + k, u < w});
        }
    std::sort(sides.begin(), sides.end(),
              [](const Side& a, const Side& b) { return a.key != b.key ? a.key < b.key : a.corner < b.corner; });
    auto next_corner = [&](std::size_t c) {  // the corner after c in its face
        const std::size_t f = std::size_t(std::upper_bound(first.begin(), first.end(), c) - first.begin()) - 1;
        return c + 1 < first[f + 1] ? c + 1 : first[f];
    };
    for (std::size_t i = 0; i < sides.size();) {
        std::size_t j = i;
        while (j < sides.size() && sides[j].key == sides[i].key) ++j;
        if (j - i == 2 && sides[i].forward != sides[i + 1].forward) {
            // Side c: p -> q in one face, side d: q -> p in the other; join their corners at p and at q.
            const std::size_t c = sides[i].corner, d = sides[i + 1].corner;
            join(c, next_corner(d));
            join(next_corner(c), d);
        }
        i = j;
    }
    ManifoldFaces out;
    out.point_of.resize(point_count);
    for (std::size_t v = 0; v < point_count; ++v) out.point_of[v] = std::uint32_t(v);
    std::vector<std::size_t> owner(point_count, SIZE_MAX);   // the fan root that keeps the point itself
    std::unordered_map<std::size_t, std::uint32_t> copy_of;  // fan root -> its copy of the point
    out.faces.resize(faces.size());
    std::vector<bool> counted(point_count, false);
    for (std::size_t f = 0; f < faces.size(); ++f)
        for (std::size_t k = 0; k < faces[f].size(); ++k) {
            const std::uint32_t v = faces[f][k];
            const std::size_t r = find(first[f] + k);
            std::uint32_t id = v;
            if (alone[f]) {
                id = std::uint32_t(out.point_of.size());
                out.point_of.push_back(v);
                if (!counted[v]) ++out.split_points;
                counted[v] = true;
            } else if (owner[v] == SIZE_MAX) {
                owner[v] = r;
            } else if (owner[v] != r) {
                const auto [it, made] = copy_of.try_emplace(r, std::uint32_t(out.point_of.size()));
                if (made) {
                    out.point_of.push_back(v);
                    if (!counted[v]) ++out.split_points;
                    counted[v] = true;
                }
                id = it->second;
            }
            out.faces[f].push_back(id);
        }
    return out;
}

OpenPatchMesh::FaceHandle add_face_or_alone(OpenPatchMesh& mesh, const std::vector<OpenPatchMesh::VertexHandle>& vh,
                                            bool& alone) {
    const auto f = mesh.add_face(vh);
    if (f.is_valid()) return f;
    std::vector<OpenPatchMesh::VertexHandle> own;
    for (const auto& h : vh) {
        const OpenPatchMesh::Point q = mesh.point(h);  // a copy: add_vertex may move the points
        own.push_back(mesh.add_vertex(q));
    }
    alone = true;
    return mesh.add_face(own);
}

std::vector<int> drop_unused_vertices(OpenPatchMesh& mesh) {
    bool any = false;
    for (auto v : mesh.vertices()) any = any || mesh.is_isolated(v);
    if (!any) return {};
    OpenPatchMesh compact;
    std::vector<OpenPatchMesh::VertexHandle> to(mesh.n_vertices());
    for (auto v : mesh.vertices())
        if (!mesh.is_isolated(v)) {
            const OpenPatchMesh::Point q = mesh.point(v);
            to[std::size_t(v.idx())] = compact.add_vertex(q);
        }
    OpenMesh::FPropHandleT<int> surface_in, surface_out;
    const bool has_surface = mesh.get_property_handle(surface_in, "f:surface");
    if (has_surface) compact.add_property(surface_out, "f:surface");
    std::vector<OpenPatchMesh::VertexHandle> vh;
    for (auto f : mesh.faces()) {
        vh.clear();
        for (auto v : mesh.fv_range(f)) vh.push_back(to[std::size_t(v.idx())]);
        bool alone = false;
        const auto g = add_face_or_alone(compact, vh, alone);
        if (!g.is_valid() || g.idx() != f.idx()) throw std::runtime_error("patch mesh: compacting the vertices failed");
        if (has_surface) compact.property(surface_out, g) = mesh.property(surface_in, f);
    }
    mesh = compact;
    std::vector<int> index(to.size(), -1);
    for (std::size_t v = 0; v < to.size(); ++v)
        if (to[v].is_valid()) index[v] = to[v].idx();
    return index;
}

}  // namespace bounce
