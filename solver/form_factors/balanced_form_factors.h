// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <vector>

#include "mesh/meshing/patch.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/open_parts.h"

namespace bounce {

/// What balancing did: the patches it balanced and how close their row sums came to the target.
struct BalanceReport {
    std::size_t balanced = 0;    // patches whose open part is closed and whose row was balanced
    int iterations = 0;          // scaling sweeps
    double worst_row_error = 0;  // max |sum_j F'_ij / a_i - 1| over the balanced rows
};

/// The form factors made reciprocal and, on closed open parts, summing to what they must.
///
/// Sampled rows carry noise: a closed part's row sums to a_i (its open share) only on
/// average, and each patch gathers along its own noisy row, so in a bright closed scene each
/// patch is off by its row's error times about 1/(1 - rho). Scaling each row to its sum keeps
/// the power but breaks reciprocity (A_i F_ij = A_j F_ji), and a patch then receives along
/// its column a total that is still off. Balancing keeps both: the exchange G_ij = A_i F_ij
/// is made symmetric ((G_ij + G_ji) / 2) and scaled on both sides, G'_ij = d_i G_ij d_j,
/// with d found by the symmetric Sinkhorn iteration d_i <- sqrt(d_i t_i / (G d)_i) (Knight
/// 2008, "The Sinkhorn-Knopp algorithm: convergence and applications"; for view factors,
/// Larsen & Howell 1986, "Least-squares smoothing of direct-exchange areas in zonal
/// analysis"), so that every closed part's row sums to its open share a_i: a furnace is then
/// flat, whatever blocks what.
///
/// Only closed parts (every ray from the open part met a front, OpenPart::closed) are scaled;
/// the exchange between a closed part and a patch that sees openings or back sides stays as
/// sampled, and the target t_i = a_i A_i less that exchange. A part whose target is not
/// positive, or which sees no other closed part, is left as sampled.
///
/// `whole`: the whole patches' matrix (before open_part_matrix), `open` one per patch.
FormFactorMatrix balance_form_factors(FormFactorMatrix whole, const std::vector<Patch>& patches,
                                      const std::vector<OpenPart>& open, BalanceReport* report = nullptr);

}  // namespace bounce
