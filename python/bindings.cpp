// SPDX-License-Identifier: MIT
// _bounce, the extension inside the Python package `bounce` (python/bounce/__init__.py):
// scenes, form factors and solutions as numpy arrays, over the same mesh, solver and viewer
// libraries as the command line. Every long call runs on a worker thread with the GIL
// released while the calling thread polls for Ctrl-C and reports progress (Job::run).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "mesh/input_error.h"
#include "mesh/patch_mesh.h"
#include "mesh/scene.h"
#include "mesh/scene_loader.h"
#include "solver/form_factors/form_factor_check.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/gather/hierarchical_point_values.h"
#include "solver/gather/point_values.h"
#include "solver/linear/solver.h"
#include "solver/reference/path_tracer.h"
#include "solver/reference/probe_classes.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"
#include "viewer/pending_output.h"
#include "viewer/renderer.h"
#include "viewer/version.h"
#include "viewer/vtu_writer.h"

namespace py = pybind11;

namespace bounce::python {
namespace {

// ---------------------------------------------------------------------------------------------
// Long calls

/// What a running job last reported, for the Python progress callback.
struct Progress {
    std::string stage;       // "form factors", "solve", "gathering: vertices", ...
    std::size_t step = 0;    // rows, shots, sweeps or points done
    std::size_t total = 0;   // of how many (0: unknown)
    double value = -1.0;     // solve: estimated relative error (shooting) or relative residual
    double tolerance = 0.0;  // solve: the value it stops under
    double seconds = 0.0;    // since the stage began
};

class Job {
public:
    std::atomic<bool> cancel{false};

    /// Called from worker threads: keeps the latest state for the next poll.
    void report(const Progress& p) {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_progress = p;
        ++m_version;
    }
    void report_items(const char* stage, std::size_t done, std::size_t total) {
        Progress p;
        p.stage = stage;
        p.step = done;
        p.total = total;
        p.seconds = elapsed();
        report(p);
    }
    double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count(); }

    /// Runs `work` on a worker thread, the GIL released. Every 50 ms the calling thread takes
    /// the GIL back to run Python's signal handlers (Ctrl-C raises KeyboardInterrupt there,
    /// and only there: CPython runs handlers on the main thread) and to call `callback` with
    /// fresh progress. A Python exception from either sets `cancel`, waits for the work to
    /// stop (within one shot, sweep or row) and propagates; the work's result is dropped, so
    /// nothing half-done reaches the caller.
    void run(const std::function<void()>& work, const py::object& callback) {
        std::exception_ptr error;
        bool done = false;
        std::mutex mutex;
        std::condition_variable finished;
        std::thread worker([&] {
            try {
                work();
            } catch (...) {
                error = std::current_exception();
            }
            std::lock_guard<std::mutex> lock(mutex);
            done = true;
            finished.notify_all();
        });
        auto stop = [&] {
            cancel = true;
            py::gil_scoped_release release;
            worker.join();
        };
        std::uint64_t seen = 0;
        for (bool over = false; !over;) {
            {
                py::gil_scoped_release release;
                std::unique_lock<std::mutex> lock(mutex);
                over = finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; });
            }
            if (PyErr_CheckSignals() != 0) {
                py::error_already_set e;
                stop();
                throw e;
            }
            if (callback.is_none()) continue;
            std::optional<Progress> fresh;
            {
                std::lock_guard<std::mutex> lock(m_mutex);
                if (m_version != seen) fresh = m_progress;
                seen = m_version;
            }
            if (!fresh) continue;
            try {
                callback(*fresh);
            } catch (...) {
                stop();
                throw;
            }
        }
        {
            py::gil_scoped_release release;
            worker.join();
        }
        if (error) std::rethrow_exception(error);
    }

private:
    std::mutex m_mutex;
    Progress m_progress;
    std::uint64_t m_version = 0;
    std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now();
};

// ---------------------------------------------------------------------------------------------
// Arguments, refused before any work in the command line's words

void check_range(const char* name, double x, double lo, double hi) {
    if (!(x >= lo && x <= hi)) {
        std::ostringstream v;
        v << x;
        throw InputError(std::string(name) + ": " + out_of_range_text(v.str(), lo, hi));
    }
}

void check_positive(const char* name, double x) {
    if (!(x > 0) || !std::isfinite(x)) {
        std::ostringstream v;
        v << x;
        throw InputError(std::string(name) + ": " + not_positive_text(v.str()));
    }
}

void check_member(const char* name, const std::string& value, const std::vector<std::string>& valid) {
    if (std::find(valid.begin(), valid.end(), value) != valid.end()) return;
    std::string list;
    for (const auto& v : valid) list += (list.empty() ? "" : ", ") + v;
    throw InputError(std::string(name) + ": unknown, got '" + value + "' (expected one of " + list + ")");
}

FormFactorOptions form_factor_options(const std::string& method, std::optional<int> rays, int receiver_samples,
                                      int hemicube_res, bool hemicube_jitter, std::uint64_t seed) {
    check_member("method", method, form_factor_methods());
    if (rays) check_range("rays", *rays, 1, 4096);
    check_range("receiver_samples", receiver_samples, 0, 16);
    check_range("hemicube_res", hemicube_res, 2, 4096);
    FormFactorOptions f;
    f.visibility_rays = rays.value_or(0);  // None: the method's default (kPatchPairRays, kRefinementRays)
    f.receiver_samples = receiver_samples;
    f.hemicube_resolution = hemicube_res;
    f.hemicube_jitter = hemicube_jitter;
    f.seed = seed;
    return f;
}

// ---------------------------------------------------------------------------------------------
// Arrays over library storage

/// Marks an array read-only: it shows the library's own data, which other results depend on.
py::array read_only(py::array a) {
    py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return a;
}

/// A view of one field of an array of structs: `rows` records `stride` bytes apart, `field`
/// pointing into the first, `cols` values of T each (0: a 1-D array), owned by `owner`.
template <class T>
py::array field_view(const void* field, std::size_t rows, std::size_t stride, std::size_t cols, py::handle owner) {
    if (cols == 0)
        return read_only(py::array(py::dtype::of<T>(), {rows}, {stride}, static_cast<const T*>(field), owner));
    return read_only(
        py::array(py::dtype::of<T>(), {rows, cols}, {stride, sizeof(T)}, static_cast<const T*>(field), owner));
}

