// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/meshing/patch.h"

namespace bounce {

/// Candidate blockers of a patch pair, found before any ray is traced: a conservative shaft
/// test (Haines and Wallace 1991, "Shaft culling for efficient ray-cast radiosity") over a
/// bounding-volume hierarchy of the patches, in double precision.
///
/// The shaft of the pair (i, j) is the convex hull of the two polygons, bounded by their planes
/// and by the planes through an edge of one and a vertex of the other that hold both polygons
/// on one side. A patch k is a candidate unless it is separated from the shaft: its box misses
/// the shaft's box, or it lies outside (or on) one of the shaft's planes, or the whole shaft
/// lies on one side of k's own plane (so no segment between i and j crosses it). In an empty
/// convex room every other patch is separated by its own plane: no candidates, no rays. The
/// test never drops a true blocker; it may keep patches that block nothing. Patches are grouped
/// by plane first, so a wall of many patches is rejected by one test.
class ShaftCuller {
public:
    /// Callers test a pair with unblocked() when the rays it could spare, times this, reach
    /// plane_groups(): in a room every pair, among furniture only pairs that spare many rays.
    /// On the Cornell box's gather a ray with its target and kernel cost about 2-3 of the
    /// box's plane tests (5.7 million rays spared, 0.3 s, for 272k tests of 11 planes, 69 ms),
    /// but a test walks more per plane among furniture; 16 keeps the box testing every link and
    /// took the 10k office's hierarchical solve at 3e-6 from 58 s to 55 s (every link: 80 s).
    static constexpr double kPlaneTestsPerRay = 16.0;

    explicit ShaftCuller(const std::vector<Patch>& patches);

    /// Replaces `out` with the candidate blockers of the pair (i, j) (neither i nor j).
    void candidates(std::size_t i, std::size_t j, std::vector<std::uint32_t>& out) const;
    /// The first, cheap stage of `candidates` alone: true when every plane group lies beside
    /// the pair's shaft, so nothing can block it. A false answer proves nothing (the full test
    /// may still find no candidate); it costs a few dot products per plane of the scene, while
    /// the full test walks the tree and can cost a hundred rays' worth in cluttered scenes.
    bool clear(std::size_t i, std::size_t j) const;
    /// True when no patch of the culler is a candidate blocker of the shaft between polygons
    /// p and q, which need not be among its patches (a hierarchy's elements against the input
    /// patches): every segment from p to q is then unoccluded. The patches p and q lie on are
    /// separated by their own planes and never count. p and q must lie within the convex hull
    /// of the culler's patches (pieces of them do): the planes every vertex of the scene lies
    /// beside are left out at construction, which holds only for shafts inside that hull.
    bool unblocked(const Patch& p, const Patch& q) const;
    const std::vector<Patch>& patches() const { return m_patches; }
    /// The planes a shaft may cross (the scene's planes less those every vertex lies beside):
    /// a test that proves a shaft empty visits each once, so it costs about this many plane
    /// tests (11 on the Cornell box, thousands in a furnished room).
    std::size_t plane_groups() const { return m_groups.size(); }

private:
    struct Node {
        glm::dvec3 lo, hi;    // box of everything below
        std::uint32_t first;  // leaf: first index into m_order; inner: left child (right = first + 1)
        std::uint32_t count;  // leaf: patch count; 0 for an inner node
    };
    /// Patches in one plane (a wall cut into patches) share one test: when the whole shaft is
    /// on one side of their plane, none of them is a candidate, and their tree is skipped.
    struct Group {
        glm::dvec3 normal;
        double offset;       // plane: normal . x = offset
        std::uint32_t root;  // its tree's root in m_nodes
        double spread;       // the members' largest distance from that plane
    };
    void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end);
    /// The candidate search of the shaft between p and q (patches i and j of the culler, which
    /// are skipped, or any index for outside polygons): found(k) for each candidate k, until it
    /// returns true.
    template <class Found>
    void walk(const Patch& p, const Patch& q, std::size_t i, std::size_t j, Found&& found) const;
    /// True when every vertex of the scene lies beside g's plane (on its front, or all behind):
    /// then so does every shaft, whose corners are scene vertices, and g never blocks. The walls
    /// of a convex room are such planes (View3D's prescreen finds the same: no rays at all).
    bool supporting(const Group& g, const std::vector<Patch>& patches, const glm::dvec3& lo,
                    const glm::dvec3& hi) const;
    /// Whether all the points lie above g's plane, and whether all lie below it, beyond its
    /// spread: the one side test behind beside(), the per-patch bits and supporting().
    struct Sides {
        bool above = true, below = true;
    };
    Sides sides(const Group& g, const glm::dvec3* pts, int np) const;
    /// True when the points (the pair's vertices) lie on one side of g's plane, beyond its spread.
    bool beside(const Group& g, const glm::dvec3* pts, int np) const;

    const std::vector<Patch>& m_patches;
    std::vector<glm::dvec3> m_lo, m_hi;  // per-patch boxes
    std::vector<std::uint32_t> m_order;  // patch indices, leaves are ranges of it
    std::vector<Node> m_nodes;           // the groups' trees
    std::vector<Group> m_groups;         // only the planes some shaft may cross (supporting ones are left out)
    /// Per patch, one bit per plane group: the patch lies wholly on the group's positive
    /// (m_above) or negative (m_below) side, beyond its spread (beside() for the patch's own
    /// vertices). The shaft of (i, j) is beside group g exactly when both patches are on the
    /// same side of it, so clear() is a few word operations. m_words words per patch; 0 when
    /// patches x groups is over the budget (then clear() tests the corners per pair).
    std::vector<std::uint64_t> m_above, m_below;
    std::size_t m_words = 0;
    double m_tol = 0.0;  // 1e-9 of the scene's diagonal: "on the plane"
};

}  // namespace bounce
