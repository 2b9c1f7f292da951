// SPDX-License-Identifier: MIT
// bounce compare --meshes: uniform element meshes of several sizes, uniform and discontinuity
// patch meshes, the receiver-only refinement at several targets, and hierarchical radiosity
// (without and, as `solve --adaptive`, with the power bound) at several link epsilons, each
// scored at the path-traced probes (and, but for hierarchical, against fine uniform elements
// over the same patches); meshes.csv, meshes.png and a table.
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
#include "app/point_values.h"
#include "app/progress_line.h"
#include "app/reference_points.h"
#include "app/signals.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/errors.h"
#include "mesh/scene/input_error.h"
#include "mesh/scene/specular_occluders.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/pipeline/solve_scene.h"
#include "solver/reference/probe_classes.h"
#include "solver/reference/probe_score.h"
#include "solver/refinement/adaptive_radiosity.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"
#include "viewer/charts.h"
#include "viewer/pending_output.h"

namespace bounce::app {
namespace {

struct Row {
    std::string method, setting;
    std::size_t elements = 0, links = 0;
    double seconds = 0.0, rms = -1.0;  // rms: against the fine uniform elements (-1: not comparable)
    ProbeScore probe;
    bool gathered = false;  // point data gathered (else averaged: beyond the gather's budget, or --gather none)
};

/// One --meshes run: the coarse patches every element method starts from, the probes, and the
/// rows as the runs add them. A run cut short by a signal keeps no row (the rows done are
/// written).
class MeshComparison {
public:
    MeshComparison(const CommonOptions& o, const CompareCommand& c);
    int run();

private:
    void run_uniform_elements();
    void run_patch_meshes();
    void run_receiver();
    void run_hierarchical();
    void run_hierarchical_one(const char* family, double eps, double power_eps);
    int write_files() const;
    void write_error_map() const;
    void print_table() const;

    bool wanted(const char* method) const {
        return std::find(m_c.mesh_methods.begin(), m_c.mesh_methods.end(), method) != m_c.mesh_methods.end();
    }
    std::size_t total_runs() const;
    void starting(const std::string& what) { m_progress.runs("compare --meshes", m_runs_done, m_total_runs, what); }
    ProbeScore score_mesh(const PatchMesh& m, const std::vector<Rgb>& B, double& seconds, bool& gathered,
                          double display = 0.0) const;
    void add_row(std::string method, std::string setting, std::size_t links, double seconds, double rms,
                 const PatchMesh& m, const std::vector<Rgb>& B, double display = 0.0);
    /// RMS against the fine uniform elements ("vs fine"; -1 without them, --reference-level 0).
    double vs_fine(const ElementTree& tree, const std::vector<std::uint32_t>& leaves, const std::vector<Rgb>& B) const {
        return m_reference ? rms_difference(tree, leaves, B, *m_reference) : -1.0;
    }

