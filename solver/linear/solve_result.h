// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "mesh/scene/rgb.h"

namespace bounce {

/// One line of a solver's convergence log. Errors are against a reference solution when one
/// is known (else negative: unknown); residual is negative when it was not computed.
struct ConvergenceRecord {
    std::size_t step = 0;             // shots or sweeps so far
    double seconds = 0.0;             // since the solver started (form factors not included)
    double residual = -1.0;           // ||E + rho F B - B|| / ||E||, area-weighted 2-norm
    double unshot_fraction = -1.0;    // shooting only
    double rms_error = -1.0;          // ||B - B_ref|| / ||B_ref|| over patches and channels
    double max_error = -1.0;          // max over patches of |B_i - B_ref,i| / |B_ref,i|
    double ambient_rms_error = -1.0;  // shooting: rms_error of B plus the ambient term
};

/// How a solve ended, or that it is still running (a snapshot). Compares with and prints as
/// its text ("converged", "max iterations", ...), which the .vtu's status field and the Python
/// module show.
class SolveStatus {
public:
    enum Value : std::uint8_t {
        converged,       // within the tolerance
        max_iterations,  // the shot or sweep limit came first
        max_seconds,     // the time limit came first
        diverged,        // the residual grew without bound (rows summing above 1, reflectance near 1)
        stalled,         // shooting: the unshot power stopped falling
        interrupted,     // stopped on request (Ctrl-C, a cancel flag)
        running,         // a snapshot taken during the solve
    };
    constexpr SolveStatus(Value v = max_iterations) : m_value(v) {}
    constexpr operator Value() const { return m_value; }
    const char* c_str() const {
        switch (m_value) {
            case converged:
                return "converged";
            case max_iterations:
                return "max iterations";
            case max_seconds:
                return "max seconds";
            case diverged:
                return "diverged";
            case stalled:
                return "stalled";
            case interrupted:
                return "interrupted";
            case running:
                return "running";
        }
        return "unknown";
    }
    operator std::string() const { return c_str(); }
    friend bool operator==(SolveStatus s, std::string_view text) { return text == s.c_str(); }
    friend std::ostream& operator<<(std::ostream& out, SolveStatus s) { return out << s.c_str(); }

private:
    Value m_value;
};

inline std::string to_string(SolveStatus s) { return s.c_str(); }

/// A radiosity solution and the account of where the emitted power went. Powers are
/// sum over patches of (per-area quantity) * area, per channel. Energy balance:
///     emitted = absorbed + escaped + unshot   (to rounding)
/// escaped: power that left the scene through openings (or that a form-factor row summing
/// to less than 1 lost); negative escaped means rows summed to more than 1.
struct SolveResult {
    std::vector<Rgb> radiosity;    // B_i, per patch
    std::vector<Rgb> irradiance;   // H_i: power arriving per unit area (B = E + rho H)
    std::vector<Rgb> unshot;       // radiosity received but not yet shot on (shooting solvers)
    std::string solver;            // e.g. "shooting"
    std::string form_factors;      // e.g. "raycast"
    std::size_t steps = 0;         // shots, or sweeps for iterative solvers
    double seconds = 0.0;          // wall time of the solve, form factors included
    double unshot_fraction = 0.0;  // unshot power / emitted power, summed over channels
    // Shooting: the largest relative error of a patch's radiosity (channel sums) that the unshot
    // power left would still add, as estimated from the convergence so far (infinite until
    // known); the solve stops below its tolerance.
    double error_estimate = -1.0;
    bool converged = false;
    double residual = -1.0;  // last relative residual, when computed
    SolveStatus status;      // how the solve ended
    Rgb emitted_power, absorbed_power, escaped_power, unshot_power;
    Rgb shot_power;           // shooting: all power shot; -escaped / shot is the mean row surplus of a closed scene
    Rgb back_absorbed_power;  // of absorbed_power: what black back sides took (open parts, open_parts.h)
    std::vector<ConvergenceRecord> log;
    std::vector<Rgb> display;  // shooting: B plus the ambient term (Cohen et al. 1988), for display
    // Per mesh vertex, by final gather (solver/gather); empty: the exported point data is the
    // area-weighted mean of the patches around each vertex.
    std::vector<Rgb> point_radiosity;
    std::vector<Rgb> gathered_centres;  // per patch, B gathered at its centre (--gather centres)
};

/// Progress of a running solver, for a progress line.
struct SolveProgress {
    std::size_t step = 0;
    std::size_t max_steps = 0;
    double unshot_fraction = 1.0;
    double tolerance = 0.0;
    double seconds = 0.0;
};

}  // namespace bounce
