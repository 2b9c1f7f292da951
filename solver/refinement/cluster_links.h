// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "mesh/meshing/element_tree.h"
#include "mesh/meshing/patch.h"
#include "solver/refinement/cluster_tree.h"

namespace bounce {

class Visibility;

/// The parts of hierarchical radiosity (hierarchical_radiosity.h) that its files share: the
/// cluster links' geometry, the link refiner and the iteration over the links.
namespace hierarchical {

/// One end of a link with a cluster: what the isotropic transfer needs of it.
struct End {
    double area = 0.0;
    glm::dvec3 centre{0.0};
    double radius = 0.0;  // bounding sphere about centre
    const ClusterTree::Cluster* cluster = nullptr;
    const Patch* element = nullptr;
    std::uint32_t ref = 0;
    const ClusterTree* tree = nullptr;
    const std::vector<Patch>* patches = nullptr;  // the input patches (the clusters' members)
    /// The area the end shows towards unit d (its members facing d; ClusterTree::shown_area).
    double shown(const glm::dvec3& d) const {
        if (element) return element->area * std::max(0.0, glm::dot(element->normal, d));
        return tree->shown_area(ref, d, *patches);
    }
    /// True when no part of the end is strictly in front of element p's plane.
    bool behind(const Patch& p) const {
        if (element) return wholly_behind(p, *element);
        const double tol = 1e-12 * std::sqrt(p.area + area);
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 x((k & 1) ? cluster->hi.x : cluster->lo.x, (k & 2) ? cluster->hi.y : cluster->lo.y,
                               (k & 4) ? cluster->hi.z : cluster->lo.z);
            if (p.height(x) > tol) return false;
        }
        return true;
    }
};

/// End `ref` of a link: an element node of `tree` or a cluster of `clusters`.
End end_of(const ElementTree& tree, const ClusterTree& clusters, std::uint32_t ref);

/// A_a F_ab for a link with a cluster, unoccluded: both ends shrunk to points at their
/// centres, each showing the other the area its members turn towards it (Sillion 1995's
/// isotropic cluster with the members' orientation kept, as Smits et al. 1994 do), capped so
/// that neither F exceeds 1. Ends whose bounding spheres meet (faint links the power bound
/// accepts) have no point-to-point kernel: it is softened there as Wallace, Elmquist and
/// Haines (1989) soften the point-to-disc factor, pi r^2 + A for pi r^2, so they do not send
/// each other all they have (the cap alone lets a gather over such links diverge).
double cluster_transfer(const End& a, const End& b);

/// Fraction of the rays between the ends' sample points (member centroids, up to 4 each)
/// that arrive unblocked; only pairs of samples that face each other cast a ray (1 if none).
double cluster_visible_fraction(const End& a, const End& b, const Visibility& visibility);

}  // namespace hierarchical
}  // namespace bounce
