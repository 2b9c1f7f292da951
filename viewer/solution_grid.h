// SPDX-License-Identifier: MIT
// Private to viewer/: the solution as a VTK grid, shared by the writer and the renderer.
#pragma once

#include <filesystem>

#include <string>

#include <vtkFieldData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

#include "mesh/meshing/patch_mesh.h"
#include "solver/linear/solve_result.h"
#include "viewer/vtu_writer.h"

namespace bounce {

/// One cell per patch with the arrays and field data write_vtu documents.
vtkSmartPointer<vtkUnstructuredGrid> make_solution_grid(const PatchMesh& mesh, const SolveResult& result,
                                                        const ExportInfo& info);

/// A text field written by write_vtu (a string array, or a char array with text_as_chars).
std::string field_text(vtkFieldData* fd, const char* name);

/// The caption of an unfinished solution (UnfinishedNote): "NOT CONVERGED (status) after N
/// steps, unshot fraction F"; empty when the field data says it converged or says nothing.
std::string unfinished_caption(vtkUnstructuredGrid* g);

/// Reads a .vtu written by bounce (or any .vtu with a 3-component cell array "radiosity");
/// throws InputError naming the file when it is missing, unreadable or lacks the arrays.
vtkSmartPointer<vtkUnstructuredGrid> read_solution_grid(const std::filesystem::path& path);

}  // namespace bounce
