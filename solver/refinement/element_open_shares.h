// SPDX-License-Identifier: MIT
#pragma once

#include <atomic>
#include <span>
#include <vector>

#include "mesh/meshing/element_tree.h"
#include "mesh/scene/scene.h"
#include "solver/form_factors/open_parts.h"

namespace bounce {

class Visibility;

/// Per node of an element tree, what open_parts.h finds of a patch: the share of its area open
/// to the scene (a patch may lie partly under or inside another object, and an element on it
/// emits and receives over its open part only) and, of the rays from its open part that met no
/// patch's front, the share that met a back side.
struct ElementOpenness {
    std::vector<double> share;       // a parent: its children's area-weighted mean, exactly 1 where they all are
    std::vector<double> back_share;  // leaves'
    bool all_open = true;            // every share is 1
};

/// Finds and keeps the ElementOpenness of a growing tree: every leaf is traced once, when it
/// first appears (open_parts.h's test on the element), and a parent's share is its children's
/// area-weighted mean.
class ElementOpenShares {
public:
    /// `covered`: the regions the contact and solid cuts left out (Scene::covered).
    ElementOpenShares(const std::vector<Patch>& patches, const Visibility& visibility,
                      std::span<const CoveredRegion> covered, const std::atomic<bool>* cancel);

    /// The openness of every node of `tree` (its roots are the patches given above); leaves
    /// not seen before are traced. Cancelled: every new leaf counts as open.
    const ElementOpenness& update(const ElementTree& tree);

private:
    const std::vector<Patch>& m_patches;
    const Visibility& m_visibility;
    std::span<const CoveredRegion> m_covered;
    const std::atomic<bool>* m_cancel;
    std::vector<OpenPart> m_traced;  // per node: a leaf's own, area_share negative where not traced
    ElementOpenness m_open;
};

}  // namespace bounce
