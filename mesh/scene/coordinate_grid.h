// SPDX-License-Identifier: MIT
// One scene, one set of coordinates: the same geometry written two ways (an OBJ of printed
// decimals, a JSON of shapes placed by 4x4 transforms) reaches the mesher with vertices that
// differ in their last bits, and every decision the mesher and the solvers take on a
// comparison (a contact found or not, a cut point, a link refined or not) can then go the
// other way. Rounding every vertex to a fixed number of decimals makes such inputs the same
// bits, and leaves coordinates written with fewer decimals exactly as they were.
#pragma once

#include <optional>

#include "mesh/scene/scene.h"

namespace bounce {

/// The decimals kept for `scene`: k such that 10^-k lies between 1e-11 and 1e-10 of sqrt(2)
/// times the largest absolute coordinate of its surfaces (far below any tolerance of the
/// mesher, far above the rounding of a transform or of a printed 15-digit decimal). The sqrt(2)
/// puts the extents where k changes at irrational values, which no two writings of one scene
/// straddle (at a power of ten, 10 and 10 - 1 ulp would keep different decimals). None for a
/// scene without vertices or at the origin only.
std::optional<int> coordinate_decimals(const Scene& scene);

/// Rounds every coordinate of the diffuse and specular surfaces to coordinate_decimals(scene)
/// decimals: x -> nearbyint(x 10^k) / 10^k, the double nearest to the rounded decimal. A
/// coordinate written with at most k decimals (548.8 mm, 0.725 m) keeps its bits. Spheres keep
/// their transforms (they are analytic).
void snap_coordinates(Scene& scene);

}  // namespace bounce
