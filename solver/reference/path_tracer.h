// SPDX-License-Identifier: MIT
// An independent witness for the radiosity solvers: a Monte Carlo estimate of the continuous
// radiosity equation at surface points,
//
//     B(x) = E(x) + rho(x) * integral over surfaces of B(y) cos(theta_x) cos(theta_y) V(x,y) / (pi r^2) dA_y,
//
// computed on the input polygons (never on patches), so it shares no discretisation with the
// solvers it scores.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/rgb.h"
#include "mesh/scene/scene.h"

namespace bounce {

/// A point on the front side of an input surface.
struct SurfacePoint {
    glm::dvec3 position{0.0};  // on the surface's plane
    glm::dvec3 normal{0.0};    // the surface's unit front normal
    int surface = -1;          // index into Scene::surfaces
};

/// How long to sample each point.
struct ReferenceOptions {
    double target_error = 0.005;         // stop when se(luminance) <= target * luminance
    std::uint64_t max_paths = 1u << 20;  // budget per point; a point that reaches it is flagged
    std::uint64_t min_paths = 1024;      // before the first stopping test (16 batches)
    std::uint64_t seed = 1;              // same seed -> same estimates, on any thread count
};

enum class EstimateStatus {
    converged,    // relative standard error below the target
    budget,       // stopped at max_paths above the target
    interrupted,  // stopped by the caller (Ctrl-C): value so far, or none if no batch finished
};
std::string to_string(EstimateStatus s);

/// B at one point with its standard error per channel.
struct RadiosityEstimate {
    Rgb radiosity;       // E + reflected, W/m^2 per channel
    Rgb standard_error;  // of the mean, from the spread of independent batch means
    std::uint64_t paths = 0;
    EstimateStatus status = EstimateStatus::interrupted;
};

/// The radiance arriving along a ray, per channel, with its standard error.
struct RadianceEstimate {
    Rgb radiance;        // W/(m^2 sr) per channel (scene units): B/pi at the diffuse point reached, times what
                         // the mirrors and glass on the way pass on
    Rgb standard_error;  // of the mean, from the spread of independent batch means
    std::uint64_t paths = 0;
};

/// One path's radiance along an eye ray, and the diffuse surface it ended its specular chain on.
struct PixelSample {
    Rgb radiance;      // W/(m^2 sr) per channel (scene units), as RadianceEstimate::radiance
    int surface = -1;  // index into Scene::surfaces of the diffuse surface reached; -1: none (escaped, absorbed)
};

/// Irradiance at a point, per channel, with its standard error.
struct IrradianceEstimate {
    Rgb irradiance;      // W/m^2 per channel (scene units)
    Rgb standard_error;  // of the mean, from the spread of independent batch means (0 with one batch)
    std::uint64_t paths = 0;
};

/// Path tracing with next-event estimation (Kajiya 1986; Veach 1997 ch. 9-10 for the
/// estimators): at every path vertex each emitter is sampled by area, indirect light is
/// gathered along a cosine-weighted direction, and paths end by Russian roulette on the
/// reflectance (unbiased: the throughput is divided by the survival probability). Emitters
/// are reached both ways, by the area sample and by the cosine-sampled ray, combined with the
/// balance heuristic, so the variance stays finite beside edges shared with an emitter.
///
/// Mirrors and glass (Scene::specular_surfaces and the analytic Scene::spheres) are followed in
/// the same estimator: a path that meets one is reflected (mirror, scaled by its reflectance) or
/// reflected or refracted with the exact Fresnel probability (glass, total internal reflection
/// past the critical angle), and goes on until it meets a diffuse surface. Shadow rays of the
/// next-event estimate stop at mirrors and glass, so light that they redirect (caustics) reaches
/// a diffuse point only along the sampled continuation, where it counts whole.
///
/// Paths are drawn in batches of 64 whose first-vertex emitter samples and directions are
/// stratified (8x8 jittered, independently permuted); the standard error is the spread of the
/// batch means, so it stays honest under stratification. Each point draws from its own
/// random stream (seed, point index): results do not depend on threads or scheduling.
/// Rays are traced by Embree in single precision around the scene's centre.
class PathTracer {
public:
    explicit PathTracer(const Scene& scene);
    ~PathTracer();
    PathTracer(const PathTracer&) = delete;
    PathTracer& operator=(const PathTracer&) = delete;

    const Scene& scene() const { return m_scene; }
    double diagonal() const { return m_diagonal; }
    /// How far a given point may sit off its surface: 0.5% of the bounding-box diagonal.
    double snap_distance() const { return 0.005 * m_diagonal; }

    /// The point p snapped along n to the nearest surface (within snap_distance) whose front
    /// faces n; nothing when there is none.
    std::optional<SurfacePoint> locate(const glm::dvec3& p, const glm::dvec3& n) const;

