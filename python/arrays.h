// SPDX-License-Identifier: MIT
// numpy arrays over the library's own storage: read-only views whose base keeps the owner alive.
#pragma once

#include <cstddef>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "mesh/scene/rgb.h"

namespace bounce::python {

namespace py = pybind11;

/// Marks an array read-only: it shows the library's own data, which other results depend on.
inline py::array read_only(py::array a) {
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
inline py::array rgb_view(const std::vector<Rgb>& v, py::handle owner) {
    static_assert(sizeof(Rgb) == 3 * sizeof(double));
    return field_view<double>(v.data(), v.size(), sizeof(Rgb), 3, owner);
}

inline py::array rgb_copy(const Rgb& c) {
    py::array_t<double> a(3);
    auto m = a.mutable_unchecked<1>();
    for (int k = 0; k < 3; ++k) m(k) = c[k];
    return a;
}

}  // namespace bounce::python
