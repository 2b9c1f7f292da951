// SPDX-License-Identifier: MIT
// bounce score: a .vtu already written, scored at path-traced probes exactly as compare scores
// a solve (solver/reference/probe_score.h), without solving again.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "app/command.h"
#include "mesh/scene/input_error.h"
#include "solver/reference/probe_classes.h"
#include "solver/reference/probe_score.h"
#include "solver/reference/reference_csv.h"
#include "viewer/pending_output.h"
#include "viewer/solution_reader.h"

namespace bounce::app {
namespace {

struct ScoreCommand {
    std::string vtu;
    std::string reference;
    std::string out;  // --out PROBES.csv; empty: none
};

/// The reference's class column (what `bounce reference --probes` writes), one class per row;
/// nothing when it has no such column.
std::optional<std::vector<ProbeClass>> reference_classes(const CsvTable& t, const std::string& path) {
    const int column = t.column("class");
    if (column < 0) return std::nullopt;
    std::vector<ProbeClass> out;
    for (std::size_t r = 0; r < t.rows.size(); ++r) {
        const std::string& text = t.rows[r][std::size_t(column)];
        const auto it = std::find_if(kProbeClasses.begin(), kProbeClasses.end(),
                                     [&](ProbeClass c) { return to_string(c) == text; });
        if (it == kProbeClasses.end())
            throw InputError(path + ":" + std::to_string(t.lines[r]) + ": column 'class', got '" + text +
                             "' (expected lit, penumbra, unlit or contact)");
        out.push_back(*it);
    }
    return out;
}

/// The median of |e| over the probes that have an error (not NaN) and, when `which` is given,
/// whose class in `classes` it is; NaN when there are none.
double median_abs(const std::vector<double>& errors, std::optional<ProbeClass> which = {},
                  std::span<const ProbeClass> classes = {}) {
    std::vector<double> v;
    for (std::size_t k = 0; k < errors.size(); ++k)
        if (!std::isnan(errors[k]) && (!which || classes[k] == *which)) v.push_back(std::abs(errors[k]));
    if (v.empty()) return std::nan("");
    std::sort(v.begin(), v.end());
    const std::size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

/// One row of the table: probes, then RMS / median / worst of the point data and of the cells.
void print_row(const char* name, std::size_t probes, const std::array<double, 6>& errors) {
    std::printf("%-10s %7zu", name, probes);
    for (std::size_t k = 0; k < errors.size(); ++k) {
        const char* gap = k == 3 ? "  " : "";
        if (probes == 0)
            std::printf("%s %9s", gap, "-");
        else
            std::printf("%s %8.2f%%", gap, 100 * errors[k]);
    }
    std::printf("\n");
}

void print_table(const ProbeScore& s, const std::optional<std::vector<ProbeClass>>& classes) {
    std::printf("%zu probes scored, %zu skipped (no value, dark, or on no diffuse cell); reference noise %.2f%% RMS\n",
                s.scored, s.skipped, 100 * s.reference_noise);
    std::printf("%-10s %7s %9s %9s %9s   %9s %9s %9s\n", "class", "probes", "point RMS", "median", "worst", "cell RMS",
                "median", "worst");
    print_row(
        "all", s.scored,
        {s.rms_smooth, median_abs(s.smooth_error), s.max_smooth, s.rms_patch, median_abs(s.patch_error), s.max_patch});
    if (!classes) return;
    const auto by_class = score_by_class(s, *classes);
    for (std::size_t k = 0; k < kProbeClasses.size(); ++k) {
        const ProbeClass c = kProbeClasses[k];
        if (std::find(classes->begin(), classes->end(), c) == classes->end()) continue;  // not in the reference
        const ClassScore& b = by_class[k];
        print_row(to_string(c).c_str(), b.scored,
                  {b.rms_smooth, median_abs(s.smooth_error, c, *classes), b.max_smooth, b.rms_patch,
                   median_abs(s.patch_error, c, *classes), b.max_patch});
    }
}

/// The light the solution lets out of the scene, a share of what the emitters send, per channel.
void print_escaped(const SolutionFile& solution) {
    if (!solution.emitted_power || !solution.escaped_power) return;
    std::printf("escaped share of the emitted power:");
    for (int c = 0; c < 3; ++c) {
        const double e = (*solution.emitted_power)[c];
        if (!(e > 0)) {
            std::printf(" %c -", "RGB"[c]);
            continue;
        }
        // A closed scene's books balance to a rounding either side of 0: no "-0.00%".
        const double share = 100 * (*solution.escaped_power)[c] / e;
        std::printf(" %c %.2f%%", "RGB"[c], std::abs(share) < 0.005 ? 0.0 : share);
    }
    std::printf("\n");
}

/// A number as the shortest text that reads back to it.
std::string exact_text(double x) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

void write_probes(const std::string& out, const std::vector<ReferencePoint>& reference, const ProbeScore& s,
                  const std::optional<std::vector<ProbeClass>>& classes) {
    CsvTable t;
    t.header = {"x", "y", "z", "nx", "ny", "nz", "surface", "class"};
    t.header.insert(t.header.end(), {"reference_luminance", "cell_error", "point_error"});
    for (std::size_t k = 0; k < reference.size(); ++k) {
        if (std::isnan(s.patch_error[k])) continue;  // skipped
        const ReferencePoint& r = reference[k];
        t.rows.push_back({exact_text(r.position.x), exact_text(r.position.y), exact_text(r.position.z),
                          exact_text(r.normal.x), exact_text(r.normal.y), exact_text(r.normal.z), r.surface,
                          classes ? to_string((*classes)[k]) : "", exact_text(r.radiosity.luminance()),
                          exact_text(s.patch_error[k]), exact_text(s.smooth_error[k])});
    }
    write_text_file(
        out, [&](std::ostream& o) { o << to_csv(t); }, "probe errors");
}

int run_score(const CommonOptions& o, const ScoreCommand& c) {
    if (!c.out.empty()) check_output(c.out);
    const CsvTable table = read_csv(c.reference);
    const std::vector<ReferencePoint> reference = read_reference(table, c.reference);
    const auto classes = reference_classes(table, c.reference);
    const SolutionFile solution = read_solution(c.vtu);
    const ProbeScore s = score_at_probes(solution.mesh, solution.cell_radiosity, reference, solution.point_radiosity);
    if (s.scored == 0)
        throw InputError(c.reference + ": none of its " + std::to_string(reference.size()) +
                         " probes lies on a diffuse cell of " + c.vtu + " (a reference of another scene?)");
    // Dark probes and probes without a value are few in a reference of the same scene; most
    // probes off the mesh mean another scene whose surfaces the mesh meets by chance.
    if (!o.quiet && s.skipped > s.scored)
        std::cerr << "bounce: note: " << c.reference << ": " << s.skipped << " of its " << reference.size()
                  << " probes are not scored (no value, dark, or on no diffuse cell of " << c.vtu
                  << "): a reference of another scene?\n";
    if (!o.quiet && !solution.unfinished.empty())
        std::cerr << "bounce: note: " << c.vtu << ": " << solution.unfinished
                  << "; these are the scores of that partial solution\n";
    if (!o.quiet && solution.skipped_cells > 0)
        std::cerr << "bounce: note: " << c.vtu << ": its " << solution.skipped_cells
                  << (solution.skipped_cells == 1 ? " mirror or glass cell is" : " mirror and glass cells are")
                  << " not scored, and the radiosity leaves out the light they redirect, which the reference holds\n";
    if (!o.quiet && solution.point_radiosity.empty())
        std::cerr << "bounce: note: " << c.vtu
                  << ": no point array 'radiosity'; the point data scored is the cells' area-weighted mean\n";
    print_table(s, classes);
    print_escaped(solution);
    if (!c.out.empty()) {
        write_probes(c.out, reference, s, classes);
        if (!o.quiet) std::cout << "wrote " << c.out << "\n";
    }
    return 0;
}

}  // namespace

Command add_score_command(CLI::App& app, CommonOptions& common) {
    auto sc = std::make_shared<ScoreCommand>();
    auto* cmd = app.add_subcommand(
        "score", "score a written .vtu at path-traced probes (a bounce reference CSV), as compare scores a solve");
    cmd->add_option("vtu", sc->vtu, "the solution, as bounce solve wrote it")->required();
    cmd->add_option("--reference", sc->reference,
                    "the probes: a bounce reference CSV of the same scene (with --probes, its class column gives "
                    "a row per class)")
        ->required();
    cmd->add_option("--out", sc->out,
                    "also write every scored probe: x,y,z,nx,ny,nz,surface,class,reference_luminance,cell_error,"
                    "point_error (signed relative luminance errors)");
    cmd->add_flag("-q,--quiet", common.quiet, "only the scores: no notes");
    return {cmd, [&common, sc] { return run_score(common, *sc); }};
}

}  // namespace bounce::app
