// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mesh/meshing/element_tree.h"
#include "solver/refinement/element_open_shares.h"
#include "solver/refinement/hierarchical_radiosity.h"

namespace bounce {

class RaycastFormFactor;

namespace hierarchical {

/// Where the two ends of each link see each other: per end, its nodes two levels down (or its
/// leaves above that) weighted by their open area times their point factor to the other end,
/// or, for a link partly visible to its refinement rays, the leaves its arriving rays start
/// from or reach, weighted by the rays' kernel. An end sends the weighted mean of its nodes'
/// radiosity and shares what it gathers among them by the same weights. A link otherwise hands
/// over its ends' means: a coarse element's bright side is farther from what lies down the
/// gradient than its dark side, so its mean sends light down a gradient faster than it should
/// (in a corridor lit from one end the excess compounds over every bounce), and a face beside
/// an acute wedge hands its parts in the wedge the light its open side sees. The weights are
/// the link's rank-one estimate of sum_m F(l -> m) over the ends' nodes l and m.
struct SeenEnds {
    /// Per link: its entries are [first[k], first[k + 1]) of node and weight, a's end's list
    /// then b's, split at middle[k]. An end's list is empty where it is a leaf or a cluster,
    /// where its weights would be about its nodes' shares of its area (kernel_entries), or
    /// where no ray arrived: the end then sends its mean and takes alike.
    std::vector<std::uint32_t> first, middle;
    std::vector<std::uint32_t> node;
    std::vector<float> weight;
    /// Per entry, weight times the end's area over the node's: what the node takes per unit of
    /// its area of what its end gathers per unit of the end's.
    std::vector<float> take;

    bool empty() const { return node.empty(); }
};

/// The most links a solve weighs its ends for (HierarchicalOptions::weighted_ends). An end's
/// list holds up to 16 entries of 12 bytes, and the iteration reads them every sweep, against
/// about 120 bytes a link otherwise: in an office of thousands of patches the lists would
/// nearly double the solve's memory (docs/measurements/2026-12-07-weighted-ends.md). Above
/// this the ends send their means.
inline constexpr std::size_t kWeightedEndsMaxLinks = 8'000'000;

/// SeenEnds of `links` over `tree` as it stands (`open`: its nodes' open parts, or null), with
/// `rays` of the pair's own stratified rays (RaycastFormFactor::pair_rays) per partly visible
/// link.
SeenEnds seen_ends(const ElementTree& tree, const std::vector<HierarchicalLink>& links, const RaycastFormFactor& ff,
                   int rays, const ElementOpenness* open);

}  // namespace hierarchical
}  // namespace bounce
