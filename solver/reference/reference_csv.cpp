// SPDX-License-Identifier: MIT
#include "solver/reference/reference_csv.h"

#include <array>
#include <cmath>
#include <sstream>

#include <glm/geometric.hpp>

#include "mesh/readers/text_file.h"
#include "mesh/scene/input_error.h"

namespace bounce {

int CsvTable::column(const std::string& name) const {
    for (std::size_t k = 0; k < header.size(); ++k)
        if (header[k] == name) return int(k);
    return -1;
}

namespace {

std::string trim(std::string s) {
    const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
    while (!s.empty() && blank(s.back())) s.pop_back();
    std::size_t i = 0;
    while (i < s.size() && blank(s[i])) ++i;
    return s.substr(i);
}

}  // namespace

CsvTable read_csv(const std::filesystem::path& path) {
    const std::string text = read_text_file(path, "CSV file");
    const std::string p = path.string();
    CsvTable table;
    std::vector<std::string> record;
    std::string field;
    bool quoted = false, field_was_quoted = false;
    int line = 1, record_line = 1;
    auto end_field = [&] {
        record.push_back(field_was_quoted ? field : trim(field));
        field.clear();
        field_was_quoted = false;
    };
    auto end_record = [&] {
        end_field();
        const bool blank = record.size() == 1 && record[0].empty();
        if (!blank) {
            if (table.header.empty()) {
                table.header = record;
            } else {
                if (record.size() != table.header.size())
                    throw InputError(p + ":" + std::to_string(record_line) + ": " + std::to_string(record.size()) +
                                     " fields, expected " + std::to_string(table.header.size()) +
                                     " (as in the header)");
                table.rows.push_back(record);
                table.lines.push_back(record_line);
            }
        }
        record.clear();
        record_line = line;
    };
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (quoted) {
            if (c == '"') {
                if (i + 1 < text.size() && text[i + 1] == '"') {
                    field += '"';
                    ++i;
                } else {
                    quoted = false;
                }
            } else {
                if (c == '\n') ++line;
                field += c;
            }
        } else if (c == '"' && trim(field).empty()) {
            quoted = true;
            field_was_quoted = true;
            field.clear();
        } else if (c == ',') {
            end_field();
        } else if (c == '\n') {
            ++line;
            end_record();
        } else {
            field += c;
        }
    }
    if (quoted) throw InputError(p + ":" + std::to_string(record_line) + ": unterminated quoted field");
    if (!field.empty() || !record.empty()) end_record();
    if (table.header.empty()) throw InputError(p + ": empty CSV file, expected a header row");
    return table;
}

std::string to_csv(const CsvTable& table) {
    std::ostringstream out;
    auto put = [&](const std::vector<std::string>& fields) {
        for (std::size_t k = 0; k < fields.size(); ++k) {
            if (k) out << ',';
            const std::string& f = fields[k];
            if (f.find_first_of(",\"\n\r") != std::string::npos) {
                out << '"';
                for (char c : f) out << (c == '"' ? std::string("\"\"") : std::string(1, c));
                out << '"';
            } else {
                out << f;
            }
        }
        out << '\n';
    };
    put(table.header);
    for (const auto& r : table.rows) put(r);
    return out.str();
}

namespace {

/// Column indices for the names given; throws naming the first missing one.
template <std::size_t N>
std::array<int, N> required_columns(const CsvTable& t, const std::array<const char*, N>& names, const std::string& p) {
    std::array<int, N> idx{};
    for (std::size_t k = 0; k < N; ++k) {
        idx[k] = t.column(names[k]);
        if (idx[k] < 0) throw InputError(p + ":1: no column '" + names[k] + "' in the header");
    }
    return idx;
}

double number_at(const CsvTable& t, std::size_t row, int col, const std::string& p) {
    const std::string& s = t.rows[row][std::size_t(col)];
    double v = 0;
    const std::string where = p + ":" + std::to_string(t.lines[row]) + ": column " + t.header[std::size_t(col)];
    if (!parse_double(s, v)) throw InputError(where + ": not a number, got '" + s + "'");
    if (!std::isfinite(v)) throw InputError(where + ": not a finite number, got " + s);
    return v;
}

}  // namespace

std::vector<PointRow> point_rows(const CsvTable& t, const std::filesystem::path& path) {
    const std::string p = path.string();
    const auto c = required_columns<6>(t, {"x", "y", "z", "nx", "ny", "nz"}, p);
    std::vector<PointRow> out;
    out.reserve(t.rows.size());
    for (std::size_t r = 0; r < t.rows.size(); ++r) {
        PointRow row;
        for (int k = 0; k < 3; ++k) {
            row.position[k] = number_at(t, r, c[std::size_t(k)], p);
            row.normal[k] = number_at(t, r, c[std::size_t(k + 3)], p);
        }
        if (!(glm::length(row.normal) > 0))
            throw InputError(p + ":" + std::to_string(t.lines[r]) + ": the normal (nx,ny,nz) is zero");
        out.push_back(row);
    }
    if (out.empty()) throw InputError(p + ": no points (only a header)");
    return out;
}

std::vector<ReferencePoint> read_reference(const std::filesystem::path& path) {
    return read_reference(read_csv(path), path);
}

std::vector<ReferencePoint> read_reference(const CsvTable& t, const std::filesystem::path& path) {
    const std::string p = path.string();
    const auto rows = point_rows(t, path);
    const auto c = required_columns<8>(t, {"B_r", "B_g", "B_b", "se_r", "se_g", "se_b", "paths", "status"}, p);
    const int surface = t.column("surface");
    std::vector<ReferencePoint> out;
    for (std::size_t r = 0; r < t.rows.size(); ++r) {
        ReferencePoint q;
        q.position = rows[r].position;
        q.normal = glm::normalize(rows[r].normal);
        q.status = t.rows[r][std::size_t(c[7])];
        if (surface >= 0) q.surface = t.rows[r][std::size_t(surface)];
        // An empty value is a point that was skipped or never started.
        q.has_value = !t.rows[r][std::size_t(c[0])].empty();
        if (q.has_value) {
            for (int k = 0; k < 3; ++k) {
                q.radiosity[k] = number_at(t, r, c[std::size_t(k)], p);
                q.standard_error[k] = number_at(t, r, c[std::size_t(k + 3)], p);
            }
            q.paths = std::uint64_t(number_at(t, r, c[6], p));
        }
        out.push_back(q);
    }
    return out;
}

}  // namespace bounce
