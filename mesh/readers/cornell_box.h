// SPDX-License-Identifier: MIT
#pragma once

#include "mesh/scene/scene.h"

namespace bounce {

/// The built-in Cornell box from the published measurements (millimetres, y up, open at
/// z = 0), exactly as shared/VALIDATION.md gives it: white, red and green walls, two white
/// blocks and a light of emitted radiosity (17, 12, 4) just below the ceiling.
Scene make_cornell_box();

/// The seed's picture (Jensen's Cornell box, as on his photon-mapping pages): the same box,
/// walls and light, with a mirror sphere at the back on the left (the red side, seen from the
/// open front) and a glass sphere at the front on the right in place of the blocks, both of
/// radius 100 mm resting on the floor.
struct CornellSpheresLayout {
    double radius = 100.0;                          // mm
    glm::dvec3 mirror_centre{370.0, 100.0, 370.0};  // mm, left (x towards the red wall) and back
    glm::dvec3 glass_centre{185.0, 100.0, 170.0};   // mm, right and front
    double mirror_reflectance = 0.99;               // per channel, the same at every angle
    double glass_ior = 1.5;                         // crown glass; transmittance colour 1
    glm::dvec3 lamp_centre{278.0, 548.7, 279.5};    // mm, the centre of make_cornell_box's light
};
inline const CornellSpheresLayout kCornellSpheres{};
Scene make_cornell_spheres_box();

}  // namespace bounce
