// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <vector>

#include "mesh/meshing/element_tree.h"
#include "solver/linear/solve_result.h"
#include "solver/refinement/cluster_tree.h"
#include "solver/refinement/element_open_shares.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/refinement/seen_ends.h"

namespace bounce::hierarchical {

/// The links of a hierarchy and the hierarchy they join: what one solve over them reads.
struct LinkSystem {
    const ElementTree& tree;
    const ClusterTree* clusters;  // null: no clustering
    const std::vector<HierarchicalLink>& links;
    const HierarchicalOptions& options;
    /// Per element node, its open part (element_open_shares.h); null: every node is open and
    /// sends as its links' rows say. A node's radiosity is its open part's, what it gathers
    /// lands on its open part (on the whole node where none is open: it sends nothing), a
    /// parent or cluster takes its members' mean weighted by their open areas.
    const ElementOpenness* open = nullptr;
    /// Where each link's ends see each other (seen_ends.h): an end sends the weighted mean of
    /// its nodes listed there and what it gathers lands on them by the same weights; null or
    /// empty: every link sends its ends' means and hands each end's nodes alike.
    const SeenEnds* seen = nullptr;
};

/// Radiosity B and irradiance H in W/m^2 per element node of the tree (on its open part,
/// LinkSystem::open), and B per cluster (Bc, its members' mean weighted by their open areas).
struct HierarchyRadiosity {
    std::vector<Rgb> B, Bc, H;
    /// Per element node, with open parts: a leaf's row, the share of what its open part sends
    /// that its links carry to patches (the rest escapes or meets back sides).
    std::vector<double> rows;
};

/// Gather and push-pull until the leaves settle (Jacobi over the hierarchy): every element or
/// cluster gathers F B over its links, what it gathers is pushed down to the leaves, the
/// leaves reflect it and their radiosity is pulled up as area-weighted means. Stops when no
/// leaf's luminance changes by more than `tolerance` of the mean radiosity, after
/// options.max_iterations, or when options.cancel is set; res gets the steps and status.
/// `stage` names the round for options.progress. Starts from and leaves its answer in `x`.
void solve_links(const LinkSystem& system, double tolerance, const std::string& stage, HierarchyRadiosity& x,
                 SolveResult& res);

/// The leaves' radiosity and irradiance, and the energy account, into out.result; every
/// node's radiosity and the leaves' irradiance from cluster links into out (out.links and
/// out.tree hold the solved hierarchy; `open` the nodes' open parts, or null; `seen` what the
/// links' ends saw of each other, as solved, or null).
void finish_result(const HierarchyRadiosity& x, const ElementOpenness* open, const SeenEnds* seen,
                   HierarchicalSolution& out);

}  // namespace bounce::hierarchical
