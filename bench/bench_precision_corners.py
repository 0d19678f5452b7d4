"""Design corners on an exact grid (issue 16, held-out check): at em = unitsPerEm (scale 1)
every design point of a TrueType outline is a whole unit, so the rounded input holds each
design corner exactly and only the curve samples between are rounded. The fit's corner
moves (galvo_core.fit `_corners_on_the_design`, `_joints_on_the_design`) must then not
push such a corner off. At em = unitsPerEm / 2 the design points are on a half-unit grid
(the rounding of the .5 ones is the only loss at corners).

Per style and em: the design corners (joints turning more than 7°, as in
bench_precision_worst), how many of them are on the whole-unit grid (the input has them
exactly), and of the fit there: the distance from the design corner point to the fitted
curve (max over the corners on the grid, max, 99th percentile, count above 0.05 / 0.3 /
0.6 units), the local both-ways distance (bench_precision_worst.local_dist, radius R)
and that of the polyline through the rounded input for comparison; then the worst
corners with their kind.

Usage: python bench/bench_precision_corners.py [--set heldout] [--styles ..] [--font F]
       [--text T] [--grid 1,0.5] [--top 8]
(--grid: ems as fractions of each font's unitsPerEm; the other font options as in
bench_precision.py)
"""

from __future__ import annotations

import argparse
import itertools
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.dirname(__file__))

from bench_precision import fitted_dense  # noqa: E402
from bench_precision_worst import glyph_of, local_dist, seg_len, turn_deg  # noqa: E402
from fonts import (  # noqa: E402
    add_font_options,
    contours,
    font_errors,
    font_file,
    font_options,
    glyph_set,
    style_name,
)

from galvo_core import fit as fitmod  # noqa: E402
from galvo_core.geometry import point_polyline_distance  # noqa: E402

CORNER_DEG = 7.0


def upem(style: str) -> int:
    from fontTools.ttLib import TTFont

    return int(TTFont(font_file(style))["head"].unitsPerEm)


def corners_of(segs):
    """(joint index, turn in degrees, kind) of each design corner of a closed contour."""
    n = len(segs)
    out = []
    for j in range(n):
        a, b = segs[(j - 1) % n], segs[j]
        if a[0] == "line" and np.array_equal(a[1], a[2]):
            continue  # a zero-length design line: its neighbours' joint is the corner
        if b[0] == "line" and np.array_equal(b[1], b[2]):
            b = segs[(j + 1) % n]
        t = turn_deg(a, b)
        if t <= CORNER_DEG:
            continue
        ka = "line" if a[0] == "line" else "curve"
        kb = "line" if b[0] == "line" else "curve"
        out.append((j, t, "-".join(sorted([ka, kb])).replace("line-curve", "curve-line")))
    return out


def _from_far_end(poly: np.ndarray, place: np.ndarray) -> np.ndarray:
    """A closed polyline (last point = first) started at its vertex farthest from
    ``place``, so that its part near ``place`` is one run (local_dist joins the near
    vertices in array order: across the seam it would draw a chord)."""
    ring = poly[:-1] if (poly[0] == poly[-1]).all() else poly
    k = int(np.argmax(np.hypot(*(ring - place).T)))
    ring = np.roll(ring, -k, axis=0)
    return np.vstack([ring, ring[:1]])


def run(style: str, em: float, text: str) -> tuple[dict, list[dict]]:
    gs = glyph_set(style, em=em, whole=True, text=text)
    cs = contours(font_file(style), text, em)
    fps = fitmod.fit_paths(gs.points, [True] * len(gs.points))
    rows = []
    for ci, (segs, fp, pts, T) in enumerate(zip(cs, fps, gs.points, gs.truth, strict=True)):
        F = fitted_dense(fp)
        Rp = np.vstack([pts, pts[:1]])
        ends = np.array([s.points[-1] for s in fp.segments])
        for j, t, kind in corners_of(segs):
            v = segs[j][1]
            rows.append({
                "contour": ci, "x": float(v[0]), "y": float(v[1]), "turn": t, "kind": kind,
                "on_grid": bool((v == np.round(v)).all()),
                "short": min(seg_len(segs[(j - 1) % len(segs)]), seg_len(segs[j])),
                "to_fit": float(point_polyline_distance(v[None], F)[0]),
                "to_joint": float(np.hypot(*(ends - v).T).min()),
                "local_fit": local_dist(v, _from_far_end(F, v), _from_far_end(T, v)),
                "local_poly": local_dist(v, _from_far_end(Rp, v), _from_far_end(T, v)),
            })
    d = np.array([r["to_fit"] for r in rows])
    dg = np.array([r["to_fit"] for r in rows if r["on_grid"]] or [0.0])
    summ = {
        "style": gs.style, "em": em, "corners": len(rows),
        "on_grid": sum(r["on_grid"] for r in rows),
        "grid_max": float(dg.max()), "max": float(d.max()), "p99": float(np.percentile(d, 99)),
        "n005": int((d > 0.05).sum()), "n03": int((d > 0.3).sum()), "n06": int((d > 0.6).sum()),
        "local_fit": max(r["local_fit"] for r in rows),
        "local_poly": max(r["local_poly"] for r in rows),
    }
    return summ, rows


def main() -> None:
    ap = argparse.ArgumentParser()
    add_font_options(ap)
    ap.add_argument("--grid", default="1,0.5",
                    help="ems as fractions of each font's unitsPerEm (default 1,0.5)")
    ap.add_argument("--top", type=int, default=8)
    a = ap.parse_args()
    styles, text, _ems = font_options(a)
    grids = [float(g) for g in a.grid.split(",")]
    fitmod.warm_up()
    print(f"text {text!r}: design corners (turn > {CORNER_DEG:g}°), distance of the design "
          "corner point to the fit")
    print("| style | em | corners | on grid | max on grid | max | p99 | > 0.05 | > 0.3 | > 0.6 "
          "| local fit | local polyline |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    worst = []
    for st, g in itertools.product(styles, grids):
        with font_errors(st):
            em = upem(st) * g
            s, rows = run(st, em, text)
        print(f"| {style_name(st)} | {em:g} | {s['corners']} | {s['on_grid']} "
              f"| {s['grid_max']:.3f} | {s['max']:.3f} "
              f"| {s['p99']:.3f} | {s['n005']} | {s['n03']} | {s['n06']} "
              f"| {s['local_fit']:.3f} | {s['local_poly']:.3f} |", flush=True)
        worst += [dict(r, style=st, em=em) for r in rows]
    worst.sort(key=lambda r: -r["to_fit"])
    print()
    print("| style | em | glyph | corner (x, y) | kind | on grid | to fit | nearest fit joint "
          "| local fit | local polyline |")
    print("| --- | ---: | --- | --- | --- | --- | ---: | ---: | ---: | ---: |")
    for r in worst[:a.top]:
        ch = glyph_of(r["x"], r["style"], r["em"], text)
        print(f"| {style_name(r['style'])} | {r['em']:g} | {ch} "
              f"| {r['x']:.1f}, {r['y']:.1f} | {r['kind']} corner {r['turn']:.0f}° (shorter "
              f"side {r['short']:.1f}) | {'yes' if r['on_grid'] else 'no'} | {r['to_fit']:.3f} "
              f"| {r['to_joint']:.3f} | {r['local_fit']:.3f} | {r['local_poly']:.3f} |")


if __name__ == "__main__":
    main()
