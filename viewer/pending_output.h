// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace bounce {

/// The temporary file being written right now (outputs are written to a temporary file and
/// renamed). A signal handler that must exit at once removes it with unlink(), which is
/// async-signal-safe, so an interrupted run never leaves a partial file behind.
void set_pending_output(const char* path);  // nullptr: none
const char* pending_output();               // safe to call from a signal handler

/// Finishes an output written to `tmp`: when `written` is false, removes `tmp` and throws;
/// else renames it to `final` (atomic within a directory), removing it if the rename fails.
/// Throws std::runtime_error "<final>: cannot write the <what>".
void commit_output(const std::filesystem::path& tmp, const std::filesystem::path& final, bool written,
                   const std::string& what);

/// Writes a text file the same way: `body` fills a temporary beside `final` (registered as the
/// pending output), then commit_output renames it. Throws std::runtime_error on failure.
void write_text_file(const std::filesystem::path& final, const std::function<void(std::ostream&)>& body,
                     const std::string& what);

/// Refuses an unwritable destination before any work is done: InputError (MissingFileError
/// when its folder does not exist) naming it.
void check_output(const std::filesystem::path& out);

/// Registers `path` for the lifetime of the object.
class PendingOutput {
public:
    explicit PendingOutput(const char* path) { set_pending_output(path); }
    ~PendingOutput() { set_pending_output(nullptr); }
    PendingOutput(const PendingOutput&) = delete;
    PendingOutput& operator=(const PendingOutput&) = delete;
};

}  // namespace bounce
