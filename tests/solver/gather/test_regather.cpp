// SPDX-License-Identifier: MIT
// The solve and the re-gather of a solution refined with a power epsilon (kRegatherSteps)
// where they matter most: the acute wedge (about 43 degrees) where one box crosses another in a closed room, as
// objects in real models often do. The coarse elements of the crossed faces take the
// irradiance of many links, each accepted for its small power, that their parts in the wedge
// do not see. The leaves' re-gathered centre values, and the cell values taken from them,
// are scored against the path tracer at the same centres.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/scene_loader.h"
#include "solver/gather/hierarchical_point_values.h"
#include "solver/reference/path_tracer.h"
#include "solver/refinement/hierarchical_radiosity.h"
#include "solver/visibility/visibility.h"
#include "test_util.h"

using namespace bounce;

namespace {

/// A closed 6 x 3 x 6 m room (rho 0.7) lit by a 1 m square lamp under its ceiling (which also
/// reflects, rho 0.3, so the cells' B = E + rho H is tested on an emitter too), with two
/// grey boxes (rho 0.5) of the room of 20 boxes of the scene set
/// (docs/measurements/data/open_parts/random_boxes_room.py 20 1): the second crosses the
/// first's -x face at an acute angle near (-1.32, 1.28, -0.24).
Scene wedge_room() {
    test::TempDir tmp;
    const auto path = tmp.write("wedge.json", R"({"name": "two boxes crossing at an acute wedge",
      "materials": {"wall": {"reflectance": 0.7}, "grey": {"reflectance": 0.5},
                    "lamp": {"reflectance": 0.3, "emission": 10}},
      "objects": [
        {"type": "box", "material": "wall", "inward": true, "transform": {"scale": [6, 3, 6], "translate": [0, 1.5, 0]}},
        {"type": "quad", "material": "lamp",
         "transform": {"scale": 1, "rotate": {"axis": [1, 0, 0], "degrees": 90}, "translate": [0, 2.9, 0]}},
        {"type": "box", "material": "grey", "transform": {"scale": [0.194, 0.693, 0.635], "translate": [-1.225, 1.34, -0.253]}},
        {"type": "box", "material": "grey", "transform": {"scale": [0.139, 0.709, 0.499],
         "rotate": {"axis": [-0.2864, -0.3078, 0.0770], "degrees": 56.11}, "translate": [-1.501, 1.36, -0.075]}}]})");
    return load_scene(path.string());
}

struct Error {
    double mean = 0.0, rms = 0.0;
};

/// `--adaptive`'s solution of the wedge room and the path tracer at the centres of its leaves
/// within 15 cm of the wedge that it finds open (a leaf's centre inside the other box gets
/// nothing there).
struct WedgeSolution {
    Scene scene = wedge_room();
    PatchMesh mesh{scene, roots()};
    std::unique_ptr<Visibility> visibility = make_visibility("embree", mesh.patches());
    HierarchicalSolution sol = solve_hierarchical(mesh.patches(), *visibility, adaptive());
    PatchMesh cells = sol.tree.conforming_mesh(sol.leaves);
    std::vector<std::size_t> leaves;  // into sol.leaves
    std::vector<double> truth;        // luminance at their centres

    WedgeSolution() {
        const PathTracer tracer(scene);
        const glm::dvec3 wedge(-1.324, 1.28, -0.243);
        std::vector<SurfacePoint> points;
        for (std::size_t k = 0; k < cells.size(); ++k) {
            const Patch& p = cells.patches()[k];
            if (glm::length(p.centre - wedge) > 0.15) continue;
            if (const auto x = tracer.locate(p.centre, p.normal)) {
                leaves.push_back(k);
                points.push_back(*x);
            }
        }
        ReferenceOptions o;
        o.target_error = 0.01;
        for (const auto& e : tracer.estimate_all(points, o)) truth.push_back(e.radiosity.luminance());
    }
    static MeshingOptions roots() {
        MeshingOptions coarse;
        coarse.target_patches = 30;  // the roots `bounce solve --adaptive` starts from
        return coarse;
    }
    static HierarchicalOptions adaptive() {
        HierarchicalOptions h;
        h.power_epsilon = adaptive_power_epsilon(0.0);
        return h;
    }
    /// The relative error of `values` (per leaf) at the leaves by the wedge.
    Error error_of(const std::vector<Rgb>& values) const {
        Error e;
        std::size_t n = 0;
        for (std::size_t q = 0; q < leaves.size(); ++q) {
            if (!(truth[q] > 0)) continue;
            const double off = values[leaves[q]].luminance() / truth[q] - 1;
            e.mean += off;
            e.rms += off * off;
            ++n;
        }
        EXPECT_GE(n, 20u);
        e.mean /= double(n);
        e.rms = std::sqrt(e.rms / double(n));
        return e;
    }
};

