// SPDX-License-Identifier: MIT
// The shooting solver's stopping rule (shooting_solver.cpp's own; not a public interface).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "mesh/scene/rgb.h"

namespace bounce {

/// The stopping rule: the error the solve would leave, estimated from its own convergence.
/// A checkpoint is kept each time the unshot power halves. Between checkpoints k-2 and k patch
/// j's radiosity grew by dB_j while channel c's unshot power fell from U_c(k-2) to U_c(k).
/// Shooting on at that rate, the unshot power U_c still held adds (a geometric series)
///     dB_jc * U_c / (U_c(k-2) - U_c(k))
/// more to patch j: U_c / (1 - rho_eff) of power still to shoot, where rho_eff is the share of
/// the shot power that came back as unshot, spread as the last stretch spread it. The estimate
/// is the largest over patches of that gain over the patch's radiosity (channel sums); a far
/// corner lit only by inter-reflection, still gaining the most for its brightness, sets it.
class ShootingErrorEstimate {
public:
    /// `area`: per patch; `amplification`: per channel rho / (1 - rho) of the area-weighted
    /// mean reflectance (infinite at 1).
    ShootingErrorEstimate(const std::vector<double>& area, const Rgb& amplification)
        : m_area(area), m_amplification(amplification), m_weight(area.size()) {}

    /// After every shot: keeps a checkpoint when the unshot power has halved since the last.
    void observe(const Rgb& unshot, double shot, const std::vector<Rgb>& radiosity) {
        if (m_count > 0 && unshot.sum() > 0.5 * m_last_unshot.sum()) return;
        if (m_count >= 2) weigh(m_kept[m_count % 2], radiosity, unshot);
        m_kept[m_count % 2] = {unshot, radiosity};
        m_last_unshot = unshot;
        m_last_shot = shot;
        ++m_count;
    }

    /// The estimated largest relative error of a patch, with `unshot` power left (infinite
    /// until two halvings were seen). Exact near `tolerance`; above 3x it, a bound (a maximum
    /// per channel) that costs no pass over the patches.
    double error(const Rgb& unshot, double tolerance) const {
        if (m_count < 3) return std::numeric_limits<double>::infinity();
        // Never below the scene's mean: the unshot power inter-reflected by the mean
        // reflectance (the ambient term) over the radiosity power. It guards against a stretch
        // whose light went elsewhere than the rest will (all of it out of the scene, say).
        double mean = 0.0;
        for (int c = 0; c < 3; ++c) mean += term(m_amplification[c], unshot[c]);
        mean /= m_power;
        double bound = mean;
        for (int c = 0; c < 3; ++c) bound += term(m_max[c], unshot[c]);
        if (bound < tolerance || bound >= 3 * tolerance) return bound;
        double worst = mean;
        for (const Rgb& w : m_weight)
            worst = std::max(worst, term(w.r, unshot.r) + term(w.g, unshot.g) + term(w.b, unshot.b));
        return std::max(worst, mean);
    }

    /// True when the unshot power has not halved while kStallShots times it was shot: the
    /// light comes back at over 1 - 1 / (2 kStallShots) of itself per bounce (reflectance 1 in
    /// a closed scene), or grows (form-factor rows summing above 1).
    bool stalled(double shot) const { return shot - m_last_shot > kStallShots * m_last_unshot.sum(); }

    static constexpr double kStallShots = 1000.0;

private:
    struct Checkpoint {
        Rgb unshot;
        std::vector<Rgb> radiosity;
    };
    static double term(double weight, double unshot) { return weight > 0 && unshot > 0 ? weight * unshot : 0.0; }
    void weigh(const Checkpoint& old, const std::vector<Rgb>& radiosity, const Rgb& unshot) {
        const double inf = std::numeric_limits<double>::infinity();
        m_max = Rgb();
        m_power = 0.0;
        for (std::size_t j = 0; j < radiosity.size(); ++j) m_power += radiosity[j].sum() * m_area[j];
        for (std::size_t j = 0; j < radiosity.size(); ++j) {
            const double b = radiosity[j].sum();
            Rgb& w = m_weight[j];
            for (int c = 0; c < 3; ++c) {
                const double gain = std::abs(radiosity[j][c] - old.radiosity[j][c]);
                const double drop = old.unshot[c] - unshot[c];
                w[c] = gain == 0.0 ? 0.0 : !(b > 0.0) || !(drop > 0.0) ? inf : gain / drop / b;
                m_max[c] = std::max(m_max[c], w[c]);
            }
        }
    }

    const std::vector<double>& m_area;
    Rgb m_amplification;
    double m_power = 0.0;  // radiosity power at the last checkpoint (channel sums)
    Checkpoint m_kept[2];
    std::size_t m_count = 0;
    Rgb m_last_unshot;
    double m_last_shot = 0.0;
    std::vector<Rgb> m_weight;  // per patch and channel: relative gain per unit of unshot power
    Rgb m_max;
};

}  // namespace bounce
