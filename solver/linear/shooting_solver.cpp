// SPDX-License-Identifier: MIT
#include "solver/linear/shooting_solver.h"

#include <algorithm>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "solver/linear/convergence.h"
#include "solver/linear/shooting_error_estimate.h"

namespace bounce {
namespace {

/// One run of progressive refinement: what ShootingSolver::solve() carries from shot to shot.
class ShootingRun {
public:
    ShootingRun(const std::vector<Patch>& patches, const FormFactorEstimator& ff, const SolverOptions& options,
                const FormFactorMatrix* matrix, const ElementHierarchy& hierarchy);
    SolveResult run();

private:
    /// The unshot power still held and the shooter: the patch (or shooter of elements) holding
    /// the most of it. Fills m_gathered per shooter.
    std::size_t scan(Rgb& unshot_abs, Rgb& unshot_signed);
    /// After a scan: whether to stop (the error estimate, a stall, the limits, a signal), with
    /// res.status set.
    bool stop();
    /// The shooter's form-factor row F_ij over the receivers j (null with a matrix).
    const float* row_of(std::size_t shooter);
    /// Shoots the shooter's unshot radiosity (and, over-shooting, more) to every receiver.
    void shoot(std::size_t shooter, const float* row, const Rgb& unshot_signed);
    /// Sends `shot` from the shooter to every receiver; returns the power that landed.
    Rgb deliver(std::size_t shooter, const float* row, const Rgb& shot, double ai);
    /// The same between open parts (SolverOptions::open_parts).
    Rgb deliver_open(std::size_t shooter, const float* row, const Rgb& shot);
    /// Receiver j takes irradiance dh (power `arriving`), reflects rho_j dh as unshot radiosity.
    void receive(std::size_t j, const Rgb& dh, const Rgb& arriving, Rgb& arrived);

    Rgb ambient_of(const Rgb& unshot_power) const;
    void with_ambient(std::vector<Rgb>& out) const;
    double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count() - m_log_seconds;
    }
    void log();
    void snapshot();

