// SPDX-License-Identifier: MIT
#include "solver/refinement/adaptive_radiosity.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/linear/convergence.h"
#include "solver/linear/solver.h"
#include "solver/visibility/visibility.h"

namespace bounce {
namespace {

/// The state shared by the adaptive and the uniform runs: the tree, element rows and corner
/// rows over the patches, and the patch-level solve.
class TwoLevelSystem {
public:
    TwoLevelSystem(const std::vector<Patch>& patches, const Visibility& visibility, const AdaptiveOptions& o)
        : m_tree(patches),
          m_options(o),
          m_ff(m_tree.geometry(), &visibility, with_rays_only(with_default_rays(o.form_factors, kRefinementRays))),
          m_start(std::chrono::steady_clock::now()) {
        if (patches.empty()) throw std::invalid_argument("adaptive subdivision: no patches");
    }

    ElementTree& tree() { return m_tree; }

    /// Computes what the current leaves need (rows of new elements and corners), solves the
    /// patch system and every element's radiosity and estimate.
    void solve(AdaptiveSolution& out) {
        const std::size_t np = m_tree.root_count();
        out.leaves = m_tree.leaves();
        const auto& L = out.leaves;
        const auto& G = m_tree.geometry();
        compute_rows(L);

        // Patch level: F_pq = sum over elements e of p of (A_e / A_p) g_e[q].
        std::vector<float> F(np * np, 0.0f);
        std::vector<double> acc(np * np, 0.0);
        for (const std::uint32_t e : L) {
            const std::uint32_t p = m_tree.node(e).root;
            const double w = G[e].area / m_tree.roots()[p].area;
            const auto& g = m_rows.at(e);
            for (std::size_t q = 0; q < np; ++q) acc[p * np + q] += w * g[q];
        }
        for (std::size_t k = 0; k < F.size(); ++k) F[k] = float(acc[k]);
        const FormFactorMatrix matrix = FormFactorMatrix::from_values(np, std::move(F));
        const MatrixFormFactor rows(matrix, "raycast");
        SolverOptions so;
        so.tolerance = m_options.tolerance;
        so.cancel = m_options.cancel;
        so.ambient = false;
        const SolveResult patch = make_solver("gauss-seidel", {m_tree.roots(), &rows, &matrix}, so)->solve();

        // Elements gather from the patches.
        SolveResult& res = out.result;
        const std::size_t n = L.size();
        res = SolveResult();
        res.solver = "adaptive";
        res.form_factors = "raycast";
        res.steps = patch.steps;
        res.converged = patch.converged;
        res.status = patch.status;
        res.residual = patch.residual;
        res.radiosity.resize(n);
        res.irradiance.resize(n);
        res.unshot.assign(n, Rgb());
        double area = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const Patch& g = G[L[i]];
            const auto& row = m_rows.at(L[i]);
            Rgb h;
            for (std::size_t q = 0; q < np; ++q)
                if (row[q] != 0.0f) h += patch.radiosity[q] * double(row[q]);
            res.irradiance[i] = h;
            res.radiosity[i] = g.emission + g.reflectance * h;
            area += g.area;
        }
        gathered_energy_account(G, L, res);
        // Scale of the estimates: the mean square reflected radiosity, summed over channels
        // (emitters left out, or the light's E would swamp every estimate).
        double norm = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const Rgb r = res.radiosity[i] - G[L[i]].emission;
            norm += G[L[i]].area * (r.r * r.r + r.g * r.g + r.b * r.b);
        }
        norm = std::max(norm / area, 1e-300);

