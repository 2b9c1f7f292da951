// SPDX-License-Identifier: MIT
// Linear radiance pictures in OpenEXR, the format renderers and compositors exchange high
// dynamic range images in.
#pragma once

#include <filesystem>
#include <vector>

#include "mesh/scene/rgb.h"

namespace bounce {

/// Writes linear radiance, W/(m^2 sr) per channel in the scene's units, as an OpenEXR file
/// (.exr): channels R, G and B as 32-bit floats (each value is float(L) exactly, as in the
/// .pfm), ZIP-compressed scanlines, rows top to bottom (`pixels` is width * height of them in
/// that order). Written to a temporary file beside `path`, then renamed; throws
/// std::runtime_error naming the path on failure.
void write_exr(const std::filesystem::path& path, int width, int height, const std::vector<Rgb>& pixels);

/// Writes a linear radiance picture in the format its name asks for: .exr (write_exr) or .pfm
/// (write_pfm, viewer/eye_picture.h).
void write_linear_picture(const std::filesystem::path& path, int width, int height, const std::vector<Rgb>& pixels);

/// True for the names write_linear_picture takes: .pfm and .exr (any case).
bool is_linear_picture(const std::filesystem::path& path);

}  // namespace bounce
