// SPDX-License-Identifier: MIT
#include "solver/form_factors/raycast_form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "solver/form_factors/exact_form_factor.h"
#include "solver/form_factors/hemicube_form_factor.h"
#include "solver/form_factors/patch_sampling.h"
#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/visibility/shaft_culler.h"
#include "solver/visibility/visibility.h"

namespace bounce {
namespace {

/// A grid of exactly m strata, sx x sy with sx the largest divisor of m not above sqrt(m)
/// (16 -> 4 x 4, 8 -> 2 x 4, 3 -> 1 x 3). Every stratum gets one sample, so the estimate is
/// unbiased; a ceil(sqrt(m))^2 grid with m < side^2 would leave strata unsampled.
std::pair<int, int> strata(int m) {
    int sx = 1;
    for (int d = 1; d * d <= m; ++d)
        if (m % d == 0) sx = d;
    return {sx, m / sx};
}

/// The point-to-point kernel cos(theta_a) cos(theta_b) / r^2 between points pa and pb (the
/// pi is left out: only ratios of it are used).
double pair_kernel(const glm::dvec3& na, const glm::dvec3& pa, const glm::dvec3& nb, const glm::dvec3& pb) {
    const glm::dvec3 d = pb - pa;
    const double r2 = glm::dot(d, d);
    if (!(r2 > 0)) return 0.0;
    return std::max(0.0, glm::dot(na, d)) * std::max(0.0, -glm::dot(nb, d)) / (r2 * r2);
}

/// The visible share of a pair's form factor from its rays: the kernel-weighted share of the
/// rays that arrive, sum w_k open_k / sum w_k. With both ends uniform over their patches the
/// form factor is proportional to the mean kernel, and its visible part to the mean of the
/// kernel times visibility, so their ratio is what multiplies the unoccluded factor; the plain
/// share of open rays weights a ray past a blocker's near side like one at a grazing angle, and
/// is biased where the blocker sits off-centre (-3.4% on the asymmetric blocker of
/// shared/VALIDATION.md with thousands of rays).
double weighted_open_fraction(const Visibility& visibility, std::span<const Visibility::Segment> rays,
                              std::span<const double> weight) {
    if (rays.empty()) return 1.0;
    thread_local std::vector<std::uint8_t> blocked;
    blocked.assign(rays.size(), 0);
    visibility.occluded(rays, blocked);
    double open = 0.0, total = 0.0;
    std::size_t open_count = 0;
    for (std::size_t k = 0; k < rays.size(); ++k) {
        total += weight[k];
        if (!blocked[k]) {
            open += weight[k];
            ++open_count;
        }
    }
    // No kernel to weigh by (every ray grazing): the plain share.
    return total > 0.0 ? open / total : double(open_count) / double(rays.size());
}

/// The exact method's settings for the pairs raycast clips (FormFactorOptions::clip_above).
FormFactorOptions clipper_options(FormFactorOptions o) {
    o.visibility_levels = 2;
    o.flat_shadows = false;
    return o;
}

}  // namespace

RaycastFormFactor::RaycastFormFactor(const std::vector<Patch>& patches, const Visibility* visibility,
                                     const FormFactorOptions& options)
    : m_patches(patches),
      m_visibility(visibility),
      m_options(with_default_rays(options, kPatchPairRays)),
      m_unoccluded(patches, options.unoccluded_tolerance),
      // Mirrors and glass block rays without being patches: no shaft test over the patches.
      m_culler(visibility && !visibility->has_occluders() ? std::make_unique<ShaftCuller>(patches) : nullptr),
      m_clip_count(patches.size()),
      m_clipper(m_culler && options.receiver_samples == 0 && options.clip_above > 0 && options.clip_above <= 1
                    ? std::make_unique<ExactFormFactor>(patches, true, clipper_options(options), visibility)
                    : nullptr) {
    if (m_options.visibility_rays < 1) throw std::invalid_argument("visibility rays must be at least 1");
    // (m_unoccluded has checked the tolerance.)
    if (options.receiver_samples < 0) throw std::invalid_argument("receiver samples must not be negative");
}

RaycastFormFactor::~RaycastFormFactor() = default;

double RaycastFormFactor::visible_fraction(std::size_t i, std::size_t j) const {
    return visible_fraction(i, j, m_options.visibility_rays);
}

double RaycastFormFactor::visible_fraction(std::size_t i, std::size_t j, int ray_count) const {
    if (!m_visibility) return 1.0;
    if (m_options.partial_rays > ray_count) {
        // A pilot of ray_count rays on its own stream says whether the pair is partly
        // blocked; the estimate then comes from fresh rays, partial_rays of them if so. Reusing
        // the pilot's rays would bias the answer towards 0 and 1, since rays that agree decide
        // to stop (two independent rays at visibility v give v^2 (3 - 2v) on average, not v).
        const double pilot = traced_fraction(i, j, ray_count, 0x5EEDF00Dull);
        if (pilot > 0.0 && pilot < 1.0) return traced_fraction(i, j, m_options.partial_rays, 0);
    }
    return traced_fraction(i, j, ray_count, 0);
}

double RaycastFormFactor::traced_fraction(std::size_t i, std::size_t j, int ray_count, std::uint64_t salt) const {
    // Canonical order so (i, j) and (j, i) trace the very same rays.
    const std::size_t lo = std::min(i, j), hi = std::max(i, j);
    // Every plane of the scene beside the pair's shaft: wholly visible, and no ray can be
    // falsely blocked by rounding at a wall the rays start beside. (The full candidate search
    // costs more than the rays it saves in cluttered scenes; the plane test alone is cheap.)
    if (m_culler && m_culler->clear(lo, hi)) return 1.0;
    thread_local std::vector<Visibility::Segment> rays;
    thread_local std::vector<double> weight;
    stratified_rays(lo, hi, ray_count, salt, rays, weight, nullptr);
    return weighted_open_fraction(*m_visibility, rays, weight);
}

void RaycastFormFactor::stratified_rays(std::size_t lo, std::size_t hi, int ray_count, std::uint64_t salt,
                                        std::vector<Visibility::Segment>& rays, std::vector<double>& weight,
                                        std::vector<std::pair<glm::dvec3, glm::dvec3>>* ends) const {
    const Patch& a = m_patches[lo];
    const Patch& b = m_patches[hi];
    const int m = ray_count;
    const auto [sx, sy] = strata(m);
    SplitMix64 rng{(m_options.seed ^ salt) * 0x9E3779B97F4A7C15ull ^ (std::uint64_t(lo) << 32 | std::uint64_t(hi))};
    // Exactly m strata on each patch (sx x sy = m), each ray in its own stratum on a and in a
    // randomly paired one on b (Latin-style), so every ray end is uniform over its patch and
    // the fraction is unbiased for every ray count.
    thread_local std::vector<int> perm;
    perm.resize(std::size_t(m));
    std::iota(perm.begin(), perm.end(), 0);
    for (int k = m - 1; k > 0; --k) std::swap(perm[k], perm[rng.next() % std::uint64_t(k + 1)]);
    const double eps = m_visibility ? m_visibility->offset() : 0.0;
    rays.clear();
    weight.clear();
    if (ends) ends->clear();
    for (int r = 0; r < m; ++r) {
        const int cb = perm[r];
        const glm::dvec3 pa = patch_point(a, (r % sx + rng.uniform()) / sx, (r / sx + rng.uniform()) / sy);
        const glm::dvec3 pb = patch_point(b, (cb % sx + rng.uniform()) / sx, (cb / sx + rng.uniform()) / sy);
        // Rays from points behind the other patch carry no power; leave them out.
        if (a.height(pb) <= eps || b.height(pa) <= eps) continue;
        rays.push_back({pa + eps * a.normal, pb + eps * b.normal});
        weight.push_back(pair_kernel(a.normal, pa, b.normal, pb));
        if (ends) ends->push_back({pa, pb});
    }
}

void RaycastFormFactor::pair_rays(std::size_t i, std::size_t j, int ray_count, std::vector<PairRay>& out) const {
    const std::size_t lo = std::min(i, j), hi = std::max(i, j);
    thread_local std::vector<Visibility::Segment> rays;
    thread_local std::vector<double> weight;
    thread_local std::vector<std::pair<glm::dvec3, glm::dvec3>> ends;
    thread_local std::vector<std::uint8_t> blocked;
    stratified_rays(lo, hi, ray_count, 0, rays, weight, &ends);
    blocked.assign(rays.size(), 0);
    if (m_visibility && !rays.empty()) m_visibility->occluded(rays, blocked);
    out.clear();
    for (std::size_t k = 0; k < rays.size(); ++k) {
        const bool swap = i != lo;
        out.push_back(
            {swap ? ends[k].second : ends[k].first, swap ? ends[k].first : ends[k].second, weight[k], !blocked[k]});
    }
}

double RaycastFormFactor::point_factor(const glm::dvec3& x, const glm::dvec3& n, std::size_t j,
                                       std::uint64_t stream) const {
    const Patch& q = m_patches[j];
    const double eps = m_visibility ? m_visibility->offset() : 0.0;
    // A one-sided emitter sends nothing backwards; a point on q's own plane sees none of it.
    if (q.height(x) <= std::max(eps, 1e-12 * std::sqrt(q.area))) return 0.0;
    const double f = point_polygon_form_factor(x, n, q.polygon());
    if (f <= 0.0 || !m_visibility) return std::max(f, 0.0);
    const int m = m_options.visibility_rays;
    const auto [sx, sy] = strata(m);
    SplitMix64 rng{m_options.seed * 0x9E3779B97F4A7C15ull ^ stream * 0xD1B54A32D192ED03ull ^ std::uint64_t(j)};
    thread_local std::vector<Visibility::Segment> rays;
    thread_local std::vector<double> weight;
    rays.clear();
    weight.clear();
    for (int r = 0; r < m; ++r) {
        const glm::dvec3 pq = patch_point(q, (r % sx + rng.uniform()) / sx, (r / sx + rng.uniform()) / sy);
        if (glm::dot(n, pq - x) <= eps) continue;  // below x's tangent plane: carries nothing
        rays.push_back({x + eps * n, pq + eps * q.normal});
        weight.push_back(pair_kernel(n, x, q.normal, pq));
    }
    return f * weighted_open_fraction(*m_visibility, rays, weight);
}

double RaycastFormFactor::pair(std::size_t i, std::size_t j) const { return pair(i, j, -1.0); }

double RaycastFormFactor::pair(std::size_t i, std::size_t j, double visible) const {
    if (i == j) return 0.0;
    // Receiver points go on the smaller patch (ties: the higher index), whichever way round
    // the pair is asked for, so F_ij and F_ji come from one integral.
    const double ai = m_patches[i].area, aj = m_patches[j].area;
    const bool j_receives = aj < ai || (aj == ai && j > i);
    return j_receives ? directed(i, j, visible) : directed(j, i, visible) * aj / ai;
}

double RaycastFormFactor::directed(std::size_t i, std::size_t j, double visible) const {
    const Patch& s = m_patches[i];
    const Patch& r = m_patches[j];
    if (wholly_behind(s, r) || wholly_behind(r, s)) return 0.0;
    if (m_options.receiver_samples == 0) {
        const double f_rs = m_unoccluded(j, i);
        if (f_rs <= 0.0) return 0.0;
        if (visible < 0 && m_clipper && std::max(i, j) < m_clip_count && f_rs >= m_options.clip_above &&
            !m_culler->clear(std::min(i, j), std::max(i, j)))
            return m_clipper->pair(i, j);
        return f_rs * (visible >= 0 ? visible : visible_fraction(i, j)) * r.area / s.area;
    }
    const int n = m_options.receiver_samples;
    thread_local std::vector<AreaSample> samples;
    double fji = 0.0;
    if (wholly_in_front(s, r)) {
        patch_quadrature(r, n, samples);
        for (const auto& q : samples) fji += q.weight * point_polygon_form_factor(q.point, r.normal, s.polygon());
    } else {
        // Only the part of the receiver in front of the shooter receives. Integrating the
        // cut-off kernel over the whole patch would put a jump inside the quadrature (error
        // O(1/n)); clip the receiver to the shooter's front half-space and integrate the
        // clipped polygon's triangles instead.
        std::array<glm::dvec3, 5> clip;
        int m = 0;
        for (int k = 0; k < r.vertex_count; ++k) {
            const glm::dvec3 &a = r.vertices[k], &b = r.vertices[(k + 1) % r.vertex_count];
            const double ha = s.height(a), hb = s.height(b);
            if (ha > 0) clip[m++] = a;
            if ((ha > 0) != (hb > 0)) clip[m++] = a + (ha / (ha - hb)) * (b - a);
        }
        for (int k = 1; k + 1 < m; ++k) {
            Patch t;
            t.vertex_count = 3;
            t.vertices = {clip[0], clip[k], clip[k + 1], glm::dvec3(0.0)};
            t.centre = (clip[0] + clip[k] + clip[k + 1]) / 3.0;
            const double share = 0.5 * glm::length(glm::cross(clip[k] - clip[0], clip[k + 1] - clip[0])) / r.area;
            patch_quadrature(t, n, samples);
            for (const auto& q : samples)
                fji += share * q.weight * point_polygon_form_factor(q.point, r.normal, s.polygon());
        }
    }
    if (fji <= 0.0) return 0.0;
    return fji * visible_fraction(i, j) * r.area / s.area;
}

void RaycastFormFactor::compute_row(std::size_t i, std::span<float> row) const {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, row.size(), 64), [&](const auto& range) {
        for (std::size_t j = range.begin(); j != range.end(); ++j) row[j] = float(pair(i, j));
    });
}

