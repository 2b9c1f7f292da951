// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <vector>

#include "solver/linear/solver.h"

namespace bounce {

/// Progressive refinement radiosity (Cohen, Chen, Wallace and Greenberg 1988): Southwell
/// iteration on B = E + rho F B. Each step picks the patch with the most unshot power
/// dB_i A_i and shoots it: every patch j receives dH_j = dB_i F_ij A_i / A_j, reflects
/// rho_j dH_j, and that reflected part becomes j's unshot radiosity. Needs one form-factor row
/// per shot, never the whole matrix (rows of re-shooting patches are cached within a budget).
/// Stops on the error it leaves: when the largest relative error of a patch's radiosity that
/// the unshot power would still add, estimated from the rate the unshot power has been falling
/// at and where the last stretch of shooting sent its light, is below `tolerance`
/// (SolveResult::error_estimate). Without a shot limit it stops as "stalled" when the unshot
/// power does not halve while a thousand times it is shot (reflectance ~1 in a closed scene,
/// or rows summing above 1). The ambient term
/// (the unshot power spread uniformly and inter-reflected, 1/(1 - mean rho)) gives a display
/// estimate of an unfinished solution in SolveResult::display.
using ShootingOptions = SolverOptions;

/// Patches shoot, elements receive (Cohen, Greenberg, Immel and Brock 1986, "An efficient
/// radiosity approach for realistic image synthesis"). The solver's `patches` are then the
/// elements, element e belonging to shooters[parents[e]]. A shooter sends the area-weighted
/// mean unshot radiosity of its elements as a uniform emitter, and its form-factor rows run
/// over the elements. Rows cost O(elements) each and only shooters' rows are cached, so a
/// fine element mesh costs memory in proportion to shooters x elements, not elements^2.
struct ElementHierarchy {
    const std::vector<Patch>* shooters = nullptr;
    const std::vector<std::uint32_t>* parents = nullptr;
};

class ShootingSolver final : public Solver {
public:
    ShootingSolver(const std::vector<Patch>& patches, const FormFactorEstimator& form_factors,
                   const SolverOptions& options, const FormFactorMatrix* matrix = nullptr,
                   ElementHierarchy hierarchy = {});
    std::string name() const override { return "shooting"; }
    SolveResult solve() override;

private:
    const std::vector<Patch>& m_patches;
    const FormFactorEstimator& m_ff;
    SolverOptions m_options;
    const FormFactorMatrix* m_matrix;  // when given: residuals in the log
    ElementHierarchy m_hierarchy;
};

}  // namespace bounce
