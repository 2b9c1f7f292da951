// SPDX-License-Identifier: MIT
#include "solver/reference/path_tracer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>

#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "mesh/polygon.h"
#include "mesh/sphere.h"
#include "solver/optics/fresnel.h"

namespace bounce {

std::string to_string(EstimateStatus s) {
    switch (s) {
        case EstimateStatus::converged:
            return "converged";
        case EstimateStatus::budget:
            return "budget";
        case EstimateStatus::interrupted:
            return "interrupted";
    }
    return "?";
}

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kStrataSide = 8;
constexpr int kBatch = kStrataSide * kStrataSide;  // paths per stratified batch
constexpr int kStratifiedEmitters = 8;             // first-vertex samples of further emitters are plain random
// Russian roulette ends every path with probability >= 1 - max(rho) per bounce; only a closed
// scene of reflectance exactly 1 could run on, and this cap stops it (a bias of rho^cap).
constexpr int kMaxDepth = 100000;
// Mirror and glass bounces between two diffuse vertices (or after the eye): light trapped by
// total internal reflection in a non-spherical glass object is dropped after this many.
constexpr int kMaxSpecularBounces = 1000;

/// Uniform doubles in [0,1) from the standard 64-bit Mersenne twister.
class Random {
public:
    Random(std::uint64_t seed, std::uint64_t stream) {
        std::seed_seq seq{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(stream),
                          std::uint32_t(stream >> 32), 0x62u /* 'b' */};
        m_engine.seed(seq);
    }
    double uniform() { return double(m_engine() >> 11) * 0x1.0p-53; }
    std::mt19937_64& engine() { return m_engine; }

private:
    std::mt19937_64 m_engine;
};

/// Orthonormal basis around a unit normal (Duff et al. 2017, "Building an orthonormal basis,
/// revisited"): tangents t, b with t x b = n.
void orthonormal_basis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    t = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = glm::dvec3(c, sign + n.y * n.y * a, -n.y);
}

/// Cosine-weighted direction about n (pdf cos/pi) by Malley's method on Shirley and Chiu's
/// concentric disk map, which keeps the strata of (u1, u2) compact on the hemisphere.
glm::dvec3 cosine_direction(const glm::dvec3& n, double u1, double u2) {
    const double a = 2 * u1 - 1, b = 2 * u2 - 1;
    double r = 0, phi = 0;
    if (a != 0 || b != 0) {
        if (std::abs(a) > std::abs(b)) {
            r = a;
            phi = (kPi / 4) * (b / a);
        } else {
            r = b;
            phi = kPi / 2 - (kPi / 4) * (a / b);
        }
    }
    const double x = r * std::cos(phi), y = r * std::sin(phi);
    const double z = std::sqrt(std::max(0.0, 1 - x * x - y * y));
    glm::dvec3 t, bt;
    orthonormal_basis(n, t, bt);
    return glm::normalize(x * t + y * bt + z * n);
}

double point_segment_distance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double s = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + s * ab));
}

/// Running mean and variance (Welford) of the batch means of r, g, b and luminance.
struct BatchStatistics {
    std::uint64_t count = 0;
    std::array<double, 4> mean{}, m2{};
    void add(const Rgb& v) {
        const std::array<double, 4> x{v.r, v.g, v.b, v.luminance()};
        ++count;
        for (int c = 0; c < 4; ++c) {
            const double d = x[c] - mean[c];
            mean[c] += d / double(count);
            m2[c] += d * (x[c] - mean[c]);
        }
    }
    /// Standard error of the mean of channel c (0-2 RGB, 3 luminance).
    double standard_error(int c) const {
        return count > 1 ? std::sqrt(m2[c] / double(count - 1) / double(count)) : 0.0;
    }
};

}  // namespace

struct PathTracer::Impl {
    struct SurfaceData {
        glm::dvec3 normal{0.0};  // unit front normal
        glm::dvec3 origin{0.0};  // a vertex, for the plane
        double area = 0.0;
        Rgb reflectance, emission;
        MaterialKind kind = MaterialKind::diffuse;
        Rgb specular;      // mirror reflectance or glass transmittance per passage
        double ior = 1.0;  // glass
        std::vector<std::array<int, 3>> triangles;
        std::vector<double> cumulative;  // running triangle areas, last = area
        double size = 0.0;               // sqrt(area)
    };

