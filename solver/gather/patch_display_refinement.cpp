// SPDX-License-Identifier: MIT
#include "solver/gather/patch_display_refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <optional>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "mesh/meshing/element_tree.h"
#include "solver/gather/final_gather.h"
#include "solver/gather/point_values.h"
#include "solver/gather/point_values_by_position.h"

namespace bounce {
namespace {

/// The part of a gathered vertex's value that its near (shaped) sources sent, and the point
/// it was gathered at: the near field's passes gather that part again at the same point, so
/// what they keep and what they add are taken at one place.
struct NearPart {
    Rgb value;
    GatherPoint at;
};
using NearParts = PointMap<NearPart>;

/// A point a split adds, at parameters uv of the node's root, and the corners (indices into
/// the node's corners; -1 unused) whose mean is the linear interpolation there: an edge's
/// two ends for its midpoint, all four for a quad's centre (bilinear).
struct SplitPoint {
    glm::dvec2 uv;
    std::array<int, 4> corners;
};

/// A cell to try a split of, and how far interpolation misses the light inside it (the
/// largest relative miss or corner step that made it a candidate; a child inherits its
/// parent's worst miss when its own step is smaller): when the gather budget cannot take every
/// candidate of a level, the worst go first. Misses and steps are both shares of the larger
/// value, so one ranking serves, though they are tried against different thresholds
/// (tolerance and corner_spread): a step is a miss that interpolation cannot mend.
struct Candidate {
    std::uint32_t cell;
    double miss;
};

/// How far a gathered value misses what interpolation gives there, as a share of the larger
/// of the two, or of `floor` where both are darker.
double relative_miss(double value, double interpolated, double floor) {
    return std::abs(value - interpolated) / std::max({value, interpolated, floor});
}

std::vector<SplitPoint> split_points(const ElementTree::Node& n) {
    const auto& c = n.corners;
    const auto mid = [&](int a, int b) { return SplitPoint{0.5 * (c[a] + c[b]), {a, b, -1, -1}}; };
    if (n.corner_count == 4)
        return {mid(0, 1), mid(1, 2), mid(2, 3), mid(3, 0), {0.25 * (c[0] + c[1] + c[2] + c[3]), {0, 1, 2, 3}}};
    return {mid(0, 1), mid(1, 2), mid(2, 0)};
}

/// The luminance of the gathered values at a node's corners (its corner_count first); none
/// where a corner's value is unknown.
std::optional<std::array<double, 4>> corner_luminances(const ElementTree& tree, const PointValues& known,
                                                       std::uint32_t node, int surface) {
    const ElementTree::Node& n = tree.node(node);
    std::array<double, 4> out{};
    for (int k = 0; k < n.corner_count; ++k) {
        const Rgb* v = known.find(surface, tree.point(n.root, n.corners[std::size_t(k)]));
        if (!v) return std::nullopt;
        out[std::size_t(k)] = v->luminance();
    }
    return out;
}

/// Per new point of a split node (`points`, its split_points), the relative_miss of the value
/// gathered there against the interpolation between the node's corners; 0 where a value is
/// unknown.
std::vector<double> split_misses(const ElementTree& tree, const PointValues& known, std::uint32_t node,
                                 const std::vector<SplitPoint>& points, int surface, double floor) {
    const ElementTree::Node& n = tree.node(node);
    std::vector<double> out(points.size(), 0.0);
    const std::optional<std::array<double, 4>> known_corners = corner_luminances(tree, known, node, surface);
    if (!known_corners) return out;
    const std::array<double, 4>& corner = *known_corners;
    for (std::size_t q = 0; q < points.size(); ++q) {
        const Rgb* v = known.find(surface, tree.point(n.root, points[q].uv));
        if (!v) continue;
        double sum = 0.0;
        int count = 0;
        for (const int k : points[q].corners)
            if (k >= 0) {
                sum += corner[std::size_t(k)];
                ++count;
            }
        out[q] = relative_miss(v->luminance(), sum / count, floor);
    }
    return out;
}

/// True when child `c` of a split node has a corner at one of the node's new points (`points`,
/// with their `misses`) that missed by more than `tolerance`: the light bends there, so the
/// child may need a split too.
bool child_touches_a_miss(const ElementTree& tree, std::uint32_t c, const std::vector<SplitPoint>& points,
                          const std::vector<double>& misses, double tolerance) {
    const ElementTree::Node& child = tree.node(c);
    for (std::size_t q = 0; q < points.size(); ++q) {
        if (misses[q] <= tolerance) continue;
        for (int k = 0; k < child.corner_count; ++k) {
            const glm::dvec2 d = child.corners[std::size_t(k)] - points[q].uv;
            if (std::abs(d.x) + std::abs(d.y) < 1e-12) return true;
        }
    }
    return false;
}

/// The spread of a cell's gathered corners, relative_miss of the brightest against the
/// darkest; 0 where a corner is unknown.
double corner_step(const ElementTree& tree, const PointValues& known, std::uint32_t cell, int surface, double floor) {
    const std::optional<std::array<double, 4>> corner = corner_luminances(tree, known, cell, surface);
    if (!corner) return 0.0;
    const auto first = corner->begin(), last = first + tree.node(cell).corner_count;
    return relative_miss(*std::max_element(first, last), *std::min_element(first, last), floor);
}

/// Gathers, from the solved patches, every vertex of `mesh` (whose gather points are
/// `points`, vertex_gather_points') not yet in `known`, and adds it. False when `cancel` was set.
bool gather_new_vertices(const PatchMesh& mesh, const std::vector<GatherPoint>& points,
                         const std::vector<Patch>& sources, const std::vector<Rgb>& radiosity,
                         const Visibility& visibility, const GatherOptions& options, PointValues& known,
                         NearParts& near_known, const std::atomic<bool>* cancel,
                         const std::function<void(std::size_t, std::size_t)>& progress) {
    std::vector<GatherPoint> todo;
    std::vector<glm::dvec3> at;
    for (std::size_t v = 0; v < points.size(); ++v)
        if (!known.find(points[v].surface, mesh.vertex_position(v))) {
            todo.push_back(points[v]);
            at.push_back(mesh.vertex_position(v));
        }
    if (todo.empty()) return true;
    std::vector<Rgb> near;
    const std::vector<Rgb> gathered =
        final_gather_with_near_part(sources, radiosity, visibility, todo, options, near, cancel, progress);
    if (cancel && cancel->load()) return false;
    for (std::size_t q = 0; q < todo.size(); ++q) {
        known.add(todo[q].surface, {at[q], gathered[q]});
        near_known.add(todo[q].surface, {at[q], {near[q], todo[q]}});
    }
    return true;
}

/// Per patch, its vertices' values at its corners (GatherOptions::source_corners).
std::vector<Rgb> corner_values(const PatchMesh& mesh, const std::vector<Rgb>& point_values) {
    std::vector<Rgb> out(4 * mesh.size());
    for (std::size_t p = 0; p < mesh.size(); ++p) {
        const std::vector<int> vertices = mesh.patch_vertex_indices(p);
        for (std::size_t k = 0; k < vertices.size() && k < 4; ++k)
            out[4 * p + k] = point_values[std::size_t(vertices[k])];
    }
    return out;
}

/// True when the gather shapes source `p` at point `x` (GatherOptions::shape_within): p lies
/// on another surface, x is in front of it, and x is within `within` of p's circumradius of
/// its centre.
bool shapes_at(const Patch& p, const GatherPoint& x, double within) {
    return p.surface != x.surface && p.height(x.position) > 0 &&
           glm::length(x.position - p.centre) < within * circumradius(p);
}

/// The vertices that have a source of another surface within `within` of its circumradius
/// in front of them whose corners differ by more than `tolerance` of the brightest: their
/// values change when those sources send their shape (beside a contact, a wall's strip).
std::vector<std::size_t> vertices_beside_shaped_sources(const std::vector<GatherPoint>& points,
                                                        const std::vector<Patch>& patches, std::span<const Rgb> corners,
                                                        double within, double tolerance) {
    std::vector<std::uint32_t> shaped;
    for (std::size_t j = 0; j < patches.size(); ++j) {
        double lo = 1e300, hi = 0.0;
        for (int k = 0; k < patches[j].vertex_count; ++k) {
            const double l = corners[4 * j + std::size_t(k)].luminance();
            lo = std::min(lo, l);
            hi = std::max(hi, l);
        }
        if (hi - lo > tolerance * hi) shaped.push_back(std::uint32_t(j));
    }
    std::vector<std::uint8_t> near(points.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 64), [&](const auto& range) {
        for (std::size_t v = range.begin(); v != range.end(); ++v)
            for (const std::uint32_t j : shaped) {
                if (shapes_at(patches[j], points[v], within)) {
                    near[v] = 1;
                    break;
                }
            }
    });
    std::vector<std::size_t> out;
    for (std::size_t v = 0; v < points.size(); ++v)
        if (near[v]) out.push_back(v);
    return out;
}

/// Per-patch values spread to the cells: each cell carries its root patch's value.
void spread_to_cells(std::vector<Rgb>& values, std::size_t patches, const ElementTree& tree,
                     const std::vector<std::uint32_t>& cells) {
    if (values.size() != patches) return;
    std::vector<Rgb> out(cells.size());
    for (std::size_t k = 0; k < cells.size(); ++k) out[k] = values[tree.node(cells[k]).root];
    values = std::move(out);
}

/// A split patch's reflected radiosity B - E shared among its cells in proportion to the
/// point data over each (the mean of its corners' values less E), the patch's power kept:
/// sum_k A_k (B_k - E) = A (B - E), so the cells' own values follow a shadow line through the
/// patch. H (= (B - E) / rho) and the display value follow the same shares; a channel whose
/// point data is dark over the whole patch keeps the patch's value in every cell.
void share_by_point_data(SolveResult& res, const std::vector<Patch>& patches, const ElementTree& tree,
                         const std::vector<std::uint32_t>& cells, const PointValues& known) {
    std::vector<std::vector<std::size_t>> of_patch(patches.size());
    for (std::size_t k = 0; k < cells.size(); ++k) of_patch[tree.node(cells[k]).root].push_back(k);
    for (std::size_t p = 0; p < patches.size(); ++p) {
        const std::vector<std::size_t>& ks = of_patch[p];
        if (ks.size() < 2) continue;
        const Rgb e = patches[p].emission;
        std::vector<Rgb> reflected(ks.size());
        Rgb mean;
        double area = 0.0;
        for (std::size_t i = 0; i < ks.size(); ++i) {
            const ElementTree::Node& n = tree.node(cells[ks[i]]);
            Rgb sum;
            int count = 0;
            for (int c = 0; c < n.corner_count; ++c)
                if (const Rgb* v = known.find(patches[p].surface, tree.point(n.root, n.corners[std::size_t(c)]))) {
                    sum += *v;
                    ++count;
                }
            for (int c = 0; c < 3 && count > 0; ++c) reflected[i][c] = std::max(0.0, sum[c] / count - e[c]);
            const double a = tree.geometry()[cells[ks[i]]].area;
            mean += reflected[i] * a;
            area += a;
        }
        mean *= 1.0 / area;
        for (std::size_t i = 0; i < ks.size(); ++i) {
            const std::size_t k = ks[i];
            for (int c = 0; c < 3; ++c) {
                if (!(mean[c] > 0)) continue;
                const double share = reflected[i][c] / mean[c];
                const double b = res.radiosity[k][c];
                res.radiosity[k][c] = e[c] + (b - e[c]) * share;
                if (k < res.irradiance.size()) res.irradiance[k][c] *= share;
                if (k < res.display.size() && b > 0) res.display[k][c] *= res.radiosity[k][c] / b;
            }
        }
    }
}

/// The patches to try a split of: where the solved mean misses the mean of the gathered
/// corners, or the corners differ among themselves (PatchDisplayRefinement). Each vertex's
/// gathered value goes into `known` once, on its patch's surface.
std::vector<Candidate> patches_to_try(const PatchMesh& mesh, const std::vector<Rgb>& radiosity,
                                      const std::vector<Rgb>& point_radiosity, const PatchDisplayRefinement& options,
                                      double floor, PointValues& known) {
    const std::vector<Patch>& sources = mesh.patches();
    const std::size_t n = sources.size();
    std::vector<std::uint8_t> added(point_radiosity.size(), 0);
    std::vector<Candidate> active;
    for (std::size_t p = 0; p < n; ++p) {
        double corner_mean = 0.0, lo = 1e300, hi = 0.0;
        const std::vector<int> vertices = mesh.patch_vertex_indices(p);
        for (const int v : vertices) {
            const double b = point_radiosity[std::size_t(v)].luminance();
            corner_mean += b;
            lo = std::min(lo, b);
            hi = std::max(hi, b);
            if (!added[std::size_t(v)]) {
                known.add(sources[p].surface, {mesh.vertex_position(std::size_t(v)), point_radiosity[std::size_t(v)]});
                added[std::size_t(v)] = 1;
            }
        }
        corner_mean /= double(vertices.size());
        const double mean_miss = relative_miss(radiosity[p].luminance(), corner_mean, floor);
        const double spread = relative_miss(hi, lo, floor);
        if (mean_miss > options.tolerance || spread > options.corner_spread)
            active.push_back({std::uint32_t(p), std::max(mean_miss, spread)});
    }
    return active;
}

/// Per tree node, for the near field's sources: the display cells (`cells`, the live leaves)
/// and their ancestors, each with its corners' point values (`known`) and, as radiosity, the
/// mean of its corners (a cell) or the area-weighted mean of its children; first_child -1 below
/// the cells.
struct DisplaySources {
    std::vector<std::int32_t> first_child;
    std::vector<std::uint8_t> live;
    std::vector<Rgb> radiosity, corners;
    std::vector<double> spread;
};

void fill_display_sources(const ElementTree& tree, const PointValues& known, double shape_within, DisplaySources& out) {
    const std::vector<Patch>& geometry = tree.geometry();
    out.radiosity.assign(tree.size(), Rgb());
    out.corners.assign(4 * tree.size(), Rgb());
    out.spread.assign(tree.size(), 0.0);
    // Children come after their parent, so a backward pass sees them first.
    for (std::size_t k = tree.size(); k-- > 0;) {
        if (!out.live[k]) continue;
        const ElementTree::Node& n = tree.node(k);
        Rgb mean;
        for (int c = 0; c < n.corner_count; ++c) {
            const Rgb* v = known.find(geometry[k].surface, tree.point(n.root, n.corners[std::size_t(c)]));
            if (v) out.corners[4 * k + std::size_t(c)] = *v;
            mean += out.corners[4 * k + std::size_t(c)];
        }
        if (out.first_child[k] < 0) {
            out.radiosity[k] = mean * (1.0 / n.corner_count);
            continue;
        }
        Rgb sum;
        double area = 0.0;
        for (std::size_t c = 0; c < 4; ++c) {
            const std::size_t child = std::size_t(out.first_child[k]) + c;
            sum += out.radiosity[child] * geometry[child].area;
            area += geometry[child].area;
        }
        out.radiosity[k] = sum * (1.0 / area);
        // GatherSources::descend = 1 then takes the children within shape_within of the
        // node's circumradius: where the gather shapes a source, it goes down instead.
        out.spread[k] = shape_within * out.radiosity[k].luminance();
    }
}

/// Per point, the roots in front of it (on other surfaces) within `within` of their
/// circumradius of it, as the gather shapes them: a grid over the points, each root
/// looking in the cells its reach overlaps.
std::vector<std::vector<std::uint32_t>> near_roots(const std::vector<Patch>& roots,
                                                   const std::vector<GatherPoint>& points, double within) {
    std::vector<std::vector<std::uint32_t>> out(points.size());
    double reach = 0.0;
    for (const Patch& p : roots) reach = std::max(reach, within * circumradius(p));
    if (points.empty() || !(reach > 0)) return out;
    using Cell = std::array<std::int64_t, 3>;
    const auto key = [reach](const glm::dvec3& x) {
        return Cell{std::int64_t(std::floor(x.x / reach)), std::int64_t(std::floor(x.y / reach)),
                    std::int64_t(std::floor(x.z / reach))};
    };
    std::map<Cell, std::vector<std::uint32_t>> grid;
    for (std::size_t i = 0; i < points.size(); ++i) grid[key(points[i].position)].push_back(std::uint32_t(i));
    for (std::size_t j = 0; j < roots.size(); ++j) {
        const Patch& p = roots[j];
        const double r = within * circumradius(p);
        const Cell lo = key(p.centre - glm::dvec3(r)), hi = key(p.centre + glm::dvec3(r));
        for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
            for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
                for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
                    const auto it = grid.find({x, y, z});
                    if (it == grid.end()) continue;
                    for (const std::uint32_t i : it->second)
                        if (shapes_at(p, points[i], within)) out[i].push_back(std::uint32_t(j));
                }
    }
    return out;
}

