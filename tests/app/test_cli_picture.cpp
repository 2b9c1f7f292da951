// SPDX-License-Identifier: MIT
// `bounce compare --picture`: the two-pass picture and the path tracer at equal time, scored
// against a long path-traced image.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"

namespace {

const std::string kExe = BOUNCE_EXE;

bounce::test::RunResult bounce_run(const std::string& args) { return bounce::test::run(kExe + " " + args); }

std::vector<std::map<std::string, std::string>> read_csv(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::string line;
    std::vector<std::string> head;
    std::vector<std::map<std::string, std::string>> rows;
    auto split = [](const std::string& s) {
        std::vector<std::string> out;
        std::stringstream ss(s);
        for (std::string f; std::getline(ss, f, ',');) out.push_back(f);
        return out;
    };
    if (std::getline(in, line)) head = split(line);
    while (std::getline(in, line)) {
        const auto f = split(line);
        std::map<std::string, std::string> row;
        for (std::size_t k = 0; k < head.size() && k < f.size(); ++k) row[head[k]] = f[k];
        rows.push_back(row);
    }
    return rows;
}

}  // namespace

TEST(CliPicture, CompareScoresBothMethodsAtEqualTimeOnTheDiffusePixels) {
    bounce::test::TempDir dir;
    const auto r =
        bounce_run("compare --picture --quiet --out " + dir.path().string() +
                   " --picture-size 32x32 --picture-patches 100,150 --picture-samples 1,2 --picture-photons 2000,4000 "
                   "--reference-paths 64");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto rows = read_csv(dir / "picture.csv");
    ASSERT_EQ(rows.size(), 4u);
    for (std::size_t k = 0; k < rows.size(); k += 2) {
        const auto& two_pass = rows[k];
        const auto& traced = rows[k + 1];
        EXPECT_EQ(two_pass.at("method"), "two-pass");
        EXPECT_EQ(traced.at("method"), "path tracer");
        EXPECT_EQ(two_pass.at("scene"), "cornell-spheres");
        // The path tracer runs until the two-pass time is spent, a whole round at least.
        EXPECT_GE(std::stod(traced.at("seconds")), 0.999 * std::stod(two_pass.at("seconds")));
        EXPECT_GE(std::stoull(traced.at("paths_per_pixel")), 1u);
        for (const auto* row : {&two_pass, &traced}) {
            const double e = std::stod(row->at("rms_error"));
            EXPECT_GT(e, 0.0);
            EXPECT_LT(e, 10.0);
        }
    }
    // The front view of the box: every pixel shows a wall, the floor, the ceiling or a sphere,
    // but the lamp's few (and a pixel that may show it through the glass).
    const double scored = std::stod(rows[0].at("pixels")) / (32.0 * 32.0);
    std::printf("scored pixels %.3f of the picture, reference noise %s\n", scored,
                rows[0].at("reference_noise").c_str());
    EXPECT_GT(scored, 0.85);
    EXPECT_LT(scored, 1.0);
    EXPECT_GT(std::stod(rows[0].at("reference_noise")), 0.0);
    // Both measures of the error: over the 3 x 3 neighbourhood's reference and each pixel's own.
    EXPECT_GT(std::stod(rows[0].at("rms_error_own")), 0.0);
    EXPECT_GT(std::stod(rows[0].at("reference_noise_own")), 0.0);
    for (const char* f : {"picture_error.png", "picture_side_by_side.png", "reference_cornell-spheres_32x32_64.pfm",
                          "reference_cornell-spheres_32x32_64_se.pfm"})
        EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
    // The caustic under the glass sphere, by the last budget's emitter photons and by the path
    // tracer: its power within 20% at 4000 photons (a few hundred land there).
    const auto caustic = read_csv(dir / "caustic.csv");
    ASSERT_EQ(caustic.size(), 2u);
    EXPECT_EQ(caustic[0].at("method"), "photon map");
    EXPECT_EQ(caustic[1].at("method"), "path tracer");
    const double p = std::stod(caustic[0].at("power")), q = std::stod(caustic[1].at("power"));
    std::printf("caustic power: photon map %.0f W, path tracer %.0f W\n", p, q);
    EXPECT_NEAR(p, q, 0.2 * q);
}

TEST(CliPicture, BadPictureOptionsAreOneLineAndExitTwo) {
    bounce::test::TempDir dir;
    for (const std::string& args :
         {"compare --picture --picture-samples 1,2 --picture-photons 1000 --out " + dir.path().string(),
          "compare --picture-size 32x32 --out " + dir.path().string(),
          "compare --picture --picture-size 8x8 --out " + dir.path().string(),
          "compare --picture --meshes --out " + dir.path().string()}) {
        const auto r = bounce_run(args);
        EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    }
}
