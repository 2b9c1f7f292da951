// SPDX-License-Identifier: MIT
// bounce solve: radiosity of a scene, written as a .vtu (and optionally a .pvd series, a PNG
// and a convergence log); --adaptive and --solver hierarchical solve on quadtree elements.
// The solve itself is solver/pipeline's (solve_scene), which Python's bounce.solve runs too.
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/command.h"
#include "app/convergence_log.h"
#include "app/progress_line.h"
#include "app/signals.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/input_error.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/linear/solver.h"
#include "solver/pipeline/quality.h"
#include "solver/pipeline/solve_scene.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "viewer/paraview_script.h"
#include "viewer/renderer.h"
#include "viewer/series_writer.h"
#include "viewer/vtu_writer.h"

namespace bounce::app {
namespace {

struct SolveCommand {
    std::string output;
    std::string quality;  // a preset (quality.h); "": none
    std::string solver = "shooting";
    SolverOptions options;
    std::string method = "raycast";
    FormFactorOptions ff;
    std::size_t max_matrix_mb = 2048;
    std::string log_csv;
    bool ascii = false;
    bool meshio = false;    // text fields as char arrays, which meshio reads (ParaView then shows numbers)
    bool paraview = false;  // also OUT_paraview.py, a ParaView script that opens OUT as render shows it
    std::string png;
    std::size_t series = 0;
    RenderOptions render;
    int element_split = 1;
    bool adaptive = false;  // the hierarchical solver with the power bound (kAdaptivePowerEpsilon)
    // Options of the receiver-only refinement --adaptive ran before, by key: refused with a message.
    std::vector<std::string> retired;
    HierarchicalOptions hierarchical;
    bool no_clustering = false;       // hierarchical: refine every pair of patches, no cluster hierarchy
    bool whole_patches = false;       // no open parts (open_parts.h, element_open_shares.h)
    bool no_balance = false;          // patch solvers: rows as sampled (balanced_form_factors.h)
    std::string gather = "vertices";  // point data: final gather at the vertices (point_values.h)
    double display_tolerance = 0.0;   // hierarchical: display refinement of the point data, 0: off
    // The options whose being given matters (SolveRequest's optional fields), by key.
    std::vector<std::pair<std::string, const CLI::Option*>> given;

    /// A meshing was asked for, which a preset's patch count yields to.
    bool meshing_given() const { return was_given("patches") || was_given("max-area") || was_given("max-edge"); }