/// Rgb is three doubles: a vector of them is an N x 3 array as it stands.
py::array rgb_view(const std::vector<Rgb>& v, py::handle owner) {
    static_assert(sizeof(Rgb) == 3 * sizeof(double));
    return field_view<double>(v.data(), v.size(), sizeof(Rgb), 3, owner);
}

py::array rgb_copy(const Rgb& c) {
    py::array_t<double> a(3);
    auto m = a.mutable_unchecked<1>();
    for (int k = 0; k < 3; ++k) m(k) = c[k];
    return a;
}

// ---------------------------------------------------------------------------------------------
// Scene

struct SceneData {
    std::string spec;
    Scene scene;
    std::unique_ptr<PatchMesh> mesh;
    std::string visibility;
};

/// The patches of a scene, or the elements of a solution that refined them.
struct PatchArrays {
    const PatchMesh* mesh;
    py::object owner;  // the Scene or Solution that holds `mesh`: the base of every view
};

std::shared_ptr<SceneData> load(const std::filesystem::path& scene_path, std::int64_t patches, double max_area,
                                double max_edge, bool subdivide, bool contact_cuts, bool flip, bool strict,
                                const std::string& visibility) {
    check_range("patches", double(patches), 1, 1e8);
    if (max_area != 0) check_positive("max_area", max_area);
    if (max_edge != 0) check_positive("max_edge", max_edge);
    check_member("visibility", visibility, visibility_backends());
    const std::string spec = scene_path.string();
    auto d = std::make_shared<SceneData>();
    d->spec = spec;
    d->visibility = visibility;
    MeshingOptions m;
    m.target_patches = std::size_t(patches);
    m.max_area = max_area;
    m.max_edge = max_edge;
    m.subdivide = subdivide;
    m.cut_contacts = contact_cuts;
    Job job;
    job.run(
        [&] {
            d->scene = load_scene(spec, LoadOptions{flip, strict});
            d->mesh = std::make_unique<PatchMesh>(d->scene, m);
        },
        py::none());
    return d;
}

// ---------------------------------------------------------------------------------------------
// Form factors

struct Matrix {
    FormFactorMatrix F;
};

/// The dense matrix as an N x N float32 array over the library's own storage.
py::array matrix_view(std::unique_ptr<Matrix> m) {
    const std::size_t n = m->F.size();
    const float* data = n ? m->F.row(0) : nullptr;
    py::capsule owner(m.release(), [](void* p) { delete static_cast<Matrix*>(p); });
    return read_only(py::array(py::dtype::of<float>(), {n, n}, {n * sizeof(float), sizeof(float)}, data, owner));
}

std::unique_ptr<Matrix> build_matrix(const SceneData& s, const std::string& method, const FormFactorOptions& f,
                                     std::size_t max_matrix_mb, Job& job) {
    const auto& P = s.mesh->patches();
    auto out = std::make_unique<Matrix>();
    const auto visibility = make_visibility(s.visibility, P);
    const auto ff = make_form_factor_estimator(method, P, visibility.get(), f);
    out->F = FormFactorMatrix::build(
        *ff, P.size(), max_matrix_mb << 20,
        [&](std::size_t d, std::size_t t) { job.report_items("form factors", d, t); }, &job.cancel);
    return out;
}

py::object form_factors(const std::shared_ptr<SceneData>& s, const std::string& method, std::optional<int> rays,
                        int receiver_samples, int hemicube_res, bool hemicube_jitter, std::uint64_t seed,
                        std::size_t max_matrix_mb, const std::string& format, const py::object& progress) {
    const FormFactorOptions f =
        form_factor_options(method, rays, receiver_samples, hemicube_res, hemicube_jitter, seed);
    check_member("format", format, {"dense", "csr"});
    Job job;
    std::unique_ptr<Matrix> m;
    job.run([&] { m = build_matrix(*s, method, f, max_matrix_mb, job); }, progress);
    if (format == "dense") return matrix_view(std::move(m));
    // CSR of the non-zero entries, as scipy.sparse.csr_matrix((data, indices, indptr)) takes it.
    const std::size_t n = m->F.size();
    std::vector<std::int64_t> indptr(n + 1, 0);
    std::vector<std::int32_t> indices;
    std::vector<float> data;
    for (std::size_t i = 0; i < n; ++i) {
        const float* row = m->F.row(i);
        for (std::size_t j = 0; j < n; ++j)
            if (row[j] != 0.0f) {
                indices.push_back(std::int32_t(j));
                data.push_back(row[j]);
            }
        indptr[i + 1] = std::int64_t(indices.size());
    }
    return py::make_tuple(py::array_t<float>(data.size(), data.data()),
                          py::array_t<std::int32_t>(indices.size(), indices.data()),
                          py::array_t<std::int64_t>(indptr.size(), indptr.data()));
}

py::dict check(const std::shared_ptr<SceneData>& s,
               const py::array_t<float, py::array::c_style | py::array::forcecast>& F) {
    const std::size_t n = s->mesh->size();
    if (F.ndim() != 2 || std::size_t(F.shape(0)) != n || std::size_t(F.shape(1)) != n)
        throw InputError("check_form_factors: the matrix must be " + std::to_string(n) + " x " + std::to_string(n) +
                         " (the scene's patches)");
    const auto matrix = FormFactorMatrix::from_values(n, std::vector<float>(F.data(), F.data() + n * n));
    FormFactorCheck c;
    {
        py::gil_scoped_release release;
        c = check_form_factors(s->mesh->patches(), matrix);
    }
    py::dict d;
    d["row_sums"] = py::array_t<double>(c.row_sums.size(), c.row_sums.data());
    d["row_sum_min"] = c.row_sum_min;
    d["row_sum_mean"] = c.row_sum_mean;
    d["row_sum_max"] = c.row_sum_max;
    d["deviation_min"] = c.deviation_min;
    d["deviation_mean"] = c.deviation_mean;
    d["deviation_max"] = c.deviation_max;
    d["reciprocity_max"] = c.reciprocity_max;
    d["reciprocity_overall"] = c.reciprocity_overall;
    return d;
}

