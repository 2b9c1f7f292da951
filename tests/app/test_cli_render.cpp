// SPDX-License-Identifier: MIT
// `bounce render SCENE`: a diffuse scene is solved as `bounce solve` solves it, through the one
// pipeline, so its picture is the picture of the .vtu that solve writes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "test_util.h"

namespace {

const std::string kExe = BOUNCE_EXE;

bounce::test::RunResult bounce_run(const std::string& args) { return bounce::test::run(kExe + " " + args); }

std::string bytes_of(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(CliRender, ASceneIsDrawnWithTheSolutionSolveWrites) {
    // The PNG of the scene rendered at once and the PNG of the .vtu that `bounce solve` writes
    // with no flags but the meshing have the same bytes (one encoder: the same pixels): open
    // parts, balanced rows and display cells in both. The plain shooting solve on whole
    // patches, rows as sampled, point data averaged, draws another picture.
    bounce::test::TempDir dir;
    const auto png = [&](const std::string& name) { return (dir / name).string(); };
    const std::string picture = " --size 64x64 -q -o ";
    const auto at_once = bounce_run("render cornell --patches 300" + picture + png("scene.png"));
    ASSERT_EQ(at_once.exit_code, 0) << at_once.err;
    for (const std::string flags : {"", " --whole-patches --no-balance --gather none"}) {
        const auto solved = bounce_run("solve cornell --patches 300 -q" + flags + " -o " + png("x.vtu"));
        ASSERT_EQ(solved.exit_code, 0) << solved.err;
        const auto drawn = bounce_run("render " + png("x.vtu") + picture + png("vtu.png"));
        ASSERT_EQ(drawn.exit_code, 0) << drawn.err;
        const std::string a = bytes_of(png("scene.png")), b = bytes_of(png("vtu.png"));
        ASSERT_GT(a.size(), 100u);
        if (flags.empty())
            EXPECT_TRUE(a == b) << "render cornell and render of solve's .vtu differ";
        else
            EXPECT_FALSE(a == b) << "the plain shooting solve draws the same picture:" << flags;
    }
}
