// SPDX-License-Identifier: MIT
// Private to viewer/: how the VTK window and picture draw the mirrors and glass of a solution
// grid (its cells with material_kind > 0) beside the radiosity's patches.
#pragma once

#include <vector>

#include <vtkActor.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

namespace bounce {

struct SpecularSplit {
    vtkSmartPointer<vtkUnstructuredGrid> diffuse;     // the patches, with the grid's field data
    std::vector<vtkSmartPointer<vtkActor>> specular;  // one actor per kind present: mirror, glass
};

/// Splits a grid by its cell array material_kind: the diffuse cells, drawn by their radiosity
/// as before, and the mirror and glass cells as shaded solid actors (a mirror light grey, glass
/// pale blue and translucent: the window shows where they are, not what they reflect or
/// refract). A grid without material_kind comes back whole, with no actors.
SpecularSplit split_specular(vtkUnstructuredGrid* grid);

}  // namespace bounce
