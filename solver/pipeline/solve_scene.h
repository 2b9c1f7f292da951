// SPDX-License-Identifier: MIT
// The solve pipeline both front ends run: mesh the scene for the request, trace visibility,
// compute form factors, solve (or refine hierarchically), gather the point data, and say what
// looks wrong. The command line (app/solve.cpp) and Python (python/solve.cpp) print or issue
// the warnings and write the files; the numbers come from here alone.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/scene/scene.h"
#include "solver/linear/solve_result.h"
#include "solver/pipeline/solve_request.h"

namespace bounce {

/// How a front end follows and limits the work. Every member may be left empty.
struct SolveHooks {
    const std::atomic<bool>* cancel = nullptr;  // set: stop after this step (the result says "interrupted")
    /// Cuts the scene into patches with these options (the command line applies --max-memory
    /// and says what a large meshing costs; Python hands back the patches load() made). Empty:
    /// PatchMesh(scene, options).
    std::function<std::shared_ptr<const PatchMesh>(const MeshingOptions&)> mesh;
    /// Called before a large allocation with what it is for and its bytes; may throw
    /// ResourceLimitError.
    std::function<void(const std::string& what, double bytes)> check_memory;
    std::function<void(std::size_t done, std::size_t total)> rows;  // form-factor matrix rows
    std::function<void(const SolveProgress&)> solve;                // after each shot or sweep
    /// Refinement and gather stages ("round 1/1: refining links", "gathering: vertices");
    /// from worker threads too.
    std::function<void(const char* stage, std::size_t done, std::size_t total)> items;
    std::function<void()> stage_end;  // after the matrix, the solve and the gather
    /// With SolveRequest::series: the state so far, over `mesh`, with the settings the
    /// solution will have (status "running").
    std::function<void(const PatchMesh& mesh, const std::string& settings, const SolveResult& so_far)> snapshot;
    /// Light added to the patches' emission (W/m^2 per patch, per channel) for solves over the
    /// same form factors: asked before the first solve (so_far null; nothing: none added) and
    /// after each (so_far its solution, before the gather; nothing: the last solve stands).
    /// The two-pass render's photon rounds hand the light mirrors and glass redirect to the
    /// patches it lands on this way. Patch solvers on whole patches only (element_split 1).
    std::function<std::optional<std::vector<Rgb>>(const SolveResult* so_far)> added_emission;
};

/// What a hierarchical solve made, for the front ends' summaries.
struct HierarchySummary {
    std::size_t leaves = 0;         // elements solved (display refinement may add cells after)
    std::size_t links = 0;          // of the last round
    std::size_t cluster_links = 0;  // with a cluster at one end or both
    std::size_t clusters = 0;
    int refine_rounds = 0;
    double power_epsilon = 0.0;  // the one refined with (adaptive's default applied)
};

struct SolvedScene {
    /// The cells `result` is over: the patches, the elements (element_split), or the
    /// conforming mesh of the hierarchical leaves (with their display refinement).
    std::shared_ptr<const PatchMesh> mesh;
    SolveResult result;
    std::string settings;               // "patches=... solver=..." as the written .vtu records it
    std::vector<std::string> warnings;  // likely mistakes in the input or settings, one line each
    std::vector<std::string> notes;     // what was done differently from what was asked, one line each
    bool gathered = false;              // result.point_radiosity holds gathered values
    std::size_t patches = 0;            // input patches: those that shoot to elements, the roots of a hierarchy
    double form_factor_seconds = 0.0;   // building the matrix, included in result.seconds
    double gather_seconds = 0.0;        // the point gather, included in result.seconds
    std::optional<HierarchySummary> hierarchy;
};

/// Solves `scene` as `request` asks (validate() it first). result.seconds is the wall time
/// from the meshed scene to the gathered point data. When hooks.cancel is set the solution
/// so far comes back, not gathered and without the orientation check.
SolvedScene solve_scene(const Scene& scene, const SolveRequest& request, const SolveHooks& hooks = {});

}  // namespace bounce
