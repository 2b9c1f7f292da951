// SPDX-License-Identifier: MIT
// The oracle of the refinement tests: a hierarchical solution's leaves solved again with the
// whole raycast form-factor matrix.
#pragma once

#include <string>
#include <vector>

#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/linear/solver.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

namespace bounce::test {

struct FullMatrixSolution {
    std::vector<Patch> leaves;  // the hierarchical solution's leaves, as patches
    SolveResult result;         // per leaf, by `solver` to 1e-9
};

inline FullMatrixSolution full_matrix_solution(const HierarchicalSolution& s, const Visibility& vis,
                                               const std::string& solver) {
    FullMatrixSolution out;
    for (const auto l : s.leaves) out.leaves.push_back(s.tree.geometry()[l]);
    const auto ff = make_form_factor_estimator("raycast", out.leaves, &vis, {});
    const auto F = FormFactorMatrix::build(*ff, out.leaves.size(), std::size_t(1) << 31);
    SolverOptions so;
    so.tolerance = 1e-9;
    out.result = make_solver(solver, {out.leaves, ff.get(), &F}, so)->solve();
    return out;
}

}  // namespace bounce::test
