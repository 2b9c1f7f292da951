// SPDX-License-Identifier: MIT
// One surface wound the wrong way in a scene wound right (one wall of a room reversed): the
// light it should reflect leaves through its back, its front is black, and the scene-wide
// winding check after the solve (solver/linear/winding_check.h) says nothing, since most of
// the light still lands. This check looks at each surface from both sides before any solve.
#pragma once

#include <string>
#include <vector>

#include "mesh/geometry/surface_tree.h"
#include "mesh/scene/scene.h"

namespace bounce {

/// A surface whose front faces away from the scene: from its front, rays meet almost only the
/// backs of surfaces or nothing, while from its back they meet mostly fronts.
struct ReversedSurface {
    std::vector<int> surfaces;  // coplanar surfaces of one object and material, in input order
    double front_sees = 0.0;    // share of cosine-weighted rays from the front meeting a front face
    double back_sees = 0.0;     // the same from the back
};

/// Finds the reversed surfaces. Surfaces are judged in groups (those of one object and material
/// lying in one plane: a wall cut into triangles is one), each from 8 points spread over its area
/// with 8 stratified cosine-weighted rays a side (CGAL AABB tree of the surfaces). A group is
/// reversed when at most 20% of its front view, and at least 50% of its back view, meets a
/// front face. Only groups holding at least 1e-3 of the scene's area are looked at, the 512
/// largest, so the work stays under 66k rays on any scene. Deterministic.
std::vector<ReversedSurface> find_reversed_surfaces(const Scene& scene);

/// The same with the scene's surface tree already built (load_scene shares one).
std::vector<ReversedSurface> find_reversed_surfaces(const Scene& scene, const SurfaceTree& tree);

/// "orientation: file.obj:12 (wall) faces away from the scene: ...", with the fix (reverse the
/// face's vertices, or "flip": true on its JSON object).
std::string reversed_surface_warning(const Scene& scene, const ReversedSurface& r);

}  // namespace bounce