    RTCDevice device = nullptr;
    RTCScene rtc_scene = nullptr;
    glm::dvec3 centre{0.0};
    double epsilon = 0.0;  // ray origin offset along the normal
    // Scene::surfaces (diffuse) first, then Scene::specular_surfaces: surface index
    // scene.surfaces.size() + k is specular_surfaces[k].
    std::vector<SurfaceData> surfaces;
    std::vector<Sphere> spheres;        // analytic, intersected beside Embree's triangles
    std::vector<int> triangle_surface;  // Embree primitive -> surface
    std::vector<int> emitters;          // surfaces with emission

    ~Impl() {
        if (rtc_scene) rtcReleaseScene(rtc_scene);
        if (device) rtcReleaseDevice(device);
    }

    struct Hit {
        double t = 0;
        int surface = -1;                                  // a polygon (index into surfaces), or
        int sphere = -1;                                   // an analytic sphere (index into spheres)
        glm::dvec3 sphere_point{0.0}, sphere_normal{0.0};  // on a sphere: the exact point, outward unit normal
        bool missed() const { return surface < 0 && sphere < 0; }
    };

    /// The polygon of surface s, diffuse or specular.
    const std::vector<glm::dvec3>& polygon(const Scene& scene, int s) const {
        const std::size_t n = scene.surfaces.size();
        return std::size_t(s) < n ? scene.surfaces[std::size_t(s)].vertices
                                  : scene.specular_surfaces[std::size_t(s) - n].vertices;
    }

    /// Closest hit of a polygon or a sphere along o + t d, t in (tnear, tfar). Spheres are
    /// few in the scenes this serves (the seed's box has two), so they are tested one by one,
    /// exactly, in double precision.
    Hit trace_all(const glm::dvec3& o, const glm::dvec3& d, double tnear, double tfar) const {
        Hit best = trace(o, d, tnear, tfar);
        double t_max = best.missed() ? tfar : best.t;
        for (std::size_t k = 0; k < spheres.size(); ++k)
            if (const auto h = intersect_sphere(spheres[k], o, d, tnear, t_max)) {
                best = {h->t, -1, int(k), h->position, h->normal};
                t_max = h->t;
            }
        return best;
    }

