"""How well the curve side of a corner is estimated from whole-unit input (issue 16, fifteenth
session): per design corner (a turn of more than 7 degrees between two segments of a glyph
contour) and per side of it that is a curve, that side's smooth run of input points (the
design flattened at chord height 0.002 and rounded to whole units, as bench/fonts.py does it,
from the corner up to the run's next corner) gives a position and a tangent at the corner by
several estimates; the measure is the distance of the design's corner from the estimated
tangent line (the crossing with the other side moves by about that much). Sides with fewer
than 25 input points are left out.

Estimates: least-squares polynomials in arc length over the first n points of the side
("quadratic 20" is the fit's estimate before the fifteenth session, cut to 60 units of arc as
the fit's window is), their mean, and the mean where the 30-point quadratic's points stay
within 0.75 units of it (the fit since then, ``fit._CORNER_LONG``, ``fit._LONG_RES``).

Usage: python bench/bench_corner_sides.py [--set tuned|unseen] (tuned: DejaVu Sans, Serif,
Sans ExtraLight, Cantarell Regular and Thin at em 400/700/1000/1500; unseen: URW C059, P052
Bold Italic, URW Gothic, Z003, URW Bookman Light Italic at em 1000/2048)
"""

from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from fonts import contours, flatten_segment  # noqa: E402

TEXT = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789&@%?"
_D = "/usr/share/fonts/truetype/dejavu/"
_C = "/usr/share/fonts/opentype/cantarell/"
_U = "/usr/share/fonts/opentype/urw-base35/"
SETS = {
    "tuned": ([_D + "DejaVuSans.ttf", _C + "Cantarell-Regular.otf", _C + "Cantarell-Thin.otf",
               _D + "DejaVuSerif.ttf", _D + "DejaVuSans-ExtraLight.ttf"], [400, 700, 1000, 1500]),
    "unseen": ([_U + "C059-Roman.otf", _U + "P052-BoldItalic.otf", _U + "URWGothic-Book.otf",
                _U + "Z003-MediumItalic.otf", _U + "URWBookman-LightItalic.otf"], [1000, 2048]),
}


def _tangent(s, end: bool) -> np.ndarray:
    pts = list(s[1:])
    if end:
        pts = pts[::-1]
    for q in pts[1:]:
        d = (pts[0] - q) if end else (q - pts[0])
        if math.hypot(*d) > 1e-9:
            return d / math.hypot(*d)
    return np.zeros(2)


def _turn_deg(a, b) -> float:
    return math.degrees(math.acos(float(np.clip(_tangent(a, True) @ _tangent(b, False), -1, 1))))


def side_points(segs, j: int, after: bool, nmax: int = 120) -> np.ndarray:
    """The rounded input points of the smooth run from corner j (the start of segs[j]) away
    from it: along segs[j], ... (``after``) or back along segs[j - 1], ...; at most nmax."""
    n = len(segs)
    out: list[np.ndarray] = []
    k = j if after else (j - 1) % n
    for _ in range(n):
        s = segs[k]
        p = flatten_segment(s, 0.002)
        p = p if after else p[::-1]
        out.append(p if not out else p[1:])
        nk = (k + 1) % n if after else (k - 1) % n
        a, b = (s, segs[nk]) if after else (segs[nk], s)
        if s[0] == "line" or _turn_deg(a, b) > 7 or sum(len(x) for x in out) > 4 * nmax:
            break
        k = nk
    P = np.round(np.vstack(out))
    P = P[np.r_[True, (P[1:] != P[:-1]).any(axis=1)]]
    return P[:nmax]


def poly_estimate(P: np.ndarray, deg: int, n: int, arc_cap: float | None = None):
    """Position, unit tangent and largest residual of a degree-``deg`` least-squares fit in arc
    length over the first n points of P (cut to ``arc_cap`` units of arc, at least 6 points)."""
    P = P[:n]
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(P, axis=0).T))]
    if arc_cap is not None:
        m = max(6, int((s <= arc_cap).sum()))
        P, s = P[:m], s[:m]
    cx, cy = np.polyfit(s, P[:, 0], deg), np.polyfit(s, P[:, 1], deg)
    res = float(np.hypot(np.polyval(cx, s) - P[:, 0], np.polyval(cy, s) - P[:, 1]).max())
    t = np.array([cx[-2], cy[-2]])
    return np.array([cx[-1], cy[-1]]), t / math.hypot(*t), res


def _mean(a, b):
    t = a[1] + b[1]
    return 0.5 * (a[0] + b[0]), t / math.hypot(*t)


def estimates(P: np.ndarray) -> dict[str, tuple]:
    q20 = poly_estimate(P, 2, 20, 60.0)
    q30 = poly_estimate(P, 2, 30)
    gated = _mean(q20, q30) if len(P) > 20 and q30[2] <= 0.75 else q20[:2]
    return {
        "quadratic, 20 points (before)": q20[:2],
        "quadratic, 30 points": q30[:2],
        "quadratic, 40 points": poly_estimate(P, 2, 40)[:2],
        "cubic, 60 points": poly_estimate(P, 3, 60)[:2],
        "mean of 20 and 30 points": _mean(q20, q30),
        "... 30 only within 0.75 (the fit now)": gated,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--set", choices=sorted(SETS), default="tuned")
    a = ap.parse_args()
    files, ems = SETS[a.set]
    errs: dict[str, list[float]] = {}
    for f in files:
        for em in ems:
            for segs in contours(f, TEXT, float(em)):
                for j in range(len(segs)):
                    if _turn_deg(segs[j - 1], segs[j]) <= 7:
                        continue
                    corner = np.asarray(segs[j][1], dtype=float)
                    for after, s in ((False, segs[j - 1]), (True, segs[j])):
                        if s[0] == "line":
                            continue
                        P = side_points(segs, j, after)
                        if len(P) < 25:
                            continue
                        for name, (p, t) in estimates(P).items():
                            d = corner - p
                            errs.setdefault(name, []).append(abs(d[0] * t[1] - d[1] * t[0]))
    n = len(next(iter(errs.values())))
    print(f"set {a.set}: {n} curve sides of corners")
    print("| estimate | p50 | p90 | p99 | max | over 0.4 |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for name, v in errs.items():
        x = np.array(v)
        print(f"| {name} | {np.percentile(x, 50):.3f} | {np.percentile(x, 90):.3f} | "
              f"{np.percentile(x, 99):.3f} | {x.max():.3f} | {(x > 0.4).sum()} |")


if __name__ == "__main__":
    main()
