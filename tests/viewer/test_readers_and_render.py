#!/usr/bin/python3
"""The real program's files read by independent readers (meshio, VTK's own), and its pictures
decoded and measured. Run by ctest with Debian's python3: test_readers_and_render.py BOUNCE_EXE."""
import atexit
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

import matplotlib.image
import meshio
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

EXE = sys.argv.pop(1)
TMP = tempfile.mkdtemp(prefix="bounce-viewer-")
atexit.register(shutil.rmtree, TMP, ignore_errors=True)


def bounce(*args):
    return subprocess.run([EXE, *args], capture_output=True, text=True, timeout=600)


def vtk_read(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def meshio_cells_and_radiosity(path):
    m = meshio.read(path)
    count = sum(len(block.data) for block in m.cells)
    radiosity = np.concatenate(m.cell_data["radiosity"])
    return count, radiosity, m


class Files(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.vtu = os.path.join(TMP, "box.vtu")
        r = bounce("solve", "--max-area", "4000", "--series", "500", "-q", "-o", cls.vtu)
        assert r.returncode == 0, r.stderr

    def test_meshio_and_vtk_read_the_same_cells_and_values(self):
        count, radiosity, m = meshio_cells_and_radiosity(self.vtu)
        g = vtk_read(self.vtu)
        self.assertEqual(count, g.GetNumberOfCells())
        ref = vtk_to_numpy(g.GetCellData().GetArray("radiosity"))
        self.assertEqual(radiosity.shape, ref.shape)
        np.testing.assert_array_equal(radiosity, ref)
        # The luminance array is Rec. 709 of the radiosity.
        lum = np.concatenate(m.cell_data["luminance"])
        np.testing.assert_allclose(lum, ref @ np.array([0.2126, 0.7152, 0.0722]), rtol=1e-12)
        self.assertIn("radiosity", m.point_data)

    def test_ascii_output_reads_the_same(self):
        ascii_vtu = os.path.join(TMP, "ascii.vtu")
        r = bounce("solve", "--max-area", "4000", "-q", "--ascii", "-o", ascii_vtu)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(ascii_vtu) as f:
            self.assertIn('format="ascii"', f.read())
        _, a, _ = meshio_cells_and_radiosity(ascii_vtu)
        _, b, _ = meshio_cells_and_radiosity(self.vtu)
        np.testing.assert_allclose(a, b, rtol=1e-5)

    def test_pvd_series_replays_the_solve(self):
        pvd = os.path.join(TMP, "box.pvd")
        root = ET.parse(pvd).getroot()
        sets = root.find("Collection").findall("DataSet")
        self.assertGreaterEqual(len(sets), 2)
        steps = [int(s.get("timestep")) for s in sets]
        self.assertEqual(steps, sorted(steps))
        # Step 0 (B = E) first, then every 500 shots, then the final solution.
        self.assertEqual(steps[:3], [0, 500, 1000])
        final_grid = vtk_read(self.vtu)
        final = vtk_to_numpy(final_grid.GetCellData().GetArray("radiosity"))
        final_unshot = final_grid.GetFieldData().GetArray("unshot_fraction").GetValue(0)
        previous = None
        fractions, seconds = [], []
        for s in sets:
            path = os.path.join(TMP, s.get("file"))
            count, radiosity, _ = meshio_cells_and_radiosity(path)
            self.assertEqual(count, len(final))
            if previous is not None:
                # Shooting only adds light: every later snapshot is at least as bright.
                self.assertTrue(np.all(radiosity >= previous - 1e-12))
            previous = radiosity
            g = vtk_read(path)
            fd = g.GetFieldData()
            self.assertEqual(int(fd.GetArray("steps").GetValue(0)), int(s.get("timestep")))
            fractions.append(fd.GetArray("unshot_fraction").GetValue(0))
            seconds.append(fd.GetArray("seconds").GetValue(0))
            # Every snapshot is a whole file: B plus the ambient term, the metadata, and an
            # energy account that balances (emitted = absorbed + escaped + unshot).
            self.assertIsNotNone(g.GetCellData().GetArray("radiosity_ambient"), path)
            for name in ("scene", "solver", "form_factors", "settings", "status"):
                self.assertIsNotNone(fd.GetAbstractArray(name), f"{path}: {name}")
            power = {k: np.array(fd.GetArray(k + "_power").GetTuple3(0))
                     for k in ("emitted", "absorbed", "escaped", "unshot")}
            self.assertGreater(power["emitted"].sum(), 0)
            np.testing.assert_allclose(power["absorbed"] + power["escaped"] + power["unshot"], power["emitted"],
                                       rtol=1e-9)
        np.testing.assert_array_equal(previous, final)
        self.assertEqual(fractions[0], 1.0)
        self.assertEqual(fractions[-1], final_unshot)
        self.assertTrue(all(a > b for a, b in zip(fractions, fractions[1:])), fractions)
        self.assertTrue(all(a <= b for a, b in zip(seconds, seconds[1:])), seconds)
        self.assertGreater(seconds[-1], seconds[1])


def png(path):
    a = matplotlib.image.imread(path)
    return a[:, :, :3]


def project(p, size):
    """Pixel (column, row) of world point p for the classic Cornell camera (39 degree view)."""
    eye = np.array([278.0, 273.0, -800.0])
    d = np.array(p) - eye
    t = math.tan(math.radians(39.0 / 2))
    sx, sy = -d[0] / d[2], d[1] / d[2]
    return int(size / 2 + sx / t * size / 2), int(size / 2 - sy / t * size / 2)


class Pictures(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.vtu = os.path.join(TMP, "cornell.vtu")
        r = bounce("solve", "-q", "-o", cls.vtu)
        assert r.returncode == 0, r.stderr

    def render(self, name, *args):
        out = os.path.join(TMP, name)
        r = bounce("render", self.vtu, "-o", out, *args)
        self.assertEqual(r.returncode, 0, r.stderr)
        return png(out)

    def test_size_and_not_blank(self):
        img = self.render("size.png", "--size", "320x240")
        self.assertEqual(img.shape[:2], (240, 320))
        self.assertGreater(img.std(), 0.1)

    def test_colour_bleeding_on_the_short_block(self):
        # Of the short block's two faces in view, the front one turns toward the red wall
        # (+x) and the side one toward the green wall (-x); both are white.
        img = self.render("bleed.png", "--size", "800x800")
        def mean_around(p):
            c, r = project(p, 800)
            return img[r - 3:r + 4, c - 3:c + 4].reshape(-1, 3).mean(axis=0)
        toward_red = mean_around((210.0, 82.5, 89.5))
        toward_green = mean_around((106.0, 82.5, 145.0))
        print("toward red", toward_red, "toward green", toward_green)
        self.assertGreater(toward_red[0] / toward_red[1], 1.15 * toward_green[0] / toward_green[1])

    def test_exposure_is_monotonic_and_flat_differs_from_smooth(self):
        means = [self.render(f"ev{ev}.png", "--size", "200x200", "--exposure", str(ev)).mean() for ev in (-2, 0, 2)]
        self.assertLess(means[0], means[1])
        self.assertLess(means[1], means[2])
        flat = self.render("flat.png", "--size", "200x200", "--flat")
        smooth = self.render("smooth.png", "--size", "200x200", "--smooth")
        self.assertGreater(np.abs(flat - smooth).mean(), 0.002)

    def test_missing_or_corrupt_input_is_one_line_exit_two(self):
        bad = os.path.join(TMP, "corrupt.vtu")
        with open(bad, "w") as f:
            f.write("<VTKFile type='UnstructuredGrid'><oops")
        for path in (os.path.join(TMP, "missing.vtu"), bad):
            out = os.path.join(TMP, "never.png")
            r = bounce("render", path, "-o", out)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
            self.assertIn(os.path.basename(path), r.stderr)
            self.assertFalse(os.path.exists(out))

    def test_solve_png_and_view_window(self):
        out = os.path.join(TMP, "solve.png")
        r = bounce("solve", "--max-area", "8000", "-q", "-o", os.path.join(TMP, "s.vtu"), "--png", out, "--size", "300x300")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(png(out).shape[:2], (300, 300))
        r = bounce("view", self.vtu, "--exit-after", "1")
        self.assertEqual(r.returncode, 0, r.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
