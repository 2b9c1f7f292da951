// SPDX-License-Identifier: MIT
// bounce.reference: the path tracer at probes or given points.
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "mesh/scene/input_error.h"
#include "python/arguments.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "python/job.h"
#include "python/scene.h"
#include "solver/reference/path_tracer.h"
#include "solver/reference/probe_classes.h"

namespace bounce::python {
namespace {

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

}  // namespace

void bind_reference(py::module_& m) {
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
}

}  // namespace bounce::python
