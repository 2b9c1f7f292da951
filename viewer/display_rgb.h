// SPDX-License-Identifier: MIT
// Private to viewer/: the picture's colours as data, shared by the writer and the renderer.
#pragma once

class vtkUnstructuredGrid;

namespace bounce {

/// Adds (or replaces) the uint8 RGB arrays `display_rgb` in the cell data (from the cell
/// array `radiosity`) and, when the point data holds a 3-component `radiosity`, in the point
/// data: the tone map of `bounce render` (ToneMap::automatic over the non-emitting cells,
/// exposure ev in EV), so ParaView shows the rendered picture with Map Scalars off. Cells with
/// a nonzero material_kind (mirrors, glass) stay out of the exposure and get their tint
/// (specular_tint), their corners too.
void add_display_rgb(vtkUnstructuredGrid* grid, double ev);

}  // namespace bounce
