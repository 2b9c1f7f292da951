# SPDX-License-Identifier: MIT
# Bad input raises the exception that fits, with the command line's one-line message (the
# file and line included): the program prints "bounce: error: <message>" and exits with 2.
import pytest

import bounce

PREFIX = "bounce: error: "


def cli_message(run_cli, *args):
    code, _, err = run_cli(*args)
    assert code == 2, err
    lines = [line for line in err.splitlines() if line.startswith(PREFIX)]
    assert len(lines) == 1, err
    return lines[0][len(PREFIX):]


def test_missing_scene_is_file_not_found(tmp_path, run_cli):
    missing = tmp_path / "nowhere.obj"
    with pytest.raises(FileNotFoundError) as e:
        bounce.load(str(missing))
    assert str(e.value) == cli_message(run_cli, "info", missing)
    assert str(missing) in str(e.value)


@pytest.mark.parametrize(
    "text, line",
    [
        ("v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n", 3),      # a bad number
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n", 5),  # an index past the vertices
    ],
    ids=["bad-number", "bad-index"],
)
def test_bad_obj_is_value_error_with_file_and_line(tmp_path, run_cli, text, line):
    bad = tmp_path / "bad.obj"
    bad.write_text(text)
    with pytest.raises(ValueError) as e:
        bounce.load(str(bad))
    message = str(e.value)
    assert message.startswith(f"{bad}:{line}:"), message
    assert message == cli_message(run_cli, "info", bad)


def test_bad_options_are_value_errors_in_the_command_lines_words(run_cli):
    with pytest.raises(ValueError) as e:
        bounce.load("cornell", patches=0)
    cli = cli_message(run_cli, "info", "--patches", "0")
    assert cli.startswith("--patches: ")
    # The same sentence after the option's name (keyword in Python, flag on the command line).
    assert str(e.value) == cli[len("--"):].split(" (see --help)")[0]
    scene = bounce.load("cornell", patches=20)
    with pytest.raises(ValueError, match=r"solver: unknown, got 'newton' \(expected one of shooting"):
        bounce.solve(scene, solver="newton")
    with pytest.raises(ValueError, match="rays: out of range, got 0"):
        bounce.solve(scene, rays=0)
    with pytest.raises(ValueError, match="method: unknown"):
        bounce.form_factors(scene, method="radiance")
    # The receiver-only refinement adaptive ran before is retired, and so are its knobs.
    for retired in ({"target_error": 0.1}, {"max_patches": 200}):
        with pytest.raises(ValueError, match="retired: adaptive is the hierarchical solver refining on power"):
            bounce.solve(scene, adaptive=True, **retired)
    assert "now retired: --adaptive is the hierarchical solver" in cli_message(run_cli, "solve", "--target-error", "0.1")
    # The patch solvers' own options are refused by adaptive and hierarchical, as on the command line.
    for option, value in (("max_seconds", 5.0), ("sor", 1.2), ("overshoot", True), ("cache_mb", 10)):
        for kind in ({"solver": "hierarchical"}, {"adaptive": True}):
            with pytest.raises(ValueError, match=f"{option} applies to the patch solvers, not to adaptive or hierarchical"):
                bounce.solve(scene, gather="none", **kind, **{option: value})
    cli = cli_message(run_cli, "solve", "--solver", "hierarchical", "--sor", "1.2")
    assert "--sor applies to the patch solvers, not to --adaptive or hierarchical" in cli


def test_unwritable_output(tmp_path):
    sol = bounce.solve(bounce.load("cornell", patches=20), gather="none")
    out = tmp_path / "no" / "such" / "dir.vtu"
    with pytest.raises(FileNotFoundError, match="output directory .* does not exist"):
        sol.write_vtu(out)
    with pytest.raises(ValueError, match="png"):
        sol.render(tmp_path / "picture.bmp")
    assert list(tmp_path.iterdir()) == []


def test_a_json_mesh_objects_material_is_not_reported_missing(tmp_path):
    # Issue 35: the OBJ has no materials of its own, the JSON scene gives them one: no warning,
    # and strict loads it.
    (tmp_path / "open.obj").write_text(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
        "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\nf 5 6 7 8\n")
    scene = tmp_path / "s.json"
    scene.write_text('{"materials": {"w": {"reflectance": 0.3}}, '
                     '"objects": [{"type": "mesh", "file": "open.obj", "material": "w"}]}')
    s = bounce.load(str(scene), patches=50, strict=True, quiet=True)
    assert list(s.warnings) == []


def test_one_wall_wound_the_wrong_way_is_a_warning_naming_it(tmp_path):
    # Issue 34: a closed room lit by a lamp, its red wall (line 21) alone wound clockwise.
    (tmp_path / "room.mtl").write_text(
        "newmtl white\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.6 0.1 0.1\nnewmtl lamp\nKd 0 0 0\nKe 10 10 10\n")
    room = tmp_path / "room.obj"
    room.write_text(
        "mtllib room.mtl\nv 0 0 0\nv 4 0 0\nv 4 0 4\nv 0 0 4\nv 0 3 0\nv 4 3 0\nv 4 3 4\nv 0 3 4\n"
        "v 1.5 2.9 1.5\nv 2.5 2.9 1.5\nv 2.5 2.9 2.5\nv 1.5 2.9 2.5\nusemtl white\nf 1 4 3 2\nf 5 6 7 8\n"
        "f 1 2 6 5\nf 4 8 7 3\nf 2 3 7 6\nusemtl red\nf 4 8 5 1\nusemtl lamp\nf 9 10 11 12\n")
    with pytest.warns(UserWarning, match=r"orientation: .*room\.obj:21 \(default\) faces away") as caught:
        s = bounce.load(str(room), patches=100)
    assert len([w for w in caught if "orientation" in str(w.message)]) == 1
    assert len([w for w in s.warnings if "orientation" in w]) == 1
    with pytest.raises(ValueError, match=r"room\.obj:21 .*\(--strict\)"):
        bounce.load(str(room), patches=100, strict=True)
    assert list(bounce.load("cornell", patches=100, quiet=True).warnings) == []


def test_render_errors_name_the_keyword_not_the_command_line_option(tmp_path):
    # Issue 35: Python's camera error named the command line's --camera.
    sol = bounce.solve(bounce.load("cornell", patches=20), gather="none")
    for kwargs, word in (({"camera": "nowhere"}, "camera"), ({"fov": 200.0}, "fov"), ({"size": (8, 8)}, "size")):
        with pytest.raises(ValueError) as e:
            sol.render(tmp_path / "p.png", **kwargs)
        assert str(e.value).startswith(word + ":"), str(e.value)
        assert "--" not in str(e.value), str(e.value)
    assert list(tmp_path.iterdir()) == []
