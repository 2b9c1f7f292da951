// SPDX-License-Identifier: MIT
#include "solver/gather/final_gather.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>

#include "solver/form_factors/patch_sampling.h"
#include "solver/form_factors/point_polygon_form_factor.h"
#include "solver/form_factors/polygon_form_factor.h"
#include "solver/form_factors/unoccluded_form_factor.h"

namespace bounce {
namespace {

/// What the gather reads of a source at every point, in one place (a Patch is 216 bytes over
/// four cache lines, and a point of a hierarchy's gather reads about a thousand sources
/// scattered over the tree): its plane, bounding sphere, and when to go down to its children.
struct alignas(32) SourceCard {
    int surface = 0;
    bool dark = false;  // sends nothing (B = 0)
    glm::dvec3 normal{0.0};
    double offset = 0.0;  // dot(normal, a vertex): height(x) = dot(normal, x) - offset
    glm::dvec3 centre{0.0};
    double radius = 0.0;  // circumradius
    /// GatherSources::descend's test min(1, r / d) spread > descend L, solved for the distance
    /// d: the children are taken when d < descend_within (0: never; infinity, where L is 0 and
    /// the leaves below differ: always).
    double descend_within = 0.0;
    double area = 0.0;
};

/// Unoccluded point-to-patch factors: Lambert's formula, or for well-separated patches wholly
/// above the point's horizon the Gauss-Legendre rule of the point-to-point kernel at the order
/// the pair's separation predicts (as UnoccludedFormFactor does for patch pairs).
class PointFactor {
public:
    PointFactor(const std::vector<Patch>& patches, double tolerance) : m_patches(patches) {
        if (tolerance > 0) m_gauss.emplace(patches, tolerance);
    }

    /// F(dA at x with normal n -> patch j), for x in front of patch j, whose card is c and
    /// centre lies `distance` from x.
    double operator()(const glm::dvec3& x, const glm::dvec3& n, std::size_t j, const SourceCard& c,
                      double distance) const {
        if (m_gauss) {
            const int order = m_gauss->order(distance - c.radius, c.radius, kOrders);
            // The rule needs the kernel smooth: no part below x's horizon. The bounding sphere
            // settles most sources with one dot product, the vertices the rest.
            bool above = order > 0 && order <= kOrders;
            if (above && glm::dot(n, c.centre - x) <= c.radius) {
                const Patch& p = m_patches[j];
                for (int v = 0; v < p.vertex_count && above; ++v) above = glm::dot(n, p.vertices[v] - x) > 0;
            }
            if (above) {
                std::vector<AreaSample> unused;  // orders up to kOrders come from the cache
                const std::span<const AreaSample> at = m_gauss->points(j, order, unused);
                if (order > 2) {
                    const AreaSample at_x{x, 1.0};
                    return separated_form_factor({&at_x, 1}, n, at, c.area, c.normal);
                }
                // One or four points (most of a hierarchy's sources): the kernel summed here,
                // without separated_form_factor's blocking for many points on both sides.
                double sum = 0.0;
                for (const AreaSample& y : at) {
                    const glm::dvec3 d = y.point - x;
                    const double d2 = glm::dot(d, d);
                    sum -= y.weight * (glm::dot(n, d) * glm::dot(c.normal, d)) / (d2 * d2);
                }
                return std::max(0.0, sum * c.area / std::numbers::pi);
            }
        }
        return point_polygon_form_factor(x, n, m_patches[j].polygon());
    }
    /// Patch j's circumradius, cached with the Gauss points.
    double radius(std::size_t j) const { return m_gauss ? m_gauss->radius(j) : circumradius(m_patches[j]); }

private:
    static constexpr int kOrders = GaussPointCache::kCachedOrders;  // beyond: Lambert's formula is cheaper
    const std::vector<Patch>& m_patches;
    std::optional<GaussPointCache> m_gauss;  // with a positive tolerance only
};

/// The side of the square grid of about `want` rays: round(sqrt(want)), from a table for the
/// counts the options usually ask for (a call to lround per source was a twentieth of a gather).
int grid_side(int want) {
    static constexpr std::array<int, 17> kSide = {1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 3, 3, 4, 4, 4, 4};
    if (want >= 0 && want < int(kSide.size())) return kSide[std::size_t(want)];
    return std::max(1, int(std::lround(std::sqrt(double(want)))));
}

/// A sample's share of its patch's radiosity, per channel: the interpolation of the corner
/// values at unit-square coordinates (u, v) (patch_point_weights) over their mean, 1 where
/// the mean is 0.
Rgb corner_shape(const Patch& p, const Rgb* corners, const Rgb& mean, double u, double v) {
    const std::array<double, 4> w = patch_point_weights(p, u, v);
    Rgb at;
    for (int k = 0; k < p.vertex_count; ++k) at += corners[k] * w[std::size_t(k)];
    Rgb out;
    for (int c = 0; c < 3; ++c) out[c] = mean[c] > 0 ? at[c] / mean[c] : 1.0;
    return out;
}

/// x's kernel-weighted mean of a shaped source's corner shape (corner_shape), per channel:
/// Lambert's formula on cells of the patch, each weighted by the shape at its centre. The patch
/// is cut in four (at its edges' midpoints and its centre) at least twice, and again where a
/// cell lies within four times its size of x, so cells shrink with their distance to x and the
/// kernel changes little across each. Deterministic: a near source, whose kernel changes most
/// across it, sends its shape without the noise of a few jittered samples of a peaked kernel,
/// and its rays only decide how much of it x sees. The shape is bilinear (linear on a
/// triangle), so its value at a cell's corners and centre is the mean of its parent's.
class ExactShape {
public:
    ExactShape(const glm::dvec3& x, const glm::dvec3& n) : m_x(x), m_n(n) {}

