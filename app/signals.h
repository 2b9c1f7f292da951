// SPDX-License-Identifier: MIT
// SIGINT/SIGTERM for every command: the first asks the running work to stop (the solution so
// far is written, marked not converged); a second exits at once, removing the temporary file
// being written (viewer/pending_output.h).
#pragma once

#include <atomic>

namespace bounce::app {

/// Set by the first SIGINT/SIGTERM; long-running work polls it (the `cancel` of the options).
extern std::atomic<bool> g_interrupted;

void install_signal_handlers();

/// 128 + the signal that interrupted the run, or 0 when none did.
int interrupted_exit_code();

}  // namespace bounce::app
