// SPDX-License-Identifier: MIT
// The `bounce` command line: thin over the mesh, solver and viewer libraries.
#include <unistd.h>

#include <atomic>
#include <csignal>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <sstream>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "mesh/input_error.h"
#include "mesh/patch_mesh.h"
#include "mesh/scene_loader.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/linear/convergence.h"
#include "solver/linear/gathering_solver.h"
#include "solver/linear/shooting_solver.h"
#include "solver/linear/solver.h"
#include "solver/refinement/adaptive_radiosity.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"
#include "viewer/charts.h"
#include "viewer/pending_output.h"
#include "viewer/renderer.h"
#include "viewer/series_writer.h"
#include "viewer/version.h"
#include "viewer/vtu_writer.h"

namespace {

using namespace bounce;

// SIGINT/SIGTERM: the first asks the running work to stop (the solution so far is written,
// marked not converged); a second exits at once, removing the temporary file being written.
std::atomic<bool> g_interrupted{false};
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_signal(int sig) {
    if (g_signal != 0) {
        if (const char* p = pending_output()) ::unlink(p);
        ::_exit(128 + sig);
    }
    g_signal = sig;
    g_interrupted.store(true);
}

void install_signal_handlers() {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

int interrupted_exit_code() { return g_signal ? 128 + int(g_signal) : 0; }

/// "> 0", with a readable message (CLI11's PositiveNumber prints the whole double range).
const CLI::Validator kPositive(
    [](std::string& v) {
        try {
            std::size_t used = 0;
            const double x = std::stod(v, &used);
            if (used == v.size() && std::isfinite(x) && x > 0) return std::string();
        } catch (const std::exception&) {
        }
        return "must be a number > 0, got '" + v + "'";
    },
    "> 0");

void print_warnings(const Scene& scene, bool quiet) {
    if (quiet) return;
    for (const auto& w : scene.warnings) std::cerr << "warning: " << w << "\n";
}

struct CommonOptions {
    std::string scene = "cornell";
    MeshingOptions meshing;
    bool quiet = false;
    bool strict = false;
    int threads = 0;
    std::string visibility = visibility_backends().front();
    std::size_t max_memory_mb = 16384;
};

// Memory estimates, checked before the allocation they stand for.
constexpr std::size_t kBytesPerPatch = 1024;  // Patch, OpenMesh face and vertices, AABB triangles, solver vectors

/// Loads and meshes with the limits of --max-memory and --strict applied.
PatchMesh load_and_mesh(const CommonOptions& o, const std::string& spec, Scene& scene) {
    scene = load_scene(spec);
    if (o.strict && !scene.warnings.empty()) throw InputError(scene.warnings.front() + " (--strict)");
    print_warnings(scene, o.quiet);
    MeshingOptions m = o.meshing;
    m.max_patches = std::min(m.max_patches, (o.max_memory_mb << 20) / kBytesPerPatch);
    return PatchMesh(scene, m);
}

/// True when the user gave no meshing (no --max-area, --max-edge or --patches): the element
/// methods then start from coarser patches of their own.
bool default_meshing(const CommonOptions& o) {
    return o.meshing.max_area == 0 && o.meshing.max_edge == 0 &&
           o.meshing.target_patches == MeshingOptions{}.target_patches;
}

/// Refuses work whose estimate exceeds --max-memory, naming the estimate.
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

void add_meshing_options_no_scene(CLI::App* cmd, CommonOptions& o);

void add_meshing_options(CLI::App* cmd, CommonOptions& o) {
    cmd->add_option("scene", o.scene, "'cornell' (built-in, default), a .obj or a .json scene");
    add_meshing_options_no_scene(cmd, o);
}

void add_meshing_options_no_scene(CLI::App* cmd, CommonOptions& o) {
    cmd->add_option("--max-area", o.meshing.max_area,
                    "largest patch area (scene units^2); default: total area / 2000")
        ->check(kPositive);
    cmd->add_option("--max-edge", o.meshing.max_edge, "longest patch edge (scene units)")
        ->check(kPositive);
    cmd->add_option("--patches", o.meshing.target_patches,
                    "about this many patches when neither --max-area nor --max-edge is given (2000)")
        ->check(CLI::Range(std::size_t(1), std::size_t(100000000)));
    cmd->add_option("--max-memory", o.max_memory_mb, "refuse work estimated above this many MB (16384)")
        ->check(kPositive);
    cmd->add_flag("--strict", o.strict, "treat every warning about the input (materials, degenerate, non-planar or crossing faces) as an error");
    cmd->add_flag("--no-subdivide", [&o](std::int64_t) { o.meshing.subdivide = false; },
                  "one patch per input face");
    cmd->add_flag("-q,--quiet", o.quiet, "no progress line, no warnings");
    cmd->add_option("--threads", o.threads, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
    cmd->add_option("--visibility", o.visibility, "visibility backend for shadow rays (default: embree)")
        ->check(CLI::IsMember(visibility_backends()));
}

void add_form_factor_options(CLI::App* cmd, FormFactorOptions& f) {
    cmd->add_option("--rays", f.visibility_rays, "visibility rays per patch pair (raycast)")->check(CLI::Range(1, 4096));
    cmd->add_option("--receiver-samples", f.receiver_samples,
                    "points per side of each receiver (raycast); 0: adaptive")
        ->check(CLI::Range(0, 16));
    cmd->add_option("--hemicube-res", f.hemicube_resolution, "hemicube pixels per side (even)")
        ->check(CLI::Range(2, 4096));
    cmd->add_flag("--hemicube-jitter", f.hemicube_jitter, "rotate each hemicube randomly about the normal");
    cmd->add_option("--seed", f.seed, "seed of the rays and rotations");
}


/// A one-line progress display on a terminal, at most five updates a second.
class ProgressLine {
public:
    explicit ProgressLine(bool enabled, std::string step = "shot", std::string measure = "unshot")
        : m_enabled(enabled && ::isatty(STDERR_FILENO)), m_step(std::move(step)), m_measure(std::move(measure)) {}
    ~ProgressLine() { finish(); }
    void update(const SolveProgress& p) {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_enabled || p.seconds - m_last < 0.2) return;
        m_last = p.seconds;
        std::fprintf(stderr, "\r%s %zu, %s %.2e (target %.1e), %.1f s   ", m_step.c_str(), p.step, m_measure.c_str(),
                     p.unshot_fraction, p.tolerance, p.seconds);
        m_shown = true;
    }
    /// Rows of a form-factor matrix; called from worker threads.
    void rows(std::size_t done, std::size_t total) {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_enabled) return;
        const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
        if (now - m_last < 0.2 && done < total) return;
        m_last = now;
        std::fprintf(stderr, "\rform factors: %zu / %zu rows, %.1f s   ", done, total, now);
        m_shown = true;
    }
    void finish() {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_last = 0.0;
        m_start = std::chrono::steady_clock::now();
        if (m_shown) std::fputc('\n', stderr);
        m_shown = false;
    }

private:
    bool m_enabled;
    std::string m_step, m_measure;
    bool m_shown = false;
    double m_last = 0.0;
    std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now();
    std::mutex m_mutex;
};

std::string default_output(const std::string& scene) {
    if (scene == "cornell") return "cornell.vtu";
    return std::filesystem::path(scene).stem().string() + ".vtu";
}

int run_info(const CommonOptions& o) {
    Scene scene;
    PatchMesh mesh = load_and_mesh(o, o.scene, scene);
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
    std::string solver = "shooting";
    SolverOptions options;
    std::string method = "raycast";
    FormFactorOptions ff;
    std::size_t max_matrix_mb = 2048;
    std::string log_csv;
    bool ascii = false;
    std::string png;
    std::size_t series = 0;
    RenderOptions render;
    int element_split = 1;
    bool adaptive = false;
    AdaptiveOptions adaptive_options;
    HierarchicalOptions hierarchical;
};

/// Writes a convergence log as CSV: step,seconds,residual,unshot_fraction,rms_error,max_error
/// (empty where a quantity was not computed), through a temporary file.
void write_log_csv(const std::filesystem::path& path, const std::vector<SolveResult>& runs,
                   const std::vector<std::string>& form_factors, const std::vector<double>& ff_seconds) {
    write_text_file(path, [&](std::ostream& out) {
        out << "form_factors,solver,step,seconds,form_factor_seconds,residual,unshot_fraction,rms_error,max_error,"
               "ambient_rms_error\n";
        out.precision(10);
        auto opt = [&](double v) {
            if (v < 0) return std::string();
            std::ostringstream t;
            t.precision(10);
            t << v;
            return t.str();
        };
        for (std::size_t k = 0; k < runs.size(); ++k)
            for (const auto& r : runs[k].log)
                out << form_factors[k] << ',' << runs[k].solver << ',' << r.step << ',' << r.seconds << ','
                    << ff_seconds[k] << ',' << opt(r.residual) << ',' << opt(r.unshot_fraction) << ','
                    << opt(r.rms_error) << ',' << opt(r.max_error) << ',' << opt(r.ambient_rms_error) << '\n';
    }, "convergence log");
}

struct FormFactorCommand {
    std::string output;
    std::string method = "raycast";
    FormFactorOptions ff;
    bool check = false;
    std::size_t max_matrix_mb = 2048;
};

/// Builds the whole matrix, writes "i,j,F_ij,row_sum_i" for its non-zero entries and, with
/// --check, prints row sums and the reciprocity error max |A_i F_ij - A_j F_ji| / (A_i F_ij).
int run_form_factors(const CommonOptions& o, const FormFactorCommand& c) {
    Scene scene;
    PatchMesh mesh = load_and_mesh(o, o.scene, scene);
    const auto& P = mesh.patches();
    const std::size_t n = P.size();
    check_form_factor_memory(o, c.method, c.ff);
    check_memory(o, "the form-factor matrix (" + std::to_string(n) + " patches)", double(n) * double(n) * 4);
    const auto visibility = make_visibility(o.visibility, P);
    const auto ff = make_form_factor_estimator(c.method, P, visibility.get(), c.ff);
    ProgressLine progress(!o.quiet);
    const auto F = FormFactorMatrix::build(*ff, n, c.max_matrix_mb << 20,
                                           [&](std::size_t d, std::size_t t) { progress.rows(d, t); }, &g_interrupted);
    progress.finish();
    std::vector<double> sums(n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) sums[i] += F(i, j);
    if (!c.output.empty()) {
        write_text_file(c.output, [&](std::ostream& csv) {
            csv << "i,j,F_ij,row_sum_i\n";
            csv.precision(9);
            for (std::size_t i = 0; i < n; ++i)
                for (std::size_t j = 0; j < n; ++j)
                    if (F(i, j) != 0.0f) csv << i << ',' << j << ',' << F(i, j) << ',' << sums[i] << '\n';
        }, "form-factor CSV");
    }
    if (!o.quiet || c.check) {
        std::cout << "patches " << n << ", method " << c.method << ", " << F.seconds() << " s ("
                  << 1e3 * F.seconds() / double(std::max<std::size_t>(n, 1)) << " ms per row)\n";
    }
    if (c.check) {
        double lo = 1e300, hi = -1e300, mean = 0, recip = 0, diff = 0, total = 0;
        for (std::size_t i = 0; i < n; ++i) {
            lo = std::min(lo, sums[i]);
            hi = std::max(hi, sums[i]);
            mean += sums[i] / double(n);
            for (std::size_t j = 0; j < n; ++j) {
                const double aij = P[i].area * F(i, j), aji = P[j].area * F(j, i);
                diff += std::abs(aij - aji);
                total += aij;
                if (F(i, j) >= 1e-3) recip = std::max(recip, std::abs(aij - aji) / aij);
            }
        }
        std::cout << "row sums: min " << lo << ", mean " << mean << ", max " << hi << "\n"
                  << "reciprocity |A_i F_ij - A_j F_ji| / (A_i F_ij): max " << recip
                  << " (over F_ij >= 1e-3); overall sum|A_i F_ij - A_j F_ji| / sum A_i F_ij = "
                  << (total > 0 ? diff / total : 0.0) << "\n";
    }
    return 0;
}

/// Refuses an unwritable destination before any work is done.
void check_output(const std::filesystem::path& out) {
    const auto dir = out.has_parent_path() ? out.parent_path() : std::filesystem::path(".");
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec))
        throw InputError(out.string() + ": output directory " + dir.string() + " does not exist");
    if (std::filesystem::is_directory(out, ec)) throw InputError(out.string() + ": is a directory");
}

