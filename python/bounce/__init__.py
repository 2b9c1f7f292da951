# SPDX-License-Identifier: MIT
"""bounce from Python: scenes, form factors and radiosity solutions as numpy arrays.

A thin layer over the library the ``bounce`` command line uses (the extension ``_bounce``)::

    import bounce
    scene = bounce.load("cornell", patches=2000)        # or a .obj / .json path
    F = bounce.form_factors(scene, method="raycast")    # N x N float32, the library's storage
    sol = bounce.solve(scene, solver="shooting", tolerance=1e-3, progress=print)
    sol.radiosity                                       # N x 3, W/m^2 per channel (a view)
    sol.write_vtu("cornell.vtu"); sol.render("cornell.png")
    ref = bounce.reference(scene, probes=64)            # path-traced B at 64 points, with errors

Long calls release the GIL and stop on Ctrl-C (KeyboardInterrupt; nothing is returned or
written). Bad input raises ValueError, a missing file FileNotFoundError, each with the command
line's one-line message (file and line included).
"""

import warnings as _warnings

from ._bounce import (  # noqa: F401
    Patches,
    Progress,
    Scene,
    Solution,
    __version__,
    check_form_factors,
    form_factor_methods,
    form_factors,
    gather_modes,
    reference,
    solver_names,
    visibility_backends,
)
from ._bounce import load as _load
from ._bounce import solve as _solve

__all__ = [
    "Patches", "Progress", "Scene", "Solution", "SolveRequest", "check_form_factors", "form_factor_methods",
    "form_factors", "gather_modes", "load", "reference", "solve", "solver_names", "visibility_backends",
]


def load(scene="cornell", *, patches=None, max_area=0.0, max_edge=0.0, subdivide=True,
         contact_cuts=True, flip=False, strict=False, visibility=None, quiet=False):
    """Loads a scene ("cornell", a .obj, .json, .ply or .off path) and cuts it into patches.

    patches: about this many (2000 unless given) when neither max_area nor max_edge (scene units)
    is given; with none of the three, solve(..., quality=) cuts the scene at its preset's count.
    contact_cuts: leave out what no light reaches (a floor under a block). flip: turn every
    face round. strict: a repaired input problem is an error. The repairs are issued as Python
    warnings unless quiet (they stay in ``scene.warnings``).
    """
    if visibility is None:
        visibility = visibility_backends()[0]
    s = _load(scene, patches=patches, max_area=max_area, max_edge=max_edge, subdivide=subdivide,
              contact_cuts=contact_cuts, flip=flip, strict=strict, visibility=visibility)
    if not quiet:
        for w in s.warnings:
            _warnings.warn(w, stacklevel=2)
    return s


class SolveRequest:
    """The keywords of :func:`solve` as one object, to keep and reuse::

        req = bounce.SolveRequest(solver="hierarchical", max_level=2)
        sol = bounce.solve(scene, req)                 # or solve(scene, req, gather="none")
        fine = bounce.solve(scene, req.replace(max_level=4))

    The names and values are checked when it is solved, with the command line's messages.
    """

    def __init__(self, **options):
        self.options = dict(options)

    def replace(self, **options):
        """A copy with these keywords changed or added."""
        return SolveRequest(**{**self.options, **options})

    def __eq__(self, other):
        return isinstance(other, SolveRequest) and self.options == other.options

    def __repr__(self):
        return "SolveRequest(" + ", ".join(f"{k}={v!r}" for k, v in self.options.items()) + ")"


def solve(scene, request=None, *, quiet=False, **options):
    """Radiosity of a loaded scene, as ``bounce solve`` computes it (one pipeline for both).

    The keywords are the command line's flags; see ``help(bounce._bounce.solve)``. A
    SolveRequest gives them as one object (keywords given beside it win). The solution's
    warnings (``sol.warnings``: rows of form factors above 1, faces wound the wrong way round)
    are issued as Python warnings unless quiet.
    """
    if request is not None:
        if not isinstance(request, SolveRequest):
            raise TypeError(f"solve: request must be a bounce.SolveRequest, got {type(request).__name__}")
        options = {**request.options, **options}
    sol = _solve(scene, **options)
    if not quiet:
        for w in sol.warnings:
            _warnings.warn(w, stacklevel=2)
    return sol


solve.__doc__ += "\n" + (_solve.__doc__ or "")


def _to_meshio(self):
    """The solution as a meshio.Mesh: one cell per patch (or display cell), in one block per
    cell type (triangles, quads, then polygons by their number of corners), with the cell data
    radiosity, irradiance, emission, reflectance, area, surface and patch (each cell's row in
    the solution's arrays, which keep the patch order), and the point data radiosity
    (gathered or averaged, as in the .vtu)."""
    import meshio
    import numpy as np

    p = self.patches
    faces = p.faces
    counts = (faces >= 0).sum(axis=1)
    per_cell = {
        "radiosity": self.radiosity,
        "irradiance": self.irradiance,
        "emission": p.emission,
        "reflectance": p.reflectance,
        "area": p.area,
        "surface": p.surface,
    }
    # meshio keeps cells in blocks of one type and size: one block each, not one per run of
    # consecutive patches (the Cornell box alternated triangles and quads in 45 blocks).
    cells, cell_data = [], {k: [] for k in [*per_cell, "patch"]}
    for k in np.unique(counts):
        rows = np.flatnonzero(counts == k)
        cells.append(({3: "triangle", 4: "quad"}.get(int(k), "polygon"), faces[rows, :k]))
        for name, values in per_cell.items():
            cell_data[name].append(np.asarray(values)[rows])
        cell_data["patch"].append(rows)
    return meshio.Mesh(np.asarray(p.vertices), cells,
                       point_data={"radiosity": np.asarray(self.point_radiosity)},
                       cell_data=cell_data)


Solution.to_meshio = _to_meshio
