// SPDX-License-Identifier: MIT
#include "python/scene.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "mesh/readers/scene_loader.h"
#include "python/arguments.h"
#include "python/arrays.h"
#include "python/job.h"
#include "solver/visibility/visibility.h"

namespace bounce::python {
namespace {

std::shared_ptr<SceneData> load(const std::filesystem::path& scene_path, std::optional<std::int64_t> patches,
                                double max_area, double max_edge, bool subdivide, bool contact_cuts, bool flip,
                                bool strict, const std::string& visibility) {
    if (patches) check_range("patches", double(*patches), 1, 1e8);
    if (max_area != 0) check_positive("max_area", max_area);
    if (max_edge != 0) check_positive("max_edge", max_edge);
    check_member("visibility", visibility, visibility_backends());
    const std::string spec = scene_path.string();
    auto d = std::make_shared<SceneData>();
    d->spec = spec;
    d->visibility = visibility;
    d->flip = flip;
    MeshingOptions& m = d->meshing;
    if (patches) m.target_patches = std::size_t(*patches);
    d->meshing_given = patches || max_area != 0 || max_edge != 0;
    m.max_area = max_area;
    m.max_edge = max_edge;
    m.subdivide = subdivide;
    m.cut_contacts = contact_cuts;
    Job job;
    job.run(
        [&] {
            d->scene = load_scene(spec, LoadOptions{flip, strict, {}});
            d->mesh = std::make_shared<const PatchMesh>(d->scene, m);
        },
        py::none());
    return d;
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

}  // namespace

void bind_scene(py::module_& m) {
    bind_patches(m);
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
    m.def("load", &load, py::arg("scene") = "cornell", py::kw_only(), py::arg("patches") = py::none(),
          py::arg("max_area") = 0.0, py::arg("max_edge") = 0.0, py::arg("subdivide") = true,
          py::arg("contact_cuts") = true, py::arg("flip") = false, py::arg("strict") = false,
          py::arg("visibility") = visibility_backends().front(),
          "The scene cut into patches (the package's bounce.load wraps this and issues the warnings).");
}

}  // namespace bounce::python
