// SPDX-License-Identifier: MIT
#include "app/reference_points.h"

#include <cstdio>
#include <iostream>
#include <sstream>

#include <glm/geometric.hpp>

#include "app/progress_line.h"
#include "app/signals.h"
#include "mesh/scene/input_error.h"
#include "solver/form_factors/form_factor_matrix.h"  // Interrupted
#include "viewer/pending_output.h"

namespace bounce::app {
namespace {

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

/// FNV-1a over the scene's coordinates and materials: what the reference depends on.
std::uint64_t scene_hash(const Scene& scene) {
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&](const void* data, std::size_t n) {
        const auto* b = static_cast<const unsigned char*>(data);
        for (std::size_t k = 0; k < n; ++k) {
            h ^= b[k];
            h *= 1099511628211ull;
        }
    };
    for (const auto& s : scene.surfaces) {
        for (const auto& v : s.vertices) mix(&v, sizeof v);
        mix(&s.material, sizeof s.material);
    }
    for (const auto& m : scene.materials) {
        mix(&m.reflectance, sizeof m.reflectance);
        mix(&m.emission, sizeof m.emission);
    }
    return h;
}

}  // namespace

CsvTable probe_table(std::span<const SurfacePoint> probes, std::span<const ProbeClass> classes) {
    CsvTable t;
    t.header = {"x", "y", "z", "nx", "ny", "nz"};
    if (!classes.empty()) t.header.push_back("class");
    for (std::size_t k = 0; k < probes.size(); ++k) {
        const auto& p = probes[k];
        t.rows.push_back({number(p.position.x), number(p.position.y), number(p.position.z), number(p.normal.x),
                          number(p.normal.y), number(p.normal.z)});
        if (!classes.empty()) t.rows.back().push_back(to_string(classes[k]));
        t.lines.push_back(int(t.rows.size()) + 1);
    }
    return t;
}

std::vector<ProbeClass> probe_classes(const Scene& scene, std::span<const ReferencePoint> reference) {
    const PathTracer tracer(scene);
    std::vector<ProbeClass> out(reference.size(), ProbeClass::lit);
    for (std::size_t k = 0; k < reference.size(); ++k)
        if (const auto x = tracer.locate(reference[k].position, reference[k].normal))
            out[k] = classify_probe(tracer, *x, k);
    return out;
}

CsvTable estimate_table(const PathTracer& tracer, const CsvTable& input,
                        const std::vector<std::optional<SurfacePoint>>& points, const ReferenceOptions& options,
                        bool show_progress) {
    std::vector<SurfacePoint> located;
    std::vector<std::size_t> row_of;
    for (std::size_t k = 0; k < points.size(); ++k)
        if (points[k]) {
            located.push_back(*points[k]);
            row_of.push_back(k);
        }
    ProgressLine progress(show_progress);
    const auto estimates = tracer.estimate_all(
        located, options,
        [&](std::size_t done, std::size_t total) { progress.items("path tracing: points", done, total); },
        &g_interrupted);
    progress.finish();

    CsvTable out = input;
    for (const char* c : {"B_r", "B_g", "B_b", "se_r", "se_g", "se_b", "paths", "surface", "status"})
        out.header.push_back(c);
    for (auto& row : out.rows) {
        for (int k = 0; k < 7; ++k) row.push_back("");
        row.push_back("");
        row.push_back("missing");
    }
    for (std::size_t j = 0; j < located.size(); ++j) {
        auto& row = out.rows[row_of[j]];
        const auto& e = estimates[j];
        const std::size_t base = input.header.size();
        if (e.paths > 0) {
            for (int c = 0; c < 3; ++c) {
                row[base + std::size_t(c)] = number(e.radiosity[c]);
                row[base + 3 + std::size_t(c)] = number(e.standard_error[c]);
            }
        }
        row[base + 6] = std::to_string(e.paths);
        row[base + 7] = tracer.surface_name(located[j].surface);
        row[base + 8] = to_string(e.status);
    }
    return out;
}

std::vector<ReferencePoint> reference_for_compare(const Scene& scene, const std::string& given,
                                                  const std::filesystem::path& folder, bool quiet) {
    if (!given.empty()) return read_reference(given);
    char name[64];
    std::snprintf(name, sizeof name, "reference-classes-%016llx.csv",
                  static_cast<unsigned long long>(scene_hash(scene)));
    const std::filesystem::path cached = folder / name;
    std::error_code ec;
    if (std::filesystem::is_regular_file(cached, ec)) {
        if (!quiet) std::cout << "reference: " << cached.string() << " (cached)\n";
        return read_reference(cached);
    }
    const PathTracer tracer(scene);
    const ReferenceOptions options;
    std::vector<ProbeClass> classes;
    const auto probes = probes_by_class(tracer, kCompareProbes, options.seed, classes);
    std::vector<std::optional<SurfacePoint>> points(probes.begin(), probes.end());
    const CsvTable table = estimate_table(tracer, probe_table(probes, classes), points, options, !quiet);
    if (g_interrupted.load()) throw Interrupted("interrupted while path tracing the reference");
    write_text_file(
        cached, [&](std::ostream& out) { out << to_csv(table); }, "reference");
    if (!quiet)
        std::cout << "reference: " << probes.size() << " probes path traced to " << options.target_error * 100 << "% ("
                  << tracer.paths_traced() << " paths), cached in " << cached.string() << "\n";
    return read_reference(cached);
}

}  // namespace bounce::app
