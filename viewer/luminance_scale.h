// SPDX-License-Identifier: MIT
// Private to viewer/: the luminance colour scale (render --luminance, the ParaView script's
// luminance map), ranged over what the picture shows rather than over the whole scene.
#pragma once

#include <string>

#include "viewer/camera.h"

class vtkUnstructuredGrid;

namespace bounce {

/// Adds (or replaces) the point array `luminance` (Rec. 709 of the point array `radiosity`);
/// false, adding nothing, when the grid has no 3-component point radiosity.
bool add_point_luminance(vtkUnstructuredGrid* grid);

/// The top of the luminance colour scale for a picture taken from `pose` (aspect = width /
/// height): the area-weighted 99th percentile of the luminance over the cells that do not emit
/// and that face the camera inside its view (the point data at their corners when `points`,
/// else the cell array `luminance`). A light, or a bright face the camera cannot see (a block's
/// top above the eye), would otherwise set the top and leave every visible wall in one colour;
/// the few brighter places saturate. Falls back to every non-emitting cell when none faces the
/// camera, and to 1 when all are black.
double luminance_scale_top(vtkUnstructuredGrid* grid, const CameraPose& pose, double aspect, bool points);

/// The colour bar's unit: "W per mm^2" from the grid's field `units`, "W per unit area" when
/// the file does not say (a scene without a known length unit).
std::string luminance_unit(vtkUnstructuredGrid* grid);

}  // namespace bounce
