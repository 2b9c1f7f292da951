// SPDX-License-Identifier: MIT
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/scene.h"

namespace bounce {

/// A mirror or glass face as it is shown (the .vtu, `bounce view`): a planar polygon in scene
/// units, counter-clockwise seen from its front (the outside of a sphere), and its material.
struct SpecularFace {
    std::vector<glm::dvec3> vertices;
    MaterialKind kind = MaterialKind::mirror;
    int material = 0;  // index into Scene::materials
};

/// The scene's mirror and glass objects as faces for display: the specular polygons as they
/// are, then every sphere tessellated as the radiosity's occluders see it (tessellate_sphere,
/// 48 x 24 faces, vertices on the sphere). Empty when the scene has no specular object.
std::vector<SpecularFace> specular_faces(const Scene& scene);

}  // namespace bounce