/// PatchDisplayRefinement::near_field_passes: the vertices of `refined` whose value holds a
/// near part (`near_known`) take it again, each pass, from the display cells of their near
/// roots at the cells' current point data: B = (B_0 - near_0) + rho H_near. False when
/// `cancel` was set.
bool gather_near_field(const ElementTree& tree, const std::vector<std::uint32_t>& cells, const PatchMesh& refined,
                       const std::vector<GatherPoint>& points, PointValues& known, const NearParts& near_known,
                       const Visibility& visibility, const GatherOptions& options, int passes,
                       const std::atomic<bool>* cancel) {
    DisplaySources d;
    d.first_child.assign(tree.size(), -1);
    d.live.assign(tree.size(), 0);
    for (const std::uint32_t c : cells) {
        d.live[c] = 1;
        for (std::int32_t a = tree.node(c).parent; a >= 0; a = tree.node(std::size_t(a)).parent) {
            d.live[std::size_t(a)] = 1;
            d.first_child[std::size_t(a)] = tree.node(std::size_t(a)).first_child;
        }
    }
    std::vector<std::size_t> todo;
    std::vector<Rgb> far;  // B_0 - near_0: what the pass keeps
    std::vector<GatherPoint> at;
    for (std::size_t v = 0; v < points.size(); ++v) {
        const glm::dvec3 x = refined.vertex_position(v);
        const Rgb* b = known.find(points[v].surface, x);
        const NearPart* n = near_known.find(points[v].surface, x);
        if (!b || !n || !(n->value.max() > 0)) continue;
        todo.push_back(v);
        far.push_back(*b - n->value);
        at.push_back(n->at);
    }
    const std::vector<std::vector<std::uint32_t>> near = near_roots(tree.roots(), at, options.shape_within);
    std::vector<std::uint32_t> list(at.size()), listed;
    std::vector<std::size_t> offsets = {0};
    for (std::size_t q = 0; q < at.size(); ++q) {
        list[q] = std::uint32_t(q);
        listed.insert(listed.end(), near[q].begin(), near[q].end());
        offsets.push_back(listed.size());
    }
    if (todo.empty()) return true;
    const std::vector<Patch> sources(tree.geometry().begin(), tree.geometry().begin() + std::ptrdiff_t(tree.size()));
    for (int pass = 0; pass < passes; ++pass) {
        fill_display_sources(tree, known, options.shape_within, d);
        GatherSources s;
        s.list = list;
        s.offsets = offsets;
        s.patches = listed;
        s.first_child = d.first_child;
        s.spread = d.spread;
        s.descend = 1.0;
        GatherOptions o = options;
        o.source_corners = d.corners;
        const std::vector<Rgb> gathered = final_gather(sources, d.radiosity, visibility, at, s, o, cancel);
        if (cancel && cancel->load()) return false;
        for (std::size_t q = 0; q < todo.size(); ++q) {
            if (near[q].empty()) continue;  // its near sources are gone (none in front): B_0 stays
            Rgb b = far[q] + gathered[q] - at[q].emission;
            for (int c = 0; c < 3; ++c) b[c] = std::max(b[c], at[q].emission[c]);
            known.set(at[q].surface, refined.vertex_position(todo[q]), b);
        }
    }
    return true;
}