    const CommonOptions& m_o;
    const CompareCommand& m_c;
    Scene m_scene;
    PatchMesh m_mesh;
    std::unique_ptr<Visibility> m_visibility;
    AdaptiveOptions m_adaptive;
    std::vector<ReferencePoint> m_probes;
    std::vector<ProbeClass> m_classes;
    std::vector<Row> m_rows;
    ProgressLine m_progress;
    std::size_t m_runs_done = 0, m_total_runs = 0;
    std::optional<AdaptiveSolution> m_reference;
};

/// The coarse patches `solve --adaptive` and hierarchical start from (kCoarseTargetPatches).
CommonOptions coarse_roots(const CommonOptions& o) {
    CommonOptions roots = o;
    if (default_meshing(o)) roots.meshing.target_patches = kCoarseTargetPatches;
    return roots;
}

MeshComparison::MeshComparison(const CommonOptions& o, const CompareCommand& c)
    : m_o(o), m_c(c), m_mesh(load_and_mesh(coarse_roots(o), o.scene, m_scene)), m_progress(!o.quiet) {
    const auto& P = m_mesh.patches();
    m_visibility = make_visibility(o.visibility, P, specular_occluders(m_scene));
    m_adaptive.form_factors = c.ff;
    m_adaptive.max_elements = 200000;
    m_adaptive.cancel = &g_interrupted;
    const double per_level = 4.0;
    if (c.reference_level > 0)
        check_memory(o, "the reference elements' form-factor rows",
                     double(P.size()) * std::pow(per_level, c.reference_level) * double(P.size()) * 4.0 * 2.0);
    // The truth every row is scored on: path-traced probes, computed once and cached.
    m_probes = reference_for_compare(m_scene, c.reference, c.out, o.quiet);
    m_classes = probe_classes(m_scene, m_probes);
    m_total_runs = total_runs();
}

std::size_t MeshComparison::total_runs() const {
    const CompareCommand& c = m_c;
    return (c.reference_level > 0 ? 1 : 0) + (wanted("uniform") ? std::size_t(c.reference_level) : 0) +
           (wanted("patches") ? c.patch_counts.size() * c.display_tolerances.size() : 0) +
           (wanted("discontinuity") ? c.patch_counts.size() * c.display_tolerances.size() : 0) +
           (wanted("receiver") ? c.targets.size() : 0) + (wanted("adaptive") ? c.link_epsilons.size() : 0) +
           (wanted("hierarchical") ? c.link_epsilons.size() * c.power_epsilons.size() : 0);
}

/// Scores a solution as solve would write it: point data gathered (the time added to the row's
/// seconds) when the mesh is within the gather's budget. (A hierarchical solution gathers
/// through its links, run_hierarchical_one, and weighs its own budget from the lists it builds.)
ProbeScore MeshComparison::score_mesh(const PatchMesh& m, const std::vector<Rgb>& B, double& seconds, bool& gathered,
                                      double display) const {
    SolveResult r;
    r.radiosity = B;
    gathered = false;
    std::optional<PatchMesh> cells;  // with display refinement (solve --display-tolerance): its cells
    if (m_c.gather != "none" && double(m.mesh().n_vertices()) * double(m.size()) <= kMaxGatherPairs) {
        const auto t0 = std::chrono::steady_clock::now();  // the gather's visibility counted too
        const auto v = make_visibility(m_o.visibility, m.patches(), specular_occluders(m_scene));
        if (display > 0)
            gathered = gather_point_values(cells.emplace(m), *v, r, "vertices", PatchDisplayRefinement{display}, true);
        else
            gathered = gather_point_values(m, *v, r, "vertices", true);
        seconds += seconds_since(t0);
    }
    return score_at_probes(cells ? *cells : m, r.radiosity, m_probes, r.point_radiosity);
}

void MeshComparison::add_row(std::string method, std::string setting, std::size_t links, double seconds, double rms,
                             const PatchMesh& m, const std::vector<Rgb>& B, double display) {
    ++m_runs_done;
    if (g_interrupted.load()) return;
    Row r{std::move(method), std::move(setting), m.size(), links, seconds, rms, {}, false};
    r.probe = score_mesh(m, B, r.seconds, r.gathered, display);
    if (!g_interrupted.load()) m_rows.push_back(std::move(r));
}

/// The fine uniform elements ("vs fine"; --reference-level 0 skips them: a large scene's fine
/// elements would need patches x elements form factors), then the coarser uniform levels.
void MeshComparison::run_uniform_elements() {
    const auto& P = m_mesh.patches();
    const int level = m_c.reference_level;
    if (level > 0) {
        starting("reference, uniform level " + std::to_string(level));
        m_reference = solve_uniform_elements(P, *m_visibility, level, m_adaptive);
        add_row("reference", "uniform level " + std::to_string(level), 0, m_reference->result.seconds, 0.0,
                m_reference->tree.conforming_mesh(m_reference->leaves), m_reference->result.radiosity);
    }
    for (int l = 0; l < level && wanted("uniform") && !g_interrupted.load(); ++l) {
        starting("uniform level " + std::to_string(l));
        const AdaptiveSolution u = solve_uniform_elements(P, *m_visibility, l, m_adaptive);
        add_row("uniform", "level " + std::to_string(l), 0, u.result.seconds,
                vs_fine(u.tree, u.leaves, u.result.radiosity), u.tree.conforming_mesh(u.leaves), u.result.radiosity);
    }
}

/// Uniform patch meshes solved by the default path (every patch shoots), as `solve --patches N`
/// runs, and the same area limits with --meshing discontinuity (the meshing's time counted in
/// the row's).
void MeshComparison::run_patch_meshes() {
    for (const auto kind : {MeshingOptions::Kind::uniform, MeshingOptions::Kind::discontinuity}) {
        const char* family = kind == MeshingOptions::Kind::uniform ? "patches" : "discontinuity";
        if (!wanted(family)) continue;
        for (const std::size_t n : m_c.patch_counts) {
            if (g_interrupted.load()) return;
            starting(std::string(family) + " --patches " + std::to_string(n));
            const auto t0 = std::chrono::steady_clock::now();
            MeshingOptions m = m_o.meshing;
            m.kind = kind;
            m.target_patches = n;
            m.max_area = m.max_edge = 0;
            // As `solve --patches N` runs it, from the one pipeline; the point data are compare's.
            SolveRequest request;
            request.meshing = m;
            request.visibility = m_o.visibility;
            request.form_factors = m_c.ff;
            request.tolerance = m_c.options.tolerance;  // --tolerance, as solve's
            request.gather = GatherMode::none;
            SolveHooks hooks;
            hooks.cancel = &g_interrupted;
            std::optional<SolvedScene> solved_scene;
            try {
                solved_scene = solve_scene(m_scene, request, hooks);
            } catch (const Interrupted&) {
                return;  // stopped before the solve (open parts, form factors): no row
            }
            const PatchMesh& um = *solved_scene->mesh;
            const SolveResult& r = solved_scene->result;
            const double solved = seconds_since(t0);
            for (const double display : m_c.display_tolerances) {
                // A display row needs gathered point data to refine; without, it is not made.
                if (display > 0 && m_c.gather == "none") {
                    ++m_runs_done;
                    continue;
                }
                std::ostringstream setting;
                setting << "--patches " << n;
                if (display > 0) setting << " display " << display;
                add_row(family, setting.str(), 0, solved, -1.0, um, r.radiosity, display);
                if (g_interrupted.load()) return;
            }
        }
    }
}

/// The receiver-only refinement `solve --adaptive` ran before it became the hierarchical solver
/// refining on power, kept to compare.
void MeshComparison::run_receiver() {
    for (const double target : m_c.targets) {
        if (!wanted("receiver") || g_interrupted.load()) break;
        std::ostringstream setting;
        setting << "target " << target;
        starting("receiver " + setting.str());
        AdaptiveOptions t = m_adaptive;
        t.target_error = target;
        const AdaptiveSolution s = solve_adaptive(m_mesh.patches(), *m_visibility, t);
        add_row("receiver", setting.str(), 0, s.result.seconds, vs_fine(s.tree, s.leaves, s.result.radiosity),
                s.tree.conforming_mesh(s.leaves), s.result.radiosity);
    }
}

/// Hierarchical radiosity over the same coarse patches as the elements above (clustered), each
/// link epsilon a point of the curve, at every power epsilon ("hierarchical") and at the one
/// `solve --adaptive` adds ("adaptive").
void MeshComparison::run_hierarchical() {
    struct HierarchicalRun {
        const char* family;
        double link_epsilon, power_epsilon;
    };
    std::vector<HierarchicalRun> runs;
    if (wanted("adaptive"))
        for (const double eps : m_c.link_epsilons) runs.push_back({"adaptive", eps, adaptive_power_epsilon(0.0)});
    if (wanted("hierarchical"))
        for (const double eps : m_c.link_epsilons)
            for (const double power_eps : m_c.power_epsilons) runs.push_back({"hierarchical", eps, power_eps});
    for (const auto& [family, eps, power_eps] : runs) {
        if (g_interrupted.load()) break;
        run_hierarchical_one(family, eps, power_eps);
        ++m_runs_done;
    }
}

/// One hierarchical solve, a row per display tolerance: the wall time counts refinement,
/// solution and the conforming mesh a file would show, plus each row's own gather.
void MeshComparison::run_hierarchical_one(const char* family, double eps, double power_eps) {
    {
        std::ostringstream what;
        what << family << " link epsilon " << eps;
        if (power_eps > 0) what << " power epsilon " << power_eps;
        starting(what.str());
    }
    const auto t0 = std::chrono::steady_clock::now();
    HierarchicalOptions h;
    h.form_factors = m_c.ff;
    h.link_epsilon = eps;
    h.power_epsilon = power_eps;
    h.max_level = m_c.max_level;
    h.refine_rounds = m_c.refine_rounds;
    h.covered = m_scene.covered;
    h.cancel = &g_interrupted;
    const HierarchicalSolution s = solve_hierarchical(m_mesh.patches(), *m_visibility, h);
    const PatchMesh elements = s.tree.conforming_mesh(s.leaves);
    const double solve_seconds = seconds_since(t0);
    const double fine = vs_fine(s.tree, s.leaves, s.result.radiosity);
    // Each row gathers through the links; the elements tile the coarse patches, whose
    // visibility is theirs. "adaptive" rows gather as solve --adaptive does; "hierarchical"
    // rows at each tolerance.
    const std::vector<double> displays =
        std::string(family) == "adaptive"
            ? std::vector<double>{m_c.gather == "vertices" ? adaptive_display_tolerance(std::nullopt) : 0.0}
            : m_c.display_tolerances;
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
            if (m_c.gather != "none")
                r.gathered =
                    gather_point_values(shown, cells, *m_visibility, g, "vertices", DisplayRefinement{display}, true);
            r.probe = score_at_probes(cells, g.radiosity, m_probes, g.point_radiosity);
        } else {
            if (m_c.gather != "none") r.gathered = gather_point_values(s, elements, *m_visibility, g, "vertices", true);
            r.probe = score_at_probes(elements, g.radiosity, m_probes, g.point_radiosity);
        }
        r.seconds += g.seconds;
        if (!g_interrupted.load()) m_rows.push_back(std::move(r));
    }
}

