#!/usr/bin/python3
"""Charts for `bounce compare` (Debian's python3-matplotlib), from DIR/convergence.csv and DIR/runs.csv.

convergence.png: solver convergence, i.e. each solver's error against one reference, the direct solution
  on the first --form-factors method's matrix (runs.csv's error_reference), by step and by seconds. For
  runs on that matrix it says how fast a solver reaches its matrix's answer; runs on another matrix
  (hemicube, by default) flatten at the difference between the two matrices' answers. Neither says how
  close an answer is to the light of a real box.
speed_vs_accuracy.png: total wall time (form factors + solve) against the error at the path-traced
  probes (bounce reference): the distance to the continuous radiosity equation."""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from chart_style import noise_line, plain_ticks, save, series_style, wrapped


def read_rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def error_reference(folder, rows):
    """What the convergence errors are measured against: runs.csv's error_reference, or (files written
    before that column) the direct solution on the first run's matrix, which is how compare picks it.
    Returns (its description, the form-factor method of its matrix)."""
    first = rows[0]["form_factors"] if rows else "?"
    path = os.path.join(folder, "runs.csv")
    if os.path.exists(path):
        runs = read_rows(path)
        if runs and runs[0].get("error_reference"):
            return runs[0]["error_reference"], first
    return f"direct solution on the {first} matrix", first


def convergence(folder):
    rows = read_rows(os.path.join(folder, "convergence.csv"))
    reference, reference_ff = error_reference(folder, rows)
    runs = defaultdict(list)
    for r in rows:
        runs[(r["form_factors"], r["solver"])].append(r)
    positive = [float(r["rms_error"]) for r in rows if r["rms_error"] and float(r["rms_error"]) > 0]
    floor = min(positive) / 10 if positive else 1e-12
    fig, (a, b) = plt.subplots(1, 2, figsize=(13, 4.8), dpi=100)
    for k, ((ff, solver), recs) in enumerate(runs.items()):
        colour, marker = series_style(k)
        pts = [(int(r["step"]), float(r["seconds"]), float(r["rms_error"])) for r in recs if r["rms_error"]]
        if not pts:
            continue
        label = f"{solver} ({ff})"
        if ff != reference_ff:
            label += f": against the {reference_ff} answer"
        if all(p[2] == 0 for p in pts):
            # The direct solution is the reference itself: exact for its matrix. Marked on the floor of
            # the axis with its own symbol, not plotted at a fake error.
            label += ": exact for its matrix (on the floor)"
            for ax, x in ((a, max(pts[-1][0], 1)), (b, max(pts[-1][1], 1e-4))):
                ax.plot([x], [floor], marker="*", markersize=14, linestyle="none", color=colour, label=label)
            continue
        pts = [p for p in pts if p[2] > 0]
        a.plot([max(p[0], 1) for p in pts], [p[2] for p in pts], "-", marker=marker,
               markevery=max(1, len(pts) // 8), color=colour, label=label)
        b.plot([max(p[1], 1e-4) for p in pts], [p[2] for p in pts], "-", marker=marker,
               markevery=max(1, len(pts) // 8), color=colour, label=label)
    for ax, xlabel in ((a, "step (shots or sweeps)"), (b, "solver seconds (form factors not included)")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"relative RMS error against the\n{reference} (dimensionless)")
        ax.grid(True, which="both", alpha=0.3)
    # Beside the charts, not over the curves.
    b.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.suptitle(wrapped(f"Solver convergence against the {reference}\n(runs on other form factors end at "
                         "the difference between the matrices' answers)"))
    fig.tight_layout()
    save(fig, os.path.join(folder, "convergence.png"))
    return fig


def speed_vs_accuracy(folder):
    path = os.path.join(folder, "runs.csv")
    if not os.path.exists(path):
        return
    rows = read_rows(path)
    fig, ax = plt.subplots(figsize=(8, 5.5), dpi=100)
    for k, r in enumerate(rows):
        colour, marker = series_style(k)
        t = float(r["total_seconds"])
        label = f"{r['solver']} ({r['form_factors']})"
        # Filled: point data; hollow, the same colour and marker: patch values.
        ax.plot([t], [float(r["probe_rms_smooth"]) * 100], marker, color=colour, markersize=8,
                label=label + ": point data")
        ax.plot([t], [float(r["probe_rms_patch"]) * 100], marker, color=colour, markersize=8, fillstyle="none",
                label=label + ": patch values")
    noise = [float(r["reference_noise"]) * 100 for r in rows if r["reference_noise"]]
    if noise:
        noise_line(ax, max(noise), linestyle="--")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("total wall time, s (form factors + solve)")
    ax.set_ylabel("RMS relative luminance error at the probes, %")
    patches = rows[0]["patches"] if rows else "?"
    ax.set_title(wrapped(f"Speed against accuracy, {patches} patches, against "
                         f"{rows[0]['probe_points'] if rows else 0} path-traced probes (filled: point data; "
                         "hollow: patch values)", 60))
    ax.grid(True, which="both", alpha=0.3)
    plain_ticks(ax)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.tight_layout()
    save(fig, os.path.join(folder, "speed_vs_accuracy.png"))
    return fig


def main(folder):
    convergence(folder)
    speed_vs_accuracy(folder)


if __name__ == "__main__":
    main(sys.argv[1])