// ---------------------------------------------------------------------------------------------
// Solve

struct SolutionData {
    std::shared_ptr<SceneData> scene;
    // The scene's patches, or for the element solvers the elements they refined them into.
    std::shared_ptr<const PatchMesh> mesh;
    SolveResult result;
    std::string settings;
    bool gathered = false;
    double form_factor_seconds = 0.0;  // building the matrix (gathering solvers, or residuals=True)
    std::vector<Rgb> averaged_points;  // the point data when not gathered, as the .vtu has it

    ExportInfo info(bool meshio) const { return ExportInfo{scene->spec, settings, meshio, scene->scene.units}; }
};

std::shared_ptr<SolutionData> solve(
    const std::shared_ptr<SceneData>& s, const std::string& solver_name, std::optional<double> tolerance_given,
    std::optional<std::int64_t> max_iterations_given, std::optional<double> max_seconds_given,
    std::optional<double> sor_given, std::optional<bool> overshoot_given, std::optional<std::size_t> cache_mb_given,
    const std::string& method, std::optional<int> rays, int receiver_samples, int hemicube_res, bool hemicube_jitter,
    std::uint64_t seed, std::size_t max_matrix_mb, const std::string& gather, bool residuals,
    const std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>>& reference, bool adaptive,
    const py::object& target_error, const py::object& max_patches, double link_epsilon,
    std::optional<double> power_epsilon, int refine_rounds, int max_level, bool clustering,
    std::optional<double> display_tolerance, const py::object& progress) {
    std::vector<std::string> solvers = solver_names();
    solvers.push_back("hierarchical");
    check_member("solver", solver_name, solvers);
    const bool elements = solver_name == "hierarchical" || adaptive;  // the hierarchical solver's elements
    if (elements && method != "raycast") throw InputError("adaptive and hierarchical use raycast form factors");
    if (adaptive && solver_name != "shooting" && solver_name != "hierarchical")
        throw InputError("adaptive is the hierarchical solver: it takes no other (got '" + solver_name + "')");
    for (const auto& [name, value] : {std::pair("target_error", &target_error), std::pair("max_patches", &max_patches)})
        if (!value->is_none())
            throw InputError(std::string(name) +
                             " belonged to the receiver-only refinement adaptive ran before, now retired: adaptive is "
                             "the hierarchical solver refining on power; set power_epsilon");
    if (!elements && display_tolerance)
        throw InputError("display_tolerance applies to the hierarchical solver (and adaptive)");
    // As the command line: adaptive gathers with kSuggestedDisplayTolerance unless one is given.
    const DisplayRefinement display{adaptive && gather == "vertices" ? adaptive_display_tolerance(display_tolerance)
                                                                     : display_tolerance.value_or(0.0)};
    check_range("display_tolerance", display.tolerance, 0.0, 1.0);
    if (display.tolerance > 0 && gather != "vertices")
        throw InputError(
            "display_tolerance refines the point data gathered at the vertices: it needs gather "
            "'vertices' (got '" +
            gather + "')");
    if (elements && (residuals || reference))
        throw InputError("residuals and reference apply to the patch solvers, not to adaptive or hierarchical");
    // As the command line: tolerance and max_iterations, given, stop the hierarchical iterations
    // too; the patch solvers' other options are refused by name.
    for (const auto& [name, given] :
         {std::pair("max_seconds", max_seconds_given.has_value()), std::pair("sor", sor_given.has_value()),
          std::pair("overshoot", overshoot_given.has_value()), std::pair("cache_mb", cache_mb_given.has_value())})
        if (elements && given)
            throw InputError(std::string(name) + " applies to the patch solvers, not to adaptive or hierarchical");
    const double tolerance = tolerance_given.value_or(SolverOptions{}.tolerance);
    const std::int64_t max_iterations = max_iterations_given.value_or(0);
    const double max_seconds = max_seconds_given.value_or(0.0), sor = sor_given.value_or(1.0);
    const bool overshoot = overshoot_given.value_or(false);
    const std::size_t cache_mb = cache_mb_given.value_or(SolverOptions{}.cache_mb);
    // As the command line: adaptive takes kAdaptivePowerEpsilon unless a power epsilon above 0 is given.
    double power = power_epsilon.value_or(0.0);
    check_range("power_epsilon", power, 0.0, 1.0);
    if (adaptive) power = adaptive_power_epsilon(power);
    check_range("refine_rounds", refine_rounds, 1, 100);
    check_positive("link_epsilon", link_epsilon);
    check_range("max_level", max_level, 0, 12);
    const FormFactorOptions f =
        form_factor_options(method, rays, receiver_samples, hemicube_res, hemicube_jitter, seed);
    check_positive("tolerance", tolerance);
    check_range("max_iterations", double(max_iterations), 0, 1e15);
    check_range("sor", sor, 0.0, 2.0);
    if (max_seconds < 0) check_positive("max_seconds", max_seconds);
    check_member("gather", gather, gather_modes());
    std::vector<Rgb> reference_values;
    if (reference) {
        const auto& r = *reference;
        if (r.ndim() != 2 || std::size_t(r.shape(0)) != s->mesh->size() || r.shape(1) != 3)
            throw InputError("reference: must be " + std::to_string(s->mesh->size()) +
                             " x 3 (B per patch and channel)");
        for (py::ssize_t i = 0; i < r.shape(0); ++i) reference_values.emplace_back(r.at(i, 0), r.at(i, 1), r.at(i, 2));
    }

    auto out = std::make_shared<SolutionData>();
    out->scene = s;
    out->mesh = std::shared_ptr<const PatchMesh>(s, s->mesh.get());
    const PatchMesh& mesh = *s->mesh;
    const auto& P = mesh.patches();
    std::ostringstream settings;
    Job job;
    job.run(
        [&] {
            // `seconds`: the wall time of the whole solve, visibility to gather, for every solver.
            const auto start = std::chrono::steady_clock::now();
            const auto since_start = [&] {
                return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            };
            const auto visibility = make_visibility(s->visibility, P);
            if (elements) {
                // The scene's patches are the roots: load() chose their size.
                HierarchicalOptions h;
                h.link_epsilon = link_epsilon;
                h.power_epsilon = power;
                h.refine_rounds = refine_rounds;
                h.max_level = max_level;
                h.clustering = clustering;
                if (tolerance_given) h.tolerance = tolerance;
                if (max_iterations > 0) h.max_iterations = std::size_t(max_iterations);  // 0: the default
                h.form_factors = f;
                h.cancel = &job.cancel;
                h.progress = [&job](const std::string& stage, std::size_t d, std::size_t t) {
                    job.report_items(stage.c_str(), d, t);
                };
                // Kept for the gather through its links, which does not read its result.
                HierarchicalSolution sol = solve_hierarchical(P, *visibility, h);
                if (job.cancel) return;
                PatchMesh cells = sol.tree.conforming_mesh(sol.leaves);
                SolveResult res = std::move(sol.result);
                settings << "patches=" << P.size() << " rays=" << with_default_rays(f, kRefinementRays).visibility_rays
                         << " seed=" << seed << hierarchical_settings(h, sol);
                // The elements tile the patches: the patches' visibility is theirs (hierarchical_point_values.h).
                const auto report = [&](const char* stage, std::size_t d, std::size_t t) {
                    job.report_items(stage, d, t);
                };
                out->gathered = gather_hierarchical_point_values(sol, cells, *visibility, res, gather, display,
                                                                 &job.cancel, report) == GatherOutcome::gathered;
                settings << " display_tolerance=" << display.tolerance << " display_cells=" << cells.size();
                out->mesh = std::make_shared<const PatchMesh>(std::move(cells));
                if (!out->gathered) out->averaged_points = area_weighted_vertex_values(*out->mesh, res.radiosity);
                res.seconds = since_start();
                out->result = std::move(res);
                return;
            }
            const auto ff = make_form_factor_estimator(method, P, visibility.get(), f);
            std::optional<FormFactorMatrix> matrix;
            if (solver_name != "shooting" || residuals)
                matrix = FormFactorMatrix::build(
                    *ff, P.size(), max_matrix_mb << 20,
                    [&](std::size_t d, std::size_t t) { job.report_items("form factors", d, t); }, &job.cancel);
            SolverOptions so;
            so.tolerance = tolerance;
            so.max_iterations = std::size_t(max_iterations);
            so.max_seconds = max_seconds;
            so.sor = sor;
            so.overshoot = overshoot;
            so.cache_mb = cache_mb;
            so.max_matrix_mb = max_matrix_mb;
            so.cancel = &job.cancel;
            if (reference) so.reference = &reference_values;
            so.progress = [&](const SolveProgress& p) {
                job.report({"solve", p.step, p.max_steps, p.unshot_fraction, p.tolerance, p.seconds});
            };
            const auto solver = make_solver(solver_name, {P, ff.get(), matrix ? &*matrix : nullptr}, so);
            SolveResult res = solver->solve();
            if (job.cancel) return;
            res.form_factors = method;
            if (matrix) res.seconds += matrix->seconds();
            if (matrix) out->form_factor_seconds = matrix->seconds();
            out->gathered = gather_point_values(mesh, *visibility, res, gather, &job.cancel,
                                                [&](const char* stage, std::size_t d, std::size_t t) {
                                                    job.report_items(stage, d, t);
                                                }) == GatherOutcome::gathered;
            if (!out->gathered) out->averaged_points = area_weighted_vertex_values(mesh, res.radiosity);
            res.seconds = since_start();
            out->result = std::move(res);
        },
        progress);
    if (!elements)
        settings << "patches=" << mesh.size() << " elements=" << mesh.size() << " edge=" << mesh.edge_length()
                 << " solver=" << solver_name << " sor=" << sor << " method=" << method
                 << " rays=" << with_default_rays(f, kPatchPairRays).visibility_rays
                 << " receiver_samples=" << receiver_samples << " hemicube_res=" << hemicube_res << " seed=" << seed
                 << " tolerance=" << tolerance << " (python)";
    out->settings = settings.str();
    return out;
}

