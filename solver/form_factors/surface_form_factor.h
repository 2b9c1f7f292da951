// SPDX-License-Identifier: MIT
#pragma once

#include <vector>

#include "mesh/meshing/patch.h"
#include "solver/form_factors/form_factor_estimator.h"

namespace bounce {

/// Form factor between two input surfaces from the patch form factors:
///     F(from -> to) = sum_{i in from} sum_{j in to} A_i F_ij / A_from.
/// Computes only the rows of `from`'s patches.
double surface_form_factor(const std::vector<Patch>& patches, const FormFactorEstimator& estimator, int from, int to);

}  // namespace bounce
