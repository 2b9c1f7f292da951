#!/usr/bin/python3
"""meshes.png from meshes.csv (bounce compare --meshes): the error at the path-traced probes against
elements and against total wall time, one line per method; point data (what ParaView shows) solid,
patch values dashed; every point-data dot labelled with its setting; the reference's own noise as a
floor. Debian's python3-matplotlib."""
import csv
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from chart_style import noise_line, plain_ticks, save, series_style, wrapped

METHODS = [("patches", "uniform patches (every patch shoots)"),
           ("discontinuity", "discontinuity meshes (every patch shoots)"),
           ("uniform", "uniform elements (coarse patches shoot)"),
           ("receiver", "receiver-only refinement (retired --adaptive)"),
           ("adaptive", "adaptive (solve --adaptive)"),
           ("adaptive display", "adaptive, display refinement"),
           ("hierarchical", "hierarchical"),
           ("hierarchical display", "hierarchical, display refinement")]


def series(row):
    """The chart line of a row: hierarchical and adaptive rows with display refinement apart from those
    without."""
    return row["method"] + (" display" if " display " in row["setting"] else "")


def short_setting(row):
    """The label of a dot: what distinguishes it within its line ("250", "L2", "t 0.1", "e 0.4")."""
    s = row["setting"]
    if row["method"] in ("patches", "discontinuity"):
        return s.replace("--patches ", "")
    if row["method"] == "uniform":
        return s.replace("level ", "L")
    if row["method"] == "receiver":
        return s.replace("target ", "t ")
    label = s.replace("link epsilon ", "e ")
    if row["method"] == "adaptive":  # its power epsilon is always solve --adaptive's
        label = re.sub(r" power epsilon \S+", "", label)
    return label.replace(" power epsilon ", ", p ").replace(" display ", ", d ")


def draw(folder):
    with open(os.path.join(folder, "meshes.csv")) as f:
        rows = list(csv.DictReader(f))
    fig, (a, b) = plt.subplots(1, 2, figsize=(13, 5))
    for k, (method, name) in enumerate(METHODS):
        pts = sorted((int(r["elements"]), float(r["seconds"]), float(r["probe_rms_smooth"]) * 100,
                      float(r["probe_rms_patch"]) * 100, r.get("point_data", "averaged") == "gathered",
                      short_setting(r))
                     for r in rows if series(r) == method)
        if not pts:
            continue
        colour, marker = series_style(k)
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
            for p in pts:
                ax.annotate(p[5], (p[x], p[2]), xytext=(3, -9), textcoords="offset points", fontsize=6, color=colour)
    ref = next((r for r in rows if r["method"] == "reference"), None)
    if ref:
        for ax, x in ((a, float(ref["elements"])), (b, float(ref["seconds"]))):
            ax.plot([x], [float(ref["probe_rms_smooth"]) * 100], "*", color="black", markersize=12,
                    label=f"fine uniform elements ({ref['elements']})")
    noise = [float(r["reference_noise"]) * 100 for r in rows if r.get("reference_noise")]
    for ax in (a, b):
        if noise:
            noise_line(ax, max(noise))
        ax.set_ylabel("RMS relative luminance error at the probes, %")
        ax.grid(True, which="both", alpha=0.3)
        plain_ticks(ax)
    a.set_xlabel("elements (patches)")
    b.set_xlabel("total wall time, s (form factors + solve)")
    b.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    probes = rows[0]["probe_points"] if rows else "?"
    fig.suptitle(wrapped(f"Error against mesh size and time, scored at {probes} path-traced probes "
                         "(dots labelled by setting: patches, level L, target t, link epsilon e)", 100))
    fig.tight_layout()
    save(fig, os.path.join(folder, "meshes.png"), dpi=110)
    return fig


if __name__ == "__main__":
    draw(sys.argv[1])