    Rgb operator()(const Patch& p, const Rgb* corners, const Rgb& mean) {
        m_weighted = Rgb();
        m_total = 0.0;
        std::array<Rgb, 4> w;
        for (int k = 0; k < p.vertex_count; ++k)
            for (int c = 0; c < 3; ++c) w[std::size_t(k)][c] = mean[c] > 0 ? corners[k][c] / mean[c] : 1.0;
        cell(p.vertices, w, p.vertex_count, 0);
        if (!(m_total > 0)) return Rgb::gray(1.0);
        return m_weighted * (1.0 / m_total);
    }

private:
    static constexpr int kMinDepth = 2, kMaxDepth = 8;
    static constexpr double kNear = 4.0;  // cut a cell nearer x than this many times its size

    void cell(const std::array<glm::dvec3, 4>& v, const std::array<Rgb, 4>& w, int count, int depth) {
        glm::dvec3 centre{0.0};
        Rgb at;
        for (int k = 0; k < count; ++k) centre += v[std::size_t(k)], at += w[std::size_t(k)];
        centre *= 1.0 / count;
        at *= 1.0 / count;
        double size = 0.0;
        for (int k = 0; k < count; ++k) size = std::max(size, glm::length(v[std::size_t(k)] - centre));
        if (depth < kMinDepth || (depth < kMaxDepth && glm::length(centre - m_x) < kNear * size)) {
            split(v, w, count, depth + 1, centre, at);
            return;
        }
        const double f = point_polygon_form_factor(m_x, m_n, {v.data(), std::size_t(count)});
        if (!(f > 0)) return;
        m_total += f;
        m_weighted += at * f;
    }

    void split(const std::array<glm::dvec3, 4>& v, const std::array<Rgb, 4>& w, int count, int depth,
               const glm::dvec3& centre, const Rgb& at) {
        std::array<glm::dvec3, 4> mv;
        std::array<Rgb, 4> mw;
        for (int k = 0; k < count; ++k) {
            const std::size_t a = std::size_t(k), b = std::size_t((k + 1) % count);
            mv[a] = 0.5 * (v[a] + v[b]);
            mw[a] = (w[a] + w[b]) * 0.5;
        }
        if (count == 4) {
            for (std::size_t k = 0; k < 4; ++k) {
                const std::size_t prev = (k + 3) % 4;
                cell({v[k], mv[k], centre, mv[prev]}, {w[k], mw[k], at, mw[prev]}, 4, depth);
            }
            return;
        }
        for (std::size_t k = 0; k < 3; ++k) {
            const std::size_t prev = (k + 2) % 3;
            cell({v[k], mv[k], mv[prev], glm::dvec3(0.0)}, {w[k], mw[k], mw[prev], Rgb()}, 3, depth);
        }
        cell({mv[0], mv[1], mv[2], glm::dvec3(0.0)}, {mw[0], mw[1], mw[2], Rgb()}, 3, depth);
    }

