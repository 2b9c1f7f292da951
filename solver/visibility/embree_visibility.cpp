// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "solver/visibility/visibility.h"

namespace bounce {
namespace {

/// Embree 3 BVH of the patches' triangles, in single precision. Coordinates are recentred on
/// the scene's bounding box before rounding to float, so the rounding error scales with the
/// scene's size rather than its distance from the origin: it stays near 6e-8 of the diagonal,
/// far below the 1e-6 endpoint offset that keeps rays off their own patches.
class EmbreeVisibility final : public Visibility {
public:
    EmbreeVisibility(const std::vector<Patch>& patches, std::span<const OccluderTriangle> occluders) {
        m_centre = fit_offset(patches);
        m_has_occluders = !occluders.empty();
        std::size_t triangles = occluders.size();
        for (const auto& p : patches) triangles += std::size_t(p.vertex_count - 2);

        // "verbose=0": Embree would otherwise print to stdout, which may be a pipe we own.
        m_device = rtcNewDevice("verbose=0");
        if (!m_device)
            throw std::runtime_error("embree: cannot create a device (error " +
                                     std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
        m_scene = rtcNewScene(m_device);
        // ROBUST: watertight traversal, so a ray through an edge shared by two triangles hits
        // one of them instead of slipping through the crack.
        rtcSetSceneFlags(m_scene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(m_scene, RTC_BUILD_QUALITY_HIGH);
        if (triangles > 0) {
            RTCGeometry geometry = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
            std::size_t vertex_count = 3 * occluders.size();
            for (const auto& p : patches) vertex_count += std::size_t(p.vertex_count);
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                                  RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertex_count));
            auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
                geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles));
            if (!v || !t)
                throw std::runtime_error("embree: out of memory for " + std::to_string(triangles) + " triangles");
            unsigned base = 0;
            m_patch_of.reserve(triangles);
            for (std::size_t i = 0; i < patches.size(); ++i) {
                const Patch& p = patches[i];
                m_patch_of.insert(m_patch_of.end(), std::size_t(p.vertex_count - 2), int(i));
                for (int k = 0; k < p.vertex_count; ++k) {
                    const glm::dvec3 x = p.vertices[k] - m_centre;
                    *v++ = float(x.x);
                    *v++ = float(x.y);
                    *v++ = float(x.z);
                }
                for (int k = 1; k + 1 < p.vertex_count; ++k) {
                    *t++ = base;
                    *t++ = base + unsigned(k);
                    *t++ = base + unsigned(k + 1);
                }
                base += unsigned(p.vertex_count);
            }
            m_patch_of.insert(m_patch_of.end(), occluders.size(), kOccluder);
            for (const auto& tri : occluders) {
                for (const auto& corner : tri) {
                    const glm::dvec3 x = corner - m_centre;
                    *v++ = float(x.x);
                    *v++ = float(x.y);
                    *v++ = float(x.z);
                    *t++ = base++;
                }
            }
            rtcCommitGeometry(geometry);
            rtcAttachGeometry(m_scene, geometry);
            rtcReleaseGeometry(geometry);
        }
        rtcCommitScene(m_scene);
        if (const RTCError e = rtcGetDeviceError(m_device); e != RTC_ERROR_NONE) {
            release();
            throw std::runtime_error("embree: scene build failed (error " + std::to_string(int(e)) + ")");
        }
    }
    ~EmbreeVisibility() override { release(); }
    EmbreeVisibility(const EmbreeVisibility&) = delete;
    EmbreeVisibility& operator=(const EmbreeVisibility&) = delete;

