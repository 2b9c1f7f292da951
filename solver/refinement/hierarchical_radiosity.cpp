// SPDX-License-Identifier: MIT
#include "solver/refinement/hierarchical_radiosity.h"

#include <algorithm>
#include <atomic>

#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/linear/convergence.h"
#include "solver/refinement/cluster_tree.h"
#include "solver/visibility/shaft_culler.h"
#include "solver/visibility/visibility.h"

namespace bounce {
namespace {

using Link = HierarchicalLink;

/// One end of a link with a cluster: what the isotropic transfer needs of it.
struct End {
    double area = 0.0;
    glm::dvec3 centre{0.0};
    double radius = 0.0;  // bounding sphere about centre
    const ClusterTree::Cluster* cluster = nullptr;
    const Patch* element = nullptr;
    std::uint32_t ref = 0;
    const ClusterTree* tree = nullptr;
    const std::vector<Patch>* patches = nullptr;  // the input patches (the clusters' members)
    /// The area the end shows towards unit d (its members facing d; ClusterTree::shown_area).
    double shown(const glm::dvec3& d) const {
        if (element) return element->area * std::max(0.0, glm::dot(element->normal, d));
        return tree->shown_area(ref, d, *patches);
    }
    /// True when no part of the end is strictly in front of element p's plane.
    bool behind(const Patch& p) const {
        if (element) return wholly_behind(p, *element);
        const double tol = 1e-12 * std::sqrt(p.area + area);
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 x((k & 1) ? cluster->hi.x : cluster->lo.x, (k & 2) ? cluster->hi.y : cluster->lo.y,
                               (k & 4) ? cluster->hi.z : cluster->lo.z);
            if (p.height(x) > tol) return false;
        }
        return true;
    }
};

End end_of(const ElementTree& tree, const ClusterTree& clusters, std::uint32_t ref) {
    End e;
    if (ClusterTree::is_cluster(ref)) {
        e.cluster = &clusters.cluster(ref);
        e.ref = ref;
        e.tree = &clusters;
        e.patches = &tree.roots();
        e.area = e.cluster->area;
        e.centre = e.cluster->centre;
        e.radius = e.cluster->radius;
    } else {
        e.element = &tree.geometry()[ref];
        e.area = e.element->area;
        e.centre = e.element->centre;
        e.radius = circumradius(*e.element);
    }
    return e;
}

/// A_a F_ab for a link with a cluster, unoccluded: both ends shrunk to points at their
/// centres, each showing the other the area its members turn towards it (Sillion 1995's
/// isotropic cluster with the members' orientation kept, as Smits et al. 1994 do), capped so
/// that neither F exceeds 1. Ends whose bounding spheres meet (faint links the power bound
/// accepts) have no point-to-point kernel: it is softened there as Wallace, Elmquist and
/// Haines (1989) soften the point-to-disc factor, pi r^2 + A for pi r^2, so they do not send
/// each other all they have (with the cap alone the 100k office's gather did not settle).
double cluster_transfer(const End& a, const End& b) {
    const glm::dvec3 v = b.centre - a.centre;
    const double r2 = glm::dot(v, v);
    if (!(r2 > 0)) return 0.0;
    const glm::dvec3 d = v / std::sqrt(r2);
    const bool touching = std::sqrt(r2) <= a.radius + b.radius;
    const double soft = touching ? std::max(a.area, b.area) : 0.0;
    return std::min({a.shown(d) * b.shown(-d) / (std::numbers::pi * r2 + soft), a.area, b.area});
}

/// Fraction of the rays between the ends' sample points (member centroids, up to 4 each)
/// that arrive unblocked; only pairs of samples that face each other cast a ray (1 if none).
double cluster_visible_fraction(const End& a, const End& b, const Visibility& visibility) {
    std::array<glm::dvec3, 4> pa{}, na{}, pb{}, nb{};
    auto samples = [](const End& e, std::array<glm::dvec3, 4>& p, std::array<glm::dvec3, 4>& n) {
        if (e.element) {
            p[0] = e.element->centre;
            n[0] = e.element->normal;
            return 1;
        }
        p = e.cluster->sample;
        n = e.cluster->sample_normal;
        return e.cluster->sample_count;
    };
    const int ca = samples(a, pa, na), cb = samples(b, pb, nb);
    std::array<Visibility::Segment, 16> segments{};
    std::size_t count = 0;
    const double off = visibility.offset();
    for (int i = 0; i < ca; ++i)
        for (int j = 0; j < cb; ++j) {
            const glm::dvec3 v = pb[std::size_t(j)] - pa[std::size_t(i)];
            if (glm::dot(na[std::size_t(i)], v) <= 0 || glm::dot(nb[std::size_t(j)], v) >= 0) continue;
            segments[count++] = {pa[std::size_t(i)] + off * na[std::size_t(i)],
                                 pb[std::size_t(j)] + off * nb[std::size_t(j)]};
        }
    return visibility.open_fraction(std::span<const Visibility::Segment>(segments.data(), count));
}

/// The point of polygon a nearest to x (a convex, planar): x projected onto a's plane, or,
/// when that falls outside, the nearest point of its edges.
glm::dvec3 nearest_point(const Patch& a, const glm::dvec3& x) {
    const glm::dvec3 p = x - a.height(x) * a.normal;
    if (covers(a, p)) return p;
    glm::dvec3 best = a.vertices[0];
    double best_d = 1e300;
    for (int k = 0; k < a.vertex_count; ++k) {
        const glm::dvec3 u = a.vertices[k], v = a.vertices[(k + 1) % a.vertex_count];
        const double t = std::clamp(glm::dot(p - u, v - u) / glm::dot(v - u, v - u), 0.0, 1.0);
        const glm::dvec3 q = u + t * (v - u);
        if (glm::length(q - p) < best_d) {
            best_d = glm::length(q - p);
            best = q;
        }
    }
    return best;
}

/// How much F(dA_x -> b) varies over a (max - min), sampled at a's centre, its corners and the
/// point of a nearest to b, where the kernel peaks when b is small and close. A link hands
/// every point of a the mean, so the spread bounds the error it makes, per unit B_b, at the
/// leaves below a. Samples are taken a hair (1e-4 of the way) towards a's centre: a corner or
/// edge shared with b would make the kernel singular.
struct Spread {
    double mean = 0.0, spread = 0.0;
};

Spread point_factor_spread(const Patch& a, const Patch& b) {
    // Far from b (beyond kFar circumradii), the point-to-point kernel at b's centre: within
    // about (r_b / d)^2 < 3% of Lambert's formula, far below the link epsilons' tens of
    // percent, and no arc tangents (Lambert's formula made the oracle most of a solve).
    static constexpr double kFar = 6.0;
    const double rb = circumradius(b), far2 = kFar * kFar * rb * rb;
    auto at = [&](const glm::dvec3& y) {
        const glm::dvec3 x = y + 1e-4 * (a.centre - y);
        if (b.height(x) <= 0.0) return 0.0;  // behind b: b sends it nothing
        const glm::dvec3 d = b.centre - x;
        const double d2 = glm::dot(d, d);
        if (d2 > far2)
            return b.area * std::max(0.0, glm::dot(a.normal, d)) * std::max(0.0, -glm::dot(b.normal, d)) /
                   (std::numbers::pi * d2 * d2);
        return point_polygon_form_factor(x, a.normal, b.polygon());
    };
    double lo = at(a.centre), hi = lo, sum = lo;
    for (int k = 0; k <= a.vertex_count; ++k) {
        const double f = at(k < a.vertex_count ? a.vertices[k] : nearest_point(a, b.centre));
        lo = std::min(lo, f);
        hi = std::max(hi, f);
        sum += f;
    }
    return {sum / (a.vertex_count + 2), hi - lo};
}

/// How what travels along unit u meets a cluster's members, per axis bin (+x +y +z -x -y -z):
/// a member turned along axis k faces u by |u_k| when the signs agree, so bin k takes the
/// share |u_k| axis_area_k of the area the cluster shows along u (exact for members whose
/// normals lie along the axes, as in rooms of furniture; the "ambient cube" of irradiance
/// volumes). Power arriving along -u splits over the bins by these shares, so each member of a
/// bin gets the same irradiance per unit of projected area; the radiosity sent along u is the
/// bins' mean under the same shares. `none` when no member faces u.
struct AxisWeights {
    std::array<std::uint8_t, 3> bin{};
    std::array<double, 3> w{};
    bool none = true;
    AxisWeights(const glm::dvec3& u, const std::array<double, 6>& axis_area) {
        double sum = 0.0;
        for (int k = 0; k < 3; ++k) {
            bin[std::size_t(k)] = std::uint8_t(u[k] >= 0 ? k : k + 3);
            w[std::size_t(k)] = std::abs(u[k]) * axis_area[bin[std::size_t(k)]];
            sum += w[std::size_t(k)];
        }
        if (!(sum > 0)) return;
        none = false;
        for (double& x : w) x /= sum;
    }
    Rgb mix(const Rgb* bins) const { return bins[bin[0]] * w[0] + bins[bin[1]] * w[1] + bins[bin[2]] * w[2]; }
    void add(Rgb* bins, const Rgb& v) const {
        for (int k = 0; k < 3; ++k) bins[bin[std::size_t(k)]] += v * w[std::size_t(k)];
    }
};

/// Gather and push-pull until the leaves settle (Jacobi over the hierarchy); B and H hold a
/// value per tree node, Bc a value per cluster (clusters may be null: no clustering).
void solve_links(const ElementTree& tree, const ClusterTree* clusters, const std::vector<Link>& links,
                 const HierarchicalOptions& options, double tolerance, const std::string& stage, std::vector<Rgb>& B,
                 std::vector<Rgb>& Bc, std::vector<Rgb>& H, SolveResult& res) {
    const auto& G = tree.geometry();
    const std::size_t n = tree.size();
    const std::size_t nc = clusters ? clusters->clusters().size() : 0;
    // Element nodes first, then the clusters, in one array per quantity.
    auto slot = [n](std::uint32_t ref) {
        return ClusterTree::is_cluster(ref) ? n + ClusterTree::index(ref) : std::size_t(ref);
    };
    auto area = [&](std::uint32_t ref) {
        return ClusterTree::is_cluster(ref) ? clusters->cluster(ref).area : G[ref].area;
    };
    std::vector<Rgb> b(n + nc), h(n + nc), gathered(n + nc), next(n + nc);
    std::copy_n(B.begin(), std::min(B.size(), n), b.begin());  // one per node: the refiner gave new ones their parent's
    for (std::size_t c = 0; c < nc && c < Bc.size(); ++c) b[n + c] = Bc[c];
    const bool oriented = options.oriented_clusters && nc > 0;
    // Per receiving slot, what it gathers over each of its links (in link order): the other
    // end's slot and the form factor towards it, laid out once so that every iteration reads
    // them in sequence (links with no transfer left out).
    struct Incoming {
        std::uint32_t src;
        bool clustered;  // a cluster at either end (oriented clusters need the link's direction)
        double F;
    };
    std::vector<std::size_t> incoming_first(n + nc + 1, 0);
    for (const Link& l : links)
        if (l.fab != 0.0f) {
            ++incoming_first[slot(l.a) + 1];
            ++incoming_first[slot(l.b) + 1];
        }
    for (std::size_t r = 0; r < n + nc; ++r) incoming_first[r + 1] += incoming_first[r];
    std::vector<Incoming> incoming(incoming_first[n + nc]);
    {
        std::vector<std::size_t> fill(incoming_first.begin(), incoming_first.end() - 1);
        for (const Link& l : links) {
            if (l.fab == 0.0f) continue;
            const std::size_t sa = slot(l.a), sb = slot(l.b);
            const bool clustered = oriented && (sa >= n || sb >= n);
            incoming[fill[sa]++] = {std::uint32_t(sb), clustered, double(l.fab)};
            incoming[fill[sb]++] = {std::uint32_t(sa), clustered, double(l.fab) * area(l.a) / area(l.b)};
        }
    }
    std::vector<std::uint32_t> order;  // parents before children
    for (std::uint32_t r = 0; r < tree.root_count(); ++r) order.push_back(r);
    for (std::size_t k = 0; k < order.size(); ++k)
        if (!tree.node(order[k]).leaf())
            for (int c = 0; c < 4; ++c) order.push_back(std::uint32_t(tree.node(order[k]).first_child + c));
    auto above = [&](std::uint32_t i) -> std::size_t {  // the slot of i's parent, or SIZE_MAX
        const auto& node = tree.node(i);
        if (node.parent >= 0) return std::size_t(node.parent);
        if (clusters && clusters->patch_parent(i) >= 0) return n + std::size_t(clusters->patch_parent(i));
        return SIZE_MAX;
    };
    // Oriented clusters: per cluster and axis direction (+x +y +z -x -y -z), the radiosity of
    // the members turned that way and the power arriving from that way.
    std::vector<Rgb> bin_b(oriented ? 6 * nc : 0), next_bin_b(bin_b.size()), bin_power(bin_b.size());
    std::vector<Rgb> from_cluster(oriented ? n : 0);  // irradiance a patch gets from its cluster
    static constexpr std::array<double, 6> kNone{};
    const std::vector<ClusterTree::Cluster> no_clusters;
    const auto& C = clusters ? clusters->clusters() : no_clusters;
    auto centre = [&](std::size_t s) { return s >= n ? clusters->clusters()[s - n].centre : G[s].centre; };
    auto area_of = [&](std::size_t s) { return s >= n ? clusters->clusters()[s - n].area : G[s].area; };
    auto axis_area_of = [&](std::uint32_t ref, int x) {
        if (ClusterTree::is_cluster(ref)) return clusters->cluster(ref).axis_area[std::size_t(x)];
        const double c = G[ref].normal[x % 3];
        return G[ref].area * std::max(0.0, x < 3 ? c : -c);
    };
    if (oriented)
        for (std::size_t c = 0; c < nc; ++c)
            for (int x = 0; x < 6; ++x) bin_b[6 * c + std::size_t(x)] = b[n + c];  // until the first pull
    res.status = "max iterations";
    res.converged = false;
    for (std::size_t it = 0; it < options.max_iterations; ++it) {
        if (options.cancel && options.cancel->load()) {
            res.status = "interrupted";
            break;
        }
        // Gather: every element or cluster collects F B over its links, both ways round. A
        // cluster end sends the radiosity of its members facing the other end and hands what it
        // gathers to the members facing the other end (oriented clusters, below). In parallel
        // over the receivers, each summing its own links in link order (the same sums on any
        // number of threads).
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n + nc, 512), [&](const auto& range) {
            for (std::size_t r = range.begin(); r != range.end(); ++r) {
                Rgb sum;
                Rgb* bins = oriented && r >= n ? &bin_power[6 * (r - n)] : nullptr;
                if (bins) std::fill(bins, bins + 6, Rgb());
                for (std::size_t e = incoming_first[r]; e < incoming_first[r + 1]; ++e) {
                    const std::size_t src = incoming[e].src;
                    const double F = incoming[e].F;
                    // Only a link with a cluster end needs its direction: element pairs skip the root.
                    if (!incoming[e].clustered) {
                        sum += b[src] * F;
                        continue;
                    }
                    const glm::dvec3 v = centre(src) - centre(r);  // r towards src
                    const double length = glm::length(v);
                    if (!(length > 0)) {
                        sum += b[src] * F;
                        continue;
                    }
                    const glm::dvec3 u = v / length;
                    // r's members facing src (along u) and src's facing r (along -u).
                    const AxisWeights wr = r >= n ? AxisWeights(u, C[r - n].axis_area) : AxisWeights(u, kNone);
                    const AxisWeights ws = src >= n ? AxisWeights(-u, C[src - n].axis_area) : AxisWeights(u, kNone);
                    const Rgb from = ws.none ? b[src] : ws.mix(&bin_b[6 * (src - n)]);
                    if (wr.none)
                        sum += from * F;
                    else
                        wr.add(bins, from * (F * area_of(r)));
                }
                gathered[r] = sum;
            }
        });
        // Push: what a cluster or element gathered reaches the members and leaves below it.
        // Isotropic clusters hand every member the same irradiance; oriented ones hand the
        // power that came from each axis direction to the members facing it, in proportion to
        // the area they turn that way (the members' axis areas, cluster_tree.h), so a desk's
        // top and underside no longer share alike. Either way the power is the gathered power.
        std::fill(from_cluster.begin(), from_cluster.end(), Rgb());
        for (std::size_t c = 0; c < nc; ++c) {
            const auto& k = clusters->clusters()[c];
            const auto parent = k.parent;
            h[n + c] = gathered[n + c] + (parent >= 0 ? h[n + std::size_t(parent)] : Rgb());
            if (!oriented) continue;
            Rgb* power = &bin_power[6 * c];  // own, plus what the parent handed down (added below)
            std::array<double, 6> sa{}, sb{};
            for (int x = 0; x < 6; ++x) {
                sa[std::size_t(x)] = axis_area_of(k.child[0], x);
                sb[std::size_t(x)] = axis_area_of(k.child[1], x);
            }
            const double aa = area(k.child[0]), ab = area(k.child[1]);
            for (int side = 0; side < 2; ++side) {
                const std::uint32_t child = k.child[std::size_t(side)];
                for (int x = 0; x < 6; ++x) {
                    const double total_x = sa[std::size_t(x)] + sb[std::size_t(x)];
                    const double share =
                        total_x > 0 ? (side ? sb : sa)[std::size_t(x)] / total_x : (side ? ab : aa) / (aa + ab);
                    const Rgb part = power[x] * share;
                    if (ClusterTree::is_cluster(child))
                        bin_power[6 * ClusterTree::index(child) + std::size_t(x)] += part;
                    else
                        from_cluster[child] += part * (1.0 / G[child].area);
                }
            }
        }
        for (const std::uint32_t i : order) {
            const std::size_t up = above(i);
            // (Links an oriented cluster could not orient, ends at one point, went in alike.)
            h[i] = gathered[i] + (up != SIZE_MAX ? h[up] : Rgb()) +
                   (oriented && up >= n && up != SIZE_MAX ? from_cluster[i] : Rgb());
        }
        // Pull: leaves reflect; a parent's radiosity is its children's area-weighted mean
        // (a cluster sends the power its members emit); an oriented cluster also keeps, per
        // axis direction, the mean over the area its members turn that way.
        for (std::size_t k = order.size(); k-- > 0;) {
            const std::uint32_t i = order[k];
            const auto& node = tree.node(i);
            if (node.leaf()) {
                next[i] = G[i].emission + G[i].reflectance * h[i];
            } else {
                Rgb sum;
                for (int c = 0; c < 4; ++c) {
                    const auto child = std::size_t(node.first_child + c);
                    sum += next[child] * G[child].area;
                }
                next[i] = sum * (1.0 / G[i].area);
            }
        }
        for (std::size_t c = nc; c-- > 0;) {
            const auto& k = clusters->clusters()[c];
            next[n + c] = (next[slot(k.child[0])] * area(k.child[0]) + next[slot(k.child[1])] * area(k.child[1])) *
                          (1.0 / k.area);
            if (!oriented) continue;
            for (int x = 0; x < 6; ++x) {
                Rgb sum;
                double weight = 0.0;
                for (const std::uint32_t child : k.child) {
                    const double w = axis_area_of(child, x);
                    sum += (ClusterTree::is_cluster(child) ? next_bin_b[6 * ClusterTree::index(child) + std::size_t(x)]
                                                           : next[child]) *
                           w;
                    weight += w;
                }
                next_bin_b[6 * c + std::size_t(x)] = weight > 0 ? sum * (1.0 / weight) : next[n + c];
            }
        }
        bin_b.swap(next_bin_b);
        double change = 0.0, mean = 0.0, total = 0.0;
        for (std::uint32_t r = 0; r < tree.root_count(); ++r) {
            mean += next[r].luminance() * G[r].area;
            total += G[r].area;
        }
        mean /= total;
        for (const std::uint32_t i : order)
            if (tree.node(i).leaf()) change = std::max(change, std::abs(next[i].luminance() - b[i].luminance()));
        b.swap(next);
        res.steps += 1;
        if (options.progress) options.progress(stage + ": gather iterations", it + 1, options.max_iterations);
        if (change <= tolerance * std::max(mean, 1e-300)) {
            res.converged = true;
            res.status = "converged";
            break;
        }
    }
    B.assign(b.begin(), b.begin() + std::ptrdiff_t(n));
    Bc.assign(b.begin() + std::ptrdiff_t(n), b.end());
    H.assign(h.begin(), h.begin() + std::ptrdiff_t(n));
}

