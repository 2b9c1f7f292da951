# SPDX-License-Identifier: MIT
# Form factors from Python: the very rows `bounce form-factors` writes, and row sums and
# reciprocity as the library's own check (the one --check prints) computes them.
import csv
import re

import numpy as np
import pytest

import bounce

PATCHES = 150


@pytest.fixture(scope="module")
def scene():
    return bounce.load("cornell", patches=PATCHES)


@pytest.fixture(scope="module")
def F(scene):
    return bounce.form_factors(scene, method="raycast")


def reciprocity(F, area):
    AF = area[:, None] * F.astype(np.float64)
    diff = np.abs(AF - AF.T)
    big = F >= 1e-3
    return np.max(diff[big] / AF[big]), diff.sum() / AF.sum()


def test_rows_equal_command_line_csv(tmp_path, run_cli, scene, F):
    n = len(scene)
    assert F.shape == (n, n) and F.dtype == np.float32
    out = tmp_path / "ff.csv"
    code, stdout, err = run_cli("form-factors", "--patches", PATCHES, "-q", "--check", "-o", out)
    assert code == 0, err
    cli = np.zeros((n, n), np.float32)
    cli_sums = np.zeros(n)
    with open(out) as f:
        for row in csv.DictReader(f):
            i, j = int(row["i"]), int(row["j"])
            cli[i, j] = np.float32(row["F_ij"])  # 9 digits: a float32 exactly
            cli_sums[i] = float(row["row_sum_i"])
    np.testing.assert_array_equal(F, cli)
    sums = F.sum(axis=1, dtype=np.float64)
    np.testing.assert_allclose(sums, cli_sums, rtol=1e-8)

    check = bounce.check_form_factors(scene, F)
    np.testing.assert_allclose(check["row_sums"], sums, rtol=1e-12)
    rmax, roverall = reciprocity(F, scene.patches.area)
    assert check["reciprocity_max"] == pytest.approx(rmax, rel=1e-9)
    assert check["reciprocity_overall"] == pytest.approx(roverall, rel=1e-9)
    assert check["row_sum_max"] == pytest.approx(sums.max(), rel=1e-12)
    assert check["deviation_mean"] == pytest.approx(np.abs(sums - 1).mean(), rel=1e-9)
    # The same numbers --check prints (6 significant digits).
    printed = re.search(r"reciprocity .*: max (\S+) .* = (\S+)", stdout)
    assert printed, stdout
    assert float(printed.group(1)) == pytest.approx(rmax, rel=1e-5, abs=1e-12)
    assert float(printed.group(2)) == pytest.approx(roverall, rel=1e-5, abs=1e-12)
    sums_line = re.search(r"row sums: min (\S+), mean (\S+), max (\S+)", stdout)
    assert float(sums_line.group(1)) == pytest.approx(sums.min(), rel=1e-5)
    assert float(sums_line.group(3)) == pytest.approx(sums.max(), rel=1e-5)
    # Raycast estimates each pair once: reciprocity to float rounding.
    assert rmax < 1e-5


def test_matrix_is_a_view_and_csr_agrees(scene, F):
    assert not F.flags.owndata and not F.flags.writeable and F.base is not None
    data, indices, indptr = bounce.form_factors(scene, format="csr")
    assert len(indptr) == len(scene) + 1 and indptr[-1] == np.count_nonzero(F)
    dense = np.zeros_like(F)
    for i in range(len(scene)):
        dense[i, indices[indptr[i]:indptr[i + 1]]] = data[indptr[i]:indptr[i + 1]]
    np.testing.assert_array_equal(dense, F)

