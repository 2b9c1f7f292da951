// SPDX-License-Identifier: MIT
// The path tracer's estimator (internal to bounce::reference): next-event estimation with
// multiple importance sampling, the walk through mirrors and glass, and one path's reflected
// radiosity with Russian roulette (Kajiya 1986; Veach 1997 ch. 9-10).
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "mesh/scene/rgb.h"
#include "mesh/scene/scene.h"
#include "solver/optics/fresnel.h"
#include "solver/reference/path_tracer_sampling.h"
#include "solver/reference/path_tracer_scene.h"

namespace bounce::path_tracing {

/// Next-event estimate of sum_e E_e * F(dA_x -> e) * V at x: one area sample per emitter,
/// weighted by multiple importance sampling against the cosine-sampled continuation.
template <class Sample>
Rgb next_event(const TracedScene& ts, const Scene& scene, const glm::dvec3& x, const glm::dvec3& n, int surface,
               Sample&& sample) {
    Rgb sum;
    const glm::dvec3 xo = x + ts.epsilon * n;
    for (std::size_t k = 0; k < ts.emitters.size(); ++k) {
        const int e = ts.emitters[k];
        if (e == surface) continue;  // a planar surface does not see itself
        const SurfaceData& ed = ts.surfaces[std::size_t(e)];
        const auto [u1, u2] = sample(k);
        const glm::dvec3 y = ts.sample_surface(scene, e, u1, u2);
        const glm::dvec3 w = y - x;
        const double r2 = glm::dot(w, w);
        if (!(r2 > 0)) continue;
        const double r = std::sqrt(r2);
        const double cos_x = glm::dot(n, w) / r, cos_y = -glm::dot(ed.normal, w) / r;
        if (cos_x <= 0 || cos_y <= 0) continue;
        if (ts.occluded(xo, y + ts.epsilon * ed.normal)) continue;
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
Arrival follow_specular(const TracedScene& ts, const Scene& scene, glm::dvec3 o, glm::dvec3 d, Rgb& throughput,
                        Uniform&& uniform) {
    Arrival out;
    for (int bounce = 0; bounce <= kMaxSpecularBounces; ++bounce) {
        const Hit hit = ts.trace_all(o, d, 0.0, std::numeric_limits<float>::infinity());
        if (hit.missed()) return {};
        glm::dvec3 y, n;
        MaterialKind kind;
        Rgb specular;
        double ior;
        if (hit.sphere >= 0) {
            const Material& m = scene.materials[std::size_t(ts.spheres[std::size_t(hit.sphere)].material)];
            y = hit.sphere_point;
            n = hit.sphere_normal;
            kind = m.kind;
            specular = m.specular;
            ior = m.ior;
        } else {
            const SurfaceData& sd = ts.surfaces[std::size_t(hit.surface)];
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
            o = y + ts.epsilon * n;
        } else {
            const bool entering = cos_i > 0;
            const glm::dvec3 facing = entering ? n : -n;  // the normal on the side d comes from
            const double n1 = entering ? 1.0 : ior, n2 = entering ? ior : 1.0;
            const double reflectance = fresnel_dielectric(std::abs(cos_i), n1, n2);
            const auto refracted = refract(d, facing, n1, n2);
            if (!refracted || uniform() < reflectance) {
                d = glm::normalize(reflect(d, facing));
                o = y + ts.epsilon * facing;
            } else {
                d = *refracted;
                o = y - ts.epsilon * facing;
                if (entering) throughput = throughput * specular;
            }
        }
        if (!(throughput.max() > 0)) return {};
    }
    return {};
}

/// One path's estimate of the radiosity reflected at the diffuse point (x, n) of surface
/// `surface`, starting with `throughput` (rho(x) for B(x)): next-event estimation at every
/// diffuse vertex, cosine-sampled continuation through mirrors and glass (follow_specular),
/// Russian roulette on the reflectance. An emitter met through a mirror or glass counts whole: the
/// area sample cannot reach it that way, so its balance-heuristic share is 1.
/// `first_emitter(k)` and `first_direction()` give the first vertex's samples (stratified by
/// the caller); later vertices draw from rng.
template <class Rng, class FirstEmitter, class FirstDirection>
Rgb reflected(const TracedScene& ts, const Scene& scene, glm::dvec3 pos, glm::dvec3 normal, int surface, Rgb throughput,
              Rng& rng, FirstEmitter&& first_emitter, FirstDirection&& first_direction) {
    Rgb sum;
    auto random_pair = [&](std::size_t) { return std::pair{rng.uniform(), rng.uniform()}; };
    auto uniform = [&] { return rng.uniform(); };
    for (int depth = 0; depth < kMaxDepth && throughput.max() > 0; ++depth) {
        glm::dvec3 dir;
        if (depth == 0) {
            sum += throughput * next_event(ts, scene, pos, normal, surface, first_emitter);
            const auto [u1, u2] = first_direction();
            dir = cosine_direction(normal, u1, u2);
        } else {
            sum += throughput * next_event(ts, scene, pos, normal, surface, random_pair);
            const double u1 = rng.uniform(), u2 = rng.uniform();
            dir = cosine_direction(normal, u1, u2);
        }
        const double cos_x = glm::dot(normal, dir);
        const Arrival a = follow_specular(ts, scene, pos + ts.epsilon * normal, dir, throughput, uniform);
        if (a.surface < 0) break;  // escapes through an opening, or meets a back face
        const auto& sh = ts.surfaces[std::size_t(a.surface)];
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

}  // namespace bounce::path_tracing