/// The convergence log as arrays over the records (one column each, no copy).
py::dict history(const py::object& self) {
    const auto& log = self.cast<const SolutionData&>().result.log;
    const std::size_t n = log.size();
    const ConvergenceRecord* r = log.data();
    const std::size_t stride = sizeof(ConvergenceRecord);
    py::dict d;
    static_assert(sizeof(std::size_t) == sizeof(std::uint64_t));
    d["step"] = field_view<std::uint64_t>(n ? &r->step : nullptr, n, stride, 0, self);
    d["seconds"] = field_view<double>(n ? &r->seconds : nullptr, n, stride, 0, self);
    d["residual"] = field_view<double>(n ? &r->residual : nullptr, n, stride, 0, self);
    d["unshot_fraction"] = field_view<double>(n ? &r->unshot_fraction : nullptr, n, stride, 0, self);
    d["rms_error"] = field_view<double>(n ? &r->rms_error : nullptr, n, stride, 0, self);
    d["max_error"] = field_view<double>(n ? &r->max_error : nullptr, n, stride, 0, self);
    return d;
}

void write_vtu_file(const SolutionData& s, const std::filesystem::path& path, bool ascii, bool meshio) {
    check_output(path);
    py::gil_scoped_release release;
    write_vtu(path, *s.mesh, s.result, s.info(meshio), ascii);
}

void render_file(const SolutionData& s, const std::filesystem::path& path, const std::string& camera, double fov,
                 std::pair<int, int> size, double exposure, bool smooth, bool luminance, bool edges) {
    check_output(path);
    check_picture_path(path);
    check_range("size", size.first, 1, 16384);
    check_range("size", size.second, 1, 16384);
    RenderOptions r;
    r.camera = camera;
    r.fov = fov;
    r.width = size.first;
    r.height = size.second;
    r.exposure = exposure;
    r.smooth = smooth;
    r.luminance = luminance;
    r.edges = edges;
    r.camera_name = "camera";  // the keywords, not the command line's options
    r.fov_name = "fov";
    r.size_name = "size";
    py::gil_scoped_release release;
    render_solution(*s.mesh, s.result, s.info(false), path, r);
}

