// SPDX-License-Identifier: MIT
#include "solver/reference/path_tracer_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "mesh/geometry/embree_ray.h"
#include "mesh/scene/polygon.h"

namespace bounce::path_tracing {

TracedScene::TracedScene(const Scene& scene) {
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    const std::size_t triangle_count = add_surfaces(scene, lo, hi);
    for (const Sphere& sphere : scene.spheres) {
        spheres.push_back(sphere);
        // The ellipsoid lies within the image of the cube [-1, 1]^3.
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 c = sphere.transform.point({k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0});
            lo = glm::min(lo, c);
            hi = glm::max(hi, c);
        }
    }
    if (triangle_count == 0) throw std::invalid_argument("path tracer: the scene has no surfaces of positive area");
    diagonal = glm::length(hi - lo);
    centre = 0.5 * (lo + hi);
    // Recentred single-precision coordinates round to about 6e-8 of the diagonal; the offset
    // keeps rays off the plane they leave, far above that and far below any modelled gap.
    epsilon = 1e-6 * diagonal;
    build_embree(scene, triangle_count);
}

std::size_t TracedScene::add_surfaces(const Scene& scene, glm::dvec3& lo, glm::dvec3& hi) {
    std::size_t triangle_count = 0;
    const std::size_t diffuse_count = scene.surfaces.size();
    surfaces.resize(diffuse_count + scene.specular_surfaces.size());
    for (std::size_t s = 0; s < surfaces.size(); ++s) {
        const Surface& surf = s < diffuse_count ? scene.surfaces[s] : scene.specular_surfaces[s - diffuse_count];
        auto& sd = surfaces[s];
        for (const auto& v : surf.vertices) {
            lo = glm::min(lo, v);
            hi = glm::max(hi, v);
        }
        const glm::dvec3 nn = newell_normal(surf.vertices);
        const double len = glm::length(nn);
        if (!(len > 0) || surf.vertices.size() < 3) continue;  // degenerate: never hit, never sampled
        sd.normal = nn / len;
        sd.origin = surf.vertices[0];
        const Material& m = scene.materials.at(std::size_t(surf.material));
        sd.reflectance = m.reflectance;
        sd.emission = m.emission;
        sd.kind = m.kind;
        sd.specular = m.specular;
        sd.ior = m.ior;
        sd.triangles = triangulate_polygon(surf.vertices);
        double acc = 0;
        for (const auto& t : sd.triangles) {
            acc += 0.5 * glm::length(glm::cross(surf.vertices[std::size_t(t[1])] - surf.vertices[std::size_t(t[0])],
                                                surf.vertices[std::size_t(t[2])] - surf.vertices[std::size_t(t[0])]));
            sd.cumulative.push_back(acc);
        }
        sd.area = acc;
        sd.size = std::sqrt(acc);
        triangle_count += sd.triangles.size();
        if (sd.area > 0 && sd.emission.max() > 0 && sd.kind == MaterialKind::diffuse) emitters.push_back(int(s));
    }
    return triangle_count;
}

void TracedScene::build_embree(const Scene& scene, std::size_t triangle_count) {
    embree.device = rtcNewDevice("verbose=0");
    if (!embree.device) throw std::runtime_error("embree: cannot create a device");
    embree.scene = rtcNewScene(embree.device);
    rtcSetSceneFlags(embree.scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(embree.scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geometry = rtcNewGeometry(embree.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), 3 * triangle_count));
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), triangle_count));
    if (!v || !t) {
        rtcReleaseGeometry(geometry);
        throw std::runtime_error("embree: out of memory for " + std::to_string(triangle_count) + " triangles");
    }
    unsigned base = 0;
    triangle_surface.reserve(triangle_count);
    for (std::size_t s = 0; s < surfaces.size(); ++s) {
        const auto& poly = polygon(scene, int(s));
        for (const auto& tri : surfaces[s].triangles) {
            for (int k = 0; k < 3; ++k) {
                const glm::dvec3 x = poly[std::size_t(tri[std::size_t(k)])] - centre;
                *v++ = float(x.x);
                *v++ = float(x.y);
                *v++ = float(x.z);
                *t++ = base++;
            }
            triangle_surface.push_back(int(s));
        }
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(embree.scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(embree.scene);
    if (rtcGetDeviceError(embree.device) != RTC_ERROR_NONE) throw std::runtime_error("embree: scene build failed");
}

const std::vector<glm::dvec3>& TracedScene::polygon(const Scene& scene, int s) const {
    const std::size_t n = scene.surfaces.size();
    return std::size_t(s) < n ? scene.surfaces[std::size_t(s)].vertices
                              : scene.specular_surfaces[std::size_t(s) - n].vertices;
}

Hit TracedScene::trace_all(const glm::dvec3& o, const glm::dvec3& d, double tnear, double tfar) const {
    Hit best = trace(o, d, tnear, tfar);
    double t_max = best.missed() ? tfar : best.t;
    for (std::size_t k = 0; k < spheres.size(); ++k)
        if (const auto h = intersect_sphere(spheres[k], o, d, tnear, t_max)) {
            best = {h->t, -1, int(k), h->position, h->normal};
            t_max = h->t;
        }
    return best;
}

Hit TracedScene::trace(const glm::dvec3& o, const glm::dvec3& d, double tnear, double tfar) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh = embree_ray(o, d, tnear, tfar, centre);
    rtcIntersect1(embree.scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
    return {double(rh.ray.tfar), triangle_surface[rh.hit.primID]};
}

bool TracedScene::occluded(const glm::dvec3& a, const glm::dvec3& b) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray{};
    const glm::dvec3 o = a - centre, d = b - a;
    ray.org_x = float(o.x);
    ray.org_y = float(o.y);
    ray.org_z = float(o.z);
    ray.dir_x = float(d.x);
    ray.dir_y = float(d.y);
    ray.dir_z = float(d.z);
    ray.tnear = 0.0f;
    ray.tfar = 1.0f;
    ray.mask = 0xFFFFFFFFu;
    rtcOccluded1(embree.scene, &context, &ray);
    if (ray.tfar < 0.0f) return true;
    for (const auto& sphere : spheres)
        if (intersect_sphere(sphere, a, b - a, 1e-9, 1.0 - 1e-9)) return true;
    return false;
}

glm::dvec3 TracedScene::sample_surface(const Scene& scene, int s, double u1, double u2) const {
    const SurfaceData& sd = surfaces[std::size_t(s)];
    const double a = u1 * sd.area;
    std::size_t k =
        std::size_t(std::upper_bound(sd.cumulative.begin(), sd.cumulative.end(), a) - sd.cumulative.begin());
    k = std::min(k, sd.triangles.size() - 1);
    const double lo = k ? sd.cumulative[k - 1] : 0.0, width = sd.cumulative[k] - lo;
    // Reuse u1 within the chosen triangle, so stratification carries through.
    const double v1 = width > 0 ? std::clamp((a - lo) / width, 0.0, 1.0) : 0.5;
    const double su = std::sqrt(v1);
    const auto& tri = sd.triangles[k];
    const auto& poly = scene.surfaces[std::size_t(s)].vertices;
    const double b0 = 1 - su, b1 = u2 * su;
    return b0 * poly[std::size_t(tri[0])] + b1 * poly[std::size_t(tri[1])] + (1 - b0 - b1) * poly[std::size_t(tri[2])];
}

}  // namespace bounce::path_tracing
