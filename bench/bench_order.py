"""Order benchmark (issue 7): travel of greedy / optimized against LKH (elkai) and vpype.

Instances: random short open strokes (reversible) of n = 200, 1000 (LKH can finish these)
and 10,000 (timing only), plus the zig-zag hatch strokes of seal.plt and text_outline.plt;
then optimized / LKH on random 1000-segment instances from seeds 1-8 (the spread). LKH tour
lengths are cached in bench/out/order_lkh.json (LKH takes ~20-45 s on 1000 strokes).
LKH gets the exact problem as a symmetric TSP: two nodes per stroke (its ends) joined by a
forced zero edge, every other edge = distance + BIG, plus one free dummy node (an open
path). Run in bench/.venv-fill (elkai, vpype). Prints a markdown table.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from galvo_core.fill import hatch  # noqa: E402
from galvo_core.hpgl import read_file  # noqa: E402
from galvo_core.order import Placement, order_strokes, travel_length  # noqa: E402
from galvo_core.params import Params  # noqa: E402
from galvo_core.pipeline import Pipeline  # noqa: E402

LKH_CACHE = ROOT / "bench" / "out" / "order_lkh.json"


def lkh_cached(strokes: list[np.ndarray]) -> tuple[float, float]:
    """:func:`lkh`, remembered in bench/out/order_lkh.json by a hash of the points (LKH takes
    ~45 s on 1000 strokes). Returns (travel, LKH seconds when it was run)."""
    h = hashlib.sha1()
    for s in strokes:
        h.update(np.ascontiguousarray(s, dtype=np.float64).tobytes())
    key = h.hexdigest()
    cache = json.loads(LKH_CACHE.read_text()) if LKH_CACHE.exists() else {}
    if key not in cache:
        length, dt = lkh(strokes)
        cache = json.loads(LKH_CACHE.read_text()) if LKH_CACHE.exists() else {}
        cache[key] = [length, dt]
        LKH_CACHE.parent.mkdir(parents=True, exist_ok=True)
        tmp = LKH_CACHE.with_suffix(".tmp")
        tmp.write_text(json.dumps(cache, indent=1))
        tmp.replace(LKH_CACHE)
    return float(cache[key][0]), float(cache[key][1])


def lkh(strokes: list[np.ndarray], runs: int = 1) -> tuple[float, float]:
    import elkai

    n = len(strokes)
    ends = np.array([[s[0], s[-1]] for s in strokes]).reshape(-1, 2)  # node 2i, 2i+1
    scale = 1000.0 / max(1e-9, float(np.ptp(ends)))
    d = np.hypot(*(ends[:, None, :] - ends[None, :, :]).transpose(2, 0, 1)) * scale
    big = int(d.max() * 4) + 10
    m = 2 * n + 1
    mat = np.full((m, m), big, dtype=np.int64)
    mat[: 2 * n, : 2 * n] = np.rint(d * 1000).astype(np.int64) + big * 1000
    mat[2 * n, :] = big * 1000
    mat[:, 2 * n] = big * 1000
    for i in range(n):
        mat[2 * i, 2 * i + 1] = mat[2 * i + 1, 2 * i] = 0
    np.fill_diagonal(mat, 0)
    t0 = time.perf_counter()
    tour = elkai.DistanceMatrix(mat.tolist()).solve_tsp(runs=runs)
    dt = time.perf_counter() - t0
    tour = tour[:-1] if tour[0] == tour[-1] else tour
    k = tour.index(2 * n)
    seq = tour[k + 1:] + tour[:k]
    pls = []
    for a, b in zip(seq[0::2], seq[1::2], strict=True):
        assert a // 2 == b // 2, "LKH broke a forced edge"
        pls.append(Placement(a // 2, a % 2 == 1))
    return travel_length(strokes, pls), dt


def vpype_sort(strokes: list[np.ndarray]) -> tuple[float, float]:
    import vpype as vp

    lc = vp.LineCollection([s[:, 0] + 1j * s[:, 1] for s in strokes])
    t0 = time.perf_counter()
    new = vpype_greedy_linesort(lc)
    dt = time.perf_counter() - t0
    return float(new.pen_up_length()[0]), dt


def vpype_greedy_linesort(lc):  # type: ignore[no-untyped-def] - vpype is a bench-only peer
    """vpype_cli's ``linesort``, greedy part (as in vpype_cli/operations.py)."""
    import vpype as vp

    index = vp.LineIndex(lc[1:], reverse=True)
    new = lc.clone([lc[0]])
    while len(index) > 0:
        idx, rev = index.find_nearest(new[-1][-1])
        line = index.pop(idx)
        if line is not None:
            new.append(np.flip(line) if rev else line)
    return new


