// SPDX-License-Identifier: MIT
#include "solver/refinement/hierarchical_iteration.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "solver/linear/convergence.h"

namespace bounce::hierarchical {
namespace {

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

/// One solve over the links: the hierarchy's element nodes and clusters as slots of one array
/// per quantity (element nodes first, then the clusters), and the links laid out per receiver.
class LinkIteration {
public:
    LinkIteration(const LinkSystem& system, const HierarchyRadiosity& x)
        : m_cancel(system.options.cancel),
          m_tree(system.tree),
          m_G(system.tree.geometry()),
          m_clusters(system.clusters),
          m_C(system.clusters ? system.clusters->clusters() : m_no_clusters),
          m_n(system.tree.size()),
          m_nc(system.clusters ? system.clusters->clusters().size() : 0),
          m_oriented(system.options.oriented_clusters && m_nc > 0),
          m_b(m_n + m_nc),
          m_h(m_n + m_nc),
          m_gathered(m_n + m_nc),
          m_next(m_n + m_nc) {
        // One per node: the refiner gave new ones their parent's.
        std::copy_n(x.B.begin(), std::min(x.B.size(), m_n), m_b.begin());
        for (std::size_t c = 0; c < m_nc && c < x.Bc.size(); ++c) m_b[m_n + c] = x.Bc[c];
        lay_out(system.links);
        // Parents before children.
        for (std::uint32_t r = 0; r < m_tree.root_count(); ++r) m_order.push_back(r);
        for (std::size_t k = 0; k < m_order.size(); ++k)
            if (!m_tree.node(m_order[k]).leaf())
                for (int c = 0; c < 4; ++c) m_order.push_back(std::uint32_t(m_tree.node(m_order[k]).first_child + c));
        m_bin_b.resize(m_oriented ? 6 * m_nc : 0);
        m_next_bin_b.resize(m_bin_b.size());
        m_bin_power.resize(m_bin_b.size());
        m_from_cluster.resize(m_oriented ? m_n : 0);
        if (m_oriented)
            for (std::size_t c = 0; c < m_nc; ++c)
                for (int x = 0; x < 6; ++x) m_bin_b[6 * c + std::size_t(x)] = m_b[m_n + c];  // until the first pull
    }

    /// Iterates until the leaves settle (solve_links); into res its steps and status.
    void run(const HierarchicalOptions& options, double tolerance, const std::string& stage, SolveResult& res);
    /// The element nodes' B and H and the clusters' B into x.
    void store(HierarchyRadiosity& x) const;

private:
    /// Every element or cluster collects F B over its links, both ways round.
    void gather();
    /// What a cluster or element gathered reaches the members and leaves below it.
    void push();
    /// Leaves reflect; parents take their children's area-weighted mean.
    void pull();
    /// Makes the pulled radiosity current; returns the largest change of a leaf's luminance
    /// relative to the roots' area-weighted mean luminance, as change <= tolerance * mean.
    bool settled(double tolerance);

    /// Per receiving slot, what it gathers over each of its links (in link order): the other
    /// end's slot and the form factor towards it, laid out once so that every iteration reads
    /// them in sequence (links with no transfer left out).
    struct Incoming {
        std::uint32_t src;
        bool clustered;  // a cluster at either end (oriented clusters need the link's direction)
        double F;
    };
    void lay_out(const std::vector<HierarchicalLink>& links);
    bool cancelled() const { return m_cancel && m_cancel->load(std::memory_order_relaxed); }

    std::size_t slot(std::uint32_t ref) const {
        return ClusterTree::is_cluster(ref) ? m_n + ClusterTree::index(ref) : std::size_t(ref);
    }
    double area(std::uint32_t ref) const {
        return ClusterTree::is_cluster(ref) ? m_clusters->cluster(ref).area : m_G[ref].area;
    }
    std::size_t above(std::uint32_t i) const {  // the slot of i's parent, or SIZE_MAX
        const auto& node = m_tree.node(i);
        if (node.parent >= 0) return std::size_t(node.parent);
        if (m_clusters && m_clusters->patch_parent(i) >= 0) return m_n + std::size_t(m_clusters->patch_parent(i));
        return SIZE_MAX;
    }
    glm::dvec3 centre_of(std::size_t s) const { return s >= m_n ? m_C[s - m_n].centre : m_G[s].centre; }
    double area_of(std::size_t s) const { return s >= m_n ? m_C[s - m_n].area : m_G[s].area; }
    double axis_area_of(std::uint32_t ref, int x) const {
        if (ClusterTree::is_cluster(ref)) return m_clusters->cluster(ref).axis_area[std::size_t(x)];
        const double c = m_G[ref].normal[x % 3];
        return m_G[ref].area * std::max(0.0, x < 3 ? c : -c);
    }