/// The leaves' radiosity and irradiance, and the energy account, into out.result; every
/// node's radiosity and the leaves' irradiance from cluster links into out.
void finish_result(const ElementTree& tree, const std::vector<Rgb>& B, const std::vector<Rgb>& H,
                   HierarchicalSolution& out) {
    SolveResult& res = out.result;
    out.leaves = tree.leaves();
    res.radiosity.resize(out.leaves.size());
    res.irradiance.resize(out.leaves.size());
    res.unshot.assign(out.leaves.size(), Rgb());
    for (std::size_t k = 0; k < out.leaves.size(); ++k) {
        res.radiosity[k] = B[out.leaves[k]];
        res.irradiance[k] = H[out.leaves[k]];
    }
    gathered_energy_account(tree.geometry(), out.leaves, res);
    out.node_radiosity = B;
    // The irradiance element links bring a node, pushed down the tree (children follow their
    // parent in the node order: split() appends them); what a leaf has beyond it came over
    // cluster links.
    const auto& G = tree.geometry();
    std::vector<Rgb> by_elements(tree.size());
    for (const Link& l : out.links) {
        if (!l.between_elements()) continue;
        by_elements[l.a] += B[l.b] * double(l.fab);
        by_elements[l.b] += B[l.a] * (double(l.fab) * G[l.a].area / G[l.b].area);
    }
    for (std::size_t i = 0; i < tree.size(); ++i)
        if (tree.node(i).parent >= 0) by_elements[i] += by_elements[std::size_t(tree.node(i).parent)];
    out.cluster_irradiance.resize(out.leaves.size());
    for (std::size_t k = 0; k < out.leaves.size(); ++k) {
        const Rgb rest = H[out.leaves[k]] - by_elements[out.leaves[k]];
        for (int c = 0; c < 3; ++c) out.cluster_irradiance[k][c] = std::max(0.0, rest[c]);
    }
}

