# SPDX-License-Identifier: MIT
# Shared by the module's tests: the `bounce` program they compare against (ctest passes its
# path in BOUNCE_EXE) and a runner that returns its exit code, stdout and stderr.
import os
import subprocess

import pytest

import bounce  # noqa: F401  (fails early, with the import error, when PYTHONPATH is wrong)


def _exe():
    exe = os.environ.get("BOUNCE_EXE")
    if not exe or not os.path.exists(exe):
        pytest.fail("BOUNCE_EXE must name the built bounce program (ctest sets it)")
    return exe


@pytest.fixture(scope="session")
def run_cli():
    exe = _exe()

    def run(*args, cwd=None):
        r = subprocess.run([exe, *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=600)
        return r.returncode, r.stdout, r.stderr

    return run
