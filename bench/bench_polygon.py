"""Polygon-mode import speed against ezhpgl (issue 20, briefs 20b and s3: polygon mode in the
compiled scanner).

Two generated files (numpy, fixed seed) in the styles that use polygon mode, plus two corpus
files: ours (numba scanner loaded, as in the workstation) vs ezhpgl, CPU time
(time.process_time), median of N calls after one warm-up call each.

    PYTHONPATH=. python bench/bench_polygon.py [--reps 5]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numba  # noqa: F401  (the compiled scanner for every size, as in the workstation)
import numpy as np

from galvo_core.hpgl import read_bytes

CORPUS = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "plt"


def plotutils_style(n_lines: int = 2000, n_pts: int = 50, seed: int = 1) -> bytes:
    """GNU plotutils: each open polyline ``PA x0,y0;PM0;PD;PA x1,y1,...;PU;PM2;EP;``."""
    rng = np.random.default_rng(seed)
    xy = rng.integers(0, 10000, size=(n_lines, n_pts, 2))
    out = [b"IN;SP1;"]
    for line in xy:
        flat = ",".join(map(str, line[1:].ravel().tolist())).encode()
        out.append(b"PA%d,%d;PM0;PD;PA%s;PU;PM2;EP;\n" % (line[0, 0], line[0, 1], flat))
    return b"".join(out)


def per_point_pd(n_polys: int = 2000, n_pts: int = 50, seed: int = 2) -> bytes:
    """Per-point PD in polygon mode: ``PUx,y;PM0;PDx,y;PDx,y;...;PM2;FP;``."""
    rng = np.random.default_rng(seed)
    xy = rng.integers(0, 10000, size=(n_polys, n_pts, 2))
    out = [b"IN;SP1;"]
    for poly in xy:
        body = b"".join(b"PD%d,%d;" % (x, y) for x, y in poly[1:].tolist())
        out.append(b"PU%d,%d;PM0;%sPM2;FP;\n" % (poly[0, 0], poly[0, 1], body))
    return b"".join(out)


def cpu_ms(fn, data: bytes, reps: int) -> float:
    fn(data)
    ts = []
    for _ in range(reps):
        t0 = time.process_time()
        fn(data)
        ts.append(time.process_time() - t0)
    return 1000 * statistics.median(ts)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    try:
        import ezhpgl
    except ImportError:
        ezhpgl = None
    files = [("plotutils style, 2000 x 50 points", plotutils_style()),
             ("per-point PD in PM, 2000 x 50 points", per_point_pd())]
    for name in ("drepetto__chiplotle__foal_release-0.1.hpgl",
                 "artifexsoftware__ghostpdl__grashopp.pcl"):
        p = CORPUS / name
        if p.exists():
            files.append((name, p.read_bytes()))
    print("| file | bytes | ours ms | ezhpgl ms | ratio |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for name, data in files:
        ours = cpu_ms(lambda d: read_bytes(d, "x"), data, args.reps)
        ez = "-"
        ratio = "-"
        if ezhpgl is not None:
            limits = ezhpgl.Limits(max_input_bytes=1 << 30, max_commands=1 << 26)
            glim = ezhpgl.GeometryLimits(max_operations=1 << 26, max_vertices=1 << 26)
            kw = {"limits": limits, "geometry_limits": glim}
            try:
                ezhpgl.parse(data, **kw)
                mode = ""
            except Exception:
                mode = " (lenient, partial)"
            try:
                if mode:
                    e = cpu_ms(lambda d, kw=kw: ezhpgl.parse(d, strict=False, **kw), data,
                               args.reps)
                else:
                    e = cpu_ms(lambda d, kw=kw: ezhpgl.parse(d, **kw), data, args.reps)
                ez = f"{e:.2f}{mode}"
                ratio = f"{ours / e:.2f}"
            except Exception as exc:  # noqa: BLE001
                ez = f"error {type(exc).__name__}"
        print(f"| {name} | {len(data):,} | {ours:.2f} | {ez} | {ratio} |")


if __name__ == "__main__":
    main()
