// SPDX-License-Identifier: MIT
// bounce info: the scene's surfaces, patches, area and emitted power; with --row-sums, how far
// the form-factor rows of a closed scene are from 1, and how much of that partial visibility
// explains.
#include <algorithm>
#include <array>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/command.h"
#include "app/progress_line.h"
#include "app/signals.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/polygon.h"
#include "solver/form_factors/form_factor_check.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/visibility/shaft_culler.h"
#include "solver/visibility/visibility.h"

namespace bounce::app {
namespace {

struct InfoCommand {
    bool row_sums = false;
    std::string method = "raycast";
    FormFactorOptions ff;
};

/// Rows computed one at a time and summed (memory O(N), unlike `form-factors --check`).
void print_row_sums(const CommonOptions& o, const InfoCommand& c, const std::vector<Patch>& P) {
    check_form_factor_memory(o, c.method, c.ff);
    const auto visibility = make_visibility(o.visibility, P);
    const auto ff = make_form_factor_estimator(c.method, P, visibility.get(), c.ff);
    const ShaftCuller culler(P);
    ProgressLine progress(!o.quiet);
    const FormFactorCheck check = check_row_sums(
        P, *ff, &culler, [&](std::size_t d, std::size_t t) { progress.rows(d, t); }, &g_interrupted);
    progress.finish();
    std::cout << "form factors:   " << c.method << " (" << check.row_sums.size() << " of " << P.size() << " rows)\n"
              << row_sum_report(check);
}

int run_info(const CommonOptions& o, const InfoCommand& c) {
    Scene scene;
    PatchMesh mesh = load_and_mesh(o, o.scene, scene);
    const Rgb e = mesh.emitted_power();
    std::cout << "scene:          " << scene.name << "\n"
              << "surfaces:       " << scene.surfaces.size() << "\n"
              << "materials:      " << scene.materials.size() << "\n"
              << "patches:        " << mesh.size() << " (edge " << mesh.edge_length() << ")\n"
              << "total area:     " << mesh.total_area() << "\n"
              << "emitted power:  " << e.to_string() << "\n"
              << "warnings:       " << scene.warnings.size() + mesh.warnings().size() << "\n";
    // The surfaces themselves, as --help promises: where each came from, its material, area
    // and patches.
    // Contact cuts (mesh/geometry/contact_cuts.h): the area no light reaches, left out of the
    // patches. Measured as the surface's area less its patches', not as the covered regions'
    // sum: regions overlap (a loop and the covers inside it) and a loop may reach past a small
    // surface, so their sum can exceed the surface.
    std::vector<std::size_t> patches(scene.surfaces.size(), 0);
    std::vector<double> kept(scene.surfaces.size(), 0.0);
    for (const auto& p : mesh.patches()) {
        ++patches[std::size_t(p.surface)];
        kept[std::size_t(p.surface)] += p.area;
    }
    // A table: every column as wide as its widest entry, numbers right-aligned, text left.
    std::vector<std::array<std::string, 6>> table = {{"surface", "patches", "area", "removed", "material", "where"}};
    for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
        const Surface& f = scene.surfaces[s];
        const Material& m = scene.materials[std::size_t(f.material)];
        std::ostringstream area, cut;
        const double whole = polygon_area(f.vertices);
        // Below 1e-9 of the surface is the rounding of the patches' corners.
        const double removed = o.meshing.cut_contacts && whole - kept[s] > 1e-9 * whole ? whole - kept[s] : 0.0;
        area << whole;
        cut << removed;
        table.push_back({std::to_string(s), std::to_string(patches[s]), area.str(), cut.str(),
                         m.name + (m.emission.max() > 0 ? " (emits " + m.emission.to_string() + ")" : ""),
                         describe(f.where, f.object)});
    }
    std::array<std::size_t, 6> width{};
    for (const auto& row : table)
        for (std::size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
    for (const auto& row : table) {
        std::ostringstream line;
        for (std::size_t c = 0; c < row.size(); ++c) {
            if (c > 0) line << "  ";
            const bool number = c < 4;
            if (c + 1 == row.size())
                line << row[c];  // the last column unpadded: no trailing spaces
            else
                line << (number ? std::right : std::left) << std::setw(int(width[c])) << row[c];
        }
        std::cout << line.str() << "\n";
    }
    if (c.row_sums) print_row_sums(o, c, mesh.patches());
    return interrupted_exit_code();
}

}  // namespace

Command add_info_command(CLI::App& app, CommonOptions& common) {
    auto* info_cmd = app.add_subcommand(
        "info", "print the scene's summary, then every surface: patches, area, material and where it came from");
    add_meshing_options(info_cmd, common);
    auto ic = std::make_shared<InfoCommand>();
    info_cmd->add_flag("--row-sums", ic->row_sums,
                       "compute every form-factor row and print how far the sums are from 1 (closed scenes), "
                       "split by partially visible pairs");
    info_cmd->add_option("--method", ic->method, "form factors for --row-sums: raycast, exact, analytic or hemicube")
        ->check(CLI::IsMember(form_factor_methods()));
    add_form_factor_options(info_cmd, ic->ff);
    return {info_cmd, [&common, ic] { return run_info(common, *ic); }};
}

}  // namespace bounce::app
