// SPDX-License-Identifier: MIT
#pragma once

#include "solver/linear/solver.h"

namespace bounce {

/// Dense LU with partial pivoting of (I - diag(rho_c) F) B_c = E_c per channel: the exact
/// solution of the discrete system, the reference for error curves. O(N^3) time, N^2 doubles.
class DirectSolver final : public Solver {
public:
    DirectSolver(const RadiositySystem& system, const SolverOptions& options);
    std::string name() const override { return "direct"; }
    SolveResult solve() override;

private:
    const std::vector<Patch>& m_patches;
    const FormFactorMatrix& m_F;
    SolverOptions m_options;
};

}  // namespace bounce
