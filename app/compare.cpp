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

#include "app/command.h"
#include "app/compare_picture.h"
#include "app/convergence_log.h"
#include "app/point_values.h"
#include "app/progress_line.h"
#include "app/reference_points.h"
#include "app/signals.h"
#include "mesh/input_error.h"
#include "mesh/patch_mesh.h"
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
    int reference_level = 5;  // --meshes: the fine uniform elements (0: none, for large scenes)
    // --meshes: which families run: uniform elements, uniform patch meshes, discontinuity
    // meshes, the receiver-only refinement (what --adaptive ran before), adaptive (what
    // `solve --adaptive` runs: hierarchical refining on power), hierarchical radiosity.
    std::vector<std::string> mesh_methods = {"uniform",  "patches",  "discontinuity",
                                             "receiver", "adaptive", "hierarchical"};
    std::vector<double> targets = {0.2, 0.1, 0.07, 0.05, 0.035};  // --meshes: receiver-only target errors
    // --meshes: hierarchical and adaptive link epsilons, coarse to fine: the rows draw a curve of
    // error against time.
    std::vector<double> link_epsilons = {0.8, 0.4, 0.2, 0.1, 0.05};
    // --meshes: hierarchical quadtree depth under each coarse patch, as `solve` has it.
    int max_level = HierarchicalOptions{}.max_level;
    int refine_rounds = HierarchicalOptions{}.refine_rounds;  // --meshes: hierarchical refine-and-solve rounds
    // --meshes: hierarchical power epsilons (BF refinement on power), each with every link epsilon
    std::vector<double> power_epsilons = {HierarchicalOptions{}.power_epsilon};
    // --meshes: hierarchical display refinement tolerances (DisplayRefinement), each a row of
    // every solve (0: off)
    std::vector<double> display_tolerances = {0.0};
    std::string reference;  // --reference: a `bounce reference` CSV; empty: probes cached in `out`
    std::vector<std::size_t> patch_counts = {250, 500, 1000, 2000, 4000, 8000};  // --meshes: uniform patch meshes
    std::string gather = "vertices";  // point data of every run, as solve writes it
};

/// The probe columns shared by runs.csv and meshes.csv: the scores over every probe, then per
/// probe class (ProbeClass) the point data's RMS and worst, the patch values' RMS and the count.
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

/// How many probes of each class the scores below rest on.
void print_class_counts(std::span<const ProbeClass> classes) {
    std::printf("probe classes (penumbra, contact: point data RMS / worst):");
    for (const ProbeClass c : kProbeClasses)
        std::printf(" %s %zu", to_string(c).c_str(), std::size_t(std::count(classes.begin(), classes.end(), c)));
    std::printf("\n");
}

/// "2.31% / 7.80%": RMS and worst of the point data over one class's probes ("-" with none).
std::string class_text(const ProbeScore& s, std::span<const ProbeClass> classes, ProbeClass which) {
    const ClassScore c = score_by_class(s, classes)[std::size_t(which)];
    if (!c.scored) return "-";
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.2f%% / %.1f%%", 100 * c.rms_smooth, 100 * c.max_smooth);
    return buf;
}

