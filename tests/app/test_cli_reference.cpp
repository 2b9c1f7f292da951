// SPDX-License-Identifier: MIT
// `bounce reference` and the probe scores of `bounce compare`, run as a user runs them.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "mesh/scene/input_error.h"
#include "solver/reference/reference_csv.h"
#include "test_util.h"

using namespace bounce;

namespace {

const std::string kExe = BOUNCE_EXE;

test::RunResult bounce_run(const std::string& args) { return test::run(kExe + " " + args); }

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Column `name` of every row whose column `key` equals `value`, as numbers.
std::vector<double> column_where(const CsvTable& t, const std::string& name, const std::string& key,
                                 const std::string& value) {
    std::vector<double> out;
    const int c = t.column(name), k = t.column(key);
    for (const auto& r : t.rows)
        if (r[std::size_t(k)] == value) out.push_back(std::stod(r[std::size_t(c)]));
    return out;
}

}  // namespace

TEST(CliReference, ProbesAreEstimatedToTheTargetAndRepeatExactly) {
    test::TempDir dir;
    const auto a = dir / "a.csv", b = dir / "b.csv";
    const auto r = bounce_run("reference --probes 24 --target-error 0.02 --seed 5 -o " + a.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    ASSERT_EQ(
        bounce_run("reference --probes 24 --target-error 0.02 --seed 5 --threads 1 -q -o " + b.string()).exit_code, 0);
    EXPECT_EQ(slurp(a), slurp(b));  // same seed, same numbers, on any thread count
    const CsvTable t = read_csv(a);
    EXPECT_EQ(t.header, (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "class", "B_r", "B_g", "B_b", "se_r",
                                                  "se_g", "se_b", "paths", "surface", "status"}));
    ASSERT_EQ(t.rows.size(), 24u);
    // The Cornell box has penumbrae, contacts and points in shadow enough for a quarter each.
    std::map<std::string, int> per_class;
    for (const auto& row : t.rows) ++per_class[row[6]];
    EXPECT_EQ(per_class, (std::map<std::string, int>{{"contact", 6}, {"lit", 6}, {"penumbra", 6}, {"unlit", 6}}));
    for (const auto& p : read_reference(a)) {
        EXPECT_EQ(p.status, "converged");
        // The luminance weights applied to the channels' errors bound the luminance's error from
        // above (the channels move together, so the bound is nearly tight).
        EXPECT_LE(p.standard_error.luminance(), 0.02 * 1.25 * p.radiosity.luminance());
        EXPECT_GT(p.radiosity.luminance(), 0.0);
        EXPECT_FALSE(p.surface.empty());
    }
}

TEST(CliReference, PointsAreSnappedOrRefusedByRow) {
    test::TempDir dir;
    // Cornell box (mm): a point 1 mm above the floor, one 1 mm in front of the back wall, and a
    // label column that must be copied through, quoted.
    const auto good = dir.write("good.csv",
                                "label,x,y,z,nx,ny,nz\n"
                                "\"floor, front\",300,1,100,0,1,0\n"
                                "back,280,300,558.2,0,0,-1\n");
    const auto out = dir / "out.csv";
    const auto r = bounce_run("reference --points " + good.string() + " --target-error 0.03 -q -o " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const CsvTable t = read_csv(out);
    ASSERT_EQ(t.rows.size(), 2u);
    EXPECT_EQ(t.rows[0][0], "floor, front");
    EXPECT_EQ(t.rows[0][std::size_t(t.column("surface"))], "floor");
    EXPECT_EQ(t.rows[1][std::size_t(t.column("surface"))], "back wall");

    // 40 mm off every surface (the snap distance is 0.5% of the 950 mm diagonal, about 4.7 mm).
    const auto far = dir.write("far.csv", "x,y,z,nx,ny,nz\n300,1,100,0,1,0\n300,40,100,0,1,0\n");
    const auto bad = bounce_run("reference --points " + far.string() + " -o " + (dir / "far_out.csv").string());
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("far.csv:3: no surface"), std::string::npos) << bad.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "far_out.csv"));

    const auto skip = bounce_run("reference --points " + far.string() + " --skip-missing --target-error 0.05 -q -o " +
                                 (dir / "skip.csv").string());
    ASSERT_EQ(skip.exit_code, 0) << skip.err;
    const CsvTable s = read_csv(dir / "skip.csv");
    EXPECT_EQ(s.rows[1][std::size_t(s.column("status"))], "missing");
    EXPECT_EQ(s.rows[1][std::size_t(s.column("B_r"))], "");
    EXPECT_EQ(s.rows[0][std::size_t(s.column("status"))], "converged");

    const auto nan = dir.write("nan.csv", "x,y,z,nx,ny,nz\n300,1,100,0,1,0\n300,nan,100,0,1,0\n");
    const auto n = bounce_run("reference --points " + nan.string() + " -o " + (dir / "nan_out.csv").string());
    EXPECT_EQ(n.exit_code, 2);
    EXPECT_NE(n.err.find("nan.csv:3: column y: not a finite number"), std::string::npos) << n.err;

    EXPECT_EQ(bounce_run("reference -o " + (dir / "x.csv").string()).exit_code, 2);  // neither --points nor --probes
    const auto missing = bounce_run("reference --points " + (dir / "none.csv").string());
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_NE(missing.err.find("none.csv: CSV file not found"), std::string::npos) << missing.err;
}