// ---------------------------------------------------------------------------------------------
// The path-traced reference

struct ReferenceRun {
    std::vector<SurfacePoint> points;
    std::vector<std::uint8_t> found;  // 0: no surface near the given point (skip_missing)
    std::vector<RadiosityEstimate> estimates;
    std::vector<ProbeClass> classes;  // probes drawn by class: each one's
};

using Points = std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>>;

py::dict reference(const std::shared_ptr<SceneData>& s, const Points& points, const Points& normals,
                   std::int64_t probes, double target_error, double max_paths, std::uint64_t seed, bool skip_missing,
                   const std::string& probe_mix, const py::object& progress) {
    if (points.has_value() == (probes > 0))
        throw InputError("reference: give exactly one of points (with normals) or probes");
    if (probe_mix != "classes" && probe_mix != "area")
        throw InputError("reference: probe_mix is 'classes' or 'area' (got '" + probe_mix + "')");
    check_range("target_error", target_error, 1e-6, 1.0);
    check_range("max_paths", max_paths, 64, double(std::uint64_t(1) << 40));
    std::vector<glm::dvec3> given_p, given_n;
    if (points) {
        if (!normals) throw InputError("reference: points need normals (the side of the surface they look from)");
        const auto& P = *points;
        const auto& N = *normals;
        if (P.ndim() != 2 || P.shape(1) != 3 || N.ndim() != 2 || N.shape(1) != 3 || N.shape(0) != P.shape(0))
            throw InputError("reference: points and normals must both be M x 3");
        for (py::ssize_t k = 0; k < P.shape(0); ++k) {
            given_p.emplace_back(P.at(k, 0), P.at(k, 1), P.at(k, 2));
            given_n.emplace_back(N.at(k, 0), N.at(k, 1), N.at(k, 2));
        }
    }
    ReferenceOptions options;
    options.target_error = target_error;
    options.max_paths = std::uint64_t(max_paths);
    options.seed = seed;
    auto run = std::make_unique<ReferenceRun>();
    Job job;
    job.run(
        [&] {
            const PathTracer tracer(s->scene);
            if (points) {
                for (std::size_t k = 0; k < given_p.size(); ++k) {
                    const auto x = tracer.locate(given_p[k], given_n[k]);
                    if (!x && !skip_missing) {
                        char msg[320];
                        std::snprintf(msg, sizeof msg,
                                      "points[%zu]: no surface facing the normal within %.4g (0.5%% of the scene's "
                                      "diagonal) of the point (%.6g, %.6g, %.6g); skip_missing=True leaves such "
                                      "rows empty",
                                      k, tracer.snap_distance(), given_p[k].x, given_p[k].y, given_p[k].z);
                        throw InputError(msg);
                    }
                    run->found.push_back(x ? 1 : 0);
                    run->points.push_back(x ? *x : SurfacePoint{given_p[k], given_n[k], -1});
                }
            } else {
                run->points = probe_mix == "area" ? tracer.probes(std::size_t(probes), seed)
                                                  : probes_by_class(tracer, std::size_t(probes), seed, run->classes);
                if (run->points.empty())
                    throw InputError(s->spec + ": no surface to place probes on (every surface emits)");
                run->found.assign(run->points.size(), 1);
            }
            // Missing points are not traced. Each point draws from the stream of its index
            // among the traced ones, as `bounce reference --skip-missing` numbers them.
            std::vector<SurfacePoint> traced;
            for (std::size_t k = 0; k < run->points.size(); ++k)
                if (run->found[k]) traced.push_back(run->points[k]);
            const auto estimates = tracer.estimate_all(
                traced, options, [&](std::size_t d, std::size_t t) { job.report_items("path tracing: points", d, t); },
                &job.cancel);
            RadiosityEstimate missing;
            const double nan = std::numeric_limits<double>::quiet_NaN();
            missing.radiosity = missing.standard_error = Rgb(nan, nan, nan);
            for (std::size_t k = 0, t = 0; k < run->points.size(); ++k)
                run->estimates.push_back(run->found[k] ? estimates[t++] : missing);
        },
        progress);
    const std::size_t m = run->points.size();
    std::vector<std::string> status;
    for (std::size_t k = 0; k < m; ++k)
        status.push_back(run->found[k] ? to_string(run->estimates[k].status) : std::string("missing"));
    const ReferenceRun* r = run.get();
    py::capsule owner(run.release(), [](void* p) { delete static_cast<ReferenceRun*>(p); });
    const auto* e = m ? r->estimates.data() : nullptr;
    const auto* x = m ? r->points.data() : nullptr;
    py::dict d;
    d["position"] = field_view<double>(x ? &x->position.x : nullptr, m, sizeof(SurfacePoint), 3, owner);
    d["normal"] = field_view<double>(x ? &x->normal.x : nullptr, m, sizeof(SurfacePoint), 3, owner);
    d["surface"] = field_view<std::int32_t>(x ? &x->surface : nullptr, m, sizeof(SurfacePoint), 0, owner);
    d["radiosity"] = field_view<double>(e ? &e->radiosity.r : nullptr, m, sizeof(RadiosityEstimate), 3, owner);
    d["standard_error"] =
        field_view<double>(e ? &e->standard_error.r : nullptr, m, sizeof(RadiosityEstimate), 3, owner);
    static_assert(sizeof(std::uint64_t) == sizeof(e->paths));
    d["paths"] = field_view<std::uint64_t>(e ? &e->paths : nullptr, m, sizeof(RadiosityEstimate), 0, owner);
    d["status"] = status;
    if (!r->classes.empty()) {
        std::vector<std::string> classes;
        for (const ProbeClass c : r->classes) classes.push_back(to_string(c));
        d["class"] = classes;
    }
    return d;
}

