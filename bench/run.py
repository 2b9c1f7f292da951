#!/usr/bin/python3
"""Runs bounce's benchmarks and writes results.csv and results.png.

Micro benchmarks (Google Benchmark, medians of repeats): shadow rays per second of each
visibility backend on the same rays, form-factor rows per second of each method, shots per
second from known rows, and the default Cornell-box solve on 1 and 2 threads.
End-to-end: `bounce solve` on the Cornell box at several patch counts, to 1e-3 unshot fraction
(or residual), with wall time and peak memory (/usr/bin/time), and the fitted exponent of
time against patches for each solver and form-factor method.

    bench/run.py            full mode (1k-64k patches; about 15 minutes on 2 cores)
    bench/run.py --short    small sizes, one repeat: what CI runs so the script never rots
"""
import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# (series, solver, method, extra args, patch counts in full mode, in short mode). "elements"
# series give the patch count as elements (K x K per shooting patch).
E2E = [
    ("shooting, raycast", "shooting", "raycast", [], [1000, 4000, 16000], [250, 1000]),
    ("shooting, raycast, patches -> 8x8 elements", "shooting", "raycast", ["--elements", "8"],
     [4000, 16000, 64000], [1000, 4000]),
    ("shooting, analytic (no occlusion)", "shooting", "analytic", [], [1000, 4000, 16000], [250]),
    ("shooting, hemicube", "shooting", "hemicube", [], [1000, 4000], [250]),
    ("gauss-seidel, raycast matrix", "gauss-seidel", "raycast", [], [1000, 4000, 16000], [250, 1000]),
    ("jacobi, raycast matrix", "jacobi", "raycast", [], [1000, 4000], [250]),
    ("direct LU, raycast matrix", "direct", "raycast", [], [1000, 4000], [250]),
]


def run_gbench(exe, short, patches):
    reps = 1 if short else 5
    args = [exe, "--benchmark_format=json", f"--benchmark_repetitions={reps}",
            f"--benchmark_min_time={0.01 if short else 0.5}"]
    if reps > 1:
        args.append("--benchmark_report_aggregates_only=true")
    env = dict(os.environ, BOUNCE_BENCH_PATCHES=str(patches))
    out = subprocess.run(args, check=True, capture_output=True, text=True, env=env).stdout
    rows = {}
    for b in json.loads(out)["benchmarks"]:
        if reps > 1 and b.get("aggregate_name") != "median":
            continue
        rows[b["run_name"]] = b
    return rows