/// The vertices beside near sources whose corners differ (vertices_beside_shaped_sources)
/// gathered again with those sources' shape (`shaped`), into res.point_radiosity, each
/// vertex's near part into `near_known`. False when `cancel` was set.
bool gather_beside_shaped_sources(const PatchMesh& mesh, SolveResult& res, const Visibility& visibility,
                                  const GatherOptions& shaped, double tolerance, NearParts& near_known,
                                  const std::atomic<bool>* cancel,
                                  const std::function<void(std::size_t, std::size_t)>& progress) {
    const std::vector<GatherPoint> points = vertex_gather_points(mesh);
    const std::vector<std::size_t> again =
        vertices_beside_shaped_sources(points, mesh.patches(), shaped.source_corners, shaped.shape_within, tolerance);
    std::vector<GatherPoint> todo;
    for (const std::size_t v : again) todo.push_back(points[v]);
    std::vector<Rgb> near;
    const std::vector<Rgb> gathered =
        final_gather_with_near_part(mesh.patches(), res.radiosity, visibility, todo, shaped, near, cancel, progress);
    if (cancel && cancel->load()) return false;
    for (std::size_t q = 0; q < again.size(); ++q) {
        res.point_radiosity[again[q]] = gathered[q];
        near_known.add(todo[q].surface, {mesh.vertex_position(again[q]), {near[q], todo[q]}});
    }
    return true;
}

}  // namespace

