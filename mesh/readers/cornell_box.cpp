// SPDX-License-Identifier: MIT
#include "mesh/readers/cornell_box.h"

#include <algorithm>

#include <glm/geometric.hpp>

#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

using V = glm::dvec3;

/// Orders the polygon so its front (counter-clockwise side) faces `towards`.
std::vector<V> facing(std::vector<V> poly, const V& towards) {
    const V n = newell_normal(poly);
    if (glm::dot(n, towards - polygon_centroid(poly)) < 0) std::reverse(poly.begin(), poly.end());
    return poly;
}

/// Orders the polygon so its front faces away from `from` (block sides face out).
std::vector<V> facing_away(std::vector<V> poly, const V& from) {
    const V c = polygon_centroid(poly);
    return facing(std::move(poly), c + (c - from));
}

/// The box without its blocks: walls, floor, ceiling and light.
Scene cornell_room() {
    Scene s;
    s.name = "cornell";
    s.units = "mm";
    s.materials = {
        {"white", Rgb(0.725, 0.71, 0.68), Rgb()},
        {"red", Rgb(0.63, 0.065, 0.05), Rgb()},
        {"green", Rgb(0.14, 0.45, 0.091), Rgb()},
        {"light", Rgb(0.0, 0.0, 0.0), Rgb(17.0, 12.0, 4.0)},
    };
    enum { White, Red, Green, Light };
    const V inside(278.0, 274.4, 279.6);
    auto add = [&](std::string object, std::vector<V> poly, int mat) {
        s.surfaces.push_back({std::move(poly), mat, object, {"cornell box: " + object, 0}});
    };

    add("floor", facing({{552.8, 0, 0}, {0, 0, 0}, {0, 0, 559.2}, {549.6, 0, 559.2}}, inside), White);
    add("ceiling", facing({{556, 548.8, 0}, {556, 548.8, 559.2}, {0, 548.8, 559.2}, {0, 548.8, 0}}, inside), White);
    add("back wall", facing({{549.6, 0, 559.2}, {0, 0, 559.2}, {0, 548.8, 559.2}, {556, 548.8, 559.2}}, inside), White);
    add("green wall", facing({{0, 0, 559.2}, {0, 0, 0}, {0, 548.8, 0}, {0, 548.8, 559.2}}, inside), Green);
    // The published red wall is not planar (its four corners are 1.07 mm off their mean
    // plane), so it is two exact triangles over the published corners: no vertex moves, the
    // seams with floor, ceiling and back wall stay closed, and no face has to be flattened.
    add("red wall", facing({{552.8, 0, 0}, {549.6, 0, 559.2}, {556, 548.8, 559.2}}, inside), Red);
    add("red wall", facing({{552.8, 0, 0}, {556, 548.8, 559.2}, {556, 548.8, 0}}, inside), Red);
    // The light faces down, 0.1 mm below the ceiling.
    add("light", facing({{213, 548.7, 227}, {343, 548.7, 227}, {343, 548.7, 332}, {213, 548.7, 332}}, V(278, 0, 279.5)),
        Light);

    return s;
}

}  // namespace

Scene make_cornell_box() {
    Scene s = cornell_room();
    enum { White };
    auto add = [&](std::string object, std::vector<V> poly, int mat) {
        s.surfaces.push_back({std::move(poly), mat, object, {"cornell box: " + object, 0}});
    };
    auto block = [&](const std::string& name, const std::vector<V>& top) {
        V centre(0.0);
        for (const auto& p : top) centre += p;
        centre /= double(top.size());
        centre.y *= 0.5;
        add(name + " top", facing(top, centre + V(0, 1000, 0)), White);
        for (std::size_t k = 0; k < top.size(); ++k) {
            const V a = top[k], b = top[(k + 1) % top.size()];
            add(name + " side " + std::to_string(k + 1), facing_away({a, b, V(b.x, 0, b.z), V(a.x, 0, a.z)}, centre),
                White);
        }
    };
    block("short block", {{130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}});
    block("tall block", {{423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}});
    return s;
}

Scene make_cornell_spheres_box() {
    Scene s = cornell_room();
    s.name = "cornell-spheres";
    s.materials.push_back(
        {"mirror", Rgb(), Rgb(), MaterialKind::mirror, Rgb::gray(kCornellSpheres.mirror_reflectance)});
    s.materials.push_back({"glass", Rgb(), Rgb(), MaterialKind::glass, Rgb::gray(1.0), kCornellSpheres.glass_ior});
    const int mirror = int(s.materials.size()) - 2, glass = int(s.materials.size()) - 1;
    const double r = kCornellSpheres.radius;
    // Resting on the floor (y = 0): centres one radius up.
    s.spheres.push_back({Transform::translate(kCornellSpheres.mirror_centre) * Transform::scale(V(r)),
                         mirror,
                         "mirror sphere",
                         {"cornell-spheres box: mirror sphere", 0}});
    s.spheres.push_back({Transform::translate(kCornellSpheres.glass_centre) * Transform::scale(V(r)),
                         glass,
                         "glass sphere",
                         {"cornell-spheres box: glass sphere", 0}});
    return s;
}

}  // namespace bounce
