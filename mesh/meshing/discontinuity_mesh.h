// SPDX-License-Identifier: MIT
// Discontinuity meshing of direct light (Heckbert 1992, "Discontinuity meshing for radiosity";
// Lischinski, Tampieri and Greenberg 1992, "Discontinuity meshing for accurate radiosity"):
// mesh edges where the direct illumination from an area emitter changes in value or slope, so
// no patch averages umbra, penumbra and light into one number. The boundaries come from the
// critical surfaces of an emitter and an occluder: an emitter edge with an occluder vertex (EV)
// or an emitter vertex with an occluder edge (VE). Their traces on a receiving plane are the
// umbra and penumbra boundaries and the slope breaks inside the penumbra. EEE surfaces (three
// edges, curved traces) are left out, as in both papers' implementations.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/scene.h"

namespace bounce {

/// One traced boundary: a straight segment in the plane of its receiving surface, inside that
/// surface's polygon and outside its covered regions.
struct DiscontinuitySegment {
    enum class Kind { EV, VE };
    glm::dvec3 a{0.0}, b{0.0};
    Kind kind = Kind::EV;
    int emitter = -1;   // surface index of the emitter
    int occluder = -1;  // surface index of (one) occluding face the edge or vertex belongs to
};

struct TracedDiscontinuities {
    std::vector<std::vector<DiscontinuitySegment>> per_surface;  // indexed like Scene::surfaces
    std::vector<std::string> warnings;                           // one line each: the cap, coplanar overlaps
    std::size_t traced = 0;                                      // before the cap
};

/// Traces every EV and VE critical surface of every emitter (a surface with emission) and every
/// occluding face (any other surface), restricted to the occluders' silhouettes (the faces
/// around the vertex or edge lie on one side of the critical plane: otherwise the surface is no
/// boundary), onto every receiving surface's plane, clipped to the receiver's polygon and
/// outside its covered regions, and kept only where its critical line to the emitter is not
/// blocked by a third surface (a boundary in another object's shadow bounds nothing).
/// Surfaces with more than `max_per_surface` segments keep the longest ones, and one warning
/// line says so; another names coplanar overlapping faces (each meshed on its own).
TracedDiscontinuities trace_discontinuities(const Scene& scene, std::size_t max_per_surface);

/// A planar surface triangulated with its boundaries as constraints.
struct SurfaceTriangulation {
    std::vector<glm::dvec3> points;                       // the surface's own corners keep their coordinates
    std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from the front
    bool over_budget = false;  // the refinement needed far more points than the area limit asks: no triangles
};

/// Constrained Delaunay triangulation (CGAL) of surface `surface`'s polygon with the segments
/// and the outlines of its covered regions as constraints, refined by CGAL's Delaunay mesher to
/// triangles whose circumradius-to-shortest-edge ratio bound is `aspect_bound` (CGAL's B: 0.125
/// is a smallest angle of about 20.7 degrees) and whose area is at most `max_area` (0: no
/// limit). The covered regions are left out. Every segment is a union of triangle edges.
/// `outline_points` (points of a coplanar neighbour's triangulation on the shared outline) are
/// made vertices of the outline after refinement, so both sides of the seam have the same.
SurfaceTriangulation triangulate_surface(const Scene& scene, int surface,
                                         const std::vector<DiscontinuitySegment>& segments, double max_area,
                                         double aspect_bound = 0.125,
                                         const std::vector<glm::dvec3>& outline_points = {});

/// The surfaces discontinuity meshing triangulates, indexed like Scene::surfaces: those that
/// receive traced boundaries (trace_discontinuities) and, so that no T-vertex appears where they
/// meet, the (nearly, within about a degree) coplanar non-emitting surfaces sharing an edge with
/// one, transitively; each triangulated (triangulate_surface) with its seam neighbours' points on
/// the shared edges. A surface with no triangles (not wanted, degenerate, or over its budget
/// along with its seam neighbours) is meshed by its grid.
struct DiscontinuitySurfaces {
    std::vector<SurfaceTriangulation> per_surface;
    std::vector<std::string> warnings;  // the tracing's, and one line for surfaces given up
};

DiscontinuitySurfaces triangulate_discontinuity_surfaces(const Scene& scene, std::size_t max_discontinuities,
                                                         double max_area, double aspect_bound);

}  // namespace bounce
