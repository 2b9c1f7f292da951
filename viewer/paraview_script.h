// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>

#include "mesh/meshing/patch_mesh.h"
#include "solver/linear/solve_result.h"
#include "viewer/renderer.h"
#include "viewer/vtu_writer.h"

namespace bounce {

/// Writes a ParaView Python script (pvpython, pvbatch, or the GUI's Python Shell > Run Script)
/// that opens `vtu` as `bounce render` shows it: coloured by display_rgb with Map Scalars off,
/// unlit, back faces culled, the camera of render (choose_camera with `options`), and the
/// luminance and radiosity colour maps ranged over the surfaces that do not emit (a light would
/// flatten the rest into one colour). `--screenshot OUT.png` saves the view and exits.
/// The .vtu is found beside the script, else at its absolute path when written.
void write_paraview_script(const std::filesystem::path& script, const std::filesystem::path& vtu, const PatchMesh& mesh,
                           const SolveResult& result, const ExportInfo& info, const RenderOptions& options);

}  // namespace bounce
