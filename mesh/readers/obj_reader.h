// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>

#include "mesh/scene/scene.h"

namespace bounce {

/// Reads a Wavefront OBJ and the MTL libraries it names. Kd is the diffuse reflectance, Ke
/// the emitted radiosity; illum 3 and 5 make a mirror of reflectance Ks, illum 6 and 7 glass of
/// index Ni and transmittance Tf (the mapping is documented at finish_material in the .cpp and
/// in docs/guide/specular.md). Faces of mirror or glass go to Scene::specular_surfaces. Faces with no (or an unknown)
/// material get white 0.5 and a warning. Polygons of any size, negative indices, v/vt/vn forms, comments and odd
/// whitespace load. Throws InputError with "file:line: reason" on malformed input. own_materials false: the caller
/// gives every face its material (a JSON scene's `mesh` object with a `material`), so the file's mtllib and usemtl are
/// not read, no material is made and no warning is given about them; every surface's material is -1.
Scene read_obj(const std::filesystem::path& path, bool own_materials = true);

}  // namespace bounce
