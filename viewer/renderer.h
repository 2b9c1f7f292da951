// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "mesh/meshing/patch_mesh.h"
#include "solver/linear/solve_result.h"
#include "viewer/vtu_writer.h"

namespace bounce {

/// How to turn a solution into a picture.
struct RenderOptions {
    std::string camera = "default";  // "cornell", "auto", "x,y,z:tx,ty,tz"; default: cornell for the box
    double fov = 0.0;                // vertical field of view, degrees; 0: the camera's own (choose_camera)
    int width = 800, height = 800;   // pixels
    double exposure = 0.0;           // EV: each +1 doubles the brightness before the tone curve
    bool smooth = true;              // colours from the point data (interpolated); false (--flat): per patch
    bool smooth_required = false;    // --smooth given: an input without point data is an error, not flat
    bool luminance = false;          // pseudo-colour by luminance with a colour bar
    bool edges = false;              // draw patch edges
    // What errors call the camera, field of view and size: the command line's options, or the
    // Python keywords ("camera", "fov", "size").
    std::string camera_name = "--camera", fov_name = "--fov", size_name = "--size";
};

/// Throws InputError unless the picture's name ends in .png, .jpg or .jpeg (the formats
/// written; the bytes follow the name). Callers check before any work.
void check_picture_path(const std::filesystem::path& picture);

/// Told, before the picture is drawn, what a picture of an unfinished solution says in its
/// corner: "NOT CONVERGED (interrupted) after 812 steps, unshot fraction 0.031", from the field data
/// converged, status, steps and unshot_fraction (or residual). Not called for a converged
/// solution or a file without that field data.
using UnfinishedNote = std::function<void(const std::string& caption)>;

/// Renders a .vtu written by bounce to a PNG (temporary file, then rename), under a virtual
/// display when DISPLAY is unset. Throws InputError for a missing or corrupt input or a bad
/// camera string.
void render_vtu(const std::filesystem::path& vtu, const std::filesystem::path& png, const RenderOptions& options,
                const UnfinishedNote& note = {});

/// Renders a solution in memory to a PNG.
void render_solution(const PatchMesh& mesh, const SolveResult& result, const ExportInfo& info,
                     const std::filesystem::path& png, const RenderOptions& options);

/// An interactive window (rotate, zoom; 'e' toggles patch edges, 'l' luminance colouring with
/// a colour bar). Closes by itself after exit_after seconds when that is positive.
void view_vtu(const std::filesystem::path& vtu, const RenderOptions& options, double exit_after = 0.0,
              const UnfinishedNote& note = {});
void view_solution(const PatchMesh& mesh, const SolveResult& result, const ExportInfo& info,
                   const RenderOptions& options, double exit_after = 0.0);

}  // namespace bounce
