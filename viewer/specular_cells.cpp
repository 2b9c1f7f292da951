// SPDX-License-Identifier: MIT
#include "viewer/specular_cells.h"

#include <array>
#include <map>

#include <glm/geometric.hpp>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>

namespace bounce {
namespace {

/// Area of a planar polygon (half the length of Newell's normal).
double polygon_area(const std::vector<glm::dvec3>& v) {
    glm::dvec3 n(0.0);
    for (std::size_t k = 0; k < v.size(); ++k) n += glm::cross(v[k], v[(k + 1) % v.size()]);
    return 0.5 * glm::length(n);
}

/// Appends `count` zero tuples to every array of `data`.
void append_zeros(vtkFieldData* data, vtkIdType count) {
    for (int a = 0; a < data->GetNumberOfArrays(); ++a) {
        vtkDataArray* array = data->GetArray(a);
        if (!array) continue;
        const std::vector<double> zero(std::size_t(array->GetNumberOfComponents()), 0.0);
        for (vtkIdType k = 0; k < count; ++k) array->InsertNextTuple(zero.data());
    }
}

}  // namespace

std::vector<std::uint8_t> specular_tint(int kind) {
    if (kind == int(MaterialKind::glass)) return {165, 205, 225};
    return {195, 195, 200};
}

void add_specular_cells(vtkUnstructuredGrid* grid, const std::vector<SpecularFace>& faces) {
    if (faces.empty()) return;
    vtkPoints* points = grid->GetPoints();
    const vtkIdType diffuse_cells = grid->GetNumberOfCells();
    const vtkIdType diffuse_points = points->GetNumberOfPoints();
    std::map<std::array<double, 3>, vtkIdType> index;
    std::vector<vtkIdType> cell;
    for (const auto& f : faces) {
        cell.clear();
        for (const auto& p : f.vertices) {
            const std::array<double, 3> key{p.x, p.y, p.z};
            auto [it, added] = index.try_emplace(key, points->GetNumberOfPoints());
            if (added) points->InsertNextPoint(key.data());
            cell.push_back(it->second);
        }
        const int type = cell.size() == 3 ? VTK_TRIANGLE : (cell.size() == 4 ? VTK_QUAD : VTK_POLYGON);
        grid->InsertNextCell(type, vtkIdType(cell.size()), cell.data());
    }
    vtkCellData* cd = grid->GetCellData();
    append_zeros(cd, vtkIdType(faces.size()));
    append_zeros(grid->GetPointData(), points->GetNumberOfPoints() - diffuse_points);
    vtkDataArray* area = cd->GetArray("area");
    vtkDataArray* surface = cd->GetArray("surface");
    vtkNew<vtkIntArray> kind;
    kind->SetName(kMaterialKindArray);
    kind->SetNumberOfTuples(grid->GetNumberOfCells());
    for (vtkIdType c = 0; c < diffuse_cells; ++c) kind->SetValue(c, int(MaterialKind::diffuse));
    for (std::size_t k = 0; k < faces.size(); ++k) {
        const vtkIdType c = diffuse_cells + vtkIdType(k);
        kind->SetValue(c, int(faces[k].kind));
        if (area) area->SetTuple1(c, polygon_area(faces[k].vertices));
        if (surface) surface->SetTuple1(c, -1);
    }
    cd->AddArray(kind);
}

}  // namespace bounce
