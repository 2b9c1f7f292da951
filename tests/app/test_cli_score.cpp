// SPDX-License-Identifier: MIT
// `bounce score`: a written .vtu scored at path-traced probes, run as a user runs it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "mesh/readers/scene_loader.h"
#include "solver/pipeline/solve_scene.h"
#include "solver/reference/probe_classes.h"
#include "solver/reference/probe_score.h"
#include "solver/reference/reference_csv.h"
#include "test_util.h"
#include "viewer/vtu_writer.h"

using namespace bounce;

namespace {

const std::string kExe = BOUNCE_EXE;

test::RunResult bounce_run(const std::string& args) { return test::run(kExe + " " + args); }

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

/// The numbers of the table row that starts with `name` (the percent signs dropped), after the
/// name: probes, point RMS, median, worst, cell RMS, median, worst.
std::vector<double> row_of(const std::string& out, const std::string& name) {
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream words(line);
        std::string first;
        if (!(words >> first) || first != name) continue;
        std::vector<double> v;
        for (std::string w; words >> w;) v.push_back(std::stod(w));
        return v;
    }
    return {};
}

double median_abs(std::vector<double> v) {
    for (double& x : v) x = std::abs(x);
    std::sort(v.begin(), v.end());
    const std::size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

/// The errors of the probes that were scored (and, with `classes`, are of class `which`).
std::vector<double> scored(const std::vector<double>& errors, const std::vector<ProbeClass>* classes = nullptr,
                           ProbeClass which = ProbeClass::lit) {
    std::vector<double> out;
    for (std::size_t k = 0; k < errors.size(); ++k)
        if (!std::isnan(errors[k]) && (!classes || (*classes)[k] == which)) out.push_back(errors[k]);
    return out;
}

/// Expects a printed row to hold these fractions, as percent with two decimals.
void expect_row(const std::vector<double>& printed, std::size_t probes, const std::array<double, 6>& want,
                const std::string& name) {
    ASSERT_EQ(printed.size(), 7u) << name;
    EXPECT_EQ(printed[0], double(probes)) << name;
    for (std::size_t k = 0; k < want.size(); ++k)
        EXPECT_NEAR(printed[k + 1], 100 * want[k], 0.005 + 1e-9) << name << " column " << k + 1;
}

/// A hand-written reference: one probe in the middle of every face of the box from (-1, -0.75,
/// -0.5) to (1, 0.75, 0.5), facing in, each with radiosity `b` (grey) and standard error `se`.
std::string furnace_reference(double b, double se) {
    const char* probes[] = {"0.3,-0.75,0.1,0,1,0,lit",    "-0.2,0.75,0,0,-1,0,lit",   "-1,0.1,-0.2,1,0,0,penumbra",
                            "1,-0.3,0.2,-1,0,0,penumbra", "0.4,0.2,-0.5,0,0,1,unlit", "-0.6,0,0.5,0,0,-1,contact"};
    char values[256];
    std::snprintf(values, sizeof values, ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,4096,box,converged\n", b, b, b, se, se,
                  se);
    std::string csv = "x,y,z,nx,ny,nz,class,B_r,B_g,B_b,se_r,se_g,se_b,paths,surface,status\n";
    for (const char* p : probes) csv += p + std::string(values);
    return csv;
}

// E = 1, rho = 0.5 on every face: B = E / (1 - rho) = 2 everywhere, light neither lost nor made.
const char* kFurnace = R"({ "name": "furnace",
  "materials": { "glow": { "reflectance": 0.5, "emission": 1 } },
  "objects": [ { "type": "box", "material": "glow", "inward": true, "transform": { "scale": [2, 1.5, 1] } } ] })";

}  // namespace

