"""One place of the whole-unit fit, close up (issue 16): the design, the rounded input, the
thinned vertices (where the thinning kept them, where the corner/smooth-vertex estimates moved
them) and the fitted segments within ``--r`` units of (x, y), with the local both-ways distance
of the fit and of the rounded polyline to the true curve there.

Usage: python bench/show_place.py --font F --em E --text T --x X --y Y [--r 8] [--chord H]
(``--font``: a style name of fonts.py or a TTF/OTF path; the contour nearest to (x, y) of the
text's glyphs is fitted alone at the defaults; ``--code DIR`` imports galvo_core from DIR)
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import os
import sys

import numpy as np

_CODE = next((sys.argv[i + 1] for i, v in enumerate(sys.argv[:-1]) if v == "--code"), None)
sys.path.insert(0, os.path.abspath(_CODE) if _CODE else os.path.join(os.path.dirname(__file__),
                                                                     ".."))
sys.path.insert(0, os.path.dirname(__file__))
importlib.import_module("galvo_core.fit")
from bench_precision import fitted_dense  # noqa: E402
from bench_precision_worst import local_dist  # noqa: E402
from fonts import contours, flatten_segment, font_file, glyph_set  # noqa: E402

from galvo_core import fit as fitmod  # noqa: E402
from galvo_core.geometry import point_polyline_distance  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--font", required=True)
    ap.add_argument("--em", type=float, default=1000.0)
    ap.add_argument("--text", required=True)
    ap.add_argument("--x", type=float, required=True)
    ap.add_argument("--y", type=float, required=True)
    ap.add_argument("--r", type=float, default=8.0)
    ap.add_argument("--chord", type=float, default=0.002)
    ap.add_argument("--code")
    a = ap.parse_args()
    place = np.array([a.x, a.y])
    gs = glyph_set(a.font, em=a.em, whole=True, text=a.text, chord=a.chord)
    cs = contours(font_file(a.font), a.text, a.em)
    ci = int(np.argmin([point_polyline_distance(place[None], t)[0] for t in gs.truth]))
    segs, pts, T = cs[ci], gs.points[ci], gs.truth[ci]
    cap = {}
    orig = fitmod._on_the_design

    def spy(W, K, Q, arc, t_in, t_out, smooth, quant, tlen, eps, *rest):
        orig(W, K, Q, arc, t_in, t_out, smooth, quant, tlen, eps, *rest)
        cap.update(W=W.copy(), K=K.copy(), Q=Q.copy(), smooth=smooth.copy(),
                   t_in=t_in.copy(), t_out=t_out.copy())

    fitmod._on_the_design = spy
    # the corner estimates' locals (a patched copy of _corners_on_the_design)
    src = inspect.getsource(fitmod._corners_on_the_design)
    src = src.replace("    _split_corners(W, K, vi, vo,",
                      "    _CAP.update(dict(locals()))\n    _split_corners(W, K, vi, vo,", 1)
    ccap: dict = {}
    fitmod._CAP = ccap
    exec(compile(src, "corners", "exec"), fitmod.__dict__)
    fp = fitmod.fit_paths([pts], [True])[0]
    F = fitted_dense(fp)
    Rp = np.vstack([pts, pts[:1]]) if (pts[0] != pts[-1]).any() else pts
    print(f"contour {ci}: fit local {local_dist(place, F, T):.3f}, rounded polyline "
          f"{local_dist(place, Rp, T):.3f}; segments {len(fp.segments)} (design {len(segs)})")
    print("design segments near:")
    for i, s in enumerate(segs):
        d = flatten_segment(s, 1e-3)
        if np.hypot(*(d - place).T).min() <= a.r:
            ctl = " ".join(f"({p[0]:.2f},{p[1]:.2f})" for p in s[1:])
            print(f"  d{i} {s[0]} {ctl}")
    W = cap.get("W", pts)
    print("input points near (index, x, y, distance to design):")
    near = np.flatnonzero(np.hypot(*(W - place).T) <= a.r)
    dd = point_polyline_distance(W[near], T) if len(near) else []
    for i, d in zip(near, dd, strict=True):
        print(f"  {i} ({W[i, 0]:.0f},{W[i, 1]:.0f}) {d:.3f}")
    if cap:
        K, Q, sm = cap["K"], cap["Q"], cap["smooth"]
        print("thinned vertices near (j, K, input, moved to, dist of moved to design, smooth,"
              " t_in, t_out):")
        for j in np.flatnonzero(np.hypot(*(W[K] - place).T) <= a.r * 1.5):
            q = Q[j]
            d = point_polyline_distance(q[None], T)[0]
            print(f"  {j} K={K[j]} ({W[K[j], 0]:.0f},{W[K[j], 1]:.0f}) -> ({q[0]:.3f},"
                  f"{q[1]:.3f}) {d:.3f} {'smooth' if sm[j] else 'CORNER'} "
                  f"in ({cap['t_in'][j][0]:.3f},{cap['t_in'][j][1]:.3f}) "
                  f"out ({cap['t_out'][j][0]:.3f},{cap['t_out'][j][1]:.3f})")
    if ccap:
        c = ccap
        print("corner estimates near (vo, K, est, p_in t_in ok_in r_in | p_out t_out ok_out r_out,"
              " lone_in/out, both, tip, sharp):")
        for m in np.flatnonzero(np.hypot(*(W[K[c["vo"]]] - place).T) <= a.r * 1.5):
            f = lambda v: f"({v[0]:.3f},{v[1]:.3f})"  # noqa: E731
            print(f"  {c['vo'][m]} K={K[c['vo'][m]]} est {f(c['est'][m])} | {f(c['p_in'][m])} "
                  f"{f(c['t_in'][m])} {c['ok_in'][m]} {c['r_in'][m]:.3f} | {f(c['p_out'][m])} "
                  f"{f(c['t_out'][m])} {c['ok_out'][m]} {c['r_out'][m]:.3f} | "
                  f"{c['lone_in'][m]} {c['lone_out'][m]} {c['both'][m]} {c['tip'][m]} "
                  f"{c['sharp'][m]}; window in {c['lo_i'][m]}..{K[c['vi'][m]]} out "
                  f"{K[c['vo'][m]]}..{c['hi_o'][m]}")
    print("fitted segments near (kind, first..last input, points, end's distance to design):")
    for s in fp.segments:
        p = s.points
        samp = flatten_segment(("cubic", *p), 0.01) if s.kind == "cubic" else p
        if np.hypot(*(samp - place).T).min() <= a.r:
            ctl = " ".join(f"({x:.3f},{y:.3f})" for x, y in p)
            de = point_polyline_distance(p[[0, -1]], T)
            far = point_polyline_distance(samp, T).max()
            print(f"  {s.kind} {s.first}..{s.last} {ctl} ends {de[0]:.3f} {de[1]:.3f}, "
                  f"farthest {far:.3f}")
    print(f"(local distances within 2 units of the place {a.x}, {a.y})")


if __name__ == "__main__":
    main()