/// The exception translator and the Progress class.
void bind_errors_and_progress(py::module_& m) {
    // The command line's one-line messages, as the Python exception that fits.
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const MissingFileError& e) {
            PyErr_SetString(PyExc_FileNotFoundError, e.what());
        } catch (const InputError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        } catch (const ResourceLimitError& e) {
            PyErr_SetString(PyExc_MemoryError, e.what());
        } catch (const SingularSystemError& e) {
            PyErr_SetString(PyExc_ArithmeticError, e.what());
        } catch (const Interrupted& e) {
            PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
        }
    });

    py::class_<Progress>(m, "Progress", "What a long call reports to its progress callback.")
        .def_readonly("stage", &Progress::stage,
                      "'form factors', 'solve', the hierarchical solver's 'round 1/1: refining links', "
                      "'round 1/1: link form factors' and 'round 1/1: gather iterations', "
                      "'gathering: vertices', 'gathering: centres', 'gathering: element centres' or "
                      "'path tracing: points'")
        .def_readonly("step", &Progress::step, "rows, shots, sweeps, links, iterations or points done")
        .def_readonly("total", &Progress::total, "of how many (0: unknown)")
        .def_readonly("value", &Progress::value,
                      "solve: estimated relative error (shooting) or relative residual; else -1")
        .def_readonly("tolerance", &Progress::tolerance, "solve: the value it stops below")
        .def_readonly("seconds", &Progress::seconds)
        .def("__repr__", [](const Progress& p) {
            std::ostringstream s;
            s << "Progress(" << p.stage << " " << p.step << "/" << p.total << ", value " << p.value << ", " << p.seconds
              << " s)";
            return s.str();
        });
}

/// bounce.Patches: the patches as numpy views.
void bind_patches(py::module_& m) {
    py::class_<PatchArrays>(m, "Patches",
                            "The scene's patches as read-only numpy views of the library's storage (N patches, "
                            "V mesh vertices).")
        .def_property_readonly(
            "area",
            [](const PatchArrays& a) {
                const auto& P = a.mesh->patches();
                return field_view<double>(P.empty() ? nullptr : &P[0].area, P.size(), sizeof(Patch), 0, a.owner);
            },
            "(N,) scene units^2")
        .def_property_readonly(
            "normal",
            [](const PatchArrays& a) {
                const auto& P = a.mesh->patches();
                return field_view<double>(P.empty() ? nullptr : &P[0].normal.x, P.size(), sizeof(Patch), 3, a.owner);
            },
            "(N, 3) unit, towards the lit front")
        .def_property_readonly(
            "centroid",
            [](const PatchArrays& a) {
                const auto& P = a.mesh->patches();
                return field_view<double>(P.empty() ? nullptr : &P[0].centre.x, P.size(), sizeof(Patch), 3, a.owner);
            },
            "(N, 3) area centroid")
        .def_property_readonly(
            "reflectance",
            [](const PatchArrays& a) {
                const auto& P = a.mesh->patches();
                return field_view<double>(P.empty() ? nullptr : &P[0].reflectance.r, P.size(), sizeof(Patch), 3,
                                          a.owner);
            },
            "(N, 3) rho per RGB channel")
        .def_property_readonly(
            "emission",
            [](const PatchArrays& a) {
                const auto& P = a.mesh->patches();
                return field_view<double>(P.empty() ? nullptr : &P[0].emission.r, P.size(), sizeof(Patch), 3, a.owner);
            },
            "(N, 3) emitted radiosity E per channel")
        .def_property_readonly(
            "surface",
            [](const PatchArrays& a) {
                const auto& P = a.mesh->patches();
                return field_view<std::int32_t>(P.empty() ? nullptr : &P[0].surface, P.size(), sizeof(Patch), 0,
                                                a.owner);
            },
            "(N,) index of the input surface each patch was cut from (see surface_names)")
        .def_property_readonly(
            "corners",
            [](const PatchArrays& a) {
                const auto& P = a.mesh->patches();
                const std::size_t n = P.size();
                return read_only(py::array(py::dtype::of<double>(), {n, std::size_t(4), std::size_t(3)},
                                           {sizeof(Patch), sizeof(glm::dvec3), sizeof(double)},
                                           n ? &P[0].vertices[0].x : nullptr, a.owner));
            },
            "(N, 4, 3) the patch's corners, counter-clockwise from the front; a triangle's fourth is unused")
        .def_property_readonly(
            "vertex_count",
            [](const PatchArrays& a) {
                const auto& P = a.mesh->patches();
                return field_view<std::int32_t>(P.empty() ? nullptr : &P[0].vertex_count, P.size(), sizeof(Patch), 0,
                                                a.owner);
            },
            "(N,) 3 or 4")
        .def_property_readonly(
            "vertices",
            [](const PatchArrays& a) {
                const auto& mesh = a.mesh->mesh();
                static_assert(sizeof(OpenPatchMesh::Point) == 3 * sizeof(double));
                const std::size_t v = mesh.n_vertices();
                return field_view<double>(v ? mesh.points()[0].data() : nullptr, v, 3 * sizeof(double), 3, a.owner);
            },
            "(V, 3) the mesh's vertices (shared by the patches of one surface; the point data lives here)")
        .def_property_readonly(
            "faces",
            [](const PatchArrays& a) {
                const PatchMesh& mesh = *a.mesh;
                std::size_t width = 3;
                std::vector<std::vector<int>> faces(mesh.size());
                for (std::size_t p = 0; p < mesh.size(); ++p) {
                    faces[p] = mesh.patch_vertex_indices(p);
                    width = std::max(width, faces[p].size());
                }
                py::array_t<std::int32_t> out({mesh.size(), width});
                auto o = out.mutable_unchecked<2>();
                for (std::size_t p = 0; p < mesh.size(); ++p)
                    for (std::size_t k = 0; k < width; ++k) o(p, k) = k < faces[p].size() ? faces[p][k] : -1;
                return out;
            },
            "(N, 3 or 4) vertex indices of each patch, padded with -1 (a new array: OpenMesh keeps faces as "
            "half-edges)")
        .def("__len__", [](const PatchArrays& a) { return a.mesh->size(); });
}

