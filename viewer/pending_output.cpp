// SPDX-License-Identifier: MIT
#include "viewer/pending_output.h"

#include <atomic>
#include <cstring>

namespace bounce {
namespace {
char g_path[4096];
std::atomic<bool> g_set{false};
}  // namespace

void set_pending_output(const char* path) {
    g_set = false;
    if (!path) return;
    std::strncpy(g_path, path, sizeof g_path - 1);
    g_path[sizeof g_path - 1] = '\0';
    g_set = true;
}

const char* pending_output() { return g_set ? g_path : nullptr; }

}  // namespace bounce
