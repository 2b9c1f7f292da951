// SPDX-License-Identifier: MIT
#include "viewer/specular_actors.h"

#include <vtkCellData.h>
#include <vtkDataSetMapper.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkProperty.h>
#include <vtkThreshold.h>

#include "mesh/scene/scene.h"
#include "viewer/specular_cells.h"

namespace bounce {
namespace {

/// The cells whose material_kind is `kind`, as a grid of their own.
vtkSmartPointer<vtkUnstructuredGrid> cells_of_kind(vtkUnstructuredGrid* grid, MaterialKind kind) {
    vtkNew<vtkThreshold> pick;
    pick->SetInputData(grid);
    pick->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_CELLS, kMaterialKindArray);
    pick->SetThresholdFunction(vtkThreshold::THRESHOLD_BETWEEN);
    pick->SetLowerThreshold(double(kind));
    pick->SetUpperThreshold(double(kind));
    pick->Update();
    vtkSmartPointer<vtkUnstructuredGrid> out = pick->GetOutput();
    return out;
}

}  // namespace

SpecularSplit split_specular(vtkUnstructuredGrid* grid) {
    SpecularSplit split;
    if (!grid->GetCellData()->GetArray(kMaterialKindArray)) {
        split.diffuse = grid;
        return split;
    }
    split.diffuse = cells_of_kind(grid, MaterialKind::diffuse);
    split.diffuse->GetFieldData()->ShallowCopy(grid->GetFieldData());
    for (const MaterialKind kind : {MaterialKind::mirror, MaterialKind::glass}) {
        const auto cells = cells_of_kind(grid, kind);
        if (cells->GetNumberOfCells() == 0) continue;
        vtkNew<vtkDataSetMapper> mapper;
        mapper->SetInputData(cells);
        mapper->ScalarVisibilityOff();
        auto actor = vtkSmartPointer<vtkActor>::New();
        actor->SetMapper(mapper);
        const auto tint = specular_tint(int(kind));
        actor->GetProperty()->SetColor(tint[0] / 255.0, tint[1] / 255.0, tint[2] / 255.0);
        // Shaded by the window's headlight, so a sphere reads as round; a highlight for the
        // mirror, see-through glass.
        actor->GetProperty()->SetSpecular(kind == MaterialKind::mirror ? 0.6 : 0.3);
        actor->GetProperty()->SetSpecularPower(40.0);
        actor->GetProperty()->BackfaceCullingOn();
        if (kind == MaterialKind::glass) actor->GetProperty()->SetOpacity(0.4);
        split.specular.push_back(actor);
    }
    return split;
}

}  // namespace bounce
