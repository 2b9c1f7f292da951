// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "mesh/meshing/patch.h"
#include "mesh/scene/specular_occluders.h"

namespace bounce {

/// Answers "is the open segment a-b blocked by any patch?". Callers lift the endpoints off
/// their own patches along the normals (by `offset()`), so a ray never hits its own patch or
/// a coplanar neighbour; backends ignore hits within offset() / 4 of either end (see trim). Implementations are
/// thread-safe for concurrent queries.
class Visibility {
public:
    struct Segment {
        glm::dvec3 a, b;
    };
    virtual ~Visibility() = default;
    virtual bool occluded(const glm::dvec3& a, const glm::dvec3& b) const = 0;
    /// blocked[k] = occluded(segments[k]) for a batch (a pair's rays, traced as packets by
    /// backends that can). The answers equal the one-at-a-time ones.
    virtual void occluded(std::span<const Segment> segments, std::span<std::uint8_t> blocked) const {
        for (std::size_t k = 0; k < segments.size(); ++k) blocked[k] = occluded(segments[k].a, segments[k].b);
    }
    /// Fraction of the segments that arrive unblocked (traced as one batch); 1 for none.
    double open_fraction(std::span<const Segment> segments) const {
        if (segments.empty()) return 1.0;
        thread_local std::vector<std::uint8_t> blocked;
        blocked.resize(segments.size());
        occluded(segments, blocked);
        std::size_t open = 0;
        for (const std::uint8_t b : blocked) open += b ? 0 : 1;
        return double(open) / double(segments.size());
    }
    /// The first thing the open segment a-b meets, trimmed as occluded() trims it: the index of
    /// the patch (whichever side it meets), kNothing, or kOccluder for a mirror or glass
    /// triangle.
    virtual int first_patch(const glm::dvec3& a, const glm::dvec3& b) const = 0;
    static constexpr int kNothing = -1;
    static constexpr int kOccluder = -2;
    virtual std::string name() const = 0;
    /// Distance to lift ray endpoints off their surfaces: tiny against the scene (1e-6 of its
    /// diagonal), yet far above the rounding error of the coordinates.
    double offset() const { return m_offset; }
    /// True when rays are also blocked by occluder triangles that are no patches (mirrors and
    /// glass): a shaft test over the patches alone (ShaftCuller) cannot prove a pair unblocked.
    bool has_occluders() const { return m_has_occluders; }

protected:
    /// The part of a segment that is tested: t in [t0, 1 - t0] of a + t (b - a), trimmed at
    /// both ends by a quarter of the offset (t0 = offset / (4 |b - a|)). An endpoint within
    /// float rounding of a wall at right angles to its patch (a point at a box's edge) would
    /// otherwise hit that wall at t ~ 0: Embree rounds coordinates to float, and did (a false
    /// occlusion in an empty box). A quarter, not the whole offset: a segment lifted by the
    /// offset crosses its own surface's plane at least one offset from its end, and that
    /// crossing (e.g. a block's side just under the lifted end on its top) must stay well
    /// outside the trimmed part, where both backends see it alike. Returns >= 0.5 when nothing
    /// is left to test.
    double trim(const glm::dvec3& a, const glm::dvec3& b) const {
        const double l = glm::length(b - a);
        return l > 0 ? 0.25 * m_offset / l : 1.0;
    }

    /// Sets the offset for these patches (1e-6 of their bounding box's diagonal, the same in
    /// every backend, so they trace the same rays) and returns the box's centre.
    glm::dvec3 fit_offset(const std::vector<Patch>& patches) {
        if (patches.empty()) return glm::dvec3(0.0);
        glm::dvec3 lo(1e300), hi(-1e300);
        for (const auto& p : patches)
            for (int k = 0; k < p.vertex_count; ++k) {
                lo = glm::min(lo, p.vertices[k]);
                hi = glm::max(hi, p.vertices[k]);
            }
        m_offset = 1e-6 * glm::length(hi - lo);
        return 0.5 * (lo + hi);
    }

    double m_offset = 0.0;
    bool m_has_occluders = false;
};

/// CGAL AABB tree of the patches' triangles and the occluders, queried with exact predicates.
std::unique_ptr<Visibility> make_cgal_visibility(const std::vector<Patch>& patches,
                                                 std::span<const OccluderTriangle> occluders = {});

/// Embree 3 BVH of the patches' triangles and the occluders (single precision, watertight
/// traversal).
std::unique_ptr<Visibility> make_embree_visibility(const std::vector<Patch>& patches,
                                                   std::span<const OccluderTriangle> occluders = {});

/// Backend names, the default (the faster, measured in bench/bench_visibility) first.
std::vector<std::string> visibility_backends();

/// The backend called `backend`; std::invalid_argument names the valid ones otherwise.
/// `occluders` block rays without being patches: the scene's mirror and glass objects
/// (specular_occluders). The offset is fitted to the patches alone, so with no occluders the
/// rays and answers are those of a diffuse scene.
std::unique_ptr<Visibility> make_visibility(const std::string& backend, const std::vector<Patch>& patches,
                                            std::span<const OccluderTriangle> occluders = {});

}  // namespace bounce