    /// Closest hit along o + t d, t in (tnear, tfar); surface -1 when nothing is hit.
    Hit trace(const glm::dvec3& o, const glm::dvec3& d, double tnear, double tfar) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh{};
        const glm::dvec3 oc = o - centre;
        rh.ray.org_x = float(oc.x);
        rh.ray.org_y = float(oc.y);
        rh.ray.org_z = float(oc.z);
        rh.ray.dir_x = float(d.x);
        rh.ray.dir_y = float(d.y);
        rh.ray.dir_z = float(d.z);
        rh.ray.tnear = float(tnear);
        rh.ray.tfar = float(tfar);
        rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rtc_scene, &context, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
        return {double(rh.ray.tfar), triangle_surface[rh.hit.primID]};
    }

    /// True when something lies strictly between a and b.
    bool occluded(const glm::dvec3& a, const glm::dvec3& b) const {
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
        rtcOccluded1(rtc_scene, &context, &ray);
        if (ray.tfar < 0.0f) return true;
        for (const auto& sphere : spheres)
            if (intersect_sphere(sphere, a, b - a, 1e-9, 1.0 - 1e-9)) return true;
        return false;
    }

    /// A point of surface s, uniform by area, from (u1, u2) in [0,1)^2.
    glm::dvec3 sample_surface(const Scene& scene, int s, double u1, double u2) const {
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
        return b0 * poly[std::size_t(tri[0])] + b1 * poly[std::size_t(tri[1])] +
               (1 - b0 - b1) * poly[std::size_t(tri[2])];
    }

    /// Next-event estimate of sum_e E_e * F(dA_x -> e) * V at x: one area sample per emitter,
    /// weighted by multiple importance sampling against the cosine-sampled continuation.
    template <class Sample>
    Rgb direct(const Scene& scene, const glm::dvec3& x, const glm::dvec3& n, int surface, Sample&& sample) const {
        Rgb sum;
        const glm::dvec3 xo = x + epsilon * n;
        for (std::size_t k = 0; k < emitters.size(); ++k) {
            const int e = emitters[k];
            if (e == surface) continue;  // a planar surface does not see itself
            const SurfaceData& ed = surfaces[std::size_t(e)];
            const auto [u1, u2] = sample(k);
            const glm::dvec3 y = sample_surface(scene, e, u1, u2);
            const glm::dvec3 w = y - x;
            const double r2 = glm::dot(w, w);
            if (!(r2 > 0)) continue;
            const double r = std::sqrt(r2);
            const double cos_x = glm::dot(n, w) / r, cos_y = -glm::dot(ed.normal, w) / r;
            if (cos_x <= 0 || cos_y <= 0) continue;
            if (occluded(xo, y + epsilon * ed.normal)) continue;
            // Balance heuristic against the cosine-sampled direction (Veach 1997, 9.2): area
            // sampling alone has unbounded variance beside a shared edge, where cos cos'/r^2
            // blows up; the combined weight E cos/pi / (p_light + p_cos) stays below E.
            const double p_light = r2 / (cos_y * ed.area), p_cos = cos_x / kPi;
            sum += ed.emission * ((cos_x / kPi) / (p_light + p_cos));
        }
        return sum;
    }

    /// Where a ray that leaves a diffuse point (or the eye) arrives after the mirrors and glass
    /// it meets: a diffuse surface's front, or nothing (it escapes, meets a back face, or is
    /// absorbed).
    struct Arrival {
        int surface = -1;               // the diffuse surface met; -1: the path ends
        glm::dvec3 position{0.0};       // on that surface's plane
        glm::dvec3 direction{0.0};      // of the last segment, unit
        double distance = 0.0;          // length of the last segment
        bool through_specular = false;  // a mirror or glass redirected the ray on the way
    };

    /// Follows o + t d through ideal specular surfaces. A mirror reflects from its front (its
    /// back is black, like any one-sided face) and scales `throughput` by its reflectance.
    /// Glass is a dielectric whose front is the outside: at each crossing the ray is reflected
    /// with the Fresnel probability F (1 past the critical angle) and refracted otherwise, so
    /// the estimator needs no weight for the choice (the expectation is F L_r + (1 - F) L_t);
    /// entering, the throughput takes the transmittance colour. `uniform` draws in [0, 1).
    template <class Uniform>
    Arrival follow(const Scene& scene, glm::dvec3 o, glm::dvec3 d, Rgb& throughput, Uniform&& uniform) const {
        Arrival out;
        for (int bounce = 0; bounce <= kMaxSpecularBounces; ++bounce) {
            const Hit hit = trace_all(o, d, 0.0, std::numeric_limits<float>::infinity());
            if (hit.missed()) return {};
            glm::dvec3 y, n;
            MaterialKind kind;
            Rgb specular;
            double ior;
            if (hit.sphere >= 0) {
                const Material& m = scene.materials[std::size_t(spheres[std::size_t(hit.sphere)].material)];
                y = hit.sphere_point;
                n = hit.sphere_normal;
                kind = m.kind;
                specular = m.specular;
                ior = m.ior;
            } else {
                const SurfaceData& sd = surfaces[std::size_t(hit.surface)];
                if (glm::dot(sd.normal, d) >= 0 && sd.kind != MaterialKind::glass) return {};  // a back face: black
                y = o + hit.t * d;
                y -= glm::dot(y - sd.origin, sd.normal) * sd.normal;  // back onto the plane, exactly
                if (sd.kind == MaterialKind::diffuse) {
                    out.surface = hit.surface;
                    out.position = y;
                    out.direction = d;
                    out.distance = hit.t;
                    return out;
                }
                n = sd.normal;
                kind = sd.kind;
                specular = sd.specular;
                ior = sd.ior;
            }
            out.through_specular = true;
            const double cos_i = -glm::dot(d, n);
            if (kind == MaterialKind::mirror) {
                if (!(cos_i > 0)) return {};
                throughput = throughput * specular;
                d = glm::normalize(reflect(d, n));
                o = y + epsilon * n;
            } else {
                const bool entering = cos_i > 0;
                const glm::dvec3 facing = entering ? n : -n;  // the normal on the side d comes from
                const double n1 = entering ? 1.0 : ior, n2 = entering ? ior : 1.0;
                const double reflectance = fresnel_dielectric(std::abs(cos_i), n1, n2);
                const auto refracted = refract(d, facing, n1, n2);
                if (!refracted || uniform() < reflectance) {
                    d = glm::normalize(reflect(d, facing));
                    o = y + epsilon * facing;
                } else {
                    d = *refracted;
                    o = y - epsilon * facing;
                    if (entering) throughput = throughput * specular;
                }
            }
            if (!(throughput.max() > 0)) return {};
        }
        return {};
    }

    /// One path's estimate of the radiosity reflected at the diffuse point (x, n) of surface
    /// `surface`, starting with `throughput` (rho(x) for B(x)): next-event estimation at every
    /// diffuse vertex, cosine-sampled continuation through mirrors and glass (follow), Russian
    /// roulette on the reflectance. An emitter met through a mirror or glass counts whole: the
    /// area sample cannot reach it that way, so its balance-heuristic share is 1.
    /// `first_emitter(k)` and `first_direction()` give the first vertex's samples (stratified by
    /// the caller); later vertices draw from rng.
    template <class Rng, class FirstEmitter, class FirstDirection>
    Rgb reflected(const Scene& scene, glm::dvec3 pos, glm::dvec3 normal, int surface, Rgb throughput, Rng& rng,
                  FirstEmitter&& first_emitter, FirstDirection&& first_direction) const {
        Rgb sum;
        auto random_pair = [&](std::size_t) { return std::pair{rng.uniform(), rng.uniform()}; };
        auto uniform = [&] { return rng.uniform(); };
        for (int depth = 0; depth < kMaxDepth && throughput.max() > 0; ++depth) {
            glm::dvec3 dir;
            if (depth == 0) {
                sum += throughput * direct(scene, pos, normal, surface, first_emitter);
                const auto [u1, u2] = first_direction();
                dir = cosine_direction(normal, u1, u2);
            } else {
                sum += throughput * direct(scene, pos, normal, surface, random_pair);
                const double u1 = rng.uniform(), u2 = rng.uniform();
                dir = cosine_direction(normal, u1, u2);
            }
            const double cos_x = glm::dot(normal, dir);
            const Arrival a = follow(scene, pos + epsilon * normal, dir, throughput, uniform);
            if (a.surface < 0) break;  // escapes through an opening, or meets a back face
            const auto& sh = surfaces[std::size_t(a.surface)];
            if (sh.emission.max() > 0) {
                double weight = 1.0;
                if (!a.through_specular) {
                    // The cosine-sampled half of the multiple importance sampling of emitters.
                    const double cos_y = -glm::dot(sh.normal, a.direction);
                    const double p_cos = cos_x / kPi;
                    const double p_light = a.distance * a.distance / (cos_y * sh.area);
                    weight = p_cos / (p_cos + p_light);
                }
                sum += throughput * sh.emission * weight;
            }
            const double survive = sh.reflectance.max();  // Russian roulette on rho
            if (!(survive > 0) || rng.uniform() >= survive) break;
            throughput = throughput * sh.reflectance * (1.0 / survive);
            pos = a.position;
            normal = sh.normal;
            surface = a.surface;
        }
        return sum;
    }
};

