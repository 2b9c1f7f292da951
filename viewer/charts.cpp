// SPDX-License-Identifier: MIT
#include "viewer/charts.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace bounce {

void write_comparison_charts(const std::filesystem::path& folder) {
    const std::filesystem::path script = std::filesystem::path(BOUNCE_CHARTS_DIR) / "plot_compare.py";
    const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + folder.string() + "'";
    if (std::system(cmd.c_str()) != 0) throw std::runtime_error("drawing the charts failed: " + cmd);
}

void write_mesh_charts(const std::filesystem::path& folder) {
    for (const char* name : {"plot_meshes.py", "plot_probe_errors.py"}) {
        const std::filesystem::path script = std::filesystem::path(BOUNCE_CHARTS_DIR) / name;
        const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + folder.string() + "'";
        if (std::system(cmd.c_str()) != 0) throw std::runtime_error("drawing the charts failed: " + cmd);
    }
}

void write_picture_chart(const std::filesystem::path& folder) {
    const std::filesystem::path script = std::filesystem::path(BOUNCE_CHARTS_DIR) / "plot_picture.py";
    const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + folder.string() + "'";
    if (std::system(cmd.c_str()) != 0) throw std::runtime_error("drawing the chart failed: " + cmd);
}

}  // namespace bounce
