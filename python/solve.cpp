// SPDX-License-Identifier: MIT
// bounce.solve and bounce.Solution: the keywords become a SolveRequest and the solve is
// solver/pipeline's solve_scene, the one `bounce solve` runs, so the two cannot differ.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "mesh/scene/errors.h"
#include "mesh/scene/input_error.h"
#include "python/arguments.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "python/job.h"
#include "python/scene.h"
#include "solver/pipeline/quality.h"
#include "solver/pipeline/solve_scene.h"
#include "viewer/pending_output.h"
#include "viewer/renderer.h"
#include "viewer/vtu_writer.h"

namespace bounce::python {
namespace {

struct SolutionData {
    std::shared_ptr<SceneData> scene;
    // The scene's patches, or for the element solvers the elements they refined them into.
    std::shared_ptr<const PatchMesh> mesh;
    SolveResult result;
    std::string settings;
    std::vector<std::string> warnings, notes;  // as the command line prints them after "warning: ", "note: "
    bool gathered = false;
    double form_factor_seconds = 0.0;  // building the matrix (gathering solvers, or residuals=True)
    std::vector<Rgb> averaged_points;  // the point data when not gathered, as the .vtu has it

    ExportInfo info(bool meshio) const { return ExportInfo{scene->spec, settings, meshio, scene->scene.units}; }
};

using Reference = std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>>;

/// The keywords that are not the solver's or the form factors' into `r`.
void set_refinement(SolveRequest& r, const py::object& target_error, const py::object& max_patches, double link_epsilon,
                    std::optional<double> power_epsilon, int refine_rounds, int max_level, bool clustering,
                    std::optional<double> display_tolerance) {
    if (!target_error.is_none()) r.retired.push_back("target-error");
    if (!max_patches.is_none()) r.retired.push_back("max-patches");
    r.link_epsilon = link_epsilon;
    r.power_epsilon = power_epsilon.value_or(0.0);
    r.refine_rounds = refine_rounds;
    r.max_level = max_level;
    r.clustering = clustering;
    r.display_tolerance = display_tolerance;
}

/// B per patch and channel from an N x 3 array over the scene's patches.
std::vector<Rgb> reference_values(const py::array_t<double, py::array::c_style | py::array::forcecast>& r,
                                  std::size_t patches) {
    if (r.ndim() != 2 || std::size_t(r.shape(0)) != patches || r.shape(1) != 3)
        throw InputError("reference: must be " + std::to_string(patches) + " x 3 (B per patch and channel)");
    std::vector<Rgb> values;
    for (py::ssize_t i = 0; i < r.shape(0); ++i) values.emplace_back(r.at(i, 0), r.at(i, 1), r.at(i, 2));
    return values;
}

/// Runs the pipeline on a worker thread (job.h), reporting its stages as Progress.
std::shared_ptr<SolutionData> run(const std::shared_ptr<SceneData>& s, const SolveRequest& r,
                                  const py::object& progress) {
    Job job;
    SolveHooks hooks;
    hooks.cancel = &job.cancel;
    // load() made the patches of the scene's own meshing; other meshings (the hierarchical
    // solver's coarse roots) are cut anew.
    hooks.mesh = [&s](const MeshingOptions& m) {
        return same_meshing(m, s->meshing) ? s->mesh : std::make_shared<const PatchMesh>(s->scene, m);
    };
    hooks.rows = [&job](std::size_t d, std::size_t t) { job.report_items("form factors", d, t); };
    hooks.solve = [&job](const SolveProgress& p) {
        job.report({"solve", p.step, p.max_steps, p.unshot_fraction, p.tolerance, p.seconds});
    };
    hooks.items = [&job](const char* stage, std::size_t d, std::size_t t) { job.report_items(stage, d, t); };
    // A cancelled job's result is dropped (job.h), so an interrupted solution is not finished
    // (the hierarchical solver's element mesh, for one): the work ends at the stage that saw it.
    hooks.stage_end = [&job] {
        if (job.cancel) throw Interrupted("interrupted");
    };
    SolvedScene solved;
    job.run([&] { solved = solve_scene(s->scene, r, hooks); }, progress);
    auto out = std::make_shared<SolutionData>();
    out->scene = s;
    out->mesh = std::move(solved.mesh);
    out->result = std::move(solved.result);
    out->settings = std::move(solved.settings);
    out->warnings = std::move(solved.warnings);
    out->notes = std::move(solved.notes);
    out->gathered = solved.gathered;
    out->form_factor_seconds = solved.form_factor_seconds;
    if (!out->gathered) out->averaged_points = area_weighted_vertex_values(*out->mesh, out->result.radiosity);
    return out;
}

std::shared_ptr<SolutionData> solve(
    const std::shared_ptr<SceneData>& s, const std::string& solver, std::optional<double> tolerance,
    std::optional<std::int64_t> max_iterations, std::optional<double> max_seconds, std::optional<double> sor,
    std::optional<bool> overshoot, std::optional<std::size_t> cache_mb, const std::string& method,
    std::optional<int> rays, int receiver_samples, int hemicube_res, bool hemicube_jitter, std::uint64_t seed,
    std::size_t max_matrix_mb, const std::string& gather, bool residuals, bool whole_patches, bool balance,
    const Reference& reference, bool adaptive, const py::object& target_error, const py::object& max_patches,
    double link_epsilon, std::optional<double> power_epsilon, int refine_rounds, int max_level, bool clustering,
    std::optional<double> display_tolerance, const std::optional<std::string>& quality, const py::object& progress) {
    const OptionNames names = OptionNames::python();
    SolveRequest r;
    r.meshing = s->meshing;
    r.visibility = s->visibility;
    r.flip = s->flip;
    r.solver = parse_solver_kind(solver, names);
    r.adaptive = adaptive;
    r.tolerance = tolerance;
    if (max_iterations) check_range("max_iterations", double(*max_iterations), 0, 1e15);
    r.max_iterations = std::size_t(max_iterations.value_or(0));
    r.max_seconds = max_seconds;
    r.sor = sor;
    r.overshoot = overshoot;
    r.cache_mb = cache_mb;
    r.max_matrix_mb = max_matrix_mb;
    r.residuals = residuals;
    r.open_parts = !whole_patches;
    r.balance = balance;
    r.method = parse_form_factor_method(method, names);
    if (rays) check_range("rays", *rays, 1, 4096);  // 0 is the request's "the method's default"
    r.form_factors.visibility_rays = rays.value_or(0);
    r.form_factors.receiver_samples = receiver_samples;
    r.form_factors.hemicube_resolution = hemicube_res;
    r.form_factors.hemicube_jitter = hemicube_jitter;
    r.form_factors.seed = seed;
    r.gather = parse_gather_mode(gather, names);
    set_refinement(r, target_error, max_patches, link_epsilon, power_epsilon, refine_rounds, max_level, clustering,
                   display_tolerance);
    if (quality) r.quality = parse_quality(*quality, names);
    apply_quality(r, s->meshing_given);
    if (reference) r.reference = std::vector<Rgb>();  // validated before it is read
    r.validate(names);
    if (reference) r.reference = reference_values(*reference, s->mesh->size());
    return run(s, r, progress);
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

/// bounce.Solution.
void bind_solution(py::module_& m) {
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
        .def_readonly("warnings", &SolutionData::warnings,
                      "likely mistakes in the input or the settings, one line each, as `bounce solve` prints them "
                      "after 'warning: ' (the package's bounce.solve issues them as Python warnings)")
        .def_readonly("notes", &SolutionData::notes,
                      "what was done differently from what was asked (the point data averaged, not gathered)")
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

}  // namespace

void bind_solve(py::module_& m) {
    bind_solution(m);
    m.def("solve", &solve, py::arg("scene"), py::kw_only(), py::arg("solver") = "shooting",
          py::arg("tolerance") = py::none(), py::arg("max_iterations") = py::none(),
          py::arg("max_seconds") = py::none(), py::arg("sor") = py::none(), py::arg("overshoot") = py::none(),
          py::arg("cache_mb") = py::none(), py::arg("form_factors") = "raycast", py::arg("rays") = py::none(),
          py::arg("receiver_samples") = 0, py::arg("hemicube_res") = 256, py::arg("hemicube_jitter") = false,
          py::arg("seed") = 1, py::arg("max_matrix_mb") = 2048, py::arg("gather") = "vertices",
          py::arg("residuals") = false, py::arg("whole_patches") = false, py::arg("balance") = true,
          py::arg("reference") = py::none(), py::arg("adaptive") = false, py::arg("target_error") = py::none(),
          py::arg("max_patches") = py::none(), py::arg("link_epsilon") = 0.1, py::arg("power_epsilon") = py::none(),
          py::arg("refine_rounds") = HierarchicalOptions{}.refine_rounds, py::arg("max_level") = 4,
          py::arg("clustering") = true, py::arg("display_tolerance") = py::none(), py::arg("quality") = py::none(),
          py::arg("progress") = py::none(),
          "Radiosity of the scene, as `bounce solve` computes it with the same options (the keywords are its "
          "flags: solver shooting, gauss-seidel, jacobi, direct or hierarchical; form_factors raycast, exact, "
          "analytic or hemicube; gather vertices, centres or none; adaptive=True for --adaptive, the hierarchical "
          "solver with power_epsilon 1e-5 unless given; target_error and max_patches are retired and refused; "
          "display_tolerance above 0 splits cells for display where linear interpolation of the point data would "
          "miss the gathered light (the solution is then over the display cells, each patch's power kept): 0.02 "
          "for the patch solvers, 0.0025 with adaptive, 0 for hierarchical, unless given; quality draft, default "
          "or fine, the presets of --quality: the patch count (unless load() was given patches, max_area or "
          "max_edge; the scene is then cut anew) and display cells, unless given; whole_patches=True for "
          "--whole-patches, whole patches (and elements) rather than their parts open to the scene; "
          "balance=False for --no-balance, the form-factor rows as sampled rather than balanced). "
          "Unset, tolerance is 1e-3 (shooting: the largest relative error of a patch that the light still unshot "
          "would add, as estimated from the convergence; hierarchical: 1e-6, the largest change of an element per "
          "iteration relative to the mean), max_iterations none for shooting (it stops as stalled when the unshot "
          "power stops falling) or 10000 sweeps (hierarchical: 1000), max_seconds none, sor 1, "
          "overshoot off, cache_mb 1024; max_seconds, sor, overshoot and cache_mb are refused with adaptive or "
          "hierarchical. "
          "residuals=True builds the matrix for shooting too, so its history has residuals; reference (N x 3) "
          "adds the error columns. progress(bounce.Progress) is called up to 20 times a second; Ctrl-C raises "
          "KeyboardInterrupt within a shot or sweep.");
}

}  // namespace bounce::python