PathTracer::PathTracer(const Scene& scene) : m_scene(scene), m_impl(std::make_unique<Impl>()) {
    Impl& im = *m_impl;
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    std::size_t triangle_count = 0;
    const std::size_t diffuse_count = scene.surfaces.size();
    im.surfaces.resize(diffuse_count + scene.specular_surfaces.size());
    for (std::size_t s = 0; s < im.surfaces.size(); ++s) {
        const Surface& surf = s < diffuse_count ? scene.surfaces[s] : scene.specular_surfaces[s - diffuse_count];
        auto& sd = im.surfaces[s];
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
        if (sd.area > 0 && sd.emission.max() > 0 && sd.kind == MaterialKind::diffuse) im.emitters.push_back(int(s));
    }
    for (const Sphere& sphere : scene.spheres) {
        im.spheres.push_back(sphere);
        // The ellipsoid lies within the image of the cube [-1, 1]^3.
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 c = sphere.transform.point({k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0});
            lo = glm::min(lo, c);
            hi = glm::max(hi, c);
        }
    }
    if (triangle_count == 0) throw std::invalid_argument("path tracer: the scene has no surfaces of positive area");
    m_diagonal = glm::length(hi - lo);
    im.centre = 0.5 * (lo + hi);
    // Recentred single-precision coordinates round to about 6e-8 of the diagonal; the offset
    // keeps rays off the plane they leave, far above that and far below any modelled gap.
    im.epsilon = 1e-6 * m_diagonal;

    im.device = rtcNewDevice("verbose=0");
    if (!im.device) throw std::runtime_error("embree: cannot create a device");
    im.rtc_scene = rtcNewScene(im.device);
    rtcSetSceneFlags(im.rtc_scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(im.rtc_scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geometry = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), 3 * triangle_count));
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), triangle_count));
    if (!v || !t) {
        rtcReleaseGeometry(geometry);
        throw std::runtime_error("embree: out of memory for " + std::to_string(triangle_count) + " triangles");
    }
    unsigned base = 0;
    im.triangle_surface.reserve(triangle_count);
    for (std::size_t s = 0; s < im.surfaces.size(); ++s) {
        const auto& poly = im.polygon(scene, int(s));
        for (const auto& tri : im.surfaces[s].triangles) {
            for (int k = 0; k < 3; ++k) {
                const glm::dvec3 x = poly[std::size_t(tri[std::size_t(k)])] - im.centre;
                *v++ = float(x.x);
                *v++ = float(x.y);
                *v++ = float(x.z);
                *t++ = base++;
            }
            im.triangle_surface.push_back(int(s));
        }
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(im.rtc_scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(im.rtc_scene);
    if (rtcGetDeviceError(im.device) != RTC_ERROR_NONE) throw std::runtime_error("embree: scene build failed");
}

PathTracer::~PathTracer() = default;

std::string PathTracer::surface_name(int surface) const {
    const std::size_t n = m_scene.surfaces.size();
    const auto& s = std::size_t(surface) < n ? m_scene.surfaces.at(std::size_t(surface))
                                             : m_scene.specular_surfaces.at(std::size_t(surface) - n);
    return s.object.empty() ? "surface " + std::to_string(surface) : s.object;
}

std::optional<SurfacePoint> PathTracer::locate(const glm::dvec3& p, const glm::dvec3& n_in) const {
    const Impl& im = *m_impl;
    const double len = glm::length(n_in);
    if (!(len > 0) || !std::isfinite(len)) return std::nullopt;
    const glm::dvec3 n = n_in / len;
    const double snap = snap_distance();
    // Walk every crossing of the segment p + n*snap -> p - n*snap and keep the facing one
    // nearest to p.
    const glm::dvec3 o = p + snap * n;
    double tnear = 0;
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 64; ++k) {
        const auto hit = im.trace(o, -n, tnear, 2 * snap);
        if (hit.surface < 0) break;
        const auto& sd = im.surfaces[std::size_t(hit.surface)];
        if (sd.kind == MaterialKind::diffuse && glm::dot(sd.normal, n) > 0) {
            // Exact distance along n to the surface's plane, in double precision.
            const double t = glm::dot(sd.origin - p, sd.normal) / glm::dot(n, sd.normal);
            if (std::abs(t) < best_distance) {
                best_distance = std::abs(t);
                best = hit.surface;
            }
        }
        tnear = hit.t + 1e-7 * m_diagonal;
    }
    if (best < 0 || best_distance > snap) return std::nullopt;
    const auto& sd = im.surfaces[std::size_t(best)];
    const double t = glm::dot(sd.origin - p, sd.normal) / glm::dot(n, sd.normal);
    return SurfacePoint{p + t * n, sd.normal, best};
}

