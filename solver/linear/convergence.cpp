// SPDX-License-Identifier: MIT
#include "solver/linear/convergence.h"

#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace bounce {

double relative_residual(const std::vector<Patch>& patches, const FormFactorMatrix& F, const std::vector<Rgb>& B) {
    const std::size_t n = patches.size();
    const double num = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, 32), 0.0,
        [&](const auto& range, double acc) {
            for (std::size_t i = range.begin(); i != range.end(); ++i) {
                const float* row = F.row(i);
                double g[3] = {0, 0, 0};
                for (std::size_t j = 0; j < n; ++j) {
                    const double f = row[j];
                    g[0] += f * B[j].r;
                    g[1] += f * B[j].g;
                    g[2] += f * B[j].b;
                }
                const Patch& p = patches[i];
                for (int c = 0; c < 3; ++c) {
                    const double r = p.emission[c] + p.reflectance[c] * g[c] - B[i][c];
                    acc += p.area * r * r;
                }
            }
            return acc;
        },
        std::plus<double>());
    double den = 0.0;
    for (const auto& p : patches)
        for (int c = 0; c < 3; ++c) den += p.area * p.emission[c] * p.emission[c];
    return den > 0 ? std::sqrt(num / den) : std::sqrt(num);
}

void reference_errors(const std::vector<Rgb>& B, const std::vector<Rgb>& reference, double& rms, double& max) {
    double diff2 = 0.0, ref2 = 0.0;
    max = 0.0;
    for (std::size_t i = 0; i < B.size() && i < reference.size(); ++i) {
        const Rgb d = B[i] - reference[i];
        diff2 += d.r * d.r + d.g * d.g + d.b * d.b;
        ref2 += reference[i].r * reference[i].r + reference[i].g * reference[i].g + reference[i].b * reference[i].b;
        const double ref = reference[i].sum();
        if (ref > 0) max = std::max(max, (std::abs(d.r) + std::abs(d.g) + std::abs(d.b)) / ref);
    }
    rms = ref2 > 0 ? std::sqrt(diff2 / ref2) : 0.0;
}

double contraction_bound(const std::vector<Patch>& patches, const std::vector<double>& row_sums) {
    double worst = 0.0;
    for (std::size_t i = 0; i < patches.size(); ++i)
        worst = std::max(worst, patches[i].reflectance.max() * row_sums[i]);
    return worst;
}

void gathered_energy_account(const std::vector<Patch>& geometry, const std::vector<std::uint32_t>& leaves,
                             SolveResult& res, std::span<const double> open_share) {
    res.emitted_power = res.absorbed_power = res.escaped_power = res.unshot_power = Rgb();
    res.back_absorbed_power = Rgb();
    Rgb power, arriving;
    for (std::size_t k = 0; k < leaves.size(); ++k) {
        const Patch& g = geometry[leaves[k]];
        const Rgb& h = res.irradiance[k];
        const double open = k < open_share.size() ? open_share[k] : 1.0;
        if (open <= 0.0) {  // buried: receives over its whole area, sends nothing
            const Rgb kept = (h + g.emission) * g.area;
            res.emitted_power += g.emission * g.area;
            res.absorbed_power += kept;
            res.back_absorbed_power += kept;
            arriving += h * g.area;
            continue;
        }
        const double area = g.area * open;
        res.emitted_power += g.emission * area;
        res.absorbed_power += (h - g.reflectance * h) * area;
        arriving += h * area;
        power += res.radiosity[k] * area;
    }
    res.escaped_power = power - arriving;
}

namespace {

// Receiving form (H_i = sum_j F_ij B_j): the open parts' matrix is not reciprocal in the whole
// areas, so what lands where is read from the rows that gather it.
void open_part_energy_account(const std::vector<Patch>& P, const FormFactorMatrix& F, SolveResult& res,
                              const std::vector<OpenPart>& open) {
    const std::size_t n = P.size();
    std::vector<double> landing(n, 0.0);  // per sender j: sum_i F_ij A_i, the area-weighted part that lands
    for (std::size_t i = 0; i < n; ++i) {
        const float* row = F.row(i);
        Rgb h;
        for (std::size_t j = 0; j < n; ++j) {
            h += res.radiosity[j] * double(row[j]);
            landing[j] += double(row[j]) * P[i].area;
        }
        res.irradiance[i] = h;
    }
    for (std::size_t j = 0; j < n; ++j) {
        res.emitted_power += P[j].emission * P[j].area;
        const Rgb left = res.radiosity[j] * (P[j].area - landing[j]);
        res.absorbed_power += left * open[j].back_share;
        res.back_absorbed_power += left * open[j].back_share;
        res.escaped_power += left * (1.0 - open[j].back_share);
        const Rgb arriving = res.irradiance[j] * P[j].area;
        res.absorbed_power += arriving - P[j].reflectance * arriving;
    }
}

}  // namespace

namespace {

// Whole patches, reciprocal F: row i spreads what leaves i (H_j A_j = sum_i B_i A_i F_ij).
void whole_patch_energy_account(const std::vector<Patch>& P, const FormFactorMatrix& F, SolveResult& res) {
    const std::size_t n = P.size();
    std::vector<double> sums = F.row_sums();
    for (std::size_t i = 0; i < n; ++i) {
        res.emitted_power += P[i].emission * P[i].area;
        // Power leaving i: B_i A_i; the part not landing on any patch escapes.
        res.escaped_power += res.radiosity[i] * (P[i].area * (1.0 - sums[i]));
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const auto& range) {
        for (std::size_t j = range.begin(); j != range.end(); ++j) {
            // H_j A_j = sum_i B_i A_i F_ij (power arriving at j).
            Rgb h;
            for (std::size_t i = 0; i < n; ++i) h += res.radiosity[i] * (P[i].area * double(F(i, j)));
            res.irradiance[j] = h * (1.0 / P[j].area);
        }
    });
    for (std::size_t j = 0; j < n; ++j) {
        const Rgb arriving = res.irradiance[j] * P[j].area;
        res.absorbed_power += arriving - P[j].reflectance * arriving;
    }
}

}  // namespace

void matrix_energy_account(const std::vector<Patch>& P, const FormFactorMatrix& F, SolveResult& res,
                           const std::vector<OpenPart>* open) {
    const std::size_t n = P.size();
    res.irradiance.assign(n, Rgb());
    res.unshot.assign(n, Rgb());
    res.emitted_power = res.absorbed_power = res.escaped_power = res.unshot_power = Rgb();
    res.back_absorbed_power = Rgb();
    if (open)
        open_part_energy_account(P, F, res, *open);
    else
        whole_patch_energy_account(P, F, res);
    // Not yet in balance: B differs from E + rho H by the residual; that difference is
    // the "unshot" power a gathering solver still owes.
    for (std::size_t j = 0; j < n; ++j) {
        const Rgb owed = P[j].emission + P[j].reflectance * res.irradiance[j] - res.radiosity[j];
        res.unshot_power += owed * P[j].area;
    }
    res.unshot_fraction = res.emitted_power.sum() > 0 ? res.unshot_power.sum() / res.emitted_power.sum() : 0.0;
}

}  // namespace bounce