    const std::vector<ClusterTree::Cluster> m_no_clusters;
    // Set: lay_out() and gather() stop at the next link or receiver, and run() before it
    // applies a partial gather.
    const std::atomic<bool>* m_cancel;
    const ElementTree& m_tree;
    const std::vector<Patch>& m_G;
    const ClusterTree* m_clusters;
    const std::vector<ClusterTree::Cluster>& m_C;
    const std::size_t m_n, m_nc;  // element nodes, clusters
    const bool m_oriented;
    std::vector<Rgb> m_b, m_h;  // per slot: radiosity and irradiance
    std::vector<Rgb> m_gathered, m_next;
    std::vector<std::size_t> m_incoming_first;
    std::vector<Incoming> m_incoming;
    std::vector<std::uint32_t> m_order;  // element nodes, parents before children
    // Oriented clusters: per cluster and axis direction (+x +y +z -x -y -z), the radiosity of
    // the members turned that way and the power arriving from that way.
    std::vector<Rgb> m_bin_b, m_next_bin_b, m_bin_power;
    std::vector<Rgb> m_from_cluster;  // irradiance a patch gets from its cluster
};

void LinkIteration::lay_out(const std::vector<HierarchicalLink>& links) {
    const std::size_t n = m_n, nc = m_nc;
    m_incoming_first.assign(n + nc + 1, 0);
    for (const HierarchicalLink& l : links) {
        if (cancelled()) return;
        if (l.fab != 0.0f) {
            ++m_incoming_first[slot(l.a) + 1];
            ++m_incoming_first[slot(l.b) + 1];
        }
    }
    for (std::size_t r = 0; r < n + nc; ++r) m_incoming_first[r + 1] += m_incoming_first[r];
    m_incoming.resize(m_incoming_first[n + nc]);
    std::vector<std::size_t> fill(m_incoming_first.begin(), m_incoming_first.end() - 1);
    for (const HierarchicalLink& l : links) {
        if (cancelled()) return;
        if (l.fab == 0.0f) continue;
        const std::size_t sa = slot(l.a), sb = slot(l.b);
        const bool clustered = m_oriented && (sa >= n || sb >= n);
        m_incoming[fill[sa]++] = {std::uint32_t(sb), clustered, double(l.fab)};
        m_incoming[fill[sb]++] = {std::uint32_t(sa), clustered, double(l.fab) * area(l.a) / area(l.b)};
    }
}

void LinkIteration::run(const HierarchicalOptions& options, double tolerance, const std::string& stage,
                        SolveResult& res) {
    res.status = SolveStatus::max_iterations;
    res.converged = false;
    for (std::size_t it = 0; it < options.max_iterations; ++it) {
        if (options.cancel && options.cancel->load()) {
            res.status = SolveStatus::interrupted;
            break;
        }
        gather();
        if (cancelled()) {
            res.status = SolveStatus::interrupted;
            break;
        }
        push();
        pull();
        const bool done = settled(tolerance);
        res.steps += 1;
        if (options.progress) options.progress(stage + ": gather iterations", it + 1, options.max_iterations);
        if (done) {
            res.converged = true;
            res.status = SolveStatus::converged;
            break;
        }
    }
}

void LinkIteration::store(HierarchyRadiosity& x) const {
    x.B.assign(m_b.begin(), m_b.begin() + std::ptrdiff_t(m_n));
    x.Bc.assign(m_b.begin() + std::ptrdiff_t(m_n), m_b.end());
    x.H.assign(m_h.begin(), m_h.begin() + std::ptrdiff_t(m_n));
}

// A cluster end sends the radiosity of its members facing the other end and hands what it
// gathers to the members facing the other end (oriented clusters, push()). In parallel over
// the receivers, each summing its own links in link order (the same sums on any number of
// threads).
void LinkIteration::gather() {
    static constexpr std::array<double, 6> kNone{};
    const std::size_t n = m_n;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n + m_nc, 512), [&](const auto& range) {
        for (std::size_t r = range.begin(); r != range.end() && !cancelled(); ++r) {
            Rgb sum;
            Rgb* bins = m_oriented && r >= n ? &m_bin_power[6 * (r - n)] : nullptr;
            if (bins) std::fill(bins, bins + 6, Rgb());
            for (std::size_t e = m_incoming_first[r]; e < m_incoming_first[r + 1]; ++e) {
                const std::size_t src = m_incoming[e].src;
                const double F = m_incoming[e].F;
                // Only a link with a cluster end needs its direction: element pairs skip the root.
                if (!m_incoming[e].clustered) {
                    sum += m_b[src] * F;
                    continue;
                }
                const glm::dvec3 v = centre_of(src) - centre_of(r);  // r towards src
                const double length = glm::length(v);
                if (!(length > 0)) {
                    sum += m_b[src] * F;
                    continue;
                }
                const glm::dvec3 u = v / length;
                // r's members facing src (along u) and src's facing r (along -u).
                const AxisWeights wr = r >= n ? AxisWeights(u, m_C[r - n].axis_area) : AxisWeights(u, kNone);
                const AxisWeights ws = src >= n ? AxisWeights(-u, m_C[src - n].axis_area) : AxisWeights(u, kNone);
                const Rgb from = ws.none ? m_b[src] : ws.mix(&m_bin_b[6 * (src - n)]);
                if (wr.none)
                    sum += from * F;
                else
                    wr.add(bins, from * (F * area_of(r)));
            }
            m_gathered[r] = sum;
        }
    });
}

