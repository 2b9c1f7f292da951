// SPDX-License-Identifier: MIT
// The caustic photon map (Jensen 1996; Jensen, Realistic Image Synthesis Using Photon Mapping,
// 2001, ch. 5-7): light that mirrors and glass redirect onto diffuse surfaces, which the
// radiosity, whose form factors see mirrors and glass only as occluders, cannot carry.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/rgb.h"
#include "solver/two_pass/patch_scene_tracer.h"

namespace bounce {

struct CausticOptions {
    std::size_t photons = 500000;  // emitted (most meet a diffuse surface first and are not stored)
    std::size_t nearest = 32;      // photons a radiance estimate gathers (0: all within `radius`)
    double radius = 0.0;           // largest gathering radius, scene units; 0: 2% of the scene's diagonal
    int max_bounces = 64;          // mirror and glass bounces before a photon is dropped
    std::uint64_t seed = 1;        // the same seed gives the same map on any thread count
};

/// A photon that reached a diffuse patch's front through one or more mirrors or glass (a
/// path L S+ D in Heckbert's notation).
struct CausticPhoton {
    glm::dvec3 position{0.0};  // on the patch
    glm::dvec3 normal{0.0};    // the patch's front normal
    Rgb power;                 // W per channel (scene units)
    int patch = -1;
    /// Every turn on its way was a reflection off a sphere (convex, so the light it belongs to
    /// spreads out and lands smooth); false once it was refracted or met a flat mirror or
    /// glass face, after which light may arrive focused or sharp-edged (a caustic).
    bool diverging = true;
};

/// Follows one photon of power `power` leaving o along d (unit) through mirrors and glass, as
/// CausticMap does: the photon it stores, if any. `meets_specular` tells whether its first hit
/// was a mirror or glass. `uniform` draws in [0, 1) (the Fresnel choices).
std::optional<CausticPhoton> trace_caustic_photon(const PatchSceneTracer& tracer, glm::dvec3 o, glm::dvec3 d, Rgb power,
                                                  const std::function<double()>& uniform, int max_bounces,
                                                  bool* meets_specular = nullptr);

class CausticMap {
public:
    /// A map of given photons (for tests and other emitters): `patches` is the mesh's size;
    /// `nearest` and `radius` as in CausticOptions (radius > 0).
    CausticMap(std::vector<CausticPhoton> photons, double radius, std::size_t patches, std::size_t nearest = 0);

    /// Emits `options.photons` photons from the emitting patches, in proportion to their power
    /// (E A, summed over channels) from points uniform on them in cosine-weighted directions
    /// (they are Lambertian), each carrying (emitted power) / photons per channel, split by its
    /// emitter's share. A photon whose first hit is a diffuse patch (or nothing) is not stored: the
    /// radiosity carries that light. One that meets a mirror or glass is followed (mirror:
    /// power times its reflectance; glass: reflected with the Fresnel probability, else
    /// refracted, power times the transmittance entering) to the first diffuse patch and stored
    /// there if it arrives on the front. Photons are traced in parallel blocks, each from its own
    /// random stream. Stored in a k-d tree (nanoflann) for the radiance estimate.
    ///
    /// `exitance`, when given, replaces the emission as what leaves each patch (W per unit area
    /// per channel): the reflected radiosity of a solution, for the light that diffuse surfaces
    /// send through mirrors and glass onto others (paths L D+ S+ D), which the radiosity's
    /// form factors, blocked by mirrors and glass, do not carry.
    CausticMap(const PatchMesh& mesh, const PatchSceneTracer& tracer, const CausticOptions& options,
               const std::atomic<bool>* stop = nullptr, const std::vector<Rgb>* exitance = nullptr);
    ~CausticMap();
    CausticMap(const CausticMap&) = delete;
    CausticMap& operator=(const CausticMap&) = delete;

    /// Radiance leaving the diffuse point x (front normal n, reflectance rho) by caustic light,
    /// the density estimate of Jensen (2001, eq. 7.6 with the cone filter of eq. 7.8, k = 1):
    ///     L = rho / pi * sum_i Phi_i (1 - d_i / r) / ((1 - 2/3) pi r^2)
    /// over the photons within r on a surface facing like n (n . n_i >= 0.9), where r is the
    /// distance to the `nearest`-th nearest photon, at most `radius` (bounded: where photons
    /// are sparse, the estimate blurs no wider than that; with nearest 0, r = radius).
    Rgb radiance(const glm::dvec3& x, const glm::dvec3& n, const Rgb& rho) const;

    /// Irradiance at x (front normal n) by caustic light, W per unit area per channel: the same
    /// estimate before the reflection, sum_i Phi_i (1 - d_i / r) / ((1/3) pi r^2); radiance()
    /// is rho / pi times it. `radius`, when given, receives the r the estimate used.
    Rgb irradiance(const glm::dvec3& x, const glm::dvec3& n, double* radius = nullptr) const;

    /// Photon power arriving at each patch, W per channel: the irradiance the radiosity should
    /// also receive, so its later bounces include the light that mirrors and glass redirect.
    std::vector<Rgb> power_per_patch() const;

    const std::vector<CausticPhoton>& photons() const { return m_photons; }
    std::size_t emitted() const { return m_emitted; }
    Rgb emitted_power() const { return m_emitted_power; }  // sum of E A (or exitance A) over the patches
    /// Share of emitted photons whose first hit was a mirror or glass (before absorption on
    /// the way): the share of the emitted power the caustic paths start with.
    double specular_first_share() const { return m_specular_first; }
    double radius() const { return m_radius; }  // the largest gathering radius
    std::size_t nearest() const { return m_nearest; }

private:
    struct Tree;
    std::vector<CausticPhoton> m_photons;
    std::unique_ptr<Tree> m_tree;
    std::size_t m_emitted = 0;
    std::size_t m_patches = 0;
    Rgb m_emitted_power;
    double m_specular_first = 0.0;
    double m_radius = 0.0;
    std::size_t m_nearest = 0;
};

}  // namespace bounce
