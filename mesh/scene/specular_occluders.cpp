// SPDX-License-Identifier: MIT
#include "mesh/scene/specular_occluders.h"

#include "mesh/scene/polygon.h"
#include "mesh/scene/sphere.h"

namespace bounce {

std::vector<OccluderTriangle> specular_occluders(const Scene& scene) {
    std::vector<OccluderTriangle> out;
    auto add = [&](const std::vector<glm::dvec3>& poly) {
        if (poly.size() < 3) return;
        for (const auto& t : triangulate_polygon(poly))
            out.push_back({poly[std::size_t(t[0])], poly[std::size_t(t[1])], poly[std::size_t(t[2])]});
    };
    for (const auto& s : scene.specular_surfaces) add(s.vertices);
    for (const auto& s : scene.spheres)
        for (const auto& f : tessellate_sphere(s.transform)) add(f);
    return out;
}

}  // namespace bounce