    const std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now();
    const std::vector<Patch>& m_patches;
    const FormFactorEstimator& m_ff;
    const SolverOptions& m_options;
    const FormFactorMatrix* m_matrix;
    const ElementHierarchy& m_hierarchy;
    const std::size_t m_n;  // patches (elements with a hierarchy)
    SolveResult m_res;
    double m_emitted = 0.0;  // channel sums
    // The per-shot loops read only these two fields; packed, they stay in cache.
    std::vector<double> m_patch_area;
    std::vector<Rgb> m_patch_rho;
    // With open parts: areas above are the open parts' (a_i A_i); rows are the whole patches'.
    const std::vector<OpenPart>* m_open = nullptr;
    // Shooters and their elements: without a hierarchy every patch shoots for itself
    // (parents: the identity).
    std::vector<std::uint32_t> m_identity;
    const std::vector<Patch>* m_shooters = nullptr;
    const std::vector<std::uint32_t>* m_parent = nullptr;
    std::size_t m_ns = 0;
    std::vector<std::size_t> m_first_child;  // children of s: m_child[m_first_child[s] .. m_first_child[s+1])
    std::vector<std::uint32_t> m_child;
    std::vector<Rgb> m_gathered;  // per shooter: sum over its elements of unshot radiosity x area
    // Rows of shooters are kept (float) while the cache budget allows: a bright patch shoots
    // many times and its row does not change.
    std::size_t m_cache_rows = 0;
    std::vector<std::unique_ptr<float[]>> m_cache;
    std::vector<float> m_scratch;
    // Entries of a new row that reciprocity gives from cached rows: F_ij = F_ji A_j / A_i.
    std::vector<std::uint8_t> m_known;
    std::vector<std::size_t> m_cached;
    bool m_borrow = false;
    std::size_t m_max_shots = 0;
    double m_shot_abs = 0.0;  // power shot, channel sums of absolute values (over-shooting shoots negative too)
    double m_area = 0.0;
    Rgb m_rho_area;
    std::optional<ShootingErrorEstimate> m_estimate;
    std::vector<Rgb> m_display;
    std::size_t m_next_log = 0;
    double m_log_seconds = 0.0;  // time spent logging (residuals are O(N^2)), not counted as solving
};

ShootingRun::ShootingRun(const std::vector<Patch>& patches, const FormFactorEstimator& ff, const SolverOptions& options,
                         const FormFactorMatrix* matrix, const ElementHierarchy& hierarchy)
    : m_patches(patches), m_ff(ff), m_options(options), m_matrix(matrix), m_hierarchy(hierarchy), m_n(patches.size()) {
    m_res.solver = "shooting";
    m_res.form_factors = m_ff.name();
    m_res.radiosity.resize(m_n);
    m_res.irradiance.assign(m_n, Rgb());
    m_res.unshot.resize(m_n);
    if (m_options.open_parts && !m_hierarchy.shooters) {
        if (m_options.open_parts->size() != m_n) throw std::invalid_argument("open parts: one per patch");
        m_open = m_options.open_parts;
    }
    m_patch_area.resize(m_n);
    m_patch_rho.resize(m_n);
    for (std::size_t i = 0; i < m_n; ++i) {
        m_patch_area[i] = m_patches[i].area * (m_open ? (*m_open)[i].receiving_share() : 1.0);
        m_patch_rho[i] = m_patches[i].reflectance;
    }
    for (std::size_t i = 0; i < m_n; ++i) {
        m_res.radiosity[i] = m_patches[i].emission;
        m_res.unshot[i] = m_patches[i].emission;
        m_res.emitted_power += m_patches[i].emission * m_patch_area[i];
    }
    m_emitted = m_res.emitted_power.sum();
    if (!(m_emitted > 0.0)) throw std::invalid_argument("the scene emits no light: no surface has emission > 0");
    m_shooters = m_hierarchy.shooters ? m_hierarchy.shooters : &m_patches;
    m_ns = m_shooters->size();
    if (!m_hierarchy.parents) {
        m_identity.resize(m_n);
        for (std::size_t i = 0; i < m_n; ++i) m_identity[i] = std::uint32_t(i);
    }
    m_parent = m_hierarchy.parents ? m_hierarchy.parents : &m_identity;
    m_first_child.assign(m_ns + 1, 0);
    for (const std::uint32_t p : *m_parent) ++m_first_child[p + 1];
    for (std::size_t s = 0; s < m_ns; ++s) m_first_child[s + 1] += m_first_child[s];
    m_child.resize(m_n);
    {
        std::vector<std::size_t> at(m_first_child.begin(), m_first_child.end() - 1);
        for (std::size_t e = 0; e < m_n; ++e) m_child[at[(*m_parent)[e]]++] = std::uint32_t(e);
    }
    m_gathered.resize(m_ns);
    const std::size_t row_bytes = m_n * sizeof(float);
    m_cache_rows = row_bytes ? (m_options.cache_mb << 20) / row_bytes : 0;
    m_cache.resize(m_ns);
    m_scratch.resize(m_n);
    m_known.assign(m_n, 0);
    m_borrow = m_ff.reciprocal() && !m_hierarchy.shooters;
    // No shot limit unless one is given: the solve stops on the error it leaves, or when the
    // unshot power stops falling (stalled, below).
    m_max_shots = m_options.max_iterations ? m_options.max_iterations : SIZE_MAX;
    m_res.status = SolveStatus::max_iterations;
    for (std::size_t i = 0; i < m_n; ++i) {
        m_rho_area += m_patches[i].reflectance * m_patch_area[i];
        m_area += m_patch_area[i];
    }
    Rgb amplification;
    for (int c = 0; c < 3; ++c) {
        const double mean_rho = m_rho_area[c] / m_area;
        amplification[c] = mean_rho < 1.0 ? mean_rho / (1.0 - mean_rho) : std::numeric_limits<double>::infinity();
    }
    m_estimate.emplace(m_patch_area, amplification);
}

// Ambient term: unshot power spread over all area, inter-reflected by the mean reflectance
// (Cohen et al. 1988, eq. 5-6). For display only; B itself is untouched.
Rgb ShootingRun::ambient_of(const Rgb& unshot_power) const {
    Rgb ambient;
    for (int c = 0; c < 3; ++c) {
        const double mean_rho = m_rho_area[c] / m_area;
        ambient[c] = mean_rho < 1.0 ? unshot_power[c] / m_area / (1.0 - mean_rho) : 0.0;
    }
    return ambient;
}

void ShootingRun::with_ambient(std::vector<Rgb>& out) const {
    Rgb unshot_power;
    for (std::size_t i = 0; i < m_n; ++i) unshot_power += m_res.unshot[i] * m_patch_area[i];
    const Rgb ambient = ambient_of(unshot_power);
    out.resize(m_n);
    for (std::size_t i = 0; i < m_n; ++i) out[i] = m_res.radiosity[i] + m_patches[i].reflectance * ambient;
}

void ShootingRun::log() {
    const auto log_start = std::chrono::steady_clock::now();
    ConvergenceRecord r;
    r.step = m_res.steps;
    r.seconds = seconds();
    r.unshot_fraction = m_res.unshot_fraction;
    if (m_matrix) r.residual = relative_residual(m_patches, *m_matrix, m_res.radiosity);
    if (m_options.reference) {
        reference_errors(m_res.radiosity, *m_options.reference, r.rms_error, r.max_error);
        double ignored;
        with_ambient(m_display);
        reference_errors(m_display, *m_options.reference, r.ambient_rms_error, ignored);
    }
    m_res.log.push_back(r);
    // Log densely at first, then every ~5% more shots: the curves are drawn on log axes.
    m_next_log = std::max(m_res.steps + 1, std::size_t(double(m_res.steps) * 1.05));
    m_log_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - log_start).count();
}

