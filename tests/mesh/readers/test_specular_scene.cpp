// SPDX-License-Identifier: MIT
// Scenes with mirror and glass: analytic spheres under transforms, the JSON material kinds, the
// MTL illumination models, and the refusals of bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "mesh/readers/json_scene.h"
#include "mesh/readers/obj_reader.h"
#include "mesh/readers/scene_loader.h"
#include "mesh/scene/input_error.h"
#include "mesh/scene/polygon.h"
#include "mesh/scene/specular_occluders.h"
#include "mesh/scene/sphere.h"
#include "test_util.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

/// The first root t > 0 of (o + t d - c)^T A (o + t d - c) = 1, the ellipsoid written as a
/// quadric in the scene's frame, independent of the sphere's own-frame intersection.
double quadric_hit(const glm::dmat3& A, const V& c, const V& o, const V& d) {
    const V w = o - c;
    const double a = glm::dot(d, A * d), b = glm::dot(d, A * w), cc = glm::dot(w, A * w) - 1.0;
    const double disc = b * b - a * cc;
    EXPECT_GT(disc, 0.0);
    const double s = std::sqrt(disc);
    const double t0 = (-b - s) / a, t1 = (-b + s) / a;
    return t0 > 0 ? t0 : t1;
}

}  // namespace

TEST(Sphere, ScaledAndRotatedSphereIsHitWhereTheEllipsoidIsWithItsNormal) {
    // T = translate * rotate * scale(2, 1, 1): an ellipsoid of semi-axes 2, 1, 1 turned 37
    // degrees about (1, 2, 3). As a quadric: (x - c)^T A (x - c) = 1, A = R S^-2 R^T.
    const V centre(0.3, -1.2, 4.0);
    const Transform R = Transform::rotate(37.0, {1, 2, 3});
    const Transform T = Transform::translate(centre) * R * Transform::scale({2, 1, 1});
    const glm::dmat3 r(R.matrix());
    const glm::dmat3 s_inv2(glm::dvec3(0.25, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1));
    const glm::dmat3 A = r * s_inv2 * glm::transpose(r);
    const Sphere sphere{T, 0, "ellipsoid", {"test", 0}};
    int hits = 0;
    double naive_error = 0;
    for (int k = 0; k < 200; ++k) {
        // Rays from a ring of origins 10 away towards points scattered about the centre.
        const double a = 0.1 * k, b = 0.37 * k;
        const V o = centre + 10.0 * V(std::cos(a) * std::cos(b), std::sin(a) * std::cos(b), std::sin(b));
        const V target = centre + 0.9 * V(std::sin(1.3 * k), std::cos(0.7 * k), std::sin(0.45 * k));
        const V d = glm::normalize(target - o) * (0.5 + 0.01 * k);  // not unit: t follows d's length
        const auto hit = intersect_sphere(sphere, o, d, 0.0, 1e30);
        const V w = target - centre;
        if (glm::dot(w, A * w) >= 1.0) continue;  // the target is outside: a hit is not assured
        ASSERT_TRUE(hit) << k;
        ++hits;
        const double t = quadric_hit(A, centre, o, d);
        EXPECT_NEAR(hit->t, t, 1e-9 * t);
        const V p = o + t * d;
        EXPECT_LT(glm::length(hit->position - p), 1e-9);
        // The ellipsoid's normal is the gradient of the quadric, A (x - c), normalised.
        const V n = glm::normalize(A * (p - centre));
        EXPECT_LT(glm::length(hit->normal - n), 1e-9) << k;
        // The unit sphere's normal taken by T itself (radial from the centre) is not it.
        naive_error = std::max(naive_error, glm::length(glm::normalize(T.vector(T.inverse_point(p))) - n));
    }
    EXPECT_GT(hits, 100);
    EXPECT_GT(naive_error, 0.1);
    // From inside, the ray leaves through the far side; a ray that misses returns nothing.
    const auto out = intersect_sphere(sphere, centre, V(0, 0, 1), 0.0, 1e30);
    ASSERT_TRUE(out);
    EXPECT_NEAR(glm::dot(out->position - centre, A * (out->position - centre)), 1.0, 1e-12);
    EXPECT_FALSE(intersect_sphere(sphere, centre + V(0, 0, 10), V(0, 0, 1), 0.0, 1e30));
}

TEST(Sphere, TessellationIsInscribedClosedAndFacesOutwards) {
    const Transform T = Transform::translate({1, 2, 3}) * Transform::scale({2, 1, 0.5});
    const auto faces = tessellate_sphere(T, 16, 8);
    EXPECT_EQ(faces.size(), 16u * 8u);
    double volume = 0;
    for (const auto& f : faces) {
        const V n = newell_normal(f);
        EXPECT_GT(glm::dot(n, polygon_centroid(f) - V(1, 2, 3)), 0.0);
        for (const auto& p : f) {
            const V l = T.inverse_point(p);
            EXPECT_NEAR(glm::dot(l, l), 1.0, 1e-12);
        }
        // Divergence theorem: the polyhedron's volume from its faces.
        volume += glm::dot(polygon_centroid(f) - V(1, 2, 3), n) / 6.0;
    }
    const double ellipsoid = 4.0 / 3.0 * 3.14159265358979 * 2 * 1 * 0.5;
    EXPECT_LT(volume, ellipsoid);
    EXPECT_GT(volume, 0.9 * ellipsoid);
}