    glm::dvec3 m_x, m_n;
    Rgb m_weighted;
    double m_total = 0.0;
};

/// Every source patch's card: what the gather reads of it for each point, packed.
std::vector<SourceCard> source_cards(const std::vector<Patch>& patches, std::span<const Rgb> radiosity,
                                     const PointFactor& factor, const GatherSources* sources) {
    const bool may_descend = sources && sources->descend > 0;
    std::vector<SourceCard> cards(patches.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, patches.size(), 4096), [&](const auto& r) {
        for (std::size_t j = r.begin(); j != r.end(); ++j) {
            const Patch& p = patches[j];
            SourceCard& c = cards[j];
            c.centre = p.centre;
            c.normal = p.normal;
            c.offset = glm::dot(p.normal, p.vertices[0]);
            c.radius = factor.radius(j);
            c.area = p.area;
            c.surface = p.surface;
            c.dark = !(radiosity[j].max() > 0);
            if (may_descend && sources->first_child[j] >= 0) {
                const double limit = sources->descend * radiosity[j].luminance();
                if (sources->spread[j] > limit)
                    c.descend_within =
                        limit > 0 ? c.radius * sources->spread[j] / limit : std::numeric_limits<double>::infinity();
            }
        }
    });
    return cards;
}

/// One source's share at a point that rays decide: its unoccluded factor and its rays.
struct Term {
    std::size_t patch, first, count;
    double f0;
    bool shaped;  // weights[first .. first + count) hold the samples' shape (GatherOptions::source_corners)
    Rgb shape;    // shaped: ExactShape's, the share of B_j the whole patch sends x
};

/// The lists a gather thread reuses from point to point.
struct PointScratch {
    std::vector<Term> terms;
    std::vector<Visibility::Segment> segments;  // every term's rays, [first, first + count) each
    std::vector<double> kernel;                 // per ray: cos cos / r^4 (the area and pi come with f0)
    std::vector<std::uint8_t> blocked;          // per ray, from the visibility
    std::vector<Rgb> weights;                   // per ray of a shaped term
    // Children still to take (gone down to from a listed source, GatherSources::descend),
    // and whether a shaft test proved them unblocked.
    std::vector<std::pair<std::size_t, bool>> pending;
};

/// What the gather reads at every point.
struct GatherInputs {
    const std::vector<Patch>& patches;
    std::span<const Rgb> radiosity;
    const GatherSources* sources;  // null: every patch is a source
    const GatherOptions& options;
    const PointFactor& factor;
    const std::vector<SourceCard>& cards;
    double lift;  // Visibility::offset: rays start and end this far off their surfaces
    bool shapes;  // GatherOptions::source_corners given
};

/// Takes the sources of one point x, one at a time: a source's term and rays go into the
/// scratch lists, its children onto `pending`, and a source proved unblocked straight into
/// open_sum.
struct SourceTaker {
    const GatherInputs& in;
    const GatherPoint& x;
    glm::dvec3 from;  // x lifted off its surface: where its rays start
    SplitMix64& rng;
    PointScratch& scratch;
    Rgb open_sum;  // the sources proved wholly visible: no rays

