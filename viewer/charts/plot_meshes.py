"""meshes.png from meshes.csv (bounce compare --meshes): RMS error against elements and seconds."""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

folder = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(folder, "meshes.csv"))))
fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.5))
for method, style in [("uniform", "o-"), ("adaptive", "s-"), ("hierarchical", "^-")]:
    pts = sorted((int(r["elements"]), float(r["seconds"]), float(r["rms_error"])) for r in rows if r["method"] == method)
    if not pts:
        continue
    a.loglog([p[0] for p in pts], [p[2] for p in pts], style, label=method)
    b.loglog([p[1] for p in pts], [p[2] for p in pts], style, label=method)
a.set_xlabel("elements")
b.set_xlabel("seconds (form factors and solve)")
for ax in (a, b):
    ax.set_ylabel("relative RMS error against the fine reference")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
ref = next((r for r in rows if r["method"] == "reference"), None)
fig.suptitle("Cornell box: error against mesh size and time" +
             (f" (reference: {ref['elements']} uniform elements)" if ref else ""))
fig.tight_layout()
out = os.path.join(folder, "meshes.png")
fig.savefig(out + ".tmp.png", dpi=110)
os.replace(out + ".tmp.png", out)
