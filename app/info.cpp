// SPDX-License-Identifier: MIT
// bounce info: the scene's surfaces, patches, area and emitted power.
#include <iostream>
#include <vector>

#include "app/command.h"
#include "mesh/patch_mesh.h"
#include "mesh/polygon.h"

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
    // The surfaces themselves, as --help promises: where each came from, its material, area
    // and patches.
    std::vector<std::size_t> patches(scene.surfaces.size(), 0);
    for (const auto& p : mesh.patches()) ++patches[std::size_t(p.surface)];
    // Contact cuts (mesh/contact_cuts.h): the area no light reaches, left out of the patches.
    std::vector<double> removed(scene.surfaces.size(), 0.0);
    if (o.meshing.cut_contacts)
        for (const auto& c : scene.covered) removed[std::size_t(c.surface)] += polygon_area(c.polygon);
    std::cout << "surface  patches  area  removed  material  where\n";
    for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
        const Surface& f = scene.surfaces[s];
        const Material& m = scene.materials[std::size_t(f.material)];
        std::cout << s << "  " << patches[s] << "  " << polygon_area(f.vertices) << "  " << removed[s] << "  " << m.name
                  << (m.emission.max() > 0 ? " (emits " + m.emission.to_string() + ")" : "") << "  "
                  << describe(f.where, f.object) << "\n";
    }
    return 0;
}

}  // namespace

Command add_info_command(CLI::App& app, CommonOptions& common) {
    auto* info_cmd = app.add_subcommand(
        "info", "print the scene's summary, then every surface: patches, area, material and where it came from");
    add_meshing_options(info_cmd, common);
    return {info_cmd, [&common] { return run_info(common); }};
}

}  // namespace bounce::app
