// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/scene/rgb.h"
#include "mesh/scene/transform.h"

namespace bounce {

/// How a surface scatters light. Diffuse surfaces are the radiosity's patches; mirror and glass
/// are ideal specular (delta) surfaces: the radiosity does not mesh them, they occlude it, and
/// the path tracer and the eye pass follow light through them.
enum class MaterialKind { diffuse, mirror, glass };
std::string to_string(MaterialKind kind);

/// A material. diffuse: reflectance rho in [0,1] per channel and emitted radiosity E >= 0
/// (power per unit area leaving the surface by emission, radiance E/pi). mirror: ideal
/// reflection with `specular` the reflectance per channel in [0,1], the same at every angle.
/// glass: a dielectric of index `ior` >= 1 against air, reflecting and refracting by the exact
/// Fresnel equations for unpolarised light; `specular` is its transmittance colour in [0,1], the
/// share of each channel that survives one passage into the glass. Mirror and glass do not emit.
struct Material {
    std::string name;
    Rgb reflectance = Rgb::gray(0.5);  // rho, dimensionless (diffuse only; 0 for mirror and glass)
    Rgb emission;                      // E, W/m^2 per channel (scene units)
    MaterialKind kind = MaterialKind::diffuse;
    Rgb specular = Rgb::gray(1.0);  // mirror: reflectance; glass: transmittance colour per passage
    double ior = 1.5;               // glass: index of refraction n (relative to the surrounding air)

    bool is_specular() const { return kind != MaterialKind::diffuse; }
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
    int material = 0;    // index into Scene::materials
    std::string object;  // object or group name of the input
    SourceLocation where;
};

/// A convex polygon in the plane of surface `surface` that no light can reach: another object
/// rests on it or is mounted flush in front of it (mesh/geometry/contact_cuts.h). The mesher leaves it out.
struct CoveredRegion {
    int surface = -1;
    std::vector<glm::dvec3> polygon;  // convex, counter-clockwise seen from the surface's front
    /// How far in front of the surface the cover hangs (0: it rests on it or crosses it). Light
    /// enters the gap only a few gap widths past the outline (see gather_clearance).
    double gap = 0.0;
};

/// An analytic sphere of mirror or glass: the unit sphere (centre 0, radius 1) placed by an
/// affine transform T, so a scaled and rotated sphere is an ellipsoid. Rays are intersected with
/// it exactly (mesh/scene/sphere.h); its front is the outside.
struct Sphere {
    Transform transform;  // unit sphere -> scene; invertible
    int material = 0;     // index into Scene::materials, a mirror or glass
    std::string object;   // object name of the input
    SourceLocation where;
};

/// A scene as read from its source: polygons with materials. Surfaces are one-sided.
/// `surfaces` are the diffuse polygons, which the radiosity meshes into patches; mirror and
/// glass polygons go to `specular_surfaces`, and analytic spheres to `spheres`: both occlude the
/// radiosity (mesh/scene/specular_occluders.h) and are followed by the path tracer and the eye pass.
struct Scene {
    std::string name;
    std::string units;  // length unit of the coordinates, for messages ("mm"); empty: unknown
    std::vector<Material> materials;
    std::vector<Surface> surfaces;
    std::vector<Surface> specular_surfaces;  // polygons of mirror or glass materials
    std::vector<Sphere> spheres;             // analytic spheres of mirror or glass materials
    std::vector<std::string> warnings;       // problems that were repaired, to show the user
    std::vector<CoveredRegion> covered;      // found by load_scene; empty: mesh every surface whole

    /// True when some object is a mirror or glass.
    bool has_specular() const { return !specular_surfaces.empty() || !spheres.empty(); }

    /// Checks reflectance in [0,1], emission >= 0, mirror reflectance and glass transmittance in
    /// [0,1], indices of refraction >= 1, invertible sphere transforms, finite coordinates, and
    /// that diffuse surfaces have diffuse materials and specular objects specular ones; throws
    /// InputError naming the material, surface or object. Does not look at the geometry of
    /// faces (see check_geometry).
    void validate() const;
};

}  // namespace bounce
