// SPDX-License-Identifier: MIT
#include "viewer/solution_reader.h"

#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <string>
#include <unordered_map>

#include <glm/geometric.hpp>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>

#include "mesh/scene/input_error.h"
#include "viewer/solution_grid.h"
#include "viewer/specular_cells.h"

namespace bounce {
namespace {

/// An array of `data` named `name` with `components` components and `tuples` tuples; null when
/// the file has none of that shape.
vtkDataArray* array_of(vtkFieldData* data, const char* name, int components, vtkIdType tuples) {
    vtkDataArray* a = data->GetArray(name);
    return a && a->GetNumberOfComponents() == components && a->GetNumberOfTuples() == tuples ? a : nullptr;
}

Rgb rgb_at(vtkDataArray* a, vtkIdType i) {
    if (!a) return {};
    double v[3];
    a->GetTuple(i, v);
    return {v[0], v[1], v[2]};
}

std::optional<Rgb> field_rgb(vtkFieldData* fd, const char* name) {
    vtkDataArray* a = array_of(fd, name, 3, 1);
    return a ? std::optional<Rgb>(rgb_at(a, 0)) : std::nullopt;
}

/// The polygon's corners: its points less those on the segment between their neighbours (the
/// points a conforming mesh puts on an element's edge where smaller neighbours meet it). A point
/// counts as on the segment within `tolerance` of it, plus a millionth of the segment's length.
std::vector<glm::dvec3> corners_of(std::vector<glm::dvec3> v, double tolerance) {
    for (bool removed = true; removed && v.size() > 3;) {
        removed = false;
        for (std::size_t k = 0; k < v.size() && !removed; ++k) {
            const glm::dvec3 a = v[(k + v.size() - 1) % v.size()], b = v[k], c = v[(k + 1) % v.size()];
            const glm::dvec3 ac = c - a;
            const double length = glm::length(ac);
            if (!(length > 0)) continue;
            const double along = glm::dot(b - a, ac) / (length * length);
            const double off = glm::length(glm::cross(b - a, ac)) / length;
            if (along > 0 && along < 1 && off <= tolerance + 1e-6 * length) {
                v.erase(v.begin() + std::ptrdiff_t(k));
                removed = true;
            }
        }
    }
    return v;
}

/// The patch a cell with these points displays: its corners, Newell normal, area and area
/// centroid. Throws InputError when it is not a triangle or a quad with an area.
Patch patch_of(const std::vector<glm::dvec3>& points, double tolerance, const std::string& where) {
    const std::vector<glm::dvec3> corners = corners_of(points, tolerance);
    if (corners.size() < 3 || corners.size() > 4)
        throw InputError(where + " has " + std::to_string(corners.size()) +
                         " corners (expected a triangle or a quad, with points along its edges)");
    glm::dvec3 newell(0.0);
    for (std::size_t k = 0; k < points.size(); ++k) newell += glm::cross(points[k], points[(k + 1) % points.size()]);
    const double twice_area = glm::length(newell);
    if (!(twice_area > 0) || !std::isfinite(twice_area)) throw InputError(where + " has no area");
    Patch p;
    p.vertex_count = int(corners.size());
    for (std::size_t k = 0; k < corners.size(); ++k) p.vertices[k] = corners[k];
    p.normal = newell / twice_area;
    p.area = 0.5 * twice_area;
    // Area centroid: the fan triangles' centroids weighted by their areas along the normal.
    glm::dvec3 sum(0.0);
    double weight = 0.0;
    for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        const double w = glm::dot(glm::cross(corners[k] - corners[0], corners[k + 1] - corners[0]), p.normal);
        sum += w * (corners[0] + corners[k] + corners[k + 1]) / 3.0;
        weight += w;
    }
    p.centre = weight > 0 ? sum / weight : corners[0];
    return p;
}

/// The diffuse cells as faces over the points they use (numbered anew) and their patches.
struct CellFaces {
    std::vector<Patch> patches;
    std::vector<Rgb> radiosity;
    std::vector<glm::dvec3> points;
    std::vector<vtkIdType> source;  // per point: its id in the file
    std::vector<std::vector<std::uint32_t>> faces;
    std::size_t skipped = 0;
};

CellFaces diffuse_faces(vtkUnstructuredGrid* grid, const std::string& file) {
    const vtkIdType cells = grid->GetNumberOfCells();
    vtkCellData* cd = grid->GetCellData();
    vtkDataArray* radiosity = array_of(cd, "radiosity", 3, cells);
    vtkDataArray* reflectance = array_of(cd, "reflectance", 3, cells);
    vtkDataArray* emission = array_of(cd, "emission", 3, cells);
    vtkDataArray* surface = array_of(cd, "surface", 1, cells);
    vtkDataArray* kind = array_of(cd, kMaterialKindArray, 1, cells);
    double bounds[6];
    grid->GetBounds(bounds);
    // Well above the weld of a conforming mesh (1e-9 of the scene's size), far below any cell.
    const double tolerance =
        1e-8 * glm::length(glm::dvec3(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]));
    CellFaces out;
    std::unordered_map<vtkIdType, std::uint32_t> index;
    vtkNew<vtkIdList> ids;
    std::vector<glm::dvec3> polygon;
    for (vtkIdType c = 0; c < cells; ++c) {
        if (kind && kind->GetTuple1(c) != 0) {
            ++out.skipped;
            continue;
        }
        grid->GetCellPoints(c, ids);
        polygon.clear();
        out.faces.emplace_back();
        for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k) {
            const vtkIdType id = ids->GetId(k);
            double x[3];
            grid->GetPoint(id, x);
            polygon.emplace_back(x[0], x[1], x[2]);
            const auto [it, added] = index.try_emplace(id, std::uint32_t(out.points.size()));
            if (added) {
                out.points.push_back(polygon.back());
                out.source.push_back(id);
            }
            out.faces.back().push_back(it->second);
        }
        Patch p = patch_of(polygon, tolerance, file + ": cell " + std::to_string(c));
        p.reflectance = rgb_at(reflectance, c);
        p.emission = rgb_at(emission, c);
        p.surface = surface ? int(surface->GetTuple1(c)) : 0;
        out.patches.push_back(p);
        out.radiosity.push_back(rgb_at(radiosity, c));
    }
    return out;
}

