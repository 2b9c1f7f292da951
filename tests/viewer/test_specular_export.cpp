// SPDX-License-Identifier: MIT
// The .vtu of a scene with mirrors and glass: the real program solves, the file is read back
// by VTK's own reader.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <glm/geometric.hpp>

#include "mesh/readers/scene_loader.h"
#include "test_util.h"

using namespace bounce;

namespace {

vtkSmartPointer<vtkUnstructuredGrid> solve_and_read(const test::TempDir& dir, const std::string& scene) {
    const auto vtu = dir / (scene + ".vtu");
    const auto r = test::run(std::string(BOUNCE_EXE) + " solve " + scene + " --patches 200 --quiet -o " + vtu.string());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    vtkNew<vtkXMLUnstructuredGridReader> reader;
    reader->SetFileName(vtu.string().c_str());
    reader->Update();
    vtkSmartPointer<vtkUnstructuredGrid> g = reader->GetOutput();
    return g;
}

/// The share of the picture's pixels in the mirror's grey (R, G and B within a few levels of
/// each other, not dark): the cream walls and floor of the box are not grey.
double grey_share(const std::filesystem::path& png) {
    vtkNew<vtkPNGReader> reader;
    reader->SetFileName(png.string().c_str());
    reader->Update();
    vtkImageData* im = reader->GetOutput();
    int dims[3];
    im->GetDimensions(dims);
    std::size_t grey = 0;
    for (int y = 0; y < dims[1]; ++y)
        for (int x = 0; x < dims[0]; ++x) {
            const auto* p = static_cast<const unsigned char*>(im->GetScalarPointer(x, y, 0));
            const int r = p[0], g = p[1], b = p[2];
            grey += std::abs(r - g) < 8 && std::abs(g - b) < 10 && r > 60;
        }
    return double(grey) / (double(dims[0]) * dims[1]);
}

}  // namespace

TEST(SpecularExport, MirrorAndGlassSpheresAreCellsOnTheirSpheres) {
    const test::TempDir dir;
    const auto g = solve_and_read(dir, "cornell-spheres");
    vtkDataArray* kind = g->GetCellData()->GetArray("material_kind");
    ASSERT_NE(kind, nullptr);
    const Scene scene = load_scene("cornell-spheres", {});
    ASSERT_EQ(scene.spheres.size(), 2u);
    // 48 x 24 faces per sphere (tessellate_sphere), after every diffuse patch.
    const vtkIdType per_sphere = 48 * 24;
    vtkIdType count[3] = {0, 0, 0};
    double area[3] = {0, 0, 0};
    double worst = 0.0;  // | |T^-1 p| - 1 | over the corners of the sphere cells
    vtkNew<vtkIdList> ids;
    vtkDataArray* cell_area = g->GetCellData()->GetArray("area");
    vtkDataArray* radiosity = g->GetCellData()->GetArray("radiosity");
    vtkDataArray* point_radiosity = g->GetPointData()->GetArray("radiosity");
    for (vtkIdType c = 0; c < g->GetNumberOfCells(); ++c) {
        const int k = int(kind->GetTuple1(c));
        ASSERT_TRUE(k >= 0 && k <= 2) << "cell " << c << " kind " << k;
        ++count[k];
        area[k] += cell_area->GetTuple1(c);
        if (k == 0) {
            ASSERT_EQ(count[1] + count[2], 0) << "diffuse cell " << c << " after the specular ones";
            continue;
        }
        // The sphere of this cell's material: mirror first, glass second in the scene.
        const Sphere& s = scene.spheres[k == 1 ? 0 : 1];
        ASSERT_EQ(int(scene.materials[std::size_t(s.material)].kind), k);
        EXPECT_EQ(radiosity->GetComponent(c, 0), 0.0);
        g->GetCellPoints(c, ids);
        for (vtkIdType j = 0; j < ids->GetNumberOfIds(); ++j) {
            double p[3];
            g->GetPoint(ids->GetId(j), p);
            const double r = glm::length(s.transform.inverse_point({p[0], p[1], p[2]}));
            worst = std::max(worst, std::abs(r - 1.0));
            EXPECT_EQ(point_radiosity->GetComponent(ids->GetId(j), 1), 0.0);
        }
    }
    std::printf("cells: %lld diffuse, %lld mirror, %lld glass; worst |r - 1| of a sphere corner %.3g\n",
                (long long)count[0], (long long)count[1], (long long)count[2], worst);
    EXPECT_GT(count[0], 150);
    EXPECT_EQ(count[1], per_sphere);
    EXPECT_EQ(count[2], per_sphere);
    EXPECT_LT(worst, 1e-9);
    // Inscribed: a little less than the sphere's 4 pi r^2 (r from the transform's scale).
    const double r =
        glm::length(scene.spheres[0].transform.point({1, 0, 0}) - scene.spheres[0].transform.point({0, 0, 0}));
    const double sphere_area = 4 * std::numbers::pi * r * r;
    std::printf("mirror cells' area / 4 pi r^2 = %.5f\n", area[1] / sphere_area);
    EXPECT_LT(area[1], sphere_area);
    EXPECT_GT(area[1], 0.99 * sphere_area);
    EXPECT_NEAR(area[2], area[1], 1e-9 * area[1]);
}

TEST(SpecularExport, ADiffuseSceneHasNoMaterialKind) {
    const test::TempDir dir;
    const auto g = solve_and_read(dir, "cornell");
    EXPECT_EQ(g->GetCellData()->GetArray("material_kind"), nullptr);
    vtkDataArray* surface = g->GetCellData()->GetArray("surface");
    ASSERT_NE(surface, nullptr);
    for (vtkIdType c = 0; c < g->GetNumberOfCells(); ++c) ASSERT_GE(surface->GetTuple1(c), 0) << c;
}

TEST(SpecularExport, RenderOfTheVtuDrawsTheMirrorSphere) {
    const test::TempDir dir;
    double share[2] = {0, 0};
    int k = 0;
    for (const std::string scene : {"cornell-spheres", "cornell"}) {
        solve_and_read(dir, scene);
        const auto png = dir / (scene + ".png");
        const auto r = test::run(std::string(BOUNCE_EXE) + " render " + (dir / (scene + ".vtu")).string() + " -o " +
                                 png.string() + " --size 200x200");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        share[k++] = grey_share(png);
    }
    // The mirror ball (r = 100 mm, about 1.2 m from the Cornell camera) covers about 5% of the view.
    std::printf("grey pixels: %.4f with the spheres, %.4f in the plain box\n", share[0], share[1]);
    EXPECT_GT(share[0], 0.03);
    EXPECT_LT(share[1], 0.01);
}