/// Pairs whose partial visibility refinement has traced, with the open share of their rays,
/// sorted by pair_key.
using SeenVisibility = std::vector<std::pair<std::uint64_t, float>>;

/// A pair of elements either way round as one key (its rays do not depend on the order).
std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
    return std::uint64_t(std::min(a, b)) << 32 | std::max(a, b);
}

/// Rays that judge whether a shadow's edge crosses a pair about to be linked: with 4, an
/// element a third in shadow kept all its rays lit one time in five.
constexpr int kPartialVisibilityRays = 16;

/// Refinement asks the shaft test (ShaftCuller::unblocked) of every pair it splits or links
/// when the scene has at most this many plane groups: a test then costs about what the
/// partial-visibility rays of one pair do (kPartialVisibilityRays x kPlaneTestsPerRay), and a
/// pair that passes spares its descendants every test and ray. On the Cornell box (11 groups)
/// most pairs pass high in the tree; among furniture (the 10k office: 3,585 groups) a test
/// costs more than the rays it spares, and none is made.
constexpr double kRefinementShaftPlanes = kPartialVisibilityRays * ShaftCuller::kPlaneTestsPerRay;

class Refiner {
public:
    Refiner(ElementTree& tree, const ClusterTree* clusters, const HierarchicalOptions& o, std::vector<double> min_area,
            std::vector<Rgb>& radiosity, const std::vector<Rgb>& cluster_radiosity, double scale, double power,
            const RaycastFormFactor* ff = nullptr, const SeenVisibility* seen = nullptr,
            const ShaftCuller* culler = nullptr)
        : m_ff(ff),
          m_seen(seen),
          m_culler(culler),
          m_tree(tree),
          m_clusters(clusters),
          m_options(o),
          m_min_area(std::move(min_area)),
          m_b(radiosity),
          m_cb(cluster_radiosity),
          m_scale(scale),
          m_power_budget(o.power_epsilon * power) {
        // How much the leaves' radiosity varies under each node, from the last solution.
        m_b_range = tree.leaf_luminance_spread(radiosity);
    }

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
    /// predecessors' counts give it (serially, the writing took a third of refinement).
    void run(std::vector<Pair> pairs) {
        std::vector<Step> steps;
        std::vector<float> visible;                 // per pair linked after tracing its rays: their open share
        std::vector<std::uint8_t> shaft;            // per pair: its shaft test (HierarchicalLink::shaft)
        std::vector<std::uint32_t> first;           // per pair split at an element: that element's first child
        std::vector<std::size_t> at_next, at_link;  // per pair: where its outputs go
        std::vector<Pair> next;
        while (!pairs.empty()) {
            const std::size_t n = pairs.size();
            steps.resize(n);
            visible.assign(n, -1.0f);
            shaft.assign(n, HierarchicalLink::kShaftUntested);
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& r) {
                for (std::size_t k = r.begin(); k != r.end(); ++k) steps[k] = decide(pairs[k], visible[k], shaft[k]);
            });
            first.resize(n);
            at_next.resize(n + 1);
            at_link.resize(n + 1);
            at_next[0] = at_link[0] = 0;
            for (std::size_t k = 0; k < n; ++k) {
                const std::uint32_t s = split_element(pairs[k], steps[k]);
                if (s != kNoElement) first[k] = children(s);
                at_next[k + 1] = at_next[k] + outputs(pairs[k], steps[k]);
                at_link[k + 1] = at_link[k] + (steps[k] == Step::link);
            }
            next.resize(at_next[n]);
            const std::size_t linked = links.size();
            links.resize(linked + at_link[n]);
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& r) {
                for (std::size_t k = r.begin(); k != r.end(); ++k)
                    apply(pairs[k], steps[k], visible[k], shaft[k], first[k], next.data() + at_next[k],
                          links.data() + linked + at_link[k]);
            });
            pairs.swap(next);
        }
    }

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
    Step decide(const Pair& p, float& visible, std::uint8_t& shaft) const {
        const std::uint32_t a = p.a, b = p.b;
        const bool ca = ClusterTree::is_cluster(a), cb = ClusterTree::is_cluster(b);
        if (!ca && !cb) return decide_elements(p, visible, shaft);
        if (a == b) return Step::split_self;
        const End ea = end_of(m_tree, *m_clusters, a), eb = end_of(m_tree, *m_clusters, b);
        if ((ea.element && eb.behind(*ea.element)) || (eb.element && ea.behind(*eb.element))) return Step::drop;
        const double gap = glm::length(eb.centre - ea.centre) - ea.radius - eb.radius;
        const double la = luminance(a), lb = luminance(b);
        if (gap > 0) {
            const double k = cluster_transfer(ea, eb);  // A_a F_ab
            const double floor = m_options.cluster_floor * m_scale;
            const double eps = m_options.link_epsilon;
            const double bound_a = std::min(1.0, eb.area / (std::numbers::pi * gap * gap)) * lb;
            const double bound_b = std::min(1.0, ea.area / (std::numbers::pi * gap * gap)) * la;
            const bool relative =
                bound_a <= eps * (k / ea.area * lb + floor) && bound_b <= eps * (k / eb.area * la + floor);
            if (relative || (m_power_budget > 0 && std::min(bound_a * ea.area, lb * eb.area) <= m_power_budget &&
                             std::min(bound_b * eb.area, la * ea.area) <= m_power_budget))
                return Step::link;
        } else if (m_power_budget > 0 && std::min(ea.area, eb.area) * std::max(la, lb) <= m_power_budget) {
            // Touching or overlapping ends: no point-to-point bound, but neither can send the
            // other more than B min(A_a, A_b) (F <= 1 both ways), and that is faint.
            return Step::link;
        }
        // Split the larger of two clusters; an element meeting a cluster waits while the
        // cluster is split, so two patches always meet as a pair and the element oracle alone
        // decides how they are cut (as without clustering).
        return ca && (!cb || ea.area >= eb.area) ? Step::split_a : Step::split_b;
    }

    /// A link hands every point of a the mean F(a -> b), so it errs at a's leaves by up to
    /// spread(F(x -> b)) B_b. Link when that is below link_epsilon of what the link brings,
    /// F(a -> b) B_b, plus a floor of link_floor of the scene's mean radiosity (BF refinement,
    /// Hanrahan et al. section 4: faint interactions stay coarse), both ways round; else split
    /// the larger. Summed over a leaf's links the error is then at most link_epsilon of its
    /// irradiance plus the floors. `visible` gets the open share of the rays traced, if any.
    Step decide_elements(const Pair& p, float& visible, std::uint8_t& shaft) const {
        const std::uint32_t a = p.a, b = p.b;
        const auto& G = m_tree.geometry();
        if (wholly_behind(G[a], G[b]) || wholly_behind(G[b], G[a])) return Step::drop;
        // A pair that is split or linked asks the shaft test once (unless an ancestor pair
        // passed it): passed, its children and its link need no rays for their visibility.
        const auto open = [&] {
            if (p.open)
                shaft = HierarchicalLink::kShaftOpen;
            else if (m_culler && shaft == HierarchicalLink::kShaftUntested)
                shaft =
                    m_culler->unblocked(G[a], G[b]) ? HierarchicalLink::kShaftOpen : HierarchicalLink::kShaftCrossed;
            return shaft == HierarchicalLink::kShaftOpen;
        };
        const bool split_a = splittable(a), split_b = splittable(b);
        if (!split_a && !split_b) {  // linked whatever its error: no need to bound it
            if (open()) visible = 1.0f;
            return Step::link;
        }
        const Step split = split_a && (!split_b || G[a].area >= G[b].area) ? Step::split_a : Step::split_b;
        // A link also hands a the mean radiosity of b, where the last solution varied by
        // b_range over b's leaves: up to F(a -> b) b_range more error.
        const Spread ab = point_factor_spread(G[a], G[b]);
        const double lb = m_b[b].luminance(), la = m_b[a].luminance();
        const double err_a = ab.spread * lb + ab.mean * range(b);
        if (!accepted_at(err_a, ab.mean * lb, a)) {  // refused at a whatever b's bound (accepted())
            open();
            return split;
        }
        const Spread ba = point_factor_spread(G[b], G[a]);
        const double err_b = ba.spread * la + ba.mean * range(a);
        if (!accepted(err_a, err_b, ab.mean * lb, ba.mean * la, a, b)) {
            open();
            return split;
        }
        if (open()) {  // every ray would arrive: nothing to refine, no rays
            visible = 1.0f;
            return Step::link;
        }
        // A shadow's edge across the pair: some points of a see b, others do not, and the
        // link's one visible fraction misplaces up to all it brings, F B, at each of them
        // (Hanrahan et al. 1991, section 4: partly visible interactions are refined). Only
        // mixed rays tell; a pair whose rays all arrive or all stop keeps its bound.
        // A pair linked in the last round was judged on the same rays: its share is kept.
        if (m_ff) {
            float seen = -1.0f;
            const double v =
                seen_visible(a, b, seen) ? double(seen) : m_ff->visible_fraction(a, b, kPartialVisibilityRays);
            if (v > 0 && v < 1 &&
                !accepted(err_a + ab.mean * lb, err_b + ba.mean * la, ab.mean * lb, ba.mean * la, a, b))
                return split;
            visible = float(v);
        }
        return Step::link;
    }

    /// The link test of decide_elements: errors err_a at a and err_b at b against what the
    /// link brings each (F B), relative to it plus the floor, or on power.
    bool accepted(double err_a, double err_b, double brings_a, double brings_b, std::uint32_t a,
                  std::uint32_t b) const {
        return (relative_at(err_a, brings_a) && relative_at(err_b, brings_b)) ||
               (power_at(err_a, a) && power_at(err_b, b));
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
                      Link* link) const {
        std::size_t count = 0;
        auto any = [&](std::uint32_t x, std::uint32_t y) {
            if (!ClusterTree::is_cluster(x) && !ClusterTree::is_cluster(y) && x == y) return;
            if (next)
                next[count] = ClusterTree::is_cluster(x) || ClusterTree::is_cluster(y)
                                  ? Pair{x, y}
                                  : Pair{std::min(x, y), std::max(x, y)};
            ++count;
        };
        switch (step) {
            case Step::drop:
                return 0;
            case Step::link:
                if (link) *link = {p.a, p.b, 0.0f, visible, shaft};
                return 0;
            case Step::split_self: {
                const auto child = m_clusters->cluster(p.a).child;
                any(child[0], child[0]);
                any(child[0], child[1]);
                any(child[1], child[1]);
                return count;
            }
            case Step::split_a:
            case Step::split_b: {
                const std::uint32_t s = step == Step::split_a ? p.a : p.b, other = step == Step::split_a ? p.b : p.a;
                if (ClusterTree::is_cluster(s)) {
                    const auto child = m_clusters->cluster(s).child;
                    any(child[0], other);
                    any(child[1], other);
                    return count;
                }
                const bool open = shaft == HierarchicalLink::kShaftOpen;
                if (next)
                    for (std::uint32_t k = 0; k < 4; ++k) next[k] = {first + k, other, open};
                return 4;
            }
        }
        return 0;
    }
    /// How many pairs apply() makes of a decision.
    std::size_t outputs(const Pair& p, Step step) const {
        return apply(p, step, 0.0f, HierarchicalLink::kShaftUntested, 0, nullptr, nullptr);
    }

    bool splittable(std::uint32_t i) const {
        const auto& n = m_tree.node(i);
        return n.level < m_options.max_level && m_tree.geometry()[i].area >= 4.0 * m_min_area[n.root] * (1 - 1e-9);
    }
    std::uint32_t children(std::uint32_t i) {
        if (m_tree.node(i).leaf()) {
            const auto first = std::uint32_t(m_tree.split(i));
            // New elements start from their parent's radiosity.
            const Rgb parent = m_b[i];
            m_b.resize(m_tree.size(), parent);
            return first;
        }
        return std::uint32_t(m_tree.node(i).first_child);
    }

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

}  // namespace

