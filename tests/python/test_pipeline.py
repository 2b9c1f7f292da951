# SPDX-License-Identifier: MIT
# One solve pipeline (solver/pipeline) behind `bounce solve` and bounce.solve: the same request
# gives the same bits, the same settings and the same warnings from both.
import warnings

import meshio
import numpy as np
import pytest

import bounce


def cell_array(mesh, name):
    # meshio splits the cells into blocks of one type, in file order: joined, patch order.
    return np.concatenate([np.asarray(b) for b in mesh.cell_data[name]])


def text_field(mesh, name):
    # With --meshio a text field is a char array.
    return "".join(chr(int(c)) for c in np.asarray(mesh.field_data[name]).ravel())


FURNACE = ('{"name": "furnace", "materials": {"glow": {"reflectance": 0.9, "emission": 1}}, '
           '"objects": [{"type": "box", "material": "glow", "inward": true, '
           '"transform": {"scale": [2, 1.5, 1]}}]}')


@pytest.mark.parametrize(
    "load_options, py_options, cli_options",
    [
        ({"patches": 300}, {}, ["--patches", 300]),
        ({"patches": 300}, {"solver": "gauss-seidel", "gather": "centres"},
         ["--patches", 300, "--solver", "gauss-seidel", "--gather", "centres"]),
        ({"patches": 300}, {"solver": "direct"}, ["--patches", 300, "--solver", "direct"]),
        # The default meshing: both start the hierarchy from the same coarse roots.
        ({}, {"solver": "hierarchical", "max_level": 2}, ["--solver", "hierarchical", "--max-level", 2]),
        ({}, {"adaptive": True, "max_level": 2}, ["--adaptive", "--max-level", 2]),
        # A preset: load()'s scene is cut anew at the preset's patch count, as the flag cuts it.
        ({}, {"quality": "draft"}, ["--quality", "draft"]),
        # The rows as sampled, and whole patches: the keywords are the flags.
        ({"patches": 300}, {"balance": False}, ["--patches", 300, "--no-balance"]),
        ({"patches": 300}, {"solver": "gauss-seidel", "balance": False},
         ["--patches", 300, "--solver", "gauss-seidel", "--no-balance"]),
        ({"patches": 300}, {"whole_patches": True}, ["--patches", 300, "--whole-patches"]),
    ],
    ids=["shooting", "gauss-seidel-centres", "direct", "hierarchical-default-meshing",
         "adaptive-default-meshing", "draft-preset", "shooting-no-balance", "gauss-seidel-no-balance",
         "shooting-whole-patches"],
)
def test_same_request_same_bits(tmp_path, run_cli, load_options, py_options, cli_options):
    out = tmp_path / "cli.vtu"
    code, _, err = run_cli("solve", "--meshio", "-q", "-o", out, *cli_options)
    cli = meshio.read(out)
    sol = bounce.solve(bounce.load("cornell", **load_options), **py_options)
    assert code == (0 if sol.converged else 3), err
    radiosity = cell_array(cli, "radiosity")
    print(f"{sol.solver}: {len(radiosity)} cells, {sol.steps} steps")
    assert len(radiosity) > 100
    assert np.array_equal(sol.radiosity, radiosity)
    assert np.array_equal(sol.irradiance, cell_array(cli, "irradiance"))
    assert np.array_equal(sol.point_radiosity, cli.point_data["radiosity"])
    assert np.array_equal(sol.patches.vertices, cli.points)
    if py_options.get("gather") == "centres":
        assert np.array_equal(sol.gathered_centres, cell_array(cli, "radiosity_gathered"))
    assert sol.settings == text_field(cli, "settings")
    if py_options.get("balance") is False:
        assert " open_parts=1 " in sol.settings and "balanced=" not in sol.settings, sol.settings
    if py_options.get("whole_patches"):
        assert "open_parts=" not in sol.settings and "balanced=" not in sol.settings, sol.settings
    if not py_options:
        assert " open_parts=1 balanced=1" in sol.settings, sol.settings
    assert sol.status == text_field(cli, "status")
    assert int(np.asarray(cli.field_data["steps"]).ravel()[0]) == sol.steps


def test_a_request_object_is_its_keywords():
    scene = bounce.load("cornell", patches=100)
    request = bounce.SolveRequest(solver="gauss-seidel", gather="none")
    by_keywords = bounce.solve(scene, solver="gauss-seidel", gather="none", quiet=True)
    by_request = bounce.solve(scene, request, quiet=True)
    assert np.array_equal(by_request.radiosity, by_keywords.radiosity)
    # Keywords beside the request win; replace() makes a changed copy.
    shooting = bounce.solve(scene, request, solver="shooting")
    assert shooting.solver == "shooting" and request.options["solver"] == "gauss-seidel"
    assert request.replace(solver="shooting") == bounce.SolveRequest(solver="shooting", gather="none")
    with pytest.raises(ValueError, match=r"solver: unknown, got 'newton'"):
        bounce.solve(scene, request.replace(solver="newton"))
    with pytest.raises(TypeError, match="must be a bounce.SolveRequest"):
        bounce.solve(scene, {"solver": "jacobi"})


