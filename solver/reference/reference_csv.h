// SPDX-License-Identifier: MIT
// Reference points as CSV: the points to estimate (x,y,z,nx,ny,nz and any other columns, kept)
// and the estimates (the input columns plus B_r,B_g,B_b,se_r,se_g,se_b,paths,surface,status).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/rgb.h"

namespace bounce {

/// A CSV file as text fields under a header row (RFC 4180 quoting).
struct CsvTable {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    std::vector<int> lines;  // 1-based line of each row in the file, for messages

    /// Index of the column named `name`, or -1.
    int column(const std::string& name) const;
};

/// Reads a CSV with a header row; throws InputError naming the file (and line) when it is
/// missing, empty, or a row has a different number of fields than the header.
CsvTable read_csv(const std::filesystem::path& path);

/// The table as CSV text; fields with commas, quotes or line breaks are quoted.
std::string to_csv(const CsvTable& table);

/// A point to estimate, as given: position and (not necessarily unit) normal.
struct PointRow {
    glm::dvec3 position{0.0};
    glm::dvec3 normal{0.0};
};

/// The columns x,y,z,nx,ny,nz of every row, found by name; throws InputError naming the file,
/// line and column when one is missing, not a number, NaN or infinite, or a normal is zero.
std::vector<PointRow> point_rows(const CsvTable& table, const std::filesystem::path& path);

/// One estimated point of a reference file, as compare reads it back.
struct ReferencePoint {
    glm::dvec3 position{0.0};
    glm::dvec3 normal{0.0};
    Rgb radiosity;
    Rgb standard_error;
    std::uint64_t paths = 0;
    std::string surface;
    std::string status;  // converged, budget, interrupted, missing
    bool has_value = false;
};

/// Reads a file written by `bounce reference`; throws InputError naming the file and line.
std::vector<ReferencePoint> read_reference(const std::filesystem::path& path);
/// The same from a table already read from `path` (named in messages), for a caller that also
/// reads other columns of it.
std::vector<ReferencePoint> read_reference(const CsvTable& table, const std::filesystem::path& path);

}  // namespace bounce