/// --adaptive and --solver hierarchical: quadtree elements over the patches, exported as a
/// conforming mesh of the leaves.
int run_solve_elements(const CommonOptions& o, const SolveCommand& s, const std::filesystem::path& out) {
    if (s.element_split > 1) throw std::invalid_argument("--elements does not combine with --adaptive or hierarchical");
    if (s.method != "raycast") throw std::invalid_argument("--adaptive and hierarchical use raycast form factors");
    const bool hierarchical = s.solver == "hierarchical";
    CommonOptions roots = o;
    // Start coarse: the elements refine where the light needs it.
    if (hierarchical && default_meshing(o)) roots.meshing.subdivide = false;
    if (!hierarchical && default_meshing(o)) roots.meshing.target_patches = 150;
    Scene scene;
    const PatchMesh mesh = load_and_mesh(roots, o.scene, scene);
    const auto visibility = make_visibility(o.visibility, mesh.patches());
    ProgressLine progress(!o.quiet, "round", "estimate");
    SolveResult res;
    std::optional<PatchMesh> elements;
    std::ostringstream settings, summary;
    settings << "patches=" << mesh.size() << " rays=" << s.ff.visibility_rays << " seed=" << s.ff.seed;
    if (hierarchical) {
        HierarchicalOptions h = s.hierarchical;
        h.form_factors = s.ff;
        h.cancel = &g_interrupted;
        HierarchicalSolution sol = solve_hierarchical(mesh.patches(), *visibility, h);
        elements.emplace(sol.tree.conforming_mesh(sol.leaves));
        res = std::move(sol.result);
        const double n = double(sol.leaves.size());
        settings << " solver=hierarchical link_epsilon=" << h.link_epsilon << " link_floor=" << h.link_floor
                 << " max_level=" << h.max_level << " elements=" << sol.leaves.size() << " links=" << sol.links;
        summary << "patches " << mesh.size() << ", hierarchical: " << sol.leaves.size() << " elements, " << sol.links
                << " links (" << 100.0 * double(sol.links) / (n * n) << "% of N^2), " << res.steps << " iterations, "
                << res.seconds << " s\n";
    } else {
        AdaptiveOptions a = s.adaptive_options;
        a.form_factors = s.ff;
        a.cancel = &g_interrupted;
        a.progress = [&](std::size_t round, const AdaptiveRound& r) {
            progress.update({round, 0, r.rms_estimate, a.target_error, r.seconds});
        };
        AdaptiveSolution sol = solve_adaptive(mesh.patches(), *visibility, a);
        progress.finish();
        elements.emplace(sol.tree.conforming_mesh(sol.leaves));
        res = std::move(sol.result);
        settings << " solver=adaptive target_error=" << a.target_error << " max_patches=" << a.max_elements
                 << " elements=" << sol.leaves.size() << " rounds=" << sol.rounds.size();
        summary << "patches " << mesh.size() << ", adaptive: " << sol.leaves.size() << " elements after "
                << sol.rounds.size() << " rounds, RMS error estimate " << sol.rounds.back().rms_estimate << " (target "
                << a.target_error << "), " << res.seconds << " s\n";
        res.converged = res.converged && sol.rounds.back().rms_estimate <= a.target_error;
        if (!res.converged && res.status == "converged") res.status = "element budget reached";
    }
    write_vtu(out, *elements, res, {o.scene, settings.str()}, s.ascii);
    if (interrupted_exit_code()) {
        std::cerr << "bounce: interrupted; wrote the solution so far to " << out.string() << " (converged = 0)\n";
        return interrupted_exit_code();
    }
    if (!s.png.empty()) render_solution(*elements, res, {o.scene, settings.str()}, s.png, s.render);
    if (!o.quiet)
        std::cout << summary.str() << "wrote " << out.string() << (s.png.empty() ? "" : " and " + s.png) << "\n";
    if (!res.converged && !o.quiet) std::cerr << "bounce: not converged (" << res.status << "); the solution was written\n";
    return res.converged ? 0 : 3;
}