def test_hierarchical_roots_are_the_command_lines_coarse_patches():
    # load()'s default 2000 patches would be 2000 quadtree roots; like the command line, the
    # hierarchical solver cuts about 30 instead (90 on the box: contact cuts split faces).
    sol = bounce.solve(bounce.load("cornell"), solver="hierarchical", max_level=1, gather="none")
    assert sol.settings.startswith("patches=90 rays=4 seed=1 solver=hierarchical"), sol.settings


def test_rows_above_one_warn_in_both(tmp_path, run_cli):
    # A 16-pixel hemicube's rows sum above 1: Gauss-Seidel sums the matrix's rows before it
    # solves. Balanced (the default in both front ends) every part of the closed furnace is
    # closed and its row sums to one, so neither warns; with the rows as sampled
    # (`--no-balance`) the command line warns.
    scene = tmp_path / "furnace.json"
    scene.write_text(FURNACE)
    options = ["--patches", 216, "--solver", "gauss-seidel", "--form-factors", "hemicube", "--hemicube-res", 16,
               "--gather", "none"]
    code, _, err = run_cli("solve", scene, "-o", tmp_path / "f.vtu", *options, "--no-balance")
    assert code == 0, err
    cli = [line[len("warning: "):] for line in err.splitlines() if line.startswith("warning: ")]
    assert len(cli) == 1 and cli[0].startswith("form-factor rows sum to up to 1 + "), err
    surplus = float(cli[0].split("1 + ")[1].split(" ")[0])
    assert 1e-3 < surplus < 1e-1
    code, _, err = run_cli("solve", scene, "-o", tmp_path / "b.vtu", *options)
    assert code == 0, err
    assert "warning: " not in err, err
    loaded = bounce.load(str(scene), patches=216)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = bounce.solve(loaded, solver="gauss-seidel", form_factors="hemicube", hemicube_res=16, gather="none")
        assert list(sol.warnings) == []
        assert list(bounce.solve(loaded, form_factors="exact", gather="none").warnings) == []


def test_a_flipped_scene_warns_of_its_winding_in_both(tmp_path, run_cli):
    # The furnace turned round (flip) faces out: its light escapes, and both front ends say
    # the faces seem wound the wrong way, in the same words; the settings record the flip.
    scene = tmp_path / "furnace.json"
    scene.write_text(FURNACE)
    out = tmp_path / "flip.vtu"
    code, _, err = run_cli("solve", scene, "--patches", 100, "--flip", "--gather", "none", "--meshio", "-o", out)
    cli = [line[len("warning: "):] for line in err.splitlines() if line.startswith("warning: ")]
    loaded = bounce.load(str(scene), patches=100, flip=True, quiet=True)
    with pytest.warns(UserWarning, match="orientation: ") as caught:
        sol = bounce.solve(loaded, gather="none")
    assert code == (0 if sol.converged else 3), err
    assert any(w.startswith("orientation: ") for w in sol.warnings), sol.warnings
    assert list(loaded.warnings) + list(sol.warnings) == cli
    assert [str(w.message) for w in caught] == list(sol.warnings)
    assert sol.settings.endswith(" flip=1"), sol.settings
    assert sol.settings == text_field(meshio.read(out), "settings")


def test_a_preset_yields_to_the_meshing_given_to_load_and_names_itself():
    # Draft is 1000 patches and display cells: a patch count given to load() wins, and the
    # settings name the preset; the default preset is no preset at all.
    given = bounce.solve(bounce.load("cornell", patches=100), quality="draft", gather="none")
    plain = bounce.solve(bounce.load("cornell", patches=100), gather="none")
    assert given.settings == plain.settings + " quality=draft", given.settings
    assert np.array_equal(given.radiosity, plain.radiosity)
    draft = bounce.solve(bounce.load("cornell"), quality="draft", gather="none")
    assert draft.settings.startswith("patches=1131 "), draft.settings
    default = bounce.solve(bounce.load("cornell", patches=100), quality="default", gather="none")
    assert default.settings == plain.settings and np.array_equal(default.radiosity, plain.radiosity)
    with pytest.raises(ValueError, match=r"^quality: unknown, got 'best' \(expected one of draft, default, fine\)$"):
        bounce.solve(bounce.load("cornell", patches=100), quality="best")
    with pytest.raises(ValueError, match=r"^quality fine sets the patch solvers' patches"):
        bounce.solve(bounce.load("cornell"), quality="fine", adaptive=True)
