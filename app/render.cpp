// SPDX-License-Identifier: MIT
// bounce render: a .vtu (or a scene, solved first as bounce solve solves it) to a PNG.
#include "app/render.h"

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>

#include "app/command.h"
#include "app/signals.h"
#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/errors.h"
#include "mesh/scene/input_error.h"
#include "solver/pipeline/solve_scene.h"
#include "viewer/exr_writer.h"

namespace bounce::app {
namespace {

bool is_vtu(const std::string& p) { return std::filesystem::path(p).extension() == ".vtu"; }

/// The scene solved as `bounce solve` solves it without flags (the meshing, visibility and
/// --flip of the common options aside), through the same pipeline: open parts, balanced rows
/// and display cells, so the picture is the one of the .vtu that solve writes. Interrupted, it
/// throws: nothing is drawn.
SolvedScene solve_as_solve_does(const CommonOptions& o, const Scene& scene) {
    SolveRequest request;
    request.meshing = o.meshing;
    request.visibility = o.visibility;
    request.flip = o.flip;
    request.validate();
    SolveHooks hooks;
    hooks.cancel = &g_interrupted;
    hooks.mesh = [&](const MeshingOptions& m) { return std::make_shared<const PatchMesh>(mesh_scene(o, scene, m)); };
    hooks.check_memory = [&](const std::string& what, double bytes) { check_memory(o, what, bytes); };
    SolvedScene solved = solve_scene(scene, request, hooks);
    if (g_interrupted.load()) throw Interrupted("interrupted while solving");
    print_solve_messages(solved, o.quiet);
    return solved;
}

}  // namespace

int run_render(const CommonOptions& o, const RenderCommand& r, bool interactive) {
    // A .pfm or .exr holds linear radiance: only eye rays make one.
    const bool linear = !interactive && is_linear_picture(r.output);
    if (!interactive) {
        check_output(r.output);
        if (!linear) check_picture_path(r.output);
        if (linear && is_vtu(r.input))
            throw InputError(r.output +
                             ": a .pfm or .exr (linear radiance) is drawn by eye rays from a scene, not from a .vtu");
    }
    // A window nobody can see never closes: without a display, say so at once (exit 2)
    // instead of opening it on a private Xvfb. With --exit-after (demos, tests) it closes by
    // itself, so the private Xvfb is harmless there.
    const char* display = std::getenv("DISPLAY");
    if (interactive && !(display && *display) && !(r.exit_after > 0))
        throw InputError(
            "view: no display, DISPLAY is unset (expected an X display for the window; "
            "bounce render IN -o OUT.png draws a picture without one)");
    if (is_vtu(r.input)) {
        // A picture of a solution that did not finish says so, on the terminal and in its corner.
        const UnfinishedNote note = [&](const std::string& caption) {
            if (!o.quiet)
                std::cerr << "bounce: note: " << r.input << ": " << caption << "; the picture says so in its corner\n";
        };
        interactive ? view_vtu(r.input, r.render, r.exit_after, note) : render_vtu(r.input, r.output, r.render, note);
        if (!interactive && !o.quiet) std::cout << "wrote " << r.output << "\n";
        return 0;
    }
    const Scene scene = load_checked(o, r.input);
    if (!interactive && (scene.has_specular() || r.two_pass.ray_trace || linear)) {
        // Eye rays show what a camera sees: no patch colours, edges or colour bar.
        if (!r.render.smooth || r.render.luminance || r.render.edges)
            throw InputError(r.input + ": --flat, --luminance and --edges draw a solution's patches (a .vtu, or a " +
                             "scene without mirrors or glass), not the eye rays' picture");
        return run_two_pass_render(o, scene, mesh_scene(o, scene, o.meshing), r.output, r.render, r.two_pass);
    }
    if (scene.has_specular() && !o.quiet)
        std::cerr << "bounce: note: " << r.input << ": the window shows mirrors and glass as plain solids, "
                  << "without the light they redirect; bounce render " << r.input << " -o PICTURE.png draws it\n";
    const SolvedScene solved = solve_as_solve_does(o, scene);
    const ExportInfo info{r.input, solved.settings, false, scene.units};
    interactive ? view_solution(*solved.mesh, solved.result, info, r.render, r.exit_after)
                : render_solution(*solved.mesh, solved.result, info, r.output, r.render);
    if (!interactive && !o.quiet) std::cout << "wrote " << r.output << "\n";
    return 0;
}

Command add_render_command(CLI::App& app, CommonOptions& common) {
    auto rc = std::make_shared<RenderCommand>();
    auto* render_cmd = app.add_subcommand(
        "render",
        "render a .vtu (or a scene, solved first; by eye rays when it has mirrors or glass) to a PNG or JPEG");
    render_cmd->add_option("input", rc->input, "IN.vtu, or a scene")->required();
    render_cmd
        ->add_option("-o,--output", rc->output,
                     "output picture: .png, .jpg/.jpeg for JPEG, or .pfm or .exr for linear radiance (eye rays)")
        ->required();
    add_render_options(render_cmd, rc->render);
    add_two_pass_options(render_cmd, rc->two_pass);
    add_meshing_options_no_scene(render_cmd, common);
    return {render_cmd, [&common, rc] { return run_render(common, *rc, false); }};
}

}  // namespace bounce::app
