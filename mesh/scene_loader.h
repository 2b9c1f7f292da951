// SPDX-License-Identifier: MIT
#pragma once

#include <string>

#include "mesh/scene.h"

namespace bounce {

/// Loads a scene by name: "cornell" (the built-in box), a .obj or a .json file. Validates
/// materials and coordinates and checks the geometry (see check_geometry). Throws InputError.
Scene load_scene(const std::string& spec);

/// What every caller may ask of a load beyond the file itself.
struct LoadOptions {
    bool flip = false;    // turn every face round (scenes wound clockwise seen from the front)
    bool strict = false;  // a warning about the input is an error
};

/// load_scene, then the options: with flip the covered regions are found again (what no light
/// reaches depends on which way the faces look); with strict the first warning is thrown as
/// InputError, marked "(--strict)".
Scene load_scene(const std::string& spec, const LoadOptions& options);

}  // namespace bounce
