// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "mesh/meshing/element_tree.h"
#include "solver/refinement/cluster_tree.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/shaft_culler.h"

namespace bounce {

class RaycastFormFactor;

namespace hierarchical {

using Link = HierarchicalLink;

/// Pairs whose partial visibility refinement has traced, with the open share of their rays,
/// sorted by pair_key.
using SeenVisibility = std::vector<std::pair<std::uint64_t, float>>;

/// A pair of elements either way round as one key (its rays do not depend on the order).
inline std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    return std::uint64_t(std::min(a, b)) << 32 | std::max(a, b);
}

/// Rays that judge whether a shadow's edge crosses a pair about to be linked (enough that a
/// partly shadowed pair rarely has every ray arrive).
inline constexpr int kPartialVisibilityRays = 16;

/// Refinement asks the shaft test (ShaftCuller::unblocked) of every pair it splits or links
/// when the scene has at most this many plane groups: a test then costs about what the
/// partial-visibility rays of one pair do (kPartialVisibilityRays x kPlaneTestsPerRay), and a
/// pair that passes spares its descendants every test and ray. In a room of few planes most
/// pairs pass high in the tree; among furniture (thousands of groups) a test costs more than
/// the rays it spares, and none is made.
inline constexpr double kRefinementShaftPlanes = kPartialVisibilityRays * ShaftCuller::kPlaneTestsPerRay;

/// Builds the links of hierarchical radiosity (solve_hierarchical) by BF refinement: the
/// oracle (decide(), link_oracle.cpp) judges each pair of elements or clusters, which is
/// linked, dropped or split (link_refiner.cpp).
class Refiner {
public:
    Refiner(ElementTree& tree, const ClusterTree* clusters, const HierarchicalOptions& o, std::vector<double> min_area,
            std::vector<Rgb>& radiosity, const std::vector<Rgb>& cluster_radiosity, double scale, double power,
            const RaycastFormFactor* ff = nullptr, const SeenVisibility* seen = nullptr,
            const ShaftCuller* culler = nullptr);

    struct Pair {
        std::uint32_t a, b;
        /// A shaft test proved an ancestor pair unblocked (ShaftCuller::unblocked): this pair's
        /// shaft lies inside that one, so every segment between the two is open too.
        bool open = false;
    };

    /// Refines from `pairs`, a generation at a time: every pair of a generation is judged in
    /// parallel (decide() reads the tree and the last solution, never changes them), then, in
    /// the generation's order, linked, dropped or split into pairs of the next generation.
    /// Splitting, the one step that changes the tree, stays serial and in a fixed order, so
    /// the elements' numbering and the links do not depend on the number of threads; the
    /// links and the next generation are then written in parallel, each pair at the place its
    /// predecessors' counts give it.
    void run(std::vector<Pair> pairs);

    std::vector<Link> links;

private:
    enum class Step : std::uint8_t { drop, link, split_a, split_b, split_self };

    /// A pair of which either end may be a cluster (ClusterTree refs); pairs of elements go
    /// to decide_elements(). A link with a cluster hands every member the same irradiance, so
    /// its error at a member is bounded by what the other end could send it at most: B_b A_b
    /// / (pi r_min^2), every member of b facing the point at the bounding spheres' gap (Sillion
    /// 1995). Link when that is below link_epsilon of what the link brings plus cluster_floor
    /// of the scene's mean radiosity, both ways round; else split the larger cluster. A
    /// cluster's self-link is always refined: it would send a cluster's power to itself.
    Step decide(const Pair& p, float& visible, std::uint8_t& shaft) const;

    /// A link hands every point of a the mean F(a -> b), so it errs at a's leaves by up to
    /// spread(F(x -> b)) B_b. Link when that is below link_epsilon of what the link brings,
    /// F(a -> b) B_b, plus a floor of link_floor of the scene's mean radiosity (BF refinement,
    /// Hanrahan et al. section 4: faint interactions stay coarse), both ways round; else split
    /// the larger. Summed over a leaf's links the error is then at most link_epsilon of its
    /// irradiance plus the floors. `visible` gets the open share of the rays traced, if any.
    Step decide_elements(const Pair& p, float& visible, std::uint8_t& shaft) const;

