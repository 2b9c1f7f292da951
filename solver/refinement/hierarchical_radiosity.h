// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "mesh/meshing/element_tree.h"
#include "mesh/scene/scene.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/open_parts.h"
#include "solver/linear/solve_result.h"
#include "solver/refinement/cluster_tree.h"

namespace bounce {

class Visibility;

struct HierarchicalOptions {
    double link_epsilon = 0.1;  // link when the error bound is below this share of what the link brings
    double link_floor = 1e-3;   // ... plus this share of the scene's mean radiosity (faint links stay coarse)
    /// Refine links with the last solution's B, then solve; this many times (multigridding,
    /// Hanrahan et al. 1991 section 5: later rounds keep the links' form factors). One round
    /// refines on emission plus the ambient term (Cohen et al. 1988), whose estimate of the
    /// indirect light is close enough that further rounds rarely move a link (the study is in
    /// docs/measurements/2026-12-03-defaults.md).
    int refine_rounds = 1;
    double min_area = 0.0;           // never split an element smaller than this (0: from level_base)
    double level_base = 1.0 / 2000;  // min_area 0: max(patch area, this share of the scene's) / 4^max_level
    int max_level = 4;               // quadtree depth under each patch, or under the base where that is larger
    bool clustering = true;          // start from the root cluster's self-link, not from every pair of patches
    double cluster_floor = 0.1;      // a cluster link's error floor, a share of the scene's mean radiosity
    /// BF refinement on power (Hanrahan et al. 1991, section 4): a link is also accepted when
    /// the power it could misplace, its radiosity error bound times the receiver's area, is
    /// below this share of the scene's power (sum B A), both ways round; 0: off. Small
    /// elements and faint corners stop refining whatever their relative error.
    double power_epsilon = 0.0;
    /// A pair of elements that would be linked but whose refinement rays partly arrive (a
    /// shadow's edge crosses it) adds all the link brings, F B, to its error, so it is refined
    /// unless faint or at the depth limit; one visible fraction per link blurs penumbrae.
    bool refine_partial_visibility = true;
    bool cluster_visibility = true;  // cluster links: visible fraction of rays between member centroids
    bool oriented_clusters = true;   // a cluster sends and receives per axis direction, not alike to all members
    /// Relative error of a link's unoccluded form factor (it overrides a tighter
    /// FormFactorOptions::unoccluded_tolerance in form_factors): a link hands its receiver a mean
    /// within link_epsilon (a tenth) of the point values, so a tighter form factor buys nothing
    /// the link can keep, and costs quadrature.
    double link_factor_tolerance = 1e-3;
    /// Elements emit and receive over their open parts (element_open_shares.h): no light is
    /// lost where patches lie under or inside other objects.
    bool open_parts = true;
    std::span<const CoveredRegion> covered;  // the regions the cuts left out (Scene::covered), for open_parts
    /// A link's ends send and take by where they see each other (seen_ends.h): an end's nodes
    /// two levels down by their factor to the other end, or a partly visible link's leaves by
    /// its rays, instead of the end's mean over all of it. Light then no longer runs down a
    /// gradient faster than it should (a coarse element's bright side is farther from what
    /// lies beyond its dark side), which in a corridor lit from one end compounds over every
    /// bounce.
    bool weighted_ends = true;
    double tolerance = 1e-6;  // stop when no element's radiosity changes by more than this, relatively
    std::size_t max_iterations = 1000;
    FormFactorOptions form_factors;
    const std::atomic<bool>* cancel = nullptr;
    /// Called with a stage ("round 1/1: link form factors"), items done and their total;
    /// from worker threads too.
    std::function<void(const std::string& stage, std::size_t done, std::size_t total)> progress;
};

/// The power epsilon `--adaptive` refines with ("model no more than the scene needs"): links
/// that could misplace less than this share of the scene's power stay coarse. A share, so it
/// does not depend on the scene's units; its error and time against the other settings are in
/// docs/guide/choosing-settings.md.
inline constexpr double kAdaptivePowerEpsilon = 1e-5;

/// The power epsilon an adaptive solve refines with: the one given when above 0, else
/// kAdaptivePowerEpsilon (the command line's --adaptive and the Python module's adaptive=True).
inline double adaptive_power_epsilon(double given) { return given > 0 ? given : kAdaptivePowerEpsilon; }

/// One interaction of the hierarchy: a gathers from b and b from a. Either end is an element
/// node of the tree or a cluster (a ClusterTree ref, ClusterTree::is_cluster).
struct HierarchicalLink {
    std::uint32_t a, b;
    float fab = 0.0f;  // F_ab; F_ba = F_ab A_a / A_b (a cluster's A: its members' total area)
    /// The share of the refinement's rays between the two that arrived (refine_partial_visibility
    /// traces them before linking a pair that could still be split), which fab then uses; 1,
    /// from no rays, where the shaft test (the pair's or an ancestor pair's) proved it open; -1
    /// where neither was made and fab has its own.
    float visible = -1.0f;
    /// The shaft test of the pair (ShaftCuller::unblocked over the input patches, made by
    /// refinement on scenes of few planes): not made, passed by the pair or an ancestor pair
    /// (every segment between the ends is open: visible is 1, from no rays), or made and failed.
    static constexpr std::uint8_t kShaftUntested = 0, kShaftOpen = 1, kShaftCrossed = 2;
    std::uint8_t shaft = kShaftUntested;
    /// Both ends are elements (no cluster): the link has polygons to integrate over.
    bool between_elements() const { return !ClusterTree::is_cluster(a) && !ClusterTree::is_cluster(b); }
};

struct HierarchicalSolution {
    ElementTree tree;
    std::vector<std::uint32_t> leaves;    // the elements of the result
    SolveResult result;                   // per leaf
    std::size_t cluster_links = 0;        // links with a cluster at one end or both
    std::size_t clusters = 0;             // clusters above the patches (0 without clustering)
    std::size_t initial_links = 0;        // pairs refinement starts from: 1, or N (N - 1) / 2 without clustering
    double refine_seconds = 0.0;          // building the links (form factors included), all rounds
    std::size_t reused_links = 0;         // links whose form factor an earlier round had computed
    std::vector<HierarchicalLink> links;  // the last round's, element and cluster links, with their factors
    std::vector<Rgb> node_radiosity;      // B of every tree node (a parent: its children's mean over open area)
    /// Per leaf: the irradiance that came over links with a cluster end (directly or pushed down
    /// from an ancestor); the rest came over element links, which a final gather can redo with
    /// the exact point kernel (solver/gather/hierarchical_point_values.h).
    std::vector<Rgb> cluster_irradiance;
    /// Per node, the share of its area open to the scene (element_open_shares.h); empty: every
    /// node is open. node_radiosity and the leaves' radiosity and irradiance are the open
    /// parts'.
    std::vector<double> open_share;
    /// The share of node i's area that receives: its open share, or the whole node where none
    /// is open (or none is known: nodes display refinement added).
    double receiving_share(std::size_t i) const { return bounce::receiving_share(sending_share(i)); }
    /// The share that sends: its open share (1 where none is known).
    double sending_share(std::size_t i) const { return i < open_share.size() ? open_share[i] : 1.0; }
    /// The refinement's power epsilon. Above 0, links were also accepted because the power
    /// they could misplace is small, so a leaf may hold the mean its coarse ancestor's links
    /// hand all of it; the point gather then re-gathers the leaves first
    /// (solver/gather/hierarchical_point_values.h).
    double power_epsilon = 0.0;
    /// The last round's links sent and took by their ends' weighted nodes (seen_ends.h): on,
    /// within kWeightedEndsMaxLinks, and some end had a list.
    bool weighted_ends = false;
};

/// Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991) with BF refinement. Each pair
/// of patches that face each other is refined recursively: a link hands every point of an
/// element the mean F to the other, so it errs by up to the spread of the unoccluded
/// point-to-polygon factor over the element (sampled at centre, corners and the point nearest
/// the other) times the other's radiosity. When that is below `link_epsilon` of what the link
/// brings (F B) plus `link_floor` of the scene's mean radiosity, both ways round, or neither
/// may be split, they are linked and the link's form factor is computed with
/// visibility (RaycastFormFactor, both directions from one integral); otherwise the larger of
/// the two is split into its quadtree children. With `refine_partial_visibility` a pair so
/// accepted whose few rays partly arrive is judged again with all it brings, F B, added to
/// its error (a shadow's edge crosses it), and split unless still within the bounds. The
/// first refinement uses emission plus an ambient estimate for B, later rounds the last
/// solution's B. The solution iterates gather (every element collects F B over its links)
/// and push-pull (irradiance pushed down to the leaves, radiosity pulled up as area-weighted
/// means) until it settles. The link count grows like N, not N^2.
///
/// With `clustering` (Smits, Arvo and Greenberg 1994; Sillion 1995) the patches are the
/// leaves of a binary cluster hierarchy (cluster_tree.h) and refinement starts from the root
/// cluster linked with itself, so no step looks at every pair of patches. A self-link is
/// always refined into its children's pairs. A link with a cluster at either end carries the
/// isotropic point-to-point transfer between the two ends' centres, A_a F_ab = P_a P_b / (pi
/// r^2) times the visible fraction of a few rays, where P is the area an end shows towards
/// the other (cluster_tree.h bounds it); it is accepted when its worst-case error at any
/// point, B_b A_b / (pi r_min^2) with r_min the gap between the bounding spheres (every member
/// facing every other, Sillion 1995), is below `link_epsilon` of what it brings plus
/// `cluster_floor` of the scene's mean radiosity, both ways round; else the larger cluster is
/// split into its two children (an element waits for the cluster: two patches always meet as
/// a pair, which the element oracle refines as above). A
/// cluster's radiosity is its members' area-weighted mean (the power they emit over their
/// area) and the irradiance it gathers reaches every member alike, so power is kept.
///
/// With `open_parts` every leaf is tested as open_parts.h tests a patch (element_open_shares.h),
/// and the solve works on open parts: an element's radiosity is its open part's, what it
/// gathers lands on its open part, and a parent or cluster sends its members' mean weighted by
/// their open areas, so an element partly under or inside another object loses nothing of
/// what its open part sends. The energy account splits what a leaf's links do not carry
/// between back sides (absorbed) and openings (escaped) as its rays saw them.
HierarchicalSolution solve_hierarchical(const std::vector<Patch>& patches, const Visibility& visibility,
                                        const HierarchicalOptions& options);

/// What a written solution records of a hierarchical solve (the .vtu's settings, from the
/// command line and the Python module alike): " solver=hierarchical link_epsilon=... links=...".
std::string hierarchical_settings(const HierarchicalOptions& options, const HierarchicalSolution& solution);

}  // namespace bounce
