// SPDX-License-Identifier: MIT
// The `bounce` command line: thin over the mesh, solver and viewer libraries.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "mesh/input_error.h"
#include "mesh/patch_mesh.h"
#include "mesh/scene_loader.h"
#include "solver/form_factor_estimator.h"
#include "solver/shooting_solver.h"
#include "solver/visibility.h"
#include "viewer/version.h"
#include "viewer/vtu_writer.h"

namespace {

using namespace bounce;

struct CommonOptions {
    std::string scene = "cornell";
    MeshingOptions meshing;
    bool quiet = false;
    int threads = 0;
};

void add_meshing_options(CLI::App* cmd, CommonOptions& o) {
    cmd->add_option("scene", o.scene, "'cornell' (built-in, default), a .obj or a .json scene");
    cmd->add_option("--max-area", o.meshing.max_area,
                    "largest patch area (scene units^2); default: total area / 2000")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--max-edge", o.meshing.max_edge, "longest patch edge (scene units)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_flag("--no-subdivide", [&o](std::int64_t) { o.meshing.subdivide = false; },
                  "one patch per input face");
    cmd->add_flag("-q,--quiet", o.quiet, "no progress line, no warnings");
    cmd->add_option("--threads", o.threads, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
}

void print_warnings(const Scene& scene, bool quiet) {
    if (quiet) return;
    for (const auto& w : scene.warnings) std::cerr << "warning: " << w << "\n";
}

/// A one-line progress display on a terminal, at most five updates a second.
class ProgressLine {
public:
    explicit ProgressLine(bool enabled) : m_enabled(enabled && ::isatty(STDERR_FILENO)) {}
    ~ProgressLine() { finish(); }
    void update(const SolveProgress& p) {
        if (!m_enabled || p.seconds - m_last < 0.2) return;
        m_last = p.seconds;
        std::fprintf(stderr, "\rshot %zu, unshot %.2e (target %.1e), %.1f s   ", p.step, p.unshot_fraction,
                     p.tolerance, p.seconds);
        m_shown = true;
    }
    void finish() {
        if (m_shown) std::fputc('\n', stderr);
        m_shown = false;
    }

private:
    bool m_enabled;
    bool m_shown = false;
    double m_last = 0.0;
};

std::string default_output(const std::string& scene) {
    if (scene == "cornell") return "cornell.vtu";
    return std::filesystem::path(scene).stem().string() + ".vtu";
}

int run_info(const CommonOptions& o) {
    Scene scene = load_scene(o.scene);
    print_warnings(scene, o.quiet);
    PatchMesh mesh(scene, o.meshing);
    const Rgb e = mesh.emitted_power();
    std::cout << "scene:          " << scene.name << "\n"
              << "surfaces:       " << scene.surfaces.size() << "\n"
              << "materials:      " << scene.materials.size() << "\n"
              << "patches:        " << mesh.size() << " (edge " << mesh.edge_length() << ")\n"
              << "total area:     " << mesh.total_area() << "\n"
              << "emitted power:  " << e.to_string() << "\n"
              << "warnings:       " << scene.warnings.size() << "\n";
    return 0;
}

struct SolveCommand {
    std::string output;
    double tolerance = 1e-3;
    std::size_t max_shots = 0;
    std::string method = "raycast";
    FormFactorOptions ff;
    bool ascii = false;
};

int run_solve(const CommonOptions& o, const SolveCommand& s) {
    const std::filesystem::path out = s.output.empty() ? default_output(o.scene) : s.output;
    // Refuse an unwritable destination before any work is done.
    const auto dir = out.has_parent_path() ? out.parent_path() : std::filesystem::path(".");
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec))
        throw InputError(out.string() + ": output directory " + dir.string() + " does not exist");
    if (std::filesystem::is_directory(out, ec)) throw InputError(out.string() + ": is a directory");

    Scene scene = load_scene(o.scene);
    print_warnings(scene, o.quiet);
    PatchMesh mesh(scene, o.meshing);
    const auto visibility = make_cgal_visibility(mesh.patches());
    const auto ff = make_form_factor_estimator(s.method, mesh.patches(), visibility.get(), s.ff);
    ProgressLine progress(!o.quiet);
    ShootingOptions so;
    so.tolerance = s.tolerance;
    so.max_shots = s.max_shots;
    so.progress = [&](const SolveProgress& p) { progress.update(p); };
    const SolveResult res = ShootingSolver(mesh.patches(), *ff, so).solve();
    progress.finish();

    std::ostringstream settings;
    settings << "patches=" << mesh.size() << " edge=" << mesh.edge_length() << " method=" << s.method
             << " rays=" << s.ff.visibility_rays << " receiver_sampling=" << s.ff.receiver_sampling
             << " seed=" << s.ff.seed << " tolerance=" << s.tolerance;
    write_vtu(out, mesh, res, {o.scene, settings.str()}, s.ascii);
    if (!o.quiet) {
        std::cout << "patches " << mesh.size() << ", shots " << res.steps << ", unshot fraction "
                  << res.unshot_fraction << (res.converged ? "" : " (NOT converged)") << ", " << res.seconds
                  << " s\n"
                  << "wrote " << out.string() << "\n";
    }
    return res.converged ? 0 : 3;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: progressive-refinement radiosity"};
    app.set_version_flag("--version", std::string(bounce::kBounceVersion));
    app.require_subcommand(1);
    CommonOptions common;
    SolveCommand solve;

    auto* solve_cmd = app.add_subcommand("solve", "compute radiosity and write a .vtu");
    add_meshing_options(solve_cmd, common);
    solve_cmd->add_option("-o,--output", solve.output, "output .vtu (default: <scene>.vtu)");
    solve_cmd->add_option("--tolerance", solve.tolerance, "stop at this unshot fraction")
        ->check(CLI::PositiveNumber);
    solve_cmd->add_option("--max-shots", solve.max_shots, "stop after this many shots (default 100 N)");
    solve_cmd->add_option("--form-factors", solve.method, "raycast (with visibility) or analytic (no occlusion)")
        ->check(CLI::IsMember(bounce::form_factor_methods()));
    solve_cmd->add_option("--rays", solve.ff.visibility_rays, "visibility rays per patch pair")
        ->check(CLI::Range(1, 4096));
    solve_cmd->add_option("--seed", solve.ff.seed, "seed of the visibility rays");
    solve_cmd->add_flag("--ascii", solve.ascii, "write ASCII instead of compressed binary");

    auto* info_cmd = app.add_subcommand("info", "print the scene's surfaces, patches, area and emitted power");
    add_meshing_options(info_cmd, common);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        std::cerr << "bounce: " << e.what() << " (see --help)\n";
        return 2;
    }
    std::optional<tbb::global_control> threads;
    if (common.threads > 0)
        threads.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(common.threads));
    try {
        if (*solve_cmd) return run_solve(common, solve);
        return run_info(common);
    } catch (const bounce::InputError& e) {
        std::cerr << "bounce: error: " << e.what() << "\n";
        return 2;
    } catch (const std::invalid_argument& e) {
        std::cerr << "bounce: error: " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "bounce: failed: " << e.what() << "\n";
        return 1;
    }
}
