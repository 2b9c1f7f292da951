# SPDX-License-Identifier: MIT
# The solution from Python is the command line's: same options, same numbers (1e-12), read back
# from the .vtu `bounce solve` writes. And what the module writes itself matches what it holds.
import time

import meshio
import numpy as np
import pytest

import bounce

PATCHES = 300


def cell_array(mesh, name):
    # meshio splits the cells into blocks of one type, in file order: joined, patch order.
    return np.concatenate([np.asarray(b) for b in mesh.cell_data[name]])


def assert_same(a, b, what):
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, what
    scale = np.max(np.abs(b))
    assert scale > 0, what
    err = np.max(np.abs(a - b))
    assert err <= 1e-12 * scale, f"{what}: max difference {err} (scale {scale})"


@pytest.fixture(scope="module")
def scene():
    return bounce.load("cornell", patches=PATCHES)


@pytest.mark.parametrize(
    "py_options, cli_options",
    [
        ({}, []),
        ({"solver": "gauss-seidel", "tolerance": 1e-5, "form_factors": "analytic", "gather": "none"},
         ["--solver", "gauss-seidel", "--tolerance", "1e-5", "--form-factors", "analytic", "--gather", "none"]),
    ],
    ids=["shooting-raycast-gathered", "gauss-seidel-analytic-averaged"],
)
def test_solution_equals_command_line_vtu(tmp_path, run_cli, scene, py_options, cli_options):
    cli_vtu = tmp_path / "cli.vtu"
    code, _, err = run_cli("solve", "--patches", PATCHES, "--meshio", "-q", "-o", cli_vtu, *cli_options)
    assert code == 0, err
    cli = meshio.read(cli_vtu)

    sol = bounce.solve(scene, **py_options)
    assert sol.converged
    # Gathered, the solution is over the display cells (as the file is), each patch's power kept.
    assert len(sol.radiosity) == len(sol.patches) == len(cell_array(cli, "radiosity")) >= len(scene)
    assert_same(sol.radiosity, cell_array(cli, "radiosity"), "radiosity")
    assert_same(sol.irradiance, cell_array(cli, "irradiance"), "irradiance")
    assert_same(sol.point_radiosity, cli.point_data["radiosity"], "point radiosity")
    assert sol.point_gathered == ("gather" not in py_options)
    assert int(np.asarray(cli.field_data["steps"]).ravel()[0]) == sol.steps
    assert_same(sol.absorbed_power, np.asarray(cli.field_data["absorbed_power"]).ravel(), "absorbed power")

    # The module's own .vtu holds the same numbers.
    own = tmp_path / "own.vtu"
    sol.write_vtu(own, meshio=True)
    mine = meshio.read(own)
    assert_same(cell_array(mine, "radiosity"), cell_array(cli, "radiosity"), "written radiosity")
    assert_same(mine.point_data["radiosity"], cli.point_data["radiosity"], "written point radiosity")


def test_solution_is_consistent(scene):
    sol = bounce.solve(scene, tolerance=1e-4, gather="none")
    p = scene.patches
    # B = E + rho H, patch by patch: catches any array showing the wrong field or stride.
    np.testing.assert_allclose(sol.radiosity, p.emission + p.reflectance * sol.irradiance, rtol=1e-9, atol=1e-9)
    # The power account closes: emitted = absorbed + escaped + unshot.
    np.testing.assert_allclose(sol.emitted_power, sol.absorbed_power + sol.escaped_power + sol.unshot_power,
                               rtol=1e-9)
    np.testing.assert_allclose(sol.emitted_power, scene.emitted_power, rtol=1e-12)
    np.testing.assert_allclose((p.emission * p.area[:, None]).sum(axis=0), scene.emitted_power, rtol=1e-12)
    h = sol.history
    assert len(h["step"]) > 0 and np.all(np.diff(h["step"].astype(np.int64)) > 0)
    assert h["unshot_fraction"][-1] == pytest.approx(sol.unshot_fraction)
    assert sol.unshot_fraction < 1e-4
    # Shooting builds its balanced rows first (their time is the form factors'); no residuals.
    assert sol.form_factor_seconds > 0 and np.all(h["residual"] == -1)


