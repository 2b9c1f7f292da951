// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/rgb.h"

namespace bounce {

/// A diffuse material: reflectance rho in [0,1] per channel and emitted radiosity E >= 0
/// (power per unit area leaving the surface by emission, radiance E/pi).
struct Material {
    std::string name;
    Rgb reflectance = Rgb::gray(0.5);  // rho, dimensionless
    Rgb emission;                      // E, W/m^2 per channel (scene units)
};

/// Where a surface came from, for messages: "file.obj:42" or "cornell box: floor".
struct SourceLocation {
    std::string file;
    int line = 0;  // 1-based; 0 when there is no line (built-in or generated geometry)
    std::string to_string() const;
};

/// "file.obj:42 (object)": where a surface came from, its object named once (not when the
/// location already says it, as "cornell box: floor" does).
std::string describe(const SourceLocation& where, const std::string& object);

/// A length for messages: "1.07 mm", or "1.07 scene units" when the scene has no unit.
std::string length_text(double value, const std::string& units);

/// One planar polygon of the input, before subdivision into patches. Vertices are in
/// counter-clockwise order seen from the front; the front is the side that emits and reflects.
struct Surface {
    std::vector<glm::dvec3> vertices;
    int material = 0;     // index into Scene::materials
    std::string object;   // object or group name of the input
    SourceLocation where;
};

/// A convex polygon in the plane of surface `surface` that no light can reach: another object
/// rests on it or is mounted flush in front of it (mesh/contact_cuts.h). The mesher leaves it out.
struct CoveredRegion {
    int surface = -1;
    std::vector<glm::dvec3> polygon;  // convex, counter-clockwise seen from the surface's front
    /// How far in front of the surface the cover hangs (0: it rests on it or crosses it). Light
    /// enters the gap only a few gap widths past the outline (see gather_clearance).
    double gap = 0.0;
};

/// A scene as read from its source: polygons with materials. Surfaces are one-sided.
struct Scene {
    std::string name;
    std::string units;  // length unit of the coordinates, for messages ("mm"); empty: unknown
    std::vector<Material> materials;
    std::vector<Surface> surfaces;
    std::vector<std::string> warnings;  // problems that were repaired, to show the user
    std::vector<CoveredRegion> covered;  // found by load_scene; empty: mesh every surface whole

    /// Checks reflectance in [0,1], emission >= 0 and finite coordinates; throws InputError
    /// naming the material or surface. Does not look at the geometry of faces (see
    /// check_geometry).
    void validate() const;
};

}  // namespace bounce
