// SPDX-License-Identifier: MIT
// Putting faces into an OpenMesh mesh: the patch meshes' helpers for faces OpenMesh would
// refuse or abort on (non-manifold points, complex edges) and for unused vertices.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <OpenMesh/Core/System/omstream.hh>

#include "mesh/meshing/patch_mesh.h"

namespace bounce {

/// OpenMesh prints its refusals on its own error stream; the meshers count them and warn once.
struct QuietOpenMesh {
    bool was = omerr().is_enabled();
    QuietOpenMesh() { omerr().disable(); }
    ~QuietOpenMesh() {
        if (was) omerr().enable();
    }
    QuietOpenMesh(const QuietOpenMesh&) = delete;
    QuietOpenMesh& operator=(const QuietOpenMesh&) = delete;
};

/// Faces over shared points, made manifold before OpenMesh sees them: a point where the faces
/// around it do not form one fan (elements of contact-cut pieces meeting at a corner, or an
/// edge that three faces share or two run the same way) gets a copy per fan. OpenMesh refuses
/// some such faces and aborts on others (an assertion in its patch re-linking), so they are
/// never offered. A fan is the faces around the point joined through edges that exactly two
/// faces share in opposite directions (union-find over the faces' corners).
struct ManifoldFaces {
    std::vector<std::vector<std::uint32_t>> faces;  // into the point list below
    std::vector<std::uint32_t> point_of;            // for each point: the input point it copies
    std::size_t split_points = 0;                   // input points given more than one copy
};

ManifoldFaces manifold_faces(std::size_t point_count, const std::vector<std::vector<std::uint32_t>>& faces);

/// Adds a face; when OpenMesh refuses it (a "complex edge": pieces of a contact cut meeting at
/// a point merged within its tolerance), the face is still sound, so it goes in on vertices of
/// its own, a seam in the exported mesh that the caller warns of once (`alone` set). Invalid
/// only when even that is refused.
OpenPatchMesh::FaceHandle add_face_or_alone(OpenPatchMesh& mesh, const std::vector<OpenPatchMesh::VertexHandle>& vh,
                                            bool& alone);

/// Leaves out the vertices no face uses (grid corners inside a contact cut, the corners of a
/// face OpenMesh refused before it went in on vertices of its own): every exported point is
/// then a corner of some cell, with no stray radiosity 0 in the point data. The other vertices
/// keep their order and the faces theirs (the same faces offered in the same order join the
/// same way).
/// Returns each old vertex's new index (-1: dropped), or nothing when none was dropped.
std::vector<int> drop_unused_vertices(OpenPatchMesh& mesh);

}  // namespace bounce