RadiosityEstimate PathTracer::estimate(const SurfacePoint& x, const ReferenceOptions& options, std::uint64_t index,
                                       const std::atomic<bool>* stop) const {
    const Impl& im = *m_impl;
    const auto& sx = im.surfaces.at(std::size_t(x.surface));
    Random rng(options.seed, index);
    BatchStatistics stats;
    std::uint64_t paths = 0;
    RadiosityEstimate out;
    out.status = EstimateStatus::interrupted;

    const std::size_t stratified = std::min<std::size_t>(im.emitters.size(), kStratifiedEmitters);
    std::vector<std::array<int, kBatch>> emitter_strata(stratified);
    std::array<int, kBatch> direction_strata{};
    auto jittered = [&](int stratum) {
        return std::pair{(double(stratum % kStrataSide) + rng.uniform()) / kStrataSide,
                         (double(stratum / kStrataSide) + rng.uniform()) / kStrataSide};
    };
    auto random_pair = [&](std::size_t) { return std::pair{rng.uniform(), rng.uniform()}; };

    // One batch of kBatch paths; returns the mean reflected radiosity of its paths.
    auto run_batch = [&]() {
        // One batch: its first-vertex samples cover the 8x8 strata once each, in an order
        // drawn afresh so emitter and direction strata pair up at random.
        for (auto& strata : emitter_strata) {
            for (int k = 0; k < kBatch; ++k) strata[std::size_t(k)] = k;
            std::shuffle(strata.begin(), strata.end(), rng.engine());
        }
        for (int k = 0; k < kBatch; ++k) direction_strata[std::size_t(k)] = k;
        std::shuffle(direction_strata.begin(), direction_strata.end(), rng.engine());

        Rgb batch_sum;
        for (int path = 0; path < kBatch; ++path) {
            const Rgb reflected = im.reflected(
                m_scene, x.position, sx.normal, x.surface, sx.reflectance, rng,
                [&](std::size_t e) {
                    return e < stratified ? jittered(emitter_strata[e][std::size_t(path)]) : random_pair(e);
                },
                [&] { return jittered(direction_strata[std::size_t(path)]); });
            batch_sum += reflected;
        }
        return batch_sum * (1.0 / kBatch);
    };
    // Paths (whole batches) that statistics s predict for the target, with 10% to spare.
    auto planned = [&](const BatchStatistics& s) -> std::uint64_t {
        const double goal = options.target_error * (sx.emission.luminance() + s.mean[3]);
        const double se = s.standard_error(3);
        if (!(goal > 0)) return se > 0 ? options.max_paths : options.min_paths;
        const double batches = 1.1 * double(s.count) * (se / goal) * (se / goal);
        return std::uint64_t(std::min(std::ceil(batches), double(options.max_paths))) * kBatch;
    };
    auto stopped = [&] { return stop && stop->load(std::memory_order_relaxed); };

    // Sequential stopping on the running estimate is biased (it stops more often on a high
    // draw). A pilot run, thrown away, plans the number of paths instead; the estimate is then
    // made from fresh paths, and re-planned only in the rare case the plan fell short.
    std::uint64_t plan = options.max_paths;
    if (options.target_error > 0) {
        BatchStatistics pilot;
        for (std::uint64_t k = 0; k < options.min_paths && !stopped(); k += kBatch) pilot.add(run_batch());
        m_paths.fetch_add(pilot.count * kBatch, std::memory_order_relaxed);
        if (stopped()) return out;
        plan = std::clamp(planned(pilot), options.min_paths, options.max_paths);
    }
    while (true) {
        while (paths < plan) {
            if (stopped()) break;
            stats.add(run_batch());
            paths += kBatch;
        }
        const double mean_lum = sx.emission.luminance() + stats.mean[3];
        if (paths > 0 && options.target_error > 0 && stats.standard_error(3) <= options.target_error * mean_lum) {
            out.status = EstimateStatus::converged;
            break;
        }
        if (stopped()) {
            out.status = EstimateStatus::interrupted;
            break;
        }
        if (paths >= options.max_paths) {
            out.status = EstimateStatus::budget;
            break;
        }
        plan = std::min(options.max_paths, std::max(paths + kBatch, planned(stats)));
    }
    out.paths = paths;
    out.radiosity = sx.emission + Rgb(stats.mean[0], stats.mean[1], stats.mean[2]);
    out.standard_error = Rgb(stats.standard_error(0), stats.standard_error(1), stats.standard_error(2));
    m_paths.fetch_add(paths, std::memory_order_relaxed);
    return out;
}