// A snapshot is the state after res.steps shots, with its own energy account: the unshot power
// and fraction of this moment, seconds so far, and B plus the ambient term.
void ShootingRun::snapshot() {
    SolveResult snap;
    snap.solver = m_res.solver;
    snap.form_factors = m_res.form_factors;
    snap.status = SolveStatus::running;
    snap.steps = m_res.steps;
    snap.seconds = seconds();
    snap.radiosity = m_res.radiosity;
    snap.irradiance = m_res.irradiance;
    snap.emitted_power = m_res.emitted_power;
    snap.absorbed_power = m_res.absorbed_power;
    snap.escaped_power = m_res.escaped_power;
    snap.back_absorbed_power = m_res.back_absorbed_power;
    double unshot_total = 0.0;
    for (std::size_t i = 0; i < m_n; ++i) {
        const Rgb& u = m_res.unshot[i];
        snap.unshot_power += u * m_patch_area[i];
        unshot_total += (std::abs(u.r) + std::abs(u.g) + std::abs(u.b)) * m_patch_area[i];
    }
    snap.unshot_fraction = unshot_total / m_emitted;
    with_ambient(snap.display);
    m_options.snapshot(snap);
}

// One scan: the unshot power still held (absolute: over-shooting leaves negative unshot
// radiosity behind) and the patch holding the most of it.
std::size_t ShootingRun::scan(Rgb& unshot_abs, Rgb& unshot_signed) {
    double best = -1.0;
    std::size_t shooter = 0;
    auto consider = [&](std::size_t s) {
        const Rgb& g = m_gathered[s];
        const double p = std::abs(g.r) + std::abs(g.g) + std::abs(g.b);
        if (p > best) {
            best = p;
            shooter = s;
        }
    };
    if (m_hierarchy.parents) {
        std::fill(m_gathered.begin(), m_gathered.end(), Rgb());
        for (std::size_t i = 0; i < m_n; ++i) {
            const Rgb& u = m_res.unshot[i];
            unshot_abs += Rgb(std::abs(u.r), std::abs(u.g), std::abs(u.b)) * m_patch_area[i];
            unshot_signed += u * m_patch_area[i];
            m_gathered[(*m_parent)[i]] += u * m_patch_area[i];
        }
        for (std::size_t s = 0; s < m_ns; ++s) consider(s);
    } else {
        // Every patch shoots for itself: the same sums and choice in one serial pass.
        for (std::size_t i = 0; i < m_n; ++i) {
            const Rgb& u = m_res.unshot[i];
            unshot_abs += Rgb(std::abs(u.r), std::abs(u.g), std::abs(u.b)) * m_patch_area[i];
            m_gathered[i] = u * m_patch_area[i];
            unshot_signed += m_gathered[i];
            consider(i);
        }
    }
    return shooter;
}

