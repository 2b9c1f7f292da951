// SPDX-License-Identifier: MIT
// The path tracer through mirrors and glass against closed forms: a planar mirror, a glass slab
// at normal incidence, total internal reflection in a prism, and furnaces with a mirror or a
// glass sphere inside.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "mesh/readers/validation_scenes.h"
#include "solver/optics/fresnel.h"
#include "solver/reference/path_tracer.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

constexpr double kPi = std::numbers::pi;

Material mirror(const Rgb& reflectance) { return {"mirror", Rgb(), Rgb(), MaterialKind::mirror, reflectance}; }
Material glass(double ior) { return {"glass", Rgb(), Rgb(), MaterialKind::glass, Rgb::gray(1.0), ior}; }

/// A box [lo, hi] of material m, faces outwards, as specular surfaces.
void add_box(Scene& s, const V& lo, const V& hi, int m) {
    const double x0 = lo.x, y0 = lo.y, z0 = lo.z, x1 = hi.x, y1 = hi.y, z1 = hi.z;
    const std::vector<std::vector<V>> faces = {
        {{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}},  // +z
        {{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}},  // -z
        {{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}},  // +x
        {{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}},  // -x
        {{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}},  // +y
        {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}},  // -y
    };
    for (const auto& f : faces) s.specular_surfaces.push_back({f, m, "glass box", {"test", 0}});
}

/// |a - b| within k combined standard errors, per channel.
void expect_agree(const Rgb& a, const Rgb& se_a, const Rgb& b, const Rgb& se_b, double k, const std::string& what) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], k * std::hypot(se_a[c], se_b[c])) << what << " channel " << c;
}

}  // namespace

TEST(SpecularPathTracer, APatchSeenInAPlanarMirrorHasItsRadianceTimesTheReflectance) {
    // The plate of lamp_over_plane (z = 0, rho 0.5) under its lamp (z = 1, E = (3, 2, 1)), and
    // a mirror in the plane x = 4 facing -x, beyond the plate's edge (x = 3).
    Scene s = lamp_over_plane();
    const Rgb rho_mirror(0.9, 0.6, 0.3);
    s.materials.push_back(mirror(rho_mirror));
    s.specular_surfaces.push_back(
        {{{4, -2, 0.05}, {4, -2, 0.9}, {4, 3, 0.9}, {4, 3, 0.05}}, int(s.materials.size()) - 1, "mirror", {"test", 0}});
    const PathTracer pt(s);
    const V eye(0.5, 0.5, 0.5), target(0.5, 0.5, 0.0);
    // Directly, and by way of the mirror: towards the target's image behind the mirror.
    const V image(8.0 - target.x, target.y, target.z);
    const auto direct = pt.radiance(eye, target - eye, 64 * 800, 1, 0);
    const auto seen = pt.radiance(eye, image - eye, 64 * 800, 2, 0);
    EXPECT_LT(direct.standard_error.max(), 0.01 * direct.radiance.max());
    expect_agree(seen.radiance, seen.standard_error, rho_mirror * direct.radiance, rho_mirror * direct.standard_error,
                 3.0, "plate in the mirror");
    // The lamp in the mirror: exactly rho E / pi, no noise (the lamp reflects nothing).
    const V lamp_image(8.0 - 0.5, 0.5, 1.0);
    const auto lamp = pt.radiance(eye, lamp_image - eye, 128, 3, 0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(lamp.radiance[c], rho_mirror[c] * Rgb(3, 2, 1)[c] / kPi, 1e-12);
    // The mirror's back is black, like every face's.
    const auto back = pt.radiance(V(5, 0.5, 0.5), V(-1, 0, 0), 128, 4, 0);
    EXPECT_EQ(back.radiance, Rgb());
}

TEST(SpecularPathTracer, AGlassSlabAtNormalIncidenceTransmitsTheFresnelSeries) {
    // A slab z in [0.4, 0.6] of index n over a large emitter (z = 0, E = 1, facing up); looking
    // straight down through it the light passes once and after any even number of inner
    // reflections: T = (1 - R)^2 (1 + R^2 + R^4 + ...) = (1 - R)^2 / (1 - R^2), R = ((n - 1) / (n + 1))^2.
    for (const double n : {1.5, 2.4}) {
        Scene s;
        s.materials = {{"lamp", Rgb(), Rgb::gray(1.0)}, glass(n)};
        s.surfaces.push_back({{{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}}, 0, "lamp", {"test", 0}});
        add_box(s, {-5, -5, 0.4}, {5, 5, 0.6}, 1);
        const PathTracer pt(s);
        const double R = std::pow((n - 1) / (n + 1), 2), T = (1 - R) * (1 - R) / (1 - R * R);
        EXPECT_NEAR(R, fresnel_dielectric(1.0, 1.0, n), 1e-15);
        const auto L = pt.radiance({0.1, 0.2, 2.0}, {0, 0, -1}, 64 * 1000, 5, 0);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(L.radiance[c], T / kPi, 4 * L.standard_error[c]) << "n " << n;
            EXPECT_LT(L.standard_error[c], 0.005 * T / kPi);
        }
    }
}