    void operator()(std::size_t j, bool unblocked) {
        const SourceCard& c = in.cards[j];
        if (c.surface == x.surface || c.dark) return;
        if (glm::dot(c.normal, x.position) - c.offset <= 0) return;  // x behind: it sends nothing x's way
        const double distance = glm::length(c.centre - x.position);
        if (distance < c.descend_within) {
            for (int k = 0; k < 4; ++k)
                scratch.pending.push_back({std::size_t(in.sources->first_child[j] + k), unblocked});
            return;
        }
        const double f0 = in.factor(x.position, x.normal, j, c, distance);
        if (!(f0 > 0)) return;
        if (unblocked) {
            open_sum += in.radiosity[j] * f0;
            return;
        }
        const GatherOptions& options = in.options;
        const Patch& p = in.patches[j];
        // Stratified targets on p: a k x k jittered grid in its unit-square coordinates.
        int want = std::clamp(int(std::ceil(f0 * options.rays_per_unit_factor)), 1, options.max_rays);
        if (p.emission.max() > 0) want = std::max(want, options.emitter_rays);
        const int side = grid_side(want);
        const bool shaped = in.shapes && distance < options.shape_within * c.radius;
        Rgb mean, shape;
        if (shaped) {
            scratch.weights.resize(scratch.segments.size());
            for (int k = 0; k < p.vertex_count; ++k) mean += options.source_corners[4 * j + std::size_t(k)];
            mean *= 1.0 / p.vertex_count;
            shape = ExactShape(x.position, x.normal)(p, &options.source_corners[4 * j], mean);
        }
        scratch.terms.push_back({j, scratch.segments.size(), std::size_t(side * side), f0, shaped, shape});
        for (int a = 0; a < side; ++a)
            for (int b = 0; b < side; ++b) {
                // v drawn first: the order the call patch_point(p, u(), v()) evaluated them in.
                const double v = (b + rng.uniform()) / side;
                const double u = (a + rng.uniform()) / side;
                const glm::dvec3 y = patch_point(p, u, v);
                if (shaped) scratch.weights.push_back(corner_shape(p, &options.source_corners[4 * j], mean, u, v));
                const glm::dvec3 d = y - x.position;
                const double r2 = glm::dot(d, d);
                scratch.kernel.push_back(std::max(0.0, glm::dot(x.normal, d)) * std::max(0.0, -glm::dot(p.normal, d)) /
                                         (r2 * r2));
                scratch.segments.push_back({from, y + in.lift * p.normal});
            }
    }
};

/// Takes every source of the point with source list `list`: the list, then (chained) the
/// list's parent's, and so on up; every patch when there are no lists. A source's children
/// are taken before the next listed source.
void take_sources(const GatherInputs& in, std::size_t list, SourceTaker& take) {
    const GatherSources* sources = in.sources;
    const bool marked = sources && !sources->unblocked.empty();
    const bool chained = sources && !sources->list_parent.empty();
    std::vector<std::pair<std::size_t, bool>>& pending = take.scratch.pending;
    std::int64_t at = std::int64_t(list);
    std::size_t entry = sources ? sources->offsets[list] : 0;
    std::size_t end = sources ? sources->offsets[list + 1] : in.patches.size();
    for (;;) {
        if (entry == end) {
            if (!chained || (at = sources->list_parent[std::size_t(at)]) < 0) break;
            entry = sources->offsets[std::size_t(at)];
            end = sources->offsets[std::size_t(at) + 1];
            continue;
        }
        const std::size_t e = entry++;
        // The sources are scattered over the tree's nodes: fetch the next one's card while
        // this one is taken (its first touch was the gather's largest stall).
        if (sources && entry < end) {
            const char* next = reinterpret_cast<const char*>(&in.cards[sources->patches[entry]]);
            for (std::size_t line = 0; line < sizeof(SourceCard); line += 64) __builtin_prefetch(next + line);
        }
        take(sources ? sources->patches[e] : e, marked && sources->unblocked[e]);
        while (!pending.empty()) {  // children last in, first out, each before its siblings
            const auto [j, unblocked] = pending.back();
            pending.pop_back();
            take(j, unblocked);
        }
    }
}

/// `gathered` plus every term's radiosity times its factor and the kernel-weighted share of
/// its rays that arrived (weighted by the samples' shape where the term is shaped).
Rgb add_terms(Rgb gathered, const GatherInputs& in, const PointScratch& scratch, Rgb& near) {
    const std::vector<double>& kernel = scratch.kernel;
    const std::vector<std::uint8_t>& blocked = scratch.blocked;
    for (const Term& t : scratch.terms) {
        double open = 0, total = 0;
        std::size_t open_rays = 0;
        for (std::size_t s = t.first; s < t.first + t.count; ++s) {
            total += kernel[s];
            open += blocked[s] ? 0.0 : kernel[s];
            open_rays += blocked[s] ? 0 : 1;
        }
        // All samples at zero kernel (grazing): the plain open fraction. No rays: unblocked.
        const double share = t.count == 0 ? 1.0 : total > 0 ? open / total : double(open_rays) / double(t.count);
        if (t.shaped && total > 0) {
            // The exact shape, times the share of it the rays find open (weighted by kernel
            // and shape, so a blocked dark strip hides less than a blocked bright one).
            Rgb shaped_open, shaped_all;
            for (std::size_t s = t.first; s < t.first + t.count; ++s) {
                const Rgb w = scratch.weights[s] * kernel[s];
                shaped_all += w;
                if (!blocked[s]) shaped_open += w;
            }
            Rgb seen;
            for (int c = 0; c < 3; ++c) seen[c] = shaped_all[c] > 0 ? shaped_open[c] / shaped_all[c] : share;
            const Rgb term = in.radiosity[t.patch] * t.shape * seen * t.f0;
            gathered += term;
            near += term;
            continue;
        }
        const Rgb term = in.radiosity[t.patch] * (t.f0 * share);
        gathered += term;
        if (t.shaped) near += term;
    }
    return gathered;
}

/// B at point i, x, which reflects: its emission plus its reflectance times what it gathers.
/// First every source's unoccluded factor and ray targets, then all the point's rays in one
/// batch (traced as packets), then the sum.
Rgb gather_at(const GatherInputs& in, const Visibility& visibility, std::size_t i, const GatherPoint& x, Rgb& near) {
    SplitMix64 rng{in.options.seed * 0x9E3779B97F4A7C15ull + i};
    thread_local PointScratch scratch;
    scratch.terms.clear();
    scratch.weights.clear();
    scratch.segments.clear();
    scratch.kernel.clear();
    scratch.pending.clear();
    const std::size_t list = in.sources ? in.sources->list[i] : 0;
    SourceTaker take{in, x, x.position + in.lift * x.normal, rng, scratch, Rgb()};
    take_sources(in, list, take);
    scratch.blocked.resize(scratch.segments.size());
    visibility.occluded(scratch.segments, scratch.blocked);
    Rgb gathered = add_terms(take.open_sum, in, scratch, near);
    near = x.reflectance * near;
    if (in.sources && !in.sources->irradiance.empty()) gathered += in.sources->irradiance[list];
    return x.emission + x.reflectance * gathered;
}

/// Both final_gathers: over every patch (sources null) or over each point's list.
std::vector<Rgb> gather(const std::vector<Patch>& patches, std::span<const Rgb> radiosity, const Visibility& visibility,
                        std::span<const GatherPoint> points, const GatherSources* sources, const GatherOptions& options,
                        const std::atomic<bool>* cancel, const std::function<void(std::size_t, std::size_t)>& progress,
                        std::vector<Rgb>* near_part = nullptr) {
    std::vector<Rgb> out(points.size());
    if (near_part) near_part->assign(points.size(), Rgb());
    for (std::size_t i = 0; i < points.size(); ++i) out[i] = points[i].emission;
    std::atomic<std::size_t> done{0};
    const double lift = visibility.offset();
    const PointFactor factor(patches, options.kernel_tolerance);
    const std::vector<SourceCard> cards = source_cards(patches, radiosity, factor, sources);
    if (!options.source_corners.empty() && options.source_corners.size() != 4 * patches.size())
        throw std::invalid_argument("final gather: source corners must be 4 per patch");
    const bool shapes = !options.source_corners.empty();
    const GatherInputs in{patches, radiosity, sources, options, factor, cards, lift, shapes};
    tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) {
        if (cancel && cancel->load(std::memory_order_relaxed)) return;
        const GatherPoint& x = points[i];
        if (x.reflectance.max() <= 0) return;  // reflects nothing: B = E
        Rgb near;
        out[i] = gather_at(in, visibility, i, x, near);
        if (near_part) (*near_part)[i] = near;
        const std::size_t d = ++done;
        if (progress) progress(d, points.size());
    });
    return out;
}

}  // namespace