bool ShootingRun::stop() {
    if (m_res.error_estimate < m_options.tolerance) {
        m_res.converged = true;
        m_res.status = SolveStatus::converged;
        return true;
    }
    if (m_estimate->stalled(m_shot_abs)) {
        m_res.status = SolveStatus::stalled;
        return true;
    }
    if (m_res.steps >= m_max_shots) return true;
    if (m_options.cancel && m_options.cancel->load()) {
        m_res.status = SolveStatus::interrupted;
        return true;
    }
    if (m_options.max_seconds > 0 && seconds() > m_options.max_seconds) {
        m_res.status = SolveStatus::max_seconds;
        return true;
    }
    return false;
}

const float* ShootingRun::row_of(std::size_t shooter) {
    if (m_matrix) return nullptr;
    if (m_cache[shooter]) return m_cache[shooter].get();
    const double ai = (*m_shooters)[shooter].area;
    if (m_borrow) {
        for (const std::size_t k : m_cached) {
            m_scratch[k] = float(double(m_cache[k][shooter]) * (*m_shooters)[k].area / ai);
            m_known[k] = 1;
        }
        m_ff.compute_row(shooter, m_scratch, m_known);
        for (const std::size_t k : m_cached) m_known[k] = 0;
    } else {
        m_ff.compute_row(shooter, m_scratch);
    }
    if (m_cache_rows == 0) return m_scratch.data();
    --m_cache_rows;
    m_cached.push_back(shooter);
    m_cache[shooter].reset(new float[m_n]);
    std::copy(m_scratch.begin(), m_scratch.end(), m_cache[shooter].get());
    return m_cache[shooter].get();
}

// F_ji for every receiver j: the fraction of j's view filled by the shooter, so that
// dH_j = F_ji dB_i. With a matrix, its column i (shooting then solves exactly the system the
// gathering solvers solve); otherwise F_ij A_i / A_j from row i.
void ShootingRun::shoot(std::size_t shooter, const float* row, const Rgb& unshot_signed) {
    const double ai = m_open ? m_patch_area[shooter] : (*m_shooters)[shooter].area;
    const Rgb mean_unshot = ai > 0.0 ? m_gathered[shooter] * (1.0 / ai) : Rgb();
    Rgb shot = mean_unshot;
    if (m_options.overshoot) {
        // Over-shooting (Feda and Purgathofer 1991): also shoot the radiosity the patch will
        // still receive, estimated as rho_i times the ambient term; what was shot in advance
        // stays behind as negative unshot radiosity and is corrected later.
        shot += (*m_shooters)[shooter].reflectance * ambient_of(unshot_signed);
    }
    // Each element gives up its own unshot radiosity plus what is over-shot: in all,
    // exactly A_i * shot leaves, whatever the spread among the elements.
    for (std::size_t k = m_first_child[shooter]; k < m_first_child[shooter + 1]; ++k)
        m_res.unshot[m_child[k]] = mean_unshot - shot;
    const Rgb arrived = m_open ? deliver_open(shooter, row, shot) : deliver(shooter, row, shot, ai);
    const Rgb left = shot * ai - arrived;  // lands on no patch's front
    if (m_open) {
        // To black back sides (absorbed) and out through openings (escaped) in the shares the
        // open part's rays saw.
        const double back = (*m_open)[shooter].back_share;
        m_res.absorbed_power += left * back;
        m_res.back_absorbed_power += left * back;
        m_res.escaped_power += left * (1.0 - back);
    } else {
        m_res.escaped_power += left;
    }
    m_res.shot_power += shot * ai;
    m_shot_abs += (std::abs(shot.r) + std::abs(shot.g) + std::abs(shot.b)) * ai;
}

