// SPDX-License-Identifier: MIT
#include "solver/hierarchical_radiosity.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include "solver/point_polygon_form_factor.h"
#include "solver/raycast_form_factor.h"
#include "solver/visibility.h"

namespace bounce {
namespace {

struct Link {
    std::uint32_t a, b;  // a gathers from b and b from a
    float fab = 0.0f;    // F_ab; F_ba = F_ab A_a / A_b
};

/// True when some vertex of q is strictly in front of p.
bool any_in_front(const Patch& p, const Patch& q) {
    const double tol = 1e-12 * std::sqrt(p.area + q.area);
    for (int k = 0; k < q.vertex_count; ++k)
        if (glm::dot(p.normal, q.vertices[k] - p.vertices[0]) > tol) return true;
    return false;
}

struct Spread {
    double mean = 0.0, spread = 0.0;
};

/// F(dA_x -> b) over a, sampled at the centre and the corners: its mean and how much it varies
/// (max - min). A link hands every point of a the mean, so the spread bounds the error it
/// makes, per unit B_b, at the leaves below a. Corners are taken a hair (1e-4 of the way)
/// towards the centre: a corner shared with b would make the kernel singular.
Spread point_factor_spread(const Patch& a, const Patch& b) {
    auto at = [&](const glm::dvec3& x) {
        if (glm::dot(b.normal, x - b.vertices[0]) <= 0.0) return 0.0;  // behind b: b sends it nothing
        return point_polygon_form_factor(x, a.normal, b.polygon());
    };
    double lo = at(a.centre), hi = lo, sum = lo;
    for (int k = 0; k < a.vertex_count; ++k) {
        const double f = at(a.vertices[k] + 1e-4 * (a.centre - a.vertices[k]));
        lo = std::min(lo, f);
        hi = std::max(hi, f);
        sum += f;
    }
    return {sum / (a.vertex_count + 1), hi - lo};
}

class Refiner {
public:
    Refiner(ElementTree& tree, const HierarchicalOptions& o, std::vector<double> min_area)
        : m_tree(tree), m_options(o), m_min_area(std::move(min_area)) {}

    void refine(std::uint32_t a, std::uint32_t b) {
        const auto& G = m_tree.geometry();
        if (!any_in_front(G[a], G[b]) || !any_in_front(G[b], G[a])) return;
        // Oracle: how much the unoccluded point-to-polygon factor to the other element varies
        // over each of the two (exact over the far element, sampled over the near one),
        // relative to its mean. Then the error of all links together, at any leaf, is at most
        // link_epsilon of its irradiance; the 1e-3 floor stops refining interactions too
        // faint to matter.
        const Spread ab = point_factor_spread(G[a], G[b]), ba = point_factor_spread(G[b], G[a]);
        const double eps = m_options.link_epsilon;
        const bool fine = ab.spread <= eps * (ab.mean + 1e-3) && ba.spread <= eps * (ba.mean + 1e-3);
        const bool split_a = splittable(a), split_b = splittable(b);
        if (fine || (!split_a && !split_b)) {
            links.push_back({a, b});
            return;
        }
        // Split the larger of the two (Hanrahan et al.: the one that subtends more).
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
        if (m_tree.node(i).leaf()) return std::uint32_t(m_tree.split(i));
        return std::uint32_t(m_tree.node(i).first_child);
    }

