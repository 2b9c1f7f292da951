// SPDX-License-Identifier: MIT
// The parts of surfaces that lie inside a closed object (a box pushed into another, a beam
// through a cabinet) or outside a closed room (a box pushed through a wall). No light reaches
// them, yet a patch holding such a part receives only on the rest while it shoots from all of
// it: the rays from the hidden part end on the backs of the solid, and the light they carry
// is lost (closed rooms with crossing boxes lose several per cent of their power).
#pragma once

#include <vector>

#include "mesh/scene/scene.h"

namespace bounce {

/// A closed convex object of the scene: the surfaces of one object (same source and object
/// name, 4 to 64 of them) whose vertices all lie behind every one of its face planes
/// (`inward` false: a box seen from outside) or all in front of every one (`inward` true: a
/// room seen from inside), and whose area vectors sum to zero (closed, by the divergence
/// theorem).
struct ConvexSolid {
    std::vector<int> surfaces;
    std::vector<glm::dvec3> normals;  // unit, one per face plane, as the faces look
    std::vector<double> offsets;      // plane: dot(normal, x) = offset
    bool inward = false;
};

/// The closed convex objects of the scene (tolerances relative to each object's size).
std::vector<ConvexSolid> find_convex_solids(const Scene& scene);

/// Covered regions (gap 0) for every other surface's part strictly inside a closed convex
/// object, and its part outside a closed convex room it is partly inside of. Surfaces lying in
/// one of the solid's face planes are left to the contact cuts (find_covered_regions).
/// Exact clipping: convex pieces, counter-clockwise seen from the surface's front.
std::vector<CoveredRegion> find_solid_cuts(const Scene& scene);

/// The same with the solids already found (find_convex_solids).
std::vector<CoveredRegion> find_solid_cuts(const Scene& scene, const std::vector<ConvexSolid>& solids);

}  // namespace bounce
