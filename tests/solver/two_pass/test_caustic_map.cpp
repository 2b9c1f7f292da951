// SPDX-License-Identifier: MIT
// The caustic photon map: a glass ball lens focuses parallel light at its paraxial focus, and
// the stored power is the emitted power times the share of photons that meet a mirror first.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "mesh/meshing/patch_mesh.h"
#include "solver/optics/fresnel.h"
#include "solver/two_pass/caustic_map.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

MeshingOptions whole_faces() {
    MeshingOptions o;
    o.subdivide = false;
    return o;
}

}  // namespace

TEST(CausticMap, AGlassBallLensFocusesParallelLightAtItsParaxialFocus) {
    // A ball of radius R and index n brings paraxial rays to a focus n R / (2 (n - 1)) from its
    // centre (the thick-lens formula with both surfaces of radius R). A beam of radius R / 10
    // along +x lands on a receiver there within the map's radius; just behind the ball the
    // still converging beam is some radii wide.
    const double R = 1.0, radius = 0.01;
    for (const double n : {1.5, 1.4}) {
        const double focus = n * R / (2 * (n - 1));
        for (const double receiver : {focus, R + 0.02}) {
            Scene s;
            s.materials = {{"white", Rgb::gray(0.8), Rgb()},
                           {"glass", Rgb(), Rgb(), MaterialKind::glass, Rgb::gray(1), n}};
            s.surfaces.push_back({{{receiver, -2, -2}, {receiver, -2, 2}, {receiver, 2, 2}, {receiver, 2, -2}},
                                  0,
                                  "receiver",
                                  {"test", 0}});
            s.spheres.push_back({Transform::scale(V(R)), 1, "ball", {"test", 0}});
            const PatchMesh mesh(s, whole_faces());
            ASSERT_EQ(mesh.size(), 1u);
            const PatchSceneTracer tracer(s, mesh);
            std::mt19937_64 engine(7);
            const std::function<double()> uniform = [&] { return double(engine() >> 11) * 0x1.0p-53; };
            const int N = 20000;
            std::vector<CausticPhoton> photons;
            for (int k = 0; k < N; ++k) {
                const double rr = 0.1 * R * std::sqrt(uniform()), phi = 2 * std::numbers::pi * uniform();
                const V o(-5, rr * std::cos(phi), rr * std::sin(phi));
                if (auto p = trace_caustic_photon(tracer, o, V(1, 0, 0), Rgb::gray(1.0 / N), uniform, 64))
                    photons.push_back(*p);
            }
            double near_focus = 0, total = 0;
            for (const auto& p : photons) {
                total += p.power.g;
                if (glm::length(p.position - V(receiver, 0, 0)) < radius) near_focus += p.power.g;
            }
            const double R0 = std::pow((n - 1) / (n + 1), 2);
            EXPECT_GT(total, (1 - R0) * (1 - R0) - 0.01) << "n " << n;  // twice through, once reflected away
            const CausticMap map(photons, radius, mesh.size());
            const Rgb at = map.radiance({receiver, 0, 0}, {-1, 0, 0}, Rgb::gray(0.8));
            const Rgb off = map.radiance({receiver, 0, 4 * radius}, {-1, 0, 0}, Rgb::gray(0.8));
            if (receiver == focus) {
                EXPECT_GT(near_focus, 0.95 * total) << "n " << n;
                EXPECT_GT(at.g, 50 * off.g) << "n " << n;
                // The estimate there: rho / pi * (power within r, cone-weighted) / ((1/3) pi r^2).
                EXPECT_GT(at.g, 0.8 / std::numbers::pi * 0.5 * near_focus / (std::numbers::pi * radius * radius / 3));
            } else {
                EXPECT_LT(near_focus, 0.5 * total) << "n " << n;
            }
        }
    }
}

TEST(CausticMap, StoredPowerIsTheEmittedPowerTimesTheShareMeetingAMirrorFirst) {
    // A small lamp (facing +z) 2.9 below the centre of a perfect mirror ball of radius 1, in a
    // closed room: a Lambertian point source on the axis of a sphere sends the share
    // F = (R / d)^2 of its power to it. Every photon the ball reflects ends on a wall's front.
    Scene s;
    s.materials = {{"wall", Rgb::gray(0.5), Rgb()},
                   {"lamp", Rgb(), Rgb(3, 2, 1)},
                   {"mirror", Rgb(), Rgb(), MaterialKind::mirror, Rgb::gray(1.0)}};
    const double h = 3;
    const std::vector<std::vector<V>> walls = {
        {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h}}, {{-h, -h, h}, {-h, h, h}, {h, h, h}, {h, -h, h}},
        {{-h, -h, -h}, {-h, h, -h}, {-h, h, h}, {-h, -h, h}}, {{h, -h, -h}, {h, -h, h}, {h, h, h}, {h, h, -h}},
        {{-h, -h, -h}, {-h, -h, h}, {h, -h, h}, {h, -h, -h}}, {{-h, h, -h}, {h, h, -h}, {h, h, h}, {-h, h, h}}};
    for (const auto& w : walls) s.surfaces.push_back({w, 0, "wall", {"test", 0}});
    const double a = 0.01, z = -2.9;
    s.surfaces.push_back({{{-a, -a, z}, {a, -a, z}, {a, a, z}, {-a, a, z}}, 1, "lamp", {"test", 0}});
    s.spheres.push_back({Transform(), 2, "ball", {"test", 0}});
    const PatchMesh mesh(s, whole_faces());
    const PatchSceneTracer tracer(s, mesh);
    CausticOptions o;
    o.photons = 200000;
    const CausticMap map(mesh, tracer, o);
    const double F = 1.0 / (2.9 * 2.9);
    const double se = std::sqrt(F * (1 - F) / double(o.photons));
    EXPECT_NEAR(map.specular_first_share(), F, 4 * se);
    Rgb stored;
    for (const auto& p : map.power_per_patch()) stored += p;
    const Rgb emitted = map.emitted_power();
    EXPECT_NEAR(emitted.r, 3 * (2 * a) * (2 * a), 1e-15);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(stored[c], emitted[c] * map.specular_first_share(), 1e-3 * emitted[c] * F) << c;
    // The photons land on the walls: on the ceiling above the ball above all.
    EXPECT_GT(map.photons().size(), std::size_t(0.99 * F * double(o.photons)));
}