TEST(CliReference, CtrlCWritesWhatItHasFlagged) {
    test::TempDir dir;
    const auto out = dir / "int.csv";
    const auto r = test::run("bash -c '" + kExe + " reference --probes 400 --target-error 0.0005 -q -o " +
                             out.string() + " & pid=$!; sleep 2; kill -INT $pid; wait $pid; exit $?'");
    EXPECT_EQ(r.exit_code, 130) << r.err;
    ASSERT_TRUE(std::filesystem::exists(out)) << r.err;
    const auto points = read_reference(out);
    ASSERT_EQ(points.size(), 400u);
    std::size_t interrupted = 0;
    for (const auto& p : points) interrupted += p.status == "interrupted";
    EXPECT_GT(interrupted, 0u);
    EXPECT_NE(r.err.find("interrupted"), std::string::npos);
}

// The accuracy axis of every chart: on the default Cornell box, uniform patch meshes come closer
// to the path-traced truth as they grow (scored on probes path traced beforehand).
TEST(CliReference, CompareMeshesScoresUniformMeshesFallingWithSize) {
    test::TempDir dir;
    const auto ref = dir / "ref.csv";
    ASSERT_EQ(bounce_run("reference --probes 64 --target-error 0.01 -q -o " + ref.string()).exit_code, 0);
    const auto r = bounce_run(
        "compare --meshes --reference-level 2 --patch-counts 250,500,1000,2000 --link-epsilons 0.4,0.2,0.1 "
        "--max-level 1 --reference " +
        ref.string() + " --out " + dir.path().string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const CsvTable t = read_csv(dir / "meshes.csv");
    for (const char* c : {"probe_rms_patch", "probe_max_patch", "probe_rms_smooth", "probe_max_smooth"})
        EXPECT_GE(t.column(c), 0) << c;
    const auto smooth = column_where(t, "probe_rms_smooth", "method", "patches");
    const auto elements = column_where(t, "elements", "method", "patches");
    ASSERT_EQ(smooth.size(), 4u);
    for (std::size_t k = 1; k < smooth.size(); ++k) {
        EXPECT_GT(elements[k], elements[k - 1]);
        EXPECT_LT(smooth[k], smooth[k - 1]) << "at " << elements[k] << " patches";
    }
    // The scores are errors against an independent answer: not zero, and with contact cuts and
    // gathered point data the default-sized mesh is within 3% (7.4% with averaged point data on
    // uncut patches).
    EXPECT_GT(smooth.back(), 0.003);
    EXPECT_LT(smooth.back(), 0.03);
    for (double n : column_where(t, "probe_points", "method", "patches")) EXPECT_GT(n, 50);
}

// Issue 17's chart of error against wall time: hierarchical rows, one per link epsilon, scored
// at the shipped Cornell probes (128, path traced to 0.5%), beside uniform patch meshes; with
// --reference-level 0 no fine uniform elements are solved, as on a large scene.
TEST(CliReference, CompareMeshesScoresHierarchicalRowsPerLinkEpsilon) {
    test::TempDir dir;
    const auto probes = std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples" / "reference" / "cornell_probes_128.csv";
    const auto r = bounce_run(
        "compare --meshes --reference-level 0 --methods patches,hierarchical --patch-counts 250 "
        "--link-epsilons 0.8,0.4 --max-level 2 --reference " +
        probes.string() + " --out " + dir.path().string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const CsvTable t = read_csv(dir / "meshes.csv");
    ASSERT_EQ(t.rows.size(), 3u);  // no reference, no uniform elements, no adaptive
    EXPECT_EQ(column_where(t, "elements", "method", "patches").size(), 1u);
    const auto smooth = column_where(t, "probe_rms_smooth", "method", "hierarchical");
    const auto patch = column_where(t, "probe_rms_patch", "method", "hierarchical");
    const auto links = column_where(t, "links", "method", "hierarchical");
    const auto seconds = column_where(t, "seconds", "method", "hierarchical");
    const auto scored = column_where(t, "probe_points", "method", "hierarchical");
    ASSERT_EQ(smooth.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
        // Finite errors against an independent answer: above the probes' own noise (0.48%),
        // and not wild (measured: 8.1% and 6.6% point data, 38% and 35% patch values).
        EXPECT_TRUE(std::isfinite(smooth[k]) && std::isfinite(patch[k]));
        EXPECT_GT(smooth[k], 0.005);
        EXPECT_LT(smooth[k], 0.15);
        EXPECT_LT(patch[k], 0.6);
        EXPECT_GT(seconds[k], 0.0);
        EXPECT_EQ(scored[k], 128.0);
    }
    // A smaller link epsilon refines more links (measured 45,221 -> 101,216) and comes closer.
    EXPECT_GT(links[1], 1.5 * links[0]);
    EXPECT_LT(smooth[1], smooth[0]);
    // No fine uniform elements: the "vs fine" column is empty on every row.
    const int rms = t.column("rms_error");
    for (const auto& row : t.rows) EXPECT_TRUE(row[std::size_t(rms)].empty()) << row[0];
    EXPECT_TRUE(std::filesystem::exists(dir / "meshes.png"));
}

// Issue 35: compare --meshes' "adaptive" rows are what `solve --adaptive` runs (the same coarse
// patches, max level, power epsilon: the same elements and links), and `compare --help` states
// the coarse patch count both start from.
TEST(CliReference, CompareMeshesAdaptiveRowIsSolveAdaptive) {
    test::TempDir dir;
    const auto help = bounce_run("compare --help");
    ASSERT_EQ(help.exit_code, 0) << help.err;
    const auto at = help.out.find(" on the Cornell box");
    ASSERT_NE(at, std::string::npos) << help.out;
    const std::size_t start = help.out.find_last_not_of("0123456789", at - 1) + 1;
    const std::string coarse = help.out.substr(start, at - start);
    ASSERT_FALSE(coarse.empty()) << help.out;
    const auto probes = std::filesystem::path(BOUNCE_SOURCE_DIR) / "examples" / "reference" / "cornell_probes_128.csv";
    const auto c =
        bounce_run("compare --meshes --reference-level 0 --methods adaptive --link-epsilons 0.8 --reference " +
                   probes.string() + " --out " + dir.path().string());
    ASSERT_EQ(c.exit_code, 0) << c.err;
    const auto shoot = c.out.find(coarse + " patches shoot");
    ASSERT_NE(shoot, std::string::npos) << coarse << "\n" << c.out;
    EXPECT_TRUE(shoot == 0 || c.out[shoot - 1] == '\n') << c.out;  // the whole number
    const auto s = bounce_run("solve --adaptive --link-epsilon 0.8 --gather none -o " + (dir / "a.vtu").string());
    ASSERT_EQ(s.exit_code, 0) << s.err;
    EXPECT_NE(s.out.find("patches " + coarse + ", hierarchical (--adaptive"), std::string::npos) << s.out;
    const CsvTable t = read_csv(dir / "meshes.csv");
    const auto elements = column_where(t, "elements", "method", "adaptive");
    const auto links = column_where(t, "links", "method", "adaptive");
    ASSERT_EQ(elements.size(), 1u);
    const std::string printed =
        std::to_string(std::size_t(elements[0])) + " elements, " + std::to_string(std::size_t(links[0])) + " links";
    EXPECT_NE(s.out.find(printed), std::string::npos) << printed << "\n" << s.out;
}

TEST(CliReference, CompareCachesItsOwnProbesAndScoresEveryRun) {
    test::TempDir dir;
    const auto r = bounce_run("compare --max-area 20000 --form-factors raycast --solvers shooting,direct --out " +
                              dir.path().string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::filesystem::path cached;
    for (const auto& e : std::filesystem::directory_iterator(dir.path()))
        if (e.path().filename().string().rfind("reference-", 0) == 0) cached = e.path();
    ASSERT_FALSE(cached.empty());
    EXPECT_EQ(read_reference(cached).size(), 128u);
    const CsvTable runs = read_csv(dir / "runs.csv");
    ASSERT_EQ(runs.rows.size(), 2u);
    const auto a = column_where(runs, "probe_rms_patch", "form_factors", "raycast");
    // Shooting to 1e-3 unshot and the direct solution are the same discrete answer: same score.
    EXPECT_NEAR(a[0], a[1], 0.01);
    EXPECT_GT(a[0], 0.01);
    const auto again =
        bounce_run("compare --max-area 20000 --form-factors raycast --solvers shooting --out " + dir.path().string());
    ASSERT_EQ(again.exit_code, 0) << again.err;
    EXPECT_NE(again.out.find("(cached)"), std::string::npos) << again.out;
}

TEST(CliReference, InfoReportsTheAreaLeftOutByContactCuts) {
    // Column `k` of the table's row for `where` (0 surface, 1 patches, 2 area, 3 removed).
    auto column = [](const std::string& out, const std::string& where, int k) {
        const auto at = out.find(where);
        if (at == std::string::npos) return -1.0;
        const auto start = out.rfind('\n', at) + 1;
        std::istringstream line(out.substr(start, at - start));
        double value = -1.0;
        for (int c = 0; c <= k; ++c) line >> value;
        return value;
    };
    auto removed = [&](const std::string& out, const std::string& where) { return column(out, where, 3); };
    auto area = [&](const std::string& out, const std::string& where) { return column(out, where, 2); };
    const auto r = bounce_run("info");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NEAR(removed(r.out, "cornell box: ceiling"), 130.0 * 105.0, 1e-6);  // behind the light
    // Both blocks' footprints, which their (horizontal) tops repeat.
    EXPECT_NEAR(removed(r.out, "cornell box: floor"),
                area(r.out, "cornell box: short block top") + area(r.out, "cornell box: tall block top"), 0.05);
    EXPECT_EQ(removed(r.out, "cornell box: back wall"), 0.0);
    const auto whole = bounce_run("info --no-contact-cuts");
    ASSERT_EQ(whole.exit_code, 0) << whole.err;
    EXPECT_EQ(removed(whole.out, "cornell box: floor"), 0.0);
}

TEST(CliReference, InfoNeverRemovesMoreThanASurfaceHas) {
    // The study's table legs stand under its top: each leg's top is wholly covered, by a
    // region larger than itself (the table top's outline), and must show its own area removed.
    const auto r = bounce_run("info " + std::string(BOUNCE_SOURCE_DIR) + "/examples/scenes/study.json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::istringstream out(r.out);
    std::string line;
    int rows = 0, wholly = 0;
    while (std::getline(out, line)) {
        std::istringstream fields(line);
        double index, patches, area, removed;
        if (!(fields >> index >> patches >> area >> removed)) continue;
        ++rows;
        EXPECT_LE(removed, area * (1 + 1e-9)) << line;
        if (patches == 0) {
            ++wholly;
            EXPECT_NEAR(removed, area, 1e-9 * area) << line;
        }
    }
    EXPECT_GT(rows, 30);
    EXPECT_EQ(wholly, 4);  // the four legs' tops
}

TEST(CliReference, ImageWritesOpenExr) {
    bounce::test::TempDir dir;
    const auto r = bounce_run("reference cornell-spheres --image " + (dir / "ref.exr").string() +
                              " --size 16x16 --paths 64 --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* f : {"ref.exr", "ref_se.exr"}) {
        std::ifstream in(dir / f, std::ios::binary);
        char magic[4] = {};
        in.read(magic, 4);
        // OpenEXR's magic number 20000630, little-endian.
        EXPECT_EQ(std::string(magic, 4), std::string("\x76\x2f\x31\x01", 4)) << f;
    }
}
