#!/usr/bin/python3
"""probe_errors.png (bounce compare --meshes): the scene's outline with every path-traced probe
coloured by the signed error of the solution there, for the patch values and for the point data
(what ParaView shows). Reads DIR/probe_errors.csv and DIR/outline.csv; does nothing without them.
Debian's python3-matplotlib."""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.colors import TwoSlopeNorm

folder = sys.argv[1]
errors_csv, outline_csv = os.path.join(folder, "probe_errors.csv"), os.path.join(folder, "outline.csv")
if not (os.path.exists(errors_csv) and os.path.exists(outline_csv)):
    sys.exit(0)
rows = list(csv.DictReader(open(errors_csv)))
outline = defaultdict(list)
for r in csv.DictReader(open(outline_csv)):
    outline[int(r["surface"])].append((float(r["x"]), float(r["y"]), float(r["z"])))

fig = plt.figure(figsize=(13, 6))
limit = 10.0  # % either way; beyond it the colour saturates
norm = TwoSlopeNorm(vmin=-limit, vcenter=0.0, vmax=limit)
mesh = rows[0]["mesh"] if rows else ""
for k, (column, title) in enumerate([("patch_error", "patch values"), ("smooth_error", "point data (as ParaView shows)")]):
    ax = fig.add_subplot(1, 2, k + 1, projection="3d")
    for poly in outline.values():
        xs = [p[0] for p in poly] + [poly[0][0]]
        ys = [p[1] for p in poly] + [poly[0][1]]
        zs = [p[2] for p in poly] + [poly[0][2]]
        # The scene's y is up; matplotlib's z is up.
        ax.plot(xs, zs, ys, color="grey", linewidth=0.6)
    e = [100 * float(r[column]) for r in rows]
    sc = ax.scatter([float(r["x"]) for r in rows], [float(r["z"]) for r in rows], [float(r["y"]) for r in rows],
                    c=e, cmap="RdBu_r", norm=norm, s=28, edgecolors="black", linewidths=0.3, depthshade=False)
    rms = (sum(v * v for v in e) / len(e)) ** 0.5 if e else 0.0
    ax.set_title(f"{title}: RMS {rms:.1f}%, worst {max((abs(v) for v in e), default=0):.0f}%")
    ax.set_xlabel("x")
    ax.set_ylabel("z")
    ax.set_zlabel("y (up)")
    ax.view_init(elev=18, azim=-100)
fig.colorbar(sc, ax=fig.axes, shrink=0.7, label="relative error of luminance against the path-traced reference, %")
fig.suptitle(f"Error at each path-traced probe, {mesh}")
out = os.path.join(folder, "probe_errors.png")
fig.savefig(out + ".tmp.png", dpi=100, bbox_inches="tight")  # the title whole
os.replace(out + ".tmp.png", out)
