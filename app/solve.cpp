// SPDX-License-Identifier: MIT
// bounce solve: radiosity of a scene, written as a .vtu (and optionally a .pvd series, a PNG
// and a convergence log); --adaptive and --solver hierarchical solve on quadtree elements.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/command.h"
#include "app/convergence_log.h"
#include "app/point_values.h"
#include "app/progress_line.h"
#include "app/signals.h"
#include "mesh/patch_mesh.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/linear/convergence.h"
#include "solver/linear/shooting_solver.h"
#include "solver/linear/solver.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"
#include "viewer/paraview_script.h"
#include "viewer/renderer.h"
#include "viewer/series_writer.h"
#include "viewer/vtu_writer.h"

namespace bounce::app {
namespace {

struct SolveCommand {
    std::string output;
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
    // Options of the receiver-only refinement --adaptive ran before: refused with a message.
    std::vector<std::string> retired;
    HierarchicalOptions hierarchical;
    bool no_clustering = false;  // hierarchical: refine every pair of patches, no cluster hierarchy
    // Given, --tolerance stops the hierarchical iterations too (its default there is 1e-6).
    const CLI::Option* tolerance = nullptr;
    // Options of the patch solvers alone: given with --adaptive or hierarchical, refused by name.
    std::vector<std::pair<std::string, const CLI::Option*>> patch_solver_only;
    std::string gather = "vertices";  // point values: final gather at the vertices (point_values.h)
    /// Hierarchical: display refinement of the point data (DisplayRefinement), 0: off.
    DisplayRefinement display;
    const CLI::Option* display_given = nullptr;
};

/// A number as a stream prints it (1e-05).
std::string number_text(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
}

std::filesystem::path paraview_script_path(const std::filesystem::path& vtu) {
    return vtu.parent_path() / (vtu.stem().string() + "_paraview.py");
}

std::string default_output(const std::string& scene) {
    if (scene == "cornell") return "cornell.vtu";
    return std::filesystem::path(scene).stem().string() + ".vtu";
}

/// The seconds solve prints, writes and logs: the wall time from the meshed scene to the
/// gathered point data (visibility, form factors, refinement, solve and gather), for every solver.
double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// ", 17.3 s (form factors, refinement, solve and gather; gather 10.9 s)": what the printed
/// seconds count (the gather when it ran: `gather_seconds` above 0).
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

/// --solver hierarchical, and --adaptive (the same with the power bound): quadtree elements
/// over the patches, exported as a conforming mesh of the leaves.
int run_solve_elements(const CommonOptions& o, const SolveCommand& s, const std::filesystem::path& out) {
    if (s.element_split > 1) throw std::invalid_argument("--elements does not combine with --adaptive or hierarchical");
    if (s.method != "raycast") throw std::invalid_argument("--adaptive and hierarchical use raycast form factors");
    for (const auto& [name, option] : s.patch_solver_only)
        if (option->count() > 0)
            throw std::invalid_argument(name + " applies to the patch solvers, not to --adaptive or hierarchical");
    CommonOptions roots = o;
    // Start coarse: the elements refine where the light needs it.
    if (default_meshing(o)) roots.meshing.target_patches = kCoarseTargetPatches;
    Scene scene;
    const PatchMesh mesh = load_and_mesh(roots, o.scene, scene);
    const auto start = std::chrono::steady_clock::now();
    const auto visibility = make_visibility(o.visibility, mesh.patches(), specular_occluders(scene));
    ProgressLine progress(!o.quiet);
    SolveResult res;
    std::optional<PatchMesh> elements;
    std::optional<HierarchicalSolution> hierarchy;  // kept for the gather through its links
    std::ostringstream settings, summary;
    settings << "patches=" << mesh.size() << " rays=" << with_default_rays(s.ff, kRefinementRays).visibility_rays
             << " seed=" << s.ff.seed;
    {
        HierarchicalOptions h = s.hierarchical;
        if (s.adaptive) h.power_epsilon = adaptive_power_epsilon(h.power_epsilon);
        h.clustering = !s.no_clustering;
        if (s.tolerance->count() > 0) h.tolerance = s.options.tolerance;
        // 0 (not given, or given), as for the patch solvers, is the default.
        if (s.options.max_iterations > 0) h.max_iterations = s.options.max_iterations;
        h.form_factors = s.ff;
        h.cancel = &g_interrupted;
        h.progress = [&](const std::string& stage, std::size_t done, std::size_t total) {
            progress.items(stage.c_str(), done, total);
        };
        HierarchicalSolution& sol = hierarchy.emplace(solve_hierarchical(mesh.patches(), *visibility, h));
        progress.finish();
        elements.emplace(sol.tree.conforming_mesh(sol.leaves));
        res = std::move(sol.result);
        const double n = double(sol.leaves.size());
        settings << hierarchical_settings(h, sol);
        summary << "patches " << mesh.size() << ", hierarchical"
                << (s.adaptive ? " (--adaptive: power epsilon " + number_text(h.power_epsilon) + ")" : "") << ": "
                << sol.leaves.size() << " elements, " << sol.links.size() << " links ("
                << 100.0 * double(sol.links.size()) / (n * n) << "% of N^2; " << sol.cluster_links
                << " with a cluster, " << sol.clusters << " clusters), " << h.refine_rounds << " refinement round"
                << (h.refine_rounds == 1 ? "" : "s") << ", " << res.steps << " iterations";
    }
    double gather_seconds = 0.0;
    if (!o.quiet)
        for (const auto& w : elements->warnings()) std::cerr << "warning: " << w << "\n";
    if (s.gather != "none" && !g_interrupted.load()) {
        // The elements tile the patches: the patches' visibility is theirs, with fewer triangles
        // to trace against (hierarchical_point_values.h).
        const std::size_t solved = hierarchy->leaves.size();
        const double before = res.seconds;
        DisplayRefinement display = s.display;
        if (s.adaptive && s.gather == "vertices")
            display.tolerance = adaptive_display_tolerance(s.display_given && s.display_given->count() > 0
                                                               ? std::optional<double>(s.display.tolerance)
                                                               : std::nullopt);
        gather_point_values(*hierarchy, *elements, *visibility, res, s.gather, display, o.quiet);
        gather_seconds = res.seconds - before;
        settings << " display_tolerance=" << display.tolerance << " display_cells=" << elements->size();
        res.seconds = seconds_since(start);
        summary << seconds_text(res.seconds, gather_seconds, true) << "\n";
        if (elements->size() != solved)
            summary << "display refinement: " << elements->size() - solved << " more cells (the point data gathered "
                    << "at their vertices)\n";
    } else {
        res.seconds = seconds_since(start);
        summary << seconds_text(res.seconds, 0.0, true) << "\n";
    }
    if (!interrupted_exit_code()) warn_about_winding(o, scene, elements->patches(), res);
    write_vtu(out, *elements, res, ExportInfo{o.scene, settings.str(), s.meshio, scene.units}, s.ascii);
    if (interrupted_exit_code()) {
        std::cerr << "bounce: interrupted; wrote the solution so far to " << out.string() << " (" << file_status(res)
                  << ")\n";
        return interrupted_exit_code();
    }
    if (!s.png.empty())
        render_solution(*elements, res, ExportInfo{o.scene, settings.str(), s.meshio, scene.units}, s.png, s.render);
    if (s.paraview)
        write_paraview_script(paraview_script_path(out), out, *elements, res,
                              ExportInfo{o.scene, settings.str(), s.meshio, scene.units}, s.render);
    if (!o.quiet)
        std::cout << summary.str() << "wrote " << out.string() << (s.png.empty() ? "" : " and " + s.png)
                  << (s.paraview ? " and " + paraview_script_path(out).string() : "") << "\n";
    if (!res.converged && !o.quiet)
        std::cerr << "bounce: not converged (" << res.status << "); the solution was written\n";
    return res.converged ? 0 : 3;
}

int run_solve(const CommonOptions& o, const SolveCommand& s) {
    const std::filesystem::path out = s.output.empty() ? default_output(o.scene) : s.output;
    check_output(out);
    if (!s.png.empty()) {
        check_output(s.png);
        check_picture_path(s.png);
    }
    if (s.adaptive && s.solver != "shooting" && s.solver != "hierarchical")
        throw std::invalid_argument("--adaptive is the hierarchical solver: it takes no other (got --solver " +
                                    s.solver + ")");
    if (!s.retired.empty())
        throw std::invalid_argument(s.retired.front() +
                                    " belonged to the receiver-only refinement --adaptive ran before, now retired: "
                                    "--adaptive is the hierarchical solver refining on power; set --power-epsilon "
                                    "(with --adaptive " +
                                    number_text(kAdaptivePowerEpsilon) + " unless given)");
    if (s.display.tolerance > 0 && s.gather != "vertices")
        throw std::invalid_argument(
            "--display-tolerance refines the point data gathered at the vertices: it needs "
            "--gather vertices (got " +
            s.gather + ")");
    if (s.adaptive || s.solver == "hierarchical") return run_solve_elements(o, s, out);
    const bool display_given = s.display_given && s.display_given->count() > 0;
    if (display_given && (s.element_split > 1 || s.series > 0))
        throw std::invalid_argument("--display-tolerance does not combine with --elements or --series");
    if (!s.log_csv.empty()) check_output(s.log_csv);

    const bool elements = s.element_split > 1;
    if (elements && (s.solver != "shooting" || s.method == "hemicube" || s.method == "exact"))
        throw std::invalid_argument("--elements needs the shooting solver and raycast or analytic form factors");
    CommonOptions fine = o;
    fine.meshing.element_split = s.element_split;
    // Elements must tile their patches exactly (parents), so contact cuts go with split 1 only.
    if (elements) fine.meshing.cut_contacts = false;
    Scene scene;
    PatchMesh mesh = load_and_mesh(fine, o.scene, scene);
    const auto& P = mesh.patches();
    const double n = double(P.size());
    std::optional<PatchMesh> shooters;  // with --elements: the patches that shoot to the elements
    if (elements) {
        MeshingOptions coarse = o.meshing;
        coarse.cut_contacts = false;
        shooters.emplace(scene, coarse);
    }
    check_form_factor_memory(o, s.method, s.ff);
    if (s.solver != "shooting")
        check_memory(o, "the form-factor matrix (" + std::to_string(P.size()) + " patches)", n * n * 4);
    if (s.solver == "direct") check_memory(o, "the direct solver (matrix and LU factors)", n * n * 12);
    const auto start = std::chrono::steady_clock::now();
    const auto visibility = make_visibility(o.visibility, P, specular_occluders(scene));
    const auto ff = elements ? std::make_unique<PatchToElementFormFactor>(
                                   shooters->patches(), P, s.method == "analytic" ? nullptr : visibility.get(), s.ff)
                             : make_form_factor_estimator(s.method, P, visibility.get(), s.ff);
    const bool shooting = s.solver == "shooting";
    ProgressLine progress(!o.quiet, shooting ? "shot" : "sweep", shooting ? "error" : "residual");
    std::optional<FormFactorMatrix> matrix;
    if (s.solver != "shooting") {
        matrix = FormFactorMatrix::build(
            *ff, P.size(), s.max_matrix_mb << 20, [&](std::size_t d, std::size_t t) { progress.rows(d, t); },
            &g_interrupted);
        progress.finish();
    }
    if (matrix) {
        // No patch can send out more than all its power: a row above 1 is form-factor error,
        // amplified by 1 / (1 - rho) in a bright closed scene.
        const auto sums = matrix->row_sums();
        const double over = sums.empty() ? 0.0 : *std::max_element(sums.begin(), sums.end()) - 1.0;
        if (over > 1e-3 && !o.quiet)
            std::cerr << "warning: form-factor rows sum to up to 1 + " << over << " (> 1 + 1e-3); --form-factors "
                      << "exact keeps rows within 1e-6 of the truth\n";
        const double bound = contraction_bound(P, sums);
        if (bound >= 1.0 && !o.quiet)
            std::cerr << "warning: max rho_i * sum_j F_ij = " << bound
                      << " >= 1: the iteration may not converge (reflectance 1 in a closed scene, or row sums "
                         "above 1)\n";
    }
    SolverOptions so = s.options;
    so.progress = [&](const SolveProgress& p) { progress.update(p); };
    so.max_matrix_mb = s.max_matrix_mb;
    so.cancel = &g_interrupted;
    std::ostringstream settings;
    settings << "patches=" << (elements ? shooters->size() : mesh.size()) << " elements=" << mesh.size()
             << " edge=" << mesh.edge_length() << " solver=" << s.solver << " sor=" << s.options.sor
             << " method=" << s.method << " rays=" << with_default_rays(s.ff, kPatchPairRays).visibility_rays
             << " receiver_samples=" << s.ff.receiver_samples << " hemicube_res=" << s.ff.hemicube_resolution
             << " seed=" << s.ff.seed << " tolerance=" << s.options.tolerance << (o.flip ? " flip=1" : "");
    std::optional<SeriesWriter> series;
    if (s.series > 0) {
        series.emplace(std::filesystem::path(out).replace_extension(".pvd"), mesh,
                       ExportInfo{o.scene, settings.str(), s.meshio, scene.units});
        so.snapshot_every = s.series;
        so.snapshot = [&](const SolveResult& so_far) {
            SolveResult snap = so_far;
            snap.form_factors = s.method;
            if (matrix) snap.seconds += matrix->seconds();  // as the final file counts them
            series->add(snap);
        };
    }
    const auto solver = elements ? std::make_unique<ShootingSolver>(
                                       P, *ff, so, nullptr, ElementHierarchy{&shooters->patches(), &mesh.parents()})
                                 : make_solver(s.solver, {P, ff.get(), matrix ? &*matrix : nullptr}, so);
    SolveResult res = solver->solve();
    progress.finish();
    res.form_factors = s.method;
    if (matrix) res.seconds += matrix->seconds();
    double gather_seconds = 0.0;
    const std::size_t solved = mesh.size();
    if (s.gather != "none" && !g_interrupted.load()) {
        const double before = res.seconds;
        PatchDisplayRefinement display;
        // Off by default where the mesh must stay the solved one (a series' frames, elements).
        display.tolerance = display_given                         ? s.display.tolerance
                            : s.element_split > 1 || s.series > 0 ? 0.0
                                                                  : kPatchDisplayTolerance;
        gather_point_values(mesh, *visibility, res, s.gather, display, o.quiet);
        gather_seconds = res.seconds - before;
        if (display.tolerance > 0)
            settings << " display_tolerance=" << display.tolerance << " display_cells=" << mesh.size();
    }
    res.seconds = seconds_since(start);

    if (!interrupted_exit_code()) warn_about_winding(o, scene, P, res);
    // Shooting never holds whole rows; the power it shot that arrived beyond 100% is the rows'
    // surplus over 1, weighted by the shots (what a bright closed scene amplifies by 1/(1-rho)).
    if (const double shot = res.shot_power.sum(); shot > 0 && !o.quiet) {
        const double surplus = -res.escaped_power.sum() / shot;
        if (surplus > 1e-3)
            std::cerr << "warning: the form-factor rows of the shots sum to 1 + " << surplus
                      << " on average (> 1 + 1e-3): the solution gains energy; --form-factors exact keeps rows "
                         "within 1e-6 of the truth\n";
    }
    write_vtu(out, mesh, res, ExportInfo{o.scene, settings.str(), s.meshio, scene.units}, s.ascii);
    if (interrupted_exit_code()) {
        std::cerr << "bounce: interrupted after " << res.steps << " steps; wrote the solution so far to "
                  << out.string() << " (" << file_status(res) << ")\n";
        return interrupted_exit_code();
    }
    if (series) series->finish(res);
    if (!s.png.empty())
        render_solution(mesh, res, ExportInfo{o.scene, settings.str(), s.meshio, scene.units}, s.png, s.render);
    if (s.paraview)
        write_paraview_script(paraview_script_path(out), out, mesh, res,
                              ExportInfo{o.scene, settings.str(), s.meshio, scene.units}, s.render);
    if (!s.log_csv.empty()) write_log_csv(s.log_csv, {res}, {s.method}, {matrix ? matrix->seconds() : 0.0});
    if (!o.quiet) {
        std::cout << "patches " << (elements ? std::to_string(shooters->size()) + ", elements " : "") << solved
                  << (mesh.size() != solved ? " (" + std::to_string(mesh.size()) + " display cells)" : "") << ", "
                  << s.solver << " " << res.steps << (s.solver == "shooting" ? " shots" : " sweeps");
        if (s.solver == "shooting")
            std::cout << ", unshot fraction " << res.unshot_fraction << ", estimated error " << res.error_estimate;
        if (res.residual >= 0) std::cout << ", residual " << res.residual;
        std::cout << (res.converged ? "" : " (NOT converged: " + to_string(res.status) + ")")
                  << seconds_text(res.seconds, gather_seconds, false) << "\n"
                  << "wrote " << out.string() << (series ? " and " + series->pvd().string() : "")
                  << (s.png.empty() ? "" : " and " + s.png)
                  << (s.paraview ? " and " + paraview_script_path(out).string() : "") << "\n";
    }
    if (!res.converged && !o.quiet) {
        std::cerr << "bounce: not converged (" << res.status << "), last "
                  << (res.residual >= 0         ? "residual " + std::to_string(res.residual)
                      : res.error_estimate >= 0 ? "estimated error " + number_text(res.error_estimate) +
                                                      ", unshot fraction " + number_text(res.unshot_fraction)
                                                : "unshot fraction " + std::to_string(res.unshot_fraction))
                  << "; the partial solution was written\n";
    }
    return res.converged ? 0 : 3;
}

}  // namespace

Command add_solve_command(CLI::App& app, CommonOptions& common) {
    auto solve = std::make_shared<SolveCommand>();
    auto* solve_cmd = app.add_subcommand("solve", "compute radiosity and write a .vtu");
    add_meshing_options(solve_cmd, common);
    solve_cmd->add_option("-o,--output", solve->output, "output .vtu (default: <scene>.vtu)");
    std::vector<std::string> solve_solvers = solver_names();
    solve_solvers.push_back("hierarchical");
    solve_cmd->add_option("--solver", solve->solver, "shooting, gauss-seidel, jacobi, direct or hierarchical")
        ->check(CLI::IsMember(solve_solvers));
    solve_cmd
        ->add_option("--gather", solve->gather,
                     "point data: gathered at the vertices from the solved patches with the exact kernel and "
                     "visibility (vertices), also at the patch centres as cell array radiosity_gathered (centres), "
                     "or averaged from the patches around each vertex (none)")
        ->check(CLI::IsMember(gather_modes()))
        ->capture_default_str();
    solve_cmd->add_flag("--adaptive", solve->adaptive,
                        "model no more than the scene needs: the hierarchical solver refining on power "
                        "(--power-epsilon " +
                            number_text(kAdaptivePowerEpsilon) + " unless one above 0 is given)");
    for (const char* name : {"--target-error", "--max-patches"})
        solve_cmd
            ->add_option_function<std::string>(
                name, [solve, name](const std::string&) { solve->retired.push_back(name); },
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
    solve->display_given =
        solve_cmd
            ->add_option("--display-tolerance", solve->display.tolerance,
                         "split cells for display where linear interpolation between their vertices, as ParaView shows "
                         "the point data, would miss the light inside them by more than this share, and gather the new "
                         "vertices (patch solvers: new points tried down to 2 splits a patch; hierarchical: the "
                         "element's centre value); 0: off (default: 0.02 with the patch solvers but for "
                         "--elements and --series, 0.0025 with --adaptive, 0 with --solver hierarchical)")
            ->check(in_range(0.0, 1.0));
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
    solve->tolerance = solve_cmd
                           ->add_option("--tolerance", solve->options.tolerance,
                                        "shooting: stop when the largest relative error of a patch that the "
                                        "light still unshot would add, estimated from the convergence so far, is "
                                        "below this; the others: relative residual, or largest change of an "
                                        "element's radiosity per iteration, relative to the mean (hierarchical); "
                                        "1e-3, hierarchical 1e-6")
                           ->check(kPositive);
    solve_cmd->add_option("--max-shots,--max-iterations", solve->options.max_iterations,
                          "stop after this many shots or sweeps (default: no shot limit, shooting stops as "
                          "stalled when the unshot power stops falling; 10000 sweeps; hierarchical 1000 "
                          "iterations)");
    auto& only = solve->patch_solver_only;
    only.emplace_back("--max-seconds",
                      solve_cmd->add_option("--max-seconds", solve->options.max_seconds, "stop after this many seconds")
                          ->check(CLI::NonNegativeNumber));
    only.emplace_back(
        "--sor",
        solve_cmd->add_option("--sor", solve->options.sor, "over-relaxation factor for jacobi and gauss-seidel, (0,2)")
            ->check(in_range(0.0, 2.0)));
    only.emplace_back("--log", solve_cmd->add_option("--log", solve->log_csv, "write the convergence log (CSV)"));
    only.emplace_back("--overshoot", solve_cmd->add_flag("--overshoot", solve->options.overshoot,
                                                         "shooting: over-shoot by rho times the ambient term"));
    solve_cmd
        ->add_option("--elements", solve->element_split,
                     "shooting: cut every patch into KxK elements that receive (patches shoot to elements)")
        ->check(in_range(1, 64));
    only.emplace_back("--cache-mb", solve_cmd->add_option("--cache-mb", solve->options.cache_mb,
                                                          "shooting: memory for cached form-factor rows (MB, default "
                                                          "1024); rows beyond it are recomputed"));
    solve_cmd->add_option("--max-matrix-mb", solve->max_matrix_mb, "refuse a matrix larger than this (MB; 2048)");
    solve_cmd->add_option("--form-factors", solve->method, "raycast, exact, hemicube, or analytic (no occlusion)")
        ->check(CLI::IsMember(form_factor_methods()));
    add_form_factor_options(solve_cmd, solve->ff);
    solve_cmd->add_flag("--ascii", solve->ascii, "write ASCII instead of compressed binary");
    solve_cmd->add_flag("--paraview", solve->paraview,
                        "also write OUT_paraview.py beside OUT.vtu: a ParaView script (pvpython, or the GUI's "
                        "Python Shell) that opens it with render's camera and colours");
    solve_cmd->add_flag("--meshio", solve->meshio,
                        "store the text fields (scene, solver, ...) as Int8 char arrays, which meshio reads; "
                        "by default they are VTK string arrays, which ParaView shows as text and meshio refuses");
    solve_cmd->add_option("--png", solve->png, "render the result to this PNG after solving");
    only.emplace_back("--series", solve_cmd->add_option("--series", solve->series,
                                                        "also write a .pvd time series: a snapshot every N shots or "
                                                        "sweeps"));
    add_render_options(solve_cmd, solve->render);
    return {solve_cmd, [&common, solve] { return run_solve(common, *solve); }};
}

}  // namespace bounce::app
