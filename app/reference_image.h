// SPDX-License-Identifier: MIT
// `bounce reference SCENE --image OUT.pfm` (or OUT.exr): the path-traced picture through the camera of
// `render`, with its standard error per pixel, so a picture can be scored.
#pragma once

#include <cstdint>
#include <string>

#include <glm/vec3.hpp>

#include "app/common_options.h"
#include "mesh/scene/scene.h"
#include "solver/two_pass/eye_pass.h"
#include "viewer/renderer.h"

namespace bounce::app {

struct ReferenceImageOptions {
    std::string output;         // --image: OUT.pfm or OUT.exr (linear radiance); OUT_se.pfm or .exr beside it
    RenderOptions camera;       // --camera, --fov, --size
    std::uint64_t paths = 256;  // --paths: per pixel, whole batches of 64
    std::uint64_t seed = 1;
};

/// The camera of `render` for the scene, chosen on its faces without solving it.
PinholeCamera scene_camera(const Scene& scene, const RenderOptions& camera);

/// A pinhole camera's pixels as the path tracer takes them: pixel (col, row), rows top to
/// bottom, spans the directions corner(col, row) + u du + v dv for u, v in [0, 1).
struct PixelRays {
    glm::dvec3 origin{0.0};
    glm::dvec3 top_left{0.0}, du{0.0}, dv{0.0};  // one pixel across, one down
    glm::dvec3 corner(int col, int row) const { return top_left + double(col) * du + double(row) * dv; }
};
PixelRays pixel_rays(const PinholeCamera& camera, int width, int height);

/// Path-traces every pixel (PathTracer::pixel_radiance, rows in parallel) and writes the mean
/// radiance and its standard error as two .pfm or .exr files. Ctrl-C writes the rows done (the rest
/// black) and returns 130.
int run_reference_image(const CommonOptions& o, const ReferenceImageOptions& r);

}  // namespace bounce::app