TEST(SpecularPathTracer, TotalInternalReflectionPastTheCriticalAngle) {
    // A right-angled glass prism: light enters its top face at normal incidence, meets the
    // hypotenuse at 45 degrees and leaves by the right face at normal incidence towards an
    // emitter (x = 3, E = 1, z in [-2, 2]). For n = 1.5 the critical angle is 41.8 degrees: the hypotenuse
    // reflects all, and the prism passes the slab's (1 - R0)^2 / (1 - R0^2). For n = 1.3 it is
    // 50.3 degrees: the hypotenuse reflects only R45, and T = (1 - R0)^2 R45 / (1 - R0^2 R45^2).
    for (const double n : {1.5, 1.3}) {
        Scene s;
        s.materials = {{"lamp", Rgb(), Rgb::gray(1.0)}, glass(n)};
        // Only where the light from the right face goes: what the hypotenuse lets through
        // leaves downwards and passes below it.
        s.surfaces.push_back({{{3, -10, -2}, {3, -10, 2}, {3, 10, 2}, {3, 10, -2}}, 0, "lamp", {"test", 0}});
        const std::vector<std::vector<V>> prism = {
            {{-1, -5, 1}, {1, -5, 1}, {1, 5, 1}, {-1, 5, 1}},    // top, +z
            {{1, -5, 1}, {1, -5, -1}, {1, 5, -1}, {1, 5, 1}},    // right, +x
            {{-1, -5, 1}, {-1, 5, 1}, {1, 5, -1}, {1, -5, -1}},  // hypotenuse, (-1, 0, -1)
            {{-1, -5, 1}, {1, -5, -1}, {1, -5, 1}},              // cap, -y
            {{-1, 5, 1}, {1, 5, 1}, {1, 5, -1}}};                // cap, +y
        for (const auto& f : prism) s.specular_surfaces.push_back({f, 1, "prism", {"test", 0}});
        const PathTracer pt(s);
        const double R0 = std::pow((n - 1) / (n + 1), 2), R45 = fresnel_dielectric(std::cos(kPi / 4), n, 1.0);
        const double critical = std::asin(1 / n);
        const double T =
            n == 1.5 ? (1 - R0) * (1 - R0) / (1 - R0 * R0) : (1 - R0) * (1 - R0) * R45 / (1 - R0 * R0 * R45 * R45);
        if (n == 1.5) {
            EXPECT_LT(critical, kPi / 4);
            EXPECT_EQ(R45, 1.0);
        } else {
            EXPECT_GT(critical, kPi / 4);
            EXPECT_LT(R45, 0.2);
        }
        const auto L = pt.radiance({0.5, 0.0, 3.0}, {0, 0, -1}, 64 * 1000, 6, 0);
        EXPECT_NEAR(L.radiance.g, T / kPi, 4 * L.standard_error.g) << "n " << n;
        EXPECT_LT(L.standard_error.g, 0.05 * T / kPi);
    }
}

