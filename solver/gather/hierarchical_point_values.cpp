// SPDX-License-Identifier: MIT
#include "solver/gather/hierarchical_point_values.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <unordered_map>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "solver/gather/patch_display_refinement.h"
#include "solver/gather/point_values_by_position.h"
#include "solver/visibility/shaft_culler.h"

namespace bounce {
namespace {

/// The element links of every node (compressed rows): links between elements, whose polygons
/// the gather integrates over, also those whose few refinement rays were all blocked. A point
/// traces its own rays: at a shadow's edge it sees part of a source its element's rays missed
/// (on the Cornell box's red wall, by the tall block, the probes were up to 6% dark).
struct NodeLinks {
    std::vector<std::size_t> first;    // per node, and one past the last
    std::vector<std::uint32_t> other;  // the link's other end
    std::vector<std::uint32_t> link;   // the link's index in solution.links
};

NodeLinks node_links(const HierarchicalSolution& sol) {
    const std::size_t n = sol.tree.size();
    NodeLinks out;
    out.first.assign(n + 1, 0);
    for (const auto& l : sol.links)
        if (l.between_elements()) {
            ++out.first[l.a + 1];
            ++out.first[l.b + 1];
        }
    for (std::size_t i = 0; i < n; ++i) out.first[i + 1] += out.first[i];
    out.other.resize(out.first[n]);
    out.link.resize(out.first[n]);
    std::vector<std::size_t> fill(out.first.begin(), out.first.end() - 1);
    for (std::size_t k = 0; k < sol.links.size(); ++k) {
        const auto& l = sol.links[k];
        if (!l.between_elements()) continue;
        out.link[fill[l.a]] = std::uint32_t(k);
        out.other[fill[l.a]++] = l.b;
        out.link[fill[l.b]] = std::uint32_t(k);
        out.other[fill[l.b]++] = l.a;
    }
    return out;
}

/// Per node, the number of links along its path to the root: the length of a point's source
/// list there (parents come before their children in the node order).
std::vector<std::size_t> path_link_counts(const HierarchicalSolution& sol, const NodeLinks& links) {
    std::vector<std::size_t> out(sol.tree.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const std::int64_t parent = sol.tree.node(i).parent;
        out[i] = links.first[i + 1] - links.first[i] + (parent >= 0 ? out[std::size_t(parent)] : 0);
    }
    return out;
}

/// Each vertex's list: the leaf node of the element its gather point lies in (GatherPoint::cell;
/// the points are moved off the vertices, towards the centres around them). A source's mark
/// (LinkSources) holds for the points of the list's element only: a point in a neighbour across
/// a seam, where a wall may stand on the floor, could see less of the source.
std::vector<std::uint32_t> vertex_lists(const HierarchicalSolution& sol, std::span<const GatherPoint> points) {
    std::vector<std::uint32_t> out;
    out.reserve(points.size());
    for (const GatherPoint& x : points) out.push_back(sol.leaves[std::size_t(std::max(x.cell, 0))]);
    return out;
}

/// What both the gather and its cost estimate start from: the links per node, the vertices'
/// gather points and lists, and the gather points x sources it would meet (every vertex's
/// list, and with a power epsilon every leaf's centre too, gathered first).
struct GatherPlan {
    NodeLinks links;
    std::vector<GatherPoint> vertex_points;
    std::vector<std::uint32_t> vertex_list;  // per vertex: a leaf node
    double pairs = 0.0;
};

GatherPlan gather_plan(const HierarchicalSolution& sol, const PatchMesh& elements) {
    if (elements.size() != sol.leaves.size())
        throw std::invalid_argument("hierarchical gather: the elements are not the solution's leaves");
    GatherPlan plan{node_links(sol), vertex_gather_points(elements), {}, 0.0};
    plan.vertex_list = vertex_lists(sol, plan.vertex_points);
    const std::vector<std::size_t> counts = path_link_counts(sol, plan.links);  // per node
    for (const std::uint32_t leaf : plan.vertex_list) plan.pairs += double(counts[leaf]);
    if (sol.power_epsilon > 0)
        for (const std::uint32_t leaf : sol.leaves) plan.pairs += double(counts[leaf]);
    return plan;
}

/// The gather's sources: every node's row of element links (NodeLinks), chained to its
/// parent's (GatherSources::list_parent), so a point on a leaf gathers over the links of the
/// leaf and of every ancestor without a list stored per leaf; each entry with its mark: a shaft
/// test over the input patches (the scene's blockers) found nothing between the two ends of
/// the link, so every point of the node sees all of the source and its rays can be skipped.
/// Refinement makes the marks (a pair inherits its ancestors' proof), so most are free here.
struct LinkSources {
    std::vector<std::uint8_t> unblocked;  // per entry of NodeLinks::other
    std::vector<std::int64_t> parent;     // per node
    std::vector<Rgb> irradiance;          // per node: a leaf's cluster irradiance, 0 elsewhere
    /// The sources of points on `list`'s nodes (leaves), from `links`.
    GatherSources on(std::span<const std::uint32_t> list, const NodeLinks& links) const {
        GatherSources at{list, links.first, links.other, irradiance};
        at.unblocked = unblocked;
        at.list_parent = parent;
        return at;
    }
};

/// A shaft test that proves a link unblocked spares every gather point under either end the
/// rays to the other (GatherOptions: ceil(64 F), 1 to 16, 16 to an emitter). Refinement has
/// tested the links of scenes of few planes (HierarchicalLink::shaft: on the Cornell box every
/// pair it split or linked, so a pair inherits its ancestors' proof); an untested link is
/// tested here when those rays outweigh the scene's plane groups (ShaftCuller::kPlaneTestsPerRay).
/// The 10k office has 3585 groups, where testing every link cost 24 s more than it spared (its
/// hierarchical solve at 3e-6: 58 s -> 80 s), and the rule takes it to 55 s.
/// With `occluders` (mirrors and glass, which are no patches) no shaft over the patches is
/// proof, and links are not tested.
LinkSources link_sources(const HierarchicalSolution& sol, const NodeLinks& links, const std::atomic<bool>* cancel,
                         bool occluders) {
    const ElementTree& tree = sol.tree;
    const auto& G = tree.geometry();
    std::vector<std::uint32_t> leaves_under(tree.size(), 0);
    for (const std::uint32_t leaf : sol.leaves)
        for (std::int64_t a = leaf; a >= 0; a = tree.node(std::size_t(a)).parent) ++leaves_under[std::size_t(a)];
    const GatherOptions options = point_value_options();
    // Rays only go from a point that reflects to a source that sends something.
    const auto rays_to = [&](std::uint32_t receiver, std::uint32_t source, double factor) {
        if (G[receiver].reflectance.max() <= 0 || sol.node_radiosity[source].max() <= 0) return 0.0;
        if (G[source].emission.max() > 0) return double(options.emitter_rays);
        return std::clamp(std::ceil(factor * options.rays_per_unit_factor), 1.0, double(options.max_rays));
    };
    const ShaftCuller culler(tree.roots());
    const double planes = double(culler.plane_groups());
    std::vector<std::uint8_t> link_unblocked(sol.links.size(), 0);
    tbb::parallel_for(std::size_t(0), sol.links.size(), [&](std::size_t k) {
        const auto& l = sol.links[k];
        // Refinement's test stands (a culler over the same patches); links whose rays were all
        // blocked are not tested: their shaft holds a blocker.
        if (l.shaft == HierarchicalLink::kShaftOpen) link_unblocked[k] = 1;
        if (!l.between_elements() || l.shaft != HierarchicalLink::kShaftUntested || l.visible == 0.0f ||
            (cancel && cancel->load(std::memory_order_relaxed)))
            return;
        const double fba = double(l.fab) * G[l.a].area / G[l.b].area;
        const double spared = leaves_under[l.a] * rays_to(l.a, l.b, l.fab) + leaves_under[l.b] * rays_to(l.b, l.a, fba);
        if (!occluders && spared * ShaftCuller::kPlaneTestsPerRay >= planes)
            link_unblocked[k] = culler.unblocked(G[l.a], G[l.b]);
    });
    LinkSources out;
    out.unblocked.resize(links.link.size());
    for (std::size_t e = 0; e < links.link.size(); ++e) out.unblocked[e] = link_unblocked[links.link[e]];
    out.parent.resize(tree.size());
    for (std::size_t i = 0; i < tree.size(); ++i) out.parent[i] = tree.node(i).parent;
    out.irradiance.resize(tree.size());
    if (sol.cluster_irradiance.size() == sol.leaves.size())  // (empty: none came over cluster links)
        for (std::size_t k = 0; k < sol.leaves.size(); ++k) out.irradiance[sol.leaves[k]] = sol.cluster_irradiance[k];
    return out;
}

/// GatherSources::descend for the vertices and the leaves' centres: a point goes down from a
/// linked source to its children where their spread, times the kernel's variation over the
/// source (r / d), passes this share of what the source brings. A source's mean misplaces its
/// light by how its radiosity and the point's kernel vary together over it (the link's own
/// excess, seen_ends.h); in the corridor lit from one end it compounds down the gradient, and
/// the centres, which the vertices gather from, carry it on
/// (docs/measurements/2026-12-07-weighted-ends.md#the-gathers-descent).
constexpr double kDescendShare = 0.03;

/// The descent arrays of a gather (GatherSources::descend) for the tree as it is.
void set_descent(const ElementTree& tree, std::span<const Rgb> radiosity, std::vector<std::int32_t>& first_child,
                 std::vector<double>& spread, GatherSources& at) {
    first_child.resize(tree.size());
    for (std::size_t i = 0; i < first_child.size(); ++i) first_child[i] = tree.node(i).first_child;
    spread = tree.leaf_luminance_spread(radiosity);
    at.first_child = first_child;
    at.spread = spread;
    at.descend = kDescendShare;
}

/// Every leaf's value gathered at its centre through its own links (the leaf's row, chained to
/// its ancestors', LinkSources::on) from `radiosity` per node (empty: the solution's): mode
/// "centres", and each step of the re-gather below.
std::vector<Rgb> centre_values(const HierarchicalSolution& sol, const PatchMesh& elements, const NodeLinks& links,
                               const LinkSources& sources, const Visibility& visibility, const GatherOptions& options,
                               const std::atomic<bool>* cancel,
                               const std::function<void(std::size_t, std::size_t)>& progress,
                               std::span<const Rgb> radiosity = {}) {
    // A centre gathers through its own element (the elements are the leaves, in order).
    const std::span<const Rgb> B = radiosity.empty() ? std::span<const Rgb>(sol.node_radiosity) : radiosity;
    GatherSources at = sources.on(sol.leaves, links);
    std::vector<std::int32_t> first_child;
    std::vector<double> spread;
    set_descent(sol.tree, B, first_child, spread, at);
    return final_gather(sol.tree.geometry(), B, visibility, centre_gather_points(elements.patches()), at, options,
                        cancel, progress);
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
        // The open parts' mean, as the solve's (hierarchical_iteration.h).
        const bool open = sol.sending_share(i) > 0.0;
        Rgb sum;
        for (int c = 0; c < 4; ++c) {
            const auto child = std::size_t(node.first_child + c);
            sum += B[child] * (nodes[child].area * (open ? sol.sending_share(child) : 1.0));
        }
        B[i] = sum * (1.0 / (nodes[i].area * sol.receiving_share(i)));
    }
    return B;
}

/// The leaves' cell values from their re-gathered centre values: per input patch and channel,
/// the reflected part (B - E) of each leaf's centre value is scaled so that the patch keeps the
/// reflected power the solve gave it, and E stays exact, so the energy account stays the
/// solve's and B = E + rho H holds per cell. Links accepted for their small power hand every
/// leaf of a coarse element the element's mean, which the solve's leaf values keep; the
/// centres give each leaf its own share
/// (docs/measurements/2026-12-06-far-leg-and-wedges.md#cells-from-the-centres). Where the
/// centres' reflected power is not within a factor kCellScaleRange of the solve's, the two
/// disagree about the whole patch (a few lit centres would take all of its power): the solve's
/// values stand there.
void cells_from_centres(const HierarchicalSolution& sol, const std::vector<Rgb>& centres, SolveResult& res) {
    static constexpr double kCellScaleRange = 10.0;
    const ElementTree& tree = sol.tree;
    const auto& nodes = tree.geometry();
    const std::size_t n = sol.leaves.size();
    if (centres.size() != n || res.radiosity.size() != n) return;
    std::vector<Rgb> solve_power(tree.root_count()), gathered_power(tree.root_count());  // reflected, per root
    for (std::size_t k = 0; k < n; ++k) {
        const Patch& p = nodes[sol.leaves[k]];
        const std::uint32_t r = tree.node(sol.leaves[k]).root;
        const double area = p.area * sol.sending_share(sol.leaves[k]);  // what sends
        solve_power[r] += (res.radiosity[k] - p.emission) * area;
        gathered_power[r] += (centres[k] - p.emission) * area;
    }
    for (std::size_t k = 0; k < n; ++k) {
        const Patch& p = nodes[sol.leaves[k]];
        const std::uint32_t r = tree.node(sol.leaves[k]).root;
        for (int c = 0; c < 3; ++c) {
            const double solved = solve_power[r][c], gathered = gathered_power[r][c];
            if (!(solved > 0 && gathered > 0)) continue;
            const double scale = solved / gathered;
            if (scale > kCellScaleRange || scale < 1.0 / kCellScaleRange) continue;
            const double reflected = (centres[k][c] - p.emission[c]) * scale;
            res.radiosity[k][c] = p.emission[c] + reflected;
            if (res.irradiance.size() == n && p.reflectance[c] > 0) res.irradiance[k][c] = reflected / p.reflectance[c];
        }
    }
}

/// Jacobi steps of the re-gather (kRegatherSteps): the leaves' centre values after the last,
/// and the node radiosity made of them (regathered_radiosity). Empty when cancelled.
struct Regathered {
    std::vector<Rgb> centres, radiosity;
};
Regathered regather_leaves(const HierarchicalSolution& solution, const PatchMesh& elements, const NodeLinks& links,
                           const LinkSources& sources, const Visibility& visibility, const GatherOptions& options,
                           int steps, const std::atomic<bool>* cancel,
                           const std::function<void(const char*, std::size_t, std::size_t)>& progress) {
    Regathered out;
    for (int step = 0; step < steps; ++step) {
        out.centres = centre_values(
            solution, elements, links, sources, visibility, options, cancel,
            [&progress](std::size_t d, std::size_t t) {
                if (progress) progress("gathering: element centres", d, t);
            },
            out.radiosity);
        if (cancel && cancel->load()) return {};
        out.radiosity = regathered_radiosity(solution, out.centres);
    }
    return out;
}

/// Everything the vertex stage gathers through, kept so display refinement can gather more
/// points the same way: the per-node rows (extended by empty rows for display leaves), their
/// marks and parents, and the radiosity the vertices gather from.
struct VertexStage {
    NodeLinks& links;
    LinkSources& sources;
    std::vector<Rgb>& radiosity;  // per node
};

/// Per element, an estimate of what linear interpolation between its vertices misses at its
/// centre: the centre values (one per element, all of one Jacobi stage) of the elements that
/// share a vertex with it are fitted by a plane in its tangent coordinates (least squares), and
/// the element's own value's distance from the fit at its centre, a second difference, is about
/// four times that error (for f = x^2 on a grid of spacing h the fit misses by h^2, the
/// interpolation by h^2 / 4). A smooth difference between the centre values' stage and the
/// vertices' cancels in the fit. 0 where fewer than three neighbours span the plane.
std::vector<double> interpolation_error(const PatchMesh& elements, std::span<const Rgb> centre_values) {
    const auto& patches = elements.patches();
    const auto& mesh = elements.mesh();
    std::vector<double> out(patches.size(), 0.0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, patches.size(), 256), [&](const auto& range) {
        std::vector<int> around;
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            const Patch& p = patches[k];
            around.clear();
            for (const auto v : mesh.fv_range(mesh.face_handle(int(k))))
                for (const auto f : mesh.vf_range(v))
                    if (f.idx() != int(k) && std::find(around.begin(), around.end(), f.idx()) == around.end())
                        around.push_back(f.idx());
            if (around.size() < 3) continue;
            const glm::dvec3 seed = std::abs(p.normal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
            const glm::dvec3 t1 = glm::normalize(seed - glm::dot(seed, p.normal) * p.normal);
            const glm::dvec3 t2 = glm::cross(p.normal, t1);
            // Normal equations of f ~ a + b u + c v, (u, v) about this element's centre.
            glm::dmat3 m(0.0);
            glm::dvec3 rhs(0.0);
            for (const int j : around) {
                const glm::dvec3 d = patches[std::size_t(j)].centre - p.centre;
                const glm::dvec3 row(1.0, glm::dot(d, t1), glm::dot(d, t2));
                m += glm::outerProduct(row, row);
                rhs += row * centre_values[std::size_t(j)].luminance();
            }
            const double det = glm::determinant(m);
            // Collinear neighbours leave the plane undetermined (det ~ 0 against the scale of u, v).
            const double scale = m[1][1] + m[2][2];
            if (!(std::abs(det) > 1e-9 * m[0][0] * scale * scale)) continue;
            const double fitted = (glm::inverse(m) * rhs)[0];
            out[k] = 0.25 * std::abs(centre_values[k].luminance() - fitted);
        }
    });
    return out;
}

