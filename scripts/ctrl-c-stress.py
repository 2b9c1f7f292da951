#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Ctrl-C against bounce.solve from Python, many times: every SIGINT must end the call with
KeyboardInterrupt within --max-latency seconds, and no call may return after its signal.

    scripts/ctrl-c-stress.py [--build build] [--patches 20000] [--solvers shooting]
                             [--per-phase 3] [--early 0,0.001,0.01,0.05] [--cap 60] [--out tries.csv]
    scripts/ctrl-c-stress.py --patches 4000 --solvers shooting,jacobi,hierarchical --per-phase 2

--solvers lists the solves, each a solver and its keywords (name:key=value:...). For each it
first solves once without a signal (stopped from its progress callback after --cap seconds),
recording when each stage the callback reports begins; then it signals at the --early delays,
halfway to the first report and at --per-phase points spread over every stage, in turn by
os.kill of the process (the kernel picks the thread), by signal.pthread_kill to a thread that is not the main one (the C
handler then runs there) and by _thread.interrupt_main, with and without a progress
callback. It prints one line per try and a summary, writes the tries to --out, and exits 1
when any try returned or stopped late.
"""

import argparse
import _thread
import csv
import os
import signal
import sys
import threading
import time

HOWS = ("kill", "pthread_kill", "interrupt_main")


def send(how):
    if how == "kill":
        os.kill(os.getpid(), signal.SIGINT)
    elif how == "pthread_kill":
        signal.pthread_kill(threading.get_ident(), signal.SIGINT)  # this timer thread, not the main one
    else:
        _thread.interrupt_main()


class Capped(Exception):
    pass


def timeline(bounce, scene, options, cap):
    """Stage name -> seconds into the call when it was first reported; the total; the status."""
    stages = {}
    start = time.monotonic()

    def progress(p):
        stages.setdefault(p.stage, time.monotonic() - start)
        if time.monotonic() - start > cap:
            raise Capped

    try:
        status = bounce.solve(scene, quiet=True, progress=progress, **options).status
    except Capped:
        status = f"stopped at {cap} s"
    return stages, time.monotonic() - start, status


def parse_solve(text):
    """"shooting:tolerance=1e-2" -> {"solver": "shooting", "tolerance": 0.01}."""
    name, *pairs = text.split(":")
    options = {"solver": name}
    for pair in pairs:
        key, value = pair.split("=")
        options[key] = value if value.isalpha() else float(value) if "." in value or "e" in value else int(value)
    return options


def one_try(bounce, scene, options, delay, how, with_progress):
    """(outcome, seconds from the signal to the end of the call, last stage reported)."""
    sent, last = [], [""]
    fire = threading.Timer(delay, lambda: (sent.append(time.monotonic()), send(how)))

    def progress(p):
        last[0] = p.stage

    outcome = None
    try:
        fire.start()
        sol = bounce.solve(scene, quiet=True, progress=progress if with_progress else None, **options)
        outcome = "returned " + sol.status
    except KeyboardInterrupt:
        outcome = "KeyboardInterrupt"
    end = time.monotonic()
    try:
        fire.join()
        if not sent or outcome != "KeyboardInterrupt":
            time.sleep(0.1)  # a signal sent after the call ran has its handler here
    except KeyboardInterrupt:
        pass
    if not sent:
        return "signal not sent", float("nan"), last[0]
    if outcome != "KeyboardInterrupt" and sent[0] > end:
        return "returned before the signal", float("nan"), last[0]
    return outcome, end - sent[0], last[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(os.path.dirname(__file__), "..", "build"))
    ap.add_argument("--scene", default="cornell")
    ap.add_argument("--patches", type=int, default=20000)
    ap.add_argument("--solvers", default="shooting")
    ap.add_argument("--cap", type=float, default=60.0, help="seconds the timeline solve may run")
    ap.add_argument("--per-phase", type=int, default=3, help="signal times spread over each stage")
    ap.add_argument("--early", default="0,0.001,0.01,0.05", help="signal delays (s) before the first stage")
    ap.add_argument("--max-latency", type=float, default=0.5)
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "python"))
    import bounce

    # A process started in the background by a non-interactive shell (`cmd &`) inherits SIGINT
    # ignored, and Python then installs no KeyboardInterrupt handler: every call would run on.
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        print(f"SIGINT was {signal.getsignal(signal.SIGINT)!r} at start; installing Python's default handler")
        signal.signal(signal.SIGINT, signal.default_int_handler)

    scene = bounce.load(a.scene, patches=a.patches, quiet=True)
    rows, failures = [], 0
    for text in a.solvers.split(","):
        options = parse_solve(text)
        solver = text
        stages, total, status = timeline(bounce, scene, options, a.cap)
        print(f"{solver}: {len(scene.patches.area)} patches, {total:.1f} s uninterrupted ({status}); stages "
              + ", ".join(f"{k} at {v:.2f} s" for k, v in stages.items()), flush=True)
        starts = sorted(stages.values()) + [total]
        delays = [float(x) for x in a.early.split(",") if x]
        delays.append(starts[0] / 2)  # before the first report
        for lo, hi in zip(starts, starts[1:]):
            delays += [lo + (hi - lo) * (k + 0.5) / a.per_phase for k in range(a.per_phase)]
        n = 0
        for delay in delays:
            for how in HOWS:
                with_progress = n % 2 == 0
                n += 1
                outcome, latency, stage = one_try(bounce, scene, options, delay, how, with_progress)
                bad = outcome != "KeyboardInterrupt" and outcome != "returned before the signal" or latency > a.max_latency
                failures += bad
                rows.append([solver, f"{delay:.3f}", how, int(with_progress), outcome, f"{latency:.3f}", stage])
                print(f"  {'FAIL' if bad else 'ok  '} delay {delay:7.3f} s {how:14} progress={int(with_progress)}"
                      f" -> {outcome}, {latency:.3f} s after the signal (last stage: {stage or '-'})", flush=True)
    stopped = [float(r[5]) for r in rows if r[4] == "KeyboardInterrupt"]
    returned = sum(r[4].startswith("returned ") and r[4] != "returned before the signal" for r in rows)
    print(f"{len(rows)} tries: {len(stopped)} KeyboardInterrupt, {returned} returned after the signal, "
          f"max latency {max(stopped, default=float('nan')):.3f} s, {failures} failures")
    if a.out:
        with open(a.out, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["solver", "delay_s", "how", "progress", "outcome", "latency_s", "last_stage"])
            w.writerows(rows)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