/// bounce.Scene and bounce.Solution.
void bind_scene_and_solution(py::module_& m) {
    py::class_<SceneData, std::shared_ptr<SceneData>>(m, "Scene", "A scene cut into patches (bounce.load).")
        .def_readonly("name", &SceneData::spec, "'cornell' or the path it was loaded from")
        .def_property_readonly("patches",
                               [](const py::object& self) {
                                   return PatchArrays{self.cast<const SceneData&>().mesh.get(), self};
                               })
        .def_property_readonly(
            "warnings", [](const SceneData& s) { return s.scene.warnings; },
            "problems with the input that were repaired")
        .def_property_readonly("units", [](const SceneData& s) { return s.scene.units; })
        .def_property_readonly(
            "surface_names",
            [](const SceneData& s) {
                std::vector<std::string> names;
                for (const auto& surface : s.scene.surfaces) names.push_back(describe(surface.where, surface.object));
                return names;
            },
            "per input surface, where it came from: 'file.obj:42 (object)' or 'cornell box: floor'")
        .def_property_readonly("total_area", [](const SceneData& s) { return s.mesh->total_area(); })
        .def_property_readonly(
            "emitted_power", [](const SceneData& s) { return rgb_copy(s.mesh->emitted_power()); },
            "sum of E_i A_i per channel")
        .def_property_readonly("edge_length", [](const SceneData& s) { return s.mesh->edge_length(); })
        .def("__len__", [](const SceneData& s) { return s.mesh->size(); })
        .def("__repr__", [](const SceneData& s) {
            return "<bounce.Scene '" + s.spec + "': " + std::to_string(s.scene.surfaces.size()) + " surfaces, " +
                   std::to_string(s.mesh->size()) + " patches>";
        });

    py::class_<SolutionData, std::shared_ptr<SolutionData>>(m, "Solution", "A radiosity solution (bounce.solve).")
        .def_readonly("scene", &SolutionData::scene)
        .def_property_readonly(
            "patches",
            [](const py::object& self) {
                return PatchArrays{self.cast<const SolutionData&>().mesh.get(), self};
            },
            "the patches the solution is over: the scene's, or the elements adaptive and hierarchical made")
        .def_property_readonly(
            "radiosity",
            [](const py::object& self) { return rgb_view(self.cast<const SolutionData&>().result.radiosity, self); },
            "(N, 3) B per patch and channel, W/m^2 (a view)")
        .def_property_readonly(
            "irradiance",
            [](const py::object& self) { return rgb_view(self.cast<const SolutionData&>().result.irradiance, self); },
            "(N, 3) H, the power arriving per unit area (B = E + rho H)")
        .def_property_readonly(
            "unshot",
            [](const py::object& self) { return rgb_view(self.cast<const SolutionData&>().result.unshot, self); },
            "(N, 3) shooting: radiosity received but not shot on (empty for the other solvers)")
        .def_property_readonly(
            "display",
            [](const py::object& self) { return rgb_view(self.cast<const SolutionData&>().result.display, self); },
            "(N, 3) shooting: B plus the ambient term, for display (empty for the other solvers)")
        .def_property_readonly(
            "point_radiosity",
            [](const py::object& self) {
                const auto& s = self.cast<const SolutionData&>();
                return rgb_view(s.gathered ? s.result.point_radiosity : s.averaged_points, self);
            },
            "(V, 3) per mesh vertex: gathered (point_gathered) or else averaged over the patches around it, "
            "as the .vtu's point data")
        .def_readonly("point_gathered", &SolutionData::gathered)
        .def_property_readonly(
            "gathered_centres",
            [](const py::object& self) {
                return rgb_view(self.cast<const SolutionData&>().result.gathered_centres, self);
            },
            "(N, 3) with gather='centres': B gathered at each patch centre")
        .def_property_readonly("solver", [](const SolutionData& s) { return s.result.solver; })
        .def_property_readonly("form_factors", [](const SolutionData& s) { return s.result.form_factors; })
        .def_property_readonly(
            "steps", [](const SolutionData& s) { return s.result.steps; }, "shots or sweeps")
        .def_property_readonly(
            "seconds", [](const SolutionData& s) { return s.result.seconds; },
            "wall time of the whole solve, for every solver: visibility, form factors, refinement, solve and the "
            "point gather")
        .def_property_readonly("converged", [](const SolutionData& s) { return s.result.converged; })
        .def_property_readonly("status", [](const SolutionData& s) { return to_string(s.result.status); })
        .def_property_readonly("residual", [](const SolutionData& s) { return s.result.residual; })
        .def_property_readonly("unshot_fraction", [](const SolutionData& s) { return s.result.unshot_fraction; })
        .def_property_readonly(
            "error_estimate", [](const SolutionData& s) { return s.result.error_estimate; },
            "shooting: the largest relative error of a patch that the unshot power left would still add, as "
            "estimated from the convergence (what tolerance bounds); else -1")
        .def_property_readonly("emitted_power", [](const SolutionData& s) { return rgb_copy(s.result.emitted_power); })
        .def_property_readonly("absorbed_power",
                               [](const SolutionData& s) { return rgb_copy(s.result.absorbed_power); })
        .def_property_readonly("escaped_power", [](const SolutionData& s) { return rgb_copy(s.result.escaped_power); })
        .def_property_readonly("unshot_power", [](const SolutionData& s) { return rgb_copy(s.result.unshot_power); })
        .def_readonly("settings", &SolutionData::settings)
        .def_readonly(
            "form_factor_seconds", &SolutionData::form_factor_seconds,
            "time to build the form-factor matrix, which `seconds` includes (0 when shooting computes rows as "
            "it shoots; with residuals=True shooting reads the matrix's columns instead)")
        .def_property_readonly("history", &history,
                               "the convergence log: dict of step, seconds, residual (-1: not computed) and "
                               "unshot_fraction arrays, one entry per logged shot or sweep")
        .def("write_vtu", &write_vtu_file, py::arg("path"), py::arg("ascii") = false, py::arg("meshio") = false,
             "Writes the .vtu `bounce solve` writes (temporary file, then rename). meshio=True stores the text "
             "fields as char arrays, which meshio reads.")
        .def("render", &render_file, py::arg("path"), py::arg("camera") = "default", py::arg("fov") = 0.0,
             py::arg("size") = std::pair<int, int>(800, 800), py::arg("exposure") = 0.0, py::arg("smooth") = true,
             py::arg("luminance") = false, py::arg("edges") = false,
             "Renders the solution to a PNG or JPEG, as `bounce render` does: smooth (the point data) unless "
             "smooth=False (one colour per patch).")
        .def("__repr__", [](const SolutionData& s) {
            std::ostringstream o;
            o << "<bounce.Solution " << s.result.solver << ", " << s.result.radiosity.size() << " patches, "
              << s.result.steps << " steps, " << s.result.status << ">";
            return o.str();
        });
}

