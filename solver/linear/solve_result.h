// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "mesh/rgb.h"

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
    std::string status;      // "converged", "max iterations", "max seconds", "diverged", "stalled",
                             // "interrupted" (Ctrl-C), "running" (a snapshot during the solve)
    Rgb emitted_power, absorbed_power, escaped_power, unshot_power;
    Rgb shot_power;  // shooting: all power shot; -escaped / shot is the mean row surplus of a closed scene
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