int run_solve(const CommonOptions& o, const SolveCommand& s) {
    const std::filesystem::path out = s.output.empty() ? default_output(o.scene) : s.output;
    check_output(out);
    if (s.adaptive || s.solver == "hierarchical") return run_solve_elements(o, s, out);
    if (!s.log_csv.empty()) check_output(s.log_csv);

    const bool elements = s.element_split > 1;
    if (elements && (s.solver != "shooting" || s.method == "hemicube"))
        throw std::invalid_argument("--elements needs the shooting solver and raycast or analytic form factors");
    CommonOptions fine = o;
    fine.meshing.element_split = s.element_split;
    Scene scene;
    PatchMesh mesh = load_and_mesh(fine, o.scene, scene);
    const auto& P = mesh.patches();
    const double n = double(P.size());
    std::optional<PatchMesh> shooters;  // with --elements: the patches that shoot to the elements
    if (elements) shooters.emplace(scene, o.meshing);
    check_form_factor_memory(o, s.method, s.ff);
    if (s.solver != "shooting") check_memory(o, "the form-factor matrix (" + std::to_string(P.size()) + " patches)", n * n * 4);
    if (s.solver == "direct") check_memory(o, "the direct solver (matrix and LU factors)", n * n * 12);
    const auto visibility = make_visibility(o.visibility, P);
    const auto ff = elements ? std::make_unique<PatchToElementFormFactor>(shooters->patches(), P,
                                                                          s.method == "analytic" ? nullptr : visibility.get(), s.ff)
                             : make_form_factor_estimator(s.method, P, visibility.get(), s.ff);
    const bool shooting = s.solver == "shooting";
    ProgressLine progress(!o.quiet, shooting ? "shot" : "sweep", shooting ? "unshot" : "residual");
    std::optional<FormFactorMatrix> matrix;
    if (s.solver != "shooting") {
        matrix = FormFactorMatrix::build(*ff, P.size(), s.max_matrix_mb << 20,
                                         [&](std::size_t d, std::size_t t) { progress.rows(d, t); }, &g_interrupted);
        progress.finish();
    }
    if (matrix) {
        const double bound = contraction_bound(P, matrix->row_sums());
        if (bound >= 1.0 && !o.quiet)
            std::cerr << "warning: max rho_i * sum_j F_ij = " << bound
                      << " >= 1: the iteration may not converge (reflectance 1 in a closed scene, or row sums "
                         "above 1)\n";
    }
    SolverOptions so = s.options;
    so.progress = [&](const SolveProgress& p) { progress.update(p); };
    so.max_matrix_mb = s.max_matrix_mb;
    so.cancel = &g_interrupted;
    std::optional<SeriesWriter> series;
    const ExportInfo info{o.scene, ""};
    if (s.series > 0) {
        series.emplace(std::filesystem::path(out).replace_extension(".pvd"), mesh, info);
        so.snapshot_every = s.series;
        so.snapshot = [&](std::size_t step, const std::vector<Rgb>& B) { series->add(step, B); };
    }
    const auto solver = elements ? std::make_unique<ShootingSolver>(P, *ff, so, nullptr,
                                                                    ElementHierarchy{&shooters->patches(), &mesh.parents()})
                                 : make_solver(s.solver, {P, ff.get(), matrix ? &*matrix : nullptr}, so);
    SolveResult res = solver->solve();
    progress.finish();
    res.form_factors = s.method;
    if (matrix) res.seconds += matrix->seconds();

    std::ostringstream settings;
 settings << "patches=" << (elements ? shooters->size() : mesh.size()) << " elements=" << mesh.size() << " edge=" << mesh.edge_length() << " solver=" << s.solver
             << " sor=" << s.options.sor << " method=" << s.method << " rays=" << s.ff.visibility_rays
             << " receiver_samples=" << s.ff.receiver_samples << " hemicube_res=" << s.ff.hemicube_resolution
             << " seed=" << s.ff.seed << " tolerance=" << s.options.tolerance;
    write_vtu(out, mesh, res, {o.scene, settings.str()}, s.ascii);
    if (interrupted_exit_code()) {
        std::cerr << "bounce: interrupted after " << res.steps << " steps; wrote the solution so far to " << out.string()
                  << " (converged = 0)\n";
        return interrupted_exit_code();
    }
    if (series) series->finish(res);
    if (!s.png.empty()) render_solution(mesh, res, {o.scene, settings.str()}, s.png, s.render);
    if (!s.log_csv.empty()) write_log_csv(s.log_csv, {res}, {s.method}, {matrix ? matrix->seconds() : 0.0});
    if (!o.quiet) {
        std::cout << "patches " << (elements ? std::to_string(shooters->size()) + ", elements " : "") << mesh.size()
                  << ", " << s.solver << " " << res.steps
                  << (s.solver == "shooting" ? " shots" : " sweeps");
        if (s.solver == "shooting") std::cout << ", unshot fraction " << res.unshot_fraction;
        if (res.residual >= 0) std::cout << ", residual " << res.residual;
        std::cout << (res.converged ? "" : " (NOT converged: " + res.status + ")") << ", " << res.seconds << " s\n"
                  << "wrote " << out.string() << (series ? " and " + series->pvd().string() : "")
                  << (s.png.empty() ? "" : " and " + s.png) << "\n";
    }
    if (!res.converged && !o.quiet) {
        std::cerr << "bounce: not converged (" << res.status << "), last "
                  << (res.residual >= 0 ? "residual " + std::to_string(res.residual)
                                        : "unshot fraction " + std::to_string(res.unshot_fraction))
                  << "; the partial solution was written\n";
    }
    return res.converged ? 0 : 3;
}

