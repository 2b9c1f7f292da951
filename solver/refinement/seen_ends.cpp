// SPDX-License-Identifier: MIT
#include "solver/refinement/seen_ends.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/form_factors/raycast_form_factor.h"

namespace bounce::hierarchical {
namespace {

/// The leaf below node i that holds x (a point on i): down through the child that covers it,
/// or, where rounding puts x on no child, the child whose centre is nearest.
std::uint32_t leaf_at(const ElementTree& tree, std::uint32_t i, const glm::dvec3& x) {
    const auto& G = tree.geometry();
    while (!tree.node(i).leaf()) {
        const auto first = std::uint32_t(tree.node(i).first_child);
        std::uint32_t best = first;
        double best_d = 1e300;
        for (std::uint32_t c = first; c < first + 4; ++c) {
            if (covers(G[c], x, 1e-9 * std::sqrt(G[c].area))) {
                best = c;
                break;
            }
            const double d = glm::length(G[c].centre - x);
            if (d < best_d) {
                best_d = d;
                best = c;
            }
        }
        i = best;
    }
    return i;
}

using Entries = std::vector<std::pair<std::uint32_t, double>>;

/// F(dA at x with normal n -> q): the point-to-point kernel beyond kFar of q's circumradii,
/// else Lambert's formula; 0 behind q.
double point_factor(const glm::dvec3& x, const glm::dvec3& n, const Patch& q) {
    static constexpr double kFar = 6.0;
    if (q.height(x) <= 0.0) return 0.0;
    const glm::dvec3 d = q.centre - x;
    const double d2 = glm::dot(d, d), r = circumradius(q);
    if (d2 > kFar * kFar * r * r)
        return q.area * std::max(0.0, glm::dot(n, d)) * std::max(0.0, -glm::dot(q.normal, d)) /
               (std::numbers::pi * d2 * d2);
    return std::max(0.0, point_polygon_form_factor(x, n, q.polygon()));
}

/// The nodes kDepth levels below p (or leaves above that), each weighted by its open area
/// times the factor from its centre to q: how much of what p sends q each sends.
void kernel_entries(const ElementTree& tree, const ElementOpenness* open, std::uint32_t p, const Patch& q,
                    Entries& out) {
    static constexpr int kDepth = 2;
    const auto& G = tree.geometry();
    std::uint32_t stack[3 * kDepth + 1][2];  // (node, depth): at most 3 kDepth + 1 wait
    int top = 0;
    stack[top][0] = p;
    stack[top++][1] = 0;
    while (top > 0) {
        const std::uint32_t i = stack[--top][0], depth = stack[top][1];
        const auto& node = tree.node(i);
        if (!node.leaf() && depth < kDepth) {
            for (int c = 0; c < 4; ++c) {
                stack[top][0] = std::uint32_t(node.first_child + c);
                stack[top++][1] = depth + 1;
            }
            continue;
        }
        const double share = open && i < open->share.size() ? open->share[i] : 1.0;
        const double w = G[i].area * share * point_factor(G[i].centre, G[i].normal, q);
        if (w > 0) out.push_back({i, w});
    }
}

/// Merges an end's entries by leaf and scales their weights to sum to one.
void normalise(Entries& e) {
    std::sort(e.begin(), e.end());
    Entries out;
    double total = 0.0;
    for (const auto& [node, w] : e) {
        total += w;
        if (!out.empty() && out.back().first == node)
            out.back().second += w;
        else
            out.push_back({node, w});
    }
    for (auto& x : out) x.second /= total;
    e = std::move(out);
}

}  // namespace

SeenEnds seen_ends(const ElementTree& tree, const std::vector<HierarchicalLink>& links, const RaycastFormFactor& ff,
                   int rays, const ElementOpenness* open) {
    const std::size_t n = links.size();
    std::vector<Entries> at_a(n), at_b(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& range) {
        std::vector<RaycastFormFactor::PairRay> traced;
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            const HierarchicalLink& l = links[k];
            if (!l.between_elements() || l.fab == 0.0f) continue;
            if (tree.node(l.a).leaf() && tree.node(l.b).leaf()) continue;  // each end is its one leaf
            if (!(l.visible > 0.0f && l.visible < 1.0f)) {
                const auto& G = tree.geometry();
                kernel_entries(tree, open, l.a, G[l.b], at_a[k]);
                kernel_entries(tree, open, l.b, G[l.a], at_b[k]);
                if (at_a[k].empty() || at_b[k].empty()) {
                    at_a[k].clear();
                    at_b[k].clear();
                    continue;
                }
                normalise(at_a[k]);
                normalise(at_b[k]);
                continue;
            }
            ff.pair_rays(l.a, l.b, rays, traced);
            for (const auto& r : traced) {
                if (!r.open || !(r.weight > 0)) continue;
                at_a[k].push_back({leaf_at(tree, l.a, r.on_i), r.weight});
                at_b[k].push_back({leaf_at(tree, l.b, r.on_j), r.weight});
            }
            if (at_a[k].empty()) continue;
            normalise(at_a[k]);
            normalise(at_b[k]);
        }
    });
    SeenEnds out;
    out.first.resize(n + 1, 0);
    out.middle.resize(n, 0);
    for (std::size_t k = 0; k < n; ++k) {
        out.first[k] = std::uint32_t(out.node.size());
        for (const auto& [node, w] : at_a[k]) {
            out.node.push_back(node);
            out.weight.push_back(w);
        }
        out.middle[k] = std::uint32_t(out.node.size());
        for (const auto& [node, w] : at_b[k]) {
            out.node.push_back(node);
            out.weight.push_back(w);
        }
    }
    out.first[n] = std::uint32_t(out.node.size());
    return out;
}

}  // namespace bounce::hierarchical
