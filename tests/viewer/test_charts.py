#!/usr/bin/python3
"""The compare charts (viewer/charts) drawn from small CSV files written here, and what they say
checked on the matplotlib figures. Run by ctest with Debian's python3: test_charts.py CHARTS_DIR."""
import atexit
import os
import shutil
import sys
import tempfile
import unittest

import matplotlib

matplotlib.use("Agg")

CHARTS = sys.argv.pop(1)
sys.path.insert(0, CHARTS)
import plot_compare  # noqa: E402
import plot_meshes  # noqa: E402

TMP = tempfile.mkdtemp(prefix="bounce-charts-")
atexit.register(shutil.rmtree, TMP, ignore_errors=True)

PROBE_COLUMNS = ("probe_rms_patch,probe_max_patch,probe_rms_smooth,probe_max_smooth,probe_rms_smooth_r,"
                 "probe_rms_smooth_g,probe_rms_smooth_b,probe_points,reference_noise")


def write_compare(folder, methods, solvers, reference="direct solution on the raycast matrix"):
    """convergence.csv and runs.csv as `bounce compare` writes them, for every method x solver."""
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "convergence.csv"), "w") as f:
        f.write("form_factors,solver,step,seconds,form_factor_seconds,residual,unshot_fraction,rms_error,"
                "max_error,ambient_rms_error\n")
        for k, ff in enumerate(methods):
            for j, s in enumerate(solvers):
                for step in range(1, 20):
                    err = 0.1 * 0.6 ** step + (0.0013 if k else 0.0) + 1e-4 * j
                    f.write(f"{ff},{s},{step},{0.01 * step},1,{err},{err},{err},{err},{err}\n")
    with open(os.path.join(folder, "runs.csv"), "w") as f:
        f.write("form_factors,solver,patches,steps,form_factor_seconds,solve_seconds,total_seconds,residual,"
                "rms_error_vs_direct," + PROBE_COLUMNS + ",error_reference\n")
        for k, ff in enumerate(methods):
            for j, s in enumerate(solvers):
                smooth = 0.0045 + 0.001 * j
                f.write(f"{ff},{s},2186,19,1,0.2,{1.2 + j + 3 * k},1e-4,1e-3,0.045,0.19,{smooth},0.06,0.01,0.01,"
                        f"0.01,128,0.0048,{reference}\n")


class ConvergenceChart(unittest.TestCase):
    def test_title_and_labels_name_what_hemicube_runs_are_scored_against(self):
        folder = os.path.join(TMP, "convergence")
        write_compare(folder, ["raycast", "hemicube"], ["shooting", "jacobi"])
        fig = plot_compare.convergence(folder)
        title = fig._suptitle.get_text()
        self.assertIn("direct solution on the raycast matrix", title)
        self.assertNotIn("its own matrix", title)
        labels = fig.axes[0].get_legend_handles_labels()[1]
        hemicube = [t for t in labels if "(hemicube)" in t]
        self.assertEqual(len(hemicube), 2, labels)
        for t in hemicube:
            self.assertIn("against the raycast answer", t)
        for t in labels:
            if "(raycast)" in t:
                self.assertNotIn("against the", t)
        self.assertTrue(os.path.exists(os.path.join(folder, "convergence.png")))

    def test_files_without_the_reference_column_name_the_first_method(self):
        folder = os.path.join(TMP, "old")
        write_compare(folder, ["hemicube", "raycast"], ["shooting"])
        with open(os.path.join(folder, "runs.csv")) as f:
            text = f.read().replace(",error_reference", "").replace(",direct solution on the raycast matrix", "")
        with open(os.path.join(folder, "runs.csv"), "w") as f:
            f.write(text)
        fig = plot_compare.convergence(folder)
        self.assertIn("direct solution on the hemicube matrix", fig._suptitle.get_text())


