// SPDX-License-Identifier: MIT
#pragma once

#include <optional>
#include <vector>

#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/unoccluded_form_factor.h"

namespace bounce {

/// Hemicube form factors (Cohen and Greenberg 1985). A half-cube of `resolution` pixels per
/// side of its top face sits at the shooter's centre; every patch is projected onto its five
/// faces and kept per pixel where it is nearest (an item buffer with depth, on the CPU). Each
/// pixel carries its precomputed delta form factor
///     dF = (n . w) dA / (pi |w|^4),   w = direction through the pixel on a unit-distance face
/// (top: 1/(pi (x^2+y^2+1)^2) dA; sides: z/(pi (y^2+z^2+1)^2) dA), and F_ij is the sum over
/// the pixels that see j. A point method at the shooter's centre: it fails for patches
/// closer than their own size, and aliases with regular pixels (optionally rotate the cube
/// about the normal by a random angle per row, seeded, to break the aliasing).
/// With `hemicube_exact_kernel` (`--hemicube-baum`) the pixels only say what fraction of j the centre
/// sees, and the unoccluded factor over both patches says how much (Baum, Rushmeier and Winget
/// 1989, "Improving radiosity solutions through the use of analytically determined
/// form-factors"): F_ij = F_unoccluded,ij (delta sum of j's visible pixels / of all pixels j
/// covers, hidden or not); a patch that covers no pixel centre counts as seen.
class HemicubeFormFactor final : public FormFactorEstimator {
public:
    HemicubeFormFactor(const std::vector<Patch>& patches, const FormFactorOptions& options);
    std::string name() const override { return "hemicube"; }
    void compute_row(std::size_t i, std::span<float> row) const override;

private:
    const std::vector<Patch>& m_patches;
    FormFactorOptions m_options;
    std::optional<UnoccludedFormFactor> m_unoccluded;  // hemicube_exact_kernel: Baum et al. 1989
    std::vector<double> m_top_delta, m_side_delta;     // delta form factors per pixel
    double m_eps = 0.0;                                // eye lift off the shooter's plane
};

}  // namespace bounce
