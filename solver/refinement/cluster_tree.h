// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/meshing/patch.h"

namespace bounce {

/// A bounding-volume hierarchy of clusters above the input patches, for hierarchical
/// radiosity with clustering (Smits, Arvo and Greenberg 1994; Sillion 1995): refinement
/// starts from one link, the root cluster with itself, instead of a link for every pair of
/// patches. A binary tree, built by cutting the patches at the median centroid along the
/// longest axis of their centroids' box; a patch is the child of the smallest cluster that
/// holds it. Deterministic: ties in the median sort by patch index.
class ClusterTree {
public:
    /// A node reference: a cluster (index | cluster_bit) or an input patch (its index).
    static constexpr std::uint32_t cluster_bit = 0x80000000u;
    static bool is_cluster(std::uint32_t ref) { return (ref & cluster_bit) != 0; }
    static std::uint32_t index(std::uint32_t ref) { return ref & ~cluster_bit; }

    struct Cluster {
        std::array<std::uint32_t, 2> child{};  // node references
        std::int32_t parent = -1;              // cluster index, -1 for the root
        double area = 0.0;                     // total area of the member patches
        glm::dvec3 centre{0.0};                // area-weighted mean of the members' centroids
        double radius = 0.0;                   // a sphere about centre with this radius holds every member
        glm::dvec3 lo{1e300}, hi{-1e300};      // box of the members' vertices
        /// sum A max(0, +-n_k) over members, axes +x +y +z -x -y -z: bounds the area the
        /// members show in any direction (see projected_area)
        std::array<double, 6> axis_area{};
        glm::dvec3 area_normal{0.0};  // sum A n over members
        glm::dvec3 cone_axis{0.0};    // a cone of directions about this axis holds every member's normal ...
        double cone_cos = -1.0;       // ... with this cosine of its half-angle (-1: any direction)
        int sample_count = 0;         // up to 4 member centroids, spread over the subtree (visibility rays)
        std::array<glm::dvec3, 4> sample{};
        std::array<glm::dvec3, 4> sample_normal{};
    };

    explicit ClusterTree(const std::vector<Patch>& patches);

    /// The root: cluster 0, or patch 0 when there is one patch.
    std::uint32_t root() const { return m_clusters.empty() ? 0u : cluster_bit; }
    const std::vector<Cluster>& clusters() const { return m_clusters; }
    const Cluster& cluster(std::uint32_t ref) const { return m_clusters[index(ref)]; }
    /// The cluster holding input patch p (-1 when there is one patch). Parents come before
    /// their children in clusters(), so a forward sweep pushes down and a backward one pulls up.
    std::int32_t patch_parent(std::uint32_t p) const { return m_patch_parent[p]; }

    /// Lower and upper bounds on sum A_j max(0, n_j . d) over the members (unit d): the area
    /// they show towards d. Exact when every member faces d or away from it and the members'
    /// normals lie along the axes (walls of an axis-aligned room).
    struct Range {
        double lo = 0.0, hi = 0.0;
    };
    static Range projected_area(const Cluster& c, const glm::dvec3& d);
    /// An estimate of the area node `ref` shows towards unit d: exact for a patch, and for a
    /// cluster whose normal cone lies wholly on one side of d's normal plane; else the sum
    /// over its children, down to `depth` levels, then the midpoint of projected_area.
    double shown_area(std::uint32_t ref, const glm::dvec3& d, const std::vector<Patch>& patches, int depth = 3) const;

private:
    std::uint32_t build(const std::vector<Patch>& patches, std::vector<std::uint32_t>& ids, std::size_t begin,
                        std::size_t end, std::int32_t parent);

    std::vector<Cluster> m_clusters;
    std::vector<std::int32_t> m_patch_parent;
};

}  // namespace bounce