RadianceEstimate PathTracer::radiance(const glm::dvec3& origin, const glm::dvec3& direction, std::uint64_t paths,
                                      std::uint64_t seed, std::uint64_t index) const {
    return pixel_radiance(origin, direction, glm::dvec3(0.0), glm::dvec3(0.0), paths, seed, index);
}

RadianceEstimate PathTracer::pixel_radiance(const glm::dvec3& origin, const glm::dvec3& corner, const glm::dvec3& du,
                                            const glm::dvec3& dv, std::uint64_t paths, std::uint64_t seed,
                                            std::uint64_t index) const {
    const Impl& im = *m_impl;
    Random rng(seed, index);
    BatchStatistics stats;
    auto random_pair = [&](std::size_t) { return std::pair{rng.uniform(), rng.uniform()}; };
    const bool area = glm::length(du) > 0 || glm::length(dv) > 0;
    std::array<int, kBatch> strata{};
    const std::uint64_t batches = std::max<std::uint64_t>(2, (paths + kBatch - 1) / kBatch);
    for (std::uint64_t b = 0; b < batches; ++b) {
        Rgb batch_sum;
        if (area) {
            for (int k = 0; k < kBatch; ++k) strata[std::size_t(k)] = k;
            std::shuffle(strata.begin(), strata.end(), rng.engine());
        }
        for (int path = 0; path < kBatch; ++path) {
            glm::dvec3 d = corner;
            if (area) {
                const int stratum = strata[std::size_t(path)];
                const double u = (double(stratum % kStrataSide) + rng.uniform()) / kStrataSide;
                const double v = (double(stratum / kStrataSide) + rng.uniform()) / kStrataSide;
                d += u * du + v * dv;
            }
            d = glm::normalize(d);
            Rgb throughput = Rgb::gray(1.0);
            const auto a = im.follow(m_scene, origin, d, throughput, [&] { return rng.uniform(); });
            if (a.surface < 0) continue;
            const auto& sh = im.surfaces[std::size_t(a.surface)];
            const Rgb b_sample = sh.emission + im.reflected(m_scene, a.position, sh.normal, a.surface, sh.reflectance,
                                                            rng, random_pair, [&] { return random_pair(0); });
            batch_sum += throughput * b_sample * (1.0 / kPi);
        }
        stats.add(batch_sum * (1.0 / kBatch));
    }
    m_paths.fetch_add(batches * kBatch, std::memory_order_relaxed);
    return {Rgb(stats.mean[0], stats.mean[1], stats.mean[2]),
            Rgb(stats.standard_error(0), stats.standard_error(1), stats.standard_error(2)), batches * kBatch};
}