HierarchicalSolution solve_hierarchical(const std::vector<Patch>& patches, const Visibility& visibility,
                                        const HierarchicalOptions& options) {
    if (patches.empty()) throw std::invalid_argument("hierarchical radiosity: no patches");
    if (!(options.link_epsilon > 0))
        throw std::invalid_argument("hierarchical radiosity: the link epsilon must be > 0");
    if (options.refine_rounds < 1) throw std::invalid_argument("hierarchical radiosity: at least one refinement round");
    const auto start = std::chrono::steady_clock::now();
    auto since_start = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    HierarchicalSolution out{ElementTree(patches), {}, {}, 0, 0, 0, 0.0, 0, {}, {}, {}, options.power_epsilon};
    ElementTree& tree = out.tree;
    // First estimate of B for the oracle: emission plus the ambient term (the emitted power
    // spread over all area and inter-reflected by the mean reflectance).
    double total_area = 0.0;
    Rgb power, rho_area;
    for (const auto& p : patches) {
        total_area += p.area;
        power += p.emission * p.area;
        rho_area += p.reflectance * p.area;
    }
    // The depth counts from the patch or from the base, whichever is larger: the oracle's
    // spread-to-mean ratio does not fall with size where surfaces touch, so without the base
    // every small triangle touching another was cut max_level times (the 2k office: 2,004
    // elements at max level 0, 7,902 at 1 with 1.34 million links).
    std::vector<double> min_area(patches.size());
    const double base = options.level_base * total_area;
    for (std::size_t r = 0; r < patches.size(); ++r)
        min_area[r] = options.min_area > 0 ? options.min_area
                                           : std::max(patches[r].area, base) / std::pow(4.0, options.max_level);
    Rgb ambient;
    for (int c = 0; c < 3; ++c) ambient[c] = power[c] / total_area / std::max(1e-3, 1.0 - rho_area[c] / total_area);
    std::vector<Rgb> B(patches.size());
    for (std::size_t r = 0; r < patches.size(); ++r) B[r] = patches[r].emission + patches[r].reflectance * ambient;

    SolveResult& res = out.result;
    res.solver = "hierarchical";
    res.form_factors = "raycast";
    FormFactorOptions link_factors = with_default_rays(options.form_factors, kRefinementRays);
    link_factors.unoccluded_tolerance = std::max(link_factors.unoccluded_tolerance, options.link_factor_tolerance);
    const RaycastFormFactor ff(tree.geometry(), &visibility, link_factors);
    // Refinement's shaft tests use the estimator's culler, built over the input patches (the
    // tree held only those then), rather than building the same one again.
    const ShaftCuller* culler = ff.culler();
    std::optional<ClusterTree> clusters;
    std::vector<Rgb> Bc;
    if (options.clustering) {
        clusters.emplace(patches);
        // A cluster's radiosity: its members' area-weighted mean (children after parents).
        const auto& C = clusters->clusters();
        Bc.assign(C.size(), Rgb());
        for (std::size_t c = C.size(); c-- > 0;) {
            Rgb sum;
            for (const std::uint32_t ref : C[c].child)
                sum += ClusterTree::is_cluster(ref) ? Bc[ClusterTree::index(ref)] * C[ClusterTree::index(ref)].area
                                                    : B[ref] * patches[ref].area;
            Bc[c] = sum * (1.0 / C[c].area);
        }
        out.clusters = C.size();
        out.initial_links = 1;
    } else {
        out.initial_links = patches.size() * (patches.size() - 1) / 2;
    }
    const ClusterTree* cluster_tree = clusters ? &*clusters : nullptr;
    std::vector<Link> links;
    std::vector<Rgb> H;
    // Multigridding (Hanrahan et al. 1991, section 5): a later round keeps the form factor of
    // every link the last round had, computed once; only new links cast rays. Keyed by both
    // ends, sorted for binary search (refs are stable: the tree only grows).
    std::vector<std::pair<std::uint64_t, float>> known;
    SeenVisibility seen;  // partial visibility's ray shares, kept across rounds
    auto key = [](const Link& l) { return std::uint64_t(l.a) << 32 | l.b; };
    for (int round = 0; round < options.refine_rounds; ++round) {
        const double round_start = since_start();
        const std::string stage = "round " + std::to_string(round + 1) + "/" + std::to_string(options.refine_rounds);
        double scale = 0.0;
        for (std::uint32_t r = 0; r < patches.size(); ++r) scale += B[r].luminance() * patches[r].area;
        const double power = scale;
        scale /= total_area;
        {
            if (options.progress) options.progress(stage + ": refining links", 0, 1);
            Refiner refiner(tree, cluster_tree, options, min_area, B, Bc, scale, power,
                            options.refine_partial_visibility ? &ff : nullptr, &seen,
                            culler && culler->plane_groups() <= kRefinementShaftPlanes ? culler : nullptr);
            if (cluster_tree) {
                refiner.run({{cluster_tree->root(), cluster_tree->root()}});
            } else {
                // Every pair of patches, a patch's pairs at a time (not N^2 / 2 pairs at once).
                for (std::uint32_t p = 0; p < patches.size(); ++p) {
                    std::vector<Refiner::Pair> pairs;
                    for (std::uint32_t q = p + 1; q < patches.size(); ++q) pairs.push_back({p, q});
                    refiner.run(std::move(pairs));
                }
            }
            links = std::move(refiner.links);
        }
        // Link form factors with visibility, in parallel (the tree does not change here).
        std::atomic<std::size_t> done{0}, reused{0};
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, links.size(), 256), [&](const auto& r) {
            for (std::size_t k = r.begin(); k != r.end(); ++k) {
                const Link& l = links[k];
                const auto it = std::lower_bound(known.begin(), known.end(), std::pair(key(l), -1.0f));
                if (it != known.end() && it->first == key(l)) {
                    links[k].fab = it->second;
                    reused.fetch_add(1, std::memory_order_relaxed);
                    continue;
                }
                if (l.between_elements()) {
                    links[k].fab = float(l.visible >= 0 ? ff.pair(l.a, l.b, l.visible) : ff.pair(l.a, l.b));
                    continue;
                }
                const End ea = end_of(tree, *cluster_tree, l.a), eb = end_of(tree, *cluster_tree, l.b);
                double t = cluster_transfer(ea, eb);
                if (t > 0 && options.cluster_visibility) t *= cluster_visible_fraction(ea, eb, visibility);
                links[k].fab = float(t / ea.area);
            }
            const std::size_t now = done.fetch_add(r.size(), std::memory_order_relaxed) + r.size();
            if (options.progress) options.progress(stage + ": link form factors", now, links.size());
        });
        out.reused_links += reused.load();
        if (round + 1 < options.refine_rounds) {
            known.resize(links.size());
            for (std::size_t k = 0; k < links.size(); ++k) known[k] = {key(links[k]), links[k].fab};
            std::sort(known.begin(), known.end());
            for (const Link& l : links)
                if (l.visible >= 0) seen.push_back({pair_key(l.a, l.b), l.visible});
            std::sort(seen.begin(), seen.end());
            seen.erase(
                std::unique(seen.begin(), seen.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
                seen.end());
        }
        out.refine_seconds += since_start() - round_start;
        // A round before the last only gives the oracle its B: a few parts in a thousand do
        // (the last round starts from it and settles to the tolerance).
        const bool last = round + 1 == options.refine_rounds;
        const double tolerance = last ? options.tolerance : std::max(options.tolerance, 1e-3);
        solve_links(tree, cluster_tree, links, options, tolerance, stage, B, Bc, H, res);
        if (res.status == "interrupted") break;
    }
    for (const Link& l : links) out.cluster_links += !l.between_elements();
    out.links = std::move(links);
    finish_result(tree, B, H, out);
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
      << " links=" << solution.links.size();
    return s.str();
}

}  // namespace bounce