void add_render_options(CLI::App* cmd, RenderOptions& r) {
    cmd->add_option("--camera", r.camera, "cornell, auto or x,y,z:tx,ty,tz (default: cornell for the box)");
    cmd->add_option("--size", [&r](const CLI::results_t& v) {
        return std::sscanf(v[0].c_str(), "%dx%d", &r.width, &r.height) == 2;
    }, "picture size WxH (800x800)");
    cmd->add_option("--exposure", r.exposure, "exposure in EV (0: mean patch at mid grey)");
    cmd->add_flag("--smooth", r.smooth, "colours interpolated from the point data");
    cmd->add_flag("--flat", [&r](std::int64_t) { r.smooth = false; }, "one colour per patch (default)");
    cmd->add_flag("--luminance", r.luminance, "pseudo-colour by luminance with a colour bar");
    cmd->add_flag("--edges", r.edges, "draw the patch edges");
}

struct RenderCommand {
    std::string input;
    std::string output;
    RenderOptions render;
    double exit_after = 0.0;
};

/// IN.vtu is rendered as it is; anything else is a scene, solved first with the defaults.
bool is_vtu(const std::string& p) { return std::filesystem::path(p).extension() == ".vtu"; }

int run_render(const CommonOptions& o, const RenderCommand& r, bool interactive) {
    if (!interactive) check_output(r.output);
    if (is_vtu(r.input)) {
        interactive ? view_vtu(r.input, r.render, r.exit_after) : render_vtu(r.input, r.output, r.render);
        return 0;
    }
    Scene scene;
    PatchMesh mesh = load_and_mesh(o, r.input, scene);
    const auto visibility = make_visibility(o.visibility, mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), visibility.get(), {});
    const SolveResult res = ShootingSolver(mesh.patches(), *ff, {}).solve();
    interactive ? view_solution(mesh, res, {r.input, ""}, r.render, r.exit_after)
                : render_solution(mesh, res, {r.input, ""}, r.output, r.render);
    return 0;
}

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
    if (default_meshing(o))
        roots.meshing.target_patches = 30;  // the Cornell box: 60 patches
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
    write_text_file(dir / "meshes.csv", [&](std::ostream& out) { out << csv.str(); }, "mesh comparison");
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
        matrices.push_back(FormFactorMatrix::build(*estimators.back(), P.size(), c.max_matrix_mb << 20,
                                                   [&](std::size_t d, std::size_t t) { progress.rows(d, t); },
                                                   &g_interrupted));
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