void RaycastFormFactor::compute_row(std::size_t i, std::span<float> row, std::span<const std::uint8_t> known) const {
    if (known.size() != row.size()) throw std::invalid_argument("compute_row: known and row differ in size");
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, row.size(), 64), [&](const auto& range) {
        for (std::size_t j = range.begin(); j != range.end(); ++j)
            if (!known[j]) row[j] = float(pair(i, j));
    });
}

namespace {
std::vector<Patch> joined(const std::vector<Patch>& a, const std::vector<Patch>& b) {
    std::vector<Patch> all(a);
    all.insert(all.end(), b.begin(), b.end());
    return all;
}
}  // namespace

PatchToElementFormFactor::PatchToElementFormFactor(const std::vector<Patch>& patches,
                                                   const std::vector<Patch>& elements, const Visibility* visibility,
                                                   const FormFactorOptions& options)
    : m_all(joined(patches, elements)),
      m_first_element(patches.size()),
      m_inner(m_all, visibility, with_rays_only(options)) {}

void PatchToElementFormFactor::compute_row(std::size_t i, std::span<float> row) const {
    if (i >= m_first_element || row.size() != m_all.size() - m_first_element)
        throw std::invalid_argument("patch-to-element row: patch index or row length out of range");
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, row.size(), 64), [&](const auto& range) {
        for (std::size_t j = range.begin(); j != range.end(); ++j) row[j] = float(m_inner.pair(i, m_first_element + j));
    });
}

std::vector<std::string> form_factor_methods() { return {"raycast", "exact", "analytic", "hemicube"}; }

std::unique_ptr<FormFactorEstimator> make_form_factor_estimator(const std::string& method,
                                                                const std::vector<Patch>& patches,
                                                                const Visibility* visibility,
                                                                const FormFactorOptions& options) {
    if (method == "raycast") {
        if (!visibility) throw std::invalid_argument("raycast form factors need a visibility backend");
        return std::make_unique<RaycastFormFactor>(patches, visibility, options);
    }
    if (method == "exact") return std::make_unique<ExactFormFactor>(patches, true, options, visibility);
    if (method == "analytic") return std::make_unique<RaycastFormFactor>(patches, nullptr, options);
    if (method == "hemicube") return std::make_unique<HemicubeFormFactor>(patches, options);
    std::string valid;
    for (const auto& m : form_factor_methods()) valid += (valid.empty() ? "" : ", ") + m;
    throw std::invalid_argument("unknown form-factor method '" + method + "' (valid: " + valid + ")");
}

}  // namespace bounce
