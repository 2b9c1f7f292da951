// SPDX-License-Identifier: MIT
#include "mesh/meshing/patch_mesh.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "mesh/geometry/contact_cuts.h"
#include "mesh/meshing/discontinuity_mesh.h"
#include "mesh/meshing/open_mesh_faces.h"
#include "mesh/scene/input_error.h"
#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

using V = glm::dvec3;

bool convex_quad(std::span<const V> q) {
    const V n = newell_normal(q);
    for (int k = 0; k < 4; ++k)
        if (glm::dot(glm::cross(q[(k + 1) % 4] - q[k], q[(k + 2) % 4] - q[(k + 1) % 4]), n) <= 0) return false;
    return true;
}

/// A piece of a surface that is cut by a regular grid: a convex quad (bilinear grid nu x nv)
/// or a triangle (k x k similar triangles).
struct Piece {
    std::vector<V> corners;
    int nu = 1, nv = 1;
    std::size_t count() const { return corners.size() == 4 ? std::size_t(nu) * nv : std::size_t(nu) * nu; }
};

int cuts(double length, double h) {
    if (h <= 0) return 1;
    const double n = std::ceil(length / h - 1e-9);
    return n < 1 ? 1 : (n > 1e6 ? 1000000 : int(n));
}

}  // namespace

std::string Patch::to_string() const {
    std::ostringstream s;
    s << "Patch{surface " << surface << ", area " << area << ", centre (" << centre.x << ", " << centre.y << ", "
      << centre.z << "), normal (" << normal.x << ", " << normal.y << ", " << normal.z << "), rho "
      << reflectance.to_string() << ", E " << emission.to_string() << "}";
    return s.str();
}

namespace {

/// Every surface's pieces and their grids, planned before anything is allocated.
struct MeshPlan {
    std::vector<std::pair<int, Piece>> pieces;  // surface index, piece
    double patches = 0.0;                       // in all, with the element split
    double edge = 0.0;                          // edge length used for quads
    double max_area = 0.0;                      // the area limit (0: none)
};

MeshPlan plan_mesh(const Scene& scene, const MeshingOptions& options) {
    double total = 0.0;
    for (const auto& s : scene.surfaces) total += polygon_area(s.vertices);
    if (!(options.max_area >= 0) || !(options.max_edge >= 0))
        throw InputError("meshing: --max-area and --max-edge must be positive");
    double max_area = options.max_area;
    if (options.max_area == 0 && options.max_edge == 0 && options.target_patches > 0)
        max_area = total / double(options.target_patches);
    double h = 0.0;
    if (max_area > 0) h = std::sqrt(max_area);
    if (options.max_edge > 0) h = h > 0 ? std::min(h, options.max_edge) : options.max_edge;
    if (!options.subdivide) h = 0.0;
    MeshPlan plan;
    plan.edge = h;
    plan.max_area = options.subdivide ? max_area : 0.0;
    if (options.subdivide && options.max_edge > 0)  // a triangle with edges below h has area below h^2 sqrt(3) / 4
        plan.max_area = std::sqrt(3.0) / 4 * options.max_edge * options.max_edge;
    if (options.subdivide && max_area > 0 && options.max_edge > 0) plan.max_area = std::min(plan.max_area, max_area);

    for (std::size_t si = 0; si < scene.surfaces.size(); ++si) {
        const auto& poly = scene.surfaces[si].vertices;
        auto add_triangle = [&](const V& a, const V& b, const V& c) {
            // A triangle cut k x k gives k^2 similar triangles of area A / k^2, so the area
            // limit asks k = sqrt(A / max_area). (Cutting by the edge h = sqrt(max_area), as
            // quads are, gave a right triangle of area 1 four times its budget: its longest
            // edge is 2 sqrt(A).) --max-edge is a limit on every edge. The sub-triangles are
            // similar to the face, so no choice of k would change a sliver's aspect.
            int k = 1;
            if (options.subdivide) {
                const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
                if (max_area > 0) {
                    const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
                    k = std::max(k, cuts(std::sqrt(area), std::sqrt(max_area)));
                }
                if (options.max_edge > 0) k = std::max(k, cuts(longest, options.max_edge));
            }
            Piece p{{a, b, c}, k, 0};
            plan.patches += double(p.nu) * p.nu;
            plan.pieces.emplace_back(int(si), std::move(p));
        };
        if (poly.size() == 4 && convex_quad(poly)) {
            Piece p{poly, cuts(std::max(glm::length(poly[1] - poly[0]), glm::length(poly[2] - poly[3])), h),
                    cuts(std::max(glm::length(poly[3] - poly[0]), glm::length(poly[2] - poly[1])), h)};
            plan.patches += double(p.nu) * p.nv;
            plan.pieces.emplace_back(int(si), std::move(p));
        } else if (poly.size() == 3) {
            add_triangle(poly[0], poly[1], poly[2]);
        } else {
            for (const auto& t : triangulate_polygon(poly)) add_triangle(poly[t[0]], poly[t[1]], poly[t[2]]);
        }
    }
    if (options.element_split < 1 || options.element_split > 1024)
        throw InputError("meshing: element split out of range, got " + std::to_string(options.element_split) +
                         " (expected 1 to 1024)");
    plan.patches *= double(options.element_split) * options.element_split;
    return plan;
}

/// Whether p lies within `tol` of an edge of polygon `poly`.
bool on_outline(const std::vector<glm::dvec3>& poly, const glm::dvec3& p, double tol) {
    for (std::size_t k = 0; k < poly.size(); ++k) {
        const glm::dvec3 a = poly[k], d = poly[(k + 1) % poly.size()] - a;
        const double t = std::clamp(glm::dot(p - a, d) / glm::dot(d, d), 0.0, 1.0);
        if (glm::length(a + t * d - p) <= tol) return true;
    }
    return false;
}

}  // namespace