std::vector<Rgb> final_gather(const std::vector<Patch>& patches, std::span<const Rgb> radiosity,
                              const Visibility& visibility, std::span<const GatherPoint> points,
                              const GatherOptions& options, const std::atomic<bool>* cancel,
                              const std::function<void(std::size_t, std::size_t)>& progress) {
    return gather(patches, radiosity, visibility, points, nullptr, options, cancel, progress);
}

std::vector<Rgb> final_gather_with_near_part(const std::vector<Patch>& patches, std::span<const Rgb> radiosity,
                                             const Visibility& visibility, std::span<const GatherPoint> points,
                                             const GatherOptions& options, std::vector<Rgb>& near_part,
                                             const std::atomic<bool>* cancel,
                                             const std::function<void(std::size_t, std::size_t)>& progress) {
    return gather(patches, radiosity, visibility, points, nullptr, options, cancel, progress, &near_part);
}

std::vector<Rgb> final_gather(const std::vector<Patch>& patches, std::span<const Rgb> radiosity,
                              const Visibility& visibility, std::span<const GatherPoint> points,
                              const GatherSources& sources, const GatherOptions& options,
                              const std::atomic<bool>* cancel,
                              const std::function<void(std::size_t, std::size_t)>& progress) {
    if (sources.list.size() != points.size())
        throw std::invalid_argument("final gather: a source list is needed for every point");
    if (!sources.list_parent.empty()) {
        if (sources.list_parent.size() + 1 != sources.offsets.size())
            throw std::invalid_argument("final gather: a chained list's parent is needed for every list");
        for (std::size_t l = 0; l < sources.list_parent.size(); ++l)
            if (sources.list_parent[l] < -1 || sources.list_parent[l] >= std::int64_t(l))
                throw std::invalid_argument("final gather: a chained list's parent must come before it, got " +
                                            std::to_string(sources.list_parent[l]) + " for list " + std::to_string(l));
    }
    if (!sources.unblocked.empty() && sources.unblocked.size() != sources.patches.size())
        throw std::invalid_argument("final gather: the unblocked marks must be one per listed source");
    if (sources.descend > 0 &&
        (sources.first_child.size() != patches.size() || sources.spread.size() != patches.size()))
        throw std::invalid_argument("final gather: going down to children needs them and their spread for every patch");
    return gather(patches, radiosity, visibility, points, &sources, options, cancel, progress);
}

