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


if __name__ == "__main__":
    unittest.main(verbosity=2)