double planned_patches(const Scene& scene, const MeshingOptions& options) { return plan_mesh(scene, options).patches; }

namespace {

/// The steps of PatchMesh(scene, options): faces go into the mesh and the patch list as they
/// are made, each with the index of its patch in the element split 1 mesh (`parent`).
class MeshBuilder {
public:
    MeshBuilder(const Scene& scene, const MeshingOptions& options, OpenPatchMesh& mesh, std::vector<Patch>& patches,
                std::vector<std::uint32_t>& parents, std::vector<double>& clearance);
    /// Discontinuity meshing: the surfaces with traced shadow boundaries are triangulated with
    /// them as constraints (Lischinski, Tampieri and Greenberg 1992); their vertices are their
    /// own, like every surface's, so conformity is a property of each triangulation.
    void triangulate_discontinuities(double max_area, std::vector<std::string>& warnings);
    /// Every piece's grid, but on the surfaces triangulated already.
    void emit_pieces(const std::vector<std::pair<int, Piece>>& pieces);
    /// Drops the unused vertices, sets the parents and warns of faces OpenMesh would not join.
    void finish(std::vector<std::string>& warnings);

private:
    using VH = OpenPatchMesh::VertexHandle;
    void emit_face(int si, const std::vector<VH>& vh);
    VH vertex(const V& p) { return m_mesh.add_vertex(OpenPatchMesh::Point(p.x, p.y, p.z)); }
    /// A vertex made on a contact cut: shared with the neighbour that makes the same point on
    /// the current surface, so no T-vertex appears.
    VH cut_vertex(int si, const V& p, double tolerance);
    /// Contact cuts: a patch that overlaps a covered region keeps only its convex pieces outside
    /// it (fanned into triangles beyond four corners); one inside it is left out.
    void emit_patch(int si, const std::vector<VH>& vh);
    /// Bilinear grid: sub-quads of a planar quad are planar and tile it exactly.
    void emit_quad_grid(int si, const Piece& piece);
    /// k x k similar triangles on the barycentric lattice (i, j), i + j <= k.
    void emit_triangle_grid(int si, const Piece& piece);

