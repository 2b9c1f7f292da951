// SPDX-License-Identifier: MIT
#pragma once

#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/scene.h"

namespace bounce {

/// Rays through the scene as the two-pass method sees it: the radiosity's patches (diffuse)
/// and the mirror and glass objects (Scene::specular_surfaces through Embree, Scene::spheres
/// intersected exactly). The photon tracer and the eye pass share it. Thread-safe.
class PatchSceneTracer {
public:
    /// What a ray met.
    struct Hit {
        enum class Kind { none, patch, specular_surface, sphere };
        Kind kind = Kind::none;
        double t = 0.0;
        int index = -1;            // patch, specular surface or sphere
        glm::dvec3 position{0.0};  // on the patch's or surface's plane, or on the sphere
        glm::dvec3 normal{0.0};    // unit front (outward) normal there
        double u = 0.0, v = 0.0;   // patch: barycentrics in its fan triangle (0, fan, fan + 1)
        int fan = 1;               // patch: which fan triangle
        bool missed() const { return kind == Kind::none; }
    };

    PatchSceneTracer(const Scene& scene, const PatchMesh& mesh);
    ~PatchSceneTracer();
    PatchSceneTracer(const PatchSceneTracer&) = delete;
    PatchSceneTracer& operator=(const PatchSceneTracer&) = delete;

    /// Closest hit along o + t d, t in (t_min, infinity); d need not be unit (t is in its units).
    Hit trace(const glm::dvec3& o, const glm::dvec3& d, double t_min = 0.0) const;
    /// The material of a specular surface or sphere hit.
    const Material& material(const Hit& hit) const;
    /// Distance to lift a ray's origin off the surface it leaves: 1e-6 of the scene's diagonal.
    double epsilon() const { return m_epsilon; }
    double diagonal() const { return m_diagonal; }

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
    double m_epsilon = 0.0, m_diagonal = 0.0;
};

}  // namespace bounce