int main(int argc, char** argv) {
    CLI::App app{"bounce: progressive-refinement radiosity"};
    app.set_version_flag("--version", std::string(bounce::kBounceVersion));
    app.require_subcommand(1);
    CommonOptions common;
    SolveCommand solve;

    auto* solve_cmd = app.add_subcommand("solve", "compute radiosity and write a .vtu");
    add_meshing_options(solve_cmd, common);
    solve_cmd->add_option("-o,--output", solve.output, "output .vtu (default: <scene>.vtu)");
    std::vector<std::string> solve_solvers = bounce::solver_names();
    solve_solvers.push_back("hierarchical");
    solve_cmd->add_option("--solver", solve.solver, "shooting, gauss-seidel, jacobi, direct or hierarchical")
        ->check(CLI::IsMember(solve_solvers));
    solve_cmd->add_flag("--adaptive", solve.adaptive,
                        "adaptive subdivision: patches (150 unless meshing is given) refined into elements where the "
                        "radiosity varies");
    solve_cmd->add_option("--target-error", solve.adaptive_options.target_error,
                          "adaptive: stop when the RMS error estimate is below this (relative; 0.05)")
        ->check(kPositive);
    solve_cmd->add_option("--max-patches", solve.adaptive_options.max_elements, "adaptive: element budget (20000)")
        ->check(CLI::Range(std::size_t(1), std::size_t(10000000)));
    solve_cmd->add_option("--link-epsilon", solve.hierarchical.link_epsilon,
                          "hierarchical: link error bound, a share of what the link brings (0.1)")
        ->check(kPositive);
    solve_cmd->add_option("--max-level", solve.hierarchical.max_level,
                          "hierarchical: quadtree depth under each input face (4)")
        ->check(CLI::Range(0, 12));
    solve_cmd->add_option("--tolerance", solve.options.tolerance,
                          "stop below this unshot fraction (shooting) or relative residual (others); 1e-3")
        ->check(kPositive);
    solve_cmd->add_option("--max-shots,--max-iterations", solve.options.max_iterations,
                          "stop after this many shots or sweeps (default 100 N shots, 10000 sweeps)");
    solve_cmd->add_option("--max-seconds", solve.options.max_seconds, "stop after this many seconds")
        ->check(CLI::NonNegativeNumber);
    solve_cmd->add_option("--sor", solve.options.sor, "over-relaxation factor for jacobi and gauss-seidel, (0,2)")
        ->check(CLI::Range(0.0, 2.0));
    solve_cmd->add_option("--log", solve.log_csv, "write the convergence log (CSV)");
    solve_cmd->add_flag("--overshoot", solve.options.overshoot, "shooting: over-shoot by rho times the ambient term");
    solve_cmd->add_option("--elements", solve.element_split,
                          "shooting: cut every patch into KxK elements that receive (patches shoot to elements)")
        ->check(CLI::Range(1, 64));
    solve_cmd->add_option("--cache-mb", solve.options.cache_mb,
                          "shooting: memory for cached form-factor rows (MB, default 1024); rows beyond it are recomputed");
    solve_cmd->add_option("--max-matrix-mb", solve.max_matrix_mb, "refuse a matrix larger than this (MB)");
    solve_cmd->add_option("--form-factors", solve.method, "raycast, hemicube, or analytic (no occlusion)")
        ->check(CLI::IsMember(bounce::form_factor_methods()));
    add_form_factor_options(solve_cmd, solve.ff);
    solve_cmd->add_flag("--ascii", solve.ascii, "write ASCII instead of compressed binary");

    FormFactorCommand ffc;
    auto* ff_cmd = app.add_subcommand("form-factors", "compute the whole form-factor matrix and check it");
    add_meshing_options(ff_cmd, common);
    ff_cmd->add_option("--method", ffc.method, "raycast, analytic or hemicube")
        ->check(CLI::IsMember(bounce::form_factor_methods()));
    ff_cmd->add_option("-o,--output", ffc.output, "CSV of i,j,F_ij,row_sum_i for non-zero entries");
    ff_cmd->add_flag("--check", ffc.check, "print row sums and the reciprocity error");
    ff_cmd->add_option("--max-matrix-mb", ffc.max_matrix_mb, "refuse a matrix larger than this (MB)");
    add_form_factor_options(ff_cmd, ffc.ff);

    CompareCommand cmp;
    auto* cmp_cmd = app.add_subcommand("compare", "run several solvers and form-factor methods; chart them");
    add_meshing_options(cmp_cmd, common);
    cmp_cmd->add_option("--solvers", cmp.solvers, "solvers to run (default: all)")
        ->delimiter(',')
        ->check(CLI::IsMember(bounce::solver_names()));
    cmp_cmd->add_option("--form-factors", cmp.methods, "form-factor methods (default: raycast,hemicube); the first gives the reference")
        ->delimiter(',')
        ->check(CLI::IsMember(bounce::form_factor_methods()));
    cmp_cmd->add_option("--out", cmp.out, "output folder (default: compare)");
    cmp_cmd->add_option("--tolerance", cmp.options.tolerance, "stopping tolerance of each solver")
        ->check(kPositive);
    cmp_cmd->add_option("--max-iterations", cmp.options.max_iterations, "shots or sweeps limit");
    cmp_cmd->add_option("--sor", cmp.options.sor, "over-relaxation for jacobi and gauss-seidel")->check(CLI::Range(0.0, 2.0));
    cmp_cmd->add_option("--max-matrix-mb", cmp.max_matrix_mb, "refuse a matrix larger than this (MB)");
    cmp_cmd->add_flag("--meshes", cmp.meshes,
                      "compare uniform, adaptive and hierarchical meshes over the same patches (60 for the box) "
                      "against one fine uniform reference, instead of solvers");
    cmp_cmd->add_option("--reference-level", cmp.reference_level,
                        "--meshes: the reference cuts every patch into 4^level elements (5)")
        ->check(CLI::Range(1, 7));
    add_form_factor_options(cmp_cmd, cmp.ff);

    solve_cmd->add_option("--png", solve.png, "render the result to this PNG after solving");
    solve_cmd->add_option("--series", solve.series, "also write a .pvd time series: a snapshot every N shots or sweeps");
    add_render_options(solve_cmd, solve.render);

    RenderCommand rc;
    auto* render_cmd = app.add_subcommand("render", "render a .vtu (or a scene, solved first) to a PNG");
    render_cmd->add_option("input", rc.input, "IN.vtu, or a scene")->required();
    render_cmd->add_option("-o,--output", rc.output, "output PNG")->required();
    add_render_options(render_cmd, rc.render);
    add_meshing_options_no_scene(render_cmd, common);
    auto* view_cmd = app.add_subcommand("view", "interactive window: mouse rotates and zooms, e edges, l luminance");
    view_cmd->add_option("input", rc.input, "IN.vtu, or a scene")->required();
    add_render_options(view_cmd, rc.render);
    view_cmd->add_option("--exit-after", rc.exit_after, "close after this many seconds (demos, tests)");
    add_meshing_options_no_scene(view_cmd, common);

    auto* info_cmd = app.add_subcommand("info", "print the scene's surfaces, patches, area and emitted power");
    add_meshing_options(info_cmd, common);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        std::cerr << "bounce: " << e.what() << " (see --help)\n";
        return 2;
    }
    install_signal_handlers();
    std::optional<tbb::global_control> threads;
    if (common.threads > 0)
        threads.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(common.threads));
    try {
        if (*solve_cmd) return run_solve(common, solve);
        if (*ff_cmd) return run_form_factors(common, ffc);
        if (*cmp_cmd) return run_compare(common, cmp);
        if (*render_cmd) return run_render(common, rc, false);
        if (*view_cmd) return run_render(common, rc, true);
        return run_info(common);
    } catch (const bounce::InputError& e) {
        std::cerr << "bounce: error: " << e.what() << "\n";
        return 2;
    } catch (const bounce::Interrupted& e) {
        std::cerr << "bounce: " << e.what() << "; nothing written\n";
        return interrupted_exit_code() ? interrupted_exit_code() : 130;
    } catch (const bounce::SingularSystemError& e) {
        std::cerr << "bounce: error: " << e.what() << "\n";
        return 2;
    } catch (const bounce::ResourceLimitError& e) {
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