    const Scene& scene;
    const MeshingOptions& options;
    const int split;
    OpenPatchMesh& m_mesh;
    std::vector<Patch>& m_patches;
    std::vector<std::uint32_t>& m_parent;
    std::vector<double>& m_clearance;
    OpenMesh::FPropHandleT<int> face_surface;
    std::uint32_t parent = 0;  // index of the current element's patch in the split = 1 mesh
    std::size_t apart = 0;     // faces OpenMesh would not join to their neighbours
    int first_apart = -1;
    const bool cut;                                          // contact cuts
    std::vector<std::vector<const CoveredRegion*>> covered;  // per surface, with cut
    std::vector<std::pair<V, VH>> cut_points;                // of the current surface
    int cut_surface = -1;
    std::vector<bool> triangulated;  // per surface: meshed by discontinuity meshing
};

MeshBuilder::MeshBuilder(const Scene& scene_, const MeshingOptions& options_, OpenPatchMesh& mesh,
                         std::vector<Patch>& patches, std::vector<std::uint32_t>& parents,
                         std::vector<double>& clearance)
    : scene(scene_),
      options(options_),
      split(options_.element_split),
      m_mesh(mesh),
      m_patches(patches),
      m_parent(parents),
      m_clearance(clearance),
      cut(options_.cut_contacts && options_.element_split == 1 && !scene_.covered.empty()),
      covered(scene_.surfaces.size()),
      triangulated(scene_.surfaces.size(), false) {
    m_mesh.add_property(face_surface, "f:surface");
    if (cut)
        for (const auto& c : scene.covered)
            if (c.surface >= 0 && std::size_t(c.surface) < covered.size())
                covered[std::size_t(c.surface)].push_back(&c);
}

void MeshBuilder::emit_face(int si, const std::vector<VH>& vh) {
    const auto& surface = scene.surfaces[si];
    const auto& mat = scene.materials[surface.material];
    Patch p;
    p.vertex_count = int(vh.size());
    for (int k = 0; k < p.vertex_count; ++k) {
        const auto q = m_mesh.point(vh[k]);
        p.vertices[k] = V(q[0], q[1], q[2]);
    }
    const V n = newell_normal(p.polygon());
    p.area = 0.5 * glm::length(n);
    p.normal = n / (2.0 * p.area);
    p.centre = polygon_centroid(p.polygon());
    p.reflectance = mat.reflectance;
    p.emission = mat.emission;
    p.surface = si;
    bool alone = false;
    const auto f = add_face_or_alone(m_mesh, vh, alone);
    if (!f.is_valid())
        throw std::runtime_error("patch mesh: OpenMesh refused a face of surface " + surface.where.to_string());
    if (alone && apart++ == 0) first_apart = si;
    m_mesh.property(face_surface, f) = si;
    m_patches.push_back(p);
    m_parent.push_back(parent);
}

MeshBuilder::VH MeshBuilder::cut_vertex(int si, const V& p, double tolerance) {
    if (si != cut_surface) {
        cut_points.clear();
        cut_surface = si;
    }
    for (const auto& [q, h] : cut_points)
        if (glm::length(q - p) <= tolerance) return h;
    cut_points.emplace_back(p, vertex(p));
    return cut_points.back().second;
}

void MeshBuilder::triangulate_discontinuities(double max_area, std::vector<std::string>& warnings) {
    if (split != 1) throw InputError("meshing: discontinuity meshing does not combine with an element split");
    DiscontinuitySurfaces surfaces =
        triangulate_discontinuity_surfaces(scene, options.max_discontinuities, max_area, options.aspect_bound);
    warnings = std::move(surfaces.warnings);
    for (std::size_t si = 0; si < surfaces.per_surface.size(); ++si) {
        const SurfaceTriangulation& t = surfaces.per_surface[si];
        if (t.triangles.empty()) continue;  // not wanted or degenerate: the grid meshes it
        if (double(m_patches.size() + t.triangles.size()) > double(options.max_patches))
            throw InputError("meshing would make more than the limit of " + std::to_string(options.max_patches) +
                             " patches (raise --max-area or --max-edge, or --max-memory)");
        triangulated[si] = true;
        std::vector<OpenPatchMesh::VertexHandle> h;
        for (const V& p : t.points) h.push_back(vertex(p));
        for (const auto& tri : t.triangles) emit_face(int(si), {h[tri[0]], h[tri[1]], h[tri[2]]});
    }
}

void MeshBuilder::emit_patch(int si, const std::vector<VH>& vh) {
    if (!cut || covered[std::size_t(si)].empty()) return emit_face(si, vh);
    std::vector<V> poly;
    for (const auto& h : vh) {
        const auto q = m_mesh.point(h);
        poly.emplace_back(q[0], q[1], q[2]);
    }
    const V n = newell_normal(poly);
    const double area = 0.5 * glm::length(n);
    std::vector<std::vector<V>> pieces = {poly};
    for (const CoveredRegion* c : covered[std::size_t(si)]) {
        std::vector<std::vector<V>> next;
        for (const auto& piece : pieces)
            for (auto& q : subtract_convex(piece, c->polygon, n / (2 * area), 1e-9 * area))
                next.push_back(std::move(q));
        pieces = std::move(next);
    }
    if (pieces.size() == 1 && pieces[0] == poly) return emit_face(si, vh);
    const double tolerance = 1e-9 * std::sqrt(area);
    for (const auto& piece : pieces) {
        std::vector<OpenPatchMesh::VertexHandle> h;
        for (const V& p : piece) {
            const auto corner = std::find(poly.begin(), poly.end(), p);
            h.push_back(corner != poly.end() ? vh[std::size_t(corner - poly.begin())] : cut_vertex(si, p, tolerance));
            for (const CoveredRegion* c : covered[std::size_t(si)])
                if (c->gap > 0 && on_outline(c->polygon, p, 1e-7 * std::sqrt(area))) {
                    const auto v = std::size_t(h.back().idx());
                    if (m_clearance.size() <= v) m_clearance.resize(v + 1, 0.0);
                    m_clearance[v] = std::max(m_clearance[v], PatchMesh::kGapBand * c->gap);
                }
        }
        // Drop repeated handles (points that merged), then fan anything beyond a quad.
        h.erase(std::unique(h.begin(), h.end()), h.end());
        while (h.size() > 1 && h.front() == h.back()) h.pop_back();
        if (h.size() < 3) continue;
        if (h.size() <= 4) {
            emit_face(si, h);
        } else {
            for (std::size_t k = 1; k + 1 < h.size(); ++k) emit_face(si, {h[0], h[k], h[k + 1]});
        }
    }
}

void MeshBuilder::emit_pieces(const std::vector<std::pair<int, Piece>>& pieces) {
    for (const auto& [si, piece] : pieces) {
        if (triangulated[std::size_t(si)]) continue;
        if (piece.corners.size() == 4)
            emit_quad_grid(si, piece);
        else
            emit_triangle_grid(si, piece);
    }
}

void MeshBuilder::emit_quad_grid(int si, const Piece& piece) {
    const auto& c = piece.corners;
    const int nu = piece.nu * split, nv = piece.nv * split;
    std::vector<OpenPatchMesh::VertexHandle> grid((nu + 1) * (nv + 1));
    for (int b = 0; b <= nv; ++b)
        for (int a = 0; a <= nu; ++a) {
            const double u = double(a) / nu, v = double(b) / nv;
            grid[b * (nu + 1) + a] =
                vertex((1 - u) * (1 - v) * c[0] + u * (1 - v) * c[1] + u * v * c[2] + (1 - u) * v * c[3]);
        }
    // Elements in the order of their patches (row-major over the k = 1 grid).
    const std::uint32_t first = parent;
    for (int B = 0; B < piece.nv; ++B)
        for (int A = 0; A < piece.nu; ++A) {
            parent = first + std::uint32_t(B * piece.nu + A);
            for (int b = B * split; b < (B + 1) * split; ++b)
                for (int a = A * split; a < (A + 1) * split; ++a)
                    emit_patch(si, {grid[b * (nu + 1) + a], grid[b * (nu + 1) + a + 1],
                                    grid[(b + 1) * (nu + 1) + a + 1], grid[(b + 1) * (nu + 1) + a]});
        }
    parent = first + std::uint32_t(piece.nu * piece.nv);
}

void MeshBuilder::emit_triangle_grid(int si, const Piece& piece) {
    const auto& c = piece.corners;
    const int K = piece.nu, k = K * split;
    std::vector<std::vector<OpenPatchMesh::VertexHandle>> lat(k + 1);
    for (int i = 0; i <= k; ++i)
        for (int j = 0; i + j <= k; ++j)
            lat[i].push_back(vertex(c[0] + (double(i) / k) * (c[1] - c[0]) + (double(j) / k) * (c[2] - c[0])));
    // Patches of the k = 1 mesh in its order: up triangle (I, J), then down (I, J).
    // An element's local lattice position (ii, jj) in cell (I, J) says which it is in:
    // up elements with ii + jj < split and down ones with ii + jj + 1 < split lie in
    // the cell's up patch, the rest in its down patch.
    const std::uint32_t first = parent;
    std::vector<std::uint32_t> up(std::size_t(K) * K), down(std::size_t(K) * K);
    std::uint32_t next = first;
    for (int I = 0; I < K; ++I)
        for (int J = 0; I + J < K; ++J) {
            up[std::size_t(I) * K + J] = next++;
            if (I + J + 1 < K) down[std::size_t(I) * K + J] = next++;
        }
    auto cell_patch = [&](int i, int j, int extra) {
        const int I = i / split, J = j / split, ii = i % split, jj = j % split;
        return ii + jj + extra < split ? up[std::size_t(I) * K + J] : down[std::size_t(I) * K + J];
    };
    for (int i = 0; i < k; ++i)
        for (int j = 0; i + j < k; ++j) {
            parent = cell_patch(i, j, 0);
            emit_patch(si, {lat[i][j], lat[i + 1][j], lat[i][j + 1]});
            if (i + j + 1 < k) {
                parent = cell_patch(i, j, 1);
                emit_patch(si, {lat[i + 1][j], lat[i + 1][j + 1], lat[i][j + 1]});
            }
        }
    parent = next;
}

void MeshBuilder::finish(std::vector<std::string>& warnings) {
    if (const std::vector<int> index = drop_unused_vertices(m_mesh); !index.empty() && !m_clearance.empty()) {
        std::vector<double> kept(m_mesh.n_vertices(), 0.0);
        for (std::size_t v = 0; v < m_clearance.size(); ++v)
            if (index[v] >= 0) kept[std::size_t(index[v])] = m_clearance[v];
        m_clearance = std::move(kept);
    }
    // Cut patches were emitted in pieces (or not at all), triangulated surfaces in triangles: with
    // split 1 every face is its own parent.
    if (cut || options.kind == MeshingOptions::Kind::discontinuity)
        for (std::size_t i = 0; i < m_parent.size(); ++i) m_parent[i] = std::uint32_t(i);
    if (apart > 0) {
        const auto& first = scene.surfaces[std::size_t(first_apart)];
        const bool one = apart == 1;
        warnings.push_back("meshing: " + std::to_string(apart) + (one ? " patch on " : " patches (the first on ") +
                           describe(first.where, first.object) + (one ? "" : ")") +
                           (one ? " would not join its neighbours' edges and keeps vertices of its own"
                                : " would not join their neighbours' edges and keep vertices of their own") +
                           " (OpenMesh: complex edge): the exported mesh has a seam there");
    }
}

}  // namespace

