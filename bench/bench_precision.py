"""Precision-aware fit on typeface outlines (issue 16): segments against the typeface's own
count, distance to the true (unrounded) design curve both ways, violations of the bound, time.

Usage: python bench/bench_precision.py [--styles sans,serif] [--json out.json]
       python bench/bench_precision.py --set heldout      # typefaces the fit was not tuned on
       python bench/bench_precision.py --font F.otf [--font G.ttf] [--text T] [--em 700,1500]
(default: the six DejaVu STYLES, TEXT, em 1000; --set heldout: HELDOUT typefaces, incl. two
OpenType/CFF ones with cubic outlines, HELDOUT_TEXT, ems 700 and 1500; see fonts.py)
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.dirname(__file__))

from fonts import (  # noqa: E402
    TEXT,
    add_font_options,
    curve_distance,
    font_errors,
    font_options,
    glyph_set,
    run_label,
    style_name,
)

from galvo_core import fit as fitmod  # noqa: E402
from galvo_core.geometry import flatten_cubic  # noqa: E402


def fitted_dense(fp, h: float = 0.002) -> np.ndarray:
    parts = []
    for s in fp.segments:
        parts.append(flatten_cubic(s.points, h) if s.kind == "cubic" else s.points)
    return np.vstack([parts[0]] + [p[1:] for p in parts[1:]])


def run(style: str, whole: bool, em: float, text: str = TEXT, *, chord: float = 0.002,
        **kw) -> dict:
    gs = glyph_set(style, em=em, whole=whole, text=text, chord=chord)
    fitmod.warm_up()
    t0 = time.process_time()
    fps = fitmod.fit_paths(gs.points, [True] * len(gs.points), **kw)
    secs = time.process_time() - t0
    nseg = sum(len(f.segments) for f in fps)
    dense_fits = [fitted_dense(f) for f in fps]
    dist = max(curve_distance(d, t) for d, t in zip(dense_fits, gs.truth, strict=True))
    # the same, away from the design's line-line corners (where no method can promise
    # better than the rounding: see fonts.GlyphSet.line_corners)
    away = max(curve_distance(d, t, c) for d, t, c in
               zip(dense_fits, gs.truth, gs.line_corners, strict=True))
    viol = 0
    worst_excess = 0.0
    for f, p in zip(fps, gs.points, strict=True):
        rep = fitmod.check_fit(p, f, kw.get("e_per", 0.02), kw.get("eps_line", 0.02),
                               report=True)
        if rep["violation"]:
            viol += 1
            worst_excess = max(worst_excess, max(rep["max_in_to_curve"],
                                                 rep["max_curve_to_polyline"]) - rep["bound"])
    return {
        "style": gs.style, "text": text, "whole": whole, "em": em,
        "points": int(sum(len(p) for p in gs.points)),
        "own": gs.own_segments, "segments": nseg, "ratio": nseg / gs.own_segments,
        "dist_true": dist, "dist_away": away, "violations": viol, "excess": worst_excess,
        "cpu_s": secs,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    add_font_options(ap)
    ap.add_argument("--json")
    ap.add_argument("--e-per", type=float)
    ap.add_argument("--eps-line", type=float)
    ap.add_argument("--chord", type=float, default=0.002,
                    help="chord height (units) the curves are flattened to before rounding: "
                         "0.002 dense (the default), 0.1-1 as coarse CAD/plotter exports write")
    ap.add_argument("--whole-only", action="store_true", help="leave out the exact rows")
    a = ap.parse_args()
    styles, text, ems = font_options(a)
    kw = {}
    if a.e_per:
        kw["e_per"] = a.e_per
    if a.eps_line:
        kw["eps_line"] = a.eps_line
    rows = []
    label = run_label(text, ems)
    if a.chord != 0.002:
        label = (label + "; " if label else "") + f"curves flattened to chord height {a.chord:g}"
    if label:
        print(label)
    print("| style | input | points | own | segments | x own | to true curve "
          "| away from line-line corners | violations | cpu s |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for whole in (True,) if a.whole_only else (True, False):
        for em in ems:
            for st in styles:
                with font_errors(st):
                    r = run(st, whole, em, text, chord=a.chord, **kw)
                rows.append(r)
                name = style_name(st) + (f" em {em:g}" if len(ems) > 1 else "")
                print(f"| {name} | {'whole' if whole else 'exact'} | {r['points']} | {r['own']} | "
                      f"{r['segments']} | {r['ratio']:.2f} | {r['dist_true']:.3f} | "
                      f"{r['dist_away']:.3f} | "
                      f"{r['violations']} | {r['cpu_s']:.2f} |", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
