// SPDX-License-Identifier: MIT
#include "solver/refinement/hierarchical_radiosity.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/linear/convergence.h"
#include "solver/visibility/visibility.h"

namespace bounce {
namespace {

struct Link {
    std::uint32_t a, b;  // a gathers from b and b from a
    float fab = 0.0f;    // F_ab; F_ba = F_ab A_a / A_b
};

/// The point of polygon a nearest to x (a convex, planar): x projected onto a's plane, or,
/// when that falls outside, the nearest point of its edges.
glm::dvec3 nearest_point(const Patch& a, const glm::dvec3& x) {
    const glm::dvec3 p = x - a.height(x) * a.normal;
    bool inside = true;
    for (int k = 0; k < a.vertex_count; ++k) {
        const glm::dvec3 u = a.vertices[k], v = a.vertices[(k + 1) % a.vertex_count];
        if (glm::dot(glm::cross(v - u, p - u), a.normal) < 0) inside = false;
    }
    if (inside) return p;
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
    auto at = [&](const glm::dvec3& y) {
        const glm::dvec3 x = y + 1e-4 * (a.centre - y);
        if (b.height(x) <= 0.0) return 0.0;  // behind b: b sends it nothing
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

/// Gather and push-pull until the leaves settle (Jacobi over the hierarchy); B and H hold a
/// value per tree node.
void solve_links(const ElementTree& tree, const std::vector<Link>& links, const HierarchicalOptions& options,
                 std::vector<Rgb>& B, std::vector<Rgb>& H, SolveResult& res) {
    const auto& G = tree.geometry();
    const std::size_t n = tree.size();
    B.resize(n);
    H.assign(n, Rgb());
    std::vector<Rgb> gathered(n), next(n);
    std::vector<std::uint32_t> order;  // parents before children
    for (std::uint32_t r = 0; r < tree.root_count(); ++r) order.push_back(r);
    for (std::size_t k = 0; k < order.size(); ++k)
        if (!tree.node(order[k]).leaf())
            for (int c = 0; c < 4; ++c) order.push_back(std::uint32_t(tree.node(order[k]).first_child + c));
    res.status = "max iterations";
    res.converged = false;
    for (std::size_t it = 0; it < options.max_iterations; ++it) {
        if (options.cancel && options.cancel->load()) {
            res.status = "interrupted";
            break;
        }
        // Gather: every element collects F B over its links, both ways round.
        std::fill(gathered.begin(), gathered.end(), Rgb());
        for (const Link& l : links) {
            if (l.fab == 0.0f) continue;
            const double fab = l.fab, fba = fab * G[l.a].area / G[l.b].area;
            gathered[l.a] += B[l.b] * fab;
            gathered[l.b] += B[l.a] * fba;
        }
        // Push: what an element gathered reaches every leaf below it.
        for (const std::uint32_t i : order) {
            const auto& node = tree.node(i);
            H[i] = gathered[i] + (node.parent >= 0 ? H[std::size_t(node.parent)] : Rgb());
        }
        // Pull: leaves reflect; a parent's radiosity is its children's area-weighted mean.
        for (std::size_t k = order.size(); k-- > 0;) {
            const std::uint32_t i = order[k];
            const auto& node = tree.node(i);
            if (node.leaf()) {
                next[i] = G[i].emission + G[i].reflectance * H[i];
            } else {
                Rgb sum;
                for (int c = 0; c < 4; ++c) {
                    const auto child = std::size_t(node.first_child + c);
                    sum += next[child] * G[child].area;
                }
                next[i] = sum * (1.0 / G[i].area);
            }
        }
        double change = 0.0, mean = 0.0, area = 0.0;
        for (std::uint32_t r = 0; r < tree.root_count(); ++r) {
            mean += next[r].luminance() * G[r].area;
            area += G[r].area;
        }
        mean /= area;
        for (const std::uint32_t i : order)
            if (tree.node(i).leaf()) change = std::max(change, std::abs(next[i].luminance() - B[i].luminance()));
        B.swap(next);
        res.steps += 1;
        if (change <= options.tolerance * std::max(mean, 1e-300)) {
            res.converged = true;
            res.status = "converged";
            break;
        }
    }
}

/// The leaves' radiosity and irradiance, and the energy account, into out.result.
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
}

class Refiner {
public:
    Refiner(ElementTree& tree, const HierarchicalOptions& o, std::vector<double> min_area, std::vector<Rgb>& radiosity,
            double scale)
        : m_tree(tree), m_options(o), m_min_area(std::move(min_area)), m_b(radiosity), m_scale(scale) {}

    /// A link hands every point of a the mean F(a -> b), so it errs at a's leaves by up to
    /// spread(F(x -> b)) B_b. Link when that is below link_epsilon of what the link brings,
    /// F(a -> b) B_b, plus a floor of link_floor of the scene's mean radiosity (BF refinement,
    /// Hanrahan et al. section 4: faint interactions stay coarse), both ways round; else split
    /// the larger. Summed over a leaf's links the error is then at most link_epsilon of its
    /// irradiance plus the floors.
    void refine(std::uint32_t a, std::uint32_t b) {
        const auto& G = m_tree.geometry();
        if (wholly_behind(G[a], G[b]) || wholly_behind(G[b], G[a])) return;
        const Spread ab = point_factor_spread(G[a], G[b]), ba = point_factor_spread(G[b], G[a]);
        const double lb = m_b[b].luminance(), la = m_b[a].luminance();
        const double eps = m_options.link_epsilon, floor = m_options.link_floor * m_scale;
        const bool fine =
            ab.spread * lb <= eps * (ab.mean * lb + floor) && ba.spread * la <= eps * (ba.mean * la + floor);
        const bool split_a = splittable(a), split_b = splittable(b);
        if (fine || (!split_a && !split_b)) {
            links.push_back({a, b});
            return;
        }
        const bool take_a = split_a && (!split_b || G[a].area >= G[b].area);
        const std::uint32_t s = take_a ? a : b, other = take_a ? b : a;
        const std::uint32_t first = children(s);
        for (std::uint32_t k = 0; k < 4; ++k) refine(first + k, other);
    }

    std::vector<Link> links;

private:
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

    ElementTree& m_tree;
    const HierarchicalOptions& m_options;
    std::vector<double> m_min_area;
    std::vector<Rgb>& m_b;
    double m_scale;
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
    HierarchicalSolution out{ElementTree(patches), {}, {}, 0, 0.0};
    ElementTree& tree = out.tree;
    std::vector<double> min_area(patches.size());
    for (std::size_t r = 0; r < patches.size(); ++r)
        min_area[r] = options.min_area > 0 ? options.min_area : patches[r].area / std::pow(4.0, options.max_level);

    // First estimate of B for the oracle: emission plus the ambient term (the emitted power
    // spread over all area and inter-reflected by the mean reflectance).
    double total_area = 0.0;
    Rgb power, rho_area;
    for (const auto& p : patches) {
        total_area += p.area;
        power += p.emission * p.area;
        rho_area += p.reflectance * p.area;
    }
    Rgb ambient;
    for (int c = 0; c < 3; ++c) ambient[c] = power[c] / total_area / std::max(1e-3, 1.0 - rho_area[c] / total_area);
    std::vector<Rgb> B(patches.size());
    for (std::size_t r = 0; r < patches.size(); ++r) B[r] = patches[r].emission + patches[r].reflectance * ambient;

    SolveResult& res = out.result;
    res.solver = "hierarchical";
    res.form_factors = "raycast";
    const RaycastFormFactor ff(tree.geometry(), &visibility, options.form_factors);
    std::vector<Link> links;
    std::vector<Rgb> H;
    for (int round = 0; round < options.refine_rounds; ++round) {
        const double round_start = since_start();
        double scale = 0.0;
        for (std::uint32_t r = 0; r < patches.size(); ++r) scale += B[r].luminance() * patches[r].area;
        scale /= total_area;
        {
            Refiner refiner(tree, options, min_area, B, scale);
            for (std::uint32_t p = 0; p < patches.size(); ++p)
                for (std::uint32_t q = p + 1; q < patches.size(); ++q) refiner.refine(p, q);
            links = std::move(refiner.links);
        }
        // Link form factors with visibility, in parallel (the tree does not change here).
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, links.size(), 256), [&](const auto& r) {
            for (std::size_t k = r.begin(); k != r.end(); ++k) links[k].fab = float(ff.pair(links[k].a, links[k].b));
        });
        out.refine_seconds += since_start() - round_start;
        solve_links(tree, links, options, B, H, res);
        if (res.status == "interrupted") break;
    }
    out.links = links.size();
    finish_result(tree, B, H, out);
    res.seconds = since_start();
    return out;
}

}  // namespace bounce
