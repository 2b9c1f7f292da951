#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Solves the Cornell box from Python with two solvers, plots how each converges and renders
the picture.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/cornell_convergence.py [OUT_DIR]

writes OUT_DIR/convergence.png (unshot fraction of shooting and relative residual of
Gauss-Seidel against time, form factors included) and OUT_DIR/cornell.png.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402

import bounce  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "."
os.makedirs(out, exist_ok=True)

scene = bounce.load("cornell", patches=1000)
print(scene)


def progress(p):
    print(f"\r{p.stage}: {p.step}/{p.total}   ", end="", file=sys.stderr, flush=True)


runs = {}
for solver in ["shooting", "gauss-seidel"]:
    sol = bounce.solve(scene, solver=solver, tolerance=1e-4, gather="none", progress=progress)
    print(f"\r{solver}: {sol.steps} steps, {sol.seconds:.2f} s, {sol.status}", file=sys.stderr)
    runs[solver] = sol

fig, ax = plt.subplots(figsize=(6, 4))
shooting = runs["shooting"].history
ax.semilogy(shooting["seconds"], shooting["unshot_fraction"], label="shooting: unshot fraction")
gs = runs["gauss-seidel"].history
# The gathering solver's clock starts after its matrix; its log seconds do not include it.
ax.semilogy(gs["seconds"], gs["residual"], "o-", label="Gauss-Seidel: relative residual")
ax.axhline(1e-4, color="grey", lw=0.8, ls="--", label="tolerance")
ax.set_xlabel("seconds (solver only)")
ax.set_ylabel("error measure")
ax.set_title(f"Cornell box, {len(scene)} patches")
ax.legend()
fig.tight_layout()
fig.savefig(os.path.join(out, "convergence.png"), dpi=120)

runs["shooting"].render(os.path.join(out, "cornell.png"), size=(400, 400))
print(f"wrote {os.path.join(out, 'convergence.png')} and {os.path.join(out, 'cornell.png')}")
