#!/usr/bin/python3
"""Chart of form_factor_accuracy.csv: relative error against time, log-log, one series per
method. Run with Debian's python3 (matplotlib from python3-matplotlib)."""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

src, dst = sys.argv[1], sys.argv[2]
rows = list(csv.DictReader(open(src)))
fig, ax = plt.subplots(figsize=(8, 5.5), dpi=110)
markers = {"raycast": "o", "analytic": "s", "exact": "P", "raycast-point": "^", "hemicube": "D"}
for method in ["raycast", "analytic", "exact", "raycast-point", "hemicube"]:
    pts = [(max(float(r["seconds"]), 1e-7), max(float(r["relative_error"]), 1e-12)) for r in rows if r["method"] == method]
    if pts:
        ax.scatter(*zip(*pts), label=method, marker=markers[method], alpha=0.6, s=22)
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel("time to compute F between the two surfaces (s, median of 3)")
ax.set_ylabel("relative error against the closed form")
ax.set_title("Form factors: error against time, all validation cases and settings")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
fig.tight_layout()
tmp = dst + ".tmp.png"
fig.savefig(tmp)
import os

os.replace(tmp, dst)
