// SPDX-License-Identifier: MIT
#pragma once

#include <embree3/rtcore.h>
#include <glm/vec3.hpp>

namespace bounce {

/// An Embree closest-hit query from a double-precision ray: the origin taken relative to the
/// BVH's `centre` (the scenes are built recentred, so single precision errs by a share of the
/// scene's size, not of its distance from the origin), [tnear, tfar] along `dir`, no hit yet.
inline RTCRayHit embree_ray(const glm::dvec3& origin, const glm::dvec3& dir, double tnear, double tfar,
                            const glm::dvec3& centre) {
    RTCRayHit rh{};
    const glm::dvec3 o = origin - centre;
    rh.ray.org_x = float(o.x);
    rh.ray.org_y = float(o.y);
    rh.ray.org_z = float(o.z);
    rh.ray.dir_x = float(dir.x);
    rh.ray.dir_y = float(dir.y);
    rh.ray.dir_z = float(dir.z);
    rh.ray.tnear = float(tnear);
    rh.ray.tfar = float(tfar);
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

}  // namespace bounce