    bool occluded(const glm::dvec3& a, const glm::dvec3& b) const override {
        const double t0 = trim(a, b);
        if (t0 >= 0.5) return false;
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay ray = segment_ray(a, b, t0);
        rtcOccluded1(m_scene, &context, &ray);
        // Embree marks an occluded ray by setting tfar to -inf.
        return ray.tfar < 0.0f;
    }
    void occluded(std::span<const Segment> segments, std::span<std::uint8_t> blocked) const override {
        // Packets of four (SSE width, available on every x86-64): a pair's rays run between
        // the same two patches, so they traverse the same BVH nodes. Long batches (a gather
        // point's rays to every patch, in patch order, so neighbours run to neighbouring
        // patches) go sixteen at a time: the final gather of the default Cornell box took 14%
        // less CPU than in fours (bench_reference, BM_GatherVertices).
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        std::size_t base = 0;
        for (; base + 16 <= segments.size(); base += 16) trace_packet<RTCRay16, 16>(segments, base, blocked, context);
        for (; base < segments.size(); base += 4) trace_packet<RTCRay4, 4>(segments, base, blocked, context);
    }
    int first_patch(const glm::dvec3& a, const glm::dvec3& b) const override {
        const double t0 = trim(a, b);
        if (t0 >= 0.5) return kNothing;
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh{};
        rh.ray = segment_ray(a, b, t0);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(m_scene, &context, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return kNothing;
        return m_patch_of[rh.hit.primID];
    }
    std::string name() const override { return "embree"; }

private:
    /// The segment a-b as an Embree ray: t in [t0, 1 - t0] along the unnormalised direction b - a
    /// (trimmed by trim()), the origin recentred.
    RTCRay segment_ray(const glm::dvec3& a, const glm::dvec3& b, double t0) const {
        RTCRay ray{};
        const glm::dvec3 o = a - m_centre, d = b - a;
        ray.org_x = float(o.x);
        ray.org_y = float(o.y);
        ray.org_z = float(o.z);
        ray.dir_x = float(d.x);
        ray.dir_y = float(d.y);
        ray.dir_z = float(d.z);
        ray.tnear = float(t0);
        ray.tfar = float(1.0 - t0);
        ray.mask = 0xFFFFFFFFu;
        ray.flags = 0;
        return ray;
    }

    /// Segments [base, base + N) (fewer at the end) as one packet of N; a segment shorter than
    /// twice the offset is left invalid and reported open.
    template <class Packet, int N>
    void trace_packet(std::span<const Segment> segments, std::size_t base, std::span<std::uint8_t> blocked,
                      RTCIntersectContext& context) const {
        Packet packet{};
        alignas(64) int valid[N] = {};
        const std::size_t count = std::min<std::size_t>(N, segments.size() - base);
        for (std::size_t k = 0; k < count; ++k) {
            const double t0 = trim(segments[base + k].a, segments[base + k].b);
            if (t0 >= 0.5) continue;  // nothing to test
            const glm::dvec3 o = segments[base + k].a - m_centre, d = segments[base + k].b - segments[base + k].a;
            packet.org_x[k] = float(o.x);
            packet.org_y[k] = float(o.y);
            packet.org_z[k] = float(o.z);
            packet.dir_x[k] = float(d.x);
            packet.dir_y[k] = float(d.y);
            packet.dir_z[k] = float(d.z);
            packet.tnear[k] = float(t0);
            packet.tfar[k] = float(1.0 - t0);
            packet.mask[k] = 0xFFFFFFFFu;
            valid[k] = -1;
        }
        if constexpr (N == 16)
            rtcOccluded16(valid, m_scene, &context, &packet);
        else
            rtcOccluded4(valid, m_scene, &context, &packet);
        for (std::size_t k = 0; k < count; ++k) blocked[base + k] = valid[k] && packet.tfar[k] < 0.0f;
    }

    void release() {
        if (m_scene) rtcReleaseScene(m_scene);
        if (m_device) rtcReleaseDevice(m_device);
        m_scene = nullptr;
        m_device = nullptr;
    }

    glm::dvec3 m_centre{0.0};
    std::vector<int> m_patch_of;  // per triangle: its patch, or kOccluder
    RTCDevice m_device = nullptr;
    RTCScene m_scene = nullptr;
};

}  // namespace

std::unique_ptr<Visibility> make_embree_visibility(const std::vector<Patch>& patches,
                                                   std::span<const OccluderTriangle> occluders) {
    return std::make_unique<EmbreeVisibility>(patches, occluders);
}

std::vector<std::string> visibility_backends() { return {"embree", "cgal"}; }

std::unique_ptr<Visibility> make_visibility(const std::string& backend, const std::vector<Patch>& patches,
                                            std::span<const OccluderTriangle> occluders) {
    if (backend == "embree") return make_embree_visibility(patches, occluders);
    if (backend == "cgal") return make_cgal_visibility(patches, occluders);
    throw std::invalid_argument("unknown visibility backend '" + backend + "' (valid: embree, cgal)");
}

}  // namespace bounce
