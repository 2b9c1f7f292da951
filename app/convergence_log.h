// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "solver/linear/solve_result.h"

namespace bounce::app {

/// Writes a convergence log as CSV: step,seconds,residual,unshot_fraction,rms_error,max_error
/// (empty where a quantity was not computed), through a temporary file. runs[k] used the
/// form factors form_factors[k], which took ff_seconds[k].
void write_log_csv(const std::filesystem::path& path, const std::vector<SolveResult>& runs,
                   const std::vector<std::string>& form_factors, const std::vector<double>& ff_seconds);

}  // namespace bounce::app
