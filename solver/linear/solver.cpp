// SPDX-License-Identifier: MIT
#include "solver/linear/solver.h"

#include "solver/linear/direct_solver.h"
#include "solver/linear/gathering_solver.h"
#include "solver/linear/shooting_solver.h"

namespace bounce {

std::vector<std::string> solver_names() { return {"shooting", "gauss-seidel", "jacobi", "direct"}; }

std::unique_ptr<Solver> make_solver(const std::string& name, const RadiositySystem& system,
                                    const SolverOptions& options) {
    const bool gathering = name == "gauss-seidel" || name == "jacobi" || name == "direct";
    if (gathering && !system.matrix) throw std::invalid_argument("solver '" + name + "' needs the form-factor matrix");
    if (name == "shooting") {
        if (!system.rows) throw std::invalid_argument("shooting needs form-factor rows");
        return std::make_unique<ShootingSolver>(system.patches, *system.rows, options, system.matrix);
    }
    if (name == "gauss-seidel") return std::make_unique<GatheringSolver>(true, system, options);
    if (name == "jacobi") return std::make_unique<GatheringSolver>(false, system, options);
    if (name == "direct") return std::make_unique<DirectSolver>(system, options);
    std::string valid;
    for (const auto& s : solver_names()) valid += (valid.empty() ? "" : ", ") + s;
    throw std::invalid_argument("unknown solver '" + name + "' (valid: " + valid + ")");
}

}  // namespace bounce