        // est_e^2 = mean over corners of sum_c (B_c(x) - B_e,c)^2 / norm: the element's share
        // of the relative RMS error of a constant element, estimated from its corners.
        out.estimate.assign(n, 0.0);
        double sum_sq = 0.0, max_est = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const auto& node = m_tree.node(L[i]);
            const Patch& g = G[L[i]];
            double sq = 0.0;
            for (int k = 0; k < node.corner_count; ++k) {
                const auto& row = m_corners.at({node.root, node.corners[k].x, node.corners[k].y});
                Rgb h;
                for (std::size_t q = 0; q < np; ++q)
                    if (row[q] != 0.0f) h += patch.radiosity[q] * double(row[q]);
                const Rgb d = g.reflectance * h - g.reflectance * res.irradiance[i];
                sq += d.r * d.r + d.g * d.g + d.b * d.b;
            }
            const double est = std::sqrt(sq / node.corner_count / norm);
            out.estimate[i] = est;
            sum_sq += g.area * est * est;
            max_est = std::max(max_est, est);
        }
        res.seconds = seconds();
        out.rounds.push_back({n, max_est, std::sqrt(sum_sq / area), res.seconds});
        if (m_options.progress) m_options.progress(out.rounds.size(), out.rounds.back());
    }

    /// The form-factor rows of the leaves and of their corners not computed before.
    void compute_rows(const std::vector<std::uint32_t>& L) {
        const std::size_t np = m_tree.root_count();
        // Element rows g_e[q] = F(e -> q), for leaves not seen before.
        std::vector<std::uint32_t> todo;
        for (const std::uint32_t e : L)
            if (!m_rows.count(e)) todo.push_back(e);
        std::vector<std::vector<float>> fresh(todo.size());
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, todo.size(), 4), [&](const auto& r) {
            for (std::size_t k = r.begin(); k != r.end(); ++k) {
                fresh[k].resize(np);
                for (std::size_t q = 0; q < np; ++q) fresh[k][q] = float(m_ff.pair(todo[k], q));
            }
        });
        for (std::size_t k = 0; k < todo.size(); ++k) m_rows.emplace(todo[k], std::move(fresh[k]));
        // Corner rows, keyed by (root, parameters): corners shared within a patch are computed once.
        std::vector<CornerKey> corner_todo;
        for (const std::uint32_t e : L) {
            const auto& n = m_tree.node(e);
            for (int k = 0; k < n.corner_count; ++k) {
                const CornerKey key{n.root, n.corners[k].x, n.corners[k].y};
                if (!m_corners.count(key)) {
                    m_corners.emplace(key, std::vector<float>());
                    corner_todo.push_back(key);
                }
            }
        }
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, corner_todo.size(), 4), [&](const auto& r) {
            for (std::size_t k = r.begin(); k != r.end(); ++k) {
                const CornerKey& key = corner_todo[k];
                const Patch& root = m_tree.roots()[std::get<0>(key)];
                // A corner on the patch's boundary may sit on a junction with another wall,
                // where the point kernel jumps (the wall's plane passes through it): evaluate a
                // hair inside, 1e-4 of the way to the patch's centre.
                const glm::dvec2 centre = root.vertex_count == 4 ? glm::dvec2(0.5, 0.5) : glm::dvec2(1.0 / 3, 1.0 / 3);
                const glm::dvec2 uv(std::get<1>(key), std::get<2>(key));
                const glm::dvec3 x = m_tree.point(std::get<0>(key), uv + 1e-4 * (centre - uv));
                std::vector<float> row(np);
                const std::uint64_t stream = std::hash<double>()(std::get<1>(key)) * 31 +
                                             std::hash<double>()(std::get<2>(key)) +
                                             (std::uint64_t(std::get<0>(key)) << 40);
                for (std::size_t q = 0; q < np; ++q)
                    row[q] = q == std::get<0>(key) ? 0.0f : float(m_ff.point_factor(x, root.normal, q, stream));
                m_corners.at(key) = std::move(row);  // the map's shape does not change here
            }
        });
    }

    double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count(); }

private:
    using CornerKey = std::tuple<std::uint32_t, double, double>;
    ElementTree m_tree;
    AdaptiveOptions m_options;
    RaycastFormFactor m_ff;  // over m_tree.geometry(), which grows as elements split
    std::map<std::uint32_t, std::vector<float>> m_rows;
    std::map<CornerKey, std::vector<float>> m_corners;
    std::chrono::steady_clock::time_point m_start;
};

AdaptiveSolution finish(TwoLevelSystem& system, AdaptiveSolution&& s) {
    s.tree = system.tree();
    return std::move(s);
}

}  // namespace