    bool was_given(const std::string& key) const {
        for (const auto& [k, option] : given)
            if (k == key) return option->count() > 0;
        return false;
    }
};

/// The request the flags state (SolveRequest's options that were not given stay unset).
SolveRequest request_of(const CommonOptions& o, const SolveCommand& s) {
    SolveRequest r;
    r.meshing = o.meshing;
    r.element_split = s.element_split;
    r.visibility = o.visibility;
    r.flip = o.flip;
    r.solver = parse_solver_kind(s.solver);
    r.adaptive = s.adaptive;
    if (s.was_given("tolerance")) r.tolerance = s.options.tolerance;
    r.max_iterations = s.options.max_iterations;
    if (s.was_given("max-seconds")) r.max_seconds = s.options.max_seconds;
    if (s.was_given("sor")) r.sor = s.options.sor;
    if (s.was_given("overshoot")) r.overshoot = s.options.overshoot;
    if (s.was_given("cache-mb")) r.cache_mb = s.options.cache_mb;
    if (s.was_given("series")) r.series = s.series;
    r.max_matrix_mb = s.max_matrix_mb;
    r.retired = s.retired;
    r.method = parse_form_factor_method(s.method);
    r.form_factors = s.ff;
    r.link_epsilon = s.hierarchical.link_epsilon;
    r.power_epsilon = s.hierarchical.power_epsilon;
    r.refine_rounds = s.hierarchical.refine_rounds;
    r.max_level = s.hierarchical.max_level;
    r.clustering = !s.no_clustering;
    r.open_parts = !s.whole_patches;
    r.balance = !s.no_balance;
    r.gather = parse_gather_mode(s.gather);
    if (s.was_given("display-tolerance")) r.display_tolerance = s.display_tolerance;
    if (!s.quality.empty()) r.quality = parse_quality(s.quality);
    apply_quality(r, s.meshing_given());
    return r;
}

std::filesystem::path paraview_script_path(const std::filesystem::path& vtu) {
    return vtu.parent_path() / (vtu.stem().string() + "_paraview.py");
}

std::string default_output(const std::string& scene) {
    if (scene == "cornell") return "cornell.vtu";
    return std::filesystem::path(scene).stem().string() + ".vtu";
}

/// ", 17.3 s (form factors, refinement, solve and gather; gather 10.9 s)": what the printed
/// seconds count, the wall time from the meshed scene to the gathered point data (the gather
/// when it ran: `gather_seconds` above 0).
std::string seconds_text(double seconds, double gather_seconds, bool hierarchical) {
    std::ostringstream s;
    s.precision(3);
    s << ", " << seconds << " s (form factors, " << (hierarchical ? "refinement, " : "") << "solve";
    if (gather_seconds > 0) s << " and gather; gather " << gather_seconds << " s";
    s << ")";
    return s.str();
}

/// What the written file says, so the message after a signal cannot contradict it.
std::string file_status(const SolveResult& res) {
    return "status = " + to_string(res.status) + ", converged = " + (res.converged ? "1" : "0");
}

/// "patches 90, hierarchical: 1234 elements, ... iterations, 1.2 s (...)" and the display
/// refinement's cells.
std::string hierarchy_summary(const SolveRequest& r, const SolvedScene& solved) {
    const HierarchySummary& h = *solved.hierarchy;
    const double n = double(h.leaves);
    std::ostringstream s;
    s << "patches " << solved.patches << ", hierarchical"
      << (r.adaptive ? " (--adaptive: power epsilon " + number_text(h.power_epsilon) + ")" : "") << ": " << h.leaves
      << " elements, " << h.links << " links (" << 100.0 * double(h.links) / (n * n) << "% of N^2; " << h.cluster_links
      << " with a cluster, " << h.clusters << " clusters), " << h.refine_rounds << " refinement round"
      << (h.refine_rounds == 1 ? "" : "s") << ", " << solved.result.steps << " iterations"
      << seconds_text(solved.result.seconds, solved.gather_seconds, true) << "\n";
    if (solved.mesh->size() != h.leaves)
        s << "display refinement: " << solved.mesh->size() - h.leaves << " more cells (the point data gathered "
          << "at their vertices)\n";
    return s.str();
}

/// "patches 2000, shooting 812 shots, unshot fraction ..., 1.1 s (...)".
std::string patch_summary(const SolveRequest& r, const SolvedScene& solved) {
    const SolveResult& res = solved.result;
    const bool shooting = r.solver == SolverKind::shooting;
    std::ostringstream s;
    const bool elements = r.element_split > 1;
    s << "patches " << (elements ? std::to_string(solved.patches) + ", elements " : "")
      << (elements ? solved.mesh->size() : solved.patches)
      << (!elements && solved.mesh->size() != solved.patches
              ? " (" + std::to_string(solved.mesh->size()) + " display cells)"
              : "")
      << ", " << to_string(r.solver) << " " << res.steps << (shooting ? " shots" : " sweeps");
    if (shooting) s << ", unshot fraction " << res.unshot_fraction << ", estimated error " << res.error_estimate;
    if (res.residual >= 0) s << ", residual " << res.residual;
    s << (res.converged ? "" : " (NOT converged: " + to_string(res.status) + ")")
      << seconds_text(res.seconds, solved.gather_seconds, false) << "\n";
    return s.str();
}

/// What the patch solvers say when they stop short of the tolerance.
std::string not_converged_text(const SolveResult& res) {
    return "bounce: not converged (" + to_string(res.status) + "), last " +
           (res.residual >= 0         ? "residual " + std::to_string(res.residual)
            : res.error_estimate >= 0 ? "estimated error " + number_text(res.error_estimate) + ", unshot fraction " +
                                            number_text(res.unshot_fraction)
                                      : "unshot fraction " + std::to_string(res.unshot_fraction)) +
           "; the partial solution was written\n";
}

/// The solve with the command line's progress line, signals, --max-memory and series.
SolvedScene run_pipeline(const CommonOptions& o, const SolveCommand& s, const SolveRequest& request, const Scene& scene,
                         const std::filesystem::path& out, std::optional<SeriesWriter>& series) {
    const bool shooting = request.solver == SolverKind::shooting;
    ProgressLine progress(!o.quiet, shooting ? "shot" : "sweep", shooting ? "error" : "residual");
    SolveHooks hooks;
    hooks.cancel = &g_interrupted;
    hooks.mesh = [&](const MeshingOptions& m) { return std::make_shared<const PatchMesh>(mesh_scene(o, scene, m)); };
    hooks.check_memory = [&](const std::string& what, double bytes) { check_memory(o, what, bytes); };
    hooks.rows = [&](std::size_t d, std::size_t t) { progress.rows(d, t); };
    hooks.solve = [&](const SolveProgress& p) { progress.update(p); };
    hooks.items = [&](const char* stage, std::size_t d, std::size_t t) { progress.items(stage, d, t); };
    hooks.stage_end = [&] { progress.finish(); };
    hooks.snapshot = [&](const PatchMesh& mesh, const std::string& settings, const SolveResult& so_far) {
        if (!series)
            series.emplace(std::filesystem::path(out).replace_extension(".pvd"), mesh,
                           ExportInfo{o.scene, settings, s.meshio, scene.units});
        series->add(so_far);
    };
    SolvedScene solved = solve_scene(scene, request, hooks);
    print_solve_messages(solved, o.quiet);
    return solved;
}

int run_solve(const CommonOptions& o, const SolveCommand& s) {
    const std::filesystem::path out = s.output.empty() ? default_output(o.scene) : s.output;
    check_output(out);
    if (!s.png.empty()) {
        check_output(s.png);
        check_picture_path(s.png);
    }
    const SolveRequest request = request_of(o, s);
    request.validate();
    const bool refines = request.refines();
    if (refines && s.was_given("log"))
        throw InputError("--log applies to the patch solvers, not to --adaptive or hierarchical");
    if (!s.log_csv.empty()) check_output(s.log_csv);
    const Scene scene = load_checked(o, o.scene);
    if (!refines) check_form_factor_memory(o, s.method, s.ff);
    std::optional<SeriesWriter> series;
    const SolvedScene solved = run_pipeline(o, s, request, scene, out, series);
    const SolveResult& res = solved.result;
    const ExportInfo info{o.scene, solved.settings, s.meshio, scene.units};
    write_vtu(out, *solved.mesh, res, info, s.ascii);
    if (interrupted_exit_code()) {
        std::cerr << "bounce: interrupted" << (refines ? "" : " after " + std::to_string(res.steps) + " steps")
                  << "; wrote the solution so far to " << out.string() << " (" << file_status(res) << ")\n";
        return interrupted_exit_code();
    }
    if (series) series->finish(res);
    if (!s.png.empty()) render_solution(*solved.mesh, res, info, s.png, s.render);
    if (s.paraview) write_paraview_script(paraview_script_path(out), out, *solved.mesh, res, info, s.render);
    if (!s.log_csv.empty()) write_log_csv(s.log_csv, {res}, {s.method}, {solved.form_factor_seconds});
    if (!o.quiet)
        std::cout << (refines ? hierarchy_summary(request, solved) : patch_summary(request, solved)) << "wrote "
                  << out.string() << (series ? " and " + series->pvd().string() : "")
                  << (s.png.empty() ? "" : " and " + s.png)
                  << (s.paraview ? " and " + paraview_script_path(out).string() : "") << "\n";
    if (!res.converged && !o.quiet)
        std::cerr << (refines ? "bounce: not converged (" + to_string(res.status) + "); the solution was written\n"
                              : not_converged_text(res));
    return res.converged ? 0 : 3;
}

}  // namespace
Command add_solve_command(CLI::App& app, CommonOptions& common) {
    auto solve = std::make_shared<SolveCommand>();
    auto* solve_cmd = app.add_subcommand("solve", "compute radiosity and write a .vtu");
    add_meshing_options(solve_cmd, common);
    for (const char* key : {"patches", "max-area", "max-edge"})
        solve->given.emplace_back(key, solve_cmd->get_option(std::string("--") + key));
    solve_cmd->add_option("-o,--output", solve->output, "output .vtu (default: <scene>.vtu)");
    solve_cmd->add_option("--quality", solve->quality,
                          "a preset of the patch count and display cells, measured on the scenes with path-traced "
                          "references: draft (" +
                              quality_preset(Quality::draft).flags + "), default (the defaults) or fine (" +
                              quality_preset(Quality::fine).flags + "); options given beside it win");
    solve_cmd->add_option("--solver", solve->solver, "shooting, gauss-seidel, jacobi, direct or hierarchical")
        ->check(CLI::IsMember(solver_kind_names()));
    solve_cmd
        ->add_option("--gather", solve->gather,
                     "point data: gathered at the vertices from the solved patches with the exact kernel and "
                     "visibility (vertices), also at the patch centres as cell array radiosity_gathered (centres), "
                     "or averaged from the patches around each vertex (none)")
        ->check(CLI::IsMember(gather_mode_names()))
        ->capture_default_str();
    solve_cmd->add_flag("--adaptive", solve->adaptive,
                        "model no more than the scene needs: the hierarchical solver refining on power "
                        "(--power-epsilon " +
                            number_text(kAdaptivePowerEpsilon) + " unless one above 0 is given)");
    for (const char* name : {"--target-error", "--max-patches"})
        solve_cmd
            ->add_option_function<std::string>(
                name, [solve, name](const std::string&) { solve->retired.push_back(name + 2); },
                "retired with --adaptive's receiver-only refinement (use --power-epsilon)")
            ->group("");  // hidden from --help; given, it is refused with a message
    solve_cmd
        ->add_option("--link-epsilon", solve->hierarchical.link_epsilon,
                     "hierarchical: link error bound, a share of what the link brings (0.1)")
        ->check(kPositive);
    solve_cmd
        ->add_option("--power-epsilon", solve->hierarchical.power_epsilon,
                     "hierarchical: also link when the power a link could misplace is below this share of the "
                     "scene's power (BF refinement; 0: off)")
        ->check(in_range(0.0, 1.0))
        ->capture_default_str();
    solve->given.emplace_back(
        "display-tolerance",
        solve_cmd
            ->add_option("--display-tolerance", solve->display_tolerance,
                         "split cells for display where linear interpolation between their vertices, as ParaView shows "
                         "the point data, would miss the light inside them by more than this share, and gather the new "
                         "vertices (patch solvers: new points tried down to 2 splits a patch, 6 where a step in the "
                         "light crosses a cell; hierarchical: the "
                         "element's centre value); 0: off (default: 0.02 with the patch solvers but for --elements and "
                         "--series, 0.0025 with --adaptive, 0 with --solver hierarchical)")
            ->check(in_range(0.0, 1.0)));
    solve_cmd
        ->add_option("--refine-rounds", solve->hierarchical.refine_rounds,
                     "hierarchical: refine the links and solve this many times, each round refining with the last "
                     "one's radiosity and keeping the form factors it had (multigridding)")
        ->check(in_range(1, 100))
        ->capture_default_str();
    solve_cmd->add_flag("--no-clustering", solve->no_clustering,
                        "hierarchical: start from every pair of input patches, not from one cluster hierarchy "
                        "(Smits, Arvo and Greenberg 1994), to compare");
    solve_cmd
        ->add_option("--max-level", solve->hierarchical.max_level,
                     "hierarchical: quadtree depth under each input face, or under 1/2000 of the scene's area where a "
                     "face is smaller (4)")
        ->check(in_range(0, 12));
    solve->given.emplace_back(
        "tolerance", solve_cmd
                         ->add_option("--tolerance", solve->options.tolerance,
                                      "shooting: stop when the largest relative error of a patch that the "
                                      "light still unshot would add, estimated from the convergence so far, is "
                                      "below this; the others: relative residual, or largest change of an "
                                      "element's radiosity per iteration, relative to the mean (hierarchical); "
                                      "1e-3, hierarchical 1e-6")
                         ->check(kPositive));
    solve_cmd->add_option("--max-shots,--max-iterations", solve->options.max_iterations,
                          "stop after this many shots or sweeps (default: no shot limit, shooting stops as "
                          "stalled when the unshot power stops falling; 10000 sweeps; hierarchical 1000 "
                          "iterations)");
    auto& only = solve->given;
    only.emplace_back("max-seconds",
                      solve_cmd->add_option("--max-seconds", solve->options.max_seconds, "stop after this many seconds")
                          ->check(CLI::NonNegativeNumber));
    only.emplace_back(
        "sor",
        solve_cmd->add_option("--sor", solve->options.sor, "over-relaxation factor for jacobi and gauss-seidel, (0,2)")
            ->check(in_range(0.0, 2.0)));
    only.emplace_back("log", solve_cmd->add_option("--log", solve->log_csv, "write the convergence log (CSV)"));
    only.emplace_back("overshoot", solve_cmd->add_flag("--overshoot", solve->options.overshoot,
                                                       "shooting: over-shoot by rho times the ambient term"));
    solve_cmd
        ->add_option("--elements", solve->element_split,
                     "shooting: cut every patch into KxK elements that receive (patches shoot to elements)")
        ->check(in_range(1, 64));
    only.emplace_back("cache-mb", solve_cmd->add_option("--cache-mb", solve->options.cache_mb,
                                                        "shooting: memory for cached form-factor rows (MB, default "
                                                        "1024); rows beyond it are recomputed"));
    solve_cmd->add_option("--max-matrix-mb", solve->max_matrix_mb, "refuse a matrix larger than this (MB; 2048)");
    solve_cmd->add_option("--form-factors", solve->method, "raycast, exact, hemicube, or analytic (no occlusion)")
        ->check(CLI::IsMember(form_factor_methods()));
    add_form_factor_options(solve_cmd, solve->ff);
    solve_cmd->add_flag("--whole-patches", solve->whole_patches,
                        "solve on whole patches and elements, not on their parts open to the scene (a patch "
                        "partly under another object then loses the light its buried part sends, and the patch "
                        "solvers' rows keep their sampling error)");
    solve_cmd->add_flag("--no-balance", solve->no_balance, "patch solvers: form-factor rows as sampled, not balanced");
    solve_cmd->add_flag("--ascii", solve->ascii, "write ASCII instead of compressed binary");
    solve_cmd->add_flag("--paraview", solve->paraview,
                        "also write OUT_paraview.py beside OUT.vtu: a ParaView script (pvpython, or the GUI's "
                        "Python Shell) that opens it with render's camera and colours");
    solve_cmd->add_flag("--meshio", solve->meshio,
                        "store the text fields (scene, solver, ...) as Int8 char arrays, which meshio reads; "
                        "by default they are VTK string arrays, which ParaView shows as text and meshio refuses");
    solve_cmd->add_option("--png", solve->png, "render the result to this PNG after solving");
    only.emplace_back("series", solve_cmd->add_option("--series", solve->series,
                                                      "also write a .pvd time series: a snapshot every N shots or "
                                                      "sweeps"));
    add_render_options(solve_cmd, solve->render);
    return {solve_cmd, [&common, solve] { return run_solve(common, *solve); }};
}

}  // namespace bounce::app
