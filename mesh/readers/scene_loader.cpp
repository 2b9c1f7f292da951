// SPDX-License-Identifier: MIT
#include "mesh/readers/scene_loader.h"

#include <algorithm>
#include <filesystem>

#include "mesh/geometry/contact_cuts.h"
#include "mesh/geometry/geometry_check.h"
#include "mesh/geometry/orientation_check.h"
#include "mesh/geometry/surface_tree.h"
#include "mesh/readers/cornell_box.h"
#include "mesh/readers/json_scene.h"
#include "mesh/readers/obj_reader.h"
#include "mesh/scene/coordinate_grid.h"
#include "mesh/scene/input_error.h"

namespace bounce {

namespace {

// Reads, validates and checks the geometry; the covered regions and the orientation wait for
// the flip.
Scene read_scene(const std::string& spec) {
    Scene scene;
    if (spec == "cornell") {
        scene = make_cornell_box();
    } else if (spec == "cornell-spheres") {
        scene = make_cornell_spheres_box();
    } else {
        std::string ext = std::filesystem::path(spec).extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
        if (ext == ".obj") {
            scene = read_obj(spec);
        } else if (ext == ".json") {
            scene = read_json_scene(spec);
        } else if (ext == ".ply" || ext == ".off") {
            scene = read_mesh_scene(spec);
        } else {
            throw InputError(spec + ": unknown scene type, got '" + ext +
                             "' (expected 'cornell', 'cornell-spheres', .obj, .json, .ply or .off)");
        }
    }
    scene.validate();
    snap_coordinates(scene);
    check_geometry(scene, spec);
    return scene;
}

}  // namespace

Scene load_scene(const std::string& spec) { return load_scene(spec, LoadOptions{}); }

Scene load_scene(const std::string& spec, const LoadOptions& options) {
    Scene scene = read_scene(spec);
    if (options.flip)
        for (auto& surface : scene.surfaces) std::reverse(surface.vertices.begin(), surface.vertices.end());
    // One tree serves both searches: it holds the geometry, which the flip does not change.
    const SurfaceTree tree(scene);
    scene.covered = find_covered_regions(scene, tree, options.progress);
    for (const auto& r : find_reversed_surfaces(scene, tree))
        scene.warnings.push_back(reversed_surface_warning(scene, r));
    if (options.strict && !scene.warnings.empty()) throw InputError(scene.warnings.front() + " (--strict)");
    return scene;
}

}  // namespace bounce
