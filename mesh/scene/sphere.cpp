// SPDX-License-Identifier: MIT
#include "mesh/scene/sphere.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include <glm/geometric.hpp>

namespace bounce {

std::optional<SphereHit> intersect_sphere(const Sphere& sphere, const glm::dvec3& o, const glm::dvec3& d, double t_min,
                                          double t_max) {
    const Transform& T = sphere.transform;
    const glm::dvec3 ol = T.inverse_point(o), dl = T.inverse_vector(d);
    // |ol + t dl|^2 = 1:  a t^2 + 2 b t + c = 0.
    const double a = glm::dot(dl, dl), b = glm::dot(ol, dl), c = glm::dot(ol, ol) - 1.0;
    if (!(a > 0)) return std::nullopt;
    // The discriminant from the distance of the centre to the line, which does not cancel
    // when the ray starts far away (Haines et al., "Precision improvements for ray/sphere
    // intersection", Ray Tracing Gems 2019, ch. 7).
    const glm::dvec3 perp = ol - (b / a) * dl;
    const double disc = a * (1.0 - glm::dot(perp, perp));
    if (disc < 0) return std::nullopt;
    const double q = -(b + std::copysign(std::sqrt(disc), b));
    double t0 = c / q, t1 = q / a;
    if (q == 0) t0 = t1 = -b / a;
    if (t0 > t1) std::swap(t0, t1);
    double t = t0;
    if (!(t > t_min && t < t_max)) {
        t = t1;
        if (!(t > t_min && t < t_max)) return std::nullopt;
    }
    SphereHit hit;
    hit.t = t;
    hit.position = o + t * d;
    hit.normal = T.normal(ol + t * dl);
    return hit;
}

std::vector<std::vector<glm::dvec3>> tessellate_sphere(const Transform& transform, int slices, int stacks) {
    const double pi = std::numbers::pi;
    auto at = [&](int i, int j) {
        const double theta = pi * double(j) / double(stacks), phi = 2 * pi * double(i) / double(slices);
        return transform.point({std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
    };
    std::vector<std::vector<glm::dvec3>> faces;
    faces.reserve(std::size_t(slices * stacks));
    for (int j = 0; j < stacks; ++j)
        for (int i = 0; i < slices; ++i) {
            // theta grows from the north pole (+z) down; seen from outside, (i, j), (i, j+1),
            // (i+1, j+1), (i+1, j) runs counter-clockwise.
            std::vector<glm::dvec3> f;
            if (j > 0) f.push_back(at(i, j));
            f.push_back(at(i, j + 1));
            if (j + 1 < stacks) f.push_back(at(i + 1, j + 1));
            f.push_back(at(i + 1, j));
            if (j == stacks - 1) f = {at(i, j), at(i, j + 1), at(i + 1, j)};
            faces.push_back(std::move(f));
        }
    if (transform.flips_orientation())
        for (auto& f : faces) std::reverse(f.begin(), f.end());
    return faces;
}

}  // namespace bounce