TEST(SpecularScene, JsonReadsMaterialKindsAndSpheres) {
    test::TempDir dir;
    const auto file = dir.write("s.json", R"({"materials": {
        "white": {"reflectance": 0.7},
        "silver": {"kind": "mirror", "reflectance": [0.9, 0.8, 0.7]},
        "glass": {"kind": "glass", "ior": 1.33, "transmittance": [1, 0.9, 0.8]}},
      "objects": [
        {"type": "quad", "material": "white"},
        {"type": "sphere", "material": "glass", "transform": {"scale": 0.5, "translate": [0, 0, 1]}},
        {"type": "quad", "material": "silver", "transform": {"translate": [0, 0, 3]}},
        {"type": "sphere", "material": "white", "transform": {"translate": [3, 0, 1]}}]})");
    const Scene s = load_scene(file.string());
    ASSERT_EQ(s.spheres.size(), 1u);
    ASSERT_EQ(s.specular_surfaces.size(), 1u);
    EXPECT_EQ(s.surfaces.size(), 1u + 32u * 16u);  // the white quad and the meshed white sphere
    const Material& glass = s.materials[std::size_t(s.spheres[0].material)];
    EXPECT_EQ(glass.kind, MaterialKind::glass);
    EXPECT_DOUBLE_EQ(glass.ior, 1.33);
    EXPECT_EQ(glass.specular, Rgb(1, 0.9, 0.8));
    const Material& silver = s.materials[std::size_t(s.specular_surfaces[0].material)];
    EXPECT_EQ(silver.kind, MaterialKind::mirror);
    EXPECT_EQ(silver.specular, Rgb(0.9, 0.8, 0.7));
    EXPECT_TRUE(s.has_specular());
    // The occluders: the mirror quad's two triangles and the sphere's 48 x 24 faces.
    const auto occ = specular_occluders(s);
    EXPECT_EQ(occ.size(), 2u + 48u * 2u + 48u * 22u * 2u);
    const auto hit = intersect_sphere(s.spheres[0], V(0, 0, 5), V(0, 0, -1), 0.0, 1e30);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->position.z, 1.5, 1e-12);
}

TEST(SpecularScene, BadSpecularInputIsRefusedInOneLineNamingIt) {
    test::TempDir dir;
    struct Case {
        std::string json, expect;
    };
    const std::vector<Case> cases = {
        {R"({"materials": {"g": {"kind": "glass", "ior": 0.9}}, "objects": [{"type": "sphere", "material": "g"}]})",
         "material 'g': index of refraction"},
        {R"({"materials": {"m": {"kind": "mirror", "reflectance": 1.2}}, "objects": []})",
         "material 'm': mirror reflectance out of range"},
        {R"({"materials": {"m": {"kind": "mirror", "reflectance": [-0.1, 0.5, 0.5]}}, "objects": []})",
         "mirror reflectance out of range"},
        {R"({"materials": {"g": {"kind": "glass", "transmittance": [1, -1, 1]}}, "objects": []})",
         "glass transmittance out of range"},
        {R"({"materials": {"m": {"kind": "mirror", "emission": 1}}, "objects": []})", "unknown key 'emission'"},
        {R"({"materials": {"m": {"kind": "chrome"}}, "objects": []})", "unknown kind 'chrome'"},
        {R"({"materials": {"m": {"kind": "mirror"}}, "objects": [{"type": "sphere", "material": "m",
            "transform": {"scale": [1, 0, 1]}}]})",
         "objects[0]: transform is singular"},
        {R"({"materials": {"m": {"kind": "mirror"}}, "objects": [{"type": "sphere", "material": "m",
            "transform": {"matrix": [1, 2, 3, 0,  2, 4, 6, 0,  0, 0, 1, 0,  0, 0, 0, 1]}}]})",
         "objects[0]: transform is singular"},
    };
    for (const auto& c : cases) {
        const auto file = dir.write("bad.json", c.json);
        try {
            (void)load_scene(file.string());
            ADD_FAILURE() << "accepted: " << c.json;
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(c.expect), std::string::npos) << what;
            EXPECT_NE(what.find("bad.json"), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        }
    }
    // A sphere whose transform collapses, built in code, is refused by validate.
    Scene s;
    s.materials.push_back({"m", Rgb(), Rgb(), MaterialKind::mirror});
    s.spheres.push_back({Transform(glm::dmat4(glm::dvec4(1, 0, 0, 0), glm::dvec4(2, 0, 0, 0), glm::dvec4(0, 0, 1, 0),
                                              glm::dvec4(0, 0, 0, 1))),
                         0,
                         "ball",
                         {"code", 0}});
    EXPECT_THROW(s.validate(), InputError);
}