PatchMesh::PatchMesh(const Scene& scene, const MeshingOptions& options) {
    // Plan every piece first, so an absurd request is refused before anything is allocated.
    MeshPlan plan = plan_mesh(scene, options);
    m_edge = plan.edge;
    const double planned = plan.patches;
    if (planned > double(options.max_patches)) {
        std::ostringstream msg;
        msg << "meshing would make " << planned << " patches, more than the limit of " << options.max_patches
            << " (raise --max-area or --max-edge, or --max-memory)";
        throw InputError(msg.str());
    }
    m_patches.reserve(std::size_t(planned));
    m_parent.reserve(std::size_t(planned));
    // OpenMesh prints its refusals on its own error stream; they are counted and reported below.
    const QuietOpenMesh quiet;
    MeshBuilder builder(scene, options, m_mesh, m_patches, m_parent, m_clearance);
    if (options.kind == MeshingOptions::Kind::discontinuity)
        builder.triangulate_discontinuities(plan.max_area, m_warnings);
    builder.emit_pieces(plan.pieces);
    builder.finish(m_warnings);
    m_specular = bounce::specular_faces(scene);
}
PatchMesh::PatchMesh(std::vector<Patch> patches, const std::vector<glm::dvec3>& points,
                     const std::vector<std::vector<std::uint32_t>>& faces)
    : m_patches(std::move(patches)) {
    if (faces.size() != m_patches.size()) throw std::invalid_argument("patch mesh: one face per patch");
    auto face_surface = OpenMesh::FPropHandleT<int>();
    m_mesh.add_property(face_surface, "f:surface");
    const QuietOpenMesh quiet;
    for (const auto& f : faces)
        for (const std::uint32_t q : f)
            if (q >= points.size()) throw std::invalid_argument("patch mesh: face point out of range");
    const ManifoldFaces manifold = manifold_faces(points.size(), faces);
    std::size_t apart = 0, first_apart = 0;  // elements OpenMesh still would not join (none expected)
    std::vector<OpenPatchMesh::VertexHandle> vh;
    vh.reserve(manifold.point_of.size());
    for (const std::uint32_t q : manifold.point_of)
        vh.push_back(m_mesh.add_vertex(OpenPatchMesh::Point(points[q].x, points[q].y, points[q].z)));
    m_parent.resize(m_patches.size());
    for (std::size_t i = 0; i < faces.size(); ++i) {
        std::vector<OpenPatchMesh::VertexHandle> f;
        for (const std::uint32_t q : manifold.faces[i]) f.push_back(vh[q]);
        bool alone = false;
        const auto face = add_face_or_alone(m_mesh, f, alone);
        if (!face.is_valid())
            throw std::runtime_error("patch mesh: OpenMesh refused element face " + std::to_string(i) + " (" +
                                     m_patches[i].to_string() + ")");
        if (alone && apart++ == 0) first_apart = i;
        m_mesh.property(face_surface, face) = m_patches[i].surface;
        m_parent[i] = std::uint32_t(i);
    }
    drop_unused_vertices(m_mesh);
    if (manifold.split_points > 0)
        m_warnings.push_back("meshing: " + std::to_string(manifold.split_points) + " element corner" +
                             (manifold.split_points == 1 ? "" : "s") +
                             " where the elements around do not form one fan (contact-cut pieces meeting at a "
                             "point, or an edge of three elements) get a copy per fan: the exported mesh has a "
                             "seam there");
    if (apart > 0)
        m_warnings.push_back("meshing: " + std::to_string(apart) + " element" + (apart == 1 ? "" : "s") +
                             " (the first " + m_patches[first_apart].to_string() +
                             ") would not join the neighbouring elements' edges (OpenMesh): the exported mesh has "
                             "a seam there");
}

