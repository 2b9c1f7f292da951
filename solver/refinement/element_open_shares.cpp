// SPDX-License-Identifier: MIT
#include "solver/refinement/element_open_shares.h"

#include <algorithm>

#include "mesh/scene/errors.h"

namespace bounce {
namespace {

/// Points per side of an element's test (open_parts): 4 x 4, and 8 x 8 where they disagree,
/// as a patch's. An element straddling a cover's edge receives over its open share, so the
/// share's error becomes its radiosity's: fewer points make such elements visibly uneven
/// (ElementOpenShares.AFurnaceWithACabinetIsFlatAndKeepsItsLight).
constexpr int kPointsPerSide = 4;

}  // namespace

ElementOpenShares::ElementOpenShares(const std::vector<Patch>& patches, const Visibility& visibility,
                                     std::span<const CoveredRegion> covered, const std::atomic<bool>* cancel)
    : m_patches(patches), m_visibility(visibility), m_covered(covered), m_cancel(cancel) {}

const ElementOpenness& ElementOpenShares::update(const ElementTree& tree) {
    const std::size_t n = tree.size();
    OpenPart untraced;
    untraced.area_share = -1.0;
    m_traced.resize(n, untraced);
    // Every leaf not traced before: a patch's test (4 x 4 points of 16 rays) can miss a
    // lamp's back or a box's foot on a large patch, which its elements then see.
    std::vector<std::uint32_t> todo, patch_of;
    std::vector<Patch> elements;
    for (std::size_t i = 0; i < n; ++i) {
        const auto& node = tree.node(i);
        if (!node.leaf() || m_traced[i].area_share >= 0) continue;
        todo.push_back(std::uint32_t(i));
        patch_of.push_back(node.root);
        elements.push_back(tree.geometry()[i]);
    }
    if (!todo.empty()) {
        try {
            // Another seed per call: a later round's elements are not traced like the first's.
            const std::vector<OpenPart> open = element_open_parts(elements, patch_of, m_patches, m_visibility,
                                                                  kPointsPerSide, 16, 1 + n, m_cancel, m_covered);
            for (std::size_t k = 0; k < todo.size(); ++k) m_traced[todo[k]] = open[k];
        } catch (const Interrupted&) {
            for (const std::uint32_t i : todo) m_traced[i] = OpenPart{};  // the solve stops before its first sweep
        }
    }
    ElementOpenness& o = m_open;
    o.share.assign(n, 1.0);
    o.back_share.assign(n, 0.0);
    // Children follow their parent in the node order (ElementTree::split appends them).
    for (std::size_t i = n; i-- > 0;) {
        const auto& node = tree.node(i);
        if (node.leaf()) {
            o.share[i] = m_traced[i].area_share;
            o.back_share[i] = m_traced[i].back_share;
            continue;
        }
        double open = 0.0;
        bool whole = true;
        for (int c = 0; c < 4; ++c) {
            const auto child = std::size_t(node.first_child + c);
            open += tree.geometry()[child].area * o.share[child];
            whole = whole && o.share[child] == 1.0;
        }
        o.share[i] = whole ? 1.0 : std::clamp(open / tree.geometry()[i].area, 0.0, 1.0);
    }
    o.all_open = std::all_of(o.share.begin(), o.share.end(), [](double s) { return s == 1.0; });
    return o;
}

}  // namespace bounce
