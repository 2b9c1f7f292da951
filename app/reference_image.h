// SPDX-License-Identifier: MIT
// `bounce reference SCENE --image OUT.pfm` (or OUT.exr): the path-traced picture through the camera of
// `render`, with its standard error per pixel, so a picture can be scored.
#pragma once

#include <cstdint>
#include <string>

#include "app/common_options.h"
#include "viewer/renderer.h"

namespace bounce::app {

struct ReferenceImageOptions {
    std::string output;         // --image: OUT.pfm or OUT.exr (linear radiance); OUT_se.pfm or .exr beside it
    RenderOptions camera;       // --camera, --fov, --size
    std::uint64_t paths = 256;  // --paths: per pixel, whole batches of 64
    std::uint64_t seed = 1;
};

/// Path-traces every pixel (PathTracer::pixel_radiance, rows in parallel) and writes the mean
/// radiance and its standard error as two .pfm or .exr files. Ctrl-C writes the rows done (the rest
/// black) and returns 130.
int run_reference_image(const CommonOptions& o, const ReferenceImageOptions& r);

}  // namespace bounce::app
