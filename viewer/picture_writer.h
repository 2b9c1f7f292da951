// SPDX-License-Identifier: MIT
// Writing an 8-bit RGB picture: the format follows the file's name (a .jpg holding PNG bytes
// confuses every viewer), written to a temporary file and renamed, so an interrupted or failed
// write never leaves half a picture under the name.
#pragma once

#include <filesystem>
#include <string>

class vtkImageData;

namespace bounce {

/// The picture's extension in lower case (".png", ".jpg").
std::string picture_extension(const std::filesystem::path& picture);

/// Writes `image` to `picture` as PNG (".png") or JPEG at quality 95 (anything else the
/// caller has let through check_picture_path). Throws std::runtime_error on failure.
void write_picture(vtkImageData* image, const std::filesystem::path& picture);

}  // namespace bounce