// The numbers score prints are score_at_probes' on the solution in memory: the .vtu's cells,
// their corners and the point data come back as the solver held them.
TEST(CliScore, PrintsWhatTheSolveInMemoryScores) {
    test::TempDir dir;
    const Scene scene = load_scene("cornell");
    SolveRequest request;
    request.meshing.target_patches = 300;
    request.validate();
    const SolvedScene solved = solve_scene(scene, request);
    const auto vtu = dir / "c.vtu", probes = dir / "probes.csv";
    write_vtu(vtu, *solved.mesh, solved.result, ExportInfo{"cornell", solved.settings});
    const auto ref = std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples" / "reference" / "cornell_classes_192.csv";
    const auto reference = read_reference(ref);
    const SolveResult& r = solved.result;
    const ProbeScore want = score_at_probes(*solved.mesh, r.radiosity, reference, r.point_radiosity);
    ASSERT_GT(want.scored, 150u);

    const auto run = bounce_run("score " + vtu.string() + " --reference " + ref.string() + " --out " + probes.string());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_EQ(run.err, "");
    char head[200];
    std::snprintf(
        head, sizeof head,
        "%zu probes scored, %zu skipped (no value, dark, or on no diffuse cell); reference noise %.2f%% RMS\n",
        want.scored, want.skipped, 100 * want.reference_noise);
    EXPECT_EQ(run.out.substr(0, run.out.find('\n') + 1), head) << run.out;
    expect_row(row_of(run.out, "all"), want.scored,
               {want.rms_smooth, median_abs(scored(want.smooth_error)), want.max_smooth, want.rms_patch,
                median_abs(scored(want.patch_error)), want.max_patch},
               "all");
    // The reference's class column, a row per class.
    const CsvTable table = read_csv(ref);
    std::vector<ProbeClass> classes;
    for (const auto& row : table.rows)
        for (const ProbeClass c : kProbeClasses)
            if (row[std::size_t(table.column("class"))] == to_string(c)) classes.push_back(c);
    ASSERT_EQ(classes.size(), reference.size());
    const auto by_class = score_by_class(want, classes);
    for (std::size_t k = 0; k < kProbeClasses.size(); ++k) {
        const ClassScore& b = by_class[k];
        const ProbeClass c = kProbeClasses[k];
        EXPECT_GT(b.scored, 30u);
        expect_row(row_of(run.out, to_string(c)), b.scored,
                   {b.rms_smooth, median_abs(scored(want.smooth_error, &classes, c)), b.max_smooth, b.rms_patch,
                    median_abs(scored(want.patch_error, &classes, c)), b.max_patch},
                   to_string(c));
    }
    // The box is open at the front: the light that leaves it, per channel.
    char escaped[120];
    std::snprintf(escaped, sizeof escaped, "escaped share of the emitted power: R %.2f%% G %.2f%% B %.2f%%\n",
                  100 * r.escaped_power.r / r.emitted_power.r, 100 * r.escaped_power.g / r.emitted_power.g,
                  100 * r.escaped_power.b / r.emitted_power.b);
    EXPECT_NE(run.out.find(escaped), std::string::npos) << escaped << run.out;
    EXPECT_GT(r.escaped_power.g, 0.01 * r.emitted_power.g);

    // --out: every scored probe, in the reference's order, its errors to the last bit.
    const CsvTable out = read_csv(probes);
    EXPECT_EQ(out.header, (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "surface", "class",
                                                    "reference_luminance", "cell_error", "point_error"}));
    ASSERT_EQ(out.rows.size(), want.scored);
    std::size_t row = 0;
    for (std::size_t k = 0; k < reference.size(); ++k) {
        if (std::isnan(want.patch_error[k])) continue;
        const auto& f = out.rows[row++];
        EXPECT_EQ(std::stod(f[0]), reference[k].position.x);
        EXPECT_EQ(f[6], reference[k].surface);
        EXPECT_EQ(f[7], to_string(classes[k]));
        EXPECT_EQ(std::stod(f[8]), reference[k].radiosity.luminance());
        EXPECT_NEAR(std::stod(f[9]), want.patch_error[k], 1e-12) << "probe " << k;
        EXPECT_NEAR(std::stod(f[10]), want.smooth_error[k], 1e-12) << "probe " << k;
    }

    // The same solution written as ASCII scores the same.
    const auto ascii = dir / "ascii.vtu";
    write_vtu(ascii, *solved.mesh, r, ExportInfo{"cornell", solved.settings}, true);
    const auto again = bounce_run("score " + ascii.string() + " --reference " + ref.string() + " --quiet");
    ASSERT_EQ(again.exit_code, 0) << again.err;
    EXPECT_EQ(again.out, run.out.substr(0, run.out.find("wrote ")));
}

