// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mesh/meshing/patch.h"
#include "mesh/scene/errors.h"  // SingularSystemError
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/form_factors/open_parts.h"
#include "solver/linear/solve_result.h"

namespace bounce {

/// Settings shared by every solver; each reads what applies to it.
struct SolverOptions {
    double tolerance = 1e-3;                      // shooting: estimated error left; gathering: relative residual
    std::size_t max_iterations = 0;               // shots or sweeps; 0: no shot limit, 10000 sweeps
    double max_seconds = 0.0;                     // 0: no time limit
    double sor = 1.0;                             // over-relaxation factor for Jacobi and Gauss-Seidel (0, 2)
    bool ambient = true;                          // shooting: keep B + ambient for display
    bool overshoot = false;                       // shooting: over-shoot by rho_i times the ambient term
    std::size_t cache_mb = 1024;                  // shooting: form-factor rows kept for re-shooting patches
    std::size_t max_matrix_mb = 2048;             // direct: refuse larger dense systems
    const std::vector<Rgb>* reference = nullptr;  // for the error columns of the log
    /// Per patch, its part open to the scene (open_parts.h): the solve works on open parts,
    /// so buried parts neither emit nor receive and closed rows send all their light. Shooting
    /// (without elements) takes the whole patches and their rows (or open_part_matrix); the
    /// matrix solvers take open_part_patches and open_part_matrix. Null: whole patches.
    const std::vector<OpenPart>* open_parts = nullptr;
    std::function<void(const SolveProgress&)> progress;  // after every shot or sweep
    const std::atomic<bool>* cancel = nullptr;  // set (e.g. by SIGINT): stop after this step, status "interrupted"
    std::size_t snapshot_every = 0;  // call `snapshot` at step 0 and every this many shots or sweeps (0: never)
    /// The state so far as a result (status "running"): radiosity, steps, seconds, the energy
    /// account and unshot fraction of that moment, and for shooting B plus the ambient term.
    std::function<void(const SolveResult& so_far)> snapshot;
};

/// A radiosity solver: B = E + rho F B per channel.
class Solver {
public:
    virtual ~Solver() = default;
    virtual std::string name() const = 0;
    virtual SolveResult solve() = 0;
};

/// The system a solver works on: the patches, and either rows on demand (shooting) or the full
/// matrix (gathering, direct; shooting also logs residuals when it is given).
struct RadiositySystem {
    const std::vector<Patch>& patches;
    const FormFactorEstimator* rows = nullptr;
    const FormFactorMatrix* matrix = nullptr;
};

/// "shooting", "gauss-seidel", "jacobi" or "direct". Throws std::invalid_argument on an
/// unknown name (listing the valid ones) or when the solver needs the matrix and has none.
std::unique_ptr<Solver> make_solver(const std::string& name, const RadiositySystem& system,
                                    const SolverOptions& options);
std::vector<std::string> solver_names();

}  // namespace bounce
