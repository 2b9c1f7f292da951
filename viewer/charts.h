// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>

namespace bounce {

/// Draws convergence.png and speed_vs_accuracy.png in `folder` from its convergence.csv, with
/// matplotlib from Debian's /usr/bin/python3 (a plotting library, not hand-drawn pixels).
/// Throws std::runtime_error when the plotting fails.
void write_comparison_charts(const std::filesystem::path& folder);

/// Draws meshes.png in `folder` from its meshes.csv (bounce compare --meshes): probe error
/// against elements and against seconds, for every method; and probe_errors.png, the box with
/// every probe coloured by its signed error (from probe_errors.csv and outline.csv, when there).
void write_mesh_charts(const std::filesystem::path& folder);

/// Draws picture_error.png in `folder` from its picture.csv (bounce compare --picture): each
/// picture's error against the long path-traced image, against seconds, for both methods.
void write_picture_chart(const std::filesystem::path& folder);

}  // namespace bounce
