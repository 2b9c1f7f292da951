// SPDX-License-Identifier: MIT
#pragma once

#include "solver/linear/direct_solver.h"  // the exact solution of the same system
#include "solver/linear/solver.h"

namespace bounce {

/// Jacobi and Gauss-Seidel iteration on the full matrix ("gathering": each patch collects
/// from all others), optionally over-relaxed:
///     B_i <- B_i + w (E_i + rho_i sum_j F_ij B_j - B_i).
/// Jacobi uses the previous sweep's B everywhere (rows in parallel); Gauss-Seidel uses each
/// new value at once (sequential) and converges in fewer sweeps. Both contract like
/// (rho * row sum)^k. The residual of the previous iterate is computed in the same pass over
/// F, so checking it costs no extra sweep.
class GatheringSolver final : public Solver {
public:
    GatheringSolver(bool gauss_seidel, const RadiositySystem& system, const SolverOptions& options);
    std::string name() const override { return m_gauss_seidel ? "gauss-seidel" : "jacobi"; }
    SolveResult solve() override;

private:
    bool m_gauss_seidel;
    const std::vector<Patch>& m_patches;
    const FormFactorMatrix& m_F;
    SolverOptions m_options;
};

}  // namespace bounce
