// SPDX-License-Identifier: MIT
#include "solver/gather/hierarchical_point_values.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace bounce {
namespace {

/// Per leaf (in solution.leaves order), the nodes its element links reach along its path to
/// the root, as GatherSources lists; and each gather point's list.
struct LinkSources {
    std::vector<std::size_t> offsets;
    std::vector<std::uint32_t> nodes;
    std::vector<std::uint32_t> vertex_list;  // per vertex of the elements: its leaf
    double pairs = 0.0;                      // gather points x sources (leaf centres too, with a power epsilon)
};

LinkSources link_sources(const HierarchicalSolution& sol, const PatchMesh& elements) {
    const ElementTree& tree = sol.tree;
    const std::size_t n = tree.size();
    if (elements.size() != sol.leaves.size())
        throw std::invalid_argument("hierarchical gather: the elements are not the solution's leaves");
    // Element links per node (compressed rows).
    // Only links between elements with a factor: the gather integrates over their polygons.
    auto gathered = [](const HierarchicalLink& l) { return l.between_elements() && l.fab != 0.0f; };
    std::vector<std::size_t> first(n + 1, 0);
    for (const auto& l : sol.links)
        if (gathered(l)) {
            ++first[l.a + 1];
            ++first[l.b + 1];
        }
    for (std::size_t i = 0; i < n; ++i) first[i + 1] += first[i];
    std::vector<std::uint32_t> other(first[n]);
    std::vector<std::size_t> fill(first.begin(), first.end() - 1);
    for (const auto& l : sol.links)
        if (gathered(l)) {
            other[fill[l.a]++] = l.b;
            other[fill[l.b]++] = l.a;
        }
    LinkSources out;
    out.offsets.push_back(0);
    for (const std::uint32_t leaf : sol.leaves) {
        for (std::int64_t a = leaf; a >= 0; a = tree.node(std::size_t(a)).parent)
            out.nodes.insert(out.nodes.end(), other.begin() + std::ptrdiff_t(first[std::size_t(a)]),
                             other.begin() + std::ptrdiff_t(first[std::size_t(a) + 1]));
        out.offsets.push_back(out.nodes.size());
    }
    // A vertex takes the last element around it, as vertex_gather_points takes its surface.
    out.vertex_list.assign(elements.mesh().n_vertices(), 0);
    for (std::size_t k = 0; k < elements.size(); ++k)
        for (const int v : elements.patch_vertex_indices(k)) out.vertex_list[std::size_t(v)] = std::uint32_t(k);
    for (const std::uint32_t k : out.vertex_list) out.pairs += double(out.offsets[k + 1] - out.offsets[k]);
    if (sol.power_epsilon > 0) out.pairs += double(out.nodes.size());  // the leaves' centres first
    return out;
}

/// Per leaf, its own source list: a centre gathers through its own element.
std::vector<std::uint32_t> own_lists(std::size_t leaves) {
    std::vector<std::uint32_t> own(leaves);
    for (std::size_t k = 0; k < own.size(); ++k) own[k] = std::uint32_t(k);
    return own;
}

/// Every leaf's radiosity gathered anew at its centre through its own links (one Jacobi step
/// with the exact point kernel and visibility), every parent the area-weighted mean of its
/// children. A link accepted for its small power hands all of a coarse element the same
/// irradiance, however differently its leaves see the source; the centre gather gives each
/// leaf its own. Returns the leaves' values in `centres` too.
std::vector<Rgb> regathered_radiosity(const HierarchicalSolution& sol, const PatchMesh& elements,
                                      const LinkSources& sources, const Visibility& visibility,
                                      const GatherOptions& options, std::vector<Rgb>& centres,
                                      const std::atomic<bool>* cancel,
                                      const std::function<void(std::size_t, std::size_t)>& progress) {
    const ElementTree& tree = sol.tree;
    const auto& nodes = tree.geometry();
    const auto own = own_lists(elements.size());
    const GatherSources at{own, sources.offsets, sources.nodes, sol.cluster_irradiance};
    centres = final_gather(nodes, sol.node_radiosity, visibility, centre_gather_points(elements.patches()), at, options,
                           cancel, progress);
    std::vector<Rgb> B = sol.node_radiosity;
    for (std::size_t k = 0; k < centres.size(); ++k) B[sol.leaves[k]] = centres[k];
    for (std::size_t i = tree.size(); i-- > 0;) {  // children follow their parent in the node order
        const auto& node = tree.node(i);
        if (node.leaf()) continue;
        Rgb sum;
        for (int c = 0; c < 4; ++c) {
            const auto child = std::size_t(node.first_child + c);
            sum += B[child] * nodes[child].area;
        }
        B[i] = sum * (1.0 / nodes[i].area);
    }
    return B;
}

}  // namespace

double hierarchical_gather_pairs(const HierarchicalSolution& solution, const PatchMesh& elements) {
    return link_sources(solution, elements).pairs;
}

GatherOutcome gather_hierarchical_point_values(
    const HierarchicalSolution& solution, const PatchMesh& elements, const Visibility& visibility, SolveResult& res,
    const std::string& mode, const std::atomic<bool>* cancel,
    const std::function<void(const char*, std::size_t, std::size_t)>& progress) {
    check_gather_mode(mode);
    if (mode == "none") return GatherOutcome::not_asked;
    const LinkSources sources = link_sources(solution, elements);
    if (sources.pairs > kMaxGatherPairs) return GatherOutcome::over_budget;
    const GatherOptions options = point_value_options();
    const auto& nodes = solution.tree.geometry();
    std::vector<Rgb> centres;  // with a power epsilon: the leaves re-gathered first
    return run_point_gather(
        mode, res, cancel, progress,
        [&](const auto& report) {
            const GatherSources at{sources.vertex_list, sources.offsets, sources.nodes, solution.cluster_irradiance};
            if (!(solution.power_epsilon > 0)) {
                res.point_radiosity = final_gather(nodes, solution.node_radiosity, visibility,
                                                   vertex_gather_points(elements), at, options, cancel, report);
                return;
            }
            const auto centre_progress = [&progress](std::size_t d, std::size_t t) {
                if (progress) progress("gathering: element centres", d, t);
            };
            const std::vector<Rgb> B = regathered_radiosity(solution, elements, sources, visibility, options, centres,
                                                            cancel, centre_progress);
            if (cancel && cancel->load()) return;
            res.point_radiosity =
                final_gather(nodes, B, visibility, vertex_gather_points(elements), at, options, cancel, report);
        },
        [&](const auto& report) {
            if (!centres.empty()) {  // the same gather, already done
                res.gathered_centres = std::move(centres);
                return;
            }
            const auto own = own_lists(elements.size());
            const GatherSources at{own, sources.offsets, sources.nodes, solution.cluster_irradiance};
            res.gathered_centres = final_gather(nodes, solution.node_radiosity, visibility,
                                                centre_gather_points(elements.patches()), at, options, cancel, report);
        });
}

}  // namespace bounce
