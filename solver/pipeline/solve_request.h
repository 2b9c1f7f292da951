// SPDX-License-Identifier: MIT
// What one solve is asked to do, as both front ends (the `bounce solve` command and Python's
// bounce.solve) state it: the solver, the form-factor method, the meshing, the hierarchical
// refinement and the point data. solve_scene (solve_scene.h) runs it.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/rgb.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"

namespace bounce {

/// The solvers: the four on a fixed mesh (solver/linear) and the hierarchical one, which
/// refines quadtree elements over the patches (solver/refinement).
enum class SolverKind { shooting, gauss_seidel, jacobi, direct, hierarchical };
/// The form-factor estimators of make_form_factor_estimator.
enum class FormFactorMethod { raycast, exact, hemicube, analytic };
/// The point data: gathered at the vertices, also at the patch centres, or averaged (none).
enum class GatherMode { vertices, centres, none };
/// The presets of quality.h, named "draft", "default" (standard: what no preset gives) and "fine".
enum class Quality { draft, standard, fine };

/// The names the options take ("gauss-seidel", "raycast", "vertices"): those of solver_names()
/// (and "hierarchical"), form_factor_methods() and gather_modes().
std::string to_string(SolverKind s);
std::string to_string(FormFactorMethod m);
std::string to_string(GatherMode g);
std::string to_string(Quality q);
/// Every name of each enum, in the order of its values.
std::vector<std::string> solver_kind_names();
std::vector<std::string> form_factor_method_names();
std::vector<std::string> gather_mode_names();
std::vector<std::string> quality_names();

/// How a front end spells an option in its messages. Keys are the command line's flag without
/// its dashes ("display-tolerance"): the command line prints "--display-tolerance", Python the
/// keyword "display_tolerance".
struct OptionNames {
    bool command_line = true;
    std::string operator()(std::string_view key) const;
    static OptionNames python() { return OptionNames{false}; }
};

/// The enum of a name; throws InputError "<option>: unknown, got 'x' (expected one of ...)".
SolverKind parse_solver_kind(const std::string& name, const OptionNames& names = {});
FormFactorMethod parse_form_factor_method(const std::string& name, const OptionNames& names = {});
GatherMode parse_gather_mode(const std::string& name, const OptionNames& names = {});
Quality parse_quality(const std::string& name, const OptionNames& names = {});

/// The patches the hierarchical solver starts from when the meshing is the default one: it
/// refines where the light needs it, so it starts coarse.
inline constexpr std::size_t kCoarseTargetPatches = 30;

/// True when `a` and `b` cut a scene into the same patches (every field equal).
bool same_meshing(const MeshingOptions& a, const MeshingOptions& b);

/// True when no meshing was asked for (no max_area, max_edge or patch count other than the
/// default): the hierarchical solver then meshes kCoarseTargetPatches roots of its own.
bool default_meshing(const MeshingOptions& m);

/// One solve, as plain values. Optional fields tell given from default where a given value
/// changes what happens (the hierarchical solver takes a given tolerance; the patch solvers'
/// own options are refused by it).
struct SolveRequest {
    /// The preset the request was filled from (apply_quality, quality.h); the settings name it
    /// unless it is the standard one.
    std::optional<Quality> quality;

    // The patches.
    MeshingOptions meshing;  // as loaded; the hierarchical solver may start coarser
    int element_split = 1;   // shooting: K x K receiving elements per patch
    std::string visibility = visibility_backends().front();
    bool flip = false;  // the scene was loaded turned round (the settings say so)

    // The solver.
    SolverKind solver = SolverKind::shooting;
    bool adaptive = false;                // hierarchical, power epsilon kAdaptivePowerEpsilon unless given
    std::optional<double> tolerance;      // 1e-3 (hierarchical 1e-6)
    std::size_t max_iterations = 0;       // shots or sweeps; 0: the solver's default
    std::optional<double> max_seconds;    // patch solvers: 0, no limit
    std::optional<double> sor;            // jacobi and gauss-seidel: 1
    std::optional<bool> overshoot;        // shooting: off
    std::optional<std::size_t> cache_mb;  // shooting: SolverOptions' 1024 MB
    std::optional<std::size_t> series;    // a snapshot every N shots or sweeps (SolveHooks::snapshot)
    std::size_t max_matrix_mb = 2048;     // refuse a larger form-factor matrix
    bool residuals = false;               // shooting: build the matrix too, to log residuals
    /// Patch solvers with visibility: solve on the patches' open parts (open_parts.h); the
    /// hierarchical solver: on the elements' (element_open_shares.h); false: whole patches and
    /// elements, with rows as the form factors give them.
    bool open_parts = true;
    /// With open parts, where the whole matrix fits (the matrix solvers; shooting within its
    /// cache): reciprocal rows that sum to the open share on closed parts
    /// (balanced_form_factors.h); false: rows as sampled, each shot scaled.
    bool balance = true;
    std::optional<std::vector<Rgb>> reference;  // B per patch: the log's error columns
    std::vector<std::string> retired;           // keys of retired options that were given (refused)

    // Form factors.
    FormFactorMethod method = FormFactorMethod::raycast;
    FormFactorOptions form_factors;  // visibility_rays 0: the method's default

    // Hierarchical refinement (SolverKind::hierarchical and adaptive).
    double link_epsilon = HierarchicalOptions{}.link_epsilon;
    double power_epsilon = 0.0;  // 0: off (adaptive: kAdaptivePowerEpsilon)
    int refine_rounds = HierarchicalOptions{}.refine_rounds;
    int max_level = HierarchicalOptions{}.max_level;
    bool clustering = true;

    // The point data.
    GatherMode gather = GatherMode::vertices;
    /// Unset: kPatchDisplayTolerance for the patch solvers (0 with element_split > 1 or a
    /// series), kSuggestedDisplayTolerance with adaptive, 0 for the hierarchical solver.
    std::optional<double> display_tolerance;
    /// The display tolerance of the patch solvers (patch_display_refinement.h).
    double patch_display_tolerance() const;

    /// True for the solvers that refine quadtree elements (hierarchical, adaptive).
    bool refines() const { return adaptive || solver == SolverKind::hierarchical; }

    /// Throws InputError, naming the option as `names` spells it, when a value is out of its
    /// range or the options do not combine (what the command line refused, in its words).
    void validate(const OptionNames& names = {}) const;
};

}  // namespace bounce
