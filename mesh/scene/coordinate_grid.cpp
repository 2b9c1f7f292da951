// SPDX-License-Identifier: MIT
#include "mesh/scene/coordinate_grid.h"

#include <algorithm>
#include <cmath>

namespace bounce {

std::optional<int> coordinate_decimals(const Scene& scene) {
    double extent = 0;
    for (const auto* list : {&scene.surfaces, &scene.specular_surfaces})
        for (const Surface& s : *list)
            for (const glm::dvec3& v : s.vertices)
                extent = std::max({extent, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    if (!(extent > 0) || !std::isfinite(extent)) return std::nullopt;
    return 10 - int(std::floor(std::log10(extent * std::sqrt(2.0))));
}

void snap_coordinates(Scene& scene) {
    const std::optional<int> k = coordinate_decimals(scene);
    if (!k) return;
    // For 0 < k <= 22, 10^k is an exact double and x 10^k of a coordinate with at most k
    // decimals lies within an ulp of an integer below 2^53, so the rounding lands on that
    // integer and the division (correctly rounded) gives back the same nearest double.
    const double scale = std::pow(10.0, *k);
    const auto snap = [scale](double x) { return std::nearbyint(x * scale) / scale; };
    for (auto* list : {&scene.surfaces, &scene.specular_surfaces})
        for (Surface& s : *list)
            for (glm::dvec3& v : s.vertices) v = {snap(v.x), snap(v.y), snap(v.z)};
}

}  // namespace bounce
