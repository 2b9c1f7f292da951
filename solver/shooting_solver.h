// SPDX-License-Identifier: MIT
#pragma once

#include <functional>
#include <vector>

#include "mesh/patch.h"
#include "solver/form_factor_estimator.h"
#include "solver/solve_result.h"

namespace bounce {

struct ShootingOptions {
    double tolerance = 1e-3;        // stop when unshot power / emitted power falls below this
    std::size_t max_shots = 0;      // hard stop; 0: 100 * patch count
    std::size_t cache_mb = 1024;    // form-factor rows kept for patches that shoot again
    std::function<void(const SolveProgress&)> progress;  // called after every shot
};

/// Progressive refinement radiosity (Cohen, Chen, Wallace and Greenberg 1988): Southwell
/// iteration on B = E + rho F B. Each step picks the patch with the most unshot power
/// dB_i A_i and shoots it: every patch j receives dH_j = dB_i F_ij A_i / A_j, reflects
/// rho_j dH_j, and that reflected part becomes j's unshot radiosity. Needs one form-factor row
/// per shot, never the whole matrix.
class ShootingSolver {
public:
    ShootingSolver(const std::vector<Patch>& patches, const FormFactorEstimator& form_factors,
                   const ShootingOptions& options);
    SolveResult solve();

private:
    const std::vector<Patch>& m_patches;
    const FormFactorEstimator& m_ff;
    ShootingOptions m_options;
};

}  // namespace bounce
