// SPDX-License-Identifier: MIT
#include "solver/pipeline/solve_request.h"

#include <algorithm>
#include <cmath>

#include "mesh/scene/input_error.h"
#include "solver/gather/patch_display_refinement.h"

namespace bounce {

namespace {

template <class E>
std::string name_of(E value, const std::vector<std::string>& names) {
    return names.at(std::size_t(value));
}

template <class E>
E parse(const std::string& name, const std::vector<std::string>& names, const std::string& option) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it != names.end()) return E(it - names.begin());
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw InputError(option + ": unknown, got '" + name + "' (expected one of " + list + ")");
}

void check_range(const OptionNames& names, std::string_view key, double x, double lo, double hi) {
    if (!(x >= lo && x <= hi)) throw InputError(names(key) + ": " + out_of_range_text(number_text(x), lo, hi));
}

void check_positive(const OptionNames& names, std::string_view key, double x) {
    if (!(x > 0) || !std::isfinite(x)) throw InputError(names(key) + ": " + not_positive_text(number_text(x)));
}

/// The ranges the command line's validators hold each option to.
void check_ranges(const SolveRequest& r, const OptionNames& names) {
    const FormFactorOptions& f = r.form_factors;
    if (f.visibility_rays != 0) check_range(names, "rays", f.visibility_rays, 1, 4096);
    check_range(names, "receiver-samples", f.receiver_samples, 0, 16);
    check_range(names, "hemicube-res", f.hemicube_resolution, 2, 4096);
    check_range(names, "elements", r.element_split, 1, 64);
    if (r.tolerance) check_positive(names, "tolerance", *r.tolerance);
    check_range(names, "max-iterations", double(r.max_iterations), 0, 1e15);
    if (r.max_seconds && *r.max_seconds < 0) check_positive(names, "max-seconds", *r.max_seconds);
    if (r.sor) check_range(names, "sor", *r.sor, 0.0, 2.0);
    check_positive(names, "link-epsilon", r.link_epsilon);
    check_range(names, "power-epsilon", r.power_epsilon, 0.0, 1.0);
    check_range(names, "refine-rounds", r.refine_rounds, 1, 100);
    check_range(names, "max-level", r.max_level, 0, 12);
    if (r.display_tolerance) check_range(names, "display-tolerance", *r.display_tolerance, 0.0, 1.0);
}

/// The hierarchical solver takes none of the patch solvers' own options.
void check_refining(const SolveRequest& r, const OptionNames& names) {
    const std::string solvers = " applies to the patch solvers, not to " + names("adaptive") + " or hierarchical";
    if (r.element_split > 1)
        throw InputError(names("elements") + " does not combine with " + names("adaptive") + " or hierarchical");
    if (r.method != FormFactorMethod::raycast)
        throw InputError(names("adaptive") + " and hierarchical use raycast form factors");
    const std::pair<const char*, bool> patch_only[] = {{"max-seconds", r.max_seconds.has_value()},
                                                       {"sor", r.sor.has_value()},
                                                       {"overshoot", r.overshoot.has_value()},
                                                       {"cache-mb", r.cache_mb.has_value()},
                                                       {"series", r.series.has_value()}};
    for (const auto& [key, given] : patch_only)
        if (given) throw InputError(names(key) + solvers);
    if (r.residuals || r.reference)
        throw InputError(names("residuals") + " and " + names("reference") + " apply to the patch solvers, not to " +
                         names("adaptive") + " or hierarchical");
}

}  // namespace

std::vector<std::string> solver_kind_names() {
    return {"shooting", "gauss-seidel", "jacobi", "direct", "hierarchical"};
}
std::vector<std::string> form_factor_method_names() { return {"raycast", "exact", "hemicube", "analytic"}; }
std::vector<std::string> gather_mode_names() { return {"vertices", "centres", "none"}; }
std::vector<std::string> quality_names() { return {"draft", "default", "fine"}; }

