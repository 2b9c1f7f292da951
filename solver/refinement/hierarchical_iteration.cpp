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
        : m_seen(system.seen && !system.seen->empty() && system.seen->first.size() == system.links.size() + 1
                     ? system.seen
                     : nullptr),
          m_cancel(system.options.cancel),
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
          m_next(m_n + m_nc),
          m_row(m_n, 1.0) {
        // One per node: the refiner gave new ones their parent's.
        std::copy_n(x.B.begin(), std::min(x.B.size(), m_n), m_b.begin());
        for (std::size_t c = 0; c < m_nc && c < x.Bc.size(); ++c) m_b[m_n + c] = x.Bc[c];
        set_open_shares(system.open);
        lay_out(system.links);
        if (m_seen) {
            m_delivered.resize(m_incoming.size());
            // Element nodes by root: what a receiver shares lands on nodes of its own root.
            m_root_first.assign(m_tree.root_count() + 1, 0);
            for (std::size_t i = 0; i < m_n; ++i) ++m_root_first[m_tree.node(i).root + 1];
            for (std::size_t r = 0; r < m_tree.root_count(); ++r) m_root_first[r + 1] += m_root_first[r];
            m_by_root.resize(m_n);
            std::vector<std::size_t> fill(m_root_first.begin(), m_root_first.end() - 1);
            for (std::size_t i = 0; i < m_n; ++i) m_by_root[fill[m_tree.node(i).root]++] = std::uint32_t(i);
        }
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
        if (system.open) set_rows();
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
        // The source's nodes that see this end (SeenEnds entries [seen_first, seen_last)),
        // whose weighted mean it sends instead of its own; empty: its mean.
        std::uint32_t seen_first = 0, seen_last = 0;
        // The receiver's nodes that see the source (SeenEnds entries [to_first, to_last)), among
        // which what it gathers is shared by their weights; empty: the receiver takes it all.
        std::uint32_t to_first = 0, to_last = 0;
    };
    /// What the source of `in` sends along it: its seen nodes' weighted mean, or its own.
    Rgb sent(const Incoming& in) const {
        if (in.seen_first == in.seen_last) return m_b[in.src];
        Rgb sum;
        for (std::uint32_t e = in.seen_first; e < in.seen_last; ++e)
            sum += m_b[m_seen->node[e]] * double(m_seen->weight[e]);
        return sum;
    }
    void lay_out(const std::vector<HierarchicalLink>& links);
    /// Every slot's sending and receiving share and every cluster's open axis areas.
    void set_open_shares(const ElementOpenness* open);
    /// Every leaf's row (m_row), from the form factors of the links on its path.
    void set_rows();
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
    /// The open area a node or cluster turns along axis direction x (+x +y +z -x -y -z).
    double axis_area_of(std::uint32_t ref, int x) const {
        if (ClusterTree::is_cluster(ref)) return m_open_axis[ClusterTree::index(ref)][std::size_t(x)];
        const double c = m_G[ref].normal[x % 3];
        return m_G[ref].area * std::max(0.0, x < 3 ? c : -c) * m_send[ref];
    }
    double open_area(std::uint32_t ref) const { return area(ref) * m_send[slot(ref)]; }
    /// A slot with an open part sends over its links; a buried one (open share 0) only
    /// receives, what its own links bring through a gap, and keeps it.
    bool sends(std::size_t s) const { return m_send[s] > 0.0; }
    /// Whether slot s takes its parent `up`'s irradiance (and, sending, its links): what an
    /// element or cluster gathers lands on its open part, so a buried member of an open one
    /// takes none of it.
    bool inherits(std::size_t s, std::size_t up) const { return sends(s) || !sends(up); }
    Rgb handed_down(std::size_t s, std::size_t up) const { return inherits(s, up) ? m_h[up] : Rgb(); }

    const std::vector<ClusterTree::Cluster> m_no_clusters;
    const SeenEnds* m_seen;  // null: every link sends its source's mean
    // Set: lay_out() and gather() stop at the next link or receiver, and run() before it
    // applies a partial gather.
    const std::atomic<bool>* m_cancel;
    const ElementTree& m_tree;
    const std::vector<Patch>& m_G;
    const ClusterTree* m_clusters;
    const std::vector<ClusterTree::Cluster>& m_C;
    const std::size_t m_n, m_nc;  // element nodes, clusters
    const bool m_oriented;
    std::vector<Rgb> m_b, m_h;  // per slot: radiosity and irradiance (on the open part)
    // Per slot: the share of its area that sends (open) and that receives (open, or the whole
    // where nothing is open).
    std::vector<double> m_send, m_recv;
    std::vector<std::array<double, 6>> m_open_axis;  // per cluster: its members' open axis areas
    std::vector<Rgb> m_gathered, m_next;
    std::vector<Rgb> m_delivered;           // per incoming entry shared among seen nodes: F times what it sent
    std::vector<std::size_t> m_root_first;  // with weighted ends: m_by_root's range per root
    std::vector<std::uint32_t> m_by_root;   // element nodes grouped by root
    // Per element node: a leaf's row, the share of what its open part sends that its links
    // carry to patches (set_rows).
    std::vector<double> m_row;
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
            if (sends(slot(l.b))) ++m_incoming_first[slot(l.a) + 1];
            if (sends(slot(l.a))) ++m_incoming_first[slot(l.b) + 1];
        }
    }
    for (std::size_t r = 0; r < n + nc; ++r) m_incoming_first[r + 1] += m_incoming_first[r];
    m_incoming.resize(m_incoming_first[n + nc]);
    std::vector<std::size_t> fill(m_incoming_first.begin(), m_incoming_first.end() - 1);
    for (std::size_t k = 0; k < links.size(); ++k) {
        const HierarchicalLink& l = links[k];
        if (cancelled()) return;
        if (l.fab == 0.0f) continue;
        const std::size_t sa = slot(l.a), sb = slot(l.b);
        const bool clustered = m_oriented && (sa >= n || sb >= n);
        // a gathers what b's seen nodes send and shares it among its own, and b the same.
        std::uint32_t a0 = 0, a1 = 0, b0 = 0, b1 = 0;
        if (m_seen) {
            a0 = m_seen->first[k];
            a1 = b0 = m_seen->middle[k];
            b1 = m_seen->first[k + 1];
        }
        if (sends(sb)) m_incoming[fill[sa]++] = {std::uint32_t(sb), clustered, double(l.fab), b0, b1, a0, a1};
        if (sends(sa))
            m_incoming[fill[sb]++] = {
                std::uint32_t(sa), clustered, double(l.fab) * area(l.a) / area(l.b), a0, a1, b0, b1};
    }
}

