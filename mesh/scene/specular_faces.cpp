// SPDX-License-Identifier: MIT
#include "mesh/scene/specular_faces.h"

#include "mesh/scene/sphere.h"

namespace bounce {

std::vector<SpecularFace> specular_faces(const Scene& scene) {
    std::vector<SpecularFace> out;
    auto kind = [&](int material) { return scene.materials[std::size_t(material)].kind; };
    for (const auto& s : scene.specular_surfaces) out.push_back({s.vertices, kind(s.material), s.material});
    for (const auto& s : scene.spheres)
        for (auto& f : tessellate_sphere(s.transform)) out.push_back({std::move(f), kind(s.material), s.material});
    return out;
}

}  // namespace bounce
