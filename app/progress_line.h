// SPDX-License-Identifier: MIT
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <mutex>
#include <string>

#include "solver/linear/solve_result.h"

namespace bounce::app {

/// A one-line progress display on a terminal, at most five updates a second.
class ProgressLine {
public:
    explicit ProgressLine(bool enabled, std::string step = "shot", std::string measure = "unshot")
        : m_enabled(enabled && ::isatty(STDERR_FILENO)), m_step(std::move(step)), m_measure(std::move(measure)) {}
    ~ProgressLine() { finish(); }
    void update(const SolveProgress& p) {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_enabled || p.seconds - m_last < 0.2) return;
        m_last = p.seconds;
        std::fprintf(stderr, "\r%s %zu, %s %.2e (target %.1e), %.1f s   ", m_step.c_str(), p.step, m_measure.c_str(),
                     p.unshot_fraction, p.tolerance, p.seconds);
        m_shown = true;
    }
    /// Rows of a form-factor matrix; called from worker threads.
    void rows(std::size_t done, std::size_t total) {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_enabled) return;
        const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
        if (now - m_last < 0.2 && done < total) return;
        m_last = now;
        std::fprintf(stderr, "\rform factors: %zu / %zu rows, %.1f s   ", done, total, now);
        m_shown = true;
    }
    /// Items of a parallel job ("path tracing: points"); called from worker threads.
    void items(const char* what, std::size_t done, std::size_t total) {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_enabled) return;
        const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
        if (now - m_last < 0.2 && done < total) return;
        m_last = now;
        std::fprintf(stderr, "\r%s %zu / %zu, %.1f s   ", what, done, total, now);
        m_shown = true;
    }
    /// Runs of a series ("compare --meshes: 3 / 19 runs, hierarchical link epsilon 0.4"),
    /// shown at once: called as each run starts, from one thread.
    void runs(const char* what, std::size_t done, std::size_t total, const std::string& running) {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_enabled) return;
        const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
        m_last = now;
        std::fprintf(stderr, "\r%s: %zu / %zu runs done, %.1f s; now %-40s", what, done, total, now, running.c_str());
        m_shown = true;
    }
    void finish() {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_last = 0.0;
        m_start = std::chrono::steady_clock::now();
        if (m_shown) std::fputc('\n', stderr);
        m_shown = false;
    }

private:
    bool m_enabled;
    std::string m_step, m_measure;
    bool m_shown = false;
    double m_last = 0.0;
    std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now();
    std::mutex m_mutex;
};

}  // namespace bounce::app
