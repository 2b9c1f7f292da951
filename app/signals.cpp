// SPDX-License-Identifier: MIT
#include "app/signals.h"

#include <unistd.h>

#include <csignal>

#include "viewer/pending_output.h"

namespace bounce::app {

std::atomic<bool> g_interrupted{false};

namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_signal(int sig) {
    if (g_signal != 0) {
        if (const char* p = pending_output()) ::unlink(p);
        ::_exit(128 + sig);
    }
    g_signal = sig;
    g_interrupted.store(true);
}

}  // namespace

void install_signal_handlers() {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

int interrupted_exit_code() { return g_signal ? 128 + int(g_signal) : 0; }

}  // namespace bounce::app