void ShootingRun::receive(std::size_t j, const Rgb& dh, const Rgb& arriving, Rgb& arrived) {
    const Rgb reflected = m_patch_rho[j] * dh;  // radiosity increment
    m_res.irradiance[j] += dh;
    m_res.radiosity[j] += reflected;
    m_res.unshot[j] += reflected;
    m_res.absorbed_power += arriving - m_patch_rho[j] * arriving;
    arrived += arriving;
}

Rgb ShootingRun::deliver(std::size_t shooter, const float* row, const Rgb& shot, double ai) {
    Rgb arrived;
    for (std::size_t j = 0; j < m_n; ++j) {
        if (row && row[j] == 0.0f) continue;
        const double fji = row ? double(row[j]) * ai / m_patch_area[j] : double((*m_matrix)(j, shooter));
        if (fji == 0.0) continue;
        const Rgb dh = shot * fji;                      // irradiance increment
        receive(j, dh, dh * m_patch_area[j], arrived);  // power arriving at j: dh A_j
    }
    return arrived;
}

// Shooting from and to open parts (open_parts.h): patch i's open part, area a_i A_i, sends
// A'_i dB_i along the row F'_ij = k_i F_ij, where F_ij is the whole patches' row (what its
// open points' rays reach) and k_i its scale (OpenPart::shot_scale over a_i); j's open part
// receives it over a_j A_j.
Rgb ShootingRun::deliver_open(std::size_t i, const float* row, const Rgb& shot) {
    double power_scale = 1.0;  // k_i a_i A_i
    if (row) {
        double row_sum = 0.0;
        for (std::size_t j = 0; j < m_n; ++j) row_sum += double(row[j]);
        power_scale = (*m_open)[i].shot_scale(row_sum) * m_patches[i].area;
    }
    Rgb arrived;
    for (std::size_t j = 0; j < m_n; ++j) {
        // Power arriving at j per unit shot radiosity: F_ij A_i k_i a_i from the row, or the
        // open parts' matrix (open_part_matrix) times j's open area.
        const double landing = row ? double(row[j]) * power_scale : double((*m_matrix)(j, i)) * m_patch_area[j];
        if (landing == 0.0) continue;
        const Rgb arriving = shot * landing;
        receive(j, arriving * (1.0 / m_patch_area[j]), arriving, arrived);
    }
    return arrived;
}

SolveResult ShootingRun::run() {
    const bool snapshots = m_options.snapshot && m_options.snapshot_every;
    if (snapshots) snapshot();
    while (true) {
        Rgb unshot_signed, unshot_abs;
        const std::size_t shooter = scan(unshot_abs, unshot_signed);
        m_res.unshot_fraction = unshot_abs.sum() / m_emitted;
        m_estimate->observe(unshot_abs, m_shot_abs, m_res.radiosity);
        m_res.error_estimate = m_estimate->error(unshot_abs, m_options.tolerance);
        if (m_res.steps >= m_next_log) log();
        if (stop()) break;
        shoot(shooter, row_of(shooter), unshot_signed);
        ++m_res.steps;
        if (snapshots && m_res.steps % m_options.snapshot_every == 0) snapshot();
        if (m_options.progress) {
            m_options.progress(
                {m_res.steps, m_options.max_iterations, m_res.error_estimate, m_options.tolerance, seconds()});
        }
    }
    if (m_res.log.empty() || m_res.log.back().step != m_res.steps) log();
    m_res.residual = m_res.log.back().residual;
    for (std::size_t i = 0; i < m_n; ++i) m_res.unshot_power += m_res.unshot[i] * m_patch_area[i];
    if (m_options.ambient) with_ambient(m_res.display);
    m_res.seconds = seconds();
    return std::move(m_res);
}

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

SolveResult ShootingSolver::solve() { return ShootingRun(m_patches, m_ff, m_options, m_matrix, m_hierarchy).run(); }

}  // namespace bounce
