#!/usr/bin/python3
"""Charts for `bounce compare`: convergence.png (error against step and against seconds, one
line per form-factor method and solver) and speed_vs_accuracy.png (final error against total
time, form factors included). Reads DIR/convergence.csv. Debian's python3-matplotlib."""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.ticker


def save(fig, path):
    tmp = path + ".tmp.png"
    fig.savefig(tmp)
    os.replace(tmp, path)


def main(folder):
    rows = list(csv.DictReader(open(os.path.join(folder, "convergence.csv"))))
    runs = defaultdict(list)
    for r in rows:
        runs[(r["form_factors"], r["solver"])].append(r)
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.8), dpi=100)
    for (ff, solver), recs in runs.items():
        pts = [(int(r["step"]), float(r["seconds"]), float(r["rms_error"])) for r in recs if r["rms_error"]]
        pts = [p for p in pts if p[2] > 0]
        if not pts:
            continue
        label = f"{solver} ({ff})"
        style = "o-" if len(pts) == 1 else "-"
        a.plot([max(p[0], 1) for p in pts], [p[2] for p in pts], style, label=label)
        b.plot([max(p[1], 1e-4) for p in pts], [p[2] for p in pts], style, label=label)
    for ax, xlabel in ((a, "step (shots or sweeps)"), (b, "seconds (solver only)")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("relative RMS error against the reference")
        ax.grid(True, which="both", alpha=0.3)
    a.legend(fontsize=8)
    fig.suptitle("Convergence")
    fig.tight_layout()
    save(fig, os.path.join(folder, "convergence.png"))

    fig, ax = plt.subplots(figsize=(7, 5), dpi=100)
    for (ff, solver), recs in runs.items():
        last = recs[-1]
        if not last["rms_error"]:
            continue
        t = float(last["seconds"]) + float(last["form_factor_seconds"])
        e = max(float(last["rms_error"]), 1e-16)
        ax.scatter([t], [e], s=40)
        ax.annotate(f"{solver} ({ff})", (t, e), fontsize=8, xytext=(4, 4), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_major_locator(matplotlib.ticker.LogLocator(subs="all"))
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%.3g"))
    ax.set_xlabel("total seconds (form factors + solve)")
    ax.set_ylabel("final relative RMS error against the reference")
    ax.set_title("Speed against accuracy (exact: plotted at 1e-16)")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    save(fig, os.path.join(folder, "speed_vs_accuracy.png"))


if __name__ == "__main__":
    main(sys.argv[1])
