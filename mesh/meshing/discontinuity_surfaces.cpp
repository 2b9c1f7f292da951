// SPDX-License-Identifier: MIT
#include <cmath>
#include <sstream>

#include <glm/geometric.hpp>

#include "mesh/meshing/discontinuity_mesh.h"
#include "mesh/scene/polygon.h"

namespace bounce {
namespace {

using V = glm::dvec3;

// A (nearly) coplanar neighbour sharing an edge with a triangulated surface (the red wall's
// two triangles, 0.2 degrees apart) is triangulated too, and each takes the other's points
// on the seam: no T-vertex where the two meet. (At creases, as in the uniform mesh, each
// surface keeps its own vertices.)
std::vector<std::vector<std::size_t>> seam_neighbours(const Scene& scene) {
    const std::size_t n = scene.surfaces.size();
    auto emits = [&](std::size_t si) {
        return scene.materials[std::size_t(scene.surfaces[si].material)].emission.max() > 0;
    };
    std::vector<std::vector<std::size_t>> neighbours(n);
    for (std::size_t i = 0; i < n; ++i) {
        const auto& a = scene.surfaces[i].vertices;
        const V na = newell_normal(a);
        if (!(glm::length(na) > 0) || emits(i)) continue;
        const double tol = 1e-9 * std::sqrt(glm::length(na));
        for (std::size_t j = i + 1; j < n; ++j) {
            const auto& b = scene.surfaces[j].vertices;
            const V nb = newell_normal(b);
            if (!(glm::length(nb) > 0) || emits(j) ||
                glm::dot(na, nb) < std::cos(0.02) * glm::length(na) * glm::length(nb))  // about a degree
                continue;
            bool shared = false;
            for (std::size_t k = 0; k < a.size() && !shared; ++k)
                for (std::size_t l = 0; l < b.size() && !shared; ++l)
                    shared = glm::length(a[k] - b[(l + 1) % b.size()]) <= tol &&
                             glm::length(a[(k + 1) % a.size()] - b[l]) <= tol;
            if (shared) {
                neighbours[i].push_back(j);
                neighbours[j].push_back(i);
            }
        }
    }
    return neighbours;
}

/// The surfaces with traced boundaries and, through seam neighbours, the surfaces sharing a
/// seam with them.
std::vector<bool> wanted_surfaces(const TracedDiscontinuities& traced,
                                  const std::vector<std::vector<std::size_t>>& neighbours) {
    const std::size_t n = neighbours.size();
    std::vector<bool> wanted(n, false);
    std::vector<std::size_t> queue;
    for (std::size_t si = 0; si < n; ++si)
        if (!traced.per_surface[si].empty()) {
            wanted[si] = true;
            queue.push_back(si);
        }
    for (std::size_t k = 0; k < queue.size(); ++k)
        for (const std::size_t j : neighbours[queue[k]])
            if (!wanted[j]) {
                wanted[j] = true;
                queue.push_back(j);
            }
    return wanted;
}

/// The points of the neighbours' triangulations on surface si's outline (not its corners) that
/// si's own triangulation lacks.
std::vector<V> seam_points(const Scene& scene, std::size_t si, const std::vector<std::vector<std::size_t>>& neighbours,
                           const std::vector<SurfaceTriangulation>& first) {
    const auto& poly = scene.surfaces[si].vertices;
    const double tol = 1e-9 * std::sqrt(polygon_area(poly));
    std::vector<V> seam;
    for (const std::size_t j : neighbours[si])
        for (const V& p : first[j].points) {
            bool on = false;
            for (std::size_t k = 0; k < poly.size() && !on; ++k) {
                const V a = poly[k], d = poly[(k + 1) % poly.size()] - a;
                const double t = glm::dot(p - a, d) / glm::dot(d, d);
                on = t > 1e-9 && t < 1 - 1e-9 && glm::length(a + t * d - p) <= tol;
            }
            if (!on) continue;
            bool known = false;
            for (const V& q : first[si].points) known = known || glm::length(q - p) <= tol;
            if (!known) seam.push_back(p);
        }
    return seam;
}

/// A surface whose refinement ran over its budget keeps its grid, and so do its seam
/// neighbours (their seam points would be missing on its side). Returns the warning line, or
/// nothing when no surface was given up.
std::string give_up_over_budget(const Scene& scene, const std::vector<bool>& wanted,
                                const std::vector<std::vector<std::size_t>>& neighbours,
                                std::vector<SurfaceTriangulation>& first) {
    const std::size_t n = neighbours.size();
    std::vector<std::size_t> given_up;
    for (std::size_t si = 0; si < n; ++si)
        if (wanted[si] && first[si].over_budget) given_up.push_back(si);
    for (std::size_t k = 0; k < given_up.size(); ++k)
        for (const std::size_t j : neighbours[given_up[k]])
            if (wanted[j] && !first[j].triangles.empty()) {
                first[j] = {};
                given_up.push_back(j);
            }
    if (given_up.empty()) return {};
    std::ostringstream msg;
    msg << "discontinuity meshing: the shadow boundaries on "
        << describe(scene.surfaces[given_up[0]].where, scene.surfaces[given_up[0]].object);
    if (given_up.size() > 1)
        msg << " and " << given_up.size() - 1 << " more surface" << (given_up.size() > 2 ? "s" : "");
    msg << " leave slivers too thin to mesh within the area limit; meshed uniformly";
    return msg.str();
}

}  // namespace

DiscontinuitySurfaces triangulate_discontinuity_surfaces(const Scene& scene, std::size_t max_discontinuities,
                                                         double max_area, double aspect_bound) {
    const TracedDiscontinuities traced = trace_discontinuities(scene, max_discontinuities);
    DiscontinuitySurfaces out;
    out.warnings = traced.warnings;
    const std::size_t n = scene.surfaces.size();
    const std::vector<std::vector<std::size_t>> neighbours = seam_neighbours(scene);
    const std::vector<bool> wanted = wanted_surfaces(traced, neighbours);
    std::vector<SurfaceTriangulation> first(n);
    for (std::size_t si = 0; si < n; ++si)
        if (wanted[si]) first[si] = triangulate_surface(scene, int(si), traced.per_surface[si], max_area, aspect_bound);
    // The seams: each surface again, with its neighbours' points on the shared edges that it
    // lacks put in after refinement (mesh/meshing/discontinuity_mesh.h).
    std::vector<SurfaceTriangulation> with_seams = first;
    for (std::size_t si = 0; si < n; ++si) {
        if (!wanted[si]) continue;
        const std::vector<V> seam = seam_points(scene, si, neighbours, first);
        if (!seam.empty())
            with_seams[si] = triangulate_surface(scene, int(si), traced.per_surface[si], max_area, aspect_bound, seam);
    }
    first = std::move(with_seams);
    if (std::string warning = give_up_over_budget(scene, wanted, neighbours, first); !warning.empty())
        out.warnings.push_back(std::move(warning));
    out.per_surface = std::move(first);
    return out;
}

}  // namespace bounce
