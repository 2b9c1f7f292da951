// SPDX-License-Identifier: MIT
// _bounce, the extension inside the Python package `bounce` (python/bounce/__init__.py):
// scenes, form factors and solutions as numpy arrays, over the same mesh, solver and viewer
// libraries as the command line. Every long call runs on a worker thread with the GIL
// released while the calling thread polls for Ctrl-C and reports progress (job.h).
#include <sstream>
#include <string>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "mesh/scene/errors.h"
#include "python/bindings.h"
#include "python/job.h"
#include "python/scene.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/gather/point_values.h"
#include "solver/linear/solver.h"
#include "solver/visibility/visibility.h"
#include "viewer/version.h"

namespace bounce::python {
namespace {

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

}  // namespace
}  // namespace bounce::python

PYBIND11_MODULE(_bounce, m) {
    using namespace bounce;
    using namespace bounce::python;
    m.doc() = "bounce: progressive-refinement radiosity (the extension inside the package `bounce`)";
    m.attr("__version__") = std::string(kBounceVersion);
    bind_errors_and_progress(m);
    bind_scene(m);
    bind_form_factors(m);
    bind_solve(m);
    bind_reference(m);
    m.def("solver_names", &solver_names);
    m.def("form_factor_methods", &form_factor_methods);
    m.def("gather_modes", &gather_modes);
    m.def("visibility_backends", &visibility_backends);
}
