// SPDX-License-Identifier: MIT
// Pictures made by eye rays (solver/two_pass) rather than by VTK: the camera `render` would
// take for a solution, and the linear radiance image tone mapped into a PNG or JPEG.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "solver/linear/solve_result.h"
#include "solver/two_pass/eye_pass.h"
#include "viewer/renderer.h"
#include "viewer/vtu_writer.h"

namespace bounce {

/// The camera of `bounce render` for this solution and options (--camera, --fov, --size), as
/// a pinhole camera for eye rays: "default" is the Cornell front view for the built-in boxes
/// (`cornell` and `cornell-spheres`), else auto (viewer/camera.h).
PinholeCamera eye_camera(const PatchMesh& mesh, const SolveResult& result, const ExportInfo& info,
                         const RenderOptions& options);

/// Writes linear radiance, W/(m^2 sr) per channel, as a Portable Float Map (.pfm: 32-bit
/// floats, little-endian, for scoring pictures against each other), through a temporary file.
/// `pixels` are rows top to bottom, width * height of them.
void write_pfm(const std::filesystem::path& path, int width, int height, const std::vector<Rgb>& pixels);

/// Reads a .pfm as write_pfm writes it (3 channels, little-endian), rows top to bottom; sets
/// width and height. Throws InputError naming the file when it is missing or not such a file.
std::vector<Rgb> read_pfm(const std::filesystem::path& path, int& width, int& height);

/// Writes the picture (a .pfm or .exr: the linear radiance as it is, see write_linear_picture): radiance L times pi
/// (the radiosity a diffuse surface of that radiance has) through the tone map `render` uses (exposure from the
/// solution's patches: their mean non-emitting luminance at mid grey, times 2^exposure; 1 - exp(-x); sRGB), as 8-bit
/// PNG or JPEG by the name's extension, through a temporary file renamed at the end.
void write_eye_picture(const EyeImage& image, const PatchMesh& mesh, const SolveResult& result, double exposure,
                       const std::filesystem::path& picture);

/// Writes several pictures side by side, left to right with a 4-pixel black gap, through the
/// tone map write_eye_picture uses (one exposure for all: the same radiance, the same colour),
/// as 8-bit PNG or JPEG.
void write_eye_pictures(const std::vector<const EyeImage*>& images, const PatchMesh& mesh, const SolveResult& result,
                        double exposure, const std::filesystem::path& picture);

}  // namespace bounce
