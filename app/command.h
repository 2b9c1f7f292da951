// SPDX-License-Identifier: MIT
// The commands of `bounce`, one file each (app/<command>.cpp). Each defines one function
//     Command add_<command>_command(CLI::App& app, CommonOptions& common);
// that adds its subcommand and flags to `app` and returns how to run it; main.cpp calls them
// in the order of --help and runs the one that was chosen. A new command is one more file,
// its declaration here, and one more line in main.cpp's list.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

#include "app/common_options.h"

namespace bounce::app {

struct Command {
    CLI::App* cli = nullptr;   // the subcommand; true when it was chosen on the command line
    std::function<int()> run;  // runs it with the parsed options; returns the exit code
};

Command add_solve_command(CLI::App& app, CommonOptions& common);         // app/solve.cpp
Command add_form_factors_command(CLI::App& app, CommonOptions& common);  // app/form_factors.cpp
Command add_compare_command(CLI::App& app, CommonOptions& common);       // app/compare.cpp
Command add_render_command(CLI::App& app, CommonOptions& common);        // app/render.cpp
Command add_view_command(CLI::App& app, CommonOptions& common);          // app/view.cpp
Command add_info_command(CLI::App& app, CommonOptions& common);          // app/info.cpp
Command add_reference_command(CLI::App& app, CommonOptions& common);     // app/reference.cpp
Command add_score_command(CLI::App& app, CommonOptions& common);         // app/score.cpp

}  // namespace bounce::app
