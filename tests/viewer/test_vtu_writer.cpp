// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include <vtkCellData.h>
#include <vtkCellLocator.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkStringArray.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/cornell_box.h"
#include "mesh/readers/json_scene.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/linear/shooting_solver.h"
#include "solver/visibility/visibility.h"
#include "test_util.h"
#include "viewer/camera.h"
#include "viewer/luminance_scale.h"
#include "viewer/solution_grid.h"
#include "viewer/tone_map.h"
#include "viewer/vtu_writer.h"

using namespace bounce;

namespace {

struct Solved {
    PatchMesh mesh;
    SolveResult result;
};

const Solved& cornell() {
    static const Solved s = [] {
        MeshingOptions o;
        o.target_patches = 600;
        PatchMesh mesh(make_cornell_box(), o);
        const auto vis = make_cgal_visibility(mesh.patches());
        const auto ff = make_form_factor_estimator("raycast", mesh.patches(), vis.get(), {});
        ShootingOptions so;
        so.tolerance = 1e-3;
        SolveResult r = ShootingSolver(mesh.patches(), *ff, so).solve();
        return Solved{std::move(mesh), std::move(r)};
    }();
    return s;
}

vtkSmartPointer<vtkUnstructuredGrid> read(const std::filesystem::path& p) {
    vtkNew<vtkXMLUnstructuredGridReader> r;
    r->SetFileName(p.string().c_str());
    r->Update();
    return r->GetOutput();
}

double field(vtkUnstructuredGrid* g, const char* name, int component = 0) {
    auto* a = g->GetFieldData()->GetArray(name);
    if (!a) ADD_FAILURE() << "missing field " << name;
    return a ? a->GetComponent(0, component) : 0.0;
}

}  // namespace

TEST(VtuWriter, ReadsBackWithEveryArrayAndTheEnergyBalanceHoldsFromTheFile) {
    test::TempDir dir;
    const auto& s = cornell();
    for (bool ascii : {false, true}) {
        const auto path = dir / (ascii ? "a.vtu" : "b.vtu");
        write_vtu(path, s.mesh, s.result, {"cornell", "test"}, ascii);
        const auto g = read(path);
        const vtkIdType n = vtkIdType(s.mesh.size());
        ASSERT_EQ(g->GetNumberOfCells(), n);
        auto* cd = g->GetCellData();
        for (const char* name : {"radiosity", "emission", "reflectance", "irradiance"}) {
            ASSERT_NE(cd->GetArray(name), nullptr) << name;
            EXPECT_EQ(cd->GetArray(name)->GetNumberOfTuples(), n);
            EXPECT_EQ(cd->GetArray(name)->GetNumberOfComponents(), 3);
        }
        for (const char* name : {"area", "surface", "luminance"}) {
            ASSERT_NE(cd->GetArray(name), nullptr) << name;
            EXPECT_EQ(cd->GetArray(name)->GetNumberOfTuples(), n);
        }
        ASSERT_NE(g->GetPointData()->GetArray("radiosity"), nullptr);
        EXPECT_EQ(g->GetPointData()->GetArray("radiosity")->GetNumberOfTuples(), g->GetNumberOfPoints());
        // Text fields are string arrays (ParaView shows them as text), one value each.
        for (const auto& [name, value] : {std::pair<const char*, std::string>{"solver", "shooting"},
                                          {"scene", "cornell"},
                                          {"settings", "test"},
                                          {"status", s.result.status}}) {
            auto* text = vtkStringArray::SafeDownCast(g->GetFieldData()->GetAbstractArray(name));
            ASSERT_NE(text, nullptr) << name;
            ASSERT_EQ(text->GetNumberOfValues(), 1) << name;
            EXPECT_EQ(text->GetValue(0), value) << name;
        }

        // Energy balance from the file's own numbers, per channel:
        // emitted = sum E A, absorbed = sum (1 - rho) H A, emitted = absorbed + escaped + unshot,
        // and every patch satisfies B = E + rho H.
        auto* B = cd->GetArray("radiosity");
        auto* E = cd->GetArray("emission");
        auto* R = cd->GetArray("reflectance");
        auto* H = cd->GetArray("irradiance");
        auto* A = cd->GetArray("area");
        for (int c = 0; c < 3; ++c) {
            double emitted = 0, absorbed = 0, worst = 0;
            for (vtkIdType i = 0; i < n; ++i) {
                const double a = A->GetTuple1(i);
                emitted += E->GetComponent(i, c) * a;
                absorbed += (1 - R->GetComponent(i, c)) * H->GetComponent(i, c) * a;
                const double b = E->GetComponent(i, c) + R->GetComponent(i, c) * H->GetComponent(i, c);
                worst = std::max(worst, std::abs(B->GetComponent(i, c) - b) / std::max(b, 1e-300));
            }
            EXPECT_LT(worst, 1e-12);
            EXPECT_NEAR(emitted / field(g, "emitted_power", c), 1.0, 1e-12);
            EXPECT_NEAR(absorbed / field(g, "absorbed_power", c), 1.0, 1e-9);
            const double balance =
                field(g, "absorbed_power", c) + field(g, "escaped_power", c) + field(g, "unshot_power", c);
            EXPECT_NEAR(balance / emitted, 1.0, 1e-9);
        }
        EXPECT_EQ(field(g, "converged"), 1.0);
        EXPECT_LT(field(g, "unshot_fraction"), 1e-3);
    }
}