/// The module's functions: load, form_factors, solve, reference and the name lists.
void bind_functions(py::module_& m) {
    m.def("load", &load, py::arg("scene") = "cornell", py::kw_only(), py::arg("patches") = 2000,
          py::arg("max_area") = 0.0, py::arg("max_edge") = 0.0, py::arg("subdivide") = true,
          py::arg("contact_cuts") = true, py::arg("flip") = false, py::arg("strict") = false,
          py::arg("visibility") = visibility_backends().front(),
          "The scene cut into patches (the package's bounce.load wraps this and issues the warnings).");
    m.def("form_factors", &form_factors, py::arg("scene"), py::kw_only(), py::arg("method") = "raycast",
          py::arg("rays") = py::none(), py::arg("receiver_samples") = 0, py::arg("hemicube_res") = 256,
          py::arg("hemicube_jitter") = false, py::arg("seed") = 1, py::arg("max_matrix_mb") = 2048,
          py::arg("format") = "dense", py::arg("progress") = py::none(),
          "The whole form-factor matrix, F[i, j] the fraction of power leaving patch i that reaches j, as "
          "`bounce form-factors` computes it: an N x N float32 view of the library's matrix, or with "
          "format='csr' the tuple (data, indices, indptr) of its non-zero entries (built from the dense one).");
    m.def("check_form_factors", &check, py::arg("scene"), py::arg("F"),
          "Row sums and reciprocity of F over the scene's patches, as `bounce form-factors --check` prints them: "
          "a dict of row_sums (N,), row_sum_min/mean/max, deviation_min/mean/max (|sum - 1|), reciprocity_max "
          "(max |A_i F_ij - A_j F_ji| / (A_i F_ij) over F_ij >= 1e-3) and reciprocity_overall.");
    m.def("solve", &solve, py::arg("scene"), py::kw_only(), py::arg("solver") = "shooting",
          py::arg("tolerance") = py::none(), py::arg("max_iterations") = py::none(),
          py::arg("max_seconds") = py::none(), py::arg("sor") = py::none(), py::arg("overshoot") = py::none(),
          py::arg("cache_mb") = py::none(), py::arg("form_factors") = "raycast", py::arg("rays") = py::none(),
          py::arg("receiver_samples") = 0, py::arg("hemicube_res") = 256, py::arg("hemicube_jitter") = false,
          py::arg("seed") = 1, py::arg("max_matrix_mb") = 2048, py::arg("gather") = "vertices",
          py::arg("residuals") = false, py::arg("reference") = py::none(), py::arg("adaptive") = false,
          py::arg("target_error") = py::none(), py::arg("max_patches") = py::none(), py::arg("link_epsilon") = 0.1,
          py::arg("power_epsilon") = py::none(), py::arg("refine_rounds") = HierarchicalOptions{}.refine_rounds,
          py::arg("max_level") = 4, py::arg("clustering") = true, py::arg("display_tolerance") = py::none(),
          py::arg("progress") = py::none(),
          "Radiosity of the scene, as `bounce solve` computes it with the same options (the keywords are its "
          "flags: solver shooting, gauss-seidel, jacobi, direct or hierarchical; form_factors raycast, exact, "
          "analytic or hemicube; gather vertices, centres or none; adaptive=True for --adaptive, the hierarchical "
          "solver with power_epsilon 1e-5 unless given; target_error and max_patches are retired and refused; "
          "display_tolerance, hierarchical only, above 0 splits elements for display where linear interpolation of "
          "the point data would miss the gathered light: 0.0025 with adaptive, else 0 (off), unless given). "
          "Unset, tolerance is 1e-3 (shooting: the largest relative error of a patch that the light still unshot "
          "would add, as estimated from the convergence; hierarchical: 1e-6, the largest change of an element per "
          "iteration relative to the mean), max_iterations none for shooting (it stops as stalled when the unshot "
          "power stops falling) or 10000 sweeps (hierarchical: 1000), max_seconds none, sor 1, "
          "overshoot off, cache_mb 1024; max_seconds, sor, overshoot and cache_mb are refused with adaptive or "
          "hierarchical. "
          "residuals=True builds the matrix for shooting too, so its history has residuals; reference (N x 3) "
          "adds the error columns. progress(bounce.Progress) is called up to 20 times a second; Ctrl-C raises "
          "KeyboardInterrupt within a shot or sweep.");
    m.def("reference", &reference, py::arg("scene"), py::arg("points") = py::none(), py::arg("normals") = py::none(),
          py::kw_only(), py::arg("probes") = 0, py::arg("target_error") = 0.005,
          py::arg("max_paths") = double(std::uint64_t(1) << 20), py::arg("seed") = 1, py::arg("skip_missing") = false,
          py::arg("probe_mix") = "classes", py::arg("progress") = py::none(),
          "The path-traced reference, as `bounce reference` computes it: at `probes` points (probe_mix 'classes': "
          "a quarter each lit, penumbra, unlit and contact; 'area': spread by area), or "
          "at the given points (M x 3, with their normals M x 3, snapped to the surface they face). A dict of "
          "position, normal, surface, radiosity and standard_error (M x 3), paths, status ('converged', "
          "'budget', 'interrupted' or, with skip_missing, 'missing' with NaN values) and, for probes by class, "
          "class.");
    m.def("solver_names", &solver_names);
    m.def("form_factor_methods", &form_factor_methods);
    m.def("gather_modes", &gather_modes);
    m.def("visibility_backends", &visibility_backends);
}

}  // namespace
}  // namespace bounce::python

PYBIND11_MODULE(_bounce, m) {
    using namespace bounce;
    using namespace bounce::python;
    m.doc() = "bounce: progressive-refinement radiosity (the extension inside the package `bounce`)";
    m.attr("__version__") = std::string(kBounceVersion);
    bind_errors_and_progress(m);
    bind_patches(m);
    bind_scene_and_solution(m);
    bind_functions(m);
}
