"""Fit throughput with the precision detection (issue 16): 1 M input points of the speed
curve (bench_thin.sines) as 10 paths, exact and rounded to whole units; CPU time
(time.process_time), best of N, fit_drawing with the defaults (quantum detected) against
quantum_units=0 given (no detection, the rounding ignored: today's fit). ``--nesting``: the
refit of the corpus's fabric nesting file (40,705 paths) at e_per 0.05 and 0.02.

``--code DIR`` imports galvo_core from another checkout (e.g. ``git worktree add /tmp/wt-66c
66c99cd``), to measure two versions side by side in the same minutes (alternate the runs).

Usage: python bench/bench_precision_speed.py [--reps 3] [--code DIR] [--only exact|whole]
       [--nesting]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
NESTING = os.path.join(HERE, "..", "..", "shared", "corpus", "plt",
                       "straight-coding__gcode-hpgl-viewer__b_fabric_nesting.plt")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--code", help="import galvo_core from this checkout")
    ap.add_argument("--only", choices=("exact", "whole"))
    ap.add_argument("--nesting", action="store_true", help="the nesting refit only")
    a = ap.parse_args()
    root = os.path.abspath(a.code) if a.code else os.path.join(HERE, "..")
    sys.path.insert(0, root)
    sys.path.insert(1, os.path.join(root, "bench"))  # (its bench_thin puts its root first)
    from bench_thin import sines

    from galvo_core.drawing import Drawing, Path
    from galvo_core.fit import fit_drawing, warm_up

    def segments(f) -> int:
        return sum(len(x.is_cubic) if hasattr(x, "is_cubic") else len(x.segments) for x in f)

    warm_up()
    tag = a.code or "this checkout"
    if a.nesting:
        from galvo_core import hpgl

        d = hpgl.read_file(NESTING)
        n = sum(len(p.points) for p in d.paths)
        for e_per in (0.05, 0.02):
            best = np.inf
            for _ in range(a.reps):
                t0 = time.process_time()
                f = fit_drawing(d, e_per=e_per)
                best = min(best, time.process_time() - t0)
            print(f"{tag}: nesting {len(d.paths)} paths {n} points e_per {e_per}  "
                  f"{best:.3f} s CPU  {segments(f)} segments", flush=True)
        return
    paths = [sines(100_000, seed=s) + [0.0, 200.0 * s] for s in range(10)]
    for label, pts in (("exact", paths), ("whole units", [np.round(p) for p in paths])):
        if a.only and not label.startswith(a.only):
            continue
        d = Drawing(tuple(Path(p, 1, False) for p in pts), name=label)
        n = sum(len(p) for p in pts)
        for qu in (None, 0.0):
            if a.only and qu is not None:
                continue
            best = np.inf
            for _ in range(a.reps):
                t0 = time.process_time()
                f = fit_drawing(d, quantum_units=qu) if qu is not None else fit_drawing(d)
                best = min(best, time.process_time() - t0)
            print(f"{tag}: {label:12s} quantum {'detected' if qu is None else 'given 0':9s} "
                  f"{n} points  {best:.2f} s CPU  {n / best / 1e3:.0f} k points/s  "
                  f"{segments(f)} segments", flush=True)


if __name__ == "__main__":
    main()
