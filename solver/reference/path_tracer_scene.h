// SPDX-License-Identifier: MIT
// The scene as the path tracer sees it (internal to bounce::reference): per-surface planes,
// materials and area-sampling tables, the analytic spheres, and the Embree scene of all polygons.
#pragma once

#include <array>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/vec3.hpp>

#include "mesh/scene/rgb.h"
#include "mesh/scene/scene.h"
#include "mesh/scene/sphere.h"
#include "solver/reference/path_tracer.h"

namespace bounce::path_tracing {

/// What the tracer reads of one input polygon, diffuse or specular.
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

/// The closest thing a ray meets: a polygon, an analytic sphere, or nothing.
struct Hit {
    double t = 0;
    int surface = -1;                                  // a polygon (index into surfaces), or
    int sphere = -1;                                   // an analytic sphere (index into spheres)
    glm::dvec3 sphere_point{0.0}, sphere_normal{0.0};  // on a sphere: the exact point, outward unit normal
    bool missed() const { return surface < 0 && sphere < 0; }
};

/// The Embree device and scene, released in reverse order of creation.
struct EmbreeHandles {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    EmbreeHandles() = default;
    EmbreeHandles(const EmbreeHandles&) = delete;
    EmbreeHandles& operator=(const EmbreeHandles&) = delete;
    ~EmbreeHandles() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

/// The input polygons (Scene::surfaces, then Scene::specular_surfaces) and spheres, traced by
/// Embree in single precision around the scene's centre and sampled by area.
struct TracedScene {
    /// Builds the surface data and the Embree scene; throws std::invalid_argument when no
    /// surface has positive area and std::runtime_error when Embree fails.
    explicit TracedScene(const Scene& scene);

    EmbreeHandles embree;
    glm::dvec3 centre{0.0};
    double diagonal = 0.0;  // of the bounding box of polygons and spheres
    double epsilon = 0.0;   // ray origin offset along the normal
    // Scene::surfaces (diffuse) first, then Scene::specular_surfaces: surface index
    // scene.surfaces.size() + k is specular_surfaces[k].
    std::vector<SurfaceData> surfaces;
    std::vector<Sphere> spheres;        // analytic, intersected beside Embree's triangles
    std::vector<int> triangle_surface;  // Embree primitive -> surface
    std::vector<int> emitters;          // surfaces with emission

    /// The polygon of surface s, diffuse or specular.
    const std::vector<glm::dvec3>& polygon(const Scene& scene, int s) const;

    /// Closest hit of a polygon or a sphere along o + t d, t in (tnear, tfar). Spheres are
    /// few in the scenes this serves (the seed's box has two), so they are tested one by one,
    /// exactly, in double precision.
    Hit trace_all(const glm::dvec3& o, const glm::dvec3& d, double tnear, double tfar) const;

    /// Closest hit along o + t d, t in (tnear, tfar); surface -1 when nothing is hit.
    Hit trace(const glm::dvec3& o, const glm::dvec3& d, double tnear, double tfar) const;

    /// True when something lies strictly between a and b.
    bool occluded(const glm::dvec3& a, const glm::dvec3& b) const;

    /// A point of surface s, uniform by area, from (u1, u2) in [0,1)^2.
    glm::dvec3 sample_surface(const Scene& scene, int s, double u1, double u2) const;

private:
    /// Fills `surfaces` and `emitters`, widens [lo, hi] by every vertex; returns the number of
    /// triangles.
    std::size_t add_surfaces(const Scene& scene, glm::dvec3& lo, glm::dvec3& hi);
    /// Builds the Embree scene of every surface's triangles, recentred on `centre`.
    void build_embree(const Scene& scene, std::size_t triangle_count);
};

}  // namespace bounce::path_tracing

namespace bounce {

struct PathTracer::Impl : path_tracing::TracedScene {
    using TracedScene::TracedScene;
};

}  // namespace bounce
