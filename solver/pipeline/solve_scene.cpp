// SPDX-License-Identifier: MIT
#include "solver/pipeline/solve_scene.h"

#include <algorithm>
#include <chrono>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "mesh/scene/errors.h"
#include "mesh/scene/specular_occluders.h"
#include "solver/form_factors/balanced_form_factors.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/open_parts.h"
#include "solver/form_factors/raycast_form_factor.h"
#include "solver/gather/hierarchical_point_values.h"
#include "solver/gather/point_values.h"
#include "solver/linear/convergence.h"
#include "solver/linear/shooting_solver.h"
#include "solver/linear/solver.h"
#include "solver/linear/winding_check.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

namespace bounce {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

bool cancelled(const SolveHooks& hooks) { return hooks.cancel && hooks.cancel->load(); }

void stage_end(const SolveHooks& hooks) {
    if (hooks.stage_end) hooks.stage_end();
}

std::shared_ptr<const PatchMesh> mesh_with(const Scene& scene, const MeshingOptions& m, const SolveHooks& hooks) {
    return hooks.mesh ? hooks.mesh(m) : std::make_shared<const PatchMesh>(scene, m);
}

void check_memory(const SolveHooks& hooks, const std::string& what, double bytes) {
    if (hooks.check_memory) hooks.check_memory(what, bytes);
}

/// The orientation warning: faces that seem wound clockwise seen from their front, named, with
/// --flip (winding_check.h). Empty when nothing looks wrong.
std::optional<std::string> winding_warning(const Scene& scene, const std::vector<Patch>& patches,
                                           const SolveResult& result) {
    const WindingReport w = check_winding(patches, result);
    if (!w.suspicious()) return std::nullopt;
    auto name = [&](int s) { return describe(scene.surfaces[s].where, scene.surfaces[s].object); };
    std::ostringstream msg;
    msg.precision(3);
    msg << "orientation: " << 100.0 * w.escaped_fraction << "% of the emitted power escapes or meets back sides";
    for (const int s : w.dark_emitters) msg << "; the emitter " << name(s) << " reaches no surface";
    msg << "; with every face turned round, " << 100.0 * w.reach_turned << "% of the emitters' first bounce would land"
        << " on the scene instead of " << 100.0 * w.reach_as_wound
        << "%. Faces seem wound clockwise seen from their front; likely:";
    for (std::size_t k = 0; k < w.likely_faces.size(); ++k) msg << (k ? ", " : " ") << name(w.likely_faces[k]);
    msg << ". --flip turns every face (in JSON, \"flip\": true on an object)";
    return msg.str();
}

/// No patch can send out more than all its power: a row above 1 is form-factor error,
/// amplified by 1 / (1 - rho) in a bright closed scene.
void check_rows(const std::vector<Patch>& patches, const FormFactorMatrix& matrix, std::vector<std::string>& warnings) {
    const auto sums = matrix.row_sums();
    const double over = sums.empty() ? 0.0 : *std::max_element(sums.begin(), sums.end()) - 1.0;
    std::ostringstream w;
    if (over > 1e-3) {
        w << "form-factor rows sum to up to 1 + " << over
          << " (> 1 + 1e-3); --form-factors exact keeps rows within 1e-6 of the truth";
        warnings.push_back(w.str());
    }
    const double bound = contraction_bound(patches, sums);
    if (bound >= 1.0) {
        w.str("");
        w << "max rho_i * sum_j F_ij = " << bound
          << " >= 1: the iteration may not converge (reflectance 1 in a closed scene, or row sums above 1)";
        warnings.push_back(w.str());
    }
}

/// Shooting never holds whole rows; the power it shot that arrived beyond 100% is the rows'
/// surplus over 1, weighted by the shots (what a bright closed scene amplifies by 1/(1-rho)).
void check_shots(const SolveResult& res, std::vector<std::string>& warnings) {
    const double shot = res.shot_power.sum();
    if (!(shot > 0)) return;
    const double surplus = -res.escaped_power.sum() / shot;
    if (surplus <= 1e-3) return;
    std::ostringstream w;
    w << "the form-factor rows of the shots sum to 1 + " << surplus
      << " on average (> 1 + 1e-3): the solution gains energy; --form-factors exact keeps rows within 1e-6 of the "
         "truth";
    warnings.push_back(w.str());
}

std::string over_budget_note(const std::string& pairs) {
    std::ostringstream n;
    n << "point data averaged, not gathered: " << pairs << " is beyond the gather's budget of " << kMaxGatherPairs
      << " pairs";
    return n.str();
}

/// Runs a point gather (skipped when cancelled or not asked), timing it and noting an
/// over-budget gather.
template <class Gather>
void gather_points(const SolveRequest& r, const SolveHooks& hooks, SolvedScene& out, const std::string& pairs,
                   Gather&& gather) {
    if (r.gather == GatherMode::none || cancelled(hooks)) return;
    const double before = out.result.seconds;
    const GatherOutcome outcome = gather();
    stage_end(hooks);
    out.gather_seconds = out.result.seconds - before;
    out.gathered = outcome == GatherOutcome::gathered;
    if (outcome == GatherOutcome::over_budget) out.notes.push_back(over_budget_note(pairs));
}

HierarchicalOptions hierarchical_options(const SolveRequest& r, const SolveHooks& hooks) {
    HierarchicalOptions h;
    h.link_epsilon = r.link_epsilon;
    h.power_epsilon = r.adaptive ? adaptive_power_epsilon(r.power_epsilon) : r.power_epsilon;
    h.refine_rounds = r.refine_rounds;
    h.max_level = r.max_level;
    h.clustering = r.clustering;
    if (r.tolerance) h.tolerance = *r.tolerance;
    if (r.max_iterations > 0) h.max_iterations = r.max_iterations;  // 0: the default
    h.form_factors = r.form_factors;
    h.cancel = hooks.cancel;
    if (hooks.items)
        h.progress = [&hooks](const std::string& stage, std::size_t done, std::size_t total) {
            hooks.items(stage.c_str(), done, total);
        };
    return h;
}

/// Hierarchical radiosity (and adaptive, its power bound) on quadtree elements over the
/// patches, exported as the conforming mesh of the leaves.
SolvedScene solve_refining(const Scene& scene, const SolveRequest& r, const SolveHooks& hooks) {
    MeshingOptions roots = r.meshing;
    if (default_meshing(roots)) roots.target_patches = kCoarseTargetPatches;
    const auto mesh = mesh_with(scene, roots, hooks);
    const auto start = Clock::now();
    const auto visibility = make_visibility(r.visibility, mesh->patches(), specular_occluders(scene));
    SolvedScene out;
    out.patches = mesh->size();
    std::ostringstream settings;
    settings << "patches=" << mesh->size()
             << " rays=" << with_default_rays(r.form_factors, kRefinementRays).visibility_rays
             << " seed=" << r.form_factors.seed;
    HierarchicalOptions h = hierarchical_options(r, hooks);
    h.open_parts = r.open_parts;
    h.covered = scene.covered;
    HierarchicalSolution sol = solve_hierarchical(mesh->patches(), *visibility, h);
    stage_end(hooks);
    auto elements = std::make_shared<PatchMesh>(sol.tree.conforming_mesh(sol.leaves));
    elements->set_specular_faces(mesh->specular_faces());  // mirrors and glass stay in the export
    out.result = std::move(sol.result);
    settings << hierarchical_settings(h, sol);
    out.hierarchy = HierarchySummary{sol.leaves.size(), sol.links.size(), sol.cluster_links,
                                     sol.clusters,      h.refine_rounds,  h.power_epsilon};
    out.warnings = elements->warnings();
    // The elements tile the patches: the patches' visibility is theirs, with fewer triangles
    // to trace against (hierarchical_point_values.h).
    DisplayRefinement display{r.display_tolerance.value_or(0.0)};
    if (r.adaptive && r.gather == GatherMode::vertices)
        display.tolerance = adaptive_display_tolerance(r.display_tolerance);
    const std::string pairs =
        std::to_string(elements->mesh().n_vertices()) +
        " vertices (and, with a power epsilon, the elements' centres) x the links along their elements' paths";
    const bool gathering = r.gather != GatherMode::none && !cancelled(hooks);
    gather_points(r, hooks, out, pairs, [&] {
        return gather_hierarchical_point_values(sol, *elements, *visibility, out.result, to_string(r.gather), display,
                                                hooks.cancel, hooks.items);
    });
    if (gathering) settings << " display_tolerance=" << display.tolerance << " display_cells=" << elements->size();
    out.result.seconds = seconds_since(start);
    if (!cancelled(hooks))
        if (auto w = winding_warning(scene, elements->patches(), out.result)) out.warnings.push_back(*w);
    out.settings = settings.str();
    out.mesh = std::move(elements);
    return out;
}

/// The whole matrix, or, for shooting that builds it only to balance its rows, nothing when
/// interrupted: shooting then returns its starting state marked interrupted, as when it is
/// interrupted before its first shot.
std::optional<FormFactorMatrix> build_matrix(const FormFactorEstimator& ff, std::size_t n, std::size_t limit,
                                             const SolveHooks& hooks, bool shooting) {
    try {
        FormFactorMatrix m = FormFactorMatrix::build(ff, n, limit, hooks.rows, hooks.cancel);
        stage_end(hooks);
        return m;
    } catch (const Interrupted&) {
        if (!shooting) throw;
        return std::nullopt;
    }
}

SolverOptions solver_options(const SolveRequest& r, const SolveHooks& hooks) {
    SolverOptions so;
    if (r.tolerance) so.tolerance = *r.tolerance;
    so.max_iterations = r.max_iterations;
    so.max_seconds = r.max_seconds.value_or(so.max_seconds);
    so.sor = r.sor.value_or(so.sor);
    so.overshoot = r.overshoot.value_or(so.overshoot);
    so.cache_mb = r.cache_mb.value_or(so.cache_mb);
    so.max_matrix_mb = r.max_matrix_mb;
    so.cancel = hooks.cancel;
    if (r.reference) so.reference = &*r.reference;
    if (hooks.solve) so.progress = hooks.solve;
    return so;
}

/// Shooting balances its rows (the whole matrix) only when they fit its row cache and the
/// front end's memory check allows them; refused, it shoots rows as sampled, computed as it
/// shoots (as with SolveRequest::balance false), and says so in a warning.
bool shooting_balances(const SolveHooks& hooks, std::size_t n, std::size_t cache_mb,
                       std::vector<std::string>& warnings) {
    if (FormFactorMatrix::bytes_for(n) > cache_mb << 20) return false;
    try {
        check_memory(hooks, "the balanced form-factor matrix (" + std::to_string(n) + " patches)",
                     double(FormFactorMatrix::bytes_for(n)));
    } catch (const ResourceLimitError& e) {
        warnings.push_back(std::string(e.what()) +
                           ": shooting on rows as sampled, computed as it shoots, not balanced (as --no-balance)");
        return false;
    }
    return true;
}

std::string patch_settings(const SolveRequest& r, const SolverOptions& so, bool balanced, std::size_t patches,
                           const PatchMesh& mesh) {
    std::ostringstream s;
    s << "patches=" << patches << " elements=" << mesh.size() << " edge=" << mesh.edge_length()
      << " solver=" << to_string(r.solver) << " sor=" << so.sor << " method=" << to_string(r.method)
      << " rays=" << with_default_rays(r.form_factors, kPatchPairRays).visibility_rays
      << " receiver_samples=" << r.form_factors.receiver_samples
      << " hemicube_res=" << r.form_factors.hemicube_resolution << " seed=" << r.form_factors.seed
      << " tolerance=" << so.tolerance << (so.open_parts ? " open_parts=1" : "") << (balanced ? " balanced=1" : "")
      << (r.flip ? " flip=1" : "")
      << (r.quality.value_or(Quality::standard) != Quality::standard ? " quality=" + to_string(*r.quality) : "");
    return s.str();
}

/// Solves `patches` with hooks.added_emission's light added, as often as it asks (solve_scene.h).
template <class Solve>
SolveResult solve_with_added_emission(const std::vector<Patch>& patches, const SolveHooks& hooks, Solve&& solve) {
    std::optional<std::vector<Rgb>> added = hooks.added_emission(nullptr);
    SolveResult result;
    do {
        std::vector<Patch> lit = patches;
        if (added) {
            if (added->size() != patches.size())
                throw std::invalid_argument("added_emission: one value per patch expected");
            for (std::size_t p = 0; p < lit.size(); ++p) lit[p].emission += (*added)[p];
        }
        result = solve(lit);
    } while (!cancelled(hooks) && (added = hooks.added_emission(&result)));
    return result;
}

/// The solvers on a fixed mesh: the patches, or with element_split > 1 elements that receive
/// from the patches that shoot (PatchToElementFormFactor).
SolvedScene solve_patches(const Scene& scene, const SolveRequest& r, const SolveHooks& hooks) {
    const bool elements = r.element_split > 1;
    MeshingOptions fine = r.meshing;
    fine.element_split = r.element_split;
    // Elements must tile their patches exactly (parents), so contact cuts go with split 1 only.
    if (elements) fine.cut_contacts = false;
    const auto mesh = mesh_with(scene, fine, hooks);
    const auto& P = mesh->patches();
    const double n = double(P.size());
    std::optional<PatchMesh> shooters;
    if (elements) {
        MeshingOptions coarse = r.meshing;
        coarse.cut_contacts = false;
        shooters.emplace(scene, coarse);
    }
    const bool shooting = r.solver == SolverKind::shooting;
    if (!shooting) check_memory(hooks, "the form-factor matrix (" + std::to_string(P.size()) + " patches)", n * n * 4);
    if (r.solver == SolverKind::direct) check_memory(hooks, "the direct solver (matrix and LU factors)", n * n * 12);
    const auto start = Clock::now();
    const auto visibility = make_visibility(r.visibility, P, specular_occluders(scene));
    const std::string method = to_string(r.method);
    const auto ff = elements ? std::make_unique<PatchToElementFormFactor>(
                                   shooters->patches(), P,
                                   r.method == FormFactorMethod::analytic ? nullptr : visibility.get(), r.form_factors)
                             : make_form_factor_estimator(method, P, visibility.get(), r.form_factors);
    SolvedScene out;
    // Open parts need rays, so a method with visibility; elements shoot from whole patches.
    std::optional<std::vector<OpenPart>> open;
    if (r.open_parts && !elements && r.method != FormFactorMethod::analytic && !cancelled(hooks))
        open = open_parts(P, *visibility, 4, 16, 1, hooks.cancel, scene.covered);
    SolverOptions so = solver_options(r, hooks);
    // Balancing needs every row; shooting builds them all when they fit in its row cache and
    // the memory check allows them.
    const bool balance =
        open && r.balance && (!shooting || shooting_balances(hooks, P.size(), so.cache_mb, out.warnings));
    std::optional<FormFactorMatrix> matrix;
    std::optional<FormFactorMatrix> balanced;  // shooting's rows, whole patches
    std::unique_ptr<MatrixFormFactor> balanced_rows;
    if (!shooting || r.residuals || balance) {
        const std::size_t limit = (shooting && !r.residuals ? so.cache_mb : r.max_matrix_mb) << 20;
        matrix = build_matrix(*ff, P.size(), limit, hooks, shooting);
        if (matrix) out.form_factor_seconds = matrix->seconds();
        if (balance && matrix) {
            const auto balance_start = Clock::now();
            matrix = balance_form_factors(std::move(*matrix), P, *open);
            out.form_factor_seconds += seconds_since(balance_start);
        }
        if (matrix && (!shooting || r.residuals)) check_rows(P, *matrix, out.warnings);
        if (shooting && matrix && balance) {
            // Shooting reads the balanced rows from the matrix, so keeps no cache of its own.
            if (r.residuals)
                balanced = *matrix;
            else
                balanced = std::move(matrix), matrix.reset();
            balanced_rows = std::make_unique<MatrixFormFactor>(*balanced, to_string(r.method));
            so.cache_mb = 0;
        }
        if (open && matrix) matrix = open_part_matrix(*matrix, *open);
    }
    if (open) so.open_parts = &*open;
    out.patches = elements ? shooters->size() : mesh->size();
    out.settings = patch_settings(r, so, balance && (!shooting || balanced_rows), out.patches, *mesh);
    if (r.series.value_or(0) > 0 && hooks.snapshot) {
        so.snapshot_every = *r.series;
        so.snapshot = [&](const SolveResult& so_far) {
            SolveResult snap = so_far;
            snap.form_factors = method;
            snap.seconds += out.form_factor_seconds;  // as the final result counts them
            hooks.snapshot(*mesh, out.settings, snap);
        };
    }
    auto solve = [&](const std::vector<Patch>& patches) {
        if (elements)
            return ShootingSolver(patches, *ff, so, nullptr, ElementHierarchy{&shooters->patches(), &mesh->parents()})
                .solve();
        // The matrix solvers see the open parts' areas; shooting reads whole patches' rows and
        // scales them itself.
        const std::vector<Patch> open_patches =
            open && !shooting ? open_part_patches(patches, *open) : std::vector<Patch>{};
        return make_solver(to_string(r.solver),
                           {open_patches.empty() ? patches : open_patches,
                            balanced_rows ? balanced_rows.get() : ff.get(), matrix ? &*matrix : nullptr},
                           so)
            ->solve();
    };
    out.result = hooks.added_emission ? solve_with_added_emission(P, hooks, solve) : solve(P);
    stage_end(hooks);
    out.result.form_factors = method;
    out.result.seconds += out.form_factor_seconds;
    const std::string pairs =
        std::to_string(mesh->mesh().n_vertices()) + " vertices x " + std::to_string(mesh->size()) + " patches";
    // The point data, with display cells (patch_display_refinement.h) where they are asked:
    // they then replace the patches as the cells the result is over.
    const PatchDisplayRefinement display{r.gather == GatherMode::vertices ? r.patch_display_tolerance() : 0.0};
    std::shared_ptr<PatchMesh> cells;
    if (display.tolerance > 0 && !cancelled(hooks)) cells = std::make_shared<PatchMesh>(*mesh);
    gather_points(r, hooks, out, pairs, [&] {
        if (cells)
            return gather_point_values(*cells, *visibility, out.result, to_string(r.gather), display, hooks.cancel,
                                       hooks.items);
        return gather_point_values(*mesh, *visibility, out.result, to_string(r.gather), hooks.cancel, hooks.items);
    });
    out.result.seconds = seconds_since(start);
    if (cells) {
        std::ostringstream shown;
        shown << " display_tolerance=" << display.tolerance << " display_cells=" << cells->size();
        out.settings += shown.str();
    }
    out.mesh = cells ? std::shared_ptr<const PatchMesh>(cells) : mesh;
    if (!cancelled(hooks))
        if (auto w = winding_warning(scene, out.mesh->patches(), out.result)) out.warnings.push_back(*w);
    check_shots(out.result, out.warnings);
    return out;
}

}  // namespace

SolvedScene solve_scene(const Scene& scene, const SolveRequest& request, const SolveHooks& hooks) {
    if (hooks.added_emission && (request.refines() || request.element_split > 1))
        throw std::invalid_argument("added_emission: patch solvers on whole patches only (element_split 1)");
    return request.refines() ? solve_refining(scene, request, hooks) : solve_patches(scene, request, hooks);
}

}  // namespace bounce
