// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/scene.h"

namespace bounce {

/// A triangle that blocks rays but is no patch: corners in scene units.
using OccluderTriangle = std::array<glm::dvec3, 3>;

/// The mirror and glass objects as triangles for the radiosity's visibility: the specular
/// polygons fanned into triangles and every sphere tessellated (tessellate_sphere, 48 x 24
/// faces). The radiosity meshes only diffuse surfaces; without these, light would pass through
/// a mirror or a glass ball as if it were not there. Empty when the scene has no specular
/// object, so a diffuse scene's visibility is exactly what it was.
std::vector<OccluderTriangle> specular_occluders(const Scene& scene);

}  // namespace bounce
