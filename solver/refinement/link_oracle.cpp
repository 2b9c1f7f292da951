// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/refinement/cluster_links.h"
#include "solver/refinement/link_refiner.h"

namespace bounce::hierarchical {
namespace {

/// The point of polygon a nearest to x (a convex, planar): x projected onto a's plane, or,
/// when that falls outside, the nearest point of its edges.
glm::dvec3 nearest_point(const Patch& a, const glm::dvec3& x) {
    const glm::dvec3 p = x - a.height(x) * a.normal;
    if (covers(a, p)) return p;
    glm::dvec3 best = a.vertices[0];
    double best_d = 1e300;
    for (int k = 0; k < a.vertex_count; ++k) {
        const glm::dvec3 u = a.vertices[k], v = a.vertices[(k + 1) % a.vertex_count];
        const double t = std::clamp(glm::dot(p - u, v - u) / glm::dot(v - u, v - u), 0.0, 1.0);
        const glm::dvec3 q = u + t * (v - u);
        if (glm::length(q - p) < best_d) {
            best_d = glm::length(q - p);
            best = q;
        }
    }
    return best;
}

/// How much F(dA_x -> b) varies over a (max - min), sampled at a's centre, its corners and the
/// point of a nearest to b, where the kernel peaks when b is small and close. A link hands
/// every point of a the mean, so the spread bounds the error it makes, per unit B_b, at the
/// leaves below a. Samples are taken a hair (1e-4 of the way) towards a's centre: a corner or
/// edge shared with b would make the kernel singular.
struct Spread {
    double mean = 0.0, spread = 0.0;
};

Spread point_factor_spread(const Patch& a, const Patch& b) {
    // Far from b (beyond kFar circumradii), the point-to-point kernel at b's centre: within
    // about (r_b / d)^2 < 3% of Lambert's formula, far below the link epsilons' tens of
    // percent, and no arc tangents (Lambert's formula made the oracle most of a solve).
    static constexpr double kFar = 6.0;
    const double rb = circumradius(b), far2 = kFar * kFar * rb * rb;
    auto at = [&](const glm::dvec3& y) {
        const glm::dvec3 x = y + 1e-4 * (a.centre - y);
        if (b.height(x) <= 0.0) return 0.0;  // behind b: b sends it nothing
        const glm::dvec3 d = b.centre - x;
        const double d2 = glm::dot(d, d);
        if (d2 > far2)
            return b.area * std::max(0.0, glm::dot(a.normal, d)) * std::max(0.0, -glm::dot(b.normal, d)) /
                   (std::numbers::pi * d2 * d2);
        return point_polygon_form_factor(x, a.normal, b.polygon());
    };
    double lo = at(a.centre), hi = lo, sum = lo;
    for (int k = 0; k <= a.vertex_count; ++k) {
        const double f = at(k < a.vertex_count ? a.vertices[k] : nearest_point(a, b.centre));
        lo = std::min(lo, f);
        hi = std::max(hi, f);
        sum += f;
    }
    return {sum / (a.vertex_count + 2), hi - lo};
}

}  // namespace

Refiner::Step Refiner::decide(const Pair& p, float& visible, std::uint8_t& shaft) const {
    const std::uint32_t a = p.a, b = p.b;
    const bool ca = ClusterTree::is_cluster(a), cb = ClusterTree::is_cluster(b);
    if (!ca && !cb) return decide_elements(p, visible, shaft);
    if (a == b) return Step::split_self;
    const End ea = end_of(m_tree, *m_clusters, a), eb = end_of(m_tree, *m_clusters, b);
    if ((ea.element && eb.behind(*ea.element)) || (eb.element && ea.behind(*eb.element))) return Step::drop;
    const double gap = glm::length(eb.centre - ea.centre) - ea.radius - eb.radius;
    const double la = luminance(a), lb = luminance(b);
    if (gap > 0) {
        const double k = cluster_transfer(ea, eb);  // A_a F_ab
        const double floor = m_options.cluster_floor * m_scale;
        const double eps = m_options.link_epsilon;
        const double bound_a = std::min(1.0, eb.area / (std::numbers::pi * gap * gap)) * lb;
        const double bound_b = std::min(1.0, ea.area / (std::numbers::pi * gap * gap)) * la;
        const bool relative =
            bound_a <= eps * (k / ea.area * lb + floor) && bound_b <= eps * (k / eb.area * la + floor);
        if (relative || (m_power_budget > 0 && std::min(bound_a * ea.area, lb * eb.area) <= m_power_budget &&
                         std::min(bound_b * eb.area, la * ea.area) <= m_power_budget))
            return Step::link;
    } else if (m_power_budget > 0 && std::min(ea.area, eb.area) * std::max(la, lb) <= m_power_budget) {
        // Touching or overlapping ends: no point-to-point bound, but neither can send the
        // other more than B min(A_a, A_b) (F <= 1 both ways), and that is faint.
        return Step::link;
    }
    // Split the larger of two clusters; an element meeting a cluster waits while the
    // cluster is split, so two patches always meet as a pair and the element oracle alone
    // decides how they are cut (as without clustering).
    return ca && (!cb || ea.area >= eb.area) ? Step::split_a : Step::split_b;
}

Refiner::Step Refiner::decide_elements(const Pair& p, float& visible, std::uint8_t& shaft) const {
    const std::uint32_t a = p.a, b = p.b;
    const auto& G = m_tree.geometry();
    if (wholly_behind(G[a], G[b]) || wholly_behind(G[b], G[a])) return Step::drop;
    // A pair that is split or linked asks the shaft test once (unless an ancestor pair
    // passed it): passed, its children and its link need no rays for their visibility.
    const auto open = [&] {
        if (p.open)
            shaft = HierarchicalLink::kShaftOpen;
        else if (m_culler && shaft == HierarchicalLink::kShaftUntested)
            shaft = m_culler->unblocked(G[a], G[b]) ? HierarchicalLink::kShaftOpen : HierarchicalLink::kShaftCrossed;
        return shaft == HierarchicalLink::kShaftOpen;
    };
    const bool split_a = splittable(a), split_b = splittable(b);
    if (!split_a && !split_b) {  // linked whatever its error: no need to bound it
        if (open()) visible = 1.0f;
        return Step::link;
    }
    const Step split = split_a && (!split_b || G[a].area >= G[b].area) ? Step::split_a : Step::split_b;
    // A link also hands a the mean radiosity of b, where the last solution varied by
    // b_range over b's leaves: up to F(a -> b) b_range more error.
    const Spread ab = point_factor_spread(G[a], G[b]);
    const double lb = m_b[b].luminance(), la = m_b[a].luminance();
    const double err_a = ab.spread * lb + ab.mean * range(b);
    if (!accepted_at(err_a, ab.mean * lb, a)) {  // refused at a whatever b's bound (accepted())
        open();
        return split;
    }
    const Spread ba = point_factor_spread(G[b], G[a]);
    const double err_b = ba.spread * la + ba.mean * range(a);
    if (!accepted(err_a, err_b, ab.mean * lb, ba.mean * la, a, b)) {
        open();
        return split;
    }
    if (open()) {  // every ray would arrive: nothing to refine, no rays
        visible = 1.0f;
        return Step::link;
    }
    // A shadow's edge across the pair: some points of a see b, others do not, and the
    // link's one visible fraction misplaces up to all it brings, F B, at each of them
    // (Hanrahan et al. 1991, section 4: partly visible interactions are refined). Only
    // mixed rays tell; a pair whose rays all arrive or all stop keeps its bound.
    // A pair linked in the last round was judged on the same rays: its share is kept.
    if (m_ff) {
        float seen = -1.0f;
        const double v = seen_visible(a, b, seen) ? double(seen) : m_ff->visible_fraction(a, b, kPartialVisibilityRays);
        if (v > 0 && v < 1 &&
            !partly_visible_accepted(err_a + ab.mean * lb, err_b + ba.mean * la, ab.mean * lb, ba.mean * la, a, b))
            return split;
        visible = float(v);
    }
    return Step::link;
}

}  // namespace bounce::hierarchical
