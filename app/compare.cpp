// SPDX-License-Identifier: MIT
// bounce compare: every requested solver on every requested form-factor method against one
// reference (convergence.csv and charts), or with --meshes uniform, receiver-only, adaptive and
// hierarchical meshes of the scene, all scored at the same path-traced probes (meshes.csv and charts).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "app/compare.h"

#include "app/command.h"
#include "app/compare_picture.h"
#include "app/convergence_log.h"
#include "app/point_values.h"
#include "app/progress_line.h"
#include "app/reference_points.h"
#include "app/signals.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/input_error.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/linear/gathering_solver.h"
#include "solver/linear/shooting_solver.h"
#include "solver/linear/solver.h"
#include "solver/reference/probe_classes.h"
#include "solver/reference/probe_score.h"
#include "solver/refinement/adaptive_radiosity.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"
#include "viewer/charts.h"
#include "viewer/pending_output.h"

namespace bounce::app {

std::string probe_columns() {
    std::string h =
        "probe_rms_patch,probe_max_patch,probe_rms_smooth,probe_max_smooth,probe_rms_smooth_r,probe_rms_smooth_g,"
        "probe_rms_smooth_b,probe_points,reference_noise";
    for (const ProbeClass c : kProbeClasses) {
        const std::string n = to_string(c);
        h += ",probe_rms_smooth_" + n + ",probe_max_smooth_" + n + ",probe_rms_patch_" + n + ",probe_points_" + n;
    }
    return h;
}

std::string probe_fields(const ProbeScore& s, std::span<const ProbeClass> classes) {
    std::ostringstream t;
    t.precision(6);
    t << s.rms_patch << ',' << s.max_patch << ',' << s.rms_smooth << ',' << s.max_smooth << ','
      << s.rms_smooth_channel.r << ',' << s.rms_smooth_channel.g << ',' << s.rms_smooth_channel.b << ',' << s.scored
      << ',' << s.reference_noise;
    for (const ClassScore& c : score_by_class(s, classes)) {
        t << ',';
        if (c.scored) t << c.rms_smooth;
        t << ',';
        if (c.scored) t << c.max_smooth;
        t << ',';
        if (c.scored) t << c.rms_patch;
        t << ',' << c.scored;
    }
    return t.str();
}

void print_class_counts(std::span<const ProbeClass> classes) {
    std::printf("probe classes (penumbra, contact: point data RMS / worst):");
    for (const ProbeClass c : kProbeClasses)
        std::printf(" %s %zu", to_string(c).c_str(), std::size_t(std::count(classes.begin(), classes.end(), c)));
    std::printf("\n");
}

std::string class_text(const ProbeScore& s, std::span<const ProbeClass> classes, ProbeClass which) {
    const ClassScore c = score_by_class(s, classes)[std::size_t(which)];
    if (!c.scored) return "-";
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.2f%% / %.1f%%", 100 * c.rms_smooth, 100 * c.max_smooth);
    return buf;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

namespace {

/// A number as a stream prints it (1e-05).
std::string shortest_text(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
}

/// Every requested solver on every requested form-factor method, on one meshing, against one
/// reference: the direct solution on the first method's matrix when the scene is small
/// enough, else Gauss-Seidel to a relative residual of 1e-12 (said so).
int run_compare(const CommonOptions& o, const CompareCommand& c) {
    if (c.meshes) return run_compare_meshes(o, c);
    std::error_code ec;
    std::filesystem::create_directories(c.out, ec);
    if (!std::filesystem::is_directory(c.out)) throw InputError(c.out + ": cannot create the output directory");
    Scene scene;
    PatchMesh mesh = load_and_mesh(o, o.scene, scene);
    const auto& P = mesh.patches();
    const double n = double(P.size());
    const std::vector<ReferencePoint> probes = reference_for_compare(scene, c.reference, c.out, o.quiet);
    const std::vector<ProbeClass> classes = probe_classes(scene, probes);
    for (const auto& m : c.methods) check_form_factor_memory(o, m, c.ff);
    check_memory(o, "the form-factor matrices and the reference (" + std::to_string(P.size()) + " patches)",
                 n * n * (4.0 * double(c.methods.size()) + (P.size() <= c.max_direct ? 8.0 : 0.0)));
    const auto visibility = make_visibility(o.visibility, P, specular_occluders(scene));
    std::vector<std::unique_ptr<FormFactorEstimator>> estimators;
    std::vector<FormFactorMatrix> matrices;
    for (const auto& m : c.methods) {
        estimators.push_back(make_form_factor_estimator(m, P, visibility.get(), c.ff));
        ProgressLine progress(!o.quiet);
        matrices.push_back(FormFactorMatrix::build(
            *estimators.back(), P.size(), c.max_matrix_mb << 20,
            [&](std::size_t d, std::size_t t) { progress.rows(d, t); }, &g_interrupted));
        progress.finish();
        if (!o.quiet) std::cout << m << " form factors: " << matrices.back().seconds() << " s\n";
    }
    SolverOptions ref_options;
    ref_options.max_matrix_mb = c.max_matrix_mb;
    SolveResult reference;
    std::string reference_name;
    const auto reference_start = std::chrono::steady_clock::now();
    if (P.size() <= c.max_direct) {
        reference = DirectSolver({P, nullptr, &matrices[0]}, ref_options).solve();
        reference_name = "direct solution on the " + c.methods[0] + " matrix";
    } else {
        ref_options.tolerance = 1e-12;
        ref_options.max_iterations = 100000;
        reference = GatheringSolver(true, {P, nullptr, &matrices[0]}, ref_options).solve();
        reference_name = "Gauss-Seidel to residual 1e-12 on the " + c.methods[0] + " matrix (too large for direct)";
    }
    if (!o.quiet)
        std::cout << "convergence reference: " << reference_name << ", " << seconds_since(reference_start) << " s\n";

    std::vector<SolveResult> runs;
    std::vector<std::string> run_methods;
    std::vector<double> ff_seconds;
    for (std::size_t k = 0; k < c.methods.size(); ++k) {
        const MatrixFormFactor rows(matrices[k], c.methods[k]);
        for (const auto& name : c.solvers) {
            if (name == "direct" && P.size() > c.max_direct) continue;
            SolverOptions so = c.options;
            so.reference = &reference.radiosity;
            so.max_matrix_mb = c.max_matrix_mb;
            SolveResult r = make_solver(name, {P, &rows, &matrices[k]}, so)->solve();
            r.form_factors = c.methods[k];
            runs.push_back(std::move(r));
            run_methods.push_back(c.methods[k]);
            ff_seconds.push_back(matrices[k].seconds());
        }
    }
    std::vector<ProbeScore> scores;
    for (auto& r : runs) {
        // Point data as solve writes it: gathered at the vertices (time added to the run).
        gather_point_values(mesh, *visibility, r, c.gather, true);
        scores.push_back(score_at_probes(mesh, r.radiosity, probes, r.point_radiosity));
    }
    const std::filesystem::path dir = c.out;
    write_log_csv(dir / "convergence.csv", runs, run_methods, ff_seconds);
    write_text_file(
        dir / "runs.csv",
        [&](std::ostream& out) {
            out << "form_factors,solver,patches,steps,form_factor_seconds,solve_seconds,total_seconds,residual,"
                   "rms_error_vs_direct,"
                << probe_columns() << ",error_reference\n";
            out.precision(8);
            for (std::size_t k = 0; k < runs.size(); ++k) {
                const auto& r = runs[k];
                out << run_methods[k] << ',' << r.solver << ',' << P.size() << ',' << r.steps << ',' << ff_seconds[k]
                    << ',' << r.seconds << ',' << r.seconds + ff_seconds[k] << ',' << r.residual << ','
                    << std::max(0.0, r.log.back().rms_error) << ',' << probe_fields(scores[k], classes) << ','
                    << reference_name << "\n";
            }
        },
        "run summary");
    write_comparison_charts(dir);
    if (!o.quiet) {
        std::printf(
            "probe errors: relative RMS luminance error at %zu path-traced probes (their own noise %.2f%%), "
            "patch value and smooth point data\n",
            scores.empty() ? std::size_t(0) : scores[0].scored, scores.empty() ? 0.0 : 100 * scores[0].reference_noise);
        std::printf("%-10s %-13s %8s %10s %10s %11s %11s %18s %11s %12s %16s\n", "ff", "solver", "steps", "solve s",
                    "total s", "residual", "vs direct", "to 1e-3 (steps, s)", "probe patch", "probe smooth",
                    "penumbra");
        for (std::size_t k = 0; k < runs.size(); ++k) {
            const auto& r = runs[k];
            const auto& last = r.log.back();
            std::string to = "-";
            for (const auto& rec : r.log)
                if (rec.residual >= 0 && rec.residual < 1e-3) {
                    to = std::to_string(rec.step) + ", " + std::to_string(rec.seconds).substr(0, 6) + " s";
                    break;
                }
            std::printf("%-10s %-13s %8zu %10.3f %10.3f %11.3g %11.3g %18s %10.2f%% %11.2f%% %16s\n",
                        run_methods[k].c_str(), r.solver.c_str(), r.steps, r.seconds, r.seconds + ff_seconds[k],
                        r.residual, last.rms_error, to.c_str(), 100 * scores[k].rms_patch, 100 * scores[k].rms_smooth,
                        class_text(scores[k], classes, ProbeClass::penumbra).c_str());
        }
        print_class_counts(classes);
        std::cout << "patches " << P.size() << "; wrote " << (dir / "convergence.csv").string()
                  << ", runs.csv, convergence.png, speed_vs_accuracy.png\n";
    }
    return 0;
}

}  // namespace

Command add_compare_command(CLI::App& app, CommonOptions& common) {
    auto cmp = std::make_shared<CompareCommand>();
    auto* cmp_cmd = app.add_subcommand("compare", "run several solvers and form-factor methods; chart them");
    add_meshing_options(cmp_cmd, common);
    cmp_cmd->add_option("--solvers", cmp->solvers, "solvers to run (default: all)")
        ->delimiter(',')
        ->check(CLI::IsMember(solver_names()));
    cmp_cmd
        ->add_option("--form-factors", cmp->methods,
                     "form-factor methods (default: raycast,hemicube); the first gives the reference")
        ->delimiter(',')
        ->check(CLI::IsMember(form_factor_methods()));
    cmp_cmd->add_option("--out", cmp->out, "output folder (default: compare)");
    cmp_cmd->add_option("--tolerance", cmp->options.tolerance, "stopping tolerance of each solver")->check(kPositive);
    cmp_cmd->add_option("--max-iterations", cmp->options.max_iterations, "shots or sweeps limit");
    cmp_cmd->add_option("--sor", cmp->options.sor, "over-relaxation for jacobi and gauss-seidel")
        ->check(in_range(0.0, 2.0));
    cmp_cmd->add_option("--max-matrix-mb", cmp->max_matrix_mb, "refuse a matrix larger than this (MB)");
    cmp_cmd->add_flag("--meshes", cmp->meshes,
                      "compare uniform, receiver-only, adaptive and hierarchical meshes over the same coarse "
                      "patches as solve --adaptive (" +
                          std::to_string(kCoarseCornellPatches) + " on the Cornell box, from --patches " +
                          std::to_string(kCoarseTargetPatches) +
                          " and the contact cuts; a meshing option given: that meshing), instead of solvers");
    cmp_cmd
        ->add_option("--reference-level", cmp->reference_level,
                     "--meshes: the reference cuts every patch into 4^level elements (5; 0: no fine reference, "
                     "no uniform elements)")
        ->check(in_range(0, 7));
    cmp_cmd->add_option("--reference", cmp->reference,
                        "score every run at the points of this `bounce reference` CSV (default: path-trace " +
                            std::to_string(kCompareProbes) + " probes once and cache them in the output folder)");
    cmp_cmd
        ->add_option("--patch-counts", cmp->patch_counts,
                     "--meshes: uniform patch meshes solved by shooting, for the speed-accuracy chart")
        ->delimiter(',')
        ->capture_default_str();
    cmp_cmd
        ->add_option(
            "--methods", cmp->mesh_methods,
            "--meshes: uniform (elements), patches, discontinuity, receiver (the receiver-only refinement solve "
            "--adaptive ran before it became the hierarchical solver refining on power, to compare), adaptive "
            "(what solve --adaptive runs: hierarchical with power epsilon " +
                shortest_text(adaptive_power_epsilon(0.0)) + ", at every --link-epsilons), hierarchical (default: all)")
        ->delimiter(',')
        ->check(CLI::IsMember(
            std::vector<std::string>{"uniform", "patches", "discontinuity", "receiver", "adaptive", "hierarchical"}));
    cmp_cmd->add_option("--targets", cmp->targets, "--meshes: receiver-only refinement's target errors")
        ->delimiter(',')
        ->check(kPositive)
        ->capture_default_str();
    cmp_cmd->add_option("--link-epsilons", cmp->link_epsilons, "--meshes: hierarchical and adaptive link epsilons")
        ->delimiter(',')
        ->check(kPositive)
        ->capture_default_str();
    cmp_cmd
        ->add_option("--power-epsilons", cmp->power_epsilons,
                     "--meshes: hierarchical power epsilons, each run with every link epsilon (0: off)")
        ->delimiter(',')
        ->check(in_range(0.0, 1.0))
        ->capture_default_str();
    cmp_cmd
        ->add_option("--display-tolerances", cmp->display_tolerances,
                     "--meshes: display refinement tolerances (solve --display-tolerance), each a row of every "
                     "patches and hierarchical solve (0: off)")
        ->delimiter(',')
        ->check(in_range(0.0, 1.0))
        ->capture_default_str();
    cmp_cmd
        ->add_option("--refine-rounds", cmp->refine_rounds,
                     "--meshes: hierarchical refine-and-solve rounds (multigridding)")
        ->check(in_range(1, 100))
        ->capture_default_str();
    cmp_cmd
        ->add_option("--max-level", cmp->max_level,
                     "--meshes: hierarchical and adaptive quadtree depth under each coarse patch, as solve's")
        ->check(in_range(0, 12))
        ->capture_default_str();
    cmp_cmd
        ->add_option("--gather", cmp->gather,
                     "point data of every run: gathered at the vertices (vertices) or averaged (none); the gather's "
                     "time is counted in the run's")
        ->check(CLI::IsMember(std::vector<std::string>{"vertices", "none"}))
        ->capture_default_str();
    add_form_factor_options(cmp_cmd, cmp->ff);
    const auto picture = add_compare_picture_options(cmp_cmd);
    return {cmp_cmd, [&common, cmp, picture] {
                return picture->enabled ? run_compare_picture(common, *picture, cmp->out) : run_compare(common, *cmp);
            }};
}

}  // namespace bounce::app
