// SPDX-License-Identifier: MIT
// bounce view: a .vtu (or a scene, solved first) in an interactive window.
#include <memory>

#include "app/command.h"
#include "app/render.h"

namespace bounce::app {

Command add_view_command(CLI::App& app, CommonOptions& common) {
    auto rc = std::make_shared<RenderCommand>();
    auto* view_cmd = app.add_subcommand("view", "interactive window: mouse rotates and zooms, e edges, l luminance");
    view_cmd->add_option("input", rc->input, "IN.vtu, or a scene")->required();
    add_render_options(view_cmd, rc->render);
    view_cmd->add_option("--exit-after", rc->exit_after, "close after this many seconds (demos, tests)");
    add_meshing_options_no_scene(view_cmd, common);
    return {view_cmd, [&common, rc] { return run_render(common, *rc, true); }};
}

}  // namespace bounce::app
