// SPDX-License-Identifier: MIT
// Contact-aware meshing: the parts of a surface that no light can ever reach because another
// object rests on it (a block on the floor) or is mounted flush against it (a lamp just below
// the ceiling). A patch that straddles such a footprint would average lit and never-lit area
// into one value (the worst errors of a uniform mesh against the path-traced reference sit
// there), and a patch wholly inside it would shoot and receive light that does not exist.
#pragma once

#include <functional>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/geometry/surface_tree.h"
#include "mesh/scene/scene.h"

namespace bounce {

/// Finds the covered regions of every surface. Candidates are closed loops of the segments in
/// which other surfaces touch or cross the surface's plane (within 5e-4 of the scene's
/// diagonal; of closed convex objects only where they touch it, since find_solid_cuts cuts
/// their crossings exactly), and the outlines of surfaces lying parallel in front of it with the same facing
/// (their backs towards it), flush or hung at a gap of at most 1/20 of their side (a lamp panel
/// a centimetre below a ceiling; CoveredRegion::gap records it). A candidate counts only if it
/// is enclosed: from points inside it every cosine-distributed ray meets a back face (Embree,
/// surface_rays.h; a hung cover: 64 rays at its centre and half-way to each corner; a loop: 16 rays at
/// the centres of its two largest triangles and half-way to their corners), so a loop that
/// light can enter (the legs of a table, an open frame) never removes anything. Non-convex
/// loops come back as triangles. Appends find_solid_cuts (mesh/geometry/solid_cuts.h).
std::vector<CoveredRegion> find_covered_regions(const Scene& scene);

/// Surfaces searched so far and their total, from worker threads (the search grows with the
/// surfaces and the objects near each).
using CoverProgress = std::function<void(std::size_t done, std::size_t total)>;

/// The same with the scene's surface tree already built (load_scene shares one); `progress`,
/// if given, is called as blocks of surfaces finish.
std::vector<CoveredRegion> find_covered_regions(const Scene& scene, const SurfaceTree& tree,
                                                const CoverProgress& progress = {});

/// Convex polygon `poly` (in the plane with unit normal `normal`) minus convex polygon `hole`:
/// `poly` itself when they do not overlap (by more than `min_area`), nothing when the hole
/// covers it, else triangles of the rest whose corners are only the corners of `poly` and the
/// points of the hole's outline inside or on `poly` (no point on `poly`'s edges that a
/// neighbour sharing the edge would not make too).
std::vector<std::vector<glm::dvec3>> subtract_convex(const std::vector<glm::dvec3>& poly,
                                                     const std::vector<glm::dvec3>& hole, const glm::dvec3& normal,
                                                     double min_area);

}  // namespace bounce
