// SPDX-License-Identifier: MIT
// The `bounce` command line: thin over the mesh, solver and viewer libraries. Each command
// lives in its own file (app/command.h); this builds the CLI11 app, runs the chosen command
// and turns what it throws into a message and an exit code.
#include <cstddef>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef __GLIBC__  // (defined by the standard headers above)
#include <malloc.h>
#endif

#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include "app/command.h"
#include "app/signals.h"
#include "mesh/scene/errors.h"
#include "viewer/version.h"

int main(int argc, char** argv) {
    // First of all, so a signal during start-up or parsing already asks the work to stop
    // instead of killing the process before it can write anything.
    bounce::app::install_signal_handlers();
    // Large blocks a stage frees (links, the gather's arrays, Gauss points) stay with the
    // process for the next stage instead of going back to the kernel, whose fresh pages fault
    // again: glibc returns blocks above 128 kB by default. On the 2-core machines a page fault
    // costs about 10 us; the hierarchical box at power epsilon 1e-6 took 28k of them, 16k so,
    // and about 8% less wall time (alternated runs).
    // Resident memory then stays near its peak between stages, which --max-memory's estimates
    // already count.
#ifdef __GLIBC__
    mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    mallopt(M_TOP_PAD, 64 << 20);
#endif
    using namespace bounce::app;
    CLI::App app{"bounce: progressive-refinement radiosity"};
    app.set_version_flag("--version", std::string(bounce::kBounceVersion));
    app.require_subcommand(1);
    CommonOptions common;
    // In the order --help lists them.
    const std::vector<Command> commands = {
        add_solve_command(app, common),     add_form_factors_command(app, common), add_compare_command(app, common),
        add_render_command(app, common),    add_view_command(app, common),         add_info_command(app, common),
        add_reference_command(app, common), add_score_command(app, common),
    };

    // CLI11 answers an unknown command with "A subcommand is required": name it instead, and
    // list the real ones.
    if (argc > 1 && argv[1][0] != '-') {
        std::string known;
        bool found = false;
        for (const Command& c : commands) {
            known += (known.empty() ? "" : ", ") + c.cli->get_name();
            found |= c.cli->get_name() == argv[1];
        }
        if (!found) {
            std::cerr << "bounce: error: command line: unknown command, got '" << argv[1] << "' (expected one of "
                      << known << "; see bounce --help)\n";
            return 2;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        std::cerr << "bounce: error: " << e.what() << " (see --help)\n";
        return 2;
    }
    std::optional<tbb::global_control> threads;
    if (common.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(common.threads));
    try {
        for (const Command& c : commands)
            if (*c.cli) return c.run();
        return 2;                           // unreachable: require_subcommand(1)
    } catch (const bounce::UserError& e) {  // bad input, a limit, no solution (mesh/scene/errors.h)
        std::cerr << "bounce: error: " << e.what() << "\n";
        return 2;
    } catch (const bounce::Interrupted& e) {
        std::cerr << "bounce: " << e.what() << "; nothing written\n";
        return interrupted_exit_code() ? interrupted_exit_code() : 130;
    } catch (const std::invalid_argument& e) {  // an option value the library refuses
        std::cerr << "bounce: error: " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {  // a programmer error
        std::cerr << "bounce: failed: " << e.what() << "\n";
        return 1;
    }
}
