// SPDX-License-Identifier: MIT
// A written solution read back as the solver held it: the patch mesh, the patches' radiosity
// and the point data, so a .vtu solved long ago can be scored without solving again.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/rgb.h"

namespace bounce {

/// What read_solution rebuilds from a .vtu.
struct SolutionFile {
    PatchMesh mesh;                    // one patch per diffuse cell, in the file's order
    std::vector<Rgb> cell_radiosity;   // per patch: the cell array radiosity
    std::vector<Rgb> point_radiosity;  // per mesh vertex: the point array radiosity; empty without one
    std::optional<Rgb> emitted_power;  // field data, when the file has it
    std::optional<Rgb> escaped_power;  // field data, when the file has it
    std::size_t skipped_cells = 0;     // mirrors and glass (material_kind nonzero), not patches
    std::string unfinished;            // "NOT CONVERGED (status) ..." when the field data says so; else empty
};

/// Reads a .vtu written by `bounce solve` (read_solution_grid's checks first). Every cell whose
/// material_kind is 0, or every cell when the array is absent, becomes a patch: its points form
/// the face (conforming meshes carry extra points on their edges), its corners (the points not
/// collinear with their neighbours, 3 or 4) the Patch, with the cell arrays reflectance,
/// emission and surface (zero when absent). Throws InputError naming the file when a cell is not
/// a triangle or a quad, or the cells do not form a mesh.
SolutionFile read_solution(const std::filesystem::path& path);

}  // namespace bounce
