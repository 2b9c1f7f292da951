// SPDX-License-Identifier: MIT
// What `render` and `view` share: a .vtu, or a scene solved first as `bounce solve` solves it, shown
// either in a PNG or in a window.
#pragma once

#include <string>

#include "app/common_options.h"
#include "app/two_pass_render.h"
#include "viewer/renderer.h"

namespace bounce::app {

struct RenderCommand {
    std::string input;
    std::string output;
    RenderOptions render;
    double exit_after = 0.0;
    TwoPassOptions two_pass;  // render only: eye rays for scenes with mirrors or glass, or --ray-trace
};

/// IN.vtu is rendered as it is; anything else is a scene, solved first as `bounce solve` solves
/// it without flags (solve_scene, the meshing options aside), so the picture is its .vtu's. A
/// scene with mirrors or glass (or any scene with --ray-trace) is drawn by the two-pass method
/// (app/two_pass_render.h); `view` shows its diffuse patches only.
/// interactive: a window (view) instead of the PNG r.output (render).
int run_render(const CommonOptions& o, const RenderCommand& r, bool interactive);

}  // namespace bounce::app
