// SPDX-License-Identifier: MIT
// The parts of the extension _bounce, one per concern; module.cpp calls them in order.
#pragma once

#include <pybind11/pybind11.h>

namespace bounce::python {

namespace py = pybind11;

void bind_form_factors(py::module_& m);  // form_factors, check_form_factors
void bind_solve(py::module_& m);         // Solution, solve
void bind_reference(py::module_& m);     // reference

}  // namespace bounce::python
