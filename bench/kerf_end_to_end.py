"""Is the kerf stage's own vertex reduction worth its code? (issue 17)

The vector kerf draws GEOS's offset with arcs at 1/16 of the arc tolerance, redraws the
round joins with the error on both sides of the arc (``offset_arcs``) and thins the outline
(``kerf._reduce``, with its hash table of kept vertices). The fit stage thins and fits the
outline again anyway. This runs the whole pipeline (kerf -> fit -> sample) both ways:

* ``current``: the kerf stage as it is;
* ``plain``: GEOS's offset with arcs drawn at the whole arc tolerance (the fewest chords
  with sagitta <= tol, GEOS's own minimum of 8 per quarter kept), no redrawn joins, no
  reduction; the fit's thinning does the rest;

and compares the marks (count, and how far apart the two mark sets are, in bits) and the
CPU time of the run (best of N, fresh pipeline each time).

    .venv/bin/python bench/kerf_end_to_end.py [--repeat 3] [--files N]
"""

from __future__ import annotations

import argparse
import contextlib
import platform
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from galvo_core import kerf
from galvo_core.hpgl import read_file
from galvo_core.params import Params
from galvo_core.pipeline import Pipeline

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = sorted((ROOT / "resources" / "samples").glob("*.plt"))
CORPUS = ROOT.parent / "shared" / "corpus" / "plt"


@contextlib.contextmanager
def plain_geos() -> Iterator[None]:
    saved = kerf.ARC_SHARE, kerf.two_sided_arcs, kerf._reduce
    kerf.ARC_SHARE = 1.0
    kerf.two_sided_arcs = lambda out, d, tol, check=False: (out, np.empty(0))
    kerf._reduce = lambda geom, eps, keep=None, fallback=None: (geom, False)
    try:
        yield
    finally:
        kerf.ARC_SHARE, kerf.two_sided_arcs, kerf._reduce = saved


def run(d, p: Params, repeat: int):
    best = float("inf")
    job = None
    for _ in range(repeat):
        t0 = time.process_time()
        job = Pipeline().run(d, p).job
        best = min(best, time.process_time() - t0)
    return job, best


def gap_bits(a, b) -> float:
    """Largest distance from a mark of one job to the nearest stroke (polyline through its
    marks) of the other, both ways (bits): how far apart the two markings are."""
    import shapely

    def segments(job) -> np.ndarray:
        segs = [np.stack([s.marks[:-1], s.marks[1:]], axis=1) for s in job.strokes
                if len(s.marks) > 1]
        return np.concatenate(segs) if segs else np.zeros((0, 2, 2))

    def one_way(p, q) -> float:
        pts = np.concatenate([s.marks for s in p.strokes]) if p.strokes else np.zeros((0, 2))
        segs = segments(q)
        if not len(pts) or not len(segs):
            return 0.0
        tree = shapely.STRtree(shapely.linestrings(segs.astype(float)))
        _, dist = tree.query_nearest(shapely.points(pts.astype(float)), return_distance=True,
                                     all_matches=False)
        return float(dist.max())

    return max(one_way(a, b), one_way(b, a))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--files", type=int, default=12, help="corpus files (largest first)")
    a = ap.parse_args()
    corpus = sorted((f for f in CORPUS.glob("*") if f.suffix.lower() in (".plt", ".hpgl")),
                    key=lambda f: -f.stat().st_size)[: a.files] if CORPUS.is_dir() else []
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    cpu = platform.processor() or platform.machine()
    print(f"# {when}, {cpu}, CPU time best of {a.repeat}")
    print("| file | side | marks current | marks plain | x | gap (bits) | CPU current (s) | "
          "CPU plain (s) | x |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    tot = np.zeros(4)
    for f in SAMPLES + corpus:
        try:
            d = read_file(f)
        except Exception:  # noqa: BLE001 - refused corpus files are not the point here
            continue
        if d.n_closed == 0:
            continue
        for side in ("outside", "inside"):
            p = Params(fit_field=True, kerf_mm=0.1, kerf_side=side)
            try:
                cur, tc = run(d, p, a.repeat)
                with plain_geos():
                    pla, tp = run(d, p, a.repeat)
            except Exception as exc:  # noqa: BLE001
                print(f"| {f.name} | {side} | error: {exc} |")
                continue
            mc = cur.stats["mark_points"]
            mp = pla.stats["mark_points"]
            tot += (mc, mp, tc, tp)
            print(f"| {f.name[:40]} | {side} | {mc} | {mp} | {mp / max(mc, 1):.3f} | "
                  f"{gap_bits(cur, pla):.2f} | {tc:.3f} | {tp:.3f} | {tp / max(tc, 1e-9):.2f} |")
    print(f"| **total** | | {tot[0]:.0f} | {tot[1]:.0f} | {tot[1] / tot[0]:.3f} | | "
          f"{tot[2]:.2f} | {tot[3]:.2f} | {tot[3] / tot[2]:.2f} |")


if __name__ == "__main__":
    main()
