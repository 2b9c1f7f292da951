// SPDX-License-Identifier: MIT
#include "solver/form_factors/unoccluded_form_factor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "solver/form_factors/polygon_form_factor.h"

namespace bounce {

UnoccludedFormFactor::UnoccludedFormFactor(const std::vector<Patch>& patches, double tolerance)
    : m_patches(patches), m_tolerance(tolerance) {
    if (!(tolerance > 0)) throw std::invalid_argument("form-factor tolerance must be positive");
    // Gauss points of orders 1..kCachedOrders per patch, end to end: far pairs need only these.
    m_points.reserve(patches.size() * kCachedPoints);
    m_radius.reserve(patches.size());
    for (int n = 1; n <= kCachedOrders; ++n) m_rho_needed[std::size_t(n)] = std::pow(1.0 / tolerance, 1.0 / (2.0 * n));
    thread_local std::vector<AreaSample> q;
    for (const Patch& p : patches)
        for (int n = 1; n <= kCachedOrders; ++n) {
            patch_quadrature(p, n, q);
            m_points.insert(m_points.end(), q.begin(), q.end());
        }
    for (const Patch& p : patches) m_radius.push_back(circumradius(p));
}

int UnoccludedFormFactor::cached_order(double gap, double radius) const {
    const double rho = separation_rho(gap, radius);
    if (rho == 0.0) return 0;
    for (int n = 1; n <= kCachedOrders; ++n)
        if (rho >= m_rho_needed[std::size_t(n)]) return n;
    return kCachedOrders + 1;
}

std::span<const AreaSample> UnoccludedFormFactor::gauss_points(std::size_t patch, int n,
                                                               std::vector<AreaSample>& scratch) const {
    // Patches added after construction (refinement appends elements) are not cached.
    if (patch >= m_points.size() / kCachedPoints) {
        patch_quadrature(m_patches[patch], n, scratch);
        return scratch;
    }
    const std::size_t first = patch * kCachedPoints + std::size_t((n - 1) * n * (2 * n - 1) / 6);  // sum k^2, k < n
    return {m_points.data() + first, std::size_t(n * n)};
}

double UnoccludedFormFactor::operator()(std::size_t from, std::size_t to) const {
    const Patch& a = m_patches[from];
    const Patch& b = m_patches[to];
    const double tol = m_tolerance;
    // Only whole pairs in front of each other suit the product rule; one that straddles the
    // other's plane is clipped first (polygon_form_factor does that).
    const bool cached = std::max(from, to) < m_radius.size();
    const double ra = cached ? m_radius[from] : circumradius(a), rb = cached ? m_radius[to] : circumradius(b);
    const double gap = glm::length(b.centre - a.centre) - ra - rb;
    const int na = cached_order(gap, ra), nb = cached_order(gap, rb);
    // Near pairs (high predicted orders) cost less by the point-to-polygon kernel or, when
    // touching, the contour integral; both are in polygon_form_factor.
    if (na == 0 || nb == 0 || na > kCachedOrders || nb > kCachedOrders || !wholly_in_front(a, b) ||
        !wholly_in_front(b, a))
        return polygon_form_factor(a.polygon(), a.normal, b.polygon(), b.normal, tol);
    thread_local std::vector<AreaSample> qa, qb;
    return separated_form_factor(gauss_points(from, na, qa), a.normal, gauss_points(to, nb, qb), b.area, b.normal);
}

}  // namespace bounce
