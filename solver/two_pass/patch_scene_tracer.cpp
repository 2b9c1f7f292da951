// SPDX-License-Identifier: MIT
#include "solver/two_pass/patch_scene_tracer.h"

#include <limits>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "mesh/geometry/embree_ray.h"
#include "mesh/scene/polygon.h"
#include "mesh/scene/sphere.h"

namespace bounce {

struct PatchSceneTracer::Impl {
    const Scene& scene;
    const PatchMesh& mesh;
    RTCDevice device = nullptr;
    RTCScene rtc = nullptr;
    glm::dvec3 centre{0.0};
    unsigned patch_geometry = RTC_INVALID_GEOMETRY_ID, specular_geometry = RTC_INVALID_GEOMETRY_ID;
    std::vector<int> patch_of, fan_of;  // patch geometry: triangle -> patch, fan index
    std::vector<int> specular_of;       // specular geometry: triangle -> specular surface
    std::vector<glm::dvec3> specular_normal, specular_origin;

    Impl(const Scene& s, const PatchMesh& m) : scene(s), mesh(m) {}
    ~Impl() {
        if (rtc) rtcReleaseScene(rtc);
        if (device) rtcReleaseDevice(device);
    }

    /// Attaches the triangles (corners in scene units) as one geometry; returns its id.
    unsigned attach(const std::vector<glm::dvec3>& corners) {
        const std::size_t n = corners.size() / 3;
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
        auto* t = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n));
        if (!v || !t) {
            rtcReleaseGeometry(g);
            throw std::runtime_error("embree: out of memory for " + std::to_string(n) + " triangles");
        }
        for (std::size_t k = 0; k < 3 * n; ++k) {
            const glm::dvec3 x = corners[k] - centre;
            v[3 * k] = float(x.x);
            v[3 * k + 1] = float(x.y);
            v[3 * k + 2] = float(x.z);
            t[k] = unsigned(k);
        }
        rtcCommitGeometry(g);
        const unsigned id = rtcAttachGeometry(rtc, g);
        rtcReleaseGeometry(g);
        return id;
    }
};

PatchSceneTracer::PatchSceneTracer(const Scene& scene, const PatchMesh& mesh)
    : m_impl(std::make_unique<Impl>(scene, mesh)) {
    Impl& im = *m_impl;
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (const auto& p : mesh.patches())
        for (const auto& x : p.polygon()) lo = glm::min(lo, x), hi = glm::max(hi, x);
    for (const auto& s : scene.specular_surfaces)
        for (const auto& x : s.vertices) lo = glm::min(lo, x), hi = glm::max(hi, x);
    for (const auto& s : scene.spheres)
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 c = s.transform.point({k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0});
            lo = glm::min(lo, c), hi = glm::max(hi, c);
        }
    if (!(lo.x <= hi.x)) throw std::invalid_argument("two-pass: the scene is empty");
    im.centre = 0.5 * (lo + hi);
    m_diagonal = glm::length(hi - lo);
    m_epsilon = 1e-6 * m_diagonal;

    im.device = rtcNewDevice("verbose=0");
    if (!im.device) throw std::runtime_error("embree: cannot create a device");
    im.rtc = rtcNewScene(im.device);
    rtcSetSceneFlags(im.rtc, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(im.rtc, RTC_BUILD_QUALITY_HIGH);
    std::vector<glm::dvec3> corners;
    for (std::size_t p = 0; p < mesh.size(); ++p) {
        const Patch& patch = mesh.patches()[p];
        for (int k = 1; k + 1 < patch.vertex_count; ++k) {
            corners.insert(corners.end(),
                           {patch.vertices[0], patch.vertices[std::size_t(k)], patch.vertices[std::size_t(k + 1)]});
            im.patch_of.push_back(int(p));
            im.fan_of.push_back(k);
        }
    }
    if (!corners.empty()) im.patch_geometry = im.attach(corners);
    corners.clear();
    for (std::size_t s = 0; s < scene.specular_surfaces.size(); ++s) {
        const auto& poly = scene.specular_surfaces[s].vertices;
        const glm::dvec3 n = newell_normal(poly);
        im.specular_normal.push_back(glm::length(n) > 0 ? glm::normalize(n) : glm::dvec3(0.0));
        im.specular_origin.push_back(poly.empty() ? glm::dvec3(0.0) : poly[0]);
        if (poly.size() < 3) continue;
        for (const auto& t : triangulate_polygon(poly)) {
            corners.insert(corners.end(), {poly[std::size_t(t[0])], poly[std::size_t(t[1])], poly[std::size_t(t[2])]});
            im.specular_of.push_back(int(s));
        }
    }
    if (!corners.empty()) im.specular_geometry = im.attach(corners);
    rtcCommitScene(im.rtc);
    if (rtcGetDeviceError(im.device) != RTC_ERROR_NONE) throw std::runtime_error("embree: scene build failed");
}

