// SPDX-License-Identifier: MIT
#include "solver/refinement/hierarchical_radiosity.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>

#include "solver/form_factors/raycast_form_factor.h"
#include "solver/refinement/cluster_links.h"
#include "solver/refinement/cluster_tree.h"
#include "solver/refinement/element_open_shares.h"
#include "solver/refinement/hierarchical_iteration.h"
#include "solver/refinement/link_refiner.h"
#include "solver/refinement/seen_ends.h"
#include "solver/visibility/shaft_culler.h"
#include "solver/visibility/visibility.h"

namespace bounce {
namespace {

using namespace hierarchical;

/// What refinement starts from: the scene's area, each patch's smallest element and a first
/// estimate of B.
struct Start {
    double total_area = 0.0;
    std::vector<double> min_area;  // per patch: never split an element below this area
    std::vector<Rgb> B;            // per patch
};

Start start_of(const std::vector<Patch>& patches, const HierarchicalOptions& options) {
    Start s;
    // First estimate of B for the oracle: emission plus the ambient term (the emitted power
    // spread over all area and inter-reflected by the mean reflectance).
    Rgb power, rho_area;
    for (const auto& p : patches) {
        s.total_area += p.area;
        power += p.emission * p.area;
        rho_area += p.reflectance * p.area;
    }
    // The depth counts from the patch or from the base, whichever is larger: the oracle's
    // spread-to-mean ratio does not fall with size where surfaces touch, so without the base
    // every small triangle touching another would be cut max_level times.
    s.min_area.resize(patches.size());
    const double base = options.level_base * s.total_area;
    for (std::size_t r = 0; r < patches.size(); ++r)
        s.min_area[r] = options.min_area > 0 ? options.min_area
                                             : std::max(patches[r].area, base) / std::pow(4.0, options.max_level);
    Rgb ambient;
    for (int c = 0; c < 3; ++c) ambient[c] = power[c] / s.total_area / std::max(1e-3, 1.0 - rho_area[c] / s.total_area);
    s.B.resize(patches.size());
    for (std::size_t r = 0; r < patches.size(); ++r) s.B[r] = patches[r].emission + patches[r].reflectance * ambient;
    return s;
}

/// A cluster's radiosity: its members' area-weighted mean (children after parents).
std::vector<Rgb> cluster_radiosity(const ClusterTree& clusters, const std::vector<Patch>& patches,
                                   const std::vector<Rgb>& B) {
    const auto& C = clusters.clusters();
    std::vector<Rgb> Bc(C.size(), Rgb());
    for (std::size_t c = C.size(); c-- > 0;) {
        Rgb sum;
        for (const std::uint32_t ref : C[c].child)
            sum += ClusterTree::is_cluster(ref) ? Bc[ClusterTree::index(ref)] * C[ClusterTree::index(ref)].area
                                                : B[ref] * patches[ref].area;
        Bc[c] = sum * (1.0 / C[c].area);
    }
    return Bc;
}

/// Link form factors a round keeps for the next, keyed by both ends (key()) and sorted for
/// binary search (refs are stable: the tree only grows). Multigridding (Hanrahan et al. 1991,
/// section 5): a later round keeps the form factor of every link the last round had, computed
/// once; only new links cast rays.
using KnownFactors = std::vector<std::pair<std::uint64_t, float>>;

std::uint64_t key(const Link& l) { return std::uint64_t(l.a) << 32 | l.b; }

/// What every round of refinement shares.
struct Rounds {
    const std::vector<Patch>& patches;
    const Visibility& visibility;
    const HierarchicalOptions& options;
    const Start& start;
    const RaycastFormFactor& ff;
    const ClusterTree* clusters;  // null: no clustering
};

/// One round's links, refined on the radiosity in x (the refiner adds the new elements').
std::vector<Link> refine(const Rounds& r, ElementTree& tree, HierarchyRadiosity& x, const SeenVisibility& seen) {
    const auto& patches = r.patches;
    const HierarchicalOptions& options = r.options;
    double scale = 0.0;
    for (std::uint32_t p = 0; p < patches.size(); ++p) scale += x.B[p].luminance() * patches[p].area;
    const double power = scale;
    scale /= r.start.total_area;
    // Refinement's shaft tests use the estimator's culler, built over the input patches (the
    // tree held only those then), rather than building the same one again.
    const ShaftCuller* culler = r.ff.culler();
    Refiner refiner(tree, r.clusters, options, r.start.min_area, x.B, x.Bc, scale, power,
                    options.refine_partial_visibility ? &r.ff : nullptr, &seen,
                    culler && culler->plane_groups() <= kRefinementShaftPlanes ? culler : nullptr);
    if (r.clusters) {
        refiner.run({{r.clusters->root(), r.clusters->root()}});
    } else {
        // Every pair of patches, a patch's pairs at a time (not N^2 / 2 pairs at once).
        for (std::uint32_t p = 0; p < patches.size(); ++p) {
            if (options.cancel && options.cancel->load()) break;
            std::vector<Refiner::Pair> pairs;
            for (std::uint32_t q = p + 1; q < patches.size(); ++q) pairs.push_back({p, q});
            refiner.run(std::move(pairs));
        }
    }
    return std::move(refiner.links);
}

/// The links' form factors with visibility, in parallel (the tree does not change here);
/// those `known` holds are taken from it. Returns how many were.
std::size_t link_form_factors(const Rounds& r, const ElementTree& tree, const KnownFactors& known,
                              const std::string& stage, std::vector<Link>& links) {
    const HierarchicalOptions& options = r.options;
    std::atomic<std::size_t> done{0}, reused{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, links.size(), 256), [&](const auto& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            // Cancelled: the links left keep form factor 0, and the iteration that follows
            // stops before its first sweep.
            if (options.cancel && options.cancel->load(std::memory_order_relaxed)) return;
            const Link& l = links[k];
            const auto it = std::lower_bound(known.begin(), known.end(), std::pair(key(l), -1.0f));
            if (it != known.end() && it->first == key(l)) {
                links[k].fab = it->second;
                reused.fetch_add(1, std::memory_order_relaxed);
                continue;
            }
            if (l.between_elements()) {
                links[k].fab = float(l.visible >= 0 ? r.ff.pair(l.a, l.b, l.visible) : r.ff.pair(l.a, l.b));
                continue;
            }
            const End ea = end_of(tree, *r.clusters, l.a), eb = end_of(tree, *r.clusters, l.b);
            double t = cluster_transfer(ea, eb);
            if (t > 0 && options.cluster_visibility) t *= cluster_visible_fraction(ea, eb, r.visibility);
            links[k].fab = float(t / ea.area);
        }
        const std::size_t now = done.fetch_add(range.size(), std::memory_order_relaxed) + range.size();
        if (options.progress) options.progress(stage + ": link form factors", now, links.size());
    });
    return reused.load();
}