/// The file's point values on the rebuilt mesh's vertices: each vertex is a copy of one point
/// of the file (the mesh may copy a point where the cells around it do not form one fan, and
/// numbers its vertices anew), found among its face's points by position.
std::vector<Rgb> vertex_values(const PatchMesh& mesh, const CellFaces& f, vtkDataArray* values) {
    std::vector<Rgb> out(mesh.mesh().n_vertices());
    for (std::size_t i = 0; i < f.faces.size(); ++i)
        for (const int v : mesh.patch_vertex_indices(i)) {
            const glm::dvec3 x = mesh.vertex_position(std::size_t(v));
            double best = std::numeric_limits<double>::infinity();
            for (const std::uint32_t q : f.faces[i])
                if (const double d = glm::length(f.points[q] - x); d < best) {
                    best = d;
                    out[std::size_t(v)] = rgb_at(values, f.source[q]);
                }
        }
    return out;
}

}  // namespace

SolutionFile read_solution(const std::filesystem::path& path) {
    const auto grid = read_solution_grid(path);
    const std::string file = path.string();
    CellFaces f = diffuse_faces(grid, file);
    if (f.patches.empty()) throw InputError(file + ": no diffuse cells (every cell is a mirror or glass)");
    std::optional<PatchMesh> mesh;
    try {
        mesh.emplace(f.patches, f.points, f.faces);
    } catch (const std::exception& e) {  // OpenMesh refused a face: not a surface mesh
        throw InputError(file + ": the cells do not form a mesh (" + e.what() + ")");
    }
    vtkDataArray* points = array_of(grid->GetPointData(), "radiosity", 3, grid->GetNumberOfPoints());
    std::vector<Rgb> at_vertex = points ? vertex_values(*mesh, f, points) : std::vector<Rgb>{};
    vtkFieldData* fd = grid->GetFieldData();
    return SolutionFile{std::move(*mesh),
                        std::move(f.radiosity),
                        std::move(at_vertex),
                        field_rgb(fd, "emitted_power"),
                        field_rgb(fd, "escaped_power"),
                        f.skipped,
                        unfinished_caption(grid)};
}

}  // namespace bounce
