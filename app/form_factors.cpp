// SPDX-License-Identifier: MIT
// bounce form-factors: the whole form-factor matrix of a scene, as CSV, with --check its row
// sums and reciprocity.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "app/command.h"
#include "app/progress_line.h"
#include "app/signals.h"
#include "mesh/meshing/patch_mesh.h"
#include "solver/form_factors/exact_form_factor.h"
#include "solver/form_factors/form_factor_check.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/form_factors/form_factor_matrix.h"
#include "solver/visibility/shaft_culler.h"
#include "solver/visibility/visibility.h"
#include "viewer/pending_output.h"

namespace bounce::app {
namespace {

struct FormFactorCommand {
    std::string output;
    std::string method = "raycast";
    FormFactorOptions ff;
    bool check = false;
    std::size_t max_matrix_mb = 2048;
};

/// Builds the whole matrix, writes "i,j,F_ij,row_sum_i" for its non-zero entries and, with
/// --check, prints row sums and the reciprocity error max |A_i F_ij - A_j F_ji| / (A_i F_ij).
int run_form_factors(const CommonOptions& o, const FormFactorCommand& c) {
    Scene scene;
    PatchMesh mesh = load_and_mesh(o, o.scene, scene);
    const auto& P = mesh.patches();
    const std::size_t n = P.size();
    check_form_factor_memory(o, c.method, c.ff);
    check_memory(o, "the form-factor matrix (" + std::to_string(n) + " patches)", double(n) * double(n) * 4);
    const auto visibility = make_visibility(o.visibility, P, specular_occluders(scene));
    const auto ff = make_form_factor_estimator(c.method, P, visibility.get(), c.ff);
    ProgressLine progress(!o.quiet);
    const auto F = FormFactorMatrix::build(
        *ff, n, c.max_matrix_mb << 20, [&](std::size_t d, std::size_t t) { progress.rows(d, t); }, &g_interrupted);
    progress.finish();
    // The culler splits the row-sum deviation by partial visibility (only --check prints it).
    const std::unique_ptr<ShaftCuller> culler = c.check ? std::make_unique<ShaftCuller>(P) : nullptr;
    const FormFactorCheck check = check_form_factors(P, F, culler.get());
    const std::vector<double>& sums = check.row_sums;
    if (!c.output.empty()) {
        write_text_file(
            c.output,
            [&](std::ostream& csv) {
                csv << "i,j,F_ij,row_sum_i\n";
                csv.precision(9);
                for (std::size_t i = 0; i < n; ++i)
                    for (std::size_t j = 0; j < n; ++j)
                        if (F(i, j) != 0.0f) csv << i << ',' << j << ',' << F(i, j) << ',' << sums[i] << '\n';
            },
            "form-factor CSV");
    }
    if (!o.quiet || c.check) {
        std::cout << "patches " << n << ", method " << c.method << ", " << F.seconds() << " s ("
                  << 1e3 * F.seconds() / double(std::max<std::size_t>(n, 1)) << " ms per row)\n";
    }
    if (c.check) {
        std::cout << row_sum_report(check);
        if (const auto* exact = dynamic_cast<const ExactFormFactor*>(ff.get())) {
            const PairTally t = exact->tally();
            double area = 0;
            for (const auto& p : P) area += p.area;
            std::cout << "pairs: " << t.unoccluded << " unoccluded (exact), " << t.partial << " partially visible, "
                      << t.hidden << " hidden; partially visible pairs carry " << t.partial_area_factor / area
                      << " of the mean row sum, with estimated error " << t.partial_area_error / area
                      << " (area-weighted mean per row)\n";
        }
    }
    return 0;
}

}  // namespace

Command add_form_factors_command(CLI::App& app, CommonOptions& common) {
    auto ffc = std::make_shared<FormFactorCommand>();
    auto* ff_cmd = app.add_subcommand("form-factors", "compute the whole form-factor matrix and check it");
    add_meshing_options(ff_cmd, common);
    ff_cmd->add_option("--method", ffc->method, "raycast, exact, analytic or hemicube")
        ->check(CLI::IsMember(form_factor_methods()));
    ff_cmd->add_option("-o,--output", ffc->output, "CSV of i,j,F_ij,row_sum_i for non-zero entries");
    ff_cmd->add_flag("--check", ffc->check, "print row sums and the reciprocity error");
    ff_cmd->add_option("--max-matrix-mb", ffc->max_matrix_mb, "refuse a matrix larger than this (MB; 2048)");
    add_form_factor_options(ff_cmd, ffc->ff);
    return {ff_cmd, [&common, ffc] { return run_form_factors(common, *ffc); }};
}

}  // namespace bounce::app
