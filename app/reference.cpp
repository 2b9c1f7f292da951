// SPDX-License-Identifier: MIT
// bounce reference: the path-traced radiosity at surface points, the witness every solver and
// mesh is scored against (solver/reference/path_tracer.h).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "app/command.h"
#include "app/reference_image.h"
#include "app/reference_points.h"
#include "app/signals.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/input_error.h"
#include "viewer/pending_output.h"

namespace bounce::app {
namespace {

struct ReferenceCommand {
    std::string points;                 // --points FILE.csv
    std::size_t probes = 0;             // --probes N
    std::string probe_mix = "classes";  // --probe-mix: classes (probes_by_class) or area
    std::string output = "reference.csv";
    ReferenceOptions options;
    bool skip_missing = false;
    ReferenceImageOptions image;  // --image: a path-traced picture instead (app/reference_image.h)
};

int run_reference(const CommonOptions& o, const ReferenceCommand& r) {
    if (!r.image.output.empty()) {
        if (!r.points.empty() || r.probes > 0)
            throw InputError("reference: --image does not combine with --points or --probes");
        ReferenceImageOptions image = r.image;
        image.seed = r.options.seed;
        return run_reference_image(o, image);
    }
    if (r.points.empty() == (r.probes == 0))
        throw InputError("reference: give exactly one of --points FILE.csv or --probes N");
    check_output(r.output);
    const Scene scene = load_scene(o.scene);
    const PathTracer tracer(scene);
    const auto start = std::chrono::steady_clock::now();

    CsvTable input;
    std::vector<std::optional<SurfacePoint>> points;
    if (!r.points.empty()) {
        input = read_csv(r.points);
        const auto rows = point_rows(input, r.points);
        for (std::size_t k = 0; k < rows.size(); ++k) {
            auto x = tracer.locate(rows[k].position, rows[k].normal);
            if (!x && !r.skip_missing) {
                char msg[256];
                std::snprintf(msg, sizeof msg,
                              ":%d: no surface facing the normal within %.4g (0.5%% of the scene's diagonal) of "
                              "the point (%.6g, %.6g, %.6g); --skip-missing leaves such rows empty",
                              input.lines[k], tracer.snap_distance(), rows[k].position.x, rows[k].position.y,
                              rows[k].position.z);
                throw InputError(r.points + msg);
            }
            points.push_back(x);
        }
    } else {
        std::vector<ProbeClass> classes;
        const auto probes = r.probe_mix == "area" ? tracer.probes(r.probes, r.options.seed)
                                                  : probes_by_class(tracer, r.probes, r.options.seed, classes);
        if (probes.empty()) throw InputError(o.scene + ": no surface to place probes on (every surface emits)");
        input = probe_table(probes, classes);
        points.assign(probes.begin(), probes.end());
    }

    const CsvTable table = estimate_table(tracer, input, points, r.options, !o.quiet);
    write_text_file(
        r.output, [&](std::ostream& out) { out << to_csv(table); }, "reference");

    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::size_t converged = 0, budget = 0, missing = 0, interrupted = 0;
    const int status = table.column("status");
    for (const auto& row : table.rows) {
        const std::string& s = row[std::size_t(status)];
        converged += s == "converged";
        budget += s == "budget";
        missing += s == "missing";
        interrupted += s == "interrupted";
    }
    if (budget)
        std::cerr << "bounce: warning: " << budget << " point(s) reached --max-paths " << r.options.max_paths
                  << " above the target error " << r.options.target_error << " (status=budget in the file)\n";
    if (!o.quiet) {
        const double paths = double(tracer.paths_traced());
        std::printf("%zu points: %zu converged to %.3g%%, %zu at the budget, %zu missing, %zu interrupted\n",
                    table.rows.size(), converged, r.options.target_error * 100, budget, missing, interrupted);
        std::printf("%.0f paths in %.2f s (%.0f paths/s)\n", paths, seconds, paths / std::max(seconds, 1e-9));
        std::cout << "wrote " << r.output << "\n";
    }
    if (interrupted_exit_code()) {
        std::cerr << "bounce: interrupted; " << interrupted << " point(s) marked status=interrupted in " << r.output
                  << "\n";
        return interrupted_exit_code();
    }
    return 0;
}

}  // namespace

Command add_reference_command(CLI::App& app, CommonOptions& common) {
    auto r = std::make_shared<ReferenceCommand>();
    auto* cmd = app.add_subcommand(
        "reference", "path-trace radiosity at surface points: the independent reference solvers are scored against");
    cmd->add_option("scene", common.scene, "cornell (built-in), a .obj or a .json scene")->capture_default_str();
    auto* points = cmd->add_option("--points", r->points,
                                   "CSV with a header and columns x,y,z,nx,ny,nz (others are copied through)");
    auto* probes =
        cmd->add_option("--probes", r->probes,
                        "instead of --points: N points on the non-emitting surfaces, spread as --probe-mix says");
    points->excludes(probes);
    cmd->add_option("--probe-mix", r->probe_mix,
                    "--probes: classes (a share each for penumbrae, contacts, points unlit by direct light and lit "
                    "points, written in a class column) or area (spread by area alone)")
        ->capture_default_str()
        ->check(CLI::IsMember({"classes", "area"}));
    cmd->add_option("-o,--output", r->output,
                    "output CSV: the input columns plus B_r,B_g,B_b,se_r,se_g,se_b,paths,surface,status")
        ->capture_default_str();
    cmd->add_option("--target-error", r->options.target_error,
                    "sample each point until the standard error of its luminance is below this fraction")
        ->capture_default_str()
        ->check(in_range(1e-6, 1.0));
    cmd->add_option("--max-paths", r->options.max_paths, "budget of paths per point; points that reach it are flagged")
        ->capture_default_str()
        ->check(in_range(std::uint64_t(64), std::uint64_t(1) << 40));
    cmd->add_option("--seed", r->options.seed, "random seed: same seed and scene, same numbers")->capture_default_str();
    cmd->add_flag("--skip-missing", r->skip_missing,
                  "leave rows with no surface near them empty (status=missing) instead of stopping");
    cmd->add_option("--threads", common.threads, "worker threads (0: all cores)")->capture_default_str();
    cmd->add_flag("-q,--quiet", common.quiet, "no progress and no summary");
    cmd->add_option("--image", r->image.output,
                    "instead of points: a path-traced picture OUT.pfm or OUT.exr (linear radiance) through render's "
                    "camera, and its standard error per pixel in OUT_se.pfm or OUT_se.exr");
    cmd->add_option("--paths", r->image.paths, "--image: paths per pixel, whole batches of 64")
        ->capture_default_str()
        ->check(in_range(std::uint64_t(64), std::uint64_t(1) << 30));
    auto& cam = r->image.camera;
    cam.width = cam.height = 256;
    cmd->add_option("--camera", cam.camera, "--image: the camera, as render's (cornell, auto or x,y,z:tx,ty,tz)");
    cmd->add_option("--fov", cam.fov, "--image: vertical field of view in degrees, as render's");
    cmd->add_option(
        "--size",
        [&cam](const CLI::results_t& v) { return std::sscanf(v[0].c_str(), "%dx%d", &cam.width, &cam.height) == 2; },
        "--image: picture size WxH (256x256)");
    return {cmd, [&common, r] { return run_reference(common, *r); }};
}

}  // namespace bounce::app
