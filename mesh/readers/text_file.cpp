// SPDX-License-Identifier: MIT
#include "mesh/readers/text_file.h"

#include <charconv>
#include <fstream>
#include <sstream>

#include "mesh/scene/input_error.h"

namespace bounce {

std::string read_text_file(const std::filesystem::path& path, std::string_view what) {
    std::error_code ec;
    const std::string p = path.string();
    if (!std::filesystem::exists(path, ec)) throw MissingFileError(p + ": " + std::string(what) + " not found");
    if (std::filesystem::is_directory(path, ec))
        throw InputError(p + ": is a directory, expected " + std::string(what));
    // Devices and pipes (/dev/zero, a FIFO) never end; only regular files are read.
    if (!std::filesystem::is_regular_file(path, ec))
        throw InputError(p + ": not a regular file, expected " + std::string(what));
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec && size > (std::uintmax_t(1) << 30))
        throw InputError(p + ": larger than 1 GiB, not read as " + std::string(what));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(p + ": cannot open " + std::string(what));
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw InputError(p + ": read error");
    std::string text = ss.str();
    if (text.find('\0') != std::string::npos)
        throw InputError(p + ": binary data where a text " + std::string(what) + " was expected");
    return text;
}

std::vector<std::string_view> split_words(std::string_view line) {
    if (auto h = line.find('#'); h != std::string_view::npos) line = line.substr(0, h);
    std::vector<std::string_view> words;
    std::size_t i = 0;
    auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; };
    while (i < line.size()) {
        while (i < line.size() && blank(line[i])) ++i;
        std::size_t j = i;
        while (j < line.size() && !blank(line[j])) ++j;
        if (j > i) words.push_back(line.substr(i, j - i));
        i = j;
    }
    return words;
}

bool parse_double(std::string_view word, double& out) {
    // strtod accepts "nan" and "inf", which the callers then reject with a clear message.
    std::string s(word);
    char* end = nullptr;
    out = std::strtod(s.c_str(), &end);
    return !s.empty() && end == s.c_str() + s.size();
}

}  // namespace bounce