int MeshComparison::run() {
    run_uniform_elements();
    run_patch_meshes();
    run_receiver();
    run_hierarchical();
    m_progress.finish();
    if (const int code = write_files()) return code;
    print_table();
    return 0;
}

/// meshes.csv; unless interrupted, the error map and the charts.
int MeshComparison::write_files() const {
    std::ostringstream csv;
    csv << "method,setting,elements,links,seconds,rms_error," << probe_columns() << ",point_data\n";
    for (const auto& r : m_rows) {
        csv << r.method << "," << r.setting << "," << r.elements << "," << r.links << "," << r.seconds << ",";
        if (r.rms >= 0) csv << r.rms;
        csv << "," << probe_fields(r.probe, m_classes) << "," << (r.gathered ? "gathered" : "averaged") << "\n";
    }
    const std::filesystem::path dir = m_c.out;
    write_text_file(
        dir / "meshes.csv", [&](std::ostream& out) { out << csv.str(); }, "mesh comparison");
    if (interrupted_exit_code()) {
        std::cerr << "bounce: interrupted; wrote the " << m_rows.size() << " run" << (m_rows.size() == 1 ? "" : "s")
                  << " done of " << m_total_runs << " to " << (dir / "meshes.csv").string() << " (no charts)\n";
        return interrupted_exit_code();
    }
    write_error_map();
    write_mesh_charts(dir);
    return 0;
}

