// SPDX-License-Identifier: MIT
#pragma once

#include <vector>

#include "mesh/meshing/patch.h"
#include "solver/linear/solve_result.h"

namespace bounce {

/// Faces wound the wrong way (clockwise seen from the front) are the most common mistake in
/// a hand-made OBJ: the solve runs, the light leaves through the backs of the walls and the
/// picture is black. After a solve this compares where the emitters' first bounce lands as
/// wound and with every face turned (unoccluded point-to-polygon form factors from a few
/// patches of each emitting surface), and says which faces are the likely culprits.
struct WindingReport {
    double escaped_fraction = 0.0;   // escaped or taken by back sides / emitted power, all channels
    double reach_as_wound = 0.0;     // share of the emitters' power whose first bounce lands on a patch
    double reach_turned = 0.0;       // the same with every face turned round
    std::vector<int> dark_emitters;  // emitting surfaces whose light reaches no patch as wound
    std::vector<int> likely_faces;   // surfaces that would receive the most light if turned, most first (<= 5)
    /// True when a warning is due: an emitter that reaches nothing, or most of the emitted
    /// power escaping while turning the faces would catch clearly more of it.
    bool suspicious() const;
};

WindingReport check_winding(const std::vector<Patch>& patches, const SolveResult& result);

/// The patch turned round: vertices in reverse order, normal negated (what --flip does to
/// the surfaces before meshing, for one patch).
Patch turned(const Patch& p);

}  // namespace bounce
