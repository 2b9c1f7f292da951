// SPDX-License-Identifier: MIT
// Linear pictures in OpenEXR: read back by OpenEXR itself.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

#include "test_util.h"
#include "viewer/exr_writer.h"

using namespace bounce;

namespace {

struct Picture {
    int width = 0, height = 0;
    std::vector<float> rgb;  // rows top to bottom, interleaved
};

Picture read_exr(const std::filesystem::path& p) {
    Imf::InputFile file(p.c_str());
    const auto window = file.header().dataWindow();
    Picture out;
    out.width = window.max.x - window.min.x + 1;
    out.height = window.max.y - window.min.y + 1;
    out.rgb.assign(3 * std::size_t(out.width) * std::size_t(out.height), -1.0f);
    Imf::FrameBuffer frame;
    const std::size_t xs = 3 * sizeof(float), ys = xs * std::size_t(out.width);
    const char* names[3] = {"R", "G", "B"};
    for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_EQ(file.header().channels().findChannel(names[k])->type, Imf::FLOAT) << names[k];
        frame.insert(names[k], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(out.rgb.data() + k), xs, ys));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return out;
}

/// A .pfm as write_pfm writes it (little-endian floats, rows bottom to top), rows top to bottom.
Picture read_pfm(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::string magic;
    double scale = 0;
    Picture out;
    in >> magic >> out.width >> out.height >> scale;
    in.get();
    out.rgb.resize(3 * std::size_t(out.width) * std::size_t(out.height));
    const std::size_t row = 3 * std::size_t(out.width);
    for (int r = out.height - 1; r >= 0; --r)
        in.read(reinterpret_cast<char*>(out.rgb.data() + std::size_t(r) * row), std::streamsize(row * sizeof(float)));
    return out;
}

}  // namespace

TEST(ExrWriter, ReadsBackAsTheFloatsOfTheRadiance) {
    const test::TempDir dir;
    const int W = 7, H = 5;
    std::vector<Rgb> pixels;
    for (int i = 0; i < W * H; ++i)
        // Values a float cannot hold exactly, a wide range, and zero.
        pixels.push_back({0.1 * i + 1.0 / 3.0, 1e-7 * i * i, i == 3 ? 0.0 : 12345.678 / (i + 1)});
    pixels[10] = {std::numeric_limits<float>::max(), 1e-30, 0.5};
    const auto path = dir / "x.exr";
    write_exr(path, W, H, pixels);
    const Picture p = read_exr(path);
    ASSERT_EQ(p.width, W);
    ASSERT_EQ(p.height, H);
    for (std::size_t i = 0; i < pixels.size(); ++i)
        for (int k = 0; k < 3; ++k) ASSERT_EQ(p.rgb[3 * i + std::size_t(k)], float(pixels[i][k])) << i << " " << k;
    // Only the picture is left: the temporary was renamed.
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
    EXPECT_EQ(files, 1u);
}

TEST(ExrWriter, AFailedWriteThrowsAndLeavesNoFile) {
    const test::TempDir dir;
    EXPECT_THROW(write_exr(dir / "missing" / "x.exr", 2, 2, std::vector<Rgb>(4)), std::runtime_error);
    EXPECT_THROW(write_exr(dir / "x.exr", 2, 2, std::vector<Rgb>(3)), std::runtime_error);
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(ExrWriter, RenderWritesTheSameRadianceAsThePfm) {
    const test::TempDir dir;
    const std::string args = " --size 24x20 --samples 1 --photons 2000 --patches 100 --quiet";
    for (const char* name : {"a.exr", "a.pfm"}) {
        const auto r =
            test::run(std::string(BOUNCE_EXE) + " render cornell-spheres -o " + (dir / name).string() + args);
        ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    const Picture exr = read_exr(dir / "a.exr"), pfm = read_pfm(dir / "a.pfm");
    ASSERT_EQ(exr.width, 24);
    ASSERT_EQ(exr.height, 20);
    ASSERT_EQ(exr.rgb.size(), pfm.rgb.size());
    double sum = 0;
    for (std::size_t i = 0; i < exr.rgb.size(); ++i) {
        ASSERT_EQ(exr.rgb[i], pfm.rgb[i]) << i;
        sum += exr.rgb[i];
    }
    std::printf("mean radiance of the picture %.6g\n", sum / double(exr.rgb.size()));
    EXPECT_GT(sum, 0.0);
}