// A closed furnace has one exact answer, B = 2 everywhere. The direct solve on balanced rows
// (each sums to 1 but for rounding) reaches it in every cell, and with --gather none the point
// data are means of cells: score finds no error beyond that rounding; a reference 10% below it
// reads as 10% too bright, and its standard error as its noise.
TEST(CliScore, FurnaceScoresItsKnownAnswer) {
    test::TempDir dir;
    const auto scene = dir.write("furnace.json", kFurnace);
    const auto vtu = dir / "furnace.vtu";
    const auto solve =
        bounce_run("solve " + scene.string() + " --patches 200 --solver direct --gather none -q -o " + vtu.string());
    ASSERT_EQ(solve.exit_code, 0) << solve.err;

    const auto exact = dir.write("exact.csv", furnace_reference(2.0, 0.02));
    const auto probes = dir / "probes.csv";
    const auto r = bounce_run("score " + vtu.string() + " --reference " + exact.string() + " --out " + probes.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(
        r.out.find("6 probes scored, 0 skipped (no value, dark, or on no diffuse cell); reference noise 1.00% RMS"),
        std::string::npos)
        << r.out;
    expect_row(row_of(r.out, "all"), 6, {0, 0, 0, 0, 0, 0}, "all");
    expect_row(row_of(r.out, "penumbra"), 2, {0, 0, 0, 0, 0, 0}, "penumbra");
    EXPECT_EQ(row_of(r.out, "contact")[0], 1.0);
    EXPECT_NE(r.out.find("escaped share of the emitted power: R 0.00% G 0.00% B 0.00%"), std::string::npos) << r.out;
    const CsvTable t = read_csv(probes);
    ASSERT_EQ(t.rows.size(), 6u);
    for (const auto& row : t.rows) {
        EXPECT_NEAR(std::stod(row[8]), 2.0, 1e-15);
        EXPECT_LT(std::abs(std::stod(row[9])), 1e-7) << row[9];
        EXPECT_LT(std::abs(std::stod(row[10])), 1e-7) << row[10];
    }

    const auto off = dir.write("off.csv", furnace_reference(2.0 / 1.1, 0.0));
    const auto o = bounce_run("score " + vtu.string() + " --reference " + off.string() + " --out " + probes.string());
    ASSERT_EQ(o.exit_code, 0) << o.err;
    EXPECT_NE(o.out.find("reference noise 0.00% RMS"), std::string::npos) << o.out;
    expect_row(row_of(o.out, "all"), 6, {0.1, 0.1, 0.1, 0.1, 0.1, 0.1}, "all");
    for (const auto& row : read_csv(probes).rows) {
        EXPECT_NEAR(std::stod(row[9]), 0.1, 1.1e-7) << row[9];
        EXPECT_NEAR(std::stod(row[10]), 0.1, 1.1e-7) << row[10];
    }
}

// Mirrors and glass are cells of the .vtu (material_kind 1 and 2) but not patches: a probe on
// the mirror scores nowhere, and the note says why the scores may run high.
TEST(CliScore, SkipsMirrorsAndGlass) {
    test::TempDir dir;
    const auto scene = dir.write("mirror.json", R"({ "name": "furnace with a mirror",
  "materials": { "glow": { "reflectance": 0.5, "emission": 1 }, "silver": { "kind": "mirror" } },
  "objects": [ { "type": "box", "material": "glow", "inward": true, "transform": { "scale": [2, 1.5, 1] } },
               { "type": "quad", "material": "silver", "transform": { "scale": 0.5 } } ] })");
    const auto vtu = dir / "mirror.vtu", probes = dir / "probes.csv";
    ASSERT_EQ(bounce_run("solve " + scene.string() + " --patches 200 -q -o " + vtu.string()).exit_code, 0);
    const auto ref =
        dir.write("ref.csv", furnace_reference(2.0, 0.02) + "0.1,0.05,0,0,0,1,lit,2,2,2,0,0,0,4096,box,converged\n");
    const auto r = bounce_run("score " + vtu.string() + " --reference " + ref.string() + " --out " + probes.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("6 probes scored, 1 skipped"), std::string::npos) << r.out;
    EXPECT_EQ(row_of(r.out, "lit")[0], 2.0) << r.out;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("mirror.vtu: its 1 mirror or glass cell is not scored"), std::string::npos) << r.err;
    for (const auto& row : read_csv(probes).rows) EXPECT_NE(row[0], "0.1");  // not the mirror's probe
    const auto quiet = bounce_run("score " + vtu.string() + " --reference " + ref.string() + " -q");
    ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
    EXPECT_EQ(quiet.err, "");
    EXPECT_EQ(quiet.out, r.out.substr(0, r.out.find("wrote ")));
}

