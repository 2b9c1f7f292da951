// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <vector>

#include "mesh/meshing/element_tree.h"
#include "solver/linear/solve_result.h"
#include "solver/refinement/cluster_tree.h"
#include "solver/refinement/hierarchical_radiosity.h"

namespace bounce::hierarchical {

/// The links of a hierarchy and the hierarchy they join: what one solve over them reads.
struct LinkSystem {
    const ElementTree& tree;
    const ClusterTree* clusters;  // null: no clustering
    const std::vector<HierarchicalLink>& links;
    const HierarchicalOptions& options;
};

/// Radiosity B and irradiance H in W/m^2 per element node of the tree, and B per cluster
/// (Bc, a cluster's members' area-weighted mean).
struct HierarchyRadiosity {
    std::vector<Rgb> B, Bc, H;
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
/// out.tree hold the solved hierarchy).
void finish_result(const HierarchyRadiosity& x, HierarchicalSolution& out);

}  // namespace bounce::hierarchical
