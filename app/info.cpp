// SPDX-License-Identifier: MIT
// bounce info: the scene's surfaces, patches, area and emitted power.
#include <iostream>

#include "app/command.h"
#include "mesh/patch_mesh.h"

namespace bounce::app {
namespace {

int run_info(const CommonOptions& o) {
    Scene scene;
    PatchMesh mesh = load_and_mesh(o, o.scene, scene);
    const Rgb e = mesh.emitted_power();
    std::cout << "scene:          " << scene.name << "\n"
              << "surfaces:       " << scene.surfaces.size() << "\n"
              << "materials:      " << scene.materials.size() << "\n"
              << "patches:        " << mesh.size() << " (edge " << mesh.edge_length() << ")\n"
              << "total area:     " << mesh.total_area() << "\n"
              << "emitted power:  " << e.to_string() << "\n"
              << "warnings:       " << scene.warnings.size() << "\n";
    return 0;
}

}  // namespace

Command add_info_command(CLI::App& app, CommonOptions& common) {
    auto* info_cmd = app.add_subcommand("info", "print the scene's surfaces, patches, area and emitted power");
    add_meshing_options(info_cmd, common);
    return {info_cmd, [&common] { return run_info(common); }};
}

}  // namespace bounce::app