// Isotropic clusters hand every member the same irradiance; oriented ones hand the power that
// came from each axis direction to the members facing it, in proportion to the area they turn
// that way (the members' axis areas, cluster_tree.h), so a desk's top and underside do not
// share alike. Either way the power is the gathered power.
void LinkIteration::push() {
    const std::size_t n = m_n;
    std::fill(m_from_cluster.begin(), m_from_cluster.end(), Rgb());
    for (std::size_t c = 0; c < m_nc; ++c) {
        const auto& k = m_C[c];
        const auto parent = k.parent;
        m_h[n + c] = m_gathered[n + c] + (parent >= 0 ? m_h[n + std::size_t(parent)] : Rgb());
        if (!m_oriented) continue;
        Rgb* power = &m_bin_power[6 * c];  // own, plus what the parent handed down (added below)
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
                    m_bin_power[6 * ClusterTree::index(child) + std::size_t(x)] += part;
                else
                    m_from_cluster[child] += part * (1.0 / m_G[child].area);
            }
        }
    }
    for (const std::uint32_t i : m_order) {
        const std::size_t up = above(i);
        // (Links an oriented cluster could not orient, ends at one point, went in alike.)
        m_h[i] = m_gathered[i] + (up != SIZE_MAX ? m_h[up] : Rgb()) +
                 (m_oriented && up >= n && up != SIZE_MAX ? m_from_cluster[i] : Rgb());
    }
}

// A cluster sends the power its members emit; an oriented cluster also keeps, per axis
// direction, the mean over the area its members turn that way.
void LinkIteration::pull() {
    const std::size_t n = m_n;
    for (std::size_t k = m_order.size(); k-- > 0;) {
        const std::uint32_t i = m_order[k];
        const auto& node = m_tree.node(i);
        if (node.leaf()) {
            m_next[i] = m_G[i].emission + m_G[i].reflectance * m_h[i];
        } else {
            Rgb sum;
            for (int c = 0; c < 4; ++c) {
                const auto child = std::size_t(node.first_child + c);
                sum += m_next[child] * m_G[child].area;
            }
            m_next[i] = sum * (1.0 / m_G[i].area);
        }
    }
    for (std::size_t c = m_nc; c-- > 0;) {
        const auto& k = m_C[c];
        m_next[n + c] = (m_next[slot(k.child[0])] * area(k.child[0]) + m_next[slot(k.child[1])] * area(k.child[1])) *
                        (1.0 / k.area);
        if (!m_oriented) continue;
        for (int x = 0; x < 6; ++x) {
            Rgb sum;
            double weight = 0.0;
            for (const std::uint32_t child : k.child) {
                const double w = axis_area_of(child, x);
                sum += (ClusterTree::is_cluster(child) ? m_next_bin_b[6 * ClusterTree::index(child) + std::size_t(x)]
                                                       : m_next[child]) *
                       w;
                weight += w;
            }
            m_next_bin_b[6 * c + std::size_t(x)] = weight > 0 ? sum * (1.0 / weight) : m_next[n + c];
        }
    }
    m_bin_b.swap(m_next_bin_b);
}

bool LinkIteration::settled(double tolerance) {
    double change = 0.0, mean = 0.0, total = 0.0;
    for (std::uint32_t r = 0; r < m_tree.root_count(); ++r) {
        mean += m_next[r].luminance() * m_G[r].area;
        total += m_G[r].area;
    }
    mean /= total;
    for (const std::uint32_t i : m_order)
        if (m_tree.node(i).leaf()) change = std::max(change, std::abs(m_next[i].luminance() - m_b[i].luminance()));
    m_b.swap(m_next);
    return change <= tolerance * std::max(mean, 1e-300);
}

}  // namespace

void solve_links(const LinkSystem& system, double tolerance, const std::string& stage, HierarchyRadiosity& x,
                 SolveResult& res) {
    LinkIteration iteration(system, x);
    iteration.run(system.options, tolerance, stage, res);
    iteration.store(x);
}

void finish_result(const HierarchyRadiosity& x, HierarchicalSolution& out) {
    const ElementTree& tree = out.tree;
    const std::vector<Rgb>& B = x.B;
    const std::vector<Rgb>& H = x.H;
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
    // With no sweep (interrupted first) nothing was gathered: H is 0, and so is the rest.
    const std::size_t gathered_links = res.steps > 0 ? out.links.size() : 0;
    for (std::size_t k = 0; k < gathered_links; ++k) {
        const HierarchicalLink& l = out.links[k];
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

}  // namespace bounce::hierarchical
