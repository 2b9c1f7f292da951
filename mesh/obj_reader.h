// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>

#include "mesh/scene.h"

namespace bounce {

/// Reads a Wavefront OBJ and the MTL libraries it names. Kd is the diffuse reflectance, Ke
/// the emitted radiosity. Faces with no (or an unknown) material get white 0.5 and a warning.
/// Polygons of any size, negative indices, v/vt/vn forms, comments and odd whitespace load.
/// Throws InputError with "file:line: reason" on malformed input.
Scene read_obj(const std::filesystem::path& path);

}  // namespace bounce