PixelSample PathTracer::pixel_sample(const glm::dvec3& origin, const glm::dvec3& corner, const glm::dvec3& du,
                                     const glm::dvec3& dv, std::uint64_t seed, std::uint64_t index) const {
    const Impl& im = *m_impl;
    Random rng(seed, index);
    auto random_pair = [&](std::size_t) { return std::pair{rng.uniform(), rng.uniform()}; };
    const double u = rng.uniform(), v = rng.uniform();
    Rgb throughput = Rgb::gray(1.0);
    const auto a =
        im.follow(m_scene, origin, glm::normalize(corner + u * du + v * dv), throughput, [&] { return rng.uniform(); });
    m_paths.fetch_add(1, std::memory_order_relaxed);
    if (a.surface < 0) return {};
    const auto& sh = im.surfaces[std::size_t(a.surface)];
    const Rgb b = sh.emission + im.reflected(m_scene, a.position, sh.normal, a.surface, sh.reflectance, rng,
                                             random_pair, [&] { return random_pair(0); });
    return {throughput * b * (1.0 / kPi), a.surface};
}

std::vector<RadiosityEstimate> PathTracer::estimate_all(std::span<const SurfacePoint> points,
                                                        const ReferenceOptions& options,
                                                        const std::function<void(std::size_t, std::size_t)>& progress,
                                                        const std::atomic<bool>* stop) const {
    std::vector<RadiosityEstimate> out(points.size());
    std::atomic<std::size_t> done{0};
    tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) {
        if (stop && stop->load(std::memory_order_relaxed)) return;  // left as interrupted, 0 paths
        out[i] = estimate(points[i], options, i, stop);
        const std::size_t d = ++done;
        if (progress) progress(d, points.size());
    });
    return out;
}

