"""Vector kerf time and vertex count against Clipper2 over the corpus (issue 6).

Per corpus file with closed paths and side: ``compensate_indexed`` (vector, kerf 0.1 mm at
the fit-field magnification, 1 bit arc tolerance) against Clipper2's even-odd union +
InflatePaths per pen (numpy in and out), best of 3 each (``--repeat N``: best of N, for a
busy machine; ``--clock cpu``: the process's CPU time instead of wall time, which other
processes on a busy machine do not inflate; both sides are single-threaded). Prints the
totals, the ratios over the runs where Clipper2 takes at least 5 ms (below that both are a
few milliseconds and the ratio is fixed per-call cost), and the runs above 1.2x Clipper2's
vertex count, each with both outlines' reference-free offset error (largest | distance to
the input outline - d |, densified to 0.1 bit) in bits.

Run with the benchmark's own environment (made by run_kerf.sh):
``PYTHONPATH=. bench/.venv-kerf/bin/python bench/kerf_corpus_time.py [--repeat N]
[--clock cpu]``
"""

from __future__ import annotations

import argparse
import functools
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_kerf as bk  # noqa: E402

from galvo_core import kerf  # noqa: E402
from galvo_core.drawing import Drawing  # noqa: E402
from galvo_core.field import make_field  # noqa: E402

KERF_MM = 0.1
MEANINGFUL_S = 0.005


def offset_errors(dr: Drawing, side: str) -> tuple[float, float]:
    """Largest offset error of ours and of Clipper2's outline, in bits, over the pens."""
    fm = make_field(dr.bbox(), magnification=None, fit_field=True)
    d = fm.mm_to_units(KERF_MM / 2)
    bit = fm.bits_to_units(1.0)
    ours = theirs = 0.0
    for pen in sorted({p.pen for p in dr.paths}):
        rings = bk.pen_rings(dr, pen)
        if not rings:
            continue
        region = kerf.even_odd_region(rings)
        mine = kerf.compensate_geometry(region, d, side=side, method="vector", tol=bit,
                                        res=bit)
        clip = bk.clipper_geom(bk.clipper_offset(rings, d, side, bit))
        ours = max(ours, bk.offset_error(mine, region, d, step=bit / 10) / bit)
        theirs = max(theirs, bk.offset_error(clip, region, d, step=bit / 10) / bit)
    return ours, theirs




def runs(drawings: dict[str, Drawing], repeat: int = 3
         ) -> list[tuple[str, str, float, float, int, int]]:
    """(file, side, our time, Clipper2 time, our vertices, Clipper2 vertices) per run."""
    rows = []
    for name, dr in drawings.items():
        fm = make_field(dr.bbox(), magnification=None, fit_field=True)
        x0, y0, x1, y1 = dr.bbox()
        if KERF_MM > max(x1 - x0, y1 - y0) * fm.mm_per_unit:
            continue
        d = fm.mm_to_units(KERF_MM / 2)
        bit = fm.bits_to_units(1.0)
        for side in ("outside", "inside"):
            (out, _), t = bk.timed(lambda side=side, dr=dr, fm=fm: kerf.compensate_indexed(
                dr, kerf_mm=KERF_MM, side=side, method="vector", fm=fm), repeat)
            tc, nc = 0.0, 0
            for pen in sorted({p.pen for p in dr.paths}):
                rings = bk.pen_rings(dr, pen)
                if rings:
                    paths, t1 = bk.timed(lambda rings=rings, d=d, side=side, bit=bit:
                                         bk.clipper_offset(rings, d, side, bit), repeat)
                    tc += t1
                    nc += sum(len(p) for p in paths)
            nv = sum(len(p.points) - 1 for p in out.paths if p.closed)
            rows.append((name, side, t, tc, nv, nc))
    return rows


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3, help="best of this many runs each")
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall")
    args = ap.parse_args()
    if args.clock == "cpu":
        bk.timed = functools.partial(bk.timed, clock=time.process_time)
    drawings = dict(bk.corpus_drawings())
    rows = runs(drawings, args.repeat)
    t = np.array([r[2] for r in rows])
    c = np.array([r[3] for r in rows])
    nv = np.array([r[4] for r in rows])
    nc = np.array([r[5] for r in rows])
    big = c >= MEANINGFUL_S
    ratio = t[big] / c[big]
    print(f"runs {len(rows)}; total time ours {t.sum():.2f} s, Clipper2 {c.sum():.2f} s "
          f"(x{t.sum() / c.sum():.2f})")
    print(f"runs where Clipper2 takes >= {MEANINGFUL_S * 1000:.0f} ms: {int(big.sum())}, "
          f"ours / Clipper2 median x{np.median(ratio):.2f}, max x{ratio.max():.2f}; "
          f"within 5x: {int((ratio <= 5).sum())}")
    for r in sorted((r for r in rows if r[3] >= MEANINGFUL_S), key=lambda r: -r[2] / r[3])[:8]:
        print(f"  {r[0]} {r[1]}: {r[2] * 1000:.1f} ms vs {r[3] * 1000:.1f} ms")
    print(f"other runs: ours median {np.median(t[~big]) * 1000:.1f} ms, "
          f"max {t[~big].max() * 1000:.1f} ms")
    over = []
    for r in rows:
        if r[4] > 1.2 * r[5]:
            e_ours, e_clip = offset_errors(drawings[r[0]], r[1])
            over.append(f"{r[0]} {r[1]} ({r[4]} at {e_ours:.4f} bits vs {r[5]} at "
                        f"{e_clip:.4f} bits)")
    vr = nv / np.maximum(nc, 1)
    print(f"vertices: total x{nv.sum() / nc.sum():.2f}, median x{np.median(vr):.2f}; "
          f"runs above x1.2: {len(over)}: " + "; ".join(over))


if __name__ == "__main__":
    main()
