// SPDX-License-Identifier: MIT
// Balanced form factors (balanced_form_factors.h): reciprocal rows that sum to the open share
// on closed parts, and untouched exchange with parts that see an opening.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "mesh/patch_mesh.h"
#include "mesh/validation_scenes.h"
#include "solver/form_factors/balanced_form_factors.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/visibility/visibility.h"

using namespace bounce;

namespace {

struct Balanced {
    std::vector<Patch> patches;
    std::vector<OpenPart> open;
    FormFactorMatrix sampled, balanced;
    BalanceReport report;
};

Balanced balance(const Scene& s) {
    MeshingOptions o;
    o.max_edge = 0.25 * (1 + 1e-9);
    const PatchMesh mesh(s, o);
    const auto vis = make_visibility("embree", mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
    Balanced b{
        mesh.patches(), open_parts(mesh.patches(), *vis), FormFactorMatrix::build(*ff, mesh.size(), 1u << 30), {}, {}};
    b.balanced = balance_form_factors(b.sampled, b.patches, b.open, &b.report);
    return b;
}

}  // namespace

TEST(BalancedFormFactors, ClosedRowsSumToOneAndStayReciprocal) {
    // Closed box: every part closed and open (a_i = 1), so every row must sum to 1; sampled
    // with 2 rays a pair the partly hidden pairs leave rows off by up to a few per cent.
    const Balanced b = balance(floating_block_furnace());
    const std::size_t n = b.patches.size();
    ASSERT_EQ(b.report.balanced, n);
    const std::vector<double> before = b.sampled.row_sums(), after = b.balanced.row_sums();
    double worst_before = 0, worst_after = 0, worst_reciprocity = 0, change = 0;
    for (std::size_t i = 0; i < n; ++i) {
        worst_before = std::max(worst_before, std::abs(before[i] - 1));
        worst_after = std::max(worst_after, std::abs(after[i] - 1));
        for (std::size_t j = 0; j < n; ++j) {
            const double gij = b.patches[i].area * b.balanced(i, j), gji = b.patches[j].area * b.balanced(j, i);
            worst_reciprocity = std::max(worst_reciprocity, std::abs(gij - gji) / std::max(gij, 1e-12));
            if (b.sampled(i, j) > 1e-4f)
                change = std::max(change, std::abs(double(b.balanced(i, j)) / b.sampled(i, j) - 1));
        }
    }
    std::printf(
        "closed box with a block, %zu patches: row sums off by up to %.2e sampled, %.2e balanced "
        "(%d sweeps); reciprocity %.1e; entries changed by up to %.2f%%\n",
        n, worst_before, worst_after, b.report.iterations, worst_reciprocity, 100 * change);
    EXPECT_GT(worst_before, 1e-3);
    EXPECT_LT(worst_after, 2e-6);
    EXPECT_LT(b.report.worst_row_error, 2e-6);
    EXPECT_LT(worst_reciprocity, 1e-5);
    EXPECT_LT(change, 0.1) << "balancing corrects sampling noise, not the form factors";
}

TEST(BalancedFormFactors, ExchangeWithPartsThatSeeAnOpeningStaysAsSampled) {
    // Without its lid the box's parts see the opening: they are not closed, so their rows
    // (and, by reciprocity, their columns) keep the sampled exchange.
    const Balanced b = balance(floating_block_furnace(false));
    const std::size_t n = b.patches.size();
    std::size_t open_rows = 0;
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (b.open[i].closed) continue;
        ++open_rows;
        for (std::size_t j = 0; j < n; ++j) {
            const double s = b.sampled(i, j), t = b.balanced(i, j);
            // the sampled pair made symmetric: (A_i F_ij + A_j F_ji) / 2 over A_i
            const double sym = 0.5 * (s + double(b.sampled(j, i)) * b.patches[j].area / b.patches[i].area);
            worst = std::max(worst, std::abs(t - sym) / std::max(sym, 1e-9));
        }
    }
    std::printf("open box: %zu of %zu rows see the opening, %zu balanced; their entries differ by %.1e\n", open_rows, n,
                b.report.balanced, worst);
    EXPECT_GT(open_rows, n / 2);
    EXPECT_LT(worst, 1e-6);
}