@pytest.mark.parametrize("gather", ["vertices", "none"])
def test_every_point_is_a_patch_corner(scene, gather):
    # Issue 35: the regions contact cuts remove left vertices no patch used, with radiosity 0
    # in point_radiosity. Every vertex is some face's corner, and the point data is all lit.
    faces = scene.patches.faces
    vertices = np.asarray(scene.patches.vertices)
    used = np.unique(faces[faces >= 0])
    assert len(used) == len(vertices)
    assert used[0] == 0 and used[-1] == len(vertices) - 1
    sol = bounce.solve(scene, tolerance=1e-4, gather=gather)
    # The solution's cells: the scene's patches, or with gathered vertices its display cells.
    cells = sol.patches.faces
    cell_vertices = np.asarray(sol.patches.vertices)
    used = np.unique(cells[cells >= 0])
    assert len(used) == len(cell_vertices)
    points = np.asarray(sol.point_radiosity)
    assert points.shape == cell_vertices.shape
    assert points.max(axis=1).min() > 0


def test_residuals_and_reference_columns(scene):
    # With the matrix built, shooting logs the relative residual; against a reference solution
    # it logs the error, which must end at the distance to that reference.
    ref = bounce.solve(scene, solver="gauss-seidel", tolerance=1e-9, gather="none")
    sol = bounce.solve(scene, tolerance=1e-3, gather="none", residuals=True, reference=ref.radiosity)
    h = sol.history
    assert sol.form_factor_seconds > 0
    assert np.all(h["residual"] >= 0) and h["residual"][-1] < h["residual"][0]
    rms = np.linalg.norm(sol.radiosity - ref.radiosity) / np.linalg.norm(ref.radiosity)
    assert h["rms_error"][-1] == pytest.approx(rms, rel=1e-9)


def test_to_meshio_and_render(tmp_path, scene):
    sol = bounce.solve(scene, tolerance=1e-3, gather="none")
    m = sol.to_meshio()
    # One block per cell type (the box's triangles and quads alternated in 45 blocks), and
    # the cell array patch leads back to the solution's rows.
    types = [b.type for b in m.cells]
    assert types == ["triangle", "quad"], types
    patch = cell_array(m, "patch")
    assert sorted(patch) == list(range(len(sol.radiosity)))
    order = np.argsort(patch)
    assert_same(cell_array(m, "radiosity")[order], sol.radiosity, "meshio radiosity")
    assert_same(m.points, scene.patches.vertices, "meshio points")
    corners = np.concatenate([np.pad(b.data, ((0, 0), (0, 4 - b.data.shape[1])), constant_values=-1)
                              for b in m.cells])[order]
    assert np.array_equal(corners, sol.patches.faces[:, :4])
    # With display cells (polygons of several sizes): one block per size, every cell once.
    shown = bounce.solve(scene, tolerance=1e-3).to_meshio()
    sizes = [b.data.shape[1] for b in shown.cells]
    assert len(sizes) == len(set(sizes)), sizes
    assert sum(len(b.data) for b in shown.cells) == len(cell_array(shown, "patch"))
    shown.write(tmp_path / "meshio.vtu")
    assert len(meshio.read(tmp_path / "meshio.vtu").points) == len(shown.points)
    out = tmp_path / "cornell.png"
    sol.render(out, size=(64, 48))
    import matplotlib.image
    assert matplotlib.image.imread(out).shape[:2] == (48, 64)


@pytest.mark.parametrize(
    "load_options, py_options, cli_options",
    [
        ({"subdivide": False}, {"solver": "hierarchical", "max_level": 1, "gather": "none"},
         ["--no-subdivide", "--solver", "hierarchical", "--max-level", "1", "--gather", "none"]),
        ({"subdivide": False}, {"solver": "hierarchical", "max_level": 1, "gather": "none", "clustering": False},
         ["--no-subdivide", "--solver", "hierarchical", "--max-level", "1", "--gather", "none", "--no-clustering"]),
        ({"patches": 100}, {"adaptive": True}, ["--patches", "100", "--adaptive"]),
    ],
    ids=["hierarchical", "hierarchical-unclustered", "adaptive-gathered"],
)
def test_element_solution_equals_command_line_vtu(tmp_path, run_cli, load_options, py_options, cli_options):
    cli_vtu = tmp_path / "cli.vtu"
    code, _, err = run_cli("solve", "--meshio", "-q", "-o", cli_vtu, *cli_options)
    cli = meshio.read(cli_vtu)
    scene = bounce.load("cornell", **load_options)
    sol = bounce.solve(scene, **py_options)
    assert code == (0 if sol.converged else 3), err
    # The solution is over the elements it made, not the scene's patches.
    assert len(sol.radiosity) == len(sol.patches) > len(scene)
    assert_same(sol.radiosity, cell_array(cli, "radiosity"), "radiosity")
    assert_same(sol.patches.area, cell_array(cli, "area"), "element areas")
    assert_same(sol.point_radiosity, cli.point_data["radiosity"], "point radiosity")
    assert_same(sol.patches.vertices, cli.points, "element vertices")
    assert sol.patches.area.sum() == pytest.approx(scene.total_area, rel=1e-9)
    assert sol.patches.area.base is sol


