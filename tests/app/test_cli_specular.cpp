// SPDX-License-Identifier: MIT
// `bounce render` of scenes with mirrors and glass: the two-pass picture by eye rays, its
// interruption, and the refusal of bad specular input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "test_util.h"

namespace {

const std::string kExe = BOUNCE_EXE;

bounce::test::RunResult bounce_run(const std::string& args) { return bounce::test::run(kExe + " " + args); }

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

bool is_png(const std::filesystem::path& p) { return slurp(p).rfind("\x89PNG\r\n\x1a\n", 0) == 0; }

bool no_temporaries(const std::filesystem::path& dir) {
    for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().filename().string().find(".tmp") != std::string::npos) return false;
    return true;
}

// A cheap light pass: few patches and photons.
const std::string kQuick = " --patches 200 --photons 20000";

}  // namespace

TEST(CliSpecular, RenderDrawsTheSpheresBoxByEyeRays) {
    bounce::test::TempDir dir;
    const auto png = dir / "spheres.png";
    const auto r = bounce_run("render cornell-spheres -o " + png.string() + " --size 48x40 --samples 1" + kQuick);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(is_png(png));
    EXPECT_NE(r.out.find("wrote " + png.string()), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("caustic photons stored"), std::string::npos) << r.err;
    EXPECT_TRUE(no_temporaries(dir.path()));
    // A diffuse scene keeps VTK's picture unless asked for eye rays.
    const auto traced = bounce_run("render cornell --ray-trace -o " + (dir / "box.png").string() +
                                   " --size 32x32 --samples 1 --patches 200 --quiet");
    EXPECT_EQ(traced.exit_code, 0) << traced.err;
    EXPECT_TRUE(is_png(dir / "box.png"));
}

TEST(CliSpecular, CtrlCKeepsAWholePictureOfTheRowsDone) {
    bounce::test::TempDir dir;
    const auto png = dir / "big.png";
    // The light pass takes a second or two (five under the sanitizers); the eye pass of
    // 1500 x 1500 at 64 rays a pixel a quarter of an hour, so the signal after 20 s stops it.
    const auto r =
        bounce::test::run("timeout --foreground --preserve-status -s INT 20 " + kExe + " render cornell-spheres -o " +
                          png.string() + " --size 1500x1500 --samples 64" + kQuick);
    EXPECT_EQ(r.exit_code, 130) << r.err;
    EXPECT_NE(r.err.find("interrupted: " + png.string() + " holds the"), std::string::npos) << r.err;
    EXPECT_TRUE(is_png(png));
    EXPECT_TRUE(no_temporaries(dir.path()));
}

TEST(CliSpecular, BadSpecularInputIsOneLineAndExitTwo) {
    bounce::test::TempDir dir;
    const auto scene = dir.write("bad.json", R"({"materials": {"g": {"kind": "glass", "ior": 0.5}},
        "objects": [{"type": "sphere", "material": "g"}]})");
    const auto r = bounce_run("render " + scene.string() + " -o " + (dir / "x.png").string());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("bad.json: material 'g': index of refraction"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
    const auto colours = bounce_run("render cornell-spheres --luminance --patches 200 -o " + (dir / "l.png").string());
    EXPECT_EQ(colours.exit_code, 2);
    EXPECT_NE(colours.err.find("not the eye rays' picture"), std::string::npos) << colours.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "l.png"));
    const auto singular = dir.write("flat.json", R"({"materials": {"m": {"kind": "mirror"}},
        "objects": [{"type": "sphere", "material": "m", "transform": {"scale": [1, 1, 0]}}]})");
    const auto s = bounce_run("solve " + singular.string() + " -o " + (dir / "x.vtu").string());
    EXPECT_EQ(s.exit_code, 2);
    EXPECT_NE(s.err.find("flat.json: objects[0]: transform is singular"), std::string::npos) << s.err;
}

TEST(CliSpecular, LinearPicturesForScoringAsPfm) {
    bounce::test::TempDir dir;
    auto header_ok = [&](const std::filesystem::path& p, int w, int h) {
        const std::string bytes = slurp(p);
        const std::string head = "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n";
        return bytes.rfind(head, 0) == 0 && bytes.size() == head.size() + std::size_t(w * h * 3 * 4);
    };
    const auto ref = bounce_run("reference cornell-spheres --image " + (dir / "ref.pfm").string() +
                                " --size 12x10 --paths 64 --quiet");
    EXPECT_EQ(ref.exit_code, 0) << ref.err;
    EXPECT_TRUE(header_ok(dir / "ref.pfm", 12, 10));
    EXPECT_TRUE(header_ok(dir / "ref_se.pfm", 12, 10));
    const auto two = bounce_run("render cornell-spheres -o " + (dir / "two.pfm").string() +
                                " --size 12x10 --samples 1 --quiet" + kQuick);
    EXPECT_EQ(two.exit_code, 0) << two.err;
    EXPECT_TRUE(header_ok(dir / "two.pfm", 12, 10));
    EXPECT_TRUE(no_temporaries(dir.path()));
    const auto bad = bounce_run("reference cornell --image " + (dir / "x.png").string());
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("expected .pfm"), std::string::npos) << bad.err;
}

TEST(CliSpecular, AFurnaceWithAPerfectMirrorInsideShowsEOverOneMinusRho) {
    // Walls emitting E = 1 with reflectance 0.5 and a perfect mirror ball inside: B = 2
    // everywhere on the walls. Without photons the ball absorbs what the walls send it (8% of
    // their power), and the picture is 8% dark; the photons give it back.
    bounce::test::TempDir dir;
    const auto scene = dir.write("furnace.json", R"({ "materials": {
        "wall": { "reflectance": 0.5, "emission": 1 }, "mirror": { "kind": "mirror", "reflectance": 1 } },
      "objects": [ { "type": "box", "material": "wall", "inward": true, "transform": { "scale": 4 } },
                   { "type": "sphere", "material": "mirror", "transform": { "scale": 0.8, "translate": [0, -1, 0] } } ] })");
    auto mean_b = [&](const std::string& extra) {
        const auto pfm = dir / "f.pfm";
        const auto r =
            bounce_run("render " + scene.string() + " -o " + pfm.string() +
                       " --size 24x24 --samples 4 --camera 0,1.5,1.9:0,-1,-1.9 --fov 60 --patches 600 --quiet" + extra);
        EXPECT_EQ(r.exit_code, 0) << r.err;
        const std::string bytes = slurp(pfm);
        const std::size_t head = bytes.size() - 24 * 24 * 3 * 4;
        double sum = 0;
        for (std::size_t k = 0; k < 24 * 24; ++k) {
            float g;
            std::memcpy(&g, bytes.data() + head + 12 * k + 4, 4);
            sum += double(g) * 3.141592653589793;
        }
        return sum / (24 * 24);
    };
    EXPECT_NEAR(mean_b(""), 2.0, 0.02);
    EXPECT_LT(mean_b(" --photons 0"), 1.9);
}