PatchSceneTracer::~PatchSceneTracer() = default;

PatchSceneTracer::Hit PatchSceneTracer::trace(const glm::dvec3& o, const glm::dvec3& d, double t_min) const {
    const Impl& im = *m_impl;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh = embree_ray(o, d, t_min, std::numeric_limits<double>::infinity(), im.centre);
    rtcIntersect1(im.rtc, &context, &rh);
    Hit hit;
    double t_max = std::numeric_limits<double>::infinity();
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
        // Embree finds the triangle in single precision; the point is then the ray's crossing
        // with the face's plane, in double precision.
        glm::dvec3 plane_point, normal;
        if (rh.hit.geomID == im.patch_geometry) {
            hit.kind = Hit::Kind::patch;
            hit.index = im.patch_of[rh.hit.primID];
            hit.fan = im.fan_of[rh.hit.primID];
            const Patch& p = im.mesh.patches()[std::size_t(hit.index)];
            normal = p.normal;
            plane_point = p.vertices[0];
        } else {
            hit.kind = Hit::Kind::specular_surface;
            hit.index = im.specular_of[rh.hit.primID];
            normal = im.specular_normal[std::size_t(hit.index)];
            plane_point = im.specular_origin[std::size_t(hit.index)];
        }
        const double dn = glm::dot(d, normal);
        hit.t = std::abs(dn) > 0 ? glm::dot(plane_point - o, normal) / dn : double(rh.ray.tfar);
        if (!(hit.t > t_min)) hit.t = double(rh.ray.tfar);
        t_max = hit.t;
        hit.normal = normal;
        hit.position = o + hit.t * d;
        hit.position -= glm::dot(hit.position - plane_point, normal) * normal;  // on the plane, exactly
        if (hit.kind == Hit::Kind::patch) {
            // Barycentrics of the point in its fan triangle (0, fan, fan + 1).
            const Patch& p = im.mesh.patches()[std::size_t(hit.index)];
            const glm::dvec3 a = p.vertices[0], b = p.vertices[std::size_t(hit.fan)],
                             c = p.vertices[std::size_t(hit.fan + 1)];
            const glm::dvec3 e1 = b - a, e2 = c - a, w = hit.position - a;
            const double d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
            const double w1 = glm::dot(w, e1), w2 = glm::dot(w, e2), det = d11 * d22 - d12 * d12;
            if (det > 0) {
                hit.u = (d22 * w1 - d12 * w2) / det;
                hit.v = (d11 * w2 - d12 * w1) / det;
            } else {
                hit.u = double(rh.hit.u);
                hit.v = double(rh.hit.v);
            }
        }
    }
    for (std::size_t k = 0; k < im.scene.spheres.size(); ++k)
        if (const auto h = intersect_sphere(im.scene.spheres[k], o, d, t_min, t_max)) {
            t_max = h->t;
            hit = Hit{};
            hit.kind = Hit::Kind::sphere;
            hit.t = h->t;
            hit.index = int(k);
            hit.position = h->position;
            hit.normal = h->normal;
        }
    return hit;
}

const Material& PatchSceneTracer::material(const Hit& hit) const {
    const Scene& s = m_impl->scene;
    const int m = hit.kind == Hit::Kind::sphere ? s.spheres.at(std::size_t(hit.index)).material
                                                : s.specular_surfaces.at(std::size_t(hit.index)).material;
    return s.materials.at(std::size_t(m));
}

}  // namespace bounce
