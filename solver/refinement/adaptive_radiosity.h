// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <vector>

#include "mesh/meshing/element_tree.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/linear/solve_result.h"

namespace bounce {

class Visibility;

struct AdaptiveOptions {
    double target_error = 0.05;        // stop when the area-weighted RMS of the estimates is below this
    std::size_t max_elements = 20000;  // element budget (compare --meshes keeps this method to compare)
    int max_rounds = 16;               // refine-and-solve rounds at most
    int max_level = 10;                // no element smaller than its patch / 4^max_level
    double tolerance = 1e-6;           // relative residual of each round's patch-level solve
    FormFactorOptions form_factors;
    const std::atomic<bool>* cancel = nullptr;
    std::function<void(std::size_t round, const struct AdaptiveRound&)> progress;  // after every round
};

/// One refine-and-solve round.
struct AdaptiveRound {
    std::size_t elements = 0;
    double max_estimate = 0.0;  // largest element error estimate after this round's solve
    double rms_estimate = 0.0;  // area-weighted RMS of the estimates
    double seconds = 0.0;       // since the start
};

struct AdaptiveSolution {
    ElementTree tree;
    std::vector<std::uint32_t> leaves;  // tree nodes, the elements of the result
    std::vector<double> estimate;       // per element: its error estimate
    SolveResult result;                 // per element
    std::vector<AdaptiveRound> rounds;
};

/// Adaptive subdivision with patches and elements (Cohen, Greenberg, Immel and Brock 1986), kept
/// for `compare --meshes` to compare against (`solve --adaptive` is the hierarchical solver):
/// the patches (coarse) carry the light transport, elements (quadtree leaves over them)
/// resolve it. Each element e gathers a row g_e[q] = F(e -> q) over the patches; the patch
/// system uses F_pq = sum over elements e of p of (A_e / A_p) g_e[q], is solved by
/// Gauss-Seidel, and every element takes B_e = E_e + rho_e sum_q g_e[q] B_q. The error estimate
/// of an element compares B_e with the radiosity gathered at its corners, B(x) = E + rho
/// sum_q F(x -> q) B_q: the RMS over corners and channels of the difference, relative to the RMS
/// reflected radiosity of the scene (the scale rms_difference uses). Until the
/// area-weighted RMS of the estimates is under the target, the elements holding the largest
/// shares A_e est_e^2 of it are split (within the budget) and the patch system is solved
/// again: rows of elements that were not split are kept, so a round costs only its new
/// elements and corners.
AdaptiveSolution solve_adaptive(const std::vector<Patch>& patches, const Visibility& visibility,
                                const AdaptiveOptions& options);

/// Uniform refinement to `level` (every patch cut into 4^level elements) with the same
/// machinery: the baseline adaptive subdivision is measured against.
AdaptiveSolution solve_uniform_elements(const std::vector<Patch>& patches, const Visibility& visibility, int level,
                                        const AdaptiveOptions& options);

/// Area-weighted RMS difference over elements and channels, relative to the RMS of the
/// reference's reflected radiosity (B - E: the light's own E would swamp the scale), between a
/// solution on `a`'s elements and a reference on `ref`'s elements over the same patches; each
/// reference element is compared with the element of `a` that contains its centre.
double rms_difference(const AdaptiveSolution& a, const AdaptiveSolution& ref);
/// The same for any solution on leaves of a tree over the same patches (hierarchical radiosity).
double rms_difference(const ElementTree& tree, const std::vector<std::uint32_t>& leaves,
                      const std::vector<Rgb>& radiosity, const AdaptiveSolution& ref);

}  // namespace bounce