    /// Estimates B at one point, drawing from stream `index` of options.seed. `stop`, when set
    /// and raised, ends sampling after the current batch (status interrupted).
    RadiosityEstimate estimate(const SurfacePoint& x, const ReferenceOptions& options, std::uint64_t index,
                               const std::atomic<bool>* stop = nullptr) const;

    /// The radiance arriving at `origin` from `direction` (towards the origin, along -direction):
    /// at the first diffuse surface the ray meets, directly or through mirrors and glass, its
    /// emitted and reflected radiosity over pi (the surface is Lambertian). `paths` (rounded up
    /// to whole batches of 64) from stream `index` of `seed`.
    RadianceEstimate radiance(const glm::dvec3& origin, const glm::dvec3& direction, std::uint64_t paths,
                              std::uint64_t seed, std::uint64_t index) const;

    /// The mean radiance over a pixel of a pinhole camera at `origin`: rays towards
    /// corner + u du + v dv for (u, v) in [0,1)^2, stratified 8 x 8 within each batch of 64
    /// (anti-aliasing by a box filter), `paths` rounded up to whole batches; the standard error
    /// from the spread of the batch means.
    RadianceEstimate pixel_radiance(const glm::dvec3& origin, const glm::dvec3& corner, const glm::dvec3& du,
                                    const glm::dvec3& dv, std::uint64_t paths, std::uint64_t seed,
                                    std::uint64_t index) const;

    /// One path through a uniformly random point of the pixel (corner + u du + v dv), without
    /// batches or strata: the unit of a progressive picture that stops when its time is up.
    /// Stream `index` of `seed`; the mean of many is an unbiased pixel_radiance.
    PixelSample pixel_sample(const glm::dvec3& origin, const glm::dvec3& corner, const glm::dvec3& du,
                             const glm::dvec3& dv, std::uint64_t seed, std::uint64_t index) const;

    /// The irradiance at the diffuse point x that arrives through mirrors and glass: light whose
    /// last scattering before x was specular (the caustic; Heckbert's L D* S+ D paths ending at
    /// x). Cosine-weighted directions from x (stratified 8 x 8 in each batch of 64) whose first
    /// hit is a mirror or glass are followed to the diffuse surface y their chain ends on; the
    /// irradiance is E[B(y) T] over those directions (pi times the mean radiance B(y) / pi, T
    /// the chain's throughput), B(y) path-traced as in `estimate`. `emitted_only`: B(y) is y's
    /// emission alone, the paths L S+ D that a caustic photon map of the emitters holds.
    /// `paths` rounded up to whole batches of 64, at least one; stream `index` of `seed`.
    IrradianceEstimate specular_irradiance(const SurfacePoint& x, std::uint64_t paths, bool emitted_only,
                                           std::uint64_t seed, std::uint64_t index) const;

    /// Estimates every point in parallel (TBB). `progress(done, total)` is called from worker
    /// threads after each point. Points not started when `stop` is raised come back with
    /// status interrupted and zero paths.
    std::vector<RadiosityEstimate> estimate_all(std::span<const SurfacePoint> points, const ReferenceOptions& options,
                                                const std::function<void(std::size_t, std::size_t)>& progress = {},
                                                const std::atomic<bool>* stop = nullptr) const;

    /// n points spread over the non-emitting surfaces by area (stratified: the k-th lies in
    /// the k-th n-th of the total area), each at least 2% of its surface's size from the
    /// surface's edges and on a part of the surface open to the scene (points enclosed by back
    /// faces, like a floor under a block or a ceiling behind a lamp hung just below it, where
    /// fewer than 4 of 16 cosine rays get out, are drawn again).
    std::vector<SurfacePoint> probes(std::size_t n, std::uint64_t seed) const;

    /// The share of the emitters' direct-light kernel E cos(theta_x) cos(theta_y) / (pi r^2)
    /// at x that arrives unblocked, from `samples` stratified area samples per emitter (in
    /// luminance); -1 when no emitter faces x at all.
    double direct_light_share(const SurfacePoint& x, int samples, std::uint64_t seed) const;

    /// Distance from x to the nearest surface along `rays` cosine-distributed directions of its
    /// front hemisphere (infinity when every ray leaves the scene).
    double clearance(const SurfacePoint& x, int rays, std::uint64_t seed) const;

    /// Name shown for a surface: its object name, or "surface K".
    std::string surface_name(int surface) const;

    /// Paths traced so far by this tracer (all threads), for rate measurements.
    std::uint64_t paths_traced() const { return m_paths.load(); }

private:
    struct Impl;
    const Scene& m_scene;
    double m_diagonal = 0.0;
    std::unique_ptr<Impl> m_impl;
    mutable std::atomic<std::uint64_t> m_paths{0};
};

}  // namespace bounce