/// A number as a stream prints it (1e-05).
std::string shortest_text(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// bounce compare --meshes: uniform element meshes of several sizes, uniform and discontinuity
/// patch meshes, the receiver-only refinement at several targets, and hierarchical radiosity
/// (without and, as `solve --adaptive`, with the power bound) at several link epsilons, each scored at the path-traced
/// probes (and, but for hierarchical, against fine uniform elements over the same patches); meshes.csv, meshes.png and
/// a table.
int run_compare_meshes(const CommonOptions& o, const CompareCommand& c) {
    std::error_code ec;
    std::filesystem::create_directories(c.out, ec);
    if (!std::filesystem::is_directory(c.out)) throw InputError(c.out + ": cannot create the output directory");
    CommonOptions roots = o;
    // The coarse patches `solve --adaptive` and hierarchical start from (kCoarsePatchesText).
    if (default_meshing(o)) roots.meshing.target_patches = kCoarseTargetPatches;
    Scene scene;
    const PatchMesh mesh = load_and_mesh(roots, o.scene, scene);
    const auto& P = mesh.patches();
    const auto visibility = make_visibility(o.visibility, P, specular_occluders(scene));
    AdaptiveOptions a;
    a.form_factors = c.ff;
    a.max_elements = 200000;
    a.cancel = &g_interrupted;
    const double per_level = 4.0;
    if (c.reference_level > 0)
        check_memory(o, "the reference elements' form-factor rows",
                     double(P.size()) * std::pow(per_level, c.reference_level) * double(P.size()) * 4.0 * 2.0);
    // The truth every row is scored on: path-traced probes, computed once and cached.
    const std::vector<ReferencePoint> probes = reference_for_compare(scene, c.reference, c.out, o.quiet);
    const std::vector<ProbeClass> classes = probe_classes(scene, probes);
    // Scores a solution as solve would write it: point data gathered (the time added to the
    // row's seconds) when the mesh is within the gather's budget. (A hierarchical solution
    // gathers through its links, below, and weighs its own budget from the lists it builds.)
    auto score_mesh = [&](const PatchMesh& m, const std::vector<Rgb>& B, double& seconds, bool& gathered) {
        SolveResult r;
        r.radiosity = B;
        gathered = false;
        if (c.gather != "none" && double(m.mesh().n_vertices()) * double(m.size()) <= kMaxGatherPairs) {
            const auto t0 = std::chrono::steady_clock::now();  // the gather's visibility counted too
            const auto v = make_visibility(o.visibility, m.patches(), specular_occluders(scene));
            gathered = gather_point_values(m, *v, r, "vertices", true);
            seconds += seconds_since(t0);
        }
        return score_at_probes(m, B, probes, r.point_radiosity);
    };
    struct Row {
        std::string method, setting;
        std::size_t elements = 0, links = 0;
        double seconds = 0.0, rms = -1.0;  // rms: against the fine uniform elements (-1: not comparable)
        ProbeScore probe;
        bool gathered = false;  // point data gathered (else averaged: beyond the gather's budget, or --gather none)
    };
    std::vector<Row> rows;
    auto wanted = [&](const char* method) {
        return std::find(c.mesh_methods.begin(), c.mesh_methods.end(), method) != c.mesh_methods.end();
    };
    // A progress line on a terminal, a run at a time; a run cut short by a signal keeps no row
    // (the rows done are written below).
    const std::size_t total_runs =
        (c.reference_level > 0 ? 1 : 0) + (wanted("uniform") ? std::size_t(c.reference_level) : 0) +
        (wanted("patches") ? c.patch_counts.size() * c.display_tolerances.size() : 0) +
        (wanted("discontinuity") ? c.patch_counts.size() : 0) + (wanted("receiver") ? c.targets.size() : 0) +
        (wanted("adaptive") ? c.link_epsilons.size() : 0) +
        (wanted("hierarchical") ? c.link_epsilons.size() * c.power_epsilons.size() : 0);
    ProgressLine progress(!o.quiet);
    std::size_t runs_done = 0;
    auto starting = [&](const std::string& what) { progress.runs("compare --meshes", runs_done, total_runs, what); };
    auto add_row = [&](std::string method, std::string setting, std::size_t links, double seconds, double rms,
                       const PatchMesh& m, const std::vector<Rgb>& B) {
        ++runs_done;
        if (g_interrupted.load()) return;
        Row r{std::move(method), std::move(setting), m.size(), links, seconds, rms, {}, false};
        r.probe = score_mesh(m, B, r.seconds, r.gathered);
        if (!g_interrupted.load()) rows.push_back(std::move(r));
    };
    // The fine uniform elements ("vs fine"); --reference-level 0 skips them (a large scene's
    // fine elements would need patches x elements form factors).
    std::optional<AdaptiveSolution> reference;
    auto vs_fine = [&](const ElementTree& tree, const std::vector<std::uint32_t>& leaves, const std::vector<Rgb>& B) {
        return reference ? rms_difference(tree, leaves, B, *reference) : -1.0;
    };
    if (c.reference_level > 0) {
        starting("reference, uniform level " + std::to_string(c.reference_level));
        reference = solve_uniform_elements(P, *visibility, c.reference_level, a);
        add_row("reference", "uniform level " + std::to_string(c.reference_level), 0, reference->result.seconds, 0.0,
                reference->tree.conforming_mesh(reference->leaves), reference->result.radiosity);
    }
    for (int level = 0; level < c.reference_level && wanted("uniform") && !g_interrupted.load(); ++level) {
        starting("uniform level " + std::to_string(level));
        const AdaptiveSolution u = solve_uniform_elements(P, *visibility, level, a);
        add_row("uniform", "level " + std::to_string(level), 0, u.result.seconds,
                vs_fine(u.tree, u.leaves, u.result.radiosity), u.tree.conforming_mesh(u.leaves), u.result.radiosity);
    }
    // Uniform patch meshes solved by the default path (every patch shoots), as `solve --patches N` runs,
    // and the same area limits with --meshing discontinuity (the meshing's time counted in the row's).
    for (const auto kind : {MeshingOptions::Kind::uniform, MeshingOptions::Kind::discontinuity}) {
        if (!wanted(kind == MeshingOptions::Kind::uniform ? "patches" : "discontinuity")) continue;
        for (const std::size_t n : c.patch_counts) {
            if (g_interrupted.load()) break;
            starting(std::string(kind == MeshingOptions::Kind::uniform ? "patches" : "discontinuity") + " --patches " +
                     std::to_string(n));
            const auto t0 = std::chrono::steady_clock::now();
            MeshingOptions m = o.meshing;
            m.kind = kind;
            m.target_patches = n;
            m.max_area = m.max_edge = 0;
            const PatchMesh um(scene, m);
            const auto uv = make_visibility(o.visibility, um.patches(), specular_occluders(scene));
            const auto ff = make_form_factor_estimator("raycast", um.patches(), uv.get(), c.ff);
            SolverOptions so;
            so.tolerance = c.options.tolerance;  // --tolerance, as solve's
            so.cancel = &g_interrupted;
            const SolveResult r = ShootingSolver(um.patches(), *ff, so).solve();
            const double solved = seconds_since(t0);
            const char* method = kind == MeshingOptions::Kind::uniform ? "patches" : "discontinuity";
            for (const double display : c.display_tolerances) {
                if (display == 0) {
                    add_row(method, "--patches " + std::to_string(n), 0, solved, -1.0, um, r.radiosity);
                    continue;
                }
                // Display refinement (solve --display-tolerance): a row of its own, the solve's
                // time plus its gather's.
                ++runs_done;
                if (g_interrupted.load() || c.gather == "none") break;
                std::ostringstream setting;
                setting << "--patches " << n << " display " << display;
                Row row{method, setting.str(), um.size(), 0, solved, -1.0, {}, false};
                const auto t1 = std::chrono::steady_clock::now();
                PatchMesh cells = um;
                SolveResult g;
                g.radiosity = r.radiosity;
                const auto v = make_visibility(o.visibility, cells.patches(), specular_occluders(scene));
                row.gathered = gather_point_values(cells, *v, g, "vertices", PatchDisplayRefinement{display}, true);
                row.seconds += seconds_since(t1);
                row.probe = score_at_probes(cells, g.radiosity, probes, g.point_radiosity);
                if (!g_interrupted.load()) rows.push_back(std::move(row));
            }
            if (g_interrupted.load()) break;
        }
        if (g_interrupted.load()) break;
    }
    // The receiver-only refinement `solve --adaptive` ran before it became the hierarchical solver
    // refining on power, kept to compare.
    for (const double target : c.targets) {
        if (!wanted("receiver") || g_interrupted.load()) break;
        std::ostringstream setting;
        setting << "target " << target;
        starting("receiver " + setting.str());
        AdaptiveOptions t = a;
        t.target_error = target;
        const AdaptiveSolution s = solve_adaptive(P, *visibility, t);
        add_row("receiver", setting.str(), 0, s.result.seconds, vs_fine(s.tree, s.leaves, s.result.radiosity),
                s.tree.conforming_mesh(s.leaves), s.result.radiosity);
    }
    // Hierarchical radiosity over the same coarse patches as the elements above (clustered),
    // each link epsilon a point of the curve, at every power epsilon ("hierarchical") and at
    // the one `solve --adaptive` adds ("adaptive"); the wall time counts refinement, solution and
    // the conforming mesh a file would show.
    struct HierarchicalRun {
        const char* family;
        double link_epsilon, power_epsilon;
    };
    std::vector<HierarchicalRun> hierarchical_runs;
    if (wanted("adaptive"))
        for (const double eps : c.link_epsilons)
            hierarchical_runs.push_back({"adaptive", eps, adaptive_power_epsilon(0.0)});
    if (wanted("hierarchical"))
        for (const double eps : c.link_epsilons)
            for (const double power_eps : c.power_epsilons)
                hierarchical_runs.push_back({"hierarchical", eps, power_eps});
    for (const auto& [family, eps, power_eps] : hierarchical_runs) {
        if (g_interrupted.load()) break;
        {
            std::ostringstream what;
            what << family << " link epsilon " << eps;
            if (power_eps > 0) what << " power epsilon " << power_eps;
            starting(what.str());
        }
        const auto t0 = std::chrono::steady_clock::now();
        HierarchicalOptions h;
        h.form_factors = c.ff;
        h.link_epsilon = eps;
        h.power_epsilon = power_eps;
        h.max_level = c.max_level;
        h.refine_rounds = c.refine_rounds;
        h.cancel = &g_interrupted;
        const HierarchicalSolution s = solve_hierarchical(P, *visibility, h);
        const PatchMesh elements = s.tree.conforming_mesh(s.leaves);
        const double solve_seconds = seconds_since(t0);
        const double fine = vs_fine(s.tree, s.leaves, s.result.radiosity);
        // One solve, a row per display tolerance: each its solve's time plus its own gather's,
        // through the links; the elements tile the coarse patches, whose visibility is theirs.
        // "adaptive" rows gather as solve --adaptive does; "hierarchical" rows at each tolerance.
        const std::vector<double> displays =
            std::string(family) == "adaptive"
                ? std::vector<double>{c.gather == "vertices" ? adaptive_display_tolerance(std::nullopt) : 0.0}
                : c.display_tolerances;
        for (const double display : displays) {
            if (g_interrupted.load()) break;
            std::ostringstream setting;
            setting << "link epsilon " << eps;
            if (power_eps > 0) setting << " power epsilon " << power_eps;
            if (display > 0) setting << " display " << display;
            // (The elements column stays the solve's; display refinement adds cells.)
            Row r{family, setting.str(), s.leaves.size(), s.links.size(), solve_seconds, fine, {}, false};
            SolveResult g;
            g.radiosity = s.result.radiosity;
            g.irradiance = s.result.irradiance;
            if (display > 0) {  // a copy to refine, the solve kept for the next tolerance
                HierarchicalSolution shown = s;
                PatchMesh cells = elements;
                if (c.gather != "none")
                    r.gathered =
                        gather_point_values(shown, cells, *visibility, g, "vertices", DisplayRefinement{display}, true);
                r.probe = score_at_probes(cells, g.radiosity, probes, g.point_radiosity);
            } else {
                if (c.gather != "none") r.gathered = gather_point_values(s, elements, *visibility, g, "vertices", true);
                r.probe = score_at_probes(elements, g.radiosity, probes, g.point_radiosity);
            }
            r.seconds += g.seconds;
            if (!g_interrupted.load()) rows.push_back(std::move(r));
        }
        ++runs_done;
    }
    progress.finish();
    std::ostringstream csv;
    csv << "method,setting,elements,links,seconds,rms_error," << probe_columns() << ",point_data\n";
    for (const auto& r : rows) {
        csv << r.method << "," << r.setting << "," << r.elements << "," << r.links << "," << r.seconds << ",";
        if (r.rms >= 0) csv << r.rms;
        csv << "," << probe_fields(r.probe, classes) << "," << (r.gathered ? "gathered" : "averaged") << "\n";
    }
    const std::filesystem::path dir = c.out;
    write_text_file(
        dir / "meshes.csv", [&](std::ostream& out) { out << csv.str(); }, "mesh comparison");
    if (interrupted_exit_code()) {
        std::cerr << "bounce: interrupted; wrote the " << rows.size() << " run" << (rows.size() == 1 ? "" : "s")
                  << " done of " << total_runs << " to " << (dir / "meshes.csv").string() << " (no charts)\n";
        return interrupted_exit_code();
    }
    // The error map: every probe's error for the uniform patch mesh nearest the default size.
    const Row* map_row = nullptr;
    for (const auto& r : rows)
        if (r.method == "patches" && (!map_row || std::abs(std::log(double(r.elements) / 2000.0)) <
                                                      std::abs(std::log(double(map_row->elements) / 2000.0))))
            map_row = &r;
    if (map_row) {
        write_text_file(
            dir / "probe_errors.csv",
            [&](std::ostream& out) {
                out << "x,y,z,nx,ny,nz,surface,reference_luminance,patch_error,smooth_error,mesh\n";
                out.precision(9);
                for (std::size_t k = 0; k < probes.size(); ++k) {
                    const auto& q = probes[k];
                    const double pe = map_row->probe.patch_error[k], se = map_row->probe.smooth_error[k];
                    if (std::isnan(pe)) continue;
                    out << q.position.x << ',' << q.position.y << ',' << q.position.z << ',' << q.normal.x << ','
                        << q.normal.y << ',' << q.normal.z << ",\"" << q.surface << "\"," << q.radiosity.luminance()
                        << ',' << pe << ',' << se << ",\"" << map_row->setting << " (" << map_row->elements
                        << " patches)\"\n";
                }
            },
            "probe errors");
        write_text_file(
            dir / "outline.csv",
            [&](std::ostream& out) {
                out << "surface,x,y,z\n";
                out.precision(9);
                for (std::size_t f = 0; f < scene.surfaces.size(); ++f)
                    for (const auto& v : scene.surfaces[f].vertices)
                        out << f << ',' << v.x << ',' << v.y << ',' << v.z << '\n';
            },
            "scene outline");
    }
    write_mesh_charts(dir);
    if (!o.quiet) {
        const std::string vs_fine_text = reference
                                             ? "RMS error of the reflected radiosity against " +
                                                   std::to_string(reference->leaves.size()) + " uniform elements"
                                             : "empty, no fine uniform elements to compare with (--reference-level 0)";
        std::printf(
            "%zu patches shoot to the elements; \"vs fine\": %s; \"probe\": relative RMS luminance error at %zu "
            "path-traced probes (their own noise %.2f%%); seconds: the whole run, form factors, solve and gather; "
            "\"points\": the point data gathered, or averaged from the patches (beyond the gather's budget, or "
            "--gather none)\n",
            P.size(), vs_fine_text.c_str(), rows.empty() ? std::size_t(0) : rows.front().probe.scored,
            rows.empty() ? 0.0 : 100 * rows.front().probe.reference_noise);
        // The setting column as wide as its longest entry ("link epsilon 0.1 power epsilon 1e-05").
        int width = 18;
        for (const auto& r : rows) width = std::max(width, int(r.setting.size()));
        std::printf("%-13s %-*s %9s %10s %9s %9s %11s %12s %11s %16s %16s %9s\n", "method", width, "setting",
                    "elements", "links", "seconds", "vs fine", "probe patch", "probe smooth", "worst", "penumbra",
                    "contact", "points");
        for (const auto& r : rows)
            std::printf("%-13s %-*s %9zu %10s %9.3f %9s %10.2f%% %11.2f%% %10.1f%% %16s %16s %9s\n", r.method.c_str(),
                        width, r.setting.c_str(), r.elements, r.links ? std::to_string(r.links).c_str() : "-",
                        r.seconds, r.rms >= 0 ? std::to_string(r.rms).substr(0, 6).c_str() : "-",
                        100 * r.probe.rms_patch, 100 * r.probe.rms_smooth, 100 * r.probe.max_smooth,
                        class_text(r.probe, classes, ProbeClass::penumbra).c_str(),
                        class_text(r.probe, classes, ProbeClass::contact).c_str(),
                        r.gathered ? "gathered" : "averaged");
        print_class_counts(classes);
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
