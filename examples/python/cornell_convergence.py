#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Solves the Cornell box from Python with two solvers, plots how each converges and renders
the picture.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/cornell_convergence.py [OUT_DIR]

writes OUT_DIR/convergence.png (the relative residual ||E + rho F B - B|| / ||E|| of shooting
and of Gauss-Seidel against time, form factors included) and OUT_DIR/cornell.png.
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
    if sys.stderr.isatty():
        print(f"\r{p.stage}: {p.step}/{p.total}   ", end="", file=sys.stderr, flush=True)


runs = {}
for solver in ["shooting", "gauss-seidel"]:
    # residuals=True: shooting too builds the whole matrix (and then shoots with its columns),
    # so both logs carry the same measure of error.
    sol = bounce.solve(scene, solver=solver, tolerance=1e-4, gather="none", residuals=True, progress=progress)
    print(f"\r{solver}: {sol.steps} steps, {sol.seconds:.2f} s, {sol.status}   ", file=sys.stderr)
    runs[solver] = sol

fig, ax = plt.subplots(figsize=(6, 4))
for name, style in [("shooting", "-"), ("gauss-seidel", "o-")]:
    sol = runs[name]
    # The logs' clocks start after the matrix: shift them by the time it took.
    ax.semilogy(sol.history["seconds"] + sol.form_factor_seconds, sol.history["residual"], style,
                label=f"{name}: {sol.steps} {'shots' if name == 'shooting' else 'sweeps'}")
ax.set_xlabel("seconds, form factors included")
ax.set_ylabel("relative residual")
ax.set_title(f"Cornell box, {len(scene)} patches")
ax.legend()
fig.tight_layout()
fig.savefig(os.path.join(out, "convergence.png"), dpi=120)

runs["shooting"].render(os.path.join(out, "cornell.png"), size=(400, 400))
print(f"wrote {os.path.join(out, 'convergence.png')} and {os.path.join(out, 'cornell.png')}")
