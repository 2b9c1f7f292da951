// SPDX-License-Identifier: MIT
// What several commands share: the scene and meshing options, the form-factor and render
// options, loading with the --max-memory and --strict limits, and the checks made before work.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/scene.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/linear/solve_result.h"
#include "solver/pipeline/solve_request.h"
#include "solver/pipeline/solve_scene.h"
#include "solver/visibility/visibility.h"
#include "viewer/pending_output.h"
#include "viewer/renderer.h"

namespace bounce::app {

/// "> 0", with a readable message (CLI11's PositiveNumber prints the whole double range).
extern const CLI::Validator kPositive;
/// lo <= value <= hi, with the same style of message: "out of range, got V (expected LO to HI)".
CLI::Validator in_range(double lo, double hi);

/// The options every command takes (one instance, bound to each subcommand's flags).
struct CommonOptions {
    std::string scene = "cornell";
    MeshingOptions meshing;
    bool quiet = false;
    bool strict = false;
    bool flip = false;  // turn every face round after loading (scenes wound clockwise)
    int threads = 0;
    std::string visibility = visibility_backends().front();
    std::size_t max_memory_mb = 16384;
};

/// The scene argument, then add_meshing_options_no_scene.
void add_meshing_options(CLI::App* cmd, CommonOptions& o);
/// --max-area, --max-edge, --patches, --max-memory, --strict, --no-subdivide, --quiet,
/// --threads, --visibility.
void add_meshing_options_no_scene(CLI::App* cmd, CommonOptions& o);
/// --rays, --receiver-samples, --hemicube-res, --hemicube-jitter, --seed.
void add_form_factor_options(CLI::App* cmd, FormFactorOptions& f);
/// --camera, --fov, --size, --exposure, --smooth, --flat, --luminance, --edges.
void add_render_options(CLI::App* cmd, RenderOptions& r);

/// Loads the scene with --strict applied, its warnings on stderr unless quiet.
Scene load_checked(const CommonOptions& o, const std::string& spec);
/// Meshes with the limit of --max-memory applied (saying what a large meshing costs), the
/// mesh's warnings on stderr unless quiet.
PatchMesh mesh_scene(const CommonOptions& o, const Scene& scene, const MeshingOptions& options);
/// Both, with the options' own meshing.
PatchMesh load_and_mesh(const CommonOptions& o, const std::string& spec, Scene& scene);

/// True when the user gave no meshing (no --max-area, --max-edge or --patches): the element
/// methods (`solve --adaptive`, `--solver hierarchical`, `compare --meshes`) then start from
/// kCoarseTargetPatches (solver/pipeline/solve_request.h) and refine where the light needs it.
bool default_meshing(const CommonOptions& o);
/// What kCoarseTargetPatches gives on the default Cornell box (contact cuts split some faces);
/// `compare --help` says it, and a test holds it to what the runs print.
inline constexpr std::size_t kCoarseCornellPatches = 90;

/// Refuses work whose estimate exceeds --max-memory, naming the estimate.
void check_memory(const CommonOptions& o, const std::string& what, double bytes);

/// The warnings and notes of a solve (SolvedScene), one line each on stderr, unless quiet.
void print_solve_messages(const SolvedScene& solved, bool quiet);
/// The hemicube's per-thread buffers against --max-memory (other methods need none).
void check_form_factor_memory(const CommonOptions& o, const std::string& method, const FormFactorOptions& f);

}  // namespace bounce::app
