// SPDX-License-Identifier: MIT
// Private to viewer/: the mirrors and glass as cells of the solution grid, so ParaView and
// `bounce view` show the whole scene, not only the radiosity's diffuse patches.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/scene/specular_faces.h"

class vtkUnstructuredGrid;

namespace bounce {

/// The cell array that tells the cells apart: 0 diffuse patch, 1 mirror, 2 glass (MaterialKind).
inline constexpr const char* kMaterialKindArray = "material_kind";

/// Appends `faces` to a solution grid as cells after the patches' (points shared where faces
/// meet exactly, as the tessellated spheres' do), and adds the int cell array material_kind.
/// Every cell and point array already present grows by zeros for them (no radiosity, emission,
/// reflectance or irradiance: light leaves a mirror or glass by the specular paths the
/// radiosity does not hold), except `area` (the face's area) and `surface` (-1: no diffuse
/// input face). Does nothing when `faces` is empty, so a diffuse scene's grid is unchanged.
void add_specular_cells(vtkUnstructuredGrid* grid, const std::vector<SpecularFace>& faces);

/// The display colour (8-bit sRGB) a specular cell of this material_kind gets in display_rgb:
/// a light grey for mirrors, a pale blue for glass.
std::vector<std::uint8_t> specular_tint(int kind);

}  // namespace bounce