std::vector<int> PatchMesh::patch_vertex_indices(std::size_t p) const {
    std::vector<int> out;
    for (auto v : m_mesh.fv_range(m_mesh.face_handle(int(p)))) out.push_back(v.idx());
    return out;
}

double PatchMesh::total_area() const {
    double a = 0.0;
    for (const auto& p : m_patches) a += p.area;
    return a;
}

Rgb PatchMesh::emitted_power() const {
    Rgb e;
    for (const auto& p : m_patches) e += p.emission * p.area;
    return e;
}

std::vector<Rgb> area_weighted_vertex_values(const PatchMesh& mesh, const std::vector<Rgb>& per_patch) {
    const auto& patches = mesh.patches();
    std::vector<Rgb> sum(mesh.mesh().n_vertices());
    std::vector<double> weight(sum.size(), 0.0);
    for (std::size_t i = 0; i < patches.size(); ++i)
        for (int v : mesh.patch_vertex_indices(i)) {
            sum[std::size_t(v)] += per_patch[i] * patches[i].area;
            weight[std::size_t(v)] += patches[i].area;
        }
    for (std::size_t v = 0; v < sum.size(); ++v) sum[v] = weight[v] > 0 ? sum[v] * (1.0 / weight[v]) : Rgb();
    return sum;
}

}  // namespace bounce
