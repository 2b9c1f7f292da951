# SPDX-License-Identifier: MIT
# Ctrl-C during a long solve: KeyboardInterrupt within a second of the signal, and the call
# returns nothing. The solve runs with the GIL released; the binding polls for signals.
import _thread
import os
import signal
import threading
import time

import pytest

import bounce


@pytest.fixture(scope="module")
def big_scene():
    return bounce.load("cornell", patches=4000)


def interrupt_later(how, delay, sent, after=None):
    """Interrupts `delay` seconds after the start, or after the event `after` is set."""
    def fire():
        if after is not None and not after.wait(60):
            return
        time.sleep(delay)
        sent.append(time.monotonic())
        if how == "interrupt_main":
            _thread.interrupt_main()
        else:
            os.kill(os.getpid(), signal.SIGINT)

    t = threading.Thread(target=fire, daemon=True)
    t.start()
    return t


@pytest.mark.parametrize(
    "how, solver, stage",
    [("interrupt_main", "shooting", "solve"), ("SIGINT", "shooting", "solve"),
     # Jacobi first builds the 4000 x 4000 matrix on all cores: stopped between rows.
     ("SIGINT", "jacobi", "form factors"),
     # The hierarchical solver on 4000 roots refines links for many seconds: stopped between
     # pairs, not at the iteration after.
     ("SIGINT", "hierarchical", "round 1/1: refining links")],
)
def test_keyboard_interrupt_stops_a_long_solve(big_scene, how, solver, stage):
    sent = []
    calls = []
    reached = threading.Event()

    def progress(p):
        calls.append(p)
        if p.stage == stage:
            reached.set()

    # Half a second into the stage (for shooting, past the open parts' rays, which come before
    # the first shot and report nothing), however long the work before it took.
    thread = interrupt_later(how, 0.5, sent, after=reached)
    with pytest.raises(KeyboardInterrupt):
        # To 1e-9 at 4000 patches takes far longer than the test allows.
        bounce.solve(big_scene, solver=solver, tolerance=1e-9, gather="none", progress=progress)
    stopped = time.monotonic()
    thread.join()
    assert sent, "the solve ended before the interrupt was sent"
    assert stopped - sent[0] < 1.0, f"stopped {stopped - sent[0]:.2f} s after the signal"
    # The work was still at the stage when the signal came (shooting reports its balanced
    # rows' "form factors" first).
    first = next(k for k, c in enumerate(calls) if c.stage == stage)
    assert all(c.stage == stage for c in calls[first:])
    if stage == "solve":
        assert calls and calls[-1].step > 0
    # Nothing is left running: the next call works at once.
    assert bounce.solve(bounce.load("cornell", patches=20), gather="none").converged


def test_exception_in_progress_callback_stops_the_solve(big_scene):
    class Enough(Exception):
        pass

    seen = []

    def progress(p):
        seen.append(p.step)
        if p.step >= 200:
            raise Enough

    with pytest.raises(Enough):
        bounce.solve(big_scene, tolerance=1e-9, gather="none", progress=progress)
    assert seen[-1] >= 200


def test_solve_releases_the_gil(big_scene):
    # Another Python thread keeps running while the solve works: were the GIL held, it would
    # not get a single step in until the solve returned.
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.001)

    t = threading.Thread(target=tick, daemon=True)
    start = time.monotonic()
    t.start()
    sol = bounce.solve(big_scene, tolerance=1e-9, max_seconds=0.5, gather="none")
    end = time.monotonic()
    stop.set()
    t.join()
    assert sol.status == "max seconds"
    during = [x for x in ticks if start + 0.1 < x < end - 0.1]
    assert len(during) > 50, f"{len(during)} ticks while the solve ran"