def solve(bounce, series, solver, method, extra, patches, tmp):
    elements = "--elements" in extra
    split = int(extra[extra.index("--elements") + 1]) if elements else 1
    out = os.path.join(tmp, "bench.vtu")
    cmd = ["/usr/bin/time", "-f", "TIME %e %M", bounce, "solve", "--patches", str(max(1, patches // (split * split))),
           "--solver", solver, "--form-factors", method, "--max-matrix-mb", "4096", "-o", out] + extra
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"bench: {' '.join(cmd[3:])} failed ({p.returncode}):\n{p.stderr}")
    wall, peak_kb = re.search(r"TIME ([0-9.]+) ([0-9]+)", p.stderr).groups()
    m = re.search(r"patches (\d+)(?:, elements (\d+))?(?: \(\d+ display cells\))?, \S+ (\d+) (shots|sweeps).*?([0-9.e+-]+) s[ \n]",
                  p.stdout)
    if not m:
        raise SystemExit(f"bench: cannot read the summary of {' '.join(cmd[3:])}:\n{p.stdout}")
    n_patches, n_elements, steps, _, solve_s = m.groups()
    n = int(n_elements or n_patches)
    return {"group": "end-to-end", "name": series, "patches": n_patches, "elements": n, "threads": os.cpu_count(),
            "seconds": float(wall), "solve_seconds": float(solve_s), "peak_mb": round(int(peak_kb) / 1024, 1),
            "steps": int(steps), "rate": "", "unit": "s to 1e-3"}


def fit_exponent(xs, ys):
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    sxx = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sxx if sxx > 0 else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--short", action="store_true", help="small sizes, one repeat (CI)")
    ap.add_argument("--out", default=os.path.join(ROOT, "bench"), help="where results.csv and results.png go")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"), help="the build directory")
    ap.add_argument("--bounce", help="the bounce program (default: BUILD/app/bounce)")
    a = ap.parse_args()
    bounce = a.bounce or os.path.join(a.build, "app", "bounce")
    os.makedirs(a.out, exist_ok=True)
    micro_patches = 300 if a.short else 2000
    rows = []

    def micro(name, value, unit, patches, extra=None):
        r = {"group": "micro", "name": name, "patches": patches, "elements": patches, "threads": "",
             "seconds": "", "solve_seconds": "", "peak_mb": "", "steps": "", "rate": value, "unit": unit}
        r.update(extra or {})
        rows.append(r)

    vis = run_gbench(os.path.join(a.build, "bench", "bench_visibility"), a.short, micro_patches)
    for key, name in [("BM_Rays/cgal/real_time", "shadow rays, cgal"), ("BM_Rays/embree/real_time", "shadow rays, embree"),
                      ("BM_Rays/embree_packets/real_time", "shadow rays, embree packets of 4")]:
        micro(name, vis[key]["items_per_second"], "rays/s (1 thread)", int(vis[key]["patches"]), {"threads": 1})
    blocked = {k: round(v["blocked_fraction"], 9) for k, v in vis.items() if k.startswith("BM_Rays/")}
    if len(set(blocked.values())) != 1:
        raise SystemExit(f"bench: the backends disagree on the same rays: {blocked}")
    # The contact cuts' enclosure rays, through the exact tree and through Embree.
    for key, name in [("BM_FirstHits<SurfaceTree>/real_time", "enclosure rays, exact tree"),
                      ("BM_FirstHits<SurfaceRays>/real_time", "enclosure rays, embree")]:
        micro(name, vis[key]["items_per_second"], "rays/s (1 thread)", micro_patches, {"threads": 1})
    met = {k: round(v["met_fraction"], 9) for k, v in vis.items() if k.startswith("BM_FirstHits")}
    if len(set(met.values())) != 1:
        raise SystemExit(f"bench: the enclosure rays' trees disagree: {met}")
    # The contact cuts' box queries: CGAL's exact listing against SurfaceTree's.
    for key, name in [("BM_BoxQueries<ExactBoxTree>/real_time", "box queries, exact test of each triangle"),
                      ("BM_BoxQueries<SurfaceTree>/real_time", "box queries, bounding boxes first")]:
        micro(name, vis[key]["items_per_second"], "queries/s (1 thread)", 20000, {"threads": 1})
    found = {k: v["found"] for k, v in vis.items() if k.startswith("BM_BoxQueries")}
    if len(set(found.values())) != 1:
        raise SystemExit(f"bench: the box queries disagree: {found}")

    ff = run_gbench(os.path.join(a.build, "bench", "bench_form_factors"), a.short, micro_patches)
    for method in ["raycast_embree", "raycast_cgal", "analytic", "hemicube"]:
        b = ff[f"BM_Rows/{method}/real_time"]
        micro(f"form-factor rows, {method.replace('_', ', ')}", b["items_per_second"], "rows/s", int(b["patches"]),
              {"threads": os.cpu_count()})

    # The closed-scene cases the form-factor issue compares with View3D (single-threaded there:
    # 0.28-0.42 s for the empty cube, 3.6 s for the blocker cut 16 x 16).
    for prefix, name, counter, threads in [
            ("BM_EmptyCube20/raycast", "empty 20x20 cube matrix, raycast", "worst_row_error", 1),
            ("BM_EmptyCube20/exact", "empty 20x20 cube matrix, exact", "worst_row_error", 1),
            ("BM_AsymmetricBlocker16/raycast", "asymmetric blocker cut 16x16, raycast", "error", os.cpu_count()),
            ("BM_AsymmetricBlocker16/exact", "asymmetric blocker cut 16x16, exact", "error", os.cpu_count())]:
        b = next(v for k, v in ff.items() if k.startswith(prefix))
        micro(f"{name} (error {b[counter]:.2g})", b["real_time"] / 1e3, "s", "", {"threads": threads,
              "seconds": b["real_time"] / 1e3})

    sh = run_gbench(os.path.join(a.build, "bench", "bench_shooting"), a.short, micro_patches)
    b = sh["BM_ShotsFromKnownRows/real_time"]
    micro("shots from known rows", b["items_per_second"], "shots/s", int(b["patches"]), {"threads": 1})
    t1 = sh["BM_CornellSolve/1/real_time"]["real_time"] / 1e3
    t2 = sh["BM_CornellSolve/2/real_time"]["real_time"] / 1e3
    for t, threads in [(t1, 1), (t2, 2)]:
        micro(f"Cornell solve to 1e-3, {threads} thread{'s' if threads > 1 else ''}", t, "s",
              int(sh["BM_CornellSolve/1/real_time"]["patches"]),
              {"threads": threads, "seconds": t, "steps": int(sh["BM_CornellSolve/1/real_time"]["shots"])})

    hr = run_gbench(os.path.join(a.build, "bench", "bench_hierarchical"), a.short, micro_patches)
    h1 = hr["BM_HierarchicalCornell/1/real_time"]
    for threads in (1, 2):
        b = hr[f"BM_HierarchicalCornell/{threads}/real_time"]
        if (b["elements"], b["links"]) != (h1["elements"], h1["links"]):
            raise SystemExit("bench: hierarchical refinement made other elements or links on another thread count")
        micro(f"hierarchical Cornell solve (link epsilon 0.2, max level {int(b['max_level'])}), {threads} thread"
              f"{'s' if threads > 1 else ''}", b["real_time"] / 1e3, "s", int(b["patches"]),
              {"threads": threads, "seconds": b["real_time"] / 1e3, "elements": int(b["elements"]),
               "steps": int(b["links"])})

    plain = hr["BM_HierarchicalPointData/0/real_time"]
    shown = hr["BM_HierarchicalPointData/1/real_time"]
    if shown["vertices"] <= plain["vertices"]:
        raise SystemExit("bench: display refinement gathered no new vertices")
    for b, what in ((plain, "without"), (shown, "with")):
        micro(f"hierarchical Cornell point data {what} display refinement ({int(b['elements'])} elements, "
              f"{int(b['cells'])} cells, {int(b['vertices'])} vertices; {shown['real_time'] / plain['real_time']:.2f}x)",
              b["real_time"] / 1e3, "s", int(b["elements"]),
              {"threads": os.cpu_count(), "seconds": b["real_time"] / 1e3, "elements": int(b["cells"])})

    ref = run_gbench(os.path.join(a.build, "bench", "bench_reference"), a.short, micro_patches)
    for threads in (1, 2):
        b = ref[f"BM_ReferencePaths/{threads}/real_time"]
        micro(f"path-traced reference, {threads} thread{'s' if threads > 1 else ''}", b["items_per_second"],
              "paths/s", "", {"threads": threads})
    b = ref["BM_DefaultRun/real_time"]
    micro("default Cornell run (mesh, form factors, shooting, gather), 2 threads", b["real_time"] / 1e3, "s",
          int(b["patches"]), {"threads": 2, "seconds": b["real_time"] / 1e3, "steps": int(b["shots"])})
    b = ref["BM_Reference100ProbesTo1Percent/real_time"]
    micro("path-traced reference: 100 probes to 1%", b["real_time"] / 1e3, "s", "",
          {"threads": 2, "seconds": b["real_time"] / 1e3, "steps": round(b["paths_per_probe"])})

    with tempfile.TemporaryDirectory() as tmp:
        for series, solver, method, extra, full, short in E2E:
            for n in (short if a.short else full):
                r = solve(bounce, series, solver, method, extra, n, tmp)
                print(f"{series:45s} {r['elements']:>7} {r['seconds']:8.2f} s {r['peak_mb']:8.1f} MB", flush=True)
                rows.append(r)

    fits, solve_fits = {}, {}
    for series, *_ in E2E:
        pts = [(r["elements"], r["seconds"]) for r in rows if r["group"] == "end-to-end" and r["name"] == series]
        if len(pts) >= 2:
            fits[series] = fit_exponent([p[0] for p in pts], [p[1] for p in pts])
            # The same fit on the solver's own time (form factors and solve, no start-up or
            # file writing), which small sizes would otherwise flatten.
            solve_k = fit_exponent([r["elements"] for r in rows if r["group"] == "end-to-end" and r["name"] == series],
                                   [max(r["solve_seconds"], 1e-6) for r in rows
                                    if r["group"] == "end-to-end" and r["name"] == series])
            solve_fits[series] = solve_k
            rows.append({"group": "fit", "name": series, "patches": "", "elements": "", "threads": "", "seconds": "",
                         "solve_seconds": "", "peak_mb": "", "steps": "", "rate": round(fits[series], 3),
                         "unit": "exponent of wall seconds ~ N^k"})
            rows.append({"group": "fit", "name": series, "patches": "", "elements": "", "threads": "", "seconds": "",
                         "solve_seconds": "", "peak_mb": "", "steps": "", "rate": round(solve_k, 3),
                         "unit": "exponent of solve seconds ~ N^k"})

    fields = ["group", "name", "patches", "elements", "threads", "seconds", "solve_seconds", "peak_mb", "steps",
              "rate", "unit"]
    csv_path = os.path.join(a.out, "results.csv")
    with open(csv_path + ".tmp", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{r[k]:.6g}" if isinstance(r[k], float) else r[k]) for k in fields})
    os.replace(csv_path + ".tmp", csv_path)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for series, *_ in E2E:
        pts = sorted((r["elements"], r["seconds"]) for r in rows if r["group"] == "end-to-end" and r["name"] == series)
        if pts:
            label = series + (f"  (k = {fits[series]:.2f})" if series in fits else "")
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=label)
    ax.set_xlabel("patches (elements for the patches -> elements series)")
    ax.set_ylabel("end-to-end seconds to 1e-3 (wall, 2 cores)")
    ax.set_title("bounce on the Cornell box: time ~ N^k" + (" (short mode)" if a.short else ""))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    png = os.path.join(a.out, "results.png")
    fig.savefig(png + ".tmp.png", dpi=110)
    os.replace(png + ".tmp.png", png)

    print(f"\nwrote {csv_path} and {png}")
    for series, k in fits.items():
        print(f"fitted exponent  {series:45s} k = {k:.2f} (wall), {solve_fits[series]:.2f} (solve)")
    ratio = lambda n, d: next(r["rate"] for r in rows if r["name"] == n) / next(r["rate"] for r in rows if r["name"] == d)
    print(f"embree / cgal shadow rays: {ratio('shadow rays, embree packets of 4', 'shadow rays, cgal'):.1f}x; "
          f"raycast rows embree / cgal: {ratio('form-factor rows, raycast, embree', 'form-factor rows, raycast, cgal'):.1f}x; "
          f"Cornell solve 2 threads / 1 thread speed-up: {t1 / t2:.2f}x")
    p1 = ref["BM_ReferencePaths/1/real_time"]["items_per_second"]
    print(f"path-traced reference: {p1 / 1e3:.0f}k paths/s per core ({p1 / 150e3:.1f}x the 150k anchor), "
          f"100 probes to 1% in {b['real_time'] / 1e3:.2f} s on 2 threads")
    return 0


if __name__ == "__main__":
    sys.exit(main())