double dark_floor(const std::vector<Patch>& patches, const std::vector<Rgb>& radiosity) {
    double area = 0.0, power = 0.0;
    for (std::size_t p = 0; p < patches.size(); ++p) {
        area += patches[p].area;
        power += patches[p].area * radiosity[p].luminance();
    }
    return area > 0 ? 0.01 * power / area : 0.0;
}

std::size_t refine_patch_display(PatchMesh& mesh, SolveResult& res, const Visibility& visibility,
                                 const PatchDisplayRefinement& options, const std::atomic<bool>* cancel,
                                 const std::function<void(std::size_t, std::size_t)>& progress) {
    if (!(options.tolerance > 0) || options.max_depth < 1) return 0;
    const std::vector<Patch> sources = mesh.patches();
    const std::size_t n = sources.size();
    if (n == 0 || res.radiosity.size() != n || res.point_radiosity.size() != mesh.mesh().n_vertices()) return 0;
    const std::vector<Rgb> radiosity = res.radiosity;
    // Near sources send their shape, from the vertices' values: first to the vertices beside
    // them, gathered again, then to every new point.
    std::vector<Rgb> corners = corner_values(mesh, res.point_radiosity);
    GatherOptions shaped = point_value_options();
    shaped.source_corners = corners;
    ElementTree tree(sources);
    NearParts near_known(tree.weld());  // per gathered point, the part its near sources sent
    if (!gather_beside_shaped_sources(mesh, res, visibility, shaped, options.tolerance, near_known, cancel, progress))
        return 0;
    corners = corner_values(mesh, res.point_radiosity);
    shaped.source_corners = corners;
    PointValues known(tree.weld());
    const double floor = dark_floor(sources, radiosity);
    std::vector<Candidate> active = patches_to_try(mesh, radiosity, res.point_radiosity, options, floor, known);
    std::vector<std::uint32_t> cells(n);
    std::iota(cells.begin(), cells.end(), 0u);
    double pairs = 0.0;
    bool last_level = false;
    const double max_pairs = options.max_pairs > 0 ? options.max_pairs : display_pairs_budget(n);
    for (int depth = 1; depth <= options.max_depth + options.step_depth && !active.empty() && !last_level; ++depth) {
        // At most five new points per split, each gathering over every patch. Past the
        // budget, the level takes the candidates that miss most, and is the last.
        const double per_split = 5.0 * double(n);
        if (pairs + per_split * double(active.size()) > max_pairs) {
            const auto fit = std::size_t(std::max(0.0, (max_pairs - pairs) / per_split));
            if (fit == 0) break;
            std::stable_sort(active.begin(), active.end(),
                             [](const Candidate& a, const Candidate& b) { return a.miss > b.miss; });
            active.resize(std::min(fit, active.size()));
            last_level = true;
        }
        pairs += per_split * double(active.size());
        // Split the active cells (children in their parent's place) and gather what that adds.
        std::vector<std::uint8_t> splitting(tree.size(), 0);
        for (const Candidate& a : active) splitting[a.cell] = 1;
        std::vector<std::uint32_t> trial;
        trial.reserve(cells.size() + 3 * active.size());
        for (const std::uint32_t c : cells) {
            if (!splitting[c]) {
                trial.push_back(c);
                continue;
            }
            const std::size_t first = tree.split(c);
            for (std::size_t k = 0; k < 4; ++k) trial.push_back(std::uint32_t(first + k));
        }
        const PatchMesh next = tree.conforming_mesh(trial);
        if (!gather_new_vertices(next, vertex_gather_points(next), sources, radiosity, visibility, shaped, known,
                                 near_known, cancel, progress))
            return 0;
        // Keep the splits whose new points the interpolation misses; the others go back to
        // their parent (its gathered points are then left unused).
        std::vector<std::uint8_t> undo(tree.size(), 0);
        std::vector<Candidate> next_active;
        for (const Candidate& candidate : active) {
            const std::uint32_t a = candidate.cell;
            const ElementTree::Node& node = tree.node(a);
            const std::vector<SplitPoint> points = split_points(node);
            const std::vector<double> misses = split_misses(tree, known, a, points, sources[node.root].surface, floor);
            const double worst = *std::max_element(misses.begin(), misses.end());
            if (worst <= options.tolerance) {
                undo[a] = 1;
                continue;
            }
            for (std::int32_t k = 0; k < 4; ++k) {
                const auto child = std::uint32_t(node.first_child + k);
                if (!child_touches_a_miss(tree, child, points, misses, options.tolerance)) continue;
                // Past max_depth only the cells a step crosses go on: their number grows with
                // the length of the shadow lines, not with the area.
                const double step = corner_step(tree, known, child, sources[node.root].surface, floor);
                if (depth >= options.max_depth && step <= options.corner_spread) continue;
                next_active.push_back({child, std::max(worst, step)});
            }
        }
        cells.clear();
        for (const std::uint32_t t : trial) {
            const std::int32_t parent = tree.node(t).parent;
            if (parent >= 0 && undo[std::size_t(parent)]) {
                if (std::int32_t(t) == tree.node(std::size_t(parent)).first_child)
                    cells.push_back(std::uint32_t(parent));
                continue;
            }
            cells.push_back(t);
        }
        active = std::move(next_active);
    }
    if (cells.size() == n) return 0;
    PatchMesh refined = tree.conforming_mesh(cells);
    const std::vector<GatherPoint> points = vertex_gather_points(refined);
    if (!gather_new_vertices(refined, points, sources, radiosity, visibility, shaped, known, near_known, cancel,
                             progress))
        return 0;
    if (options.near_field_passes > 0 && !gather_near_field(tree, cells, refined, points, known, near_known, visibility,
                                                            shaped, options.near_field_passes, cancel))
        return 0;
    std::vector<Rgb> values(points.size());
    for (std::size_t v = 0; v < points.size(); ++v)
        if (const Rgb* known_value = known.find(points[v].surface, refined.vertex_position(v)))
            values[v] = *known_value;
    for (std::vector<Rgb>* per_patch : {&res.radiosity, &res.irradiance, &res.unshot, &res.display})
        spread_to_cells(*per_patch, n, tree, cells);
    share_by_point_data(res, sources, tree, cells, known);
    res.point_radiosity = std::move(values);
    refined.set_specular_faces(mesh.specular_faces());  // mirrors and glass stay in the export
    mesh = std::move(refined);
    return cells.size() - n;
}

}  // namespace bounce
