// SPDX-License-Identifier: MIT
#include "solver/refinement/seen_ends.h"

#include <algorithm>
#include <array>
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

/// One end's list as it is built: at most 16 nodes (kDepth 2, or a partly visible link's rays).
struct EndList {
    static constexpr int kMax = 16;
    std::array<std::pair<std::uint32_t, double>, kMax> entry;
    int count = 0;
    void add(std::uint32_t node, double w) {
        for (int k = 0; k < count; ++k)
            if (entry[std::size_t(k)].first == node) {
                entry[std::size_t(k)].second += w;
                return;
            }
        if (count < kMax) entry[std::size_t(count++)] = {node, w};
    }
};

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

/// The nodes two levels below p (or leaves above that), each weighted by its open area times
/// the factor from its centre to q: how much of what p sends q each sends. Empty where those
/// weights are within kFlat (summed over the nodes) of the nodes' shares of p's open area, the
/// weights p's mean already gives them: the list would change nothing worth its memory (a
/// link whose ends are small against their distance).
void kernel_entries(const ElementTree& tree, const ElementOpenness* open, std::uint32_t p, const Patch& q,
                    EndList& out) {
    static constexpr int kDepth = 2;
    static constexpr double kFlat = 0.02;
    const auto& G = tree.geometry();
    std::uint32_t stack[3 * kDepth + 1][2];  // (node, depth): at most 3 kDepth + 1 wait
    std::array<double, EndList::kMax> area{};
    int top = 0;
    stack[top][0] = p;
    stack[top++][1] = 0;
    double total_w = 0.0, total_a = 0.0;
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
        const double a = G[i].area * (open && i < open->share.size() ? open->share[i] : 1.0);
        area[std::size_t(out.count)] = a;
        out.entry[std::size_t(out.count++)] = {i, a * point_factor(G[i].centre, G[i].normal, q)};
        total_w += out.entry[std::size_t(out.count - 1)].second;
        total_a += a;
    }
    if (!(total_w > 0) || !(total_a > 0)) {
        out.count = 0;
        return;
    }
    double apart = 0.0;
    for (int k = 0; k < out.count; ++k)
        apart += std::abs(out.entry[std::size_t(k)].second / total_w - area[std::size_t(k)] / total_a);
    if (apart <= kFlat) out.count = 0;
}

/// Scales a list's weights to sum to one, dropping nodes that weigh nothing, with no node
/// taking more than a point can: a node m of end p takes w_m A_p / A_m of what p gathers per
/// unit of area, F(p -> q) B_q, on its open part a_m A_m, and at a point of m that is at most
/// B_q (F <= 1), so w_m <= a_m A_m / (A_p F(p -> q)). Weights above that go to the other nodes (water-filling); where
/// the list cannot hold them all (a partly visible link's few rays on small leaves), it is
/// dropped and the end sends its mean. Without the bound a few rays' kernel on a small leaf
/// could hand it many times its sources' radiosity, and the iteration diverged.
void normalise(EndList& e, const ElementTree& tree, const ElementOpenness* open, std::uint32_t end, double factor) {
    const auto& G = tree.geometry();
    double total = 0.0;
    for (int k = 0; k < e.count; ++k) total += e.entry[std::size_t(k)].second;
    int kept = 0;
    for (int k = 0; k < e.count; ++k)
        if (e.entry[std::size_t(k)].second > 0)
            e.entry[std::size_t(kept++)] = {e.entry[std::size_t(k)].first, e.entry[std::size_t(k)].second / total};
    e.count = total > 0 ? kept : 0;
    if (e.count == 0 || !(factor > 0)) return;
    std::array<double, EndList::kMax> cap{};
    std::array<bool, EndList::kMax> held{};
    double room = 0.0;
    for (int k = 0; k < e.count; ++k) {
        const std::uint32_t m = e.entry[std::size_t(k)].first;
        const double share = open && m < open->share.size() ? open->share[m] : 1.0;
        cap[std::size_t(k)] = G[m].area * share / (G[end].area * factor);
        room += cap[std::size_t(k)];
    }
    if (room < 1.0) {  // the nodes cannot take it all
        e.count = 0;
        return;
    }
    for (int round = 0; round < EndList::kMax; ++round) {
        double excess = 0.0, free = 0.0;
        for (int k = 0; k < e.count; ++k) {
            auto& [node, w] = e.entry[std::size_t(k)];
            if (held[std::size_t(k)]) continue;
            if (w > cap[std::size_t(k)]) {
                excess += w - cap[std::size_t(k)];
                w = cap[std::size_t(k)];
                held[std::size_t(k)] = true;
            } else {
                free += w;
            }
        }
        if (excess <= 0.0) return;
        if (!(free > 0)) {
            e.count = 0;
            return;
        }
        for (int k = 0; k < e.count; ++k)
            if (!held[std::size_t(k)]) e.entry[std::size_t(k)].second *= 1.0 + excess / free;
    }
}

}  // namespace

