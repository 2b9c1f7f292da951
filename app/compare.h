// SPDX-License-Identifier: MIT
// bounce compare: its options, the probe columns its two tables share, and the mesh
// comparison (compare_meshes.cpp) that --meshes runs instead of the solver comparison.
#pragma once

#include <chrono>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "app/common_options.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/linear/solver.h"
#include "solver/reference/probe_classes.h"
#include "solver/reference/probe_score.h"
#include "solver/refinement/hierarchical_radiosity.h"

namespace bounce::app {

struct CompareCommand {
    std::vector<std::string> solvers = {"shooting", "gauss-seidel", "jacobi", "direct"};
    std::vector<std::string> methods = {"raycast", "hemicube"};
    std::string out = "compare";
    SolverOptions options;
    FormFactorOptions ff;
    std::size_t max_matrix_mb = 2048;
    std::size_t max_direct = 4000;
    bool meshes = false;
    int reference_level = 5;  // --meshes: the fine uniform elements (0: none, for large scenes)
    // --meshes: which families run: uniform elements, uniform patch meshes, discontinuity
    // meshes, the receiver-only refinement (what --adaptive ran before), adaptive (what
    // `solve --adaptive` runs: hierarchical refining on power), hierarchical radiosity.
    std::vector<std::string> mesh_methods = {"uniform",  "patches",  "discontinuity",
                                             "receiver", "adaptive", "hierarchical"};
    std::vector<double> targets = {0.2, 0.1, 0.07, 0.05, 0.035};  // --meshes: receiver-only target errors
    // --meshes: hierarchical and adaptive link epsilons, coarse to fine: the rows draw a curve of
    // error against time.
    std::vector<double> link_epsilons = {0.8, 0.4, 0.2, 0.1, 0.05};
    // --meshes: hierarchical quadtree depth under each coarse patch, as `solve` has it.
    int max_level = HierarchicalOptions{}.max_level;
    int refine_rounds = HierarchicalOptions{}.refine_rounds;  // --meshes: hierarchical refine-and-solve rounds
    // --meshes: hierarchical power epsilons (BF refinement on power), each with every link epsilon
    std::vector<double> power_epsilons = {HierarchicalOptions{}.power_epsilon};
    // --meshes: hierarchical display refinement tolerances (DisplayRefinement), each a row of
    // every solve (0: off)
    std::vector<double> display_tolerances = {0.0};
    std::string reference;  // --reference: a `bounce reference` CSV; empty: probes cached in `out`
    std::vector<std::size_t> patch_counts = {250, 500, 1000, 2000, 4000, 8000};  // --meshes: uniform patch meshes
    std::string gather = "vertices";  // point data of every run, as solve writes it
};

/// The probe columns shared by runs.csv and meshes.csv: the scores over every probe, then per
/// probe class (ProbeClass) the point data's RMS and worst, the patch values' RMS and the count.
std::string probe_columns();
/// One row's values of probe_columns().
std::string probe_fields(const ProbeScore& s, std::span<const ProbeClass> classes);
/// How many probes of each class the scores below rest on.
void print_class_counts(std::span<const ProbeClass> classes);
/// "2.31% / 7.80%": RMS and worst of the point data over one class's probes ("-" with none).
std::string class_text(const ProbeScore& s, std::span<const ProbeClass> classes, ProbeClass which);
double seconds_since(std::chrono::steady_clock::time_point t0);

/// bounce compare --meshes (compare_meshes.cpp).
int run_compare_meshes(const CommonOptions& o, const CompareCommand& c);

}  // namespace bounce::app
