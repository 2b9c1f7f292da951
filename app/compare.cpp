// SPDX-License-Identifier: MIT
// bounce compare: every requested solver on every requested form-factor method against one
// reference (convergence.csv and charts), or with --meshes uniform, adaptive and hierarchical
// element meshes against one fine uniform reference (meshes.csv and a chart).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "app/command.h"
#include "app/convergence_log.h"
#include "app/progress_line.h"
#include "app/signals.h"
#include "mesh/input_error.h"
#include "mesh/patch_mesh.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/linear/gathering_solver.h"
#include "solver/linear/solver.h"
#include "solver/refinement/adaptive_radiosity.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"
#include "viewer/charts.h"
#include "viewer/pending_output.h"

namespace bounce::app {
namespace {

struct CompareCommand {
    std::vector<std::string> solvers = {"shooting", "gauss-seidel", "jacobi", "direct"};
    std::vector<std::string> methods = {"raycast", "hemicube"};
    std::string out = "compare";
    SolverOptions options;
    FormFactorOptions ff;
    std::size_t max_matrix_mb = 2048;
    std::size_t max_direct = 4000;
    bool meshes = false;
    int reference_level = 5;
};

/// bounce compare --meshes: uniform element meshes of several sizes, adaptive subdivision at
/// several targets and hierarchical radiosity at several link tolerances, all over the same
/// patches and against one fine uniform reference; meshes.csv, meshes.png and a table.
int run_compare_meshes(const CommonOptions& o, const CompareCommand& c) {
    std::error_code ec;
    std::filesystem::create_directories(c.out, ec);
    if (!std::filesystem::is_directory(c.out)) throw InputError(c.out + ": cannot create the output directory");
    CommonOptions roots = o;
    if (default_meshing(o)) roots.meshing.target_patches = 30;  // the Cornell box: 60 patches
    Scene scene;
    const PatchMesh mesh = load_and_mesh(roots, o.scene, scene);
    const auto& P = mesh.patches();
    const auto visibility = make_visibility(o.visibility, P);
    AdaptiveOptions a;
    a.form_factors = c.ff;
    a.max_elements = 200000;
    a.cancel = &g_interrupted;
    const double per_level = 4.0;
    check_memory(o, "the reference elements' form-factor rows",
                 double(P.size()) * std::pow(per_level, c.reference_level) * double(P.size()) * 4.0 * 2.0);
    const AdaptiveSolution reference = solve_uniform_elements(P, *visibility, c.reference_level, a);
    struct Row {
        std::string method, setting;
        std::size_t elements = 0, links = 0;
        double seconds = 0.0, rms = 0.0;
    };
    std::vector<Row> rows;
    rows.push_back({"reference", "uniform level " + std::to_string(c.reference_level), reference.leaves.size(), 0,
                    reference.result.seconds, 0.0});
    for (int level = 0; level < c.reference_level; ++level) {
        const AdaptiveSolution u = solve_uniform_elements(P, *visibility, level, a);
        rows.push_back({"uniform", "level " + std::to_string(level), u.leaves.size(), 0, u.result.seconds,
                        rms_difference(u, reference)});
    }
    for (const double target : {0.2, 0.1, 0.07, 0.05, 0.035}) {
        AdaptiveOptions t = a;
        t.target_error = target;
        const AdaptiveSolution s = solve_adaptive(P, *visibility, t);
        std::ostringstream setting;
        setting << "target " << target;
        rows.push_back({"adaptive", setting.str(), s.leaves.size(), 0, s.result.seconds, rms_difference(s, reference)});
    }
    for (const double eps : {0.4, 0.2, 0.1}) {
        HierarchicalOptions h;
        h.form_factors = c.ff;
        h.link_epsilon = eps;
        h.max_level = std::max(1, c.reference_level - 2);
        h.cancel = &g_interrupted;
        const HierarchicalSolution s = solve_hierarchical(P, *visibility, h);
        std::ostringstream setting;
        setting << "link epsilon " << eps;
        rows.push_back({"hierarchical", setting.str(), s.leaves.size(), s.links, s.result.seconds,
                        rms_difference(s.tree, s.leaves, s.result.radiosity, reference)});
    }
    if (interrupted_exit_code()) return interrupted_exit_code();
    std::ostringstream csv;
    csv << "method,setting,elements,links,seconds,rms_error\n";
    for (const auto& r : rows)
        csv << r.method << "," << r.setting << "," << r.elements << "," << r.links << "," << r.seconds << "," << r.rms
            << "\n";
    const std::filesystem::path dir = c.out;
    write_text_file(
        dir / "meshes.csv", [&](std::ostream& out) { out << csv.str(); }, "mesh comparison");
    write_mesh_charts(dir);
    if (!o.quiet) {
        std::printf("%zu patches; RMS error of the reflected radiosity against %zu uniform elements (%d rays a pair)\n",
                    P.size(), reference.leaves.size(), c.ff.visibility_rays);
        std::printf("%-13s %-18s %9s %10s %9s %9s\n", "method", "setting", "elements", "links", "seconds", "rms error");
        for (const auto& r : rows)
            std::printf("%-13s %-18s %9zu %10s %9.3f %9.4f\n", r.method.c_str(), r.setting.c_str(), r.elements,
                        r.links ? std::to_string(r.links).c_str() : "-", r.seconds, r.rms);
        std::cout << "wrote " << (dir / "meshes.csv").string() << " and meshes.png\n";
    }
    return 0;
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
    for (const auto& m : c.methods) check_form_factor_memory(o, m, c.ff);
    check_memory(o, "the form-factor matrices and the reference (" + std::to_string(P.size()) + " patches)",
                 n * n * (4.0 * double(c.methods.size()) + (P.size() <= c.max_direct ? 8.0 : 0.0)));
    const auto visibility = make_visibility(o.visibility, P);
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
    if (P.size() <= c.max_direct) {
        reference = DirectSolver({P, nullptr, &matrices[0]}, ref_options).solve();
        reference_name = "direct solution on the " + c.methods[0] + " matrix";
    } else {
        ref_options.tolerance = 1e-12;
        ref_options.max_iterations = 100000;
        reference = GatheringSolver(true, {P, nullptr, &matrices[0]}, ref_options).solve();
        reference_name = "Gauss-Seidel to residual 1e-12 on the " + c.methods[0] + " matrix (too large for direct)";
    }
    if (!o.quiet) std::cout << "reference: " << reference_name << "\n";

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
    const std::filesystem::path dir = c.out;
    write_log_csv(dir / "convergence.csv", runs, run_methods, ff_seconds);
    write_comparison_charts(dir);
    if (!o.quiet) {
        std::printf("%-10s %-13s %8s %10s %10s %11s %11s %16s\n", "ff", "solver", "steps", "solve s", "total s",
                    "residual", "rms error", "steps/s to 1e-3");
        for (std::size_t k = 0; k < runs.size(); ++k) {
            const auto& r = runs[k];
            const auto& last = r.log.back();
            std::string to = "-";
            for (const auto& rec : r.log)
                if (rec.residual >= 0 && rec.residual < 1e-3) {
                    to = std::to_string(rec.step) + " / " + std::to_string(rec.seconds).substr(0, 6);
                    break;
                }
            std::printf("%-10s %-13s %8zu %10.3f %10.3f %11.3g %11.3g %16s\n", run_methods[k].c_str(), r.solver.c_str(),
                        r.steps, r.seconds, r.seconds + ff_seconds[k], r.residual, last.rms_error, to.c_str());
        }
        std::cout << "patches " << P.size() << "; wrote " << (dir / "convergence.csv").string() << ", convergence.png, "
                  << "speed_vs_accuracy.png\n";
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
        ->check(CLI::Range(0.0, 2.0));
    cmp_cmd->add_option("--max-matrix-mb", cmp->max_matrix_mb, "refuse a matrix larger than this (MB)");
    cmp_cmd->add_flag("--meshes", cmp->meshes,
                      "compare uniform, adaptive and hierarchical meshes over the same patches (60 for the box) "
                      "against one fine uniform reference, instead of solvers");
    cmp_cmd
        ->add_option("--reference-level", cmp->reference_level,
                     "--meshes: the reference cuts every patch into 4^level elements (5)")
        ->check(CLI::Range(1, 7));
    add_form_factor_options(cmp_cmd, cmp->ff);
    return {cmp_cmd, [&common, cmp] { return run_compare(common, *cmp); }};
}

}  // namespace bounce::app
