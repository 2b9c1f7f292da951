// SPDX-License-Identifier: MIT
// `bounce compare --picture`: the two-pass picture (radiosity, caustic photons, eye rays) against
// the path tracer given the same wall time, both scored against a long path-traced image of the
// same camera, at a few time budgets (picture.csv, picture_error.png, the pictures side by side).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/common_options.h"

namespace bounce::app {

struct ComparePictureOptions {
    bool enabled = false;           // --picture
    int width = 512, height = 512;  // --picture-size WxH
    // One value each per time budget: the patches the light pass meshes the scene into, the
    // eye rays per pixel and the emitters' photons (render's --photons).
    std::vector<std::size_t> patches = {250, 1000, 2000};          // --picture-patches
    std::vector<int> samples = {1, 4, 16};                         // --picture-samples
    std::vector<std::size_t> photons = {100000, 500000, 2000000};  // --picture-photons
    std::uint64_t reference_paths = 4096;                          // --reference-paths: per pixel of the long image
    std::uint64_t seed = 1;                                        // jitter, photons and paths
    const CLI::Option* scene = nullptr;  // compare's scene argument: not given means cornell-spheres
};

/// Adds --picture, --picture-size, --picture-patches, --picture-samples, --picture-photons and --reference-paths
/// to `compare` (after its scene argument).
std::shared_ptr<ComparePictureOptions> add_compare_picture_options(CLI::App* compare);

/// Runs the comparison into the folder `out`; returns the exit code. Per budget k: the two-pass
/// picture on patches[k] patches with samples[k] eye rays per pixel and photons[k] photons (its
/// wall time t_k from the loaded scene: meshing, light pass and eye pass), then the path tracer's progressive picture
/// (one path per pixel a round) for the same t_k. The score of a picture is the relative RMS luminance error sqrt(mean
/// (Y - Y_ref)^2 / Y_ref^2) over the pixels whose centre ray meets a non-emitting diffuse surface, directly or through
/// mirrors and glass, against the long path-traced image (reference_paths per pixel, cached in `out`). That image's
/// own noise adds to every score in quadrature: picture.csv also gives sqrt(max(0, score^2 - noise^2)), noise the RMS
/// over the same pixels of its relative standard error in luminance.
int run_compare_picture(const CommonOptions& o, const ComparePictureOptions& p, const std::string& out);

}  // namespace bounce::app