/// Display refinement (DisplayRefinement): splits, for display only, each leaf whose
/// interpolation_error passes the tolerance's share of its centre value, and gathers the
/// vertices that adds. (The centre value against the mean of the leaf's own vertices, a Jacobi
/// step ahead of it, flagged more leaves for less: on the box at 1e-6, that test at tolerance
/// 0.01 split 2,006 leaves, 5.2k new vertices, for 0.39%, the fit at 0.0025 2,269 leaves, 5.7k
/// vertices, for 0.35%; at the same 0.0025 the old test split 5,947.) A split leaf's children
/// carry its radiosity (cell data) and cluster irradiance and gather through its links (their
/// rows are empty and chained to it); only the point data gains. Returns the number of leaves
/// split. `budget` is what the passes may still gather, in vertex-link pairs: a pass that would
/// pass it splits the leaves that miss most first and spends the rest.
std::size_t split_for_display(HierarchicalSolution& sol, PatchMesh& elements, std::span<const GatherPoint> old_points,
                              SolveResult& res, VertexStage stage, std::vector<double> miss, double& budget,
                              const Visibility& visibility, const GatherOptions& options,
                              const std::atomic<bool>* cancel,
                              const std::function<void(std::size_t, std::size_t)>& progress);

std::size_t refine_display(HierarchicalSolution& sol, PatchMesh& elements, std::span<const GatherPoint> old_points,
                           SolveResult& res, VertexStage stage, std::span<const Rgb> centre_values, double& budget,
                           const Visibility& visibility, const GatherOptions& options, const DisplayRefinement& display,
                           const std::atomic<bool>* cancel,
                           const std::function<void(std::size_t, std::size_t)>& progress) {
    const std::size_t leaves = sol.leaves.size();
    if (res.radiosity.size() != leaves)
        throw std::invalid_argument("display refinement: the result must hold one radiosity per leaf");
    const std::vector<double> error = interpolation_error(elements, centre_values);
    // Per leaf past the tolerance, its miss as a share of its value, or of dark_floor where
    // it is darker (so a budget goes to visible misses before the umbra's noise); 0 within it.
    const double floor = dark_floor(elements.patches(), {centre_values.begin(), centre_values.end()});
    std::vector<double> miss(leaves, 0.0);
    for (std::size_t k = 0; k < leaves; ++k) {
        const double value = centre_values[k].luminance();
        if (error[k] > display.tolerance * value) miss[k] = error[k] / std::max({value, floor, 1e-300});
    }
    return split_for_display(sol, elements, old_points, res, stage, std::move(miss), budget, visibility, options,
                             cancel, progress);
}