void LinkIteration::set_open_shares(const ElementOpenness* open) {
    const std::size_t n = m_n;
    m_send.assign(n + m_nc, 1.0);
    m_open_axis.resize(m_nc);
    for (std::size_t c = 0; c < m_nc; ++c) m_open_axis[c] = m_C[c].axis_area;
    if (open && !open->all_open) {
        std::copy_n(open->share.begin(), std::min(open->share.size(), n), m_send.begin());
        // Children after parents: a cluster's members are done before it.
        for (std::size_t c = m_nc; c-- > 0;) {
            const auto& k = m_C[c];
            double sent = 0.0;
            bool whole = true;
            for (const std::uint32_t child : k.child) {
                sent += open_area(child);
                whole = whole && m_send[slot(child)] == 1.0;
            }
            m_send[n + c] = whole ? 1.0 : std::clamp(sent / k.area, 0.0, 1.0);
            for (int x = 0; x < 6; ++x)
                m_open_axis[c][std::size_t(x)] = axis_area_of(k.child[0], x) + axis_area_of(k.child[1], x);
        }
    }
    m_recv.resize(n + m_nc);
    for (std::size_t s = 0; s < n + m_nc; ++s) m_recv[s] = receiving_share(m_send[s]);
}

// A leaf's open part sends over the links on its path (its own, its ancestors', its
// clusters') the sum of their form factors per unit of its open area: its row. What the row
// leaves out escapes or meets back sides (the energy account splits it per input patch by its
// leaves' OpenPart::back_share, back_sides_absorb). A link hands every leaf under it the mean factor of its end, so a
// single leaf's row strays from its own by the link's error, which sums over the leaves of
// a linked element cancel. An oriented cluster sends along u the mean of its members turned
// that way (AxisWeights), which a member's row follows.
void LinkIteration::set_rows() {
    const std::size_t n = m_n;
    std::vector<double> row(n + m_nc, 0.0);  // per unit of open area, alike for every member
    // Oriented clusters send along u the mean of their members turned that way
    // (AxisWeights): per cluster and axis bin, what a member's unit of axis area sends.
    std::vector<std::array<double, 6>> by_axis(m_nc, std::array<double, 6>{});
    for (std::size_t r = 0; r < n + m_nc; ++r) {
        double sum = 0.0;
        for (std::size_t e = m_incoming_first[r]; e < m_incoming_first[r + 1]; ++e) {
            const Incoming& in = m_incoming[e];
            if (r < n || !in.clustered) {
                sum += in.F;
                continue;
            }
            const glm::dvec3 v = centre_of(in.src) - centre_of(r);  // r towards the other end
            const double length = glm::length(v);
            const AxisWeights w =
                length > 0 ? AxisWeights(v / length, m_open_axis[r - n]) : AxisWeights(v, std::array<double, 6>{});
            if (w.none) {
                sum += in.F;
                continue;
            }
            for (std::size_t k = 0; k < 3; ++k) {
                const double axis = m_open_axis[r - n][w.bin[k]];
                if (axis > 0) by_axis[r - n][w.bin[k]] += in.F * area_of(r) * w.w[k] / axis;
            }
        }
        row[r] = sum / m_recv[r];
    }
    // A link whose receiver gathers what the source's seen nodes send (Incoming::seen_first)
    // takes that power from those nodes, not from the source's open area alike.
    std::vector<double> seen_row(m_seen ? n : 0, 0.0);
    if (m_seen)
        for (std::size_t q = 0; q < n; ++q) {
            if (!sends(q)) continue;  // (the source's row holds no link to a buried receiver)
            for (std::size_t e = m_incoming_first[q]; e < m_incoming_first[q + 1]; ++e) {
                const Incoming& in = m_incoming[e];
                if (in.seen_first == in.seen_last) continue;
                const double power = m_G[q].area * in.F;  // per unit of the source's B
                row[in.src] -= power / (m_G[in.src].area * m_recv[in.src]);
                for (std::uint32_t k = in.seen_first; k < in.seen_last; ++k) {
                    const std::uint32_t m = m_seen->node[k];
                    seen_row[m] += power * double(m_seen->weight[k]) / (m_G[m].area * m_recv[m]);
                }
            }
        }
    for (std::size_t i = 0; i < seen_row.size(); ++i) row[i] += seen_row[i];
    for (std::size_t c = 0; c < m_nc; ++c) {  // parents before children
        const auto parent = m_C[c].parent;
        if (parent < 0) continue;
        row[n + c] += row[n + std::size_t(parent)];
        for (std::size_t x = 0; x < 6; ++x) by_axis[c][x] += by_axis[std::size_t(parent)][x];
    }
    for (const std::uint32_t i : m_order) {
        const std::size_t up = above(i);
        if (up != SIZE_MAX && inherits(i, up)) row[i] += row[up];
        if (up != SIZE_MAX && up >= n && sends(i))
            for (int x = 0; x < 6; ++x)
                row[i] += by_axis[up - n][std::size_t(x)] * axis_area_of(i, x) / (m_G[i].area * m_recv[i]);
        if (m_tree.node(i).leaf()) m_row[i] = row[i];
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
    x.rows = m_row;
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
                    if (m_incoming[e].to_first < m_incoming[e].to_last)
                        m_delivered[e] = sent(m_incoming[e]) * F;
                    else
                        sum += sent(m_incoming[e]) * F;
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
                const AxisWeights wr = r >= n ? AxisWeights(u, m_open_axis[r - n]) : AxisWeights(u, kNone);
                const AxisWeights ws = src >= n ? AxisWeights(-u, m_open_axis[src - n]) : AxisWeights(u, kNone);
                const Rgb from = ws.none ? m_b[src] : ws.mix(&m_bin_b[6 * (src - n)]);
                if (wr.none)
                    sum += from * F;
                else
                    wr.add(bins, from * (F * area_of(r)));
            }
            m_gathered[r] = sum;
        }
    });
    // What the receivers' seen nodes take of it (Incoming::to_first), per unit of their area;
    // in parallel over the roots, whose nodes no other root's receivers reach.
    if (!m_seen || cancelled()) return;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m_tree.root_count(), 16), [&](const auto& roots) {
        for (std::size_t root = roots.begin(); root != roots.end(); ++root)
            for (std::size_t at = m_root_first[root]; at < m_root_first[root + 1]; ++at) {
                const std::size_t r = m_by_root[at];
                for (std::size_t e = m_incoming_first[r]; e < m_incoming_first[r + 1]; ++e) {
                    const Incoming& in = m_incoming[e];
                    for (std::uint32_t k = in.to_first; k < in.to_last; ++k)
                        m_gathered[m_seen->node[k]] += m_delivered[e] * double(m_seen->take[k]);
                }
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
        m_h[n + c] = m_gathered[n + c] * (1.0 / m_recv[n + c]) +
                     (parent >= 0 ? handed_down(n + c, n + std::size_t(parent)) : Rgb());
        if (!m_oriented) continue;
        Rgb* power = &m_bin_power[6 * c];  // own, plus what the parent handed down (added below)
        std::array<double, 6> sa{}, sb{};
        for (int x = 0; x < 6; ++x) {
            sa[std::size_t(x)] = axis_area_of(k.child[0], x);
            sb[std::size_t(x)] = axis_area_of(k.child[1], x);
        }
        double aa = open_area(k.child[0]), ab = open_area(k.child[1]);
        if (!(aa + ab > 0)) aa = area(k.child[0]), ab = area(k.child[1]);
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
                    m_from_cluster[child] += part * (1.0 / (m_G[child].area * m_recv[child]));
            }
        }
    }
    for (const std::uint32_t i : m_order) {
        const std::size_t up = above(i);
        // (Links an oriented cluster could not orient, ends at one point, went in alike.)
        m_h[i] = m_gathered[i] * (1.0 / m_recv[i]) + (up != SIZE_MAX ? handed_down(i, up) : Rgb()) +
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
            // The open parts' mean (a buried node's: the whole's).
            const bool open = sends(i);
            Rgb sum;
            for (int c = 0; c < 4; ++c) {
                const auto child = std::size_t(node.first_child + c);
                sum += m_next[child] * (m_G[child].area * (open ? m_send[child] : 1.0));
            }
            m_next[i] = sum * (1.0 / (m_G[i].area * m_recv[i]));
        }
    }
    for (std::size_t c = m_nc; c-- > 0;) {
        const auto& k = m_C[c];
        const bool open = sends(n + c);
        const auto weight = [&](std::uint32_t child) { return open ? open_area(child) : area(child); };
        m_next[n + c] =
            (m_next[slot(k.child[0])] * weight(k.child[0]) + m_next[slot(k.child[1])] * weight(k.child[1])) *
            (1.0 / (k.area * m_recv[n + c]));
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

namespace {

/// Per input patch, what its leaves send but their links do not carry (their open areas times
/// B times one less their rows, summed: a single leaf's row strays both ways by its links'
/// mean factors, the patch's sum does not), times the share of its open part's missing rays
/// that met a back side (open_parts.h, weighted by open area), is absorbed there, not escaped.
void back_sides_absorb(const ElementTree& tree, const HierarchyRadiosity& x, const ElementOpenness& open,
                       HierarchicalSolution& out) {
    std::vector<Rgb> missing(tree.root_count());
    std::vector<double> back(tree.root_count(), 0.0), area(tree.root_count(), 0.0);
    for (const std::uint32_t leaf : out.leaves) {
        const double a = tree.geometry()[leaf].area * out.sending_share(leaf);
        if (!(a > 0.0)) continue;
        const std::uint32_t r = tree.node(leaf).root;
        missing[r] += x.B[leaf] * (a * (1.0 - x.rows[leaf]));
        back[r] += a * (leaf < open.back_share.size() ? open.back_share[leaf] : 0.0);
        area[r] += a;
    }
    SolveResult& res = out.result;
    for (std::size_t r = 0; r < missing.size(); ++r) {
        if (!(area[r] > 0.0) || !(back[r] > 0.0)) continue;
        Rgb kept;
        for (int c = 0; c < 3; ++c) kept[c] = std::max(0.0, missing[r][c]) * (back[r] / area[r]);
        res.absorbed_power += kept;
        res.back_absorbed_power += kept;
        res.escaped_power -= kept;
    }
}

}  // namespace

void finish_result(const HierarchyRadiosity& x, const ElementOpenness* open, const SeenEnds* seen,
                   HierarchicalSolution& out) {
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
    // (Cancelled after a round's refinement split the tree: the last openness is an earlier
    // tree's, and the leaves count as open.)
    if (open && open->share.size() != tree.size()) open = nullptr;
    if (seen && (seen->empty() || seen->first.size() != out.links.size() + 1)) seen = nullptr;  // (another round's)
    out.open_share = open && !open->all_open ? open->share : std::vector<double>{};
    std::vector<double> leaf_share;
    if (!out.open_share.empty())
        for (const std::uint32_t leaf : out.leaves) leaf_share.push_back(out.open_share[leaf]);
    gathered_energy_account(tree.geometry(), out.leaves, res, leaf_share);
    if (open && x.rows.size() == tree.size()) back_sides_absorb(tree, x, *open, out);
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
        // What each end sent along the link, and where the other end took it
        // (LinkIteration::sent and gather()), per unit of open area: an end with a list of
        // nodes sends their weighted mean and shares what it takes among them.
        const std::uint32_t a0 = seen ? seen->first[k] : 0, a1 = seen ? seen->middle[k] : 0;
        const std::uint32_t b1 = seen ? seen->first[k + 1] : 0;
        Rgb from_a = B[l.a], from_b = B[l.b];
        if (a0 < a1) from_a = Rgb();
        for (std::uint32_t e = a0; e < a1; ++e) from_a += B[seen->node[e]] * double(seen->weight[e]);
        if (a1 < b1) from_b = Rgb();
        for (std::uint32_t e = a1; e < b1; ++e) from_b += B[seen->node[e]] * double(seen->weight[e]);
        const double power = double(l.fab) * G[l.a].area;  // per unit B, either way round
        const auto take = [&](std::uint32_t end, std::uint32_t first, std::uint32_t last, const Rgb& from) {
            if (first == last) {
                by_elements[end] += from * (power / (G[end].area * out.receiving_share(end)));
                return;
            }
            for (std::uint32_t e = first; e < last; ++e) {
                const std::uint32_t m = seen->node[e];
                by_elements[m] += from * (power * double(seen->weight[e]) / (G[m].area * out.receiving_share(m)));
            }
        };
        take(l.a, a0, a1, from_b);
        take(l.b, a1, b1, from_a);
    }
    for (std::size_t i = 0; i < tree.size(); ++i) {
        const std::int64_t up = tree.node(i).parent;
        if (up >= 0 && (out.sending_share(i) > 0.0 || out.sending_share(std::size_t(up)) <= 0.0))
            by_elements[i] += by_elements[std::size_t(up)];
    }
    out.cluster_irradiance.resize(out.leaves.size());
    for (std::size_t k = 0; k < out.leaves.size(); ++k) {
        const Rgb rest = H[out.leaves[k]] - by_elements[out.leaves[k]];
        for (int c = 0; c < 3; ++c) out.cluster_irradiance[k][c] = std::max(0.0, rest[c]);
    }
}

}  // namespace bounce::hierarchical