def test_adaptive_reports_the_hierarchical_rounds_and_takes_a_given_power_epsilon():
    scene = bounce.load("cornell", patches=60)
    stages = set()
    sol = bounce.solve(scene, adaptive=True, power_epsilon=3e-5, gather="none",
                       progress=lambda p: stages.add(p.stage))
    default = bounce.solve(scene, adaptive=True, gather="none")
    # A coarser power bound links fewer, larger elements than the default 1e-5.
    assert len(sol.patches) < len(default.patches)
    assert any(stage.startswith("round 1/1: ") for stage in stages), stages


def test_hierarchical_stops_at_a_given_tolerance_or_iteration_count(run_cli, tmp_path):
    # As --tolerance and --max-iterations: unset, the hierarchical iterations settle to 1e-6.
    scene = bounce.load("cornell", patches=60)
    standard = bounce.solve(scene, solver="hierarchical", max_level=2, gather="none")
    loose = bounce.solve(scene, solver="hierarchical", max_level=2, tolerance=1e-2, gather="none")
    capped = bounce.solve(scene, solver="hierarchical", max_level=2, max_iterations=2, gather="none")
    assert standard.converged and loose.converged
    assert 0 < loose.steps < standard.steps
    assert capped.steps == 2 and not capped.converged
    out = tmp_path / "capped.vtu"
    code, _, err = run_cli("solve", "--patches", 60, "--solver", "hierarchical", "--max-level", 2,
                           "--max-iterations", 2, "--gather", "none", "--meshio", "-q", "-o", out)
    assert code == 3, err
    cli = meshio.read(out)
    assert int(np.asarray(cli.field_data["steps"]).ravel()[0]) == capped.steps
    assert_same(capped.radiosity, cell_array(cli, "radiosity"), "radiosity after two iterations")


def test_display_refinement_adds_cells_like_the_command_line(run_cli, tmp_path):
    # display_tolerance is --display-tolerance: the same cells and point data as the file.
    scene = bounce.load("cornell", subdivide=False)
    sol = bounce.solve(scene, solver="hierarchical", max_level=1, display_tolerance=0.0025)
    plain = bounce.solve(scene, solver="hierarchical", max_level=1)
    assert len(sol.patches) > len(plain.patches)
    assert len(sol.radiosity) == len(sol.patches)
    # The cells tile the same elements with their values: the same power.
    assert (sol.patches.area * sol.radiosity[:, 1]).sum() == pytest.approx(
        (plain.patches.area * plain.radiosity[:, 1]).sum(), rel=1e-12)
    out = tmp_path / "display.vtu"
    code, _, err = run_cli("solve", "--no-subdivide", "--solver", "hierarchical", "--max-level", 1,
                           "--display-tolerance", 0.0025, "--meshio", "-q", "-o", out)
    assert code == (0 if sol.converged else 3), err
    cli = meshio.read(out)
    assert_same(sol.radiosity, cell_array(cli, "radiosity"), "radiosity")
    assert_same(sol.point_radiosity, cli.point_data["radiosity"], "point radiosity")
    with pytest.raises(ValueError, match="display_tolerance refines the point data gathered at the vertices"):
        bounce.solve(scene, solver="hierarchical", max_level=1, display_tolerance=0.0025, gather="none")
    # The patch solvers take it too (they split patches into display cells).
    shown = bounce.solve(bounce.load("cornell", patches=300), display_tolerance=0.02)
    assert len(shown.radiosity) == len(shown.patches) > 300


@pytest.mark.parametrize(
    "options",
    [{"solver": "shooting"}, {"solver": "jacobi"}, {"solver": "gauss-seidel"}, {"solver": "direct"},
     {"solver": "hierarchical", "max_level": 2}, {"adaptive": True, "max_level": 2}],
    ids=["shooting", "jacobi", "gauss-seidel", "direct", "hierarchical", "adaptive"])
def test_seconds_are_the_wall_time_of_the_whole_solve(options):
    # Issue 35: `seconds` counts form factors, refinement, solve and gather for every solver:
    # within 10% of a timer around the call, whose own overhead (arguments, result) is tiny.
    elements = options.get("adaptive") or options.get("solver") == "hierarchical"
    scene = bounce.load("cornell", patches=30 if elements else 1500)  # elements: the coarse roots
    t0 = time.perf_counter()
    sol = bounce.solve(scene, **options)
    wall = time.perf_counter() - t0
    assert sol.point_gathered
    assert 0.9 * wall <= sol.seconds <= wall, (sol.seconds, wall)