/// The error map: every probe's error for the uniform patch mesh nearest the default size, or
/// without one for the first run (an adaptive or hierarchical comparison's worst probes).
void MeshComparison::write_error_map() const {
    const Row* map_row = nullptr;
    for (const auto& r : m_rows)
        if (r.method == "patches" && (!map_row || std::abs(std::log(double(r.elements) / 2000.0)) <
                                                      std::abs(std::log(double(map_row->elements) / 2000.0))))
            map_row = &r;
    if (!map_row && !m_rows.empty()) map_row = &m_rows.front();
    if (!map_row || map_row->probe.patch_error.size() != m_probes.size()) return;
    const std::filesystem::path dir = m_c.out;
    write_text_file(
        dir / "probe_errors.csv",
        [&](std::ostream& out) {
            out << "x,y,z,nx,ny,nz,surface,reference_luminance,patch_error,smooth_error,mesh\n";
            out.precision(9);
            for (std::size_t k = 0; k < m_probes.size(); ++k) {
                const auto& q = m_probes[k];
                const double pe = map_row->probe.patch_error[k], se = map_row->probe.smooth_error[k];
                if (std::isnan(pe)) continue;
                out << q.position.x << ',' << q.position.y << ',' << q.position.z << ',' << q.normal.x << ','
                    << q.normal.y << ',' << q.normal.z << ",\"" << q.surface << "\"," << q.radiosity.luminance() << ','
                    << pe << ',' << se << ",\"" << map_row->setting << " (" << map_row->elements << " patches)\"\n";
            }
        },
        "probe errors");
    write_text_file(
        dir / "outline.csv",
        [&](std::ostream& out) {
            out << "surface,x,y,z\n";
            out.precision(9);
            for (std::size_t f = 0; f < m_scene.surfaces.size(); ++f)
                for (const auto& v : m_scene.surfaces[f].vertices)
                    out << f << ',' << v.x << ',' << v.y << ',' << v.z << '\n';
        },
        "scene outline");
}

