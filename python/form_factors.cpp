// SPDX-License-Identifier: MIT
// bounce.form_factors and bounce.check_form_factors.
#include <cstdint>
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
#include "solver/form_factors/form_factor_check.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/visibility/visibility.h"

namespace bounce::python {
namespace {

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

}  // namespace

void bind_form_factors(py::module_& m) {
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
}

}  // namespace bounce::python