SeenEnds seen_ends(const ElementTree& tree, const std::vector<HierarchicalLink>& links, const RaycastFormFactor& ff,
                   int rays, const ElementOpenness* open) {
    const std::size_t n = links.size();
    const auto& G = tree.geometry();
    SeenEnds out;
    out.first.resize(n + 1, 0);
    out.middle.resize(n, 0);
    // A chunk of links at a time: their lists are built in parallel, then appended in order.
    static constexpr std::size_t kChunk = std::size_t(1) << 16;
    std::vector<EndList> at_a(std::min(n, kChunk)), at_b(at_a.size());
    for (std::size_t begin = 0; begin < n; begin += kChunk) {
        const std::size_t end = std::min(n, begin + kChunk);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 256), [&](const auto& range) {
            std::vector<RaycastFormFactor::PairRay> traced;
            for (std::size_t k = range.begin(); k != range.end(); ++k) {
                const HierarchicalLink& l = links[k];
                EndList &a = at_a[k - begin], &b = at_b[k - begin];
                a.count = b.count = 0;
                if (!l.between_elements() || l.fab == 0.0f) continue;
                if (tree.node(l.a).leaf() && tree.node(l.b).leaf()) continue;  // each end is its one leaf
                if (!(l.visible > 0.0f && l.visible < 1.0f)) {
                    if (!tree.node(l.a).leaf()) kernel_entries(tree, open, l.a, G[l.b], a);
                    if (!tree.node(l.b).leaf()) kernel_entries(tree, open, l.b, G[l.a], b);
                } else {
                    ff.pair_rays(l.a, l.b, std::min(rays, EndList::kMax), traced);
                    for (const auto& r : traced) {
                        if (!r.open || !(r.weight > 0)) continue;
                        if (!tree.node(l.a).leaf()) a.add(leaf_at(tree, l.a, r.on_i), r.weight);
                        if (!tree.node(l.b).leaf()) b.add(leaf_at(tree, l.b, r.on_j), r.weight);
                    }
                }
                normalise(a, tree, open, l.a, double(l.fab));
                normalise(b, tree, open, l.b, double(l.fab) * G[l.a].area / G[l.b].area);
            }
        });
        for (std::size_t k = begin; k < end; ++k) {
            const auto append = [&](const EndList& e, std::uint32_t end_node) {
                for (int m = 0; m < e.count; ++m) {
                    const auto [node, w] = e.entry[std::size_t(m)];
                    out.node.push_back(node);
                    out.weight.push_back(float(w));
                    out.take.push_back(float(w * G[end_node].area / G[node].area));
                }
            };
            out.first[k] = std::uint32_t(out.node.size());
            append(at_a[k - begin], links[k].a);
            out.middle[k] = std::uint32_t(out.node.size());
            append(at_b[k - begin], links[k].b);
        }
    }
    out.first[n] = std::uint32_t(out.node.size());
    return out;
}

}  // namespace bounce::hierarchical
