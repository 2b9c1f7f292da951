// SPDX-License-Identifier: MIT
#include "solver/refinement/cluster_links.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <span>

#include "solver/visibility/visibility.h"

namespace bounce::hierarchical {

End end_of(const ElementTree& tree, const ClusterTree& clusters, std::uint32_t ref) {
    End e;
    if (ClusterTree::is_cluster(ref)) {
        e.cluster = &clusters.cluster(ref);
        e.ref = ref;
        e.tree = &clusters;
        e.patches = &tree.roots();
        e.area = e.cluster->area;
        e.centre = e.cluster->centre;
        e.radius = e.cluster->radius;
    } else {
        e.element = &tree.geometry()[ref];
        e.area = e.element->area;
        e.centre = e.element->centre;
        e.radius = circumradius(*e.element);
    }
    return e;
}

double cluster_transfer(const End& a, const End& b) {
    const glm::dvec3 v = b.centre - a.centre;
    const double r2 = glm::dot(v, v);
    if (!(r2 > 0)) return 0.0;
    const glm::dvec3 d = v / std::sqrt(r2);
    const bool touching = std::sqrt(r2) <= a.radius + b.radius;
    const double soft = touching ? std::max(a.area, b.area) : 0.0;
    return std::min({a.shown(d) * b.shown(-d) / (std::numbers::pi * r2 + soft), a.area, b.area});
}

double cluster_visible_fraction(const End& a, const End& b, const Visibility& visibility) {
    std::array<glm::dvec3, 4> pa{}, na{}, pb{}, nb{};
    auto samples = [](const End& e, std::array<glm::dvec3, 4>& p, std::array<glm::dvec3, 4>& n) {
        if (e.element) {
            p[0] = e.element->centre;
            n[0] = e.element->normal;
            return 1;
        }
        p = e.cluster->sample;
        n = e.cluster->sample_normal;
        return e.cluster->sample_count;
    };
    const int ca = samples(a, pa, na), cb = samples(b, pb, nb);
    std::array<Visibility::Segment, 16> segments{};
    std::size_t count = 0;
    const double off = visibility.offset();
    for (int i = 0; i < ca; ++i)
        for (int j = 0; j < cb; ++j) {
            const glm::dvec3 v = pb[std::size_t(j)] - pa[std::size_t(i)];
            if (glm::dot(na[std::size_t(i)], v) <= 0 || glm::dot(nb[std::size_t(j)], v) >= 0) continue;
            segments[count++] = {pa[std::size_t(i)] + off * na[std::size_t(i)],
                                 pb[std::size_t(j)] + off * nb[std::size_t(j)]};
        }
    return visibility.open_fraction(std::span<const Visibility::Segment>(segments.data(), count));
}

}  // namespace bounce::hierarchical
