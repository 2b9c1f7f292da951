#!/usr/bin/python3
"""meshes.png from meshes.csv (bounce compare --meshes): the error at the path-traced probes against
elements and against total wall time, one line per method; point data (what ParaView shows) solid,
patch values dashed; the reference's own noise as a floor. Debian's python3-matplotlib."""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from chart_style import plain_ticks

folder = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(folder, "meshes.csv"))))
fig, (a, b) = plt.subplots(1, 2, figsize=(13, 5))
cmap = plt.get_cmap("viridis")
methods = [("patches", "o", "uniform patches (every patch shoots)"),
           ("discontinuity", "v", "discontinuity meshes (every patch shoots)"),
           ("uniform", "s", "uniform elements (coarse patches shoot)"),
           ("receiver", "D", "receiver-only refinement (retired --adaptive)"),
           ("adaptive", "X", "adaptive (solve --adaptive)"),
           ("adaptive display", "h", "adaptive, display refinement"),
           ("hierarchical", "^", "hierarchical"),
           ("hierarchical display", "P", "hierarchical, display refinement")]


def series(row):
    """The chart line of a row: hierarchical and adaptive rows with display refinement apart from those
    without."""
    return row["method"] + (" display" if " display " in row["setting"] else "")


for k, (method, marker, name) in enumerate(methods):
    pts = sorted((int(r["elements"]), float(r["seconds"]), float(r["probe_rms_smooth"]) * 100,
                  float(r["probe_rms_patch"]) * 100, r.get("point_data", "averaged") == "gathered")
                 for r in rows if series(r) == method)
    if not pts:
        continue
    colour = cmap(0.85 * k / (len(methods) - 1))
    for ax, x in ((a, 0), (b, 1)):
        g = [p for p in pts if p[4]]
        ax.loglog([p[x] for p in g], [p[2] for p in g], "-", marker=marker, color=colour,
                  label=name + ": point data")
        avg = [p for p in pts if not p[4]]
        if avg:
            ax.loglog([p[x] for p in avg], [p[2] for p in avg], "x", color=colour, markersize=9,
                      label=name + ": point data averaged (too large to gather)")
        ax.loglog([p[x] for p in pts], [p[3] for p in pts], "--", marker=marker, fillstyle="none", color=colour,
                  label=name + ": patch values")
ref = next((r for r in rows if r["method"] == "reference"), None)
if ref:
    for ax, x in ((a, float(ref["elements"])), (b, float(ref["seconds"]))):
        ax.plot([x], [float(ref["probe_rms_smooth"]) * 100], "*", color="black", markersize=12,
                label=f"fine uniform elements ({ref['elements']})")
noise = [float(r["reference_noise"]) * 100 for r in rows if r.get("reference_noise")]
for ax in (a, b):
    if noise:
        ax.axhline(max(noise), color="grey", linestyle=":", label="noise of the path-traced reference")
    ax.set_ylabel("RMS relative luminance error at the probes, %")
    ax.grid(True, which="both", alpha=0.3)
    plain_ticks(ax)
a.set_xlabel("elements (patches)")
b.set_xlabel("total wall time, s (form factors + solve)")
b.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
probes = rows[0]["probe_points"] if rows else "?"
fig.suptitle(f"Error against mesh size and time, scored at {probes} path-traced probes")
fig.tight_layout()
out = os.path.join(folder, "meshes.png")
fig.savefig(out + ".tmp.png", dpi=110)
os.replace(out + ".tmp.png", out)
