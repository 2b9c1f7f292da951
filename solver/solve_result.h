// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "mesh/rgb.h"

namespace bounce {

/// A radiosity solution and the account of where the emitted power went. Powers are
/// sum over patches of (per-area quantity) * area, per channel. Energy balance:
///     emitted = absorbed + escaped + unshot   (to rounding)
/// escaped: power that left the scene through openings (or that a form-factor row summing
/// to less than 1 lost); negative escaped means rows summed to more than 1.
struct SolveResult {
    std::vector<Rgb> radiosity;   // B_i, per patch
    std::vector<Rgb> irradiance;  // H_i: power arriving per unit area (B = E + rho H)
    std::vector<Rgb> unshot;      // radiosity received but not yet shot on (shooting solvers)
    std::string solver;           // e.g. "shooting"
    std::string form_factors;     // e.g. "raycast"
    std::size_t steps = 0;        // shots, or sweeps for iterative solvers
    double seconds = 0.0;         // wall time of the solve, form factors included
    double unshot_fraction = 0.0; // unshot power / emitted power, summed over channels
    bool converged = false;
    Rgb emitted_power, absorbed_power, escaped_power, unshot_power;
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
