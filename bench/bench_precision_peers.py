"""Peers on the typeface outlines of bench_precision.py (issue 16): Paper.js
``Path.simplify`` and fit-curve (Schneider) at a grid of tolerances, each result's segment
count against the typeface's own and its distance to the true design curve (both ways, as
bench_precision measures ours), and the peer's own time (node, ms). Peers installed by
bench/run_fit.sh into bench/node_modules. Whole contours are handed to fit-curve (it is not
split at corners here).

Usage: python bench/bench_precision_peers.py [--styles sans,serif-italic] [--em 1000]
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.dirname(__file__))

from bench_fit import SCALE, run_peer  # noqa: E402
from fonts import curve_distance, glyph_set  # noqa: E402

from galvo_core.geometry import flatten_cubic  # noqa: E402

DISTS = (0.05, 0.1, 0.25, 0.5, 0.75, 1.0)


def dense(cubics) -> np.ndarray:
    parts = [flatten_cubic(np.asarray(c, float), 0.002) for c in cubics]
    return np.vstack([parts[0]] + [p[1:] for p in parts[1:]])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--styles", default="sans,serif-italic,sans-light")
    ap.add_argument("--em", type=float, default=1000.0)
    a = ap.parse_args()
    print("| style | input | peer | tolerance (units) | segments | x own | to true curve | ms |")
    print("| --- | --- | --- | ---: | ---: | ---: | ---: | ---: |")
    for whole in (True, False):
        for st in a.styles.split(","):
            gs = glyph_set(st, em=a.em, whole=whole)
            paths = [(p, True) for p in gs.points]
            for lib in ("paper", "fit-curve"):
                tols = [(d * SCALE) ** 2 if lib == "fit-curve" else d * SCALE for d in DISTS]
                res = run_peer(lib, paths, tols)
                for d, r in zip(DISTS, res["results"], strict=True):
                    n = sum(len(cs) for cs in r["paths"])
                    dist = max(curve_distance(dense(cs), t)
                               for cs, t in zip(r["paths"], gs.truth, strict=True) if cs)
                    print(f"| {st} | {'whole' if whole else 'exact'} | {lib} {res['version']} | "
                          f"{d} | {n} | {n / gs.own_segments:.2f} | {dist:.3f} | "
                          f"{r['ms']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
