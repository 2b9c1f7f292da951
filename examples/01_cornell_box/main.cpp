// SPDX-License-Identifier: MIT
// The library without the command line: the built-in Cornell box, shot to 1e-3 unshot, to
// cornell_example.vtu. Run: build/examples/example_01_cornell_box
#include <iostream>

#include "mesh/meshing/patch_mesh.h"
#include "mesh/readers/cornell_box.h"
#include "solver/form_factors/form_factor_estimator.h"
#include "solver/linear/shooting_solver.h"
#include "solver/visibility/visibility.h"
#include "viewer/vtu_writer.h"

int main() {
    using namespace bounce;
    const Scene scene = make_cornell_box();
    const PatchMesh mesh(scene, MeshingOptions{});
    const auto visibility = make_cgal_visibility(mesh.patches());
    const auto ff = make_form_factor_estimator("raycast", mesh.patches(), visibility.get(), {});
    const SolveResult res = ShootingSolver(mesh.patches(), *ff, {}).solve();
    write_vtu("cornell_example.vtu", mesh, res, {"cornell", "example 01"});
    std::cout << mesh.size() << " patches, " << res.steps << " shots, unshot " << res.unshot_fraction << "\n";
}