/// Per leaf, how far its gathered corners differ where that is more than the patch solvers'
/// corner spread of the brightest (or of dark_floor, where all are darker), else 0: a step in
/// the light, such as the hard shadow line at a contact, where the penumbra narrows to nothing.
std::vector<double> corner_steps(const PatchMesh& elements, std::span<const Rgb> point_radiosity,
                                 const std::vector<Rgb>& radiosity) {
    const double spread = PatchDisplayRefinement{}.corner_spread;
    const double floor = dark_floor(elements.patches(), radiosity);
    std::vector<double> out(elements.size(), 0.0);
    for (std::size_t k = 0; k < elements.size(); ++k) {
        double lo = 1e300, hi = 0.0;
        for (const int v : elements.patch_vertex_indices(k)) {
            const double b = point_radiosity[std::size_t(v)].luminance();
            lo = std::min(lo, b);
            hi = std::max(hi, b);
        }
        const double step = (hi - lo) / std::max(hi, floor);
        if (step > spread) out[k] = step;
    }
    return out;
}

/// res.point_radiosity for the vertices of `next` (the conforming mesh of sol.leaves): those
/// in `old_values` keep them, the rest are gathered through their leaves' links.
void gather_vertices_anew(const HierarchicalSolution& sol, const PatchMesh& next, const PointValues& old_values,
                          SolveResult& res, VertexStage stage, const Visibility& visibility,
                          const GatherOptions& options, const std::atomic<bool>* cancel,
                          const std::function<void(std::size_t, std::size_t)>& progress) {
    const std::vector<GatherPoint> points = vertex_gather_points(next);
    std::vector<Rgb> values(points.size());
    std::vector<GatherPoint> todo;
    std::vector<std::size_t> todo_vertex;
    for (std::size_t v = 0; v < points.size(); ++v) {
        // An old vertex keeps its value, gathered a tenth of the way towards the centres of
        // the cells around it then. Beside a split leaf those are nearer now; gathering such
        // vertices again, where they now lie, cost a fifth more of display refinement's time
        // for no better point data on the Cornell box.
        if (const Rgb* known = old_values.find(points[v].surface, next.vertex_position(v))) {
            values[v] = *known;
            continue;
        }
        todo.push_back(points[v]);
        todo_vertex.push_back(v);
    }
    const std::vector<std::uint32_t> list = vertex_lists(sol, todo);
    GatherSources at = stage.sources.on(list, stage.links);
    std::vector<std::int32_t> first_child;
    std::vector<double> spread;
    set_descent(sol.tree, stage.radiosity, first_child, spread, at);
    const std::vector<Rgb> gathered =
        final_gather(sol.tree.geometry(), stage.radiosity, visibility, todo, at, options, cancel, progress);
    for (std::size_t q = 0; q < todo.size(); ++q) values[todo_vertex[q]] = gathered[q];
    res.point_radiosity = std::move(values);
}