TEST(VtuWriter, RedAndGreenWallsTintTheWhiteSurfacesNearThem) {
    // Colour bleeding: white floor and ceiling patches near the red wall (x ~ 550) are redder
    // (higher R/G) than those near the green wall (x = 0), and the converse for green.
    const auto& s = cornell();
    const auto& P = s.mesh.patches();
    double near_red[3] = {}, near_green[3] = {};
    for (std::size_t i = 0; i < P.size(); ++i) {
        if (!(P[i].reflectance == Rgb(0.725, 0.71, 0.68)) || std::abs(P[i].normal.y) < 0.9) continue;
        auto* acc = P[i].centre.x > 450 ? near_red : (P[i].centre.x < 100 ? near_green : nullptr);
        if (!acc) continue;
        for (int c = 0; c < 3; ++c) acc[c] += s.result.radiosity[i][c] * P[i].area;
    }
    EXPECT_GT(near_red[0] / near_red[1], 1.1 * near_green[0] / near_green[1]);
    EXPECT_GT(near_green[1] / near_green[0], 1.1 * near_red[1] / near_red[0]);
}

TEST(VtuWriter, AFailedWriteLeavesNoFile) {
    test::TempDir dir;
    const auto& s = cornell();
    const auto target = dir / "missing-dir" / "x.vtu";
    EXPECT_THROW(write_vtu(target, s.mesh, s.result, {"cornell", ""}), std::runtime_error);
    EXPECT_FALSE(std::filesystem::exists(target));
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(VtuWriter, TextAsCharsForMeshio) {
    test::TempDir dir;
    const auto& s = cornell();
    ExportInfo info{"cornell", "test"};
    info.text_as_chars = true;
    write_vtu(dir / "c.vtu", s.mesh, s.result, info);
    const auto g = read(dir / "c.vtu");
    auto* text = g->GetFieldData()->GetArray("scene");  // a numeric array: Int8 codes
    ASSERT_NE(text, nullptr);
    EXPECT_EQ(text->GetDataType(), VTK_SIGNED_CHAR);  // XML type Int8
    std::string scene;
    for (vtkIdType i = 0; i < text->GetNumberOfTuples(); ++i) scene += char(text->GetTuple1(i));
    EXPECT_EQ(scene, "cornell");
}

TEST(VtuWriter, DisplayRgbIsTheRenderToneMapAtExposureZero) {
    test::TempDir dir;
    const auto& s = cornell();
    write_vtu(dir / "d.vtu", s.mesh, s.result, {"cornell", "test"});
    const auto g = read(dir / "d.vtu");
    auto* rgb = vtkUnsignedCharArray::SafeDownCast(g->GetCellData()->GetArray("display_rgb"));
    ASSERT_NE(rgb, nullptr);
    ASSERT_EQ(rgb->GetNumberOfComponents(), 3);
    ASSERT_EQ(rgb->GetNumberOfTuples(), vtkIdType(s.mesh.size()));
    ASSERT_NE(g->GetPointData()->GetArray("display_rgb"), nullptr);
    std::vector<Rgb> E;
    std::vector<double> A;
    for (const auto& p : s.mesh.patches()) {
        E.push_back(p.emission);
        A.push_back(p.area);
    }
    const ToneMap tm = ToneMap::automatic(s.result.radiosity, E, A, 0.0);
    double mean_grey = 0, weight = 0;
    for (std::size_t i = 0; i < s.mesh.size(); ++i) {
        const auto want = tm(s.result.radiosity[i]);
        for (int c = 0; c < 3; ++c) ASSERT_EQ(rgb->GetValue(vtkIdType(3 * i + c)), want[c]) << i;
        if (E[i].max() == 0) {
            mean_grey += (rgb->GetValue(vtkIdType(3 * i)) + rgb->GetValue(vtkIdType(3 * i + 1))) * A[i] / 2;
            weight += A[i];
        }
    }
    // Not nearly black (the finding: raw radiosity with Map Scalars off is about 0.1 of full
    // scale): the walls sit around mid grey after the 1 - exp(-x) curve and sRGB encoding.
    mean_grey /= weight;
    EXPECT_GT(mean_grey, 100);
    EXPECT_LT(mean_grey, 220);
}

// Issue 35, item 9: --luminance's colour bar spans what the camera sees, not the brightest face
// anywhere (the tall block's top, above the eye, set it and left the walls in one colour), and
// names the scene's unit.
TEST(LuminanceScale, SpansWhatTheCameraSeesAndNamesTheUnit) {
    test::TempDir dir;
    const auto& s = cornell();
    write_vtu(dir / "u.vtu", s.mesh, s.result, {"cornell", "test", false, "mm"});
    const auto g = read(dir / "u.vtu");
    EXPECT_EQ(luminance_unit(g), "W per mm^2");
    write_vtu(dir / "n.vtu", s.mesh, s.result, {"cornell", "test"});
    EXPECT_EQ(luminance_unit(read(dir / "n.vtu")), "W per unit area");

    const CameraPose pose = choose_camera(g, "cornell", 0.0, 1.0);
    const double top_cells = luminance_scale_top(g, pose, 1.0, false);
    const double top_points = luminance_scale_top(g, pose, 1.0, true);
    ASSERT_NE(g->GetPointData()->GetArray("luminance"), nullptr);
    // The brightest face that does not emit, and the area-weighted median of the walls'.
    auto* l = g->GetCellData()->GetArray("luminance");
    auto* e = g->GetCellData()->GetArray("emission");
    auto* area = g->GetCellData()->GetArray("area");
    double brightest = 0;
    std::vector<std::pair<double, double>> walls;
    for (vtkIdType i = 0; i < l->GetNumberOfTuples(); ++i) {
        if (e->GetComponent(i, 0) > 0) continue;
        brightest = std::max(brightest, l->GetTuple1(i));
        walls.emplace_back(l->GetTuple1(i), area->GetTuple1(i));
    }
    std::sort(walls.begin(), walls.end());
    double total = 0, run = 0, median = 0;
    for (const auto& w : walls) total += w.second;
    for (const auto& w : walls)
        if ((run += w.second) >= 0.5 * total) {
            median = w.first;
            break;
        }
    for (const double top : {top_cells, top_points}) {
        EXPECT_LT(top, 0.6 * brightest);
        // Half the surface area in the upper three quarters of the scale (it was the bottom
        // quarter), and the scale still above the median.
        EXPECT_GT(median / top, 0.25) << median << " " << top;
        EXPECT_LT(median / top, 1.0);
    }
    // Looking away from everything lit (at the floor from just above it, face-on), the scale
    // follows the view.
    CameraPose down = pose;
    down.position = {278, 10, 279};
    down.focal_point = {278, 0, 279};
    down.view_up = {0, 0, 1};
    down.view_angle = 20;
    EXPECT_NE(luminance_scale_top(g, down, 1.0, false), top_cells);
}

namespace {

/// The share of the picture from `pose` whose first face is one of surfaces [first, last]: rays
/// through a 24 x 24 grid of the frame (aspect 1).
double frame_share(vtkUnstructuredGrid* g, const CameraPose& pose, int first, int last) {
    vtkNew<vtkCellLocator> locator;
    locator->SetDataSet(g);
    locator->BuildLocator();
    using V = std::array<double, 3>;
    auto minus = [](V a, V b) { return V{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
    auto cross = [](V a, V b) {
        return V{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    };
    auto unit = [](V a) {
        const double l = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        return V{a[0] / l, a[1] / l, a[2] / l};
    };
    const V f = unit(minus(pose.focal_point, pose.position));
    const V r = unit(cross(f, pose.view_up));
    const V u = cross(r, f);
    const double t = std::tan(pose.view_angle * M_PI / 360.0);
    auto* surface = g->GetCellData()->GetArray("surface");
    int hits = 0, rays = 0;
    for (int i = 0; i < 24; ++i)
        for (int j = 0; j < 24; ++j, ++rays) {
            const double x = t * (-1 + 2 * (i + 0.5) / 24), y = t * (-1 + 2 * (j + 0.5) / 24);
            V to;
            for (int a = 0; a < 3; ++a) to[a] = pose.position[a] + 1000 * (f[a] + x * r[a] + y * u[a]);
            double tt, xx[3], pc[3];
            int sub;
            vtkIdType cell = -1;
            if (locator->IntersectWithLine(pose.position.data(), to.data(), 1e-9, tt, xx, pc, sub, cell)) {
                const int s = int(surface->GetTuple1(cell));
                hits += s >= first && s <= last;
            }
        }
    return double(hits) / rays;
}

}  // namespace

// Issue 35, item 14: in a closed room the auto camera stood just inside the most open wall's
// centre, behind a cube that filled much of the frame. It now tries other places with rays.
TEST(AutoCamera, StandsWhereALargeObjectDoesNotBlockTheView) {
    test::TempDir dir;
    // A 6 x 3 x 6 room (y up), a lamp under the ceiling, a 1.6 cube a little in front of the
    // -z wall's centre, where the camera stood.
    const auto json = dir.write("room.json", R"({"materials": {"w": {"reflectance": 0.6},
        "lamp": {"reflectance": 0, "emission": 5}}, "objects": [
        {"type": "box", "material": "w", "inward": true, "transform": {"scale": [6, 3, 6]}},
        {"type": "quad", "material": "lamp", "transform": {"rotate": {"axis": [1, 0, 0], "degrees": 90},
            "translate": [0, 1.45, 0]}},
        {"type": "box", "material": "w", "transform": {"scale": 1.6, "translate": [0, -0.7, -1.9]}}]})");
    const Scene scene = read_json_scene(json);
    MeshingOptions mo;
    mo.target_patches = 300;
    const PatchMesh mesh(scene, mo);
    SolveResult r;
    r.radiosity.assign(mesh.size(), Rgb::gray(0.5));
    const auto g = make_solution_grid(mesh, r, {json.string(), ""});
    const CameraPose pose = choose_camera(g, "auto", 0.0, 1.0);
    // The room's 6 faces, the lamp, then the cube's 6.
    EXPECT_LT(frame_share(g, pose, 7, 12), 0.2);
    // Standing inside the room, looking across it (not from outside).
    for (int a = 0; a < 3; ++a) {
        EXPECT_GT(pose.position[a], a == 1 ? -1.5 : -3.0);
        EXPECT_LT(pose.position[a], a == 1 ? 1.5 : 3.0);
    }
    // Where it stood before, behind the cube: the cube took far more of the frame.
    CameraPose before = pose;
    before.position = {0, 0, -3 + 0.02 * 6};
    before.focal_point = {0, 0, 3};
    EXPECT_GT(frame_share(g, before, 7, 12), 0.3);
}
