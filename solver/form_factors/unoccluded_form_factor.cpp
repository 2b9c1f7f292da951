// SPDX-License-Identifier: MIT
#include "solver/form_factors/unoccluded_form_factor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "solver/form_factors/polygon_form_factor.h"

namespace bounce {

GaussPointCache::GaussPointCache(const std::vector<Patch>& patches, double tolerance) : m_patches(patches) {
    if (!(tolerance > 0)) throw std::invalid_argument("form-factor tolerance must be positive");
    // Order n serves once separation_rho(gap, r)^(2n) >= 1/tol. rho = g + sqrt(g^2 + 1) grows with
    // g = gap / r and inverts to g = (rho - 1/rho) / 2, so the test is gap >= r g_n: no root per pair.
    for (int n = 1; n <= kMaxOrder; ++n) {
        const double rho = std::pow(1.0 / tolerance, 1.0 / (2.0 * n));
        m_gap_needed[std::size_t(n)] = 0.5 * (rho - 1.0 / rho);
    }
    // Gauss points of orders 1..kCachedOrders per patch, end to end: far pairs need only these.
    // In parallel: a hierarchy's gather builds one over every node of its tree.
    m_points.resize(patches.size() * kCachedPoints);
    m_radius.resize(patches.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, patches.size(), 1024), [&](const auto& r) {
        std::vector<AreaSample> q;
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
            m_radius[k] = circumradius(patches[k]);
            auto at = m_points.begin() + std::ptrdiff_t(k * kCachedPoints);
            for (int n = 1; n <= kCachedOrders; ++n) {
                patch_quadrature(patches[k], n, q);
                at = std::copy(q.begin(), q.end(), at);
            }
        }
    });
}

int GaussPointCache::order(double gap, double radius, int max_order) const {
    if (!(gap > 0.0) || !(radius > 0.0)) return 0;  // not separated (separation_rho is 0)
    for (int n = 1; n <= std::min(max_order, kMaxOrder); ++n)
        if (gap >= m_gap_needed[std::size_t(n)] * radius) return n;
    return max_order + 1;
}

std::span<const AreaSample> GaussPointCache::points(std::size_t patch, int n, std::vector<AreaSample>& scratch) const {
    if (n > kCachedOrders || patch >= m_radius.size()) {
        patch_quadrature(m_patches[patch], n, scratch);
        return scratch;
    }
    static constexpr std::array<std::size_t, kCachedOrders + 1> kFirst = {0, 0, 1, 5, 14};  // sum k^2, k < n
    const std::size_t first = patch * kCachedPoints + kFirst[std::size_t(n)];
    return {m_points.data() + first, std::size_t(n * n)};
}

UnoccludedFormFactor::UnoccludedFormFactor(const std::vector<Patch>& patches, double tolerance)
    : m_patches(patches), m_tolerance(tolerance), m_gauss(patches, tolerance) {}

double UnoccludedFormFactor::operator()(std::size_t from, std::size_t to) const {
    const Patch& a = m_patches[from];
    const Patch& b = m_patches[to];
    const double tol = m_tolerance;
    // Only whole pairs in front of each other suit the product rule; one that straddles the
    // other's plane is clipped first (polygon_form_factor does that).
    const double ra = m_gauss.radius(from), rb = m_gauss.radius(to);
    const double gap = glm::length(b.centre - a.centre) - ra - rb;
    const int na = m_gauss.order(gap, ra, kProductOrders), nb = m_gauss.order(gap, rb, kProductOrders);
    // Near pairs (high predicted orders) cost less by the point-to-polygon kernel or, when
    // touching, the contour integral; both are in polygon_form_factor.
    // In front by the bounding spheres first (one dot product: a sphere about q's centre of
    // radius rq holds q), by the vertices only when that is not enough.
    const auto in_front = [](const Patch& p, const Patch& q, double rq) {
        return p.height(q.centre) >= rq || wholly_in_front(p, q);
    };
    if (na == 0 || nb == 0 || na > kProductOrders || nb > kProductOrders || !in_front(a, b, rb) || !in_front(b, a, ra))
        return polygon_form_factor(a.polygon(), a.normal, b.polygon(), b.normal, tol);
    thread_local std::vector<AreaSample> qa, qb;
    return separated_form_factor(m_gauss.points(from, na, qa), a.normal, m_gauss.points(to, nb, qb), b.area, b.normal);
}

}  // namespace bounce
