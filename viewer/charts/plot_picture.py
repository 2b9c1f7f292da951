#!/usr/bin/python3
"""Chart for `bounce compare --picture` (Debian's python3-matplotlib), from DIR/picture.csv.

picture_error.png: each picture's relative RMS luminance error against the long path-traced
  image, over the pixels that show a diffuse surface (directly or through mirrors and glass),
  against its wall time: the two-pass method (radiosity, caustic photons and eye rays) and the
  path tracer given the same time, at each time budget."""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from chart_style import noise_line, plain_ticks, save, series_style, wrapped


def main(folder):
    with open(os.path.join(folder, "picture.csv")) as f:
        rows = list(csv.DictReader(f))
    fig, ax = plt.subplots(figsize=(7, 4.8), dpi=100)
    methods = []
    for r in rows:
        if r["method"] not in methods:
            methods.append(r["method"])
    for k, method in enumerate(methods):
        colour, marker = series_style(k)
        pts = sorted((float(r["seconds"]), 100 * float(r["rms_error"])) for r in rows if r["method"] == method)
        ax.plot([p[0] for p in pts], [p[1] for p in pts], color=colour, marker=marker, label=method)
        less = sorted((float(r["seconds"]), 100 * float(r["rms_error_less_noise"])) for r in rows
                      if r["method"] == method and float(r["rms_error_less_noise"]) > 0)
        if less:
            ax.plot([p[0] for p in less], [p[1] for p in less], color=colour, marker=marker, linestyle="--",
                    fillstyle="none", label=f"{method}, the reference's noise taken out")
    if rows:
        noise_line(ax, 100 * float(rows[0]["reference_noise"]))
        scene, size = rows[0]["scene"], rows[0]["size"]
    else:
        scene, size = "?", "?"
    ax.set_xscale("log")
    ax.set_yscale("log")
    plain_ticks(ax)
    ax.set_xlabel("wall time (s, 2 cores)")
    ax.set_ylabel("relative RMS luminance error (%)")
    ax.set_title(wrapped(f"{scene}, {size}: picture error against a long path-traced image, "
                         "pixels on diffuse surfaces (directly or through mirrors and glass)", 70), fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, os.path.join(folder, "picture_error.png"))


if __name__ == "__main__":
    main(sys.argv[1])
