// SPDX-License-Identifier: MIT
#pragma once

#include <string>

#include "mesh/scene.h"

namespace bounce {

/// Loads a scene by name: "cornell" (the built-in box), a .obj or a .json file. Validates
/// materials and coordinates and checks the geometry (see check_geometry). Throws InputError.
Scene load_scene(const std::string& spec);

}  // namespace bounce
