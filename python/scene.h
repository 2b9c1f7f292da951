// SPDX-License-Identifier: MIT
// bounce.load, bounce.Scene and bounce.Patches.
#pragma once

#include <memory>
#include <string>

#include <pybind11/pybind11.h>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/scene.h"

namespace bounce::python {

namespace py = pybind11;

/// A loaded scene with the patches load() cut it into, and how.
struct SceneData {
    std::string spec;
    Scene scene;
    MeshingOptions meshing;      // what `mesh` was made with
    bool meshing_given = false;  // patches, max_area or max_edge given to load() (a preset then yields)
    bool flip = false;           // every face turned round on loading
    std::shared_ptr<const PatchMesh> mesh;
    std::string visibility;
};

/// The patches of a scene, or the elements of a solution that refined them.
struct PatchArrays {
    const PatchMesh* mesh;
    py::object owner;  // the Scene or Solution that holds `mesh`: the base of every view
};

/// bounce.Patches, bounce.Scene and load.
void bind_scene(py::module_& m);

}  // namespace bounce::python
