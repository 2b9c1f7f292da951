// SPDX-License-Identifier: MIT
// The view-dependent second pass of the two-pass method (Wallace, Cohen and Greenberg 1987;
// Jensen 1996): eye rays through a pinhole camera. A diffuse surface shows the radiosity the
// first pass solved for there (B / pi: it is Lambertian), plus the caustic radiance from the
// photon map when one is given; mirrors and glass are followed by Whitted recursion (Whitted
// 1980) with the exact Fresnel equations.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/rgb.h"
#include "mesh/scene/scene.h"

namespace bounce {

class CausticMap;

/// A pinhole camera: where it stands, what it looks at, which way is up.
struct PinholeCamera {
    glm::dvec3 position{0.0};
    glm::dvec3 target{0.0, 0.0, 1.0};
    glm::dvec3 up{0.0, 1.0, 0.0};
    double vertical_fov = 39.0;  // degrees, across the picture's height
};

struct EyePassOptions {
    int width = 800, height = 800;  // pixels
    int samples_per_pixel = 16;     // jittered on a k x k grid over the pixel (k = ceil(sqrt(n))), box filter
    int max_depth = 16;             // mirror and glass bounces along one eye ray; deeper branches are black
    double min_weight = 1e-3;       // a branch whose throughput falls below this (per channel max) is dropped
    std::uint64_t seed = 1;         // jitter: the same seed gives the same picture on any thread count
    /// A pixel whose rays' luminances span (max - min) / (max + min) above this gets 16 times as
    /// many more (an edge: Mitchell's contrast test, 1987); 0: never.
    double refine_contrast = 0.5;
};

/// Linear radiance per pixel, W/(m^2 sr) per channel (scene units), rows top to bottom.
struct EyeImage {
    int width = 0, height = 0;
    std::vector<Rgb> pixels;    // width * height; rows not done are black
    std::size_t rows_done = 0;  // rows finished (all, unless stopped)
    bool complete() const { return rows_done == std::size_t(height); }
};

class EyePass {
public:
    /// `vertex_radiosity`: B at each vertex of `mesh` (the solution's point data), interpolated
    /// over the patches; `patch_radiosity`: B per patch, shown where a patch's vertices are
    /// not its mesh corners. `caustics`, when given, adds its radiance estimate at every
    /// diffuse point seen (its light reached there through mirrors and glass, which the
    /// radiosity does not carry along any view). The scene and mesh must outlive the pass.
    EyePass(const Scene& scene, const PatchMesh& mesh, std::vector<Rgb> vertex_radiosity,
            std::vector<Rgb> patch_radiosity, const CausticMap* caustics = nullptr);
    ~EyePass();
    EyePass(const EyePass&) = delete;
    EyePass& operator=(const EyePass&) = delete;

    /// Radiance arriving at `origin` from `direction` (the way the eye ray travels).
    Rgb radiance(const glm::dvec3& origin, const glm::dvec3& direction, const EyePassOptions& options = {}) const;

    /// The picture, rows in parallel (TBB). `progress(rows done, rows)` is called from worker
    /// threads; when `stop` is raised, rows not started stay black (rows_done says how many
    /// were finished) and the picture is still whole.
    EyeImage render(const PinholeCamera& camera, const EyePassOptions& options,
                    const std::function<void(std::size_t, std::size_t)>& progress = {},
                    const std::atomic<bool>* stop = nullptr) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace bounce