const WedgeSolution& wedge_solution() {
    static const WedgeSolution w;
    return w;
}

}  // namespace

TEST(Regather, TheCentresTakeTheWedgesLeavesCloserToThePathTracer) {
    const WedgeSolution& w = wedge_solution();
    SolveResult res = w.sol.result;
    ASSERT_EQ(kRegatherSteps, 1);
    ASSERT_EQ(gather_hierarchical_point_values(w.sol, w.cells, *w.visibility, res, "centres"), GatherOutcome::gathered);
    ASSERT_EQ(res.gathered_centres.size(), w.sol.leaves.size());
    const Error solved = w.error_of(w.sol.result.radiosity), centres = w.error_of(res.gathered_centres);
    std::printf(
        "by the wedge: the solve's leaves %+.4f mean, %.4f RMS; their centres re-gathered %+.4f mean, %.4f RMS\n",
        solved.mean, solved.rms, centres.mean, centres.rms);
    EXPECT_LT(centres.rms, 0.6 * solved.rms);
}

// Each link's ends send and take by where they see each other (HierarchicalOptions::
// weighted_ends): a coarse element of a crossed face no longer hands its leaves in the wedge
// the irradiance of the sources only its open side sees.
TEST(Regather, WeightedEndsKeepTheLinksExcessOutOfTheWedgesLeaves) {
    const WedgeSolution& w = wedge_solution();
    HierarchicalOptions o = WedgeSolution::adaptive();
    o.weighted_ends = false;
    const HierarchicalSolution plain = solve_hierarchical(w.mesh.patches(), *w.visibility, o);
    ASSERT_EQ(plain.leaves, w.sol.leaves);  // the same refinement: only the transport differs
    const Error weighted = w.error_of(w.sol.result.radiosity), mean_ends = w.error_of(plain.result.radiosity);
    std::printf(
        "the solve's leaves by the wedge: %+.4f mean, %.4f RMS with weighted ends; %+.4f mean, %.4f RMS "
        "with means\n",
        weighted.mean, weighted.rms, mean_ends.mean, mean_ends.rms);
    EXPECT_LT(weighted.rms, 0.5 * mean_ends.rms);
    EXPECT_LT(std::abs(weighted.mean), 0.5 * mean_ends.mean);
}

TEST(Regather, CellsTakeTheCentresShareAndEachPatchKeepsItsPower) {
    const WedgeSolution& w = wedge_solution();
    SolveResult res = w.sol.result;
    ASSERT_EQ(gather_hierarchical_point_values(w.sol, w.cells, *w.visibility, res, "vertices"),
              GatherOutcome::gathered);
    const Error solved = w.error_of(w.sol.result.radiosity), cells = w.error_of(res.radiosity);
    std::printf("cell values by the wedge: the solve's %+.4f mean, %.4f RMS; exported %+.4f mean, %.4f RMS\n",
                solved.mean, solved.rms, cells.mean, cells.rms);
    // The centres' share within each patch: closer to the path tracer than the solve's leaves,
    // which hold their coarse ancestors' irradiance (the centres themselves: 0.6 of it, above).
    EXPECT_LT(cells.rms, 0.7 * solved.rms);
    // Every input patch (root) keeps the power the solve gave its open part, per channel
    // (an element partly inside the other box is partly buried: element_open_shares.h), and
    // B = E + rho H.
    const auto& tree = w.sol.tree;
    std::vector<Rgb> before(tree.root_count()), after(tree.root_count());
    for (std::size_t k = 0; k < w.sol.leaves.size(); ++k) {
        const std::uint32_t r = tree.node(w.sol.leaves[k]).root;
        const Patch& p = tree.geometry()[w.sol.leaves[k]];
        const double open_area = p.area * w.sol.sending_share(w.sol.leaves[k]);
        before[r] += w.sol.result.radiosity[k] * open_area;
        after[r] += res.radiosity[k] * open_area;
        for (int c = 0; c < 3; ++c) {
            if (!(p.reflectance[c] > 0)) continue;
            EXPECT_NEAR(res.radiosity[k][c], p.emission[c] + p.reflectance[c] * res.irradiance[k][c],
                        1e-12 * (1 + res.radiosity[k][c]));
        }
    }
    for (std::size_t r = 0; r < tree.root_count(); ++r)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(after[r][c], before[r][c], 1e-12 * (1 + before[r][c])) << r;
}
