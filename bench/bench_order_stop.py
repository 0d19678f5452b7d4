"""Optimized order that stops by itself (issue 21): travel against LKH and against the
old 1 s search (both from bench/RESULTS.md, "Order", 2026-11-23: the same instances), CPU
time and the search's work; then the growth with the number of strokes (random segments at
constant density: 1 k, 10 k, 100 k strokes; ``--sizes``).

Modes: ``own stop`` = no time budget (1e6 s): the search ends when a window of kicks stops
improving or after its kick limit; ``1 s`` = the default budget as a cap. CPU seconds
(``time.process_time``); the machine is shared, so the 1 s (wall) cap gives a loaded run
less search than an idle one.

    python bench/bench_order_stop.py [--sizes 1000 10000 100000]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from bench_order import instances, random_segments  # noqa: E402

from galvo_core.order import (  # noqa: E402
    _greedy,
    _improve,
    _placement,
    _Problem,
    order_strokes,
    travel_length,
)

#: from bench/RESULTS.md "Order" (2026-11-23): LKH (elkai, runs=1) and the old optimized
#: search with its 1 s budget, on the same instances
LKH = {"random 200 segments": 9463, "random 1000 segments": 18350,
       "seal.plt zigzag hatch (31)": 2913, "text_outline.plt zigzag hatch (21)": 3220,
       1: 18172, 2: 18565, 3: 18237, 4: 18211, 5: 17882, 6: 18479, 7: 18148, 8: 17810}
OLD = {"random 200 segments": 9541, "random 1000 segments": 18743,
       "random 10000 segments": 66798, "seal.plt zigzag hatch (31)": 2913,
       "seal.plt scanline hatch (3937)": 16348, "text_outline.plt zigzag hatch (21)": 3220,
       "text_outline.plt scanline hatch (2866)": 12419,
       1: 18688, 2: 19036, 3: 18694, 4: 18640, 5: 18281, 6: 18845, 7: 18543, 8: 18302}


def run(st: list[np.ndarray], budget: float) -> tuple[float, float]:
    t0 = time.process_time()
    pl = order_strokes(st, method="optimized", time_budget_s=budget)
    return travel_length(st, pl), time.process_time() - t0


def quality() -> None:
    cases = list(instances()) + [(s, random_segments(1000, np.random.default_rng(s)))
                                 for s in range(1, 9)]
    print("| instance | strokes | greedy | own stop (CPU s, kicks) | 1 s cap (CPU s) | "
          "old 1 s | own stop / old | own stop / LKH |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, st in cases:
        g = travel_length(st, order_strokes(st, method="greedy"))
        o, to = run(st, 1e6)
        c, tc = run(st, 1.0)
        prob = _Problem(st, [False] * len(st), None)
        stats: dict = {}
        _improve(prob, _greedy(prob, []), [], time.perf_counter() + 1e6, stats=stats)
        old = OLD.get(name)
        lk = LKH.get(name)
        label = f"random 1000 segments, seed {name}" if isinstance(name, int) else name
        print(f"| {label} | {len(st)} | {g:.0f} | {o:.0f} ({to:.2f}, {stats.get('kicks', 0)}) "
              f"| {c:.0f} ({tc:.2f}) | {old if old else '-'} | "
              f"{f'{o / old:.3f}' if old else '-'} | {f'{o / lk:.3f}' if lk else '-'} |",
              flush=True)
    print("\nload average " + " ".join(f"{x:.2f}" for x in os.getloadavg()))


def growth(sizes: list[int]) -> None:
    print("\n| strokes | greedy CPU s | optimized (own stop) CPU s | kicks | travel / greedy |")
    print("| ---: | ---: | ---: | ---: | ---: |")
    prev = None
    for n in sizes:
        rng = np.random.default_rng(5)
        side = 10000.0 * math.sqrt(n / 10000)
        a = rng.uniform(0, side, (n, 2))
        st = list(np.stack([a, a + rng.normal(0, 20, (n, 2))], axis=1))
        t0 = time.process_time()
        g_pl = order_strokes(st, method="greedy")
        tg = time.process_time() - t0
        g = travel_length(st, g_pl)
        prob = _Problem(st, [False] * n, None)
        stats: dict = {}
        t0 = time.process_time()
        out = _improve(prob, _greedy(prob, []), [], time.perf_counter() + 1e6, stats=stats)
        to = time.process_time() - t0 + tg
        o = travel_length(st, [_placement(prob, c) for c in out])
        e = ""
        if prev:
            e = (f" (exponent greedy {math.log(tg / prev[1]) / math.log(n / prev[0]):.2f}, "
                 f"optimized {math.log(to / prev[2]) / math.log(n / prev[0]):.2f})")
        print(f"| {n} | {tg:.2f} | {to:.2f}{e} | {stats.get('kicks', 0)} | {o / g:.3f} |",
              flush=True)
        prev = (n, tg, to)
    print("\nload average " + " ".join(f"{x:.2f}" for x in os.getloadavg()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[1000, 10000, 100000])
    ap.add_argument("--skip-quality", action="store_true")
    args = ap.parse_args()
    if not args.skip_quality:
        quality()
    if args.sizes:
        growth(args.sizes)


if __name__ == "__main__":
    main()
