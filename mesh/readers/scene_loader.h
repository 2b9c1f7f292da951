// SPDX-License-Identifier: MIT
#pragma once

#include <string>

#include "mesh/geometry/contact_cuts.h"

#include "mesh/scene/scene.h"

namespace bounce {

/// Loads a scene by name: "cornell" (the built-in box), a .obj or a .json file. Validates
/// materials and coordinates, checks the geometry (see check_geometry), finds the covered
/// regions and warns of surfaces that face away from the scene (find_reversed_surfaces).
/// Throws InputError.
Scene load_scene(const std::string& spec);

/// What every caller may ask of a load beyond the file itself.
struct LoadOptions {
    bool flip = false;       // turn every face round (scenes wound clockwise seen from the front)
    bool strict = false;     // a warning about the input is an error
    CoverProgress progress;  // the contact cuts' search (find_covered_regions), if given
};

/// load_scene with the options: with flip every face is turned before the covered regions and
/// the orientation are looked at (both depend on which way the faces look); with strict the first warning is thrown as
/// InputError, marked "(--strict)".
Scene load_scene(const std::string& spec, const LoadOptions& options);

}  // namespace bounce
