// SPDX-License-Identifier: MIT
// Test helper: a scene written again as an OBJ with its MTL, to check that one geometry written
// two ways (JSON shapes placed by transforms, an OBJ of printed decimals) gives one answer.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>

#include "mesh/scene/scene.h"
#include "test_util.h"

namespace bounce::test {

/// Writes the diffuse surfaces of `scene` as NAME.obj and NAME.mtl in `dir`, one OBJ object
/// per input object, each coordinate printed to `digits` significant digits. Returns the OBJ.
inline std::filesystem::path write_scene_as_obj(const Scene& scene, const TempDir& dir, const std::string& name,
                                                int digits) {
    std::string mtl, obj = "mtllib " + name + ".mtl\n";
    char line[256];
    for (std::size_t m = 0; m < scene.materials.size(); ++m) {
        const Material& mat = scene.materials[m];
        std::snprintf(line, sizeof line, "newmtl m%zu\nKd %.17g %.17g %.17g\nKe %.17g %.17g %.17g\n", m,
                      mat.reflectance.r, mat.reflectance.g, mat.reflectance.b, mat.emission.r, mat.emission.g,
                      mat.emission.b);
        mtl += line;
    }
    std::string object = "\n";  // no input object has a newline in its name
    std::size_t next_vertex = 1;
    for (const Surface& s : scene.surfaces) {
        if (s.object != object) {
            object = s.object;
            obj.append("o ").append(object).append("\n");
        }
        obj += "usemtl m" + std::to_string(s.material) + "\n";
        for (const auto& v : s.vertices) {
            std::snprintf(line, sizeof line, "v %.*g %.*g %.*g\n", digits, v.x, digits, v.y, digits, v.z);
            obj += line;
        }
        obj += "f";
        for (std::size_t k = 0; k < s.vertices.size(); ++k) {
            std::snprintf(line, sizeof line, " %zu", next_vertex++);
            obj += line;
        }
        obj += "\n";
    }
    dir.write(name + ".mtl", mtl);
    return dir.write(name + ".obj", obj);
}

}  // namespace bounce::test
