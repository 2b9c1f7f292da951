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
    // Element links per node (compressed rows): links between elements, whose polygons the
    // gather integrates over, also those whose few refinement rays were all blocked. A point
    // traces its own rays: at a shadow's edge it sees part of a source its element's rays
    // missed (on the Cornell box's red wall, by the tall block, the probes were up to 6% dark).
    auto gathered = [](const HierarchicalLink& l) { return l.between_elements(); };
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

/// GatherSources::descend for the vertices: a vertex goes down from a linked source to its
/// children where their spread, times the kernel's variation over the source (r / d), passes a
/// tenth of what the source brings. On the Cornell box (`bounce compare --meshes`, 0.1% probes)
/// it took the point data at power epsilon 3e-5 / 1e-5 from 1.71% / 1.24% to 1.26% / 0.91% for
/// about a tenth more time; at 1e-6 and without the power bound it changed nothing. By the
/// probe script of the notes, 0.3 gave 1.67% / 1.09% and 0.05 1.33% / 0.99% (0.1: 1.36%
/// / 1.02%) for a quarter more time. The leaves' centres gained nothing from it.
constexpr double kDescendShare = 0.1;

/// Every leaf's value gathered at its centre through its own links (the leaf's list of
/// `sources`) from the solution's node radiosity: mode "centres", and the first step of the
/// re-gather below.
std::vector<Rgb> centre_values(const HierarchicalSolution& sol, const PatchMesh& elements, const LinkSources& sources,
                               const Visibility& visibility, const GatherOptions& options,
                               const std::atomic<bool>* cancel,
                               const std::function<void(std::size_t, std::size_t)>& progress) {
    std::vector<std::uint32_t> own(elements.size());  // a centre gathers through its own element
    for (std::size_t k = 0; k < own.size(); ++k) own[k] = std::uint32_t(k);
    const GatherSources at{own, sources.offsets, sources.nodes, sol.cluster_irradiance};
    return final_gather(sol.tree.geometry(), sol.node_radiosity, visibility, centre_gather_points(elements.patches()),
                        at, options, cancel, progress);
}

/// The node radiosity with every leaf's replaced by its re-gathered centre value and every
/// parent the area-weighted mean of its children (one Jacobi step with the exact point kernel
/// and visibility). A link accepted for its small power hands all of a coarse element the same
/// irradiance, however differently its leaves see the source; the centre gather gives each
/// leaf its own.
std::vector<Rgb> regathered_radiosity(const HierarchicalSolution& sol, const std::vector<Rgb>& centres) {
    const ElementTree& tree = sol.tree;
    const auto& nodes = tree.geometry();
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
            GatherSources at{sources.vertex_list, sources.offsets, sources.nodes, solution.cluster_irradiance};
            std::vector<Rgb> regathered;
            if (solution.power_epsilon > 0) {
                centres = centre_values(solution, elements, sources, visibility, options, cancel,
                                        [&progress](std::size_t d, std::size_t t) {
                                            if (progress) progress("gathering: element centres", d, t);
                                        });
                if (cancel && cancel->load()) return;
                regathered = regathered_radiosity(solution, centres);
            }
            const std::vector<Rgb>& B = regathered.empty() ? solution.node_radiosity : regathered;
            std::vector<std::int32_t> first_child(solution.tree.size());
            for (std::size_t i = 0; i < first_child.size(); ++i) first_child[i] = solution.tree.node(i).first_child;
            const std::vector<double> spread = solution.tree.leaf_luminance_spread(B);
            at.first_child = first_child;
            at.spread = spread;
            at.descend = kDescendShare;
            res.point_radiosity =
                final_gather(nodes, B, visibility, vertex_gather_points(elements), at, options, cancel, report);
        },
        [&](const auto& report) {
            // With a power epsilon the same gather is already done.
            if (centres.empty())
                centres = centre_values(solution, elements, sources, visibility, options, cancel, report);
            res.gathered_centres = std::move(centres);
        });
}

}  // namespace bounce