    /// The link test of decide_elements: errors err_a at a and err_b at b against what the
    /// link brings each (F B), relative to it plus the floor, or on power.
    bool accepted(double err_a, double err_b, double brings_a, double brings_b, std::uint32_t a,
                  std::uint32_t b) const {
        return (relative_at(err_a, brings_a) && relative_at(err_b, brings_b)) ||
               (power_at(err_a, a) && power_at(err_b, b));
    }
    /// accepted() for a pair a shadow's edge crosses. Where one end emits, the other end is
    /// judged on the relative test alone: the edge of a shadow of direct light is refined
    /// whatever its power, since a faint penumbra (a dark corner's, a small lamp's) is where a
    /// power budget would stop refining and the point data most misplaces the light.
    bool partly_visible_accepted(double err_a, double err_b, double brings_a, double brings_b, std::uint32_t a,
                                 std::uint32_t b) const {
        const bool lit_a = m_tree.geometry()[b].emission.max() > 0, lit_b = m_tree.geometry()[a].emission.max() > 0;
        if (!lit_a && !lit_b) return accepted(err_a, err_b, brings_a, brings_b, a, b);
        return (!lit_a || relative_at(err_a, brings_a)) && (!lit_b || relative_at(err_b, brings_b));
    }
    /// One end's half of accepted(): false means the pair is refused whatever the other end's.
    bool accepted_at(double err, double brings, std::uint32_t end) const {
        return relative_at(err, brings) || power_at(err, end);
    }
    bool relative_at(double err, double brings) const {
        return err <= m_options.link_epsilon * (brings + m_options.link_floor * m_scale);
    }
    bool power_at(double err, std::uint32_t end) const {
        return m_power_budget > 0 && err * m_tree.geometry()[end].area <= m_power_budget;
    }

    static constexpr std::uint32_t kNoElement = std::numeric_limits<std::uint32_t>::max();

    /// The element a step splits (its quadtree children replace it), or kNoElement.
    std::uint32_t split_element(const Pair& p, Step step) const {
        if (step != Step::split_a && step != Step::split_b) return kNoElement;
        const std::uint32_t s = step == Step::split_a ? p.a : p.b;
        return ClusterTree::is_cluster(s) ? kNoElement : s;
    }

    /// Carries out a decision: the link into `link`, new pairs from `next` on (outputs() of
    /// them); `first`: the split element's first child. Pairs of elements met through clusters
    /// go in the unclustered order (the oracle's ties in area split the first); a planar patch
    /// does not see itself. With `next` null, only counts what it would write.
    std::size_t apply(const Pair& p, Step step, float visible, std::uint8_t shaft, std::uint32_t first, Pair* next,
                      Link* link) const;
    /// How many pairs apply() makes of a decision.
    std::size_t outputs(const Pair& p, Step step) const {
        return apply(p, step, 0.0f, HierarchicalLink::kShaftUntested, 0, nullptr, nullptr);
    }

    bool splittable(std::uint32_t i) const {
        const auto& n = m_tree.node(i);
        return n.level < m_options.max_level && m_tree.geometry()[i].area >= 4.0 * m_min_area[n.root] * (1 - 1e-9);
    }
    std::uint32_t children(std::uint32_t i);

    /// The open share a pair's rays had in an earlier round (the rays depend only on the pair).
    bool seen_visible(std::uint32_t a, std::uint32_t b, float& out) const {
        if (!m_seen) return false;
        const std::uint64_t key = pair_key(a, b);
        const auto it = std::lower_bound(m_seen->begin(), m_seen->end(), std::pair(key, -2.0f));
        if (it == m_seen->end() || it->first != key) return false;
        out = it->second;
        return true;
    }

    double range(std::uint32_t i) const { return i < m_b_range.size() ? m_b_range[i] : 0.0; }  // 0: made this round

    double luminance(std::uint32_t ref) const {
        return ClusterTree::is_cluster(ref) ? m_cb[ClusterTree::index(ref)].luminance() : m_b[ref].luminance();
    }

    const RaycastFormFactor* m_ff;
    const SeenVisibility* m_seen;
    const ShaftCuller* m_culler;  // over the input patches; null: no shaft tests (kRefinementShaftPlanes)
    ElementTree& m_tree;
    const ClusterTree* m_clusters;
    const HierarchicalOptions& m_options;
    std::vector<double> m_min_area;
    std::vector<Rgb>& m_b;
    const std::vector<Rgb>& m_cb;
    double m_scale;
    double m_power_budget;          // power_epsilon of the scene's power: a link misplacing less is fine
    std::vector<double> m_b_range;  // per node of the last round: max - min of its leaves' luminance
};

}  // namespace hierarchical
}  // namespace bounce
