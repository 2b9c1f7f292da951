// SPDX-License-Identifier: MIT
#include "solver/linear/shooting_solver.h"

#include <algorithm>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>

#include "solver/linear/convergence.h"

namespace bounce {
namespace {

/// The stopping rule: the error the solve would leave, estimated from its own convergence.
/// A checkpoint is kept each time the unshot power halves. Between checkpoints k-2 and k patch
/// j's radiosity grew by dB_j while channel c's unshot power fell from U_c(k-2) to U_c(k).
/// Shooting on at that rate, the unshot power U_c still held adds (a geometric series)
///     dB_jc * U_c / (U_c(k-2) - U_c(k))
/// more to patch j: U_c / (1 - rho_eff) of power still to shoot, where rho_eff is the share of
/// the shot power that came back as unshot, spread as the last stretch spread it. The estimate
/// is the largest over patches of that gain over the patch's radiosity (channel sums); a far
/// corner lit only by inter-reflection, still gaining the most for its brightness, sets it.
class ErrorEstimate {
public:
    /// `area`: per patch; `amplification`: per channel rho / (1 - rho) of the area-weighted
    /// mean reflectance (infinite at 1).
    ErrorEstimate(const std::vector<double>& area, const Rgb& amplification)
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

}  // namespace

ShootingSolver::ShootingSolver(const std::vector<Patch>& patches, const FormFactorEstimator& form_factors,
                               const SolverOptions& options, const FormFactorMatrix* matrix, ElementHierarchy hierarchy)
    : m_patches(patches), m_ff(form_factors), m_options(options), m_matrix(matrix), m_hierarchy(hierarchy) {
    if (bool(hierarchy.shooters) != bool(hierarchy.parents))
        throw std::invalid_argument("element hierarchy: give both shooters and parents");
    if (hierarchy.shooters) {
        if (matrix) throw std::invalid_argument("element hierarchy: a patch-to-patch matrix does not apply");
        if (hierarchy.parents->size() != patches.size())
            throw std::invalid_argument("element hierarchy: one parent per element");
        for (const std::uint32_t p : *hierarchy.parents)
            if (p >= hierarchy.shooters->size()) throw std::invalid_argument("element hierarchy: parent out of range");
    }
}

SolveResult ShootingSolver::solve() {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t n = m_patches.size();
    SolveResult res;
    res.solver = "shooting";
    res.form_factors = m_ff.name();
    res.radiosity.resize(n);
    res.irradiance.assign(n, Rgb());
    res.unshot.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        res.radiosity[i] = m_patches[i].emission;
        res.unshot[i] = m_patches[i].emission;
        res.emitted_power += m_patches[i].emission * m_patches[i].area;
    }
    const double emitted = res.emitted_power.sum();
    if (!(emitted > 0.0)) throw std::invalid_argument("the scene emits no light: no surface has emission > 0");

    // Without a hierarchy every patch shoots for itself (parents: the identity).
    // The per-shot loops read only these two fields; packed, they stay in cache (a Patch is 216
    // bytes, so walking the patches for them cost most of the loop's time).
    std::vector<double> patch_area(n);
    std::vector<Rgb> patch_rho(n);
    for (std::size_t i = 0; i < n; ++i) {
        patch_area[i] = m_patches[i].area;
        patch_rho[i] = m_patches[i].reflectance;
    }

    const std::vector<Patch>& shooters = m_hierarchy.shooters ? *m_hierarchy.shooters : m_patches;
    const std::size_t ns = shooters.size();
    std::vector<std::uint32_t> identity;
    if (!m_hierarchy.parents) {
        identity.resize(n);
        for (std::size_t i = 0; i < n; ++i) identity[i] = std::uint32_t(i);
    }
    const std::vector<std::uint32_t>& parent = m_hierarchy.parents ? *m_hierarchy.parents : identity;
    std::vector<std::size_t> first_child(ns + 1, 0);  // children of s: child[first_child[s] .. first_child[s+1])
    for (const std::uint32_t p : parent) ++first_child[p + 1];
    for (std::size_t s = 0; s < ns; ++s) first_child[s + 1] += first_child[s];
    std::vector<std::uint32_t> child(n);
    {
        std::vector<std::size_t> at(first_child.begin(), first_child.end() - 1);
        for (std::size_t e = 0; e < n; ++e) child[at[parent[e]]++] = std::uint32_t(e);
    }
    std::vector<Rgb> gathered(ns);  // per shooter: sum over its elements of unshot radiosity x area

    // Rows of shooters are kept (float) while the cache budget allows: a bright patch shoots
    // many times and its row does not change.
    const std::size_t row_bytes = n * sizeof(float);
    std::size_t cache_rows = row_bytes ? (m_options.cache_mb << 20) / row_bytes : 0;
    std::vector<std::unique_ptr<float[]>> cache(ns);
    std::vector<float> scratch(n);
    // Entries of a new row that reciprocity gives from cached rows: F_ij = F_ji A_j / A_i.
    std::vector<std::uint8_t> known(n, 0);
    std::vector<std::size_t> cached;
    const bool borrow = m_ff.reciprocal() && !m_hierarchy.shooters;

