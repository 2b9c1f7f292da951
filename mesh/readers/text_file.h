// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace bounce {

/// Reads a whole text file; throws InputError naming the path when it is missing, a
/// directory, unreadable, or binary (holds NUL bytes).
std::string read_text_file(const std::filesystem::path& path, std::string_view what);

/// Splits on blanks (spaces, tabs, \r) after cutting a '#' comment.
std::vector<std::string_view> split_words(std::string_view line);

/// Parses a whole word as a finite-or-not double; false when the word is not a number.
bool parse_double(std::string_view word, double& out);

}  // namespace bounce
