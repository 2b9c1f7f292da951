// SPDX-License-Identifier: MIT
// Analytic spheres placed by an affine transform T (ellipsoids): exact ray intersection in the
// sphere's own frame, and a tessellation for what sees the scene as triangles (the radiosity's
// visibility).
#pragma once

#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/scene.h"

namespace bounce {

/// Where a ray meets a sphere: the parameter t along the ray (in the units of the direction
/// given), the point, and the unit outward normal there.
struct SphereHit {
    double t = 0.0;
    glm::dvec3 position{0.0};
    glm::dvec3 normal{0.0};  // unit, outward: (T^-1)^T times the unit sphere's normal, normalised
};

/// The first crossing of the ray o + t d, t in (t_min, t_max), with the sphere, from outside or
/// from inside. The ray is taken into the unit sphere's frame, o' = T^-1 o and d' = T^-1 d
/// (linear part only), which keeps t: |o' + t d'|^2 = 1 is solved there in double precision
/// (the stable form of the quadratic), and the normal is brought back by the inverse
/// transpose of T (a normal is a covector: it must stay perpendicular to the tangents T maps).
std::optional<SphereHit> intersect_sphere(const Sphere& sphere, const glm::dvec3& o, const glm::dvec3& d, double t_min,
                                          double t_max);

/// The sphere as a closed polyhedron of `slices` x `stacks` latitude-longitude faces (quads,
/// triangles at the poles), counter-clockwise seen from outside, placed by T. Its vertices lie
/// on the sphere, so it is inscribed: at 48 x 24 the faces' centres sit at most 0.5% of the
/// radius inside. Each quad of a latitude band is planar (a symmetric trapezoid), and stays so
/// under T.
std::vector<std::vector<glm::dvec3>> tessellate_sphere(const Transform& transform, int slices = 48, int stacks = 24);

}  // namespace bounce
