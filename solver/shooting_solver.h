// SPDX-License-Identifier: MIT
#pragma once

#include <vector>

#include "solver/solver.h"

namespace bounce {

/// Progressive refinement radiosity (Cohen, Chen, Wallace and Greenberg 1988): Southwell
/// iteration on B = E + rho F B. Each step picks the patch with the most unshot power
/// dB_i A_i and shoots it: every patch j receives dH_j = dB_i F_ij A_i / A_j, reflects
/// rho_j dH_j, and that reflected part becomes j's unshot radiosity. Needs one form-factor row
/// per shot, never the whole matrix (rows of re-shooting patches are cached within a budget).
/// Stops when the unshot power falls below `tolerance` of the emitted power. The ambient term
/// (the unshot power spread uniformly and inter-reflected, 1/(1 - mean rho)) gives a display
/// estimate of an unfinished solution in SolveResult::display.
using ShootingOptions = SolverOptions;

class ShootingSolver final : public Solver {
public:
    ShootingSolver(const std::vector<Patch>& patches, const FormFactorEstimator& form_factors,
                   const SolverOptions& options, const FormFactorMatrix* matrix = nullptr);
    std::string name() const override { return "shooting"; }
    SolveResult solve() override;

private:
    const std::vector<Patch>& m_patches;
    const FormFactorEstimator& m_ff;
    SolverOptions m_options;
    const FormFactorMatrix* m_matrix;  // when given: residuals in the log
};

}  // namespace bounce