def random_segments(n: int, rng: np.random.Generator) -> list[np.ndarray]:
    """n segments: a uniform start in a 1000 square, the end ~N(0, 10) away."""
    a = rng.uniform(0, 1000, (n, 2))
    return list(np.stack([a, a + rng.normal(0, 10, (n, 2))], 1))


def instances() -> list[tuple[str, list[np.ndarray]]]:
    out = []
    rng = np.random.default_rng(7)
    for n in (200, 1000, 10000):
        out.append((f"random {n} segments", random_segments(n, rng)))
    for name in ("seal.plt", "text_outline.plt"):
        d = read_file(ROOT / "resources" / "samples" / name)
        sp = Pipeline().field_map(d, Params()).mm_to_units(0.05)
        for fill in ("zigzag", "scanline"):
            st = [s.points for s in hatch(d, fill=fill, spacing_units=sp, angle_deg=15.0)]
            out.append((f"{name} {fill} hatch ({len(st)})", st))
    return out


def seeds_table(seeds: list[int], n: int = 1000, runs: int = 1) -> None:
    """optimized / LKH on random n-segment instances from other seeds (default budget)."""
    print("| seed | strokes | greedy | optimized 1 s (s) | LKH | optimized / LKH |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: |")
    ratios = []
    for seed in seeds:
        st = random_segments(n, np.random.default_rng(seed))
        g = travel_length(st, order_strokes(st, method="greedy"))
        best = []
        for _ in range(runs):
            t0 = time.perf_counter()
            best.append(travel_length(st, order_strokes(st, method="optimized")))
            to = time.perf_counter() - t0
        o = float(np.median(best))
        lk, _ = lkh_cached(st)
        ratios.append(o / lk)
        print(f"| {seed} | {n} | {g:.0f} | {o:.0f} ({to:.2f}) | {lk:.0f} | {o / lk:.3f} |")
    r = np.array(ratios)
    print(f"\noptimized / LKH over {len(r)} seeds: median {np.median(r):.3f}, "
          f"min {r.min():.3f}, max {r.max():.3f}; load average "
          + " ".join(f"{x:.2f}" for x in os.getloadavg()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", type=int, nargs="*",
                    help="only the random 1000-segment instances from these seeds "
                         "(default: the main table, then seeds 1-8)")
    ap.add_argument("--runs", type=int, default=1, help="optimized runs per seed (median)")
    args = ap.parse_args()
    if args.seeds:
        seeds_table(args.seeds, runs=args.runs)
        return
    main_table()
    print()
    seeds_table(list(range(1, 9)), runs=args.runs)


def main_table() -> None:
    """Travel and time of every method on :func:`instances`."""
    print("| instance | strokes | file | vpype greedy | greedy (s) | optimized 1 s (s) | "
          "LKH (s) | optimized / LKH |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, st in instances():
        n = len(st)
        f = travel_length(st, [Placement(i) for i in range(n)])
        t0 = time.perf_counter()
        g = travel_length(st, order_strokes(st, method="greedy"))
        tg = time.perf_counter() - t0
        t0 = time.perf_counter()
        o = travel_length(st, order_strokes(st, method="optimized", time_budget_s=1.0))
        to = time.perf_counter() - t0
        v, _ = vpype_sort(st)
        if n <= 1000:
            lk, tl = lkh_cached(st)
            lk_s, ratio = f"{lk:.0f} ({tl:.1f})", f"{o / lk:.3f}" if lk > 0 else "-"
        else:
            lk_s, ratio = "too large", "-"
        print(f"| {name} | {n} | {f:.0f} | {v:.0f} | {g:.0f} ({tg:.2f}) | {o:.0f} ({to:.2f}) | "
              f"{lk_s} | {ratio} |")


if __name__ == "__main__":
    main()
