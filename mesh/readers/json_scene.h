// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>

#include "mesh/scene/scene.h"

namespace bounce {

/// Reads a JSON scene that places objects with materials and transforms:
///
///     { "name": "...",
///       "materials": { "white": { "reflectance": [0.7,0.7,0.7], "emission": [0,0,0] } },
///       "objects": [ { "type": "quad" | "box" | "mesh", "file": "x.obj|.ply|.off",
///                      "material": "white", "flip": false, "inward": false,
///                      "transform": { "scale": [..], "rotate": {"axis": [..], "degrees": d},
///                                     "translate": [..] }  or  { "matrix": [16 numbers, row-major] } } ] }
///
/// quad: the unit square [-0.5,0.5]^2 in z = 0 facing +z. box: the unit cube [-0.5,0.5]^3
/// facing out (or in, with "inward"). The transform is T = translate * rotate * scale.
/// Unknown keys are errors. Throws InputError naming the file and the object.
Scene read_json_scene(const std::filesystem::path& path);

/// A .ply or .off file as a scene (OpenMesh's readers): its faces, all white 0.5, with a
/// warning; neither format has materials, so nothing emits (place it from a JSON scene).
Scene read_mesh_scene(const std::filesystem::path& path);

}  // namespace bounce
