"""Where the distance to the true curve comes from (issue 16, third round): per style, the
worst places of our fit on whole-unit typeface outlines, what the design has there, and what
is reachable.

For each place (a point of the plane where our fit is far from the true design curve):
* kind: what the design has there (the design segment nearest to the place, and the joint
  within ``JOINT`` units along it: line-line / curve-line / curve-curve, corner (turn > 7°)
  or smooth, or inside a line / a curve);
* fit: the local both-ways distance between our fit and the true curve (the true curve's
  points within ``R`` units of the place to the whole fit, the fit's points within ``R`` to
  the whole true curve);
* poly: the same for the polyline through the rounded input points;
* oracle: a lower bound for any method that sees only the input, where one exists. At a
  design vertex between two lines (each written as its two rounded ends), every position
  of that vertex inside the rounding square of its input point gives the same input: for
  any output O and any two such designs D', D'', max(H(O, D'), H(O, D'')) >= H(D', D'')/2
  (triangle inequality of the Hausdorff distance H), so no method can be closer than half
  the largest H between two designs of that family, in the worst case over the designs
  consistent with the input. Measured with the vertex (and, on a line between two such
  vertices, both of its vertices) at the corners and centre of their squares, H local
  (the moved segments, sampled every 0.01 unit). Elsewhere "–" (curves: the dense points
  pin the design down to well under the rounding, no simple bound).

Worst excess (``--excess``, eighth session): per row, every place where our fit is farther
than 0.6 unit from the true curve, with its excess: fit minus max(0.6, rounded polyline) at
that place (the places where the fit is farther from the design than the rounded input it
was given, and farther than the issue's 0.6); per row the worst excess, the number of places
over 0.02, the number of places over 0.6 where the rounded polyline is under 0.6 (any
excess: ours alone; ninth session) and the worst places (``--top``).

Usage: python bench/bench_precision_worst.py [--styles sans,...] [--top 10] [--json F]
       python bench/bench_precision_worst.py --set heldout [--em 700] [--text T] [--font F.otf]
       python bench/bench_precision_worst.py --excess [--set heldout | --em 400 | --font F]
                                              [--chord H] [--code DIR]
(the font options as in bench_precision.py; see fonts.py; ``--chord H``: the curves flattened
at chord height H before rounding, as bench_precision.py; ``--code DIR``: import galvo_core
from another checkout, e.g. /work/main, to compare)
"""

from __future__ import annotations

import argparse
import importlib
import itertools
import json
import math
import os
import sys

import numpy as np

_CODE = next((sys.argv[i + 1] for i, v in enumerate(sys.argv[:-1]) if v == "--code"), None)
sys.path.insert(0, os.path.abspath(_CODE) if _CODE else os.path.join(os.path.dirname(__file__),
                                                                     ".."))
sys.path.insert(0, os.path.dirname(__file__))
# (imported first: bench_precision puts this checkout first on sys.path, --code must win)
importlib.import_module("galvo_core.fit")
from bench_precision import add_chord_option, chord_label, fitted_dense  # noqa: E402
from fonts import (  # noqa: E402
    TEXT,
    add_font_options,
    contours,
    flatten_segment,
    font_errors,
    font_file,
    font_options,
    glyph_set,
    run_label,
    style_name,
)

from galvo_core import fit as fitmod  # noqa: E402
from galvo_core.geometry import point_polyline_distance  # noqa: E402

R = 2.0  # local window radius (units)
JOINT = 3.0  # a place within this arc length of a design joint is "at" it
SEP = 6.0  # two places at least this far apart


def labelled_truth(segs):
    """The true curve (chord 1e-3) and per vertex its design segment index."""
    pts, lab = [], []
    for i, s in enumerate(segs):
        p = flatten_segment(s, 1e-3)
        if i:
            p = p[1:]
        pts.append(p)
        lab.append(np.full(len(p), i))
    return np.vstack(pts), np.concatenate(lab)


def tangent(s, end: bool) -> np.ndarray:
    """The unit tangent at the segment's end (or start): the first control point that is
    not on the end point gives it (a curve's control point may coincide with its end)."""
    pts = list(s[1:])
    if end:
        pts = pts[::-1]
    d = np.zeros(2)
    for q in pts[1:]:
        d = (pts[0] - q) if end else (q - pts[0])
        if d.any():
            break
    n = math.hypot(*d)
    return d / n if n else d


def seg_len(s) -> float:
    if s[0] == "line":
        return float(math.hypot(*(s[2] - s[1])))
    p = flatten_segment(s, 1e-3)
    return float(np.hypot(*np.diff(p, axis=0).T).sum())


def turn_deg(a, b) -> float:
    ta, tb = tangent(a, True), tangent(b, False)
    c = float(np.clip(ta @ tb, -1, 1))
    return math.degrees(math.acos(c))


