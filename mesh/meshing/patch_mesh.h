// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include "mesh/meshing/patch.h"
#include "mesh/scene/scene.h"
#include "mesh/scene/specular_faces.h"

namespace bounce {

/// How finely surfaces are cut into patches. A patch is at most max_edge long on each side
/// and at most max_area in area; 0 means "not limited by this".
struct MeshingOptions {
    double max_area = 0.0;              // scene units^2; 0 with max_edge 0: total area / target_patches
    double max_edge = 0.0;              // scene units
    std::size_t target_patches = 2000;  // used for the default when neither limit is set
    std::size_t max_patches = 2000000;  // refuse meshings larger than this, before building them
    bool subdivide = true;              // false: one patch per input face (polygons > 4 are triangulated)
    int element_split = 1;              // cut every patch into split x split elements (see PatchMesh::parents)
    bool cut_contacts = true;           // leave out Scene::covered (clipping the patches that straddle it);
                                        // only with element_split 1, whose parents are then the identity
    /// uniform: the grids above. discontinuity: surfaces that receive traced shadow boundaries
    /// (mesh/meshing/discontinuity_mesh.h) are constrained Delaunay triangulations refined to the same
    /// area limit and to aspect_bound instead; the others keep their grid. Only with element_split 1.
    enum class Kind { uniform, discontinuity };
    Kind kind = Kind::uniform;
    std::size_t max_discontinuities = 400;  // traced boundaries kept per surface (the longest)
    double aspect_bound = 0.125;            // CGAL's bound B on the squared sine of the smallest angle (20.7 degrees)
};

/// How many patches (elements, with element_split) PatchMesh(scene, options) would make,
/// without making them: for estimates and warnings before a large meshing.
double planned_patches(const Scene& scene, const MeshingOptions& options);

class PatchMesh;

/// Per mesh vertex, the area-weighted mean of `per_patch` over the patches around the vertex:
/// the exported point data when nothing better is known. (Every vertex is some patch's corner:
/// the meshes drop the ones no patch uses.)
std::vector<Rgb> area_weighted_vertex_values(const PatchMesh& mesh, const std::vector<Rgb>& per_patch);

struct PatchMeshTraits : OpenMesh::DefaultTraits {
    using Point = OpenMesh::Vec3d;
    using Normal = OpenMesh::Vec3d;
};
using OpenPatchMesh = OpenMesh::PolyMesh_ArrayKernelT<PatchMeshTraits>;

/// The scene cut into patches. OpenMesh holds the connectivity (vertices shared between
/// patches of one input surface, so exported point data is smooth within a surface and
/// radiosity does not bleed across creases); `patches()` holds the same faces as plain values.
class PatchMesh {
public:
    PatchMesh(const Scene& scene, const MeshingOptions& options);
    /// A mesh of given faces (as ElementTree::conforming_mesh makes): face i is the polygon
    /// points[faces[i][0]], points[faces[i][1]], ... (3 or more, counter-clockwise, extra points
    /// allowed on the edges) and displays patches[i].
    PatchMesh(std::vector<Patch> patches, const std::vector<glm::dvec3>& points,
              const std::vector<std::vector<std::uint32_t>>& faces);

    const std::vector<Patch>& patches() const { return m_patches; }
    std::size_t size() const { return m_patches.size(); }
    /// Every vertex is a corner of some face (vertices left unused, inside contact cuts, are
    /// dropped), so the exported points are exactly the cells' corners.
    const OpenPatchMesh& mesh() const { return m_mesh; }
    /// Vertex indices of patch p, in order (3 or 4).
    std::vector<int> patch_vertex_indices(std::size_t p) const;
    /// The position of vertex v.
    glm::dvec3 vertex_position(std::size_t v) const {
        const auto q = m_mesh.point(OpenMesh::VertexHandle(int(v)));
        return {q[0], q[1], q[2]};
    }
    /// With element_split k > 1 the faces are elements: each patch of the same scene meshed
    /// with k = 1 is cut into k x k of them (exactly: sub-grids of its bilinear or
    /// barycentric grid). parents()[e] is that patch's index in the k = 1 mesh; identity for k = 1.
    const std::vector<std::uint32_t>& parents() const { return m_parent; }
    /// Edge length actually used for cutting.
    double edge_length() const { return m_edge; }
    double total_area() const;
    Rgb emitted_power() const;  // sum of E_i A_i
    /// How far from vertex v, at least, a value meant for interpolation should be gathered: on
    /// the outline of a cover hung at a gap g in front of the surface (a lamp below a ceiling)
    /// the light falls off towards the outline within a band of a few g, far narrower than the
    /// patches; a value taken at the outline itself would carry that band's darkness across the
    /// whole patch. kGapBand g: beyond the straight edge of a cover, a point at distance r g
    /// loses the share (1/2 pi) integral cos^2(atan(r / cos phi)) dphi of a uniform surround
    /// (the cosine-weighted directions that reach under the cover): 15% at r = 1, 1.5% at 4,
    /// 0.4% at 8. 0 elsewhere.
    double gather_clearance(std::size_t v) const { return v < m_clearance.size() ? m_clearance[v] : 0.0; }
    static constexpr double kGapBand = 8.0;
    /// Problems met while meshing, one line each, to show the user (the discontinuity cap).
    const std::vector<std::string>& warnings() const { return m_warnings; }
    /// The scene's mirrors and glass, not meshed into patches but kept for display (the .vtu's
    /// specular cells, `bounce view`): specular_faces(scene) for a mesh made from a scene, empty
    /// for one made from given faces unless set_specular_faces gives them.
    const std::vector<SpecularFace>& specular_faces() const { return m_specular; }
    void set_specular_faces(std::vector<SpecularFace> faces) { m_specular = std::move(faces); }

private:
    OpenPatchMesh m_mesh;
    std::vector<Patch> m_patches;
    std::vector<std::uint32_t> m_parent;
    std::vector<std::string> m_warnings;
    std::vector<double> m_clearance;  // per vertex; empty when no vertex needs one
    std::vector<SpecularFace> m_specular;
    double m_edge = 0.0;
};

}  // namespace bounce
