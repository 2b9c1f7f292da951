// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>
#include <string>

#include "mesh/meshing/patch_mesh.h"
#include "solver/linear/solve_result.h"

namespace bounce {

/// What the exporter records about the run in the file's field data.
struct ExportInfo {
    std::string scene;           // scene name or path
    std::string settings;        // free text: meshing and form-factor settings
    bool text_as_chars = false;  // text fields as Int8 char arrays (meshio reads them; ParaView shows numbers)
    std::string units{};         // the scene's length unit ("mm"); empty: unknown (no field written)
};

/// Writes a VTK XML unstructured grid (.vtu) with one cell per patch.
/// Cell data: radiosity (RGB), emission (RGB), reflectance (RGB), irradiance (RGB),
/// luminance (Rec. 709 of radiosity), display_rgb (uint8 RGB: the picture of `bounce render
/// --flat` at exposure 0, for ParaView with Map Scalars off), area, surface (input face id), and
/// radiosity_gathered when the result holds values gathered at the patch centres. Point data (one
/// point per mesh vertex, each a corner of some cell): radiosity gathered at each vertex when the
/// result holds it (result.point_radiosity), else averaged over the patches around each vertex,
/// weighted by area, and its display_rgb (the default picture of `bounce render` and of the
/// `--paraview` script).
/// When the mesh carries mirrors or glass (PatchMesh::specular_faces), they follow the patches
/// as cells of their own, flagged by the int cell array material_kind (0 diffuse patch, 1
/// mirror, 2 glass), with zero radiosity, emission, reflectance and irradiance, surface -1 and
/// display_rgb a fixed tint; without them there is no material_kind array and the file is what
/// it was before specular objects existed.
/// Field data: the text fields scene, solver, form_factors, settings, version, status (VTK
/// string arrays, which ParaView shows as text; Int8 char arrays with info.text_as_chars, since
/// meshio rejects the String type), steps, unshot_fraction, converged, residual, seconds, and the
/// powers emitted/absorbed/escaped/unshot (RGB).
/// Written to a temporary file beside `path`, then renamed: a failed write never leaves a
/// partial file. Throws std::runtime_error naming the path.
void write_vtu(const std::filesystem::path& path, const PatchMesh& mesh, const SolveResult& result,
               const ExportInfo& info, bool ascii = false);

}  // namespace bounce

class vtkUnstructuredGrid;

namespace bounce {
/// Writes any grid as .vtu the same way (temporary file, then rename).
void write_grid(const std::filesystem::path& path, vtkUnstructuredGrid* grid, bool ascii = false);
}  // namespace bounce