// A solve stopped short is scored as written, and the note says it did not finish.
TEST(CliScore, NotesASolveThatDidNotFinish) {
    test::TempDir dir;
    const auto vtu = dir / "short.vtu";
    const auto solve = bounce_run("solve --patches 200 --max-shots 3 --gather none -q -o " + vtu.string());
    ASSERT_EQ(solve.exit_code, 3) << solve.err;
    const auto ref = std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples" / "reference" / "cornell_classes_192.csv";
    const auto r = bounce_run("score " + vtu.string() + " --reference " + ref.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("short.vtu: NOT CONVERGED (max iterations) after 3 steps"), std::string::npos) << r.err;
    EXPECT_EQ(bounce_run("score " + vtu.string() + " --reference " + ref.string() + " --quiet").err, "");
}

TEST(CliScore, RefusesMissingFilesAndAReferenceOffTheMesh) {
    test::TempDir dir;
    const auto ref = std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples" / "reference" / "cornell_classes_192.csv";
    const auto missing = bounce_run("score " + (dir / "none.vtu").string() + " --reference " + ref.string());
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_EQ(lines(missing.err), 1) << missing.err;
    EXPECT_NE(missing.err.find("none.vtu: file not found"), std::string::npos) << missing.err;
    EXPECT_EQ(missing.out, "");

    // The Cornell box's probes on the furnace's solution: a reference of another scene.
    const auto vtu = dir / "furnace.vtu";
    const auto scene = dir.write("furnace.json", kFurnace);
    ASSERT_EQ(bounce_run("solve " + scene.string() + " --patches 200 -q -o " + vtu.string()).exit_code, 0);
    const auto off = bounce_run("score " + vtu.string() + " --reference " + ref.string());
    EXPECT_EQ(off.exit_code, 2);
    EXPECT_EQ(lines(off.err), 1) << off.err;
    EXPECT_NE(off.err.find("cornell_classes_192.csv: none of its 192 probes lies on a diffuse cell of"),
              std::string::npos)
        << off.err;
    EXPECT_EQ(off.out, "");

    // The study's probes (metres) on the Cornell box (millimetres): a few lie on its floor and
    // walls by chance, and the rest are noted.
    const auto cornell = dir / "cornell.vtu";
    ASSERT_EQ(bounce_run("solve --patches 300 -q -o " + cornell.string()).exit_code, 0);
    const auto study = std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples" / "reference" / "study_classes_192.csv";
    const auto chance = bounce_run("score " + cornell.string() + " --reference " + study.string());
    EXPECT_EQ(chance.exit_code, 0);
    EXPECT_EQ(lines(chance.err), 1) << chance.err;
    EXPECT_NE(chance.err.find("probes are not scored"), std::string::npos) << chance.err;
    EXPECT_NE(chance.err.find("a reference of another scene?"), std::string::npos) << chance.err;
    const auto own = bounce_run("score " + cornell.string() + " --reference " + ref.string());
    EXPECT_EQ(own.exit_code, 0);
    EXPECT_EQ(own.err.find("not scored"), std::string::npos) << own.err;

    std::string shadow = furnace_reference(2.0, 0.02);
    shadow.replace(shadow.find(",lit,"), 5, ",shadow,");
    const auto bad_class =
        bounce_run("score " + vtu.string() + " --reference " + dir.write("shadow.csv", shadow).string());
    EXPECT_EQ(bad_class.exit_code, 2);
    EXPECT_EQ(lines(bad_class.err), 1) << bad_class.err;
    EXPECT_NE(bad_class.err.find("shadow.csv:2: column 'class', got 'shadow'"), std::string::npos) << bad_class.err;

    const auto no_ref = bounce_run("score " + vtu.string() + " --reference " + (dir / "none.csv").string());
    EXPECT_EQ(no_ref.exit_code, 2);
    EXPECT_EQ(lines(no_ref.err), 1) << no_ref.err;
    EXPECT_NE(no_ref.err.find("none.csv"), std::string::npos) << no_ref.err;

    const auto corrupt = dir.write("corrupt.vtu", "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">\n");
    const auto bad = bounce_run("score " + corrupt.string() + " --reference " + ref.string());
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_EQ(lines(bad.err), 1) << bad.err;
    EXPECT_NE(bad.err.find("corrupt.vtu"), std::string::npos) << bad.err;
}
