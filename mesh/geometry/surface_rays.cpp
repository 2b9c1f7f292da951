// SPDX-License-Identifier: MIT
#include "mesh/geometry/surface_rays.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "mesh/geometry/embree_ray.h"
#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

/// An intersection context that collects the owners of every hit it is shown and turns each
/// down, so the traversal goes on to the next (Embree's context filter).
struct Collector {
    RTCIntersectContext context;  // first: Embree hands the filter a pointer to it
    const std::vector<int>* owner;
    std::vector<int>* found;
};

void collect(const RTCFilterFunctionNArguments* args) {
    const auto* c = reinterpret_cast<const Collector*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        c->found->push_back((*c->owner)[RTCHitN_primID(args->hit, args->N, i)]);
        args->valid[i] = 0;
    }
}

}  // namespace

struct SurfaceRays::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<int> owner;  // per triangle: its surface
    glm::dvec3 centre{0.0};

    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

SurfaceRays::SurfaceRays(const Scene& scene) : m_impl(std::make_unique<Impl>()) {
    Impl& m = *m_impl;
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi = -lo;
    std::vector<glm::dvec3> corners;
    for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
        const auto& poly = scene.surfaces[s].vertices;
        if (!(glm::length(newell_normal(poly)) > 0)) continue;  // no area, nothing to meet
        for (const auto& t : triangulate_polygon(poly)) {
            for (const int k : t) {
                corners.push_back(poly[std::size_t(k)]);
                lo = glm::min(lo, poly[std::size_t(k)]);
                hi = glm::max(hi, poly[std::size_t(k)]);
            }
            m.owner.push_back(int(s));
        }
    }
    if (m.owner.empty()) return;
    m.centre = 0.5 * (lo + hi);
    // "verbose=0": Embree would otherwise print to stdout, which may be a pipe we own.
    m.device = rtcNewDevice("verbose=0");
    if (!m.device)
        throw std::runtime_error("embree: cannot create a device (error " +
                                 std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    m.scene = rtcNewScene(m.device);
    // ROBUST: watertight, so a ray through an edge shared by two triangles meets one of them.
    rtcSetSceneFlags(m.scene, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION));
    RTCGeometry geometry = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), corners.size()));
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), m.owner.size()));
    if (!v || !t) {
        rtcReleaseGeometry(geometry);
        throw std::runtime_error("embree: out of memory for " + std::to_string(m.owner.size()) + " triangles");
    }
    for (std::size_t k = 0; k < corners.size(); ++k) {
        const glm::dvec3 x = corners[k] - m.centre;
        v[3 * k] = float(x.x);
        v[3 * k + 1] = float(x.y);
        v[3 * k + 2] = float(x.z);
        t[k] = unsigned(k);
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(m.scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(m.scene);
}

SurfaceRays::~SurfaceRays() = default;

std::vector<int> SurfaceRays::first_hits(const glm::dvec3& from, const glm::dvec3& dir, double slack) const {
    const Impl& m = *m_impl;
    if (!m.scene) return {};
    RTCRayHit rh = embree_ray(from, glm::normalize(dir), 0.0, std::numeric_limits<double>::infinity(), m.centre);
    RTCIntersectContext first;
    rtcInitIntersectContext(&first);
    rtcIntersect1(m.scene, &first, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
    // Everything within the slack of the first hit, either side.
    const double t = double(rh.ray.tfar);
    std::vector<int> found{m.owner[rh.hit.primID]};
    Collector c{{}, &m.owner, &found};
    rtcInitIntersectContext(&c.context);
    c.context.filter = collect;
    rh.ray.tnear = float(std::max(0.0, t - slack));
    rh.ray.tfar = float(t + slack);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m.scene, &c.context, &rh);
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
    return found;
}

}  // namespace bounce