AdaptiveSolution solve_adaptive(const std::vector<Patch>& patches, const Visibility& visibility,
                                const AdaptiveOptions& options) {
    if (!(options.target_error > 0)) throw std::invalid_argument("adaptive subdivision: the target error must be > 0");
    TwoLevelSystem system(patches, visibility, options);
    AdaptiveSolution s{ElementTree({}), {}, {}, {}, {}};
    system.solve(s);
    for (int round = 1; round < options.max_rounds; ++round) {
        if (options.cancel && options.cancel->load()) break;
        if (s.rounds.back().rms_estimate <= options.target_error) break;
        // An element adds A_e est_e^2 to the squared RMS estimate. Split the largest
        // contributions first until half of the total is covered, within the budget (a split
        // adds three elements). A discontinuity keeps est_e near 1 at any size, but its
        // elements' contributions shrink fourfold with each split, so the budget moves on to
        // smooth gradients instead of resolving one shadow edge forever.
        const auto& G = system.tree().geometry();
        std::vector<std::size_t> order;
        double total = 0.0;
        for (std::size_t i = 0; i < s.leaves.size(); ++i) {
            const double c = G[s.leaves[i]].area * s.estimate[i] * s.estimate[i];
            total += c;
            if (c > 0 && system.tree().node(s.leaves[i]).level < options.max_level) order.push_back(i);
        }
        auto contribution = [&](std::size_t i) { return G[s.leaves[i]].area * s.estimate[i] * s.estimate[i]; };
        std::stable_sort(order.begin(), order.end(),
                         [&](std::size_t a, std::size_t b) { return contribution(a) > contribution(b); });
        std::size_t count = s.leaves.size();
        std::vector<std::uint32_t> to_split;
        double covered = 0.0;
        for (const std::size_t i : order) {
            if (count + 3 > options.max_elements || covered >= 0.5 * total) break;
            covered += contribution(i);
            to_split.push_back(s.leaves[i]);
            count += 3;
        }
        if (to_split.empty()) break;
        for (const std::uint32_t leaf : to_split) system.tree().split(leaf);
        system.solve(s);
    }
    return finish(system, std::move(s));
}

AdaptiveSolution solve_uniform_elements(const std::vector<Patch>& patches, const Visibility& visibility, int level,
                                        const AdaptiveOptions& options) {
    TwoLevelSystem system(patches, visibility, options);
    for (int l = 0; l < level; ++l)
        for (const std::uint32_t leaf : system.tree().leaves()) system.tree().split(leaf);
    AdaptiveSolution s{ElementTree({}), {}, {}, {}, {}};
    system.solve(s);
    return finish(system, std::move(s));
}

double rms_difference(const AdaptiveSolution& a, const AdaptiveSolution& ref) {
    return rms_difference(a.tree, a.leaves, a.result.radiosity, ref);
}

double rms_difference(const ElementTree& tree, const std::vector<std::uint32_t>& leaves,
                      const std::vector<Rgb>& radiosity, const AdaptiveSolution& ref) {
    if (tree.root_count() != ref.tree.root_count() || radiosity.size() != leaves.size())
        throw std::invalid_argument("rms_difference: the solutions are over different patches");
    std::map<std::uint32_t, std::size_t> index;
    for (std::size_t i = 0; i < leaves.size(); ++i) index[leaves[i]] = i;
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < ref.leaves.size(); ++i) {
        const auto& node = ref.tree.node(ref.leaves[i]);
        glm::dvec2 centre(0.0);
        for (int k = 0; k < node.corner_count; ++k) centre += node.corners[k];
        centre /= double(node.corner_count);
        const std::size_t j = index.at(tree.locate(node.root, centre));
        const Patch& g = ref.tree.geometry()[ref.leaves[i]];
        for (int c = 0; c < 3; ++c) {
            const double d = radiosity[j][c] - ref.result.radiosity[i][c];
            const double reflected = ref.result.radiosity[i][c] - g.emission[c];
            num += g.area * d * d;
            den += g.area * reflected * reflected;
        }
    }
    return std::sqrt(num / den);
}

}  // namespace bounce