    ElementTree& m_tree;
    const HierarchicalOptions& m_options;
    std::vector<double> m_min_area;
};

}  // namespace

HierarchicalSolution solve_hierarchical(const std::vector<Patch>& patches, const Visibility& visibility,
                                        const HierarchicalOptions& options) {
    if (patches.empty()) throw std::invalid_argument("hierarchical radiosity: no patches");
    if (!(options.link_epsilon > 0)) throw std::invalid_argument("hierarchical radiosity: the link epsilon must be > 0");
    const auto start = std::chrono::steady_clock::now();
    HierarchicalSolution out{ElementTree(patches), {}, {}, 0, 0.0};
    ElementTree& tree = out.tree;
    std::vector<double> min_area(patches.size());
    for (std::size_t r = 0; r < patches.size(); ++r)
        min_area[r] = options.min_area > 0 ? options.min_area : patches[r].area / std::pow(4.0, options.max_level);

    Refiner refiner(tree, options, min_area);
    for (std::uint32_t p = 0; p < patches.size(); ++p)
        for (std::uint32_t q = p + 1; q < patches.size(); ++q) refiner.refine(p, q);
    std::vector<Link>& links = refiner.links;
    // Link form factors with visibility, in parallel (the tree no longer changes).
    const RaycastFormFactor ff(tree.geometry(), &visibility, options.form_factors);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, links.size(), 256), [&](const auto& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) links[k].fab = float(ff.pair(links[k].a, links[k].b));
    });
    out.links = links.size();
    if (std::getenv("HRDEBUG")) {
        std::vector<double> rs(tree.size(), 0.0);
        for (const Link& l : links) { rs[l.a] += l.fab; rs[l.b] += double(l.fab) * tree.geometry()[l.a].area / tree.geometry()[l.b].area; }
        double lo = 1e9, hi = -1e9; std::uint32_t worst = 0;
        for (const std::uint32_t leaf : tree.leaves()) {
            double sum = 0; std::int32_t i = std::int32_t(leaf);
            while (i >= 0) { sum += rs[std::size_t(i)]; i = tree.node(std::size_t(i)).parent; }
            if (sum < lo) { lo = sum; worst = leaf; }
            hi = std::max(hi, sum);
        }
        const auto& g = tree.geometry()[worst];
        std::fprintf(stderr, "row sums over leaves: [%g, %g]; worst leaf level %d centre %g %g %g area %g\n", lo, hi, tree.node(worst).level, g.centre.x, g.centre.y, g.centre.z, g.area);
    }
    out.refine_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    // Gather and push-pull (Jacobi over the hierarchy).
    const auto& G = tree.geometry();
    const std::size_t n = tree.size();
    std::vector<Rgb> B(n), gathered(n), H(n);
    // Initial radiosity: the emission, pulled up as area-weighted means.
    std::vector<std::uint32_t> order;  // parents before children
    for (std::uint32_t r = 0; r < tree.root_count(); ++r) order.push_back(r);
    for (std::size_t k = 0; k < order.size(); ++k)
        if (!tree.node(order[k]).leaf())
            for (int c = 0; c < 4; ++c) order.push_back(std::uint32_t(tree.node(order[k]).first_child + c));
    auto push_pull = [&](std::vector<Rgb>& next) {
        // Push: irradiance gathered at every level reaches the leaves below it.
        for (const std::uint32_t i : order) {
            const auto& node = tree.node(i);
            H[i] = gathered[i] + (node.parent >= 0 ? H[std::size_t(node.parent)] : Rgb());
        }
        // Pull: leaves reflect, parents take their children's area-weighted mean.
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
    };
    std::fill(gathered.begin(), gathered.end(), Rgb());
    push_pull(B);
    double mean = 0.0, area = 0.0;
    SolveResult& res = out.result;
    res.solver = "hierarchical";
    res.form_factors = "raycast";
    res.status = "max iterations";
    std::vector<Rgb> next(n);
    for (std::size_t it = 0; it < options.max_iterations; ++it) {
        if (options.cancel && options.cancel->load()) {
            res.status = "interrupted";
            break;
        }
        std::fill(gathered.begin(), gathered.end(), Rgb());
        for (const Link& l : links) {
            if (l.fab == 0.0f) continue;
            const double fab = l.fab, fba = fab * G[l.a].area / G[l.b].area;
            gathered[l.a] += B[l.b] * fab;
            gathered[l.b] += B[l.a] * fba;
        }
        push_pull(next);
        double change = 0.0;
        mean = 0.0;
        area = 0.0;
        for (std::uint32_t r = 0; r < tree.root_count(); ++r) {
            mean += next[r].luminance() * G[r].area;
            area += G[r].area;
        }
        mean /= area;
        for (const std::uint32_t i : order)
            if (tree.node(i).leaf()) change = std::max(change, std::abs(next[i].luminance() - B[i].luminance()));
        B.swap(next);
        res.steps = it + 1;
        if (change <= options.tolerance * std::max(mean, 1e-300)) {
            res.converged = true;
            res.status = "converged";
            break;
        }
    }
    out.leaves = tree.leaves();
    res.radiosity.resize(out.leaves.size());
    res.irradiance.resize(out.leaves.size());
    res.unshot.assign(out.leaves.size(), Rgb());
    Rgb power, arriving;
    for (std::size_t k = 0; k < out.leaves.size(); ++k) {
        const std::uint32_t i = out.leaves[k];
        res.radiosity[k] = B[i];
        res.irradiance[k] = H[i];
        res.emitted_power += G[i].emission * G[i].area;
        res.absorbed_power += (H[i] - G[i].reflectance * H[i]) * G[i].area;
        arriving += H[i] * G[i].area;
        power += B[i] * G[i].area;
    }
    res.escaped_power = power - arriving;
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

}  // namespace bounce
