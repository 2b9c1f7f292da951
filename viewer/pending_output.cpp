// SPDX-License-Identifier: MIT
#include "viewer/pending_output.h"

#include <atomic>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "mesh/scene/input_error.h"

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

void check_output(const std::filesystem::path& out) {
    const auto dir = out.has_parent_path() ? out.parent_path() : std::filesystem::path(".");
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec))
        throw MissingFileError(out.string() + ": output directory " + dir.string() + " does not exist");
    if (std::filesystem::is_directory(out, ec)) throw InputError(out.string() + ": is a directory");
}

void commit_output(const std::filesystem::path& tmp, const std::filesystem::path& final, bool written,
                   const std::string& what) {
    std::error_code ec;
    if (!written) {
        std::filesystem::remove(tmp, ec);
        throw std::runtime_error(final.string() + ": cannot write the " + what);
    }
    std::filesystem::rename(tmp, final, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw std::runtime_error(final.string() + ": cannot write the " + what + " (" + ec.message() + ")");
    }
}

void write_text_file(const std::filesystem::path& final, const std::function<void(std::ostream&)>& body,
                     const std::string& what) {
    const std::filesystem::path tmp = final.string() + ".tmp";
    const PendingOutput pending(tmp.c_str());
    bool written;
    {
        std::ofstream out(tmp);
        if (out) body(out);
        written = bool(out.flush());
    }
    commit_output(tmp, final, written, what);
}

}  // namespace bounce
