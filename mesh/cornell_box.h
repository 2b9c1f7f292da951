// SPDX-License-Identifier: MIT
#pragma once

#include "mesh/scene.h"

namespace bounce {

/// The built-in Cornell box from the published measurements (millimetres, y up, open at
/// z = 0), exactly as shared/VALIDATION.md gives it: white, red and green walls, two white
/// blocks and a light of emitted radiosity (17, 12, 4) just below the ceiling.
Scene make_cornell_box();

}  // namespace bounce
