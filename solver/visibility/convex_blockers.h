// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/meshing/patch.h"

namespace bounce {

/// The convex solids of a scene (blocks, boxes, furniture parts), found among its patches, so
/// that a blocker is one shadow rather than as many as the solid has patches. Seen from a
/// point, a convex solid casts a convex shadow on a plane: the central projection of its
/// part between the point and the plane, which is the convex hull of the projected corners of
/// that part (Nishita and Nakamae 1985 use the same property for shadow volumes of convex
/// polyhedra).
///
/// Patches are joined when they come from one input surface, or share a vertex and lie each
/// wholly behind the other's plane (a convex edge). A group is a solid when every one of its
/// vertices lies behind every member plane, and its hull is closed: each hull facet is covered
/// by members, or rests on a surface of the scene that faces it (a block's missing bottom on
/// the floor), so no segment between two other patches can pass through the hull without
/// crossing a member. A surface cut into several patches on one plane that tile a convex
/// polygon is a flat solid (its outline): a segment that crosses the polygon crosses a member,
/// so a blocker cut 16 x 16 is one shadow, not 256. Anything else stays a single patch.
class ConvexBlockers {
public:
    /// `flat`: also make flat solids of tiled convex surfaces (one shadow where the rays'
    /// fallback would see many; more of a scene's pairs are then clipped, at more cost).
    explicit ConvexBlockers(const std::vector<Patch>& patches, bool flat = true);

    struct Solid {
        std::vector<glm::dvec3> corners;                             // the hull's vertices
        std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;  // the hull's edges, as corner indices
        bool flat = false;  // one plane: a tiled convex polygon, its corners in order round it
    };
    /// The solid patch i belongs to, or -1.
    std::int32_t solid_of(std::size_t i) const { return m_solid_of[i]; }
    const Solid& solid(std::size_t s) const { return m_solids[s]; }
    std::size_t solid_count() const { return m_solids.size(); }

private:
    std::vector<std::int32_t> m_solid_of;
    std::vector<Solid> m_solids;
};

/// The shadow of a convex solid seen from x on the plane through o with unit normal m (x in
/// front of it, at height hx = m . (x - o) > 0): the part of the solid between the plane and
/// x's height projected from x, as a convex polygon in the plane, counter-clockwise about m.
/// Empty when that part is empty or has no area.
void convex_shadow(const ConvexBlockers::Solid& solid, const glm::dvec3& x, const glm::dvec3& o, const glm::dvec3& m,
                   std::vector<glm::dvec3>& out);

}  // namespace bounce