std::vector<GatherPoint> vertex_gather_points(const PatchMesh& mesh) {
    // A tenth of the way: far enough to clear the lamp's 0.1 mm layer from the 2k-patch box's
    // cells on (1% left the vertices on the lamp's edges half dark and the point data 0.9% off
    // the 0.1% probes at 4k and 8k patches; 5-20% all give 0.72% and 0.50%), near enough that an
    // interior vertex, where the centres around it balance, hardly moves.
    static constexpr double kNudge = 0.1;
    const auto& patches = mesh.patches();
    const auto& om = mesh.mesh();
    std::vector<GatherPoint> out(om.n_vertices());
    std::vector<glm::dvec3> towards(om.n_vertices(), glm::dvec3(0.0));
    std::vector<double> count(om.n_vertices(), 0.0);
    std::vector<std::size_t> last_patch(om.n_vertices(), 0);
    for (std::size_t i = 0; i < patches.size(); ++i) {
        const Patch& p = patches[i];
        for (int v : mesh.patch_vertex_indices(i)) {
            auto& g = out[std::size_t(v)];
            g.normal = p.normal;
            g.surface = p.surface;
            g.reflectance = p.reflectance;
            g.emission = p.emission;
            towards[std::size_t(v)] += p.centre;
            count[std::size_t(v)] += 1.0;
            last_patch[std::size_t(v)] = i;
        }
    }
    // The share of the way towards the centres: kNudge, or further where the mesh asks for a
    // clearance (PatchMesh::gather_clearance), but never past half-way.
    auto share = [&](std::size_t v, const glm::dvec3& to) {
        const double len = glm::length(to - mesh.vertex_position(v));
        const double clearance = mesh.gather_clearance(v);
        return len > 0 && clearance > kNudge * len ? std::min(clearance / len, 0.5) : kNudge;
    };
    for (std::size_t v = 0; v < out.size(); ++v) {
        const glm::dvec3 x = mesh.vertex_position(v);
        if (count[v] == 0) {
            out[v].position = x;
            continue;
        }
        const glm::dvec3 to = towards[v] / count[v];
        out[v].position = x + share(v, to) * (to - x);
    }
    // Where the patches around a vertex fill more than a half-turn (a hole's corner, a
    // notch), the point so moved can lie in none of them: it would leave the surface (over
    // the lamp, behind it). Such a vertex moves towards the centre of one of its own cells.
    for (std::size_t i = 0; i < patches.size(); ++i)
        for (int v : mesh.patch_vertex_indices(i))
            if (covers(patches[i], out[std::size_t(v)].position, 1e-9 * patches[i].area))
                out[std::size_t(v)].cell = int(i);
    for (std::size_t v = 0; v < out.size(); ++v) {
        if (out[v].cell >= 0 || count[v] == 0) continue;
        const glm::dvec3 x = mesh.vertex_position(v);
        out[v].position = x + share(v, patches[last_patch[v]].centre) * (patches[last_patch[v]].centre - x);
        out[v].cell = int(last_patch[v]);
    }
    return out;
}

std::vector<GatherPoint> centre_gather_points(const std::vector<Patch>& patches) {
    std::vector<GatherPoint> out;
    out.reserve(patches.size());
    for (const Patch& p : patches)
        out.push_back({p.centre, p.normal, p.surface, p.reflectance, p.emission, int(out.size())});
    return out;
}

}  // namespace bounce