void MeshComparison::print_table() const {
    if (m_o.quiet) return;
    const std::string vs_fine_text = m_reference
                                         ? "RMS error of the reflected radiosity against " +
                                               std::to_string(m_reference->leaves.size()) + " uniform elements"
                                         : "empty, no fine uniform elements to compare with (--reference-level 0)";
    std::printf(
        "%zu patches shoot to the elements; \"vs fine\": %s; \"probe\": relative RMS luminance error at %zu "
        "path-traced probes (their own noise %.2f%%); seconds: the whole run, form factors, solve and gather; "
        "\"points\": the point data gathered, or averaged from the patches (beyond the gather's budget, or "
        "--gather none)\n",
        m_mesh.size(), vs_fine_text.c_str(), m_rows.empty() ? std::size_t(0) : m_rows.front().probe.scored,
        m_rows.empty() ? 0.0 : 100 * m_rows.front().probe.reference_noise);
    // The setting column as wide as its longest entry ("link epsilon 0.1 power epsilon 1e-05").
    int width = 18;
    for (const auto& r : m_rows) width = std::max(width, int(r.setting.size()));
    std::printf("%-13s %-*s %9s %10s %9s %9s %11s %12s %11s %16s %16s %9s\n", "method", width, "setting", "elements",
                "links", "seconds", "vs fine", "probe patch", "probe smooth", "worst", "penumbra", "contact", "points");
    for (const auto& r : m_rows)
        std::printf("%-13s %-*s %9zu %10s %9.3f %9s %10.2f%% %11.2f%% %10.1f%% %16s %16s %9s\n", r.method.c_str(),
                    width, r.setting.c_str(), r.elements, r.links ? std::to_string(r.links).c_str() : "-", r.seconds,
                    r.rms >= 0 ? std::to_string(r.rms).substr(0, 6).c_str() : "-", 100 * r.probe.rms_patch,
                    100 * r.probe.rms_smooth, 100 * r.probe.max_smooth,
                    class_text(r.probe, m_classes, ProbeClass::penumbra).c_str(),
                    class_text(r.probe, m_classes, ProbeClass::contact).c_str(), r.gathered ? "gathered" : "averaged");
    print_class_counts(m_classes);
    std::cout << "wrote " << (std::filesystem::path(m_c.out) / "meshes.csv").string() << " and meshes.png\n";
}

}  // namespace

int run_compare_meshes(const CommonOptions& o, const CompareCommand& c) {
    std::error_code ec;
    std::filesystem::create_directories(c.out, ec);
    if (!std::filesystem::is_directory(c.out)) throw InputError(c.out + ": cannot create the output directory");
    return MeshComparison(o, c).run();
}

}  // namespace bounce::app