def local_dist(place, A, B) -> float:
    """Both-ways distance of A and B near ``place``: A's points within R to B, B's to A
    (both resampled every 0.05 unit or closer)."""
    out = 0.0
    for X, Y in ((A, B), (B, A)):
        X = X[_near(X, place, R + 1.0)]
        if len(X) < 2:
            continue
        X = _sample(X, 0.05)
        near = X[np.hypot(*(X - place).T) <= R]
        if len(near):
            out = max(out, float(point_polyline_distance(near, Y).max()))
    return out


def _near(poly, place, r):
    """Vertices of ``poly`` of the segments that come within r of ``place`` (a run)."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    den = np.maximum((ab * ab).sum(axis=1), 1e-300)
    t = np.clip(((place - a) * ab).sum(axis=1) / den, 0, 1)
    d = np.hypot(*(a + t[:, None] * ab - place).T)
    hit = np.flatnonzero(d <= r)
    keep = np.zeros(len(poly), dtype=bool)
    keep[hit] = True
    keep[hit + 1] = True
    return keep


def _sample(poly, step=0.01):
    parts = []
    for a, b in zip(poly[:-1], poly[1:], strict=True):
        n = max(1, math.ceil(math.hypot(*(b - a)) / step))
        t = np.linspace(0, 1, n + 1)[:, None]
        parts.append(a + t * (b - a))
    return np.vstack(parts)


def _hausdorff(P, Q) -> float:
    a = float(point_polyline_distance(_sample(P), Q).max())
    b = float(point_polyline_distance(_sample(Q), P).max())
    return max(a, b)


def oracle_vertex_moves(segs, verts) -> float:
    """Half the largest local Hausdorff distance between two designs that differ only in
    the positions of the design vertices ``verts`` (joint indices j: between segs[j-1] and
    segs[j], both lines) inside the rounding squares of their rounded positions."""
    n = len(segs)
    verts = sorted(set(verts))
    # the polyline of the moved vertices and their neighbours
    chain = sorted(set(v for v in verts) | {(v - 1) % n for v in verts} | {(v + 1) % n
                                                                          for v in verts})
    pos = {j: segs[j][1] for j in chain}  # joint j = start of segs[j]

    def design(moves):
        p = dict(pos)
        for v, d in zip(verts, moves, strict=True):
            p[v] = pos[v] + d
        # local polylines: each moved vertex with its two neighbours
        return [np.array([p[(v - 1) % n], p[v], p[(v + 1) % n]]) for v in verts]

    rng = []
    for v in verts:
        c = np.round(pos[v])
        ds = [c + np.array(s) * (0.5 - 1e-9) - pos[v]
              for s in itertools.product((-1, 1), repeat=2)] + [c - pos[v]]
        rng.append(ds)
    confs = list(itertools.product(*rng))
    polys = [design(m) for m in confs]
    best = 0.0
    for i in range(len(polys)):
        for j in range(i + 1, len(polys)):
            h = max(_hausdorff(a, b) for a, b in zip(polys[i], polys[j], strict=True))
            best = max(best, h)
    return 0.5 * best


def classify(segs, lab_seg, arc_pos, seglens):
    """Kind of the place on design segment ``lab_seg`` at arc ``arc_pos`` from its start,
    and the line-line vertices an oracle bound can move (joint indices)."""
    n = len(segs)
    s = segs[lab_seg]
    L = seglens[lab_seg]
    joints = []
    if arc_pos <= JOINT:
        joints.append(lab_seg)
    if L - arc_pos <= JOINT:
        joints.append((lab_seg + 1) % n)
    if joints:
        j = min(joints, key=lambda j: arc_pos if j == lab_seg else L - arc_pos)
        a, b = segs[(j - 1) % n], segs[j]
        t = turn_deg(a, b)
        ka = "line" if a[0] == "line" else "curve"
        kb = "line" if b[0] == "line" else "curve"
        kind = "-".join(sorted([ka, kb])).replace("line-curve", "curve-line")
        short = min(seglens[(j - 1) % n], seglens[j])
        what = f"{kind} {'corner' if t > 7 else 'smooth'} {t:.0f}° (shorter side {short:.1f})"
        orc = [j] if (a[0] == "line" and b[0] == "line") else []
        return what, orc
    if s[0] == "line":
        d = s[2] - s[1]
        ang = math.degrees(math.atan2(d[1], d[0])) % 180
        ends = [j for j in (lab_seg, (lab_seg + 1) % n)
                if segs[(j - 1) % n][0] == "line" and segs[j][0] == "line"]
        return f"inside a 2-point design line (length {L:.1f}, {ang:.0f}°)", ends
    return "inside a curve", []


#: a place's excess counts when over this (the target: no place over it)
EXCESS_TOL = 0.02
#: the issue's distance bound: a place closer than this is no excess whatever the input
ISSUE_BOUND = 0.6


def design_position(p: np.ndarray, T: np.ndarray, lab: np.ndarray) -> tuple[int, float]:
    """The nearest point of the true curve T (labels ``lab``) to p: its design segment and
    its arc position along that segment."""
    a, ab = T[:-1], np.diff(T, axis=0)
    den = np.maximum((ab * ab).sum(axis=1), 1e-300)
    t = np.clip(((p - a) * ab).sum(axis=1) / den, 0, 1)
    it = int(np.argmin(np.hypot(*(a + t[:, None] * ab - p).T)))
    sgi = int(lab[it + 1])
    arc = np.r_[0, np.cumsum(np.hypot(*ab.T))]
    s0 = int(np.flatnonzero(lab == sgi)[0]) - (1 if sgi else 0)
    return sgi, float(arc[it] + t[it] * math.sqrt(den[it]) - arc[max(s0, 0)])


def fitted_contours(style: str, em: float, text: str, chord: float):
    """The style's whole-unit glyph set fitted at the defaults: (fitted paths, the style's
    name, and per contour
    (index, design segments, true curve T, its labels, dense fit F, closed rounded input,
    places T then F, their distances to the other curve))."""
    gs = glyph_set(style, em=em, whole=True, text=text, chord=chord)
    cs = contours(font_file(style), text, em)
    fps = fitmod.fit_paths(gs.points, [True] * len(gs.points))

    def each():
        for ci, (segs, fp, pts) in enumerate(zip(cs, fps, gs.points, strict=True)):
            T, lab = labelled_truth(segs)
            F = fitted_dense(fp)
            Rp = np.vstack([pts, pts[:1]]) if (pts[0] != pts[-1]).any() else pts
            errs = np.concatenate([point_polyline_distance(T, F),
                                   point_polyline_distance(F, T)])
            yield ci, segs, T, lab, F, Rp, np.vstack([T, F]), errs

    return fps, gs.style, each()


def excess_places(style: str, em: float = 1000.0, text: str = TEXT, chord: float = 0.002):
    """Every place where the fit is farther than ISSUE_BOUND from the true curve (places at
    least R apart, worst first), with the local fit and rounded-polyline distances there and
    the excess ``fit - max(ISSUE_BOUND, poly)``. Returns (rows, segments)."""
    fps, name, per_contour = fitted_contours(style, em, text, chord)
    rows = []
    for ci, segs, T, lab, F, Rp, locs, errs in per_contour:
        chosen: list[np.ndarray] = []
        for k in np.argsort(-errs):
            if errs[k] <= ISSUE_BOUND:
                break
            p = locs[k]
            if any(math.hypot(*(p - c)) < R for c in chosen):
                continue
            chosen.append(p)
            f, q = local_dist(p, F, T), local_dist(p, Rp, T)
            rows.append({"style": name, "em": em, "contour": ci, "x": float(p[0]),
                         "y": float(p[1]), "fit": f, "poly": q,
                         "excess": f - max(ISSUE_BOUND, q), "segs": segs, "lab": lab, "T": T})
    for r in rows:  # the kind of the place (its design segment and the joints near it)
        T, lab, segs, p = r.pop("T"), r.pop("lab"), r.pop("segs"), np.array([r["x"], r["y"]])
        sgi, apos = design_position(p, T, lab)
        r["kind"] = classify(segs, sgi, apos, [seg_len(s) for s in segs])[0]
    rows.sort(key=lambda r: -r["excess"])
    return rows, sum(len(f.segments) for f in fps)


def excess_main(a, styles, text, ems) -> None:
    label = chord_label(run_label(text, ems), a.chord)
    if a.code:
        label = (label + "; " if label else "") + f"code {a.code}"
    if label:
        print(label)
    allrows, summary = [], []
    for em, st in itertools.product(ems, styles):
        with font_errors(st):
            rows, nseg = excess_places(st, em, text, a.chord)
        name = style_name(st) + (f" em {em:g}" if len(ems) > 1 else "")
        for r in rows:
            r["glyph"] = glyph_of(r["x"], st, em, text)
            r["row"] = name
        worst = max([0.0] + [r["excess"] for r in rows])
        over = sum(r["excess"] > EXCESS_TOL for r in rows)
        # the places over the bound where the rounded input itself is within it (ours alone)
        under = sum(r["excess"] > 0.0 and r["poly"] < ISSUE_BOUND for r in rows)
        summary.append((name, nseg, len(rows), over, under, worst))
        allrows += rows
        print(f"{name}: segments {nseg}, places over {ISSUE_BOUND} {len(rows)}, "
              f"excess > {EXCESS_TOL} {over}, worst excess {worst:.3f}, "
              f"over with polyline under {ISSUE_BOUND} {under}", file=sys.stderr, flush=True)
    print(f"| row | segments | places over {ISSUE_BOUND} | places with excess > {EXCESS_TOL} "
          f"| worst excess | over {ISSUE_BOUND} where the polyline is under it |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for name, nseg, n, over, under, worst in summary:
        print(f"| {name} | {nseg} | {n} | {over} | {worst:.3f} | {under} |")
    bad = sorted((r for r in allrows if r["excess"] > EXCESS_TOL), key=lambda r: -r["excess"])
    if bad:
        print()
        print("| row | glyph | at (x, y) | kind | fit | rounded polyline | excess |")
        print("| --- | --- | --- | --- | ---: | ---: | ---: |")
        for r in bad[: a.top * max(1, len(summary))]:
            print(f"| {r['row']} | {r['glyph']} | {r['x']:.1f}, {r['y']:.1f} | {r['kind']} | "
                  f"{r['fit']:.3f} | {r['poly']:.3f} | {r['excess']:.3f} |")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(allrows, f, indent=1)


def worst_places(style: str, top: int, em: float = 1000.0, text: str = TEXT,
                 chord: float = 0.002):
    _, name, per_contour = fitted_contours(style, em, text, chord)
    cands = []
    for ci, segs, T, lab, F, Rp, locs, errs in per_contour:
        order = np.argsort(-errs)
        chosen = []
        for k in order[:4000]:
            if errs[k] < 0.3:
                break
            p = locs[k]
            if any(math.hypot(*(p - c[1])) < SEP for c in chosen):
                continue
            chosen.append((errs[k], p))
            if len(chosen) >= top:
                break
        seglens = [seg_len(s) for s in segs]
        for e, p in chosen:
            sgi, apos = design_position(p, T, lab)
            cands.append((float(e), ci, p, sgi, apos, segs, seglens, F, T, Rp))
    cands.sort(key=lambda c: -c[0])
    rows = []
    used = []
    for _e, ci, p, sgi, apos, segs, seglens, F, T, Rp in cands:
        if any(u[0] == ci and math.hypot(*(p - u[1])) < SEP for u in used):
            continue
        used.append((ci, p))
        kind, orc = classify(segs, sgi, apos, seglens)
        rows.append({
            "style": name, "em": em, "contour": ci, "x": float(p[0]), "y": float(p[1]),
            "kind": kind,
            "fit": local_dist(p, F, T), "poly": local_dist(p, Rp, T),
            "oracle": oracle_vertex_moves(segs, orc) if orc else None,
        })
        if len(rows) >= top:
            break
    return rows


def glyph_of(x: float, style: str, em: float = 1000.0, text: str = TEXT) -> str:
    from fontTools.ttLib import TTFont

    font = TTFont(font_file(style))
    gs = font.getGlyphSet()
    cmap = font.getBestCmap()
    scale = em / font["head"].unitsPerEm
    x0 = 0.0
    for ch in text:
        w = gs[cmap[ord(ch)]].width * scale
        if x < x0 + w:
            return ch
        x0 += w
    return text[-1]


def main() -> None:
    ap = argparse.ArgumentParser()
    add_font_options(ap)
    ap.add_argument("--top", type=int, default=10)
    ap.add_argument("--json")
    add_chord_option(ap)
    ap.add_argument("--excess", action="store_true",
                    help="per row the worst excess over max(0.6, rounded polyline)")
    ap.add_argument("--code", help="import galvo_core from this checkout")
    a = ap.parse_args()
    styles, text, ems = font_options(a)
    fitmod.warm_up()
    if a.excess:
        excess_main(a, styles, text, ems)
        return
    allrows = []
    label = chord_label(run_label(text, ems), a.chord)
    if label:
        print(label)
    print("| style | glyph | at (x, y) | kind | fit | rounded polyline | oracle bound |")
    print("| --- | --- | --- | --- | ---: | ---: | ---: |")
    for em, st in itertools.product(ems, styles):
        with font_errors(st):
            rows = worst_places(st, a.top, em, text, a.chord)
        name = style_name(st) + (f" em {em:g}" if len(ems) > 1 else "")
        for r in rows:
            r["glyph"] = glyph_of(r["x"], st, em, text)
            o = "–" if r["oracle"] is None else f"{r['oracle']:.3f}"
            print(f"| {name} | {r['glyph']} | {r['x']:.1f}, {r['y']:.1f} | {r['kind']} | "
                  f"{r['fit']:.3f} | {r['poly']:.3f} | {o} |", flush=True)
        allrows += rows
    if a.json:
        with open(a.json, "w") as f:
            json.dump(allrows, f, indent=1)


if __name__ == "__main__":
    main()