TEST(SpecularScene, MtlIllumModelsMapToMirrorAndGlass) {
    test::TempDir dir;
    dir.write("m.mtl", R"(newmtl wall
Kd 0.5 0.5 0.5
illum 2
newmtl silver
Ks 0.9 0.9 0.9
illum 3
newmtl fresnel_silver
illum 5
Ks 0.8 0.8 0.8
newmtl glass
illum 7
Ni 1.5
Tf 1 0.95 0.9
newmtl glass6
illum 6
newmtl odd
Kd 0.3 0.3 0.3
illum 4
)");
    const auto obj = dir.write("m.obj", R"(mtllib m.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
usemtl wall
f 1 2 3 4
usemtl silver
f 1 2 3 4
usemtl fresnel_silver
f 1 2 3 4
usemtl glass
f 1 2 3 4
usemtl glass6
f 1 2 3 4
usemtl odd
f 1 2 3 4
)");
    const Scene s = read_obj(obj);
    ASSERT_EQ(s.surfaces.size(), 2u);  // wall, odd
    ASSERT_EQ(s.specular_surfaces.size(), 4u);
    auto material = [&](const Surface& f) { return s.materials[std::size_t(f.material)]; };
    EXPECT_EQ(material(s.specular_surfaces[0]).kind, MaterialKind::mirror);
    EXPECT_EQ(material(s.specular_surfaces[0]).specular, Rgb::gray(0.9));
    EXPECT_EQ(material(s.specular_surfaces[1]).kind, MaterialKind::mirror);
    EXPECT_EQ(material(s.specular_surfaces[1]).specular, Rgb::gray(0.8));
    EXPECT_EQ(material(s.specular_surfaces[2]).kind, MaterialKind::glass);
    EXPECT_DOUBLE_EQ(material(s.specular_surfaces[2]).ior, 1.5);
    EXPECT_EQ(material(s.specular_surfaces[2]).specular, Rgb(1, 0.95, 0.9));
    EXPECT_EQ(material(s.specular_surfaces[3]).kind, MaterialKind::glass);  // no Ni: 1.5, warned
    EXPECT_EQ(material(s.surfaces[1]).kind, MaterialKind::diffuse);
    EXPECT_EQ(material(s.surfaces[1]).reflectance, Rgb::gray(0.3));
    int warned = 0;
    for (const auto& w : s.warnings)
        warned += w.find("glass6") != std::string::npos || w.find("illum 4") != std::string::npos;
    EXPECT_EQ(warned, 2);

    // Bad combinations: a mirror without Ks, an index below 1, Ks above 1, a glowing mirror.
    for (const auto& [mtl, expect] : std::vector<std::pair<std::string, std::string>>{
             {"newmtl a\nillum 3\n", "m.mtl:1: material 'a' is a mirror (illum 3) but gives no Ks"},
             {"newmtl a\nillum 7\nNi 0.8\n", "m.mtl:1: material 'a': index of refraction Ni out of range"},
             {"newmtl a\nKs 1.2 1 1\nillum 3\n", "mirror reflectance Ks out of range"},
             {"newmtl a\nKs 1 1 1\nKe 1 1 1\nillum 5\n", "does not emit"},
             {"newmtl a\nillum 2.5\n", "m.mtl:2: illum out of range"}}) {
        dir.write("m.mtl", mtl);
        try {
            (void)read_obj(obj);
            ADD_FAILURE() << "accepted: " << mtl;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
        }
    }
}

TEST(SpecularScene, CornellSpheresIsTheBoxWithAMirrorAndAGlassSphereOnTheFloor) {
    const Scene box = load_scene("cornell");
    const Scene s = load_scene("cornell-spheres");
    EXPECT_EQ(s.name, "cornell-spheres");
    EXPECT_EQ(s.units, "mm");
    // The room without the blocks: the same walls and light, in the same order.
    ASSERT_EQ(s.surfaces.size(), 7u);
    for (std::size_t k = 0; k < s.surfaces.size(); ++k) EXPECT_EQ(s.surfaces[k].vertices, box.surfaces[k].vertices);
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_EQ(s.materials[std::size_t(s.spheres[0].material)].kind, MaterialKind::mirror);
    EXPECT_EQ(s.materials[std::size_t(s.spheres[1].material)].kind, MaterialKind::glass);
    EXPECT_DOUBLE_EQ(s.materials[std::size_t(s.spheres[1].material)].ior, 1.5);
    for (const auto& sphere : s.spheres) {
        // Resting on the floor: a ray straight down meets it 100 mm above it.
        const V c = sphere.transform.point(V(0.0));
        EXPECT_DOUBLE_EQ(c.y, 100.0);
        const auto hit = intersect_sphere(sphere, c + V(0, 1000, 0), V(0, -1, 0), 0.0, 1e30);
        ASSERT_TRUE(hit);
        EXPECT_NEAR(hit->position.y, 200.0, 1e-9);
        EXPECT_NEAR(hit->normal.y, 1.0, 1e-12);
    }
}
