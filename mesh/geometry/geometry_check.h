// SPDX-License-Identifier: MIT
#pragma once

#include "mesh/scene/scene.h"

namespace bounce {

/// Finds faces a radiosity solver cannot use and repairs what can be repaired, each with a
/// warning naming the face and its source line (never silently):
///  - degenerate faces (fewer than 3 distinct vertices, all vertices collinear by CGAL's
///    exact predicate, or zero area) are dropped;
///  - non-planar polygons (a vertex further than 1% of the face's size from its Newell
///    plane) are split into triangles; nearly planar ones are projected onto that plane
///    (with a warning when a vertex moves by more than 0.1% of the face's size);
///  - faces whose interiors cross (self-intersections) are reported, not changed;
/// Throws InputError when no face is left (an empty scene).
void check_geometry(Scene& scene, const std::string& source);

}  // namespace bounce