def drawn(fig):
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def visible_tick_values(ax, axis="y"):
    """The values of the ticks that carry a label and lie inside the axis' view."""
    a = ax.yaxis if axis == "y" else ax.xaxis
    lo, hi = sorted(a.get_view_interval())
    out = []
    for t in a.get_majorticklabels() + a.get_minorticklabels():
        v = t.get_position()[1 if axis == "y" else 0]
        if t.get_text() and lo <= v <= hi:
            out.append(v)
    return out


class Readable(unittest.TestCase):
    """Issue 35, item 11: 16 series told apart, the title inside the picture, ticks below 1%, the
    meshes' dots labelled by setting."""

    def test_sixteen_series_differ_in_colour_or_marker(self):
        folder = os.path.join(TMP, "sixteen")
        write_compare(folder, ["raycast", "hemicube"], ["shooting", "gauss-seidel", "jacobi", "direct"])
        with open(os.path.join(folder, "runs.csv")) as f:
            lines = f.read().splitlines()
        # 16 runs: the 8 above twice, named apart.
        extra = [ln.replace("raycast,", "exact,", 1).replace("hemicube,", "analytic,", 1) for ln in lines[1:]]
        with open(os.path.join(folder, "runs.csv"), "w") as f:
            f.write("\n".join(lines + extra) + "\n")
        fig = plot_compare.speed_vs_accuracy(folder)
        ax = fig.axes[0]
        styles = [(matplotlib.colors.to_hex(h.get_color()), h.get_marker())
                  for h, label in zip(*ax.get_legend_handles_labels()) if label.endswith(": point data")]
        self.assertEqual(len(styles), 16)
        self.assertEqual(len(set(styles)), 16, styles)

    def test_the_title_fits_the_figure(self):
        folder = os.path.join(TMP, "title")
        write_compare(folder, ["raycast", "hemicube"], ["shooting", "jacobi"])
        for fig in (plot_compare.speed_vs_accuracy(folder), plot_compare.convergence(folder)):
            renderer = drawn(fig)
            title = fig._suptitle if fig._suptitle else fig.axes[0].title
            box = title.get_window_extent(renderer)
            self.assertGreaterEqual(box.x0, 0, title.get_text())
            self.assertLessEqual(box.x1, fig.bbox.width, title.get_text())

    def test_ticks_below_one_percent_are_labelled(self):
        folder = os.path.join(TMP, "ticks")
        write_compare(folder, ["raycast"], ["shooting", "jacobi"])
        fig = plot_compare.speed_vs_accuracy(folder)
        drawn(fig)
        values = visible_tick_values(fig.axes[0])
        self.assertTrue(any(v < 1 for v in values), values)
        self.assertTrue(any("0.48" in t.get_text() for t in fig.axes[0].texts), "noise line not labelled")

    def test_mesh_dots_are_labelled_by_setting(self):
        folder = os.path.join(TMP, "meshes")
        os.makedirs(folder, exist_ok=True)
        with open(os.path.join(folder, "meshes.csv"), "w") as f:
            f.write("method,setting,elements,links,seconds,rms_error," + PROBE_COLUMNS + ",point_data\n")
            for n, e in ((250, 0.08), (500, 0.05), (1000, 0.03)):
                f.write(f"patches,--patches {n},{n},0,{n / 500},,0.1,0.3,{e},0.2,{e},{e},{e},128,0.0048,gathered\n")
            for eps, e in ((0.4, 0.05), (0.1, 0.01)):
                f.write(f"adaptive,link epsilon {eps} power epsilon 1e-05,5000,90000,1,,0.08,0.3,{e},0.2,{e},{e},{e},"
                        "128,0.0048,gathered\n")
        fig = plot_meshes.draw(folder)
        texts = {t.get_text() for t in fig.axes[0].texts}
        for label in ("250", "500", "1000", "e 0.4", "e 0.1"):
            self.assertIn(label, texts)
        names = fig.axes[1].get_legend_handles_labels()[1]
        self.assertIn("adaptive (solve --adaptive): point data", names)


if __name__ == "__main__":
    unittest.main(verbosity=2)
