"""Growth of the fill, kerf and order stages (issue 21): real drawings side by side
(bench/tile_real.py: the samples and corpus drawings with closed paths, each at true size),
100 k and 1 M points (``--sizes``), CPU seconds per stage (``time.process_time``, best of
``--repeat``) and the growth exponent log(t2 / t1) / log(n2 / n1) between the sizes.

Stages, called as the pipeline calls them with default parameters except:
* fill: ``hatch(fill="zigzag")``, spacing 0.05 mm at true size (2 input units);
* kerf: ``compensate_indexed`` vector, kerf 0.1 mm outside, true-size field; also
  ``_crossings`` alone (the plain ray count) against ``_odd_crossings`` on the same faces;
* order: ``order_strokes(method="optimized")`` on the contours and hatch strokes (input
  units) with no time budget (``--order-budget``, default 1e6 s): the search stops by itself.

``--crossings-only --per-row 1000000``: the even-odd ray test alone, all drawings in one row.

    python bench/bench_scale.py --sizes 100000 1000000
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from tile_real import tiled  # noqa: E402

from galvo_core import kerf  # noqa: E402
from galvo_core.fill import hatch  # noqa: E402
from galvo_core.order import _greedy, _improve, _Problem, order_strokes  # noqa: E402
from galvo_core.params import Params  # noqa: E402
from galvo_core.pipeline import Pipeline  # noqa: E402


def best_cpu(fn, repeat: int):  # type: ignore[no-untyped-def]
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return best, out


def crossings_only(d) -> dict:  # type: ignore[no-untyped-def]
    """The even-odd face test of kerf's general path on all rings of the drawing."""
    import shapely

    rings = [np.asarray(p.points, float) for p in d.paths if p.closed]
    a, b, keep, rep = kerf._odd_edges(rings)
    lines = kerf._edge_runs(a, b, keep, [len(r) - 1 for r in rings])
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(shapely.union_all(lines))))
    pts = shapely.get_coordinates(shapely.point_on_surface(faces))
    t_new, odd = best_cpu(lambda: kerf._odd_crossings(pts, a[rep], b[rep]), 1)
    out = {"faces": len(pts), "edges": int(len(rep)), "odd_crossings_s": t_new}
    if len(pts) * 1.0 * len(rep) < 5e11:  # the plain count: quadratic, skip when hopeless
        t_old, cnt = best_cpu(lambda: kerf._crossings(pts, a[rep], b[rep]), 1)
        out["crossings_s"] = t_old
        out["same_parity"] = bool(np.array_equal(cnt % 2 == 1, odd))
    return out


def measure(n: int, repeat: int, budget: float, per_row: int = 20,
            crossings_alone: bool = False) -> dict:
    d = tiled(n, per_row=per_row)
    pts = sum(len(p.points) for p in d.paths)
    row: dict = {"n": n, "points": pts, "paths": len(d.paths), "per_row": per_row}
    if crossings_alone:
        row["crossings"] = crossings_only(d)
        print(json.dumps(row), file=sys.stderr)
        return row
    t, st = best_cpu(lambda: hatch(d, fill="zigzag", spacing_units=2.0), repeat)
    row.update(fill_s=t, hatch_strokes=len(st), cells=sum(s.cells for s in st))
    params = Params(kerf_mm=0.1, kerf_side="outside", kerf_method="vector")
    fm = Pipeline().field_map(d, params)
    t, (kd, _) = best_cpu(lambda: kerf.compensate_indexed(
        d, kerf_mm=0.1, side="outside", method="vector", fm=fm), repeat)
    row.update(kerf_s=t, kerf_paths=len(kd.paths))
    row["crossings"] = crossings_only(d)
    strokes = [np.asarray(p.points, float) for p in d.paths] + [s.points for s in st]
    closed = [p.closed for p in d.paths] + [False] * len(st)
    t, _ = best_cpu(lambda: order_strokes(strokes, method="greedy", closed=closed), 1)
    row.update(order_strokes=len(strokes), greedy_s=t)
    t, pl = best_cpu(lambda: order_strokes(strokes, method="optimized", closed=closed,
                                           time_budget_s=budget), 1)
    row["order_s"] = t
    prob = _Problem(strokes, closed, None)
    stats: dict = {}
    _improve(prob, _greedy(prob, []), [], time.perf_counter() + budget, stats=stats)
    row["order_stats"] = stats
    print(json.dumps(row), file=sys.stderr)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[100_000, 1_000_000])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--order-budget", type=float, default=1e6)
    ap.add_argument("--per-row", type=int, default=20, help="drawings per row of the tiling")
    ap.add_argument("--crossings-only", action="store_true",
                    help="only the even-odd ray test: _odd_crossings against _crossings")
    ap.add_argument("--out", type=Path, default=ROOT / "bench" / "out" / "scale.json")
    args = ap.parse_args()
    rows = [measure(n, args.repeat, args.order_budget, args.per_row, args.crossings_only)
            for n in args.sizes]
    if args.crossings_only:
        print("| points | drawings per row | faces | edges | _crossings s | _odd_crossings s |")
        print("| ---: | ---: | ---: | ---: | ---: | ---: |")
        for r in rows:
            c = r["crossings"]
            print(f"| {r['points']} | {r['per_row']} | {c['faces']} | {c['edges']} | "
                  f"{c.get('crossings_s', float('nan')):.3f} | {c['odd_crossings_s']:.3f} |")
        return
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(rows, indent=1))
    print("| points | stage | CPU s | growth exponent vs previous size |")
    print("| ---: | --- | ---: | ---: |")
    for i, r in enumerate(rows):
        for key in ("fill_s", "kerf_s", "greedy_s", "order_s"):
            e = ""
            if i:
                p = rows[i - 1]
                e = f"{math.log(r[key] / p[key]) / math.log(r['points'] / p['points']):.2f}"
            print(f"| {r['points']} | {key[:-2]} | {r[key]:.2f} | {e} |")


if __name__ == "__main__":
    main()