    // No shot limit unless one is given: the solve stops on the error it leaves, or when the
    // unshot power stops falling (stalled, below).
    const std::size_t max_shots = m_options.max_iterations ? m_options.max_iterations : SIZE_MAX;
    res.status = "max iterations";
    double shot_abs = 0.0;  // power shot, channel sums of absolute values (over-shooting shoots negative too)
    double area = 0.0;
    Rgb rho_area;
    for (std::size_t i = 0; i < n; ++i) {
        rho_area += m_patches[i].reflectance * m_patches[i].area;
        area += m_patches[i].area;
    }
    Rgb amplification;
    for (int c = 0; c < 3; ++c) {
        const double mean_rho = rho_area[c] / area;
        amplification[c] = mean_rho < 1.0 ? mean_rho / (1.0 - mean_rho) : std::numeric_limits<double>::infinity();
    }
    ErrorEstimate estimate(patch_area, amplification);
    // Ambient term: unshot power spread over all area, inter-reflected by the mean
    // reflectance (Cohen et al. 1988, eq. 5-6). For display only; B itself is untouched.
    auto ambient_of = [&](const Rgb& unshot_power) {
        Rgb ambient;
        for (int c = 0; c < 3; ++c) {
            const double mean_rho = rho_area[c] / area;
            ambient[c] = mean_rho < 1.0 ? unshot_power[c] / area / (1.0 - mean_rho) : 0.0;
        }
        return ambient;
    };
    auto with_ambient = [&](std::vector<Rgb>& out) {
        Rgb unshot_power;
        for (std::size_t i = 0; i < n; ++i) unshot_power += res.unshot[i] * m_patches[i].area;
        const Rgb ambient = ambient_of(unshot_power);
        out.resize(n);
        for (std::size_t i = 0; i < n; ++i) out[i] = res.radiosity[i] + m_patches[i].reflectance * ambient;
    };
    std::vector<Rgb> display;
    std::size_t next_log = 0;
    double log_seconds = 0.0;  // time spent logging (residuals are O(N^2)), not counted as solving
    auto seconds = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - log_seconds;
    };
    auto log = [&] {
        const auto log_start = std::chrono::steady_clock::now();
        ConvergenceRecord r;
        r.step = res.steps;
        r.seconds = seconds();
        r.unshot_fraction = res.unshot_fraction;
        if (m_matrix) r.residual = relative_residual(m_patches, *m_matrix, res.radiosity);
        if (m_options.reference) {
            reference_errors(res.radiosity, *m_options.reference, r.rms_error, r.max_error);
            double ignored;
            with_ambient(display);
            reference_errors(display, *m_options.reference, r.ambient_rms_error, ignored);
        }
        res.log.push_back(r);
        // Log densely at first, then every ~5% more shots: the curves are drawn on log axes.
        next_log = std::max(res.steps + 1, std::size_t(double(res.steps) * 1.05));
        log_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - log_start).count();
    };
    // A snapshot is the state after res.steps shots, with its own energy account: the unshot
    // power and fraction of this moment, seconds so far, and B plus the ambient term.
    auto snapshot = [&] {
        SolveResult snap;
        snap.solver = res.solver;
        snap.form_factors = res.form_factors;
        snap.status = "running";
        snap.steps = res.steps;
        snap.seconds = seconds();
        snap.radiosity = res.radiosity;
        snap.irradiance = res.irradiance;
        snap.emitted_power = res.emitted_power;
        snap.absorbed_power = res.absorbed_power;
        snap.escaped_power = res.escaped_power;
        double unshot_total = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const Rgb& u = res.unshot[i];
            snap.unshot_power += u * m_patches[i].area;
            unshot_total += (std::abs(u.r) + std::abs(u.g) + std::abs(u.b)) * m_patches[i].area;
        }
        snap.unshot_fraction = unshot_total / emitted;
        with_ambient(snap.display);
        m_options.snapshot(snap);
    };
    const bool snapshots = m_options.snapshot && m_options.snapshot_every;
    if (snapshots) snapshot();
    while (true) {
        // One scan: the unshot power still held (absolute: over-shooting leaves negative
        // unshot radiosity behind) and the patch holding the most of it.
        double unshot_total = 0.0, best = -1.0;
        std::size_t shooter = 0;
        Rgb unshot_signed, unshot_abs;
        auto consider = [&](std::size_t s) {
            const Rgb& g = gathered[s];
            const double p = std::abs(g.r) + std::abs(g.g) + std::abs(g.b);
            if (p > best) {
                best = p;
                shooter = s;
            }
        };
        if (m_hierarchy.parents) {
            std::fill(gathered.begin(), gathered.end(), Rgb());
            for (std::size_t i = 0; i < n; ++i) {
                const Rgb& u = res.unshot[i];
                unshot_abs += Rgb(std::abs(u.r), std::abs(u.g), std::abs(u.b)) * patch_area[i];
                unshot_signed += u * patch_area[i];
                gathered[parent[i]] += u * patch_area[i];
            }
            for (std::size_t s = 0; s < ns; ++s) consider(s);
        } else {
            // Every patch shoots for itself: the same sums and choice in one pass (about a
            // tenth of a default Cornell solve's CPU was these scans, all of it serial).
            for (std::size_t i = 0; i < n; ++i) {
                const Rgb& u = res.unshot[i];
                unshot_abs += Rgb(std::abs(u.r), std::abs(u.g), std::abs(u.b)) * patch_area[i];
                gathered[i] = u * patch_area[i];
                unshot_signed += gathered[i];
                consider(i);
            }
        }
        unshot_total = unshot_abs.sum();
        res.unshot_fraction = unshot_total / emitted;
        estimate.observe(unshot_abs, shot_abs, res.radiosity);
        res.error_estimate = estimate.error(unshot_abs, m_options.tolerance);
        if (res.steps >= next_log) log();
        if (res.error_estimate < m_options.tolerance) {
            res.converged = true;
            res.status = "converged";
            break;
        }
        if (estimate.stalled(shot_abs)) {
            res.status = "stalled";
            break;
        }
        if (res.steps >= max_shots) break;
        if (m_options.cancel && m_options.cancel->load()) {
            res.status = "interrupted";
            break;
        }
        if (m_options.max_seconds > 0 && seconds() > m_options.max_seconds) {
            res.status = "max seconds";
            break;
        }

        // F_ji for every receiver j: the fraction of j's view filled by the shooter, so that
        // dH_j = F_ji dB_i. With a matrix, its column i (shooting then solves exactly the
        // system the gathering solvers solve); otherwise F_ij A_i / A_j from row i.
        const float* row = nullptr;
        const double ai = shooters[shooter].area;
        if (!m_matrix) {
            if (cache[shooter]) {
                row = cache[shooter].get();
            } else {
                if (borrow) {
                    for (const std::size_t k : cached) {
                        scratch[k] = float(double(cache[k][shooter]) * shooters[k].area / ai);
                        known[k] = 1;
                    }
                    m_ff.compute_row(shooter, scratch, known);
                    for (const std::size_t k : cached) known[k] = 0;
                } else {
                    m_ff.compute_row(shooter, scratch);
                }
                if (cache_rows > 0) {
                    --cache_rows;
                    cached.push_back(shooter);
                    cache[shooter].reset(new float[n]);
                    std::copy(scratch.begin(), scratch.end(), cache[shooter].get());
                    row = cache[shooter].get();
                } else {
                    row = scratch.data();
                }
            }
        }
        const Rgb mean_unshot = gathered[shooter] * (1.0 / ai);
        Rgb shot = mean_unshot;
        if (m_options.overshoot) {
            // Over-shooting (Feda and Purgathofer 1991): also shoot the radiosity the patch will
            // still receive, estimated as rho_i times the ambient term; what was shot in advance
            // stays behind as negative unshot radiosity and is corrected later.
            shot += shooters[shooter].reflectance * ambient_of(unshot_signed);
        }
        // Each element gives up its own unshot radiosity plus what is over-shot: in all,
        // exactly A_i * shot leaves, whatever the spread among the elements.
        for (std::size_t k = first_child[shooter]; k < first_child[shooter + 1]; ++k)
            res.unshot[child[k]] = mean_unshot - shot;
        Rgb arrived;
        for (std::size_t j = 0; j < n; ++j) {
            if (row && row[j] == 0.0f) continue;
            const double fji = row ? double(row[j]) * ai / patch_area[j] : double((*m_matrix)(j, shooter));
            if (fji == 0.0) continue;
            const Rgb dh = shot * fji;                // irradiance increment
            const Rgb arriving = dh * patch_area[j];  // power arriving at j
            const Rgb reflected = patch_rho[j] * dh;  // radiosity increment
            res.irradiance[j] += dh;
            res.radiosity[j] += reflected;
            res.unshot[j] += reflected;
            res.absorbed_power += arriving - patch_rho[j] * arriving;
            arrived += arriving;
        }
        res.escaped_power += shot * ai - arrived;
        res.shot_power += shot * ai;
        shot_abs += (std::abs(shot.r) + std::abs(shot.g) + std::abs(shot.b)) * ai;
        ++res.steps;
        if (snapshots && res.steps % m_options.snapshot_every == 0) snapshot();
        if (m_options.progress) {
            m_options.progress(
                {res.steps, m_options.max_iterations, res.error_estimate, m_options.tolerance, seconds()});
        }
    }
    if (res.log.empty() || res.log.back().step != res.steps) log();
    res.residual = res.log.back().residual;
    for (std::size_t i = 0; i < n; ++i) res.unshot_power += res.unshot[i] * m_patches[i].area;
    if (m_options.ambient) with_ambient(res.display);
    res.seconds = seconds();
    return res;
}

}  // namespace bounce
