"""Fit throughput with the precision detection (issue 16): 1 M input points of the speed
curve (bench_thin.sines) as 10 paths, exact and rounded to whole units; CPU time
(time.process_time), best of N, fit_drawing with the defaults (quantum detected) against
quantum_units=0 given (no detection, the rounding ignored: today's fit).

Usage: python bench/bench_precision_speed.py [--reps 3]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.dirname(__file__))

from bench_thin import sines  # noqa: E402

from galvo_core.drawing import Drawing, Path  # noqa: E402
from galvo_core.fit import fit_drawing, warm_up  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=3)
    a = ap.parse_args()
    warm_up()
    paths = [sines(100_000, seed=s) + [0.0, 200.0 * s] for s in range(10)]
    for label, pts in (("exact", paths), ("whole units", [np.round(p) for p in paths])):
        d = Drawing(tuple(Path(p, 1, False) for p in pts), name=label)
        n = sum(len(p) for p in pts)
        for qu in (None, 0.0):
            best = np.inf
            for _ in range(a.reps):
                t0 = time.process_time()
                f = fit_drawing(d, quantum_units=qu)
                best = min(best, time.process_time() - t0)
            segs = sum(len(x.segments) for x in f)
            print(f"{label:12s} quantum {'detected' if qu is None else 'given 0':9s} "
                  f"{n} points  {best:.2f} s CPU  {n / best / 1e3:.0f} k points/s  "
                  f"{segs} segments", flush=True)


if __name__ == "__main__":
    main()