std::vector<SurfacePoint> PathTracer::probes(std::size_t n, std::uint64_t seed) const {
    const Impl& im = *m_impl;
    std::vector<int> candidates;
    std::vector<double> cumulative;
    double total = 0;
    for (std::size_t s = 0; s < im.surfaces.size(); ++s) {
        const auto& sd = im.surfaces[s];
        if (sd.area > 0 && !(sd.emission.max() > 0) && sd.kind == MaterialKind::diffuse) {
            total += sd.area;
            candidates.push_back(int(s));
            cumulative.push_back(total);
        }
    }
    std::vector<SurfacePoint> out;
    if (candidates.empty() || n == 0) return out;
    Random rng(seed, 0xB0B0u);

    // Whether x lies open to the scene: at least 4 of 16 cosine rays leave without meeting a
    // back face first. A floor under a block is enclosed; so is a ceiling deep behind a lamp
    // hung just below it, which light reaches only through the gap and no viewer sees.
    auto reachable = [&](const glm::dvec3& x, const glm::dvec3& normal) {
        int open = 0;
        for (int k = 0; k < 16; ++k) {
            const glm::dvec3 d = cosine_direction(normal, (k % 4 + rng.uniform()) / 4, (k / 4 + rng.uniform()) / 4);
            const auto hit = im.trace_all(x + im.epsilon * normal, d, 0.0, std::numeric_limits<float>::infinity());
            if (hit.surface < 0 || glm::dot(im.surfaces[std::size_t(hit.surface)].normal, d) < 0) ++open;
            if (open >= 4) return true;
        }
        return false;
    };
    auto away_from_edges = [&](int s, const glm::dvec3& x) {
        const auto& poly = m_scene.surfaces[std::size_t(s)].vertices;
        const double margin = 0.02 * im.surfaces[std::size_t(s)].size;
        for (std::size_t k = 0; k < poly.size(); ++k)
            if (point_segment_distance(x, poly[k], poly[(k + 1) % poly.size()]) < margin) return false;
        return true;
    };
    auto try_point = [&](double area_position) -> std::optional<SurfacePoint> {
        std::size_t c =
            std::size_t(std::upper_bound(cumulative.begin(), cumulative.end(), area_position) - cumulative.begin());
        c = std::min(c, candidates.size() - 1);
        const int s = candidates[c];
        const glm::dvec3 x = im.sample_surface(m_scene, s, rng.uniform(), rng.uniform());
        const glm::dvec3 normal = im.surfaces[std::size_t(s)].normal;
        if (!away_from_edges(s, x) || !reachable(x, normal)) return std::nullopt;
        return SurfacePoint{x, normal, s};
    };
    for (std::size_t k = 0; k < n; ++k) {
        std::optional<SurfacePoint> p;
        // First within the k-th stratum of area, then (a stratum wholly enclosed) anywhere.
        for (int attempt = 0; attempt < 200 && !p; ++attempt)
            p = try_point((double(k) + rng.uniform()) / double(n) * total);
        for (int attempt = 0; attempt < 2000 && !p; ++attempt) p = try_point(rng.uniform() * total);
        if (p) out.push_back(*p);
    }
    return out;
}

double PathTracer::direct_light_share(const SurfacePoint& x, int samples, std::uint64_t seed) const {
    const Impl& im = *m_impl;
    Random rng(seed, 0xD1EC7u);
    const int side = std::max(1, int(std::lround(std::sqrt(double(std::max(samples, 1))))));
    const glm::dvec3 xo = x.position + im.epsilon * x.normal;
    double total = 0.0, open = 0.0;
    for (const int e : im.emitters) {
        if (e == x.surface) continue;
        const Impl::SurfaceData& ed = im.surfaces[std::size_t(e)];
        for (int k = 0; k < side * side; ++k) {
            const double u1 = (k % side + rng.uniform()) / side, u2 = (k / side + rng.uniform()) / side;
            const glm::dvec3 y = im.sample_surface(m_scene, e, u1, u2);
            const glm::dvec3 w = y - x.position;
            const double r2 = glm::dot(w, w);
            if (!(r2 > 0)) continue;
            const double cos_x = glm::dot(x.normal, w), cos_y = -glm::dot(ed.normal, w);
            if (cos_x <= 0 || cos_y <= 0) continue;
            const double kernel = ed.emission.luminance() * ed.area * cos_x * cos_y / (r2 * r2);
            total += kernel;
            if (!im.occluded(xo, y + im.epsilon * ed.normal)) open += kernel;
        }
    }
    return total > 0 ? open / total : -1.0;
}

double PathTracer::clearance(const SurfacePoint& x, int rays, std::uint64_t seed) const {
    const Impl& im = *m_impl;
    Random rng(seed, 0xC1EAu);
    const int side = std::max(1, int(std::lround(std::sqrt(double(std::max(rays, 1))))));
    double nearest = std::numeric_limits<double>::infinity();
    for (int k = 0; k < side * side; ++k) {
        const glm::dvec3 d =
            cosine_direction(x.normal, (k % side + rng.uniform()) / side, (k / side + rng.uniform()) / side);
        const auto hit =
            im.trace_all(x.position + im.epsilon * x.normal, d, 0.0, std::numeric_limits<float>::infinity());
        if (!hit.missed()) nearest = std::min(nearest, hit.t);
    }
    return nearest;
}

}  // namespace bounce