/// Keeps a round's form factors and partial-visibility ray shares for the next round.
void remember(const std::vector<Link>& links, KnownFactors& known, SeenVisibility& seen) {
    known.resize(links.size());
    for (std::size_t k = 0; k < links.size(); ++k) known[k] = {key(links[k]), links[k].fab};
    std::sort(known.begin(), known.end());
    for (const Link& l : links)
        if (l.visible >= 0) seen.push_back({pair_key(l.a, l.b), l.visible});
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
               seen.end());
}

}  // namespace

HierarchicalSolution solve_hierarchical(const std::vector<Patch>& patches, const Visibility& visibility,
                                        const HierarchicalOptions& options) {
    if (patches.empty()) throw std::invalid_argument("hierarchical radiosity: no patches");
    if (!(options.link_epsilon > 0))
        throw std::invalid_argument("hierarchical radiosity: the link epsilon must be > 0");
    if (options.refine_rounds < 1) throw std::invalid_argument("hierarchical radiosity: at least one refinement round");
    const auto start_time = std::chrono::steady_clock::now();
    auto since_start = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
    };
    HierarchicalSolution out{ElementTree(patches), {}, {}, 0, 0, 0, 0.0, 0, {}, {}, {}, {}, options.power_epsilon};
    ElementTree& tree = out.tree;
    const Start start = start_of(patches, options);
    HierarchyRadiosity x;
    x.B = start.B;

    SolveResult& res = out.result;
    res.solver = "hierarchical";
    res.form_factors = "raycast";
    FormFactorOptions link_factors = with_rays_only(with_default_rays(options.form_factors, kRefinementRays));
    link_factors.unoccluded_tolerance = std::max(link_factors.unoccluded_tolerance, options.link_factor_tolerance);
    const RaycastFormFactor ff(tree.geometry(), &visibility, link_factors);
    std::optional<ClusterTree> clusters;
    if (options.clustering) {
        clusters.emplace(patches);
        x.Bc = cluster_radiosity(*clusters, patches, x.B);
        out.clusters = clusters->clusters().size();
        out.initial_links = 1;
    } else {
        out.initial_links = patches.size() * (patches.size() - 1) / 2;
    }
    const Rounds rounds{patches, visibility, options, start, ff, clusters ? &*clusters : nullptr};
    std::vector<Link> links;
    KnownFactors known;
    SeenVisibility seen;  // partial visibility's ray shares, kept across rounds
    std::optional<ElementOpenShares> open;
    const ElementOpenness* openness = nullptr;  // the last round's
    SeenEnds ends;                              // the last round's
    if (options.open_parts) open.emplace(patches, visibility, options.covered, options.cancel);
    for (int round = 0; round < options.refine_rounds; ++round) {
        const double round_start = since_start();
        const std::string stage = "round " + std::to_string(round + 1) + "/" + std::to_string(options.refine_rounds);
        if (options.progress) options.progress(stage + ": refining links", 0, 1);
        links = refine(rounds, tree, x, seen);
        out.reused_links += link_form_factors(rounds, tree, known, stage, links);
        if (options.cancel && options.cancel->load()) {
            // Stopped before this round's iteration, whose setup alone walks every link: B
            // stays the estimate refinement used, and nothing is gathered.
            x.H.assign(x.B.size(), Rgb());
            res.status = SolveStatus::interrupted;
            res.converged = false;
            break;
        }
        if (round + 1 < options.refine_rounds) remember(links, known, seen);
        out.refine_seconds += since_start() - round_start;
        // A round before the last only gives the oracle its B: a few parts in a thousand do
        // (the last round starts from it and settles to the tolerance).
        const bool last = round + 1 == options.refine_rounds;
        const double tolerance = last ? options.tolerance : std::max(options.tolerance, 1e-3);
        openness = open ? &open->update(tree) : nullptr;
        ends = options.weighted_ends && links.size() <= kWeightedEndsMaxLinks
                   ? seen_ends(tree, links, ff, kPartialVisibilityRays, openness)
                   : SeenEnds{};
        out.weighted_ends = !ends.empty();
        solve_links({tree, rounds.clusters, links, options, openness, &ends}, tolerance, stage, x, res);
        if (res.status == SolveStatus::interrupted) break;
    }
    for (const Link& l : links) out.cluster_links += !l.between_elements();
    out.links = std::move(links);
    finish_result(x, openness, &ends, out);
    res.seconds = since_start();
    return out;
}

std::string hierarchical_settings(const HierarchicalOptions& options, const HierarchicalSolution& solution) {
    std::ostringstream s;
    s << " solver=hierarchical link_epsilon=" << options.link_epsilon << " power_epsilon=" << options.power_epsilon
      << " link_floor=" << options.link_floor << " link_factor_tolerance=" << options.link_factor_tolerance
      << " max_level=" << options.max_level << " refine_rounds=" << options.refine_rounds
      << " clustering=" << (options.clustering ? 1 : 0) << " tolerance=" << options.tolerance
      << " max_iterations=" << options.max_iterations << " elements=" << solution.leaves.size()
      << " links=" << solution.links.size() << (options.open_parts ? " open_parts=1" : "")
      << (solution.weighted_ends ? " weighted_ends=1" : "");
    return s.str();
}

}  // namespace bounce