/// Splits for display the leaves with a positive `miss`, the largest first while `budget`
/// lasts, and gathers the vertices that adds (as refine_display).
std::size_t split_for_display(HierarchicalSolution& sol, PatchMesh& elements, std::span<const GatherPoint> old_points,
                              SolveResult& res, VertexStage stage, std::vector<double> miss, double& budget,
                              const Visibility& visibility, const GatherOptions& options,
                              const std::atomic<bool>* cancel,
                              const std::function<void(std::size_t, std::size_t)>& progress) {
    ElementTree& tree = sol.tree;
    const std::size_t leaves = sol.leaves.size();
    if (!(budget > 0)) return 0;  // spent by an earlier pass
    std::vector<std::uint8_t> split(leaves, 0);
    {
        // Each split leaf adds at most five vertices (its edges' midpoints and its centre),
        // each gathering over the leaf's path of links; the leaves that miss most go first.
        const std::vector<std::size_t> path = path_link_counts(sol, stage.links);
        std::vector<std::size_t> order;
        for (std::size_t k = 0; k < leaves; ++k)
            if (miss[k] > 0) order.push_back(k);
        std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return miss[a] > miss[b]; });
        for (const std::size_t k : order) {
            const double pairs = 5.0 * double(path[sol.leaves[k]]);
            if (pairs > budget) {
                budget = 0.0;  // the rest waits for no later pass
                break;
            }
            budget -= pairs;
            split[k] = 1;
        }
    }
    const std::size_t count = std::size_t(std::count(split.begin(), split.end(), std::uint8_t(1)));
    if (count == 0) return 0;
    // The old mesh's values by position (and surface, as the gather points have it), before
    // the tree changes.
    PointValues old_values(tree.weld());
    for (std::size_t v = 0; v < old_points.size(); ++v)
        old_values.add(old_points[v].surface, {elements.vertex_position(v), res.point_radiosity[v]});
    // Split, children in their parent's place: per-leaf arrays follow.
    std::vector<std::uint32_t> new_leaves;
    std::vector<std::size_t> from;  // per new leaf: the old leaf it lies in
    new_leaves.reserve(leaves + 3 * count);
    from.reserve(leaves + 3 * count);
    for (std::size_t k = 0; k < leaves; ++k) {
        const std::uint32_t leaf = sol.leaves[k];
        if (!split[k]) {
            new_leaves.push_back(leaf);
            from.push_back(k);
            continue;
        }
        const std::size_t first = tree.split(leaf);
        const Rgb b = stage.radiosity[leaf], node_b = sol.node_radiosity[leaf], e = stage.sources.irradiance[leaf];
        const std::size_t row_end = stage.links.first.back();
        for (int c = 0; c < 4; ++c) {
            new_leaves.push_back(std::uint32_t(first + std::size_t(c)));
            from.push_back(k);
            stage.radiosity.push_back(b);
            sol.node_radiosity.push_back(node_b);
            if (!sol.open_share.empty()) sol.open_share.push_back(sol.open_share[leaf]);
            stage.links.first.push_back(row_end);  // no links of their own: they gather through the leaf's
            stage.sources.parent.push_back(std::int64_t(leaf));
            stage.sources.irradiance.push_back(e);
        }
    }
    const auto spread_per_leaf = [&](std::vector<Rgb>& values) {
        if (values.size() != leaves) return;
        std::vector<Rgb> out(from.size());
        for (std::size_t k = 0; k < from.size(); ++k) out[k] = values[from[k]];
        values = std::move(out);
    };
    const auto spread_result = [&](SolveResult& r) {
        spread_per_leaf(r.radiosity);
        spread_per_leaf(r.irradiance);
        spread_per_leaf(r.unshot);
        spread_per_leaf(r.display);
    };
    spread_result(res);
    if (&res != &sol.result) spread_result(sol.result);
    spread_per_leaf(sol.cluster_irradiance);
    sol.leaves = std::move(new_leaves);
    // The new mesh: its vertices found in the old keep their values, the rest are gathered.
    PatchMesh next = tree.conforming_mesh(sol.leaves);
    gather_vertices_anew(sol, next, old_values, res, stage, visibility, options, cancel, progress);
    next.set_specular_faces(elements.specular_faces());  // mirrors and glass stay in the export
    elements = std::move(next);
    return count;
}

}  // namespace

