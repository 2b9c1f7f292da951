// SPDX-License-Identifier: MIT
// The eye pass: a diffuse point shows B / pi, a mirror passes it on times its reflectance, a
// glass slab at normal incidence the Fresnel series, and a stopped picture is whole.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>

#include "mesh/meshing/patch_mesh.h"
#include "solver/two_pass/eye_pass.h"

using namespace bounce;
using V = glm::dvec3;

namespace {

constexpr double kPi = std::numbers::pi;

/// A plate z = 0 facing up, radiosity 2 + x at its corners, a mirror in x = 4 facing -x, and a
/// glass slab above the plate z in [0.4, 0.6] over x in [-2, -1].
struct MirrorScene {
    Scene scene;
    std::unique_ptr<PatchMesh> mesh;
    std::vector<Rgb> vertex, patch;
    MirrorScene(const Rgb& mirror_reflectance, double ior) {
        scene.materials = {{"white", Rgb::gray(0.5), Rgb()},
                           {"mirror", Rgb(), Rgb(), MaterialKind::mirror, mirror_reflectance},
                           {"glass", Rgb(), Rgb(), MaterialKind::glass, Rgb::gray(1.0), ior}};
        scene.surfaces.push_back({{{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}}, 0, "plate", {"test", 0}});
        scene.specular_surfaces.push_back(
            {{{4, -3, 0.05}, {4, -3, 2}, {4, 3, 2}, {4, 3, 0.05}}, 1, "mirror", {"test", 0}});
        const double x0 = -2, x1 = -1, y0 = -1, y1 = 1, z0 = 0.4, z1 = 0.6;
        for (const auto& f : std::vector<std::vector<V>>{{{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}},
                                                         {{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}},
                                                         {{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}},
                                                         {{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}},
                                                         {{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}},
                                                         {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}}})
            scene.specular_surfaces.push_back({f, 2, "slab", {"test", 0}});
        MeshingOptions o;
        o.subdivide = false;
        mesh = std::make_unique<PatchMesh>(scene, o);
        for (std::size_t v = 0; v < mesh->mesh().n_vertices(); ++v)
            vertex.push_back(Rgb::gray(2.0 + mesh->vertex_position(v).x));
        patch.assign(mesh->size(), Rgb::gray(2.0));
    }
};

}  // namespace

TEST(EyePass, DiffuseShowsBOverPiAndAMirrorPassesItOnTimesItsReflectance) {
    const Rgb rho(0.9, 0.6, 0.3);
    MirrorScene m(rho, 1.5);
    const EyePass pass(m.scene, *m.mesh, m.vertex, m.patch);
    const V eye(0.5, 0.5, 0.5), target(0.5, 0.5, 0.0);
    const Rgb direct = pass.radiance(eye, target - eye);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(direct[c], (2.0 + 0.5) / kPi, 1e-9);  // interpolated linearly
    const V image(8.0 - target.x, target.y, target.z);
    const Rgb seen = pass.radiance(eye, image - eye);
    // To the offset that lifts the reflected ray off the mirror (1e-6 of the scene's diagonal),
    // which moves where it lands on the plate along its shallow path.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(seen[c], rho[c] * direct[c], 1e-5 * direct[c]);
    EXPECT_EQ(pass.radiance(V(5, 0, 0.5), V(-1, 0, 0)), Rgb());  // the mirror's back is black
}

TEST(EyePass, AGlassSlabAtNormalIncidencePassesTheFresnelSeries) {
    for (const double n : {1.5, 2.4}) {
        MirrorScene m(Rgb::gray(1.0), n);
        const EyePass pass(m.scene, *m.mesh, m.vertex, m.patch);
        EyePassOptions o;
        o.min_weight = 1e-12;
        o.max_depth = 64;
        const double R = std::pow((n - 1) / (n + 1), 2), T = (1 - R) * (1 - R) / (1 - R * R);
        const Rgb L = pass.radiance(V(-1.5, 0, 2), V(0, 0, -1), o);
        EXPECT_NEAR(L.g, T * (2.0 - 1.5) / kPi, 1e-9) << "n " << n;
    }
}

TEST(EyePass, APictureStoppedBeforeItStartsIsWholeAndBlack) {
    MirrorScene m(Rgb::gray(0.9), 1.5);
    const EyePass pass(m.scene, *m.mesh, m.vertex, m.patch);
    PinholeCamera cam{{0, -6, 3}, {0, 0, 0}, {0, 0, 1}, 50};
    EyePassOptions o;
    o.width = 40;
    o.height = 30;
    o.samples_per_pixel = 4;
    const EyeImage full = pass.render(cam, o);
    EXPECT_TRUE(full.complete());
    ASSERT_EQ(full.pixels.size(), 40u * 30u);
    // The plate fills the lower middle of the view.
    EXPECT_GT(full.pixels[std::size_t(25 * 40 + 20)].max(), 0.0);
    std::atomic<bool> stop{true};
    const EyeImage none = pass.render(cam, o, {}, &stop);
    EXPECT_EQ(none.rows_done, 0u);
    EXPECT_FALSE(none.complete());
    ASSERT_EQ(none.pixels.size(), 40u * 30u);
    for (const auto& p : none.pixels) EXPECT_EQ(p, Rgb());
    // Same seed, same picture.
    EXPECT_EQ(pass.render(cam, o).pixels, full.pixels);
}

TEST(EyePass, APixelOnAnEdgeGetsMoreRaysAndItsCoverageRight) {
    // Straight down onto the plate (B = 2 + x, to its edge x = 3; black beyond): 37 columns
    // span x in [-4, 4], so column 32 covers x in [3 - 0.375 w, 3 + 0.625 w], w = 8 / 37, and
    // shows 0.375 (5 - 0.375 w / 2) / pi. 16 rays on a 4 x 4 grid place the edge to a quarter
    // of a stratum's 4 rays; the contrast test gives the pixel 256 more.
    MirrorScene m(Rgb::gray(0.9), 1.5);
    const EyePass pass(m.scene, *m.mesh, m.vertex, m.patch);
    const double half = 0.8;  // tan(fov / 2): x = 5 * 0.8 * (2 px - 1) on the plate
    const PinholeCamera cam{{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 2 * std::atan(half) * 180 / kPi};
    EyePassOptions o;
    o.width = o.height = 37;
    o.samples_per_pixel = 16;
    const double w = 8.0 / 37, c = 0.375, expected = c * (5 - c * w / 2) / kPi;
    auto rms = [&](double contrast) {
        o.refine_contrast = contrast;
        const EyeImage img = pass.render(cam, o);
        double sum = 0;
        int n = 0;
        for (int row = 8; row <= 28; ++row, ++n) {
            const double e = img.pixels[std::size_t(row * 37 + 32)].g / expected - 1;
            sum += e * e;
        }
        return std::sqrt(sum / n);
    };
    const double refined = rms(0.5), plain = rms(0.0);
    std::cout << "edge pixels' RMS error: " << 100 * refined << "% refined, " << 100 * plain << "% with 16 rays\n";
    // 16 rays: about sqrt(c (1 - c) / 4) / 4 / c = 16% per pixel; refined, 16 rays a column of
    // strata, a sixteenth of that and the first 16 rays' share.
    EXPECT_LT(refined, 0.03);
    EXPECT_GT(plain, 3 * refined);
}
