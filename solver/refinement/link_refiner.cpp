// SPDX-License-Identifier: MIT
#include "solver/refinement/link_refiner.h"

#include <atomic>

#include <tbb/parallel_for.h>

namespace bounce::hierarchical {

Refiner::Refiner(ElementTree& tree, const ClusterTree* clusters, const HierarchicalOptions& o,
                 std::vector<double> min_area, std::vector<Rgb>& radiosity, const std::vector<Rgb>& cluster_radiosity,
                 double scale, double power, const RaycastFormFactor* ff, const SeenVisibility* seen,
                 const ShaftCuller* culler)
    : m_ff(ff),
      m_seen(seen),
      m_culler(culler),
      m_tree(tree),
      m_clusters(clusters),
      m_options(o),
      m_min_area(std::move(min_area)),
      m_b(radiosity),
      m_cb(cluster_radiosity),
      m_scale(scale),
      m_power_budget(o.power_epsilon * power) {
    // How much the leaves' radiosity varies under each node, from the last solution.
    m_b_range = tree.leaf_luminance_spread(radiosity);
}

void Refiner::run(std::vector<Pair> pairs) {
    std::vector<Step> steps;
    std::vector<float> visible;                 // per pair linked after tracing its rays: their open share
    std::vector<std::uint8_t> shaft;            // per pair: its shaft test (HierarchicalLink::shaft)
    std::vector<std::uint32_t> first;           // per pair split at an element: that element's first child
    std::vector<std::size_t> at_next, at_link;  // per pair: where its outputs go
    std::vector<Pair> next;
    // Cancelling stops every thread at its next pair (a block can hold a large share of a
    // generation): the generation being judged is left unlinked.
    const std::atomic<bool>* cancel = m_options.cancel;
    auto cancelled = [cancel] { return cancel && cancel->load(std::memory_order_relaxed); };
    while (!pairs.empty()) {
        const std::size_t n = pairs.size();
        steps.resize(n);
        visible.assign(n, -1.0f);
        shaft.assign(n, HierarchicalLink::kShaftUntested);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& r) {
            for (std::size_t k = r.begin(); k != r.end() && !cancelled(); ++k)
                steps[k] = decide(pairs[k], visible[k], shaft[k]);
        });
        if (cancelled()) return;
        first.resize(n);
        at_next.resize(n + 1);
        at_link.resize(n + 1);
        at_next[0] = at_link[0] = 0;
        for (std::size_t k = 0; k < n; ++k) {
            const std::uint32_t s = split_element(pairs[k], steps[k]);
            if (s != kNoElement) first[k] = children(s);
            at_next[k + 1] = at_next[k] + outputs(pairs[k], steps[k]);
            at_link[k + 1] = at_link[k] + (steps[k] == Step::link);
        }
        next.resize(at_next[n]);
        const std::size_t linked = links.size();
        links.resize(linked + at_link[n]);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& r) {
            for (std::size_t k = r.begin(); k != r.end(); ++k)
                apply(pairs[k], steps[k], visible[k], shaft[k], first[k], next.data() + at_next[k],
                      links.data() + linked + at_link[k]);
        });
        pairs.swap(next);
    }
}

std::size_t Refiner::apply(const Pair& p, Step step, float visible, std::uint8_t shaft, std::uint32_t first, Pair* next,
                           Link* link) const {
    std::size_t count = 0;
    auto any = [&](std::uint32_t x, std::uint32_t y) {
        if (!ClusterTree::is_cluster(x) && !ClusterTree::is_cluster(y) && x == y) return;
        if (next)
            next[count] = ClusterTree::is_cluster(x) || ClusterTree::is_cluster(y)
                              ? Pair{x, y}
                              : Pair{std::min(x, y), std::max(x, y)};
        ++count;
    };
    switch (step) {
        case Step::drop:
            return 0;
        case Step::link:
            if (link) *link = {p.a, p.b, 0.0f, visible, shaft};
            return 0;
        case Step::split_self: {
            const auto child = m_clusters->cluster(p.a).child;
            any(child[0], child[0]);
            any(child[0], child[1]);
            any(child[1], child[1]);
            return count;
        }
        case Step::split_a:
        case Step::split_b: {
            const std::uint32_t s = step == Step::split_a ? p.a : p.b, other = step == Step::split_a ? p.b : p.a;
            if (ClusterTree::is_cluster(s)) {
                const auto child = m_clusters->cluster(s).child;
                any(child[0], other);
                any(child[1], other);
                return count;
            }
            const bool open = shaft == HierarchicalLink::kShaftOpen;
            if (next)
                for (std::uint32_t k = 0; k < 4; ++k) next[k] = {first + k, other, open};
            return 4;
        }
    }
    return 0;
}

std::uint32_t Refiner::children(std::uint32_t i) {
    if (m_tree.node(i).leaf()) {
        const auto first = std::uint32_t(m_tree.split(i));
        // New elements start from their parent's radiosity.
        const Rgb parent = m_b[i];
        m_b.resize(m_tree.size(), parent);
        return first;
    }
    return std::uint32_t(m_tree.node(i).first_child);
}

}  // namespace bounce::hierarchical