double hierarchical_gather_pairs(const HierarchicalSolution& solution, const PatchMesh& elements) {
    return gather_plan(solution, elements).pairs;
}

namespace {

/// Both gather_hierarchical_point_values: `refine` (with its solution and elements, the same
/// objects as `solution` and `elements`) when display refinement may change them.
struct DisplayTarget {
    HierarchicalSolution* solution;
    PatchMesh* elements;
    DisplayRefinement options;
};

GatherOutcome gather_through_links(const HierarchicalSolution& solution, const PatchMesh& elements,
                                   const Visibility& visibility, SolveResult& res, const std::string& mode,
                                   const DisplayTarget* refine, const std::atomic<bool>* cancel,
                                   const std::function<void(const char*, std::size_t, std::size_t)>& progress,
                                   int regather_steps) {
    check_gather_mode(mode);
    if (mode == "none") return GatherOutcome::not_asked;
    GatherPlan plan = gather_plan(solution, elements);
    if (plan.pairs > kMaxGatherPairs) return GatherOutcome::over_budget;
    LinkSources sources = link_sources(solution, plan.links, cancel, visibility.has_occluders());
    if (cancel && cancel->load()) return GatherOutcome::interrupted;
    const GatherOptions options = point_value_options();
    std::vector<Rgb> centres;  // with a power epsilon: the leaves re-gathered first
    return run_point_gather(
        mode, res, cancel, progress,
        [&](const auto& report) {
            GatherSources at = sources.on(plan.vertex_list, plan.links);
            std::vector<Rgb> regathered;
            if (solution.power_epsilon > 0) {
                Regathered r = regather_leaves(solution, elements, plan.links, sources, visibility, options,
                                               regather_steps, cancel, progress);
                if (cancel && cancel->load()) return;
                centres = std::move(r.centres);
                regathered = std::move(r.radiosity);
            }
            const std::vector<Rgb>& B = regathered.empty() ? solution.node_radiosity : regathered;
            std::vector<std::int32_t> first_child;
            std::vector<double> spread;
            set_descent(solution.tree, B, first_child, spread, at);
            res.point_radiosity =
                final_gather(solution.tree.geometry(), B, visibility, plan.vertex_points, at, options, cancel, report);
            if (cancel && cancel->load()) return;
            cells_from_centres(solution, centres, res);  // before display refinement spreads the cells
            if (!refine || !(refine->options.tolerance > 0) || mode != "vertices" || (cancel && cancel->load())) return;
            // The centre values: re-gathered, or without a power epsilon the leaves' own.
            std::vector<Rgb> centre_of(solution.leaves.size());
            for (std::size_t k = 0; k < centre_of.size(); ++k)
                centre_of[k] = centres.empty() ? solution.node_radiosity[solution.leaves[k]] : centres[k];
            // B (regathered, or a copy of the solution's) grows with the display leaves.
            std::vector<Rgb> radiosity = regathered.empty() ? solution.node_radiosity : std::move(regathered);
            // `at` points into plan.links and sources, which refine_display grows: not used after.
            const auto report_display = [&progress](std::size_t d, std::size_t t) {
                if (progress) progress("gathering: display refinement", d, t);
            };
            std::size_t first_new = refine->solution->tree.size();
            PointValues original(refine->solution->tree.weld());
            for (std::size_t v = 0; v < plan.vertex_points.size(); ++v)
                original.add(plan.vertex_points[v].surface,
                             {refine->elements->vertex_position(v), res.point_radiosity[v]});
            // The passes share one budget, counted on the element links' ends.
            double budget = refine->options.max_pairs > 0 ? refine->options.max_pairs
                                                          : hierarchical_display_budget(plan.links.first.back());
            refine_display(*refine->solution, *refine->elements, plan.vertex_points, res,
                           {plan.links, sources, radiosity}, centre_of, budget, visibility, options, refine->options,
                           cancel, report_display);
            // Then the new leaves across a step are split again, as often as the patch solvers'
            // display cells are (PatchDisplayRefinement::step_depth), along such lines only.
            const int step_depth = PatchDisplayRefinement{}.step_depth;
            bool stepped = false;
            for (int step = 0; step < step_depth && !(cancel && cancel->load()); ++step) {
                std::vector<double> steps = corner_steps(*refine->elements, res.point_radiosity, res.radiosity);
                const std::vector<std::uint32_t>& leaves = refine->solution->leaves;
                for (std::size_t k = 0; k < steps.size(); ++k)
                    if (leaves[k] < first_new) steps[k] = 0.0;
                first_new = refine->solution->tree.size();
                if (split_for_display(*refine->solution, *refine->elements, vertex_gather_points(*refine->elements),
                                      res, {plan.links, sources, radiosity}, std::move(steps), budget, visibility,
                                      options, cancel, report_display) == 0)
                    break;
                stepped = true;
            }
            // The display vertices of the passes before the last moved their gather points as
            // the cells round them were split: gathered again where they now lie, every display
            // vertex holds the value at its own gather point.
            if (stepped && !(cancel && cancel->load()))
                gather_vertices_anew(*refine->solution, *refine->elements, original, res,
                                     {plan.links, sources, radiosity}, visibility, options, cancel, report_display);
        },
        [&](const auto& report) {
            // With a power epsilon the same gather is already done.
            if (centres.empty())
                centres = centre_values(solution, elements, plan.links, sources, visibility, options, cancel, report);
            res.gathered_centres = std::move(centres);
        });
}

}  // namespace

GatherOutcome gather_hierarchical_point_values(
    const HierarchicalSolution& solution, const PatchMesh& elements, const Visibility& visibility, SolveResult& res,
    const std::string& mode, const std::atomic<bool>* cancel,
    const std::function<void(const char*, std::size_t, std::size_t)>& progress, int regather_steps) {
    if (regather_steps < 1) throw std::invalid_argument("hierarchical gather: at least one re-gather step");
    return gather_through_links(solution, elements, visibility, res, mode, nullptr, cancel, progress, regather_steps);
}

GatherOutcome gather_hierarchical_point_values(
    HierarchicalSolution& solution, PatchMesh& elements, const Visibility& visibility, SolveResult& res,
    const std::string& mode, const DisplayRefinement& display, const std::atomic<bool>* cancel,
    const std::function<void(const char*, std::size_t, std::size_t)>& progress) {
    if (!(display.tolerance >= 0)) throw std::invalid_argument("display refinement: the tolerance must be 0 or more");
    const DisplayTarget target{&solution, &elements, display};
    return gather_through_links(solution, elements, visibility, res, mode, &target, cancel, progress, kRegatherSteps);
}

}  // namespace bounce
