// SPDX-License-Identifier: MIT
// `bounce solve --quality`: the presets as the program runs them.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "test_util.h"

namespace {

bounce::test::RunResult bounce_run(const std::string& args) {
    return bounce::test::run(std::string(BOUNCE_EXE) + " " + args);
}

/// An ASCII .vtu without its wall-clock field `seconds` (its DataArray, from the name to the
/// closing tag): what two runs of one solve must write alike.
std::string without_seconds(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::string vtu(std::istreambuf_iterator<char>(in), {});
    const auto name = vtu.find("Name=\"seconds\"");
    if (name == std::string::npos) return vtu;
    const auto begin = vtu.rfind('<', name);
    const std::string close = "</DataArray>";
    return vtu.erase(begin, vtu.find(close, name) + close.size() - begin);
}

/// The settings text field of an ASCII .vtu (VTK writes a string as its bytes' codes).
std::string settings_of(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    const std::string vtu(std::istreambuf_iterator<char>(in), {});
    std::istringstream codes(vtu.substr(vtu.find('>', vtu.find("Name=\"settings\"")) + 1));
    std::string text;
    int code = 0;
    while (codes >> code && code != 0) text += char(code);
    return text;
}

/// The point and cell arrays and the cells of an ASCII .vtu: all but its field data.
std::string arrays_of(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    const std::string vtu(std::istreambuf_iterator<char>(in), {});
    const auto at = vtu.find("<Piece");
    return at == std::string::npos ? "" : vtu.substr(at);
}

}  // namespace

TEST(CliQuality, TheDefaultPresetWritesTheFileNoPresetWrites) {
    bounce::test::TempDir dir;
    const auto plain = dir / "plain.vtu", preset = dir / "preset.vtu";
    ASSERT_EQ(bounce_run("solve -q --ascii -o " + plain.string()).exit_code, 0);
    ASSERT_EQ(bounce_run("solve -q --ascii --quality default -o " + preset.string()).exit_code, 0);
    const std::string a = without_seconds(plain), b = without_seconds(preset);
    ASSERT_GT(a.size(), 100000u);
    EXPECT_TRUE(a == b) << "the two files differ beyond their seconds";
}

TEST(CliQuality, AnUnknownPresetIsOneLineThatListsTheValidOnes) {
    bounce::test::TempDir dir;
    const auto r = bounce_run("solve --quality best -o " + (dir / "x.vtu").string());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, "bounce: error: --quality: unknown, got 'best' (expected one of draft, default, fine)\n");
    EXPECT_FALSE(std::filesystem::exists(dir / "x.vtu"));
    const auto mixed = bounce_run("solve --quality fine --adaptive -o " + (dir / "x.vtu").string());
    EXPECT_EQ(mixed.exit_code, 2);
    EXPECT_NE(mixed.err.find("--quality fine sets the patch solvers' patches and display cells"), std::string::npos)
        << mixed.err;
}

TEST(CliQuality, ThePresetIsRecordedAndGivenOptionsWin) {
    // Draft is --patches 1000: its file is that of --patches 1000 but for the settings naming
    // the preset. Given beside it, --patches 200 and --display-tolerance 0 win.
    bounce::test::TempDir dir;
    auto solve = [&](const std::string& name, const std::string& flags) {
        const auto out = dir / name;
        const auto r = bounce_run("solve -q --ascii " + flags + " -o " + out.string());
        EXPECT_EQ(r.exit_code, 0) << r.err;
        return out;
    };
    const auto draft = solve("draft.vtu", "--quality draft"), flags = solve("flags.vtu", "--patches 1000");
    const std::string s = settings_of(draft);
    const std::string named = " quality=draft";
    ASSERT_NE(s.find(named), std::string::npos) << s;
    EXPECT_EQ(std::string(s).erase(s.find(named), named.size()), settings_of(flags));
    EXPECT_TRUE(arrays_of(draft) == arrays_of(flags));
    const auto mixed = solve("mixed.vtu", "--quality draft --patches 200 --display-tolerance 0"),
               given = solve("given.vtu", "--patches 200 --display-tolerance 0");
    const std::string m = settings_of(mixed);
    EXPECT_EQ(m.find("display_cells"), std::string::npos) << m;
    EXPECT_EQ(std::string(m).erase(m.find(named), named.size()), settings_of(given));
    EXPECT_TRUE(arrays_of(mixed) == arrays_of(given));
    EXPECT_FALSE(arrays_of(mixed) == arrays_of(draft));
}