std::string to_string(SolverKind s) { return name_of(s, solver_kind_names()); }
std::string to_string(FormFactorMethod m) { return name_of(m, form_factor_method_names()); }
std::string to_string(GatherMode g) { return name_of(g, gather_mode_names()); }
std::string to_string(Quality q) { return name_of(q, quality_names()); }

std::string OptionNames::operator()(std::string_view key) const {
    std::string name(key);
    if (command_line) return "--" + name;
    std::replace(name.begin(), name.end(), '-', '_');
    return name;
}

SolverKind parse_solver_kind(const std::string& name, const OptionNames& names) {
    return parse<SolverKind>(name, solver_kind_names(), names("solver"));
}

FormFactorMethod parse_form_factor_method(const std::string& name, const OptionNames& names) {
    return parse<FormFactorMethod>(name, form_factor_method_names(), names("form-factors"));
}

GatherMode parse_gather_mode(const std::string& name, const OptionNames& names) {
    return parse<GatherMode>(name, gather_mode_names(), names("gather"));
}

Quality parse_quality(const std::string& name, const OptionNames& names) {
    return parse<Quality>(name, quality_names(), names("quality"));
}

bool same_meshing(const MeshingOptions& a, const MeshingOptions& b) {
    return a.max_area == b.max_area && a.max_edge == b.max_edge && a.target_patches == b.target_patches &&
           a.max_patches == b.max_patches && a.subdivide == b.subdivide && a.element_split == b.element_split &&
           a.cut_contacts == b.cut_contacts && a.kind == b.kind && a.max_discontinuities == b.max_discontinuities &&
           a.aspect_bound == b.aspect_bound;
}

bool default_meshing(const MeshingOptions& m) {
    return m.max_area == 0 && m.max_edge == 0 && m.target_patches == MeshingOptions{}.target_patches;
}

void SolveRequest::validate(const OptionNames& names) const {
    check_ranges(*this, names);
    if (adaptive && solver != SolverKind::shooting && solver != SolverKind::hierarchical)
        throw InputError(names("adaptive") + " is the hierarchical solver: it takes no other (got " + names("solver") +
                         " " + to_string(solver) + ")");
    if (!retired.empty())
        throw InputError(names(retired.front()) + " belonged to the receiver-only refinement " + names("adaptive") +
                         " ran before, now retired: " + names("adaptive") +
                         " is the hierarchical solver refining on power; set " + names("power-epsilon") + " (with " +
                         names("adaptive") + " " + number_text(kAdaptivePowerEpsilon) + " unless given)");
    if (display_tolerance.value_or(0.0) > 0 && gather != GatherMode::vertices)
        throw InputError(names("display-tolerance") + " refines the point data gathered at the vertices: it needs " +
                         names("gather") + " vertices (got " + to_string(gather) + ")");
    if (refines() && quality.value_or(Quality::standard) != Quality::standard)
        throw InputError(names("quality") + " " + to_string(*quality) +
                         " sets the patch solvers' patches and display cells: it does not combine with " +
                         names("adaptive") + " or hierarchical");
    if (refines()) return check_refining(*this, names);
    if (display_tolerance && (element_split > 1 || series.value_or(0) > 0))
        throw InputError(names("display-tolerance") + " does not combine with " + names("elements") + " or " +
                         names("series"));
    if (element_split > 1 &&
        (solver != SolverKind::shooting || method == FormFactorMethod::hemicube || method == FormFactorMethod::exact))
        throw InputError(names("elements") + " needs the shooting solver and raycast or analytic form factors");
}

double SolveRequest::patch_display_tolerance() const {
    if (display_tolerance) return *display_tolerance;
    // The display cells replace the mesh, which a series' frames and elements must keep.
    return element_split > 1 || series.value_or(0) > 0 ? 0.0 : kPatchDisplayTolerance;
}

}  // namespace bounce
