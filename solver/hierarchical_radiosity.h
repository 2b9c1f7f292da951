// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <cstddef>
#include <vector>

#include "mesh/element_tree.h"
#include "solver/form_factor_estimator.h"
#include "solver/solve_result.h"

namespace bounce {

class Visibility;

struct HierarchicalOptions {
    double link_epsilon = 0.1;   // link two elements when F(x -> other) varies by less than this share of its mean over each
    double min_area = 0.0;       // never split an element smaller than this (0: the patch area / 4^max_level)
    int max_level = 8;           // quadtree depth under each patch
    double tolerance = 1e-6;     // stop when no element's radiosity changes by more than this, relatively
    std::size_t max_iterations = 1000;
    FormFactorOptions form_factors;
    const std::atomic<bool>* cancel = nullptr;
};

struct HierarchicalSolution {
    ElementTree tree;
    std::vector<std::uint32_t> leaves;  // the elements of the result
    SolveResult result;                 // per leaf
    std::size_t links = 0;              // element-to-element interactions
    double refine_seconds = 0.0;        // building the links (form factors included)
};

/// Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991). Each pair of patches that
/// face each other is refined recursively: when the unoccluded point-to-polygon factor to the
/// other element varies by less than `link_epsilon` of its mean over each of the two (sampled
/// at centre and corners: the error a link makes by handing every point the mean), or neither
/// may be split, they are linked and the link's form factor is computed with visibility (RaycastFormFactor, both
/// directions from one integral); otherwise the larger of the two is split into its quadtree
/// children. The solution iterates gather (every element collects F B over its links) and
/// push-pull (irradiance pushed down to the leaves, radiosity pulled up as area-weighted
/// means) until it settles. The link count grows like N, not N^2.
HierarchicalSolution solve_hierarchical(const std::vector<Patch>& patches, const Visibility& visibility,
                                        const HierarchicalOptions& options);

}  // namespace bounce
