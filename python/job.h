// SPDX-License-Identifier: MIT
// A long call of the module: its work on a worker thread with the GIL released, while the
// calling thread polls for Ctrl-C and reports progress.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <pybind11/pybind11.h>

namespace bounce::python {

namespace py = pybind11;

/// What a running job last reported, for the Python progress callback.
struct Progress {
    std::string stage;       // "form factors", "solve", "gathering: vertices", ...
    std::size_t step = 0;    // rows, shots, sweeps or points done
    std::size_t total = 0;   // of how many (0: unknown)
    double value = -1.0;     // solve: estimated relative error (shooting) or relative residual
    double tolerance = 0.0;  // solve: the value it stops under
    double seconds = 0.0;    // since the stage began
};

class Job {
public:
    std::atomic<bool> cancel{false};

    /// Called from worker threads: keeps the latest state for the next poll.
    void report(const Progress& p) {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_progress = p;
        ++m_version;
    }
    void report_items(const char* stage, std::size_t done, std::size_t total) {
        Progress p;
        p.stage = stage;
        p.step = done;
        p.total = total;
        p.seconds = elapsed();
        report(p);
    }
    double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count(); }

    /// Runs `work` on a worker thread, the GIL released. Every 50 ms the calling thread takes
    /// the GIL back to run Python's signal handlers (Ctrl-C raises KeyboardInterrupt there,
    /// and only there: CPython runs handlers on the main thread) and to call `callback` with
    /// fresh progress. A Python exception from either sets `cancel`, waits for the work to
    /// stop (within one shot, sweep or row) and propagates; the work's result is dropped, so
    /// nothing half-done reaches the caller.
    void run(const std::function<void()>& work, const py::object& callback) {
        std::exception_ptr error;
        bool done = false;
        std::mutex mutex;
        std::condition_variable finished;
        std::thread worker([&] {
            try {
                work();
            } catch (...) {
                error = std::current_exception();
            }
            std::lock_guard<std::mutex> lock(mutex);
            done = true;
            finished.notify_all();
        });
        auto stop = [&] {
            cancel = true;
            py::gil_scoped_release release;
            worker.join();
        };
        std::uint64_t seen = 0;
        for (bool over = false; !over;) {
            {
                py::gil_scoped_release release;
                std::unique_lock<std::mutex> lock(mutex);
                over = finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; });
            }
            if (PyErr_CheckSignals() != 0) {
                py::error_already_set e;
                stop();
                throw e;
            }
            if (callback.is_none()) continue;
            std::optional<Progress> fresh;
            {
                std::lock_guard<std::mutex> lock(m_mutex);
                if (m_version != seen) fresh = m_progress;
                seen = m_version;
            }
            if (!fresh) continue;
            try {
                callback(*fresh);
            } catch (...) {
                stop();
                throw;
            }
        }
        {
            py::gil_scoped_release release;
            worker.join();
        }
        if (error) std::rethrow_exception(error);
    }

private:
    std::mutex m_mutex;
    Progress m_progress;
    std::uint64_t m_version = 0;
    std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now();
};

}  // namespace bounce::python
