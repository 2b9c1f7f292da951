// SPDX-License-Identifier: MIT
#include "app/common_options.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <thread>

#include "app/progress_line.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/input_error.h"
#include "solver/form_factors/form_factor_matrix.h"

namespace bounce::app {

// Both in the one error style of the program: "<option>: <what>, got <value> (expected <range>)".
const CLI::Validator kPositive(
    [](std::string& v) {
        try {
            std::size_t used = 0;
            const double x = std::stod(v, &used);
            if (used == v.size() && std::isfinite(x) && x > 0) return std::string();
        } catch (const std::exception&) {
        }
        return not_positive_text(v);
    },
    "> 0");

CLI::Validator in_range(double lo, double hi) {
    return CLI::Validator(
        [lo, hi](std::string& v) {
            try {
                std::size_t used = 0;
                const double x = std::stod(v, &used);
                if (used == v.size() && x >= lo && x <= hi) return std::string();
                if (used == v.size() && std::isfinite(x)) return out_of_range_text(v, lo, hi);
            } catch (const std::exception&) {
            }
            return not_a_number_text(v, lo, hi);
        },
        "in [" + number_text(lo) + ", " + number_text(hi) + "]");
}

namespace {

void print_warnings(const Scene& scene, bool quiet) {
    if (quiet) return;
    for (const auto& w : scene.warnings) std::cerr << "warning: " << w << "\n";
}

// Memory estimates, checked before the allocation they stand for.
constexpr std::size_t kBytesPerPatch = 1024;  // Patch, OpenMesh face and vertices, AABB triangles, solver vectors
constexpr double kManyPatches = 50000;        // above this, say how many patches, and the time, before meshing
// A shooting solve grows like N^1.9: 47 s at 16k patches on 2 cores (0.75 s a shot at 10^6).
constexpr double kShootingSeconds16k = 47.0, kShootingExponent = 1.9;

/// "34 hours", "5 minutes": a time estimate to two figures.
std::string duration_text(double seconds) {
    std::ostringstream s;
    s.precision(2);
    if (seconds < 120)
        s << seconds << " s";
    else if (seconds < 2 * 3600.0)
        s << seconds / 60 << " minutes";
    else if (seconds < 2 * 86400.0)
        s << seconds / 3600 << " hours";
    else
        s << seconds / 86400 << " days";
    return s.str();
}

/// The meshing option that sets the patch count, and which way to turn it for fewer patches.
std::string fewer_patches_advice(const CommonOptions& o) {
    if (o.meshing.max_area > 0) return "raise --max-area";
    if (o.meshing.max_edge > 0) return "raise --max-edge";
    return "lower --patches";
}

double estimated_shooting_seconds(double patches) {
    return kShootingSeconds16k * std::pow(patches / 16000.0, kShootingExponent);
}

}  // namespace

Scene load_checked(const CommonOptions& o, const std::string& spec) {
    // The contact cuts' search grows with a furnished room's surfaces: its progress shows once
    // it has run a second (a small scene's load prints nothing).
    ProgressLine line(!o.quiet);
    const auto start = std::chrono::steady_clock::now();
    LoadOptions load{o.flip, o.strict, {}};
    load.progress = [&](std::size_t done, std::size_t total) {
        if (std::chrono::steady_clock::now() - start < std::chrono::seconds(1)) return;
        line.items("finding contacts: surfaces", done, total);
    };
    Scene scene = load_scene(spec, load);
    line.finish();
    print_warnings(scene, o.quiet);
    return scene;
}

PatchMesh load_and_mesh(const CommonOptions& o, const std::string& spec, Scene& scene) {
    scene = load_checked(o, spec);
    return mesh_scene(o, scene, o.meshing);
}

PatchMesh mesh_scene(const CommonOptions& o, const Scene& scene, const MeshingOptions& options) {
    MeshingOptions m = options;
    const std::size_t by_memory = (o.max_memory_mb << 20) / kBytesPerPatch;
    m.max_patches = std::min(m.max_patches, by_memory);
    // Say what a large meshing will cost before making it, or refuse it, in one line.
    const double planned = planned_patches(scene, m);
    if (planned > double(m.max_patches)) {
        std::ostringstream msg;
        msg << "meshing would make " << planned << " patches, more than the limit of " << m.max_patches;
        if (m.max_patches == by_memory)
            msg << " that --max-memory " << o.max_memory_mb << " MB allows (about "
                << std::size_t(planned * kBytesPerPatch / double(1 << 20)) << " MB at 1 KB a patch)";
        msg << ": " << fewer_patches_advice(o)
            << ", or solve with --solver hierarchical, which starts coarse and refines only where the light needs it";
        throw ResourceLimitError(msg.str());
    }
    if (!o.quiet && planned > kManyPatches)
        std::cerr << "note: meshing into " << std::size_t(planned) << " patches (about "
                  << std::size_t(planned * kBytesPerPatch / double(1 << 20))
                  << " MB for the mesh alone); a shooting solve of as many takes about "
                  << duration_text(estimated_shooting_seconds(planned))
                  << " on 2 cores (N^1.9, 47 s at 16k patches); --solver hierarchical refines only where the light "
                     "needs it\n";
    PatchMesh mesh(scene, m);
    if (!o.quiet)
        for (const auto& w : mesh.warnings()) std::cerr << "warning: " << w << "\n";
    return mesh;
}

bool default_meshing(const CommonOptions& o) { return bounce::default_meshing(o.meshing); }

void print_solve_messages(const SolvedScene& solved, bool quiet) {
    if (quiet) return;
    for (const auto& w : solved.warnings) std::cerr << "warning: " << w << "\n";
    for (const auto& n : solved.notes) std::cerr << "note: " << n << "\n";
}

void check_memory(const CommonOptions& o, const std::string& what, double bytes) {
    if (bytes > double(o.max_memory_mb << 20)) {
        std::ostringstream msg;
        msg.precision(1);
        msg << std::fixed << what << " needs about " << bytes / double(1 << 20) << " MB, over --max-memory "
            << o.max_memory_mb << " MB";
        throw ResourceLimitError(msg.str());
    }
}

void check_form_factor_memory(const CommonOptions& o, const std::string& method, const FormFactorOptions& f) {
    if (method != "hemicube") return;
    const double r = f.hemicube_resolution;
    const double threads = o.threads > 0 ? o.threads : double(std::thread::hardware_concurrency());
    check_memory(o, "hemicube buffers (" + std::to_string(f.hemicube_resolution) + " pixels a side, per thread)",
                 threads * r * r * 1.5 * 12.0 + 1.0);
}

void add_meshing_options(CLI::App* cmd, CommonOptions& o) {
    cmd->add_option("scene", o.scene,
                    "'cornell' (built-in, default), a .obj, a .json, or a .ply/.off scene (faces only, white 0.5)");
    add_meshing_options_no_scene(cmd, o);
}

void add_meshing_options_no_scene(CLI::App* cmd, CommonOptions& o) {
    cmd->add_option("--max-area", o.meshing.max_area, "largest patch area (scene units^2); default: total area / 2000")
        ->check(kPositive);
    cmd->add_option("--max-edge", o.meshing.max_edge, "longest patch edge (scene units)")->check(kPositive);
    cmd->add_option("--patches", o.meshing.target_patches,
                    "about this many patches when neither --max-area nor --max-edge is given (2000)")
        ->check(in_range(std::size_t(1), std::size_t(100000000)));
    cmd->add_option("--max-memory", o.max_memory_mb, "refuse work estimated above this many MB (16384)")
        ->check(kPositive);
    cmd->add_flag(
        "--strict", o.strict,
        "treat every warning about the input (materials, degenerate, non-planar or crossing faces) as an error");
    cmd->add_flag(
        "--no-subdivide", [&o](std::int64_t) { o.meshing.subdivide = false; }, "one patch per input face");
    cmd->add_flag(
        "--no-contact-cuts", [&o](std::int64_t) { o.meshing.cut_contacts = false; },
        "mesh every surface whole, also where an object rests on it (by default the parts no light can reach, "
        "like a floor under a block, are left out)");
    cmd->add_option(
           "--meshing",
           [&o](const CLI::results_t& v) {
               if (v[0] != "uniform" && v[0] != "discontinuity") return false;
               o.meshing.kind = v[0] == "uniform" ? MeshingOptions::Kind::uniform : MeshingOptions::Kind::discontinuity;
               return true;
           },
           "uniform (grids of the --max-area limit, default) or discontinuity (surfaces receiving shadow boundaries of "
           "the emitters' direct light are triangulated along them, Heckbert 1992)")
        ->type_name("TEXT")
        ->check(CLI::IsMember({"uniform", "discontinuity"}));
    cmd->add_option("--max-discontinuities", o.meshing.max_discontinuities,
                    "shadow boundaries kept per surface with --meshing discontinuity, the longest (400)")
        ->check(in_range(std::size_t(1), std::size_t(1000000)));
    cmd->add_flag("--flip", o.flip,
                  "turn every face round (for scenes wound clockwise seen from the front, which light from the back)");
    cmd->add_flag("-q,--quiet", o.quiet, "no progress line, no warnings");
    cmd->add_option("--threads", o.threads, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
    cmd->add_option("--visibility", o.visibility, "visibility backend for shadow rays (default: embree)")
        ->check(CLI::IsMember(visibility_backends()));
}

void add_form_factor_options(CLI::App* cmd, FormFactorOptions& f) {
    cmd->add_option("--rays", f.visibility_rays,
                    "visibility rays per patch pair (raycast; 2, with --adaptive or the hierarchical solver 4)")
        ->check(in_range(1, 4096));
    cmd->add_option("--partial-rays", f.partial_rays,
                    "raycast: pairs that a pilot of --rays rays finds partly blocked are traced with this many "
                    "fresh rays, the others with --rays fresh ones; 0: no pilot (0)")
        ->check(in_range(0, 4096));
    cmd->add_option("--clip-above", f.clip_above,
                    "raycast: pairs whose unoccluded factor is at least this and that a blocker may hide take "
                    "the blockers' exact shadows instead of rays; 0: rays for every pair (0.1)")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--receiver-samples", f.receiver_samples,
                    "points per side of each receiver (raycast); 0: adaptive (0)")
        ->check(in_range(0, 16));
    cmd->add_option("--hemicube-res", f.hemicube_resolution, "hemicube pixels per side, even (256)")
        ->check(in_range(2, 4096));
    cmd->add_flag("--hemicube-jitter", f.hemicube_jitter, "rotate each hemicube randomly about the normal (off)");
    cmd->add_flag("--hemicube-baum", f.hemicube_exact_kernel,
                  "hemicube pixels give only the share of each patch seen, the unoccluded factor the amount "
                  "(Baum et al. 1989; off)");
    cmd->add_option("--seed", f.seed, "seed of the rays and rotations (1)");
}

void add_render_options(CLI::App* cmd, RenderOptions& r) {
    cmd->add_option("--camera", r.camera,
                    "cornell, auto or x,y,z:tx,ty,tz (default: cornell for the box, else auto: inside a "
                    "closed room, in front of an open side)");
    cmd->add_option("--fov", r.fov,
                    "vertical field of view in degrees (default: 39 for cornell and open sides, framing the "
                    "room when inside, 30 for x,y,z:tx,ty,tz)");
    cmd->add_option(
        "--size",
        [&r](const CLI::results_t& v) { return std::sscanf(v[0].c_str(), "%dx%d", &r.width, &r.height) == 2; },
        "picture size WxH (800x800)");
    cmd->add_option("--exposure", r.exposure, "exposure in EV (0: mean patch at mid grey)");
    cmd->add_flag(
        "--smooth",
        [&r](std::int64_t) {
            r.smooth = true;
            r.smooth_required = true;
        },
        "colours interpolated from the point data (default)");
    cmd->add_flag(
        "--flat", [&r](std::int64_t) { r.smooth = false; }, "one colour per patch (the patch values)");
    cmd->add_flag("--luminance", r.luminance, "pseudo-colour by luminance with a colour bar");
    cmd->add_flag("--edges", r.edges, "draw the patch edges");
}

}  // namespace bounce::app