TEST(SpecularPathTracer, FurnaceWithAPerfectMirrorOrClearGlassSphereInsideStillReturnsEOverOneMinusRho) {
    // Walls emitting E with reflectance rho: B = E / (1 - rho) everywhere on them, whatever
    // lossless object stands inside, since it neither absorbs nor emits. The sphere hides part
    // of the walls from the next-event estimate; that light now arrives through it.
    const double rho = 0.5;
    const Rgb E(1.0, 2.0, 0.5);
    for (const Material& m : {mirror(Rgb::gray(1.0)), glass(1.5)}) {
        Scene box = closed_box({1.0, 1.5, 2.0}, {"furnace", Rgb::gray(rho), E});
        box.materials.push_back(m);
        box.spheres.push_back(
            {Transform::translate({0.5, 0.75, 1.0}) * Transform::scale({0.3, 0.45, 0.35}), 1, "ball", {"test", 0}});
        const PathTracer pt(box);
        ReferenceOptions o;
        o.target_error = 0.005;
        o.seed = 11;
        const std::vector<SurfacePoint> points = {{{0.5, 0.75, 0}, {0, 0, 1}, 0},
                                                  {{0.0, 0.7, 1.0}, {1, 0, 0}, 2},
                                                  {{0.9, 1.5, 0.01}, {0, -1, 0}, 5},
                                                  {{0.5, 0.75, 2.0}, {0, 0, -1}, 1}};
        const auto est = pt.estimate_all(points, o);
        for (std::size_t k = 0; k < points.size(); ++k)
            for (int c = 0; c < 3; ++c) {
                const double exact = E[c] / (1 - rho);
                EXPECT_NEAR(est[k].radiosity[c], exact, 3 * est[k].standard_error[c])
                    << to_string(m.kind) << " point " << k << " channel " << c;
                EXPECT_LE(est[k].standard_error[c], 0.01 * exact);
            }
    }
}

TEST(SpecularPathTracer, ErrorBarsThroughGlassMatchTheSpreadOverSeeds) {
    // The lamp seen through the glass slab and, beside it, a plate lit through it: over 20
    // seeds the spread of the estimates matches the standard error they report.
    Scene s;
    s.materials = {{"lamp", Rgb(), Rgb::gray(1.0)}, glass(1.5), {"plate", Rgb::gray(0.6), Rgb()}};
    s.surfaces.push_back({{{-1, -1, 3}, {-1, 1, 3}, {1, 1, 3}, {1, -1, 3}}, 0, "lamp", {"test", 0}});  // faces down
    s.surfaces.push_back({{{-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0}}, 2, "plate", {"test", 0}});
    add_box(s, {-2, -2, 1.0}, {2, 2, 1.3}, 1);
    const PathTracer pt(s);
    for (const V& target : {V(0, 0, 3), V(0.3, 0.2, 0)}) {
        const V eye = target.z > 0 ? V(0.1, 0.1, 0.5) : V(0.3, 0.2, 0.8);
        std::vector<double> values, errors;
        for (std::uint64_t seed = 1; seed <= 20; ++seed) {
            const auto L = pt.radiance(eye, target - eye, 64 * 40, seed, 0);
            values.push_back(L.radiance.g);
            errors.push_back(L.standard_error.g);
        }
        double mean = 0, se = 0;
        for (std::size_t k = 0; k < values.size(); ++k) mean += values[k] / 20, se += errors[k] / 20;
        double var = 0;
        for (const double x : values) var += (x - mean) * (x - mean) / 19;
        const double spread = std::sqrt(var);
        EXPECT_GT(se, 0.0);
        EXPECT_LT(spread, 1.5 * se) << "target z " << target.z;
        EXPECT_GT(spread, se / 1.5) << "target z " << target.z;
    }
}
