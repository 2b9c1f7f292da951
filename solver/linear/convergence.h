// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mesh/meshing/patch.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/open_parts.h"
#include "solver/linear/solve_result.h"

namespace bounce {

/// ||E + rho F B - B|| / ||E||, with the area-weighted 2-norm ||x||^2 = sum_i A_i |x_i|^2 over
/// patches and channels (a power-like measure that does not change with the meshing).
double relative_residual(const std::vector<Patch>& patches, const FormFactorMatrix& F, const std::vector<Rgb>& B);

/// Errors of B against a reference R: the relative RMS error ||B - R|| / ||R|| (2-norms over
/// patches and channels) and the largest per-patch relative error |B_i - R_i| / |R_i|
/// (channel sums; patches with R_i = 0, fully hidden ones, are skipped).
void reference_errors(const std::vector<Rgb>& B, const std::vector<Rgb>& reference, double& rms, double& max);

/// Largest rho_i * sum_j F_ij over patches and channels: a bound on the spectral radius of
/// rho F. At or above 1 the iteration need not converge (reflectance 1 in a closed scene makes
/// the system singular; rows summing above 1 make it diverge).
double contraction_bound(const std::vector<Patch>& patches, const std::vector<double>& row_sums);

/// The energy account of a gathering solution on elements: element k is geometry[leaves[k]]
/// with res.radiosity[k] and res.irradiance[k] set. Fills emitted, absorbed ((1 - rho) H A)
/// and escaped power (what leaves the surfaces, B A, less what arrives, H A: it went out
/// through the openings); nothing is unshot. `open_share` (per element, or empty: all open):
/// the share of its area open to the scene, over which it emits, sends and receives (B and H
/// being the open part's); an element with none open receives over its whole area and sends
/// nothing, so what reaches it and what it emits is absorbed (as by a back side).
void gathered_energy_account(const std::vector<Patch>& geometry, const std::vector<std::uint32_t>& leaves,
                             SolveResult& res, std::span<const double> open_share = {});

/// The energy account of a gathering solution on the full matrix, from res.radiosity: the
/// irradiance H_j = sum_i B_i A_i F_ij / A_j, emitted, absorbed ((1 - rho) H A) and escaped
/// power (B A times what row i leaves unsummed, 1 - sum_j F_ij), and as unshot power what
/// B still differs from E + rho H by (the residual a gathering solver still owes).
/// With `open` (open_parts.h), P are the open parts and F their matrix (open_part_matrix):
/// what each open part sends that lands on no front goes to back sides (absorbed) and out
/// (escaped) in the shares its rays saw.
void matrix_energy_account(const std::vector<Patch>& P, const FormFactorMatrix& F, SolveResult& res,
                           const std::vector<OpenPart>* open = nullptr);

}  // namespace bounce
