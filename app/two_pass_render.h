// SPDX-License-Identifier: MIT
// `bounce render SCENE` for scenes with mirrors or glass (or with --ray-trace): the two-pass
// picture. The light pass solves the radiosity of the diffuse patches, with mirrors and glass
// as occluders and the caustic photons' power handed to the patches they reach; the eye pass
// traces rays from the camera (solver/two_pass/eye_pass.h).
#pragma once

#include <cstdint>
#include <string>

#include "app/common_options.h"
#include "mesh/meshing/patch_mesh.h"
#include "solver/linear/solve_result.h"
#include "solver/two_pass/eye_pass.h"
#include "viewer/renderer.h"

namespace bounce::app {

struct TwoPassOptions {
    bool ray_trace = false;           // --ray-trace: eye rays for a scene without mirrors or glass too
    int samples = 16;                 // --samples: eye rays per pixel (jittered)
    std::size_t photons = 2000000;    // --photons: the emitters' photons (later rounds: as many of like power); 0: none
    int rounds = 3;                   // --photon-rounds: the emitters', then the patches' light (2 and on)
    std::size_t nearest = 32;         // --photon-nearest: photons per caustic estimate (0: all within the radius)
    double photon_radius = 0.0;       // --photon-radius: largest estimate radius; 0: 2% of the diagonal
    int max_depth = 16;               // --max-depth: mirror and glass bounces per eye ray
    double display_tolerance = 0.02;  // --display-tolerance: display cells of the point data (as solve's); 0: off
    std::uint64_t seed = 1;           // --seed: jitter and photons
};

/// Adds --ray-trace, --samples, --photons, --photon-nearest, --photon-radius, --max-depth and --seed.
void add_two_pass_options(CLI::App* cmd, TwoPassOptions& t);

/// The two-pass picture in memory, with what it took.
struct TwoPassPicture {
    EyeImage image;             // linear radiance; rows not done (Ctrl-C) black
    SolveResult shown;          // the radiosity without the caustic term: the exposure of write_eye_picture
    std::size_t shots = 0;      // of the last radiosity solve
    std::size_t emitted = 0;    // caustic photons emitted, both rounds
    std::size_t stored = 0;     // caustic photons stored in the map
    double specular_first = 0;  // share of the emitters' photons that met a mirror or glass first
    double light_seconds = 0;   // wall time of the light pass (radiosity, photons, gather)
    double seconds = 0;         // light and eye pass together
};

/// The light pass and the eye pass of the loaded scene (meshed as `mesh`) through the camera
/// of `render`: the picture of run_two_pass_render, not written. Progress on a terminal unless
/// o.quiet; Ctrl-C stops the eye pass with the rows done.
TwoPassPicture render_two_pass(const CommonOptions& o, const Scene& scene, const PatchMesh& mesh,
                               const RenderOptions& render, const TwoPassOptions& t);

/// Solves the loaded scene (meshed as `mesh`) and writes the eye-ray picture; returns the exit code (130 when Ctrl-C
/// stopped the eye pass: the rows done are written, the rest black).
int run_two_pass_render(const CommonOptions& o, const Scene& scene, const PatchMesh& mesh, const std::string& picture,
                        const RenderOptions& render, const TwoPassOptions& t);

}  // namespace bounce::app
