# SPDX-License-Identifier: MIT
# Arrays are views of the library's storage, not copies: a 10k-patch solution's radiosity is
# the very memory the solver wrote, kept alive by the Solution object.
import numpy as np
import pytest

import bounce


@pytest.fixture(scope="module")
def scene():
    return bounce.load("cornell", patches=10000)


def assert_view(get, owner):
    a, b = get(), get()
    assert a is not b
    assert np.shares_memory(a, b), "two reads gave copies"
    assert not a.flags.owndata and not a.flags.writeable
    assert a.base is owner


def test_solution_arrays_are_views(scene):
    n = len(scene)
    assert n >= 9000
    sol = bounce.solve(scene, max_iterations=300, gather="none")
    assert sol.radiosity.shape == (n, 3)
    for name in ["radiosity", "irradiance", "unshot", "display", "point_radiosity"]:
        assert_view(lambda: getattr(sol, name), sol)
    h = sol.history
    assert np.shares_memory(h["step"], sol.history["step"])
    # A view outlives the name it came from.
    B = sol.radiosity
    expected = B.copy()
    del sol
    np.testing.assert_array_equal(B, expected)
    assert B.sum() > 0


def test_patch_arrays_are_views_of_the_patches(scene):
    p = scene.patches
    for name in ["area", "normal", "centroid", "reflectance", "emission", "surface", "corners", "vertices"]:
        assert_view(lambda: getattr(scene.patches, name), scene)
    # Strided over the patch records: the numbers must still be the right fields.
    assert p.area.sum() == pytest.approx(scene.total_area, rel=1e-12)
    np.testing.assert_allclose(np.linalg.norm(p.normal, axis=1), 1.0, rtol=1e-12)
    quads = p.vertex_count == 4
    # (The area centroid of a quad that is no parallelogram is off its corners' mean, by little.)
    off = np.linalg.norm(p.corners[quads].mean(axis=1) - p.centroid[quads], axis=1)
    assert np.all(off < 0.01 * np.sqrt(p.area[quads]))
    # faces index the vertices: each patch's corners are its mesh vertices.
    f = p.faces
    np.testing.assert_array_equal(p.vertices[f[:, 0]], p.corners[:, 0])
    assert set(np.unique(p.surface)) <= set(range(len(scene.surface_names)))
    assert np.all((p.reflectance >= 0) & (p.reflectance <= 1))
