"""Where the extra segments of a whole-unit fit sit (issue 16, cubic typefaces at large ems).

For each contour of a typeface's text (whole units, the fit's defaults): per design segment
(line / quadratic / cubic) how many fitted segments cover it, and for every fitted joint
that falls inside a design segment (not within ``--near`` input points of a design joint)
what made it: a run break of the thinned polyline (a corner by the cos rule, by the length
ratio, a short run, an inflection, the 80-degree split) or the fitter (one curve piece
fitted with several cubics) or a line (a thinned segment outside every run).

Usage: python bench/bench_cff_census.py --styles cantarell,cantarell-thin --em 1500,2048
       [--text T] [--near 3] [--list] [--contours]   # --list: one line per extra joint
"""

from __future__ import annotations

import argparse
import collections
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.dirname(__file__))

from fonts import TEXT, contours, flatten_segment, font_file  # noqa: E402

from galvo_core import fit as fitmod  # noqa: E402
from galvo_core import runs as runsmod  # noqa: E402
from galvo_core.thin import thin_many  # noqa: E402


def contour_points(segs):
    """Whole-unit points of one contour and per point the design segment it came from
    (a design joint point belongs to the segment it starts)."""
    parts, owner = [], []
    for k, s in enumerate(segs):
        p = flatten_segment(s, 0.002)
        if k:
            p = p[1:]
        parts.append(p)
        owner.append(np.full(len(p), k))
    p = np.round(np.vstack(parts))
    own = np.concatenate(owner)
    keep = np.r_[True, (p[1:] != p[:-1]).any(axis=1)]
    return p[keep], own[keep]


def census(style: str, em: float, text: str, near: int, listing: bool):
    cs = contours(font_file(style), text, em)
    pts, owners = zip(*[contour_points(s) for s in cs], strict=True)
    pts, owners = list(pts), list(owners)
    fps = fitmod.fit_paths(pts, [True] * len(pts))
    works, _ = fitmod._closed_works(pts, [True] * len(pts))
    slack = fitmod.rounding_slack(works)
    eps = fitmod.DEFAULT_EPS_LINE
    kept = thin_many(works, eps, per_path=eps + slack)
    why = collections.Counter()
    kinds = collections.Counter()
    extra_total = 0
    lines = []
    for ci, (segs, p, own, fp, kk) in enumerate(zip(cs, pts, owners, fps, kept, strict=True)):
        n = len(p)
        own_w = np.r_[own, own[:1]] if len(works[ci]) > n else own
        q = works[ci][kk]
        rnd = np.array([[eps + slack[ci], slack[ci] / fitmod._HALF_DIAGONAL]])
        a, b, curve, _, _, smooth = runsmod.split_pieces_many(
            q, [len(q)], [True], rounding=rnd, return_smooth=True,
            steps=np.diff(np.asarray(kk), append=0))
        lay = runsmod._Layout.of([len(q)])
        sm0, turn, sign = runsmod._vertex_rules(q, lay, 0.95, 3.0, want_turn=True)
        # design joints as input indices (first point of each design segment)
        djoint = np.flatnonzero(np.diff(own_w) != 0) + 1
        djoint = np.r_[0, djoint, len(own_w) - 1]
        # fitted joints (input indices)
        fj = np.asarray(fp.first)[1:]
        for j in fj.tolist():
            if np.min(np.abs(djoint - j)) <= near:
                continue
            extra_total += 1
            ds = int(own_w[j])
            dkind = segs[ds][0]
            kinds[dkind] += 1
            # thinned index of j
            ti = np.searchsorted(kk, j)
            reason = "fitter"
            if ti < len(kk) and kk[ti] == j:
                if ti in set(a.tolist()) and not (ti in set((a[curve]).tolist())
                                                  and ti in set((b[curve]).tolist())):
                    reason = "line"
                if ti in set(a[curve].tolist()) and ti in set(b[curve].tolist()):
                    if not smooth[ti]:
                        s_, l_ = q[ti] - q[ti - 1], q[ti + 1] - q[ti]
                        la, lb = math.hypot(*s_), math.hypot(*l_)
                        cos = float(s_ @ l_) / (la * lb)
                        if cos <= 0.95:
                            reason = "corner-cos"
                        elif max(la, lb) > 3 * min(la, lb):
                            reason = "corner-ratio"
                        else:
                            reason = "corner-other"
                    else:
                        reason = "inflection/split"
                elif not smooth[ti]:
                    s_, l_ = q[ti] - q[ti - 1], q[ti + 1] - q[ti]
                    la, lb = math.hypot(*s_), math.hypot(*l_)
                    cos = float(s_ @ l_) / (la * lb)
                    reason = ("line-cos" if cos <= 0.95 else
                              "line-ratio" if max(la, lb) > 3 * min(la, lb) else "line-other")
            else:
                reason = "moved"
            why[reason] += 1
            if listing:
                lo, hi = max(ti - 2, 0), min(ti + 3, len(q))
                segl = np.hypot(*np.diff(q[lo:hi], axis=0).T)
                tt = np.degrees(turn[lo + 1:hi - 1]) if hi - lo > 2 else []
                lines.append(f"  c{ci} {dkind}#{ds} at {p[min(j, n - 1)].tolist()} {reason}:"
                             f" segs {np.round(segl, 1).tolist()} turns"
                             f" {np.round(tt, 1).tolist()} smooth"
                             f" {smooth[lo + 1:hi - 1].astype(int).tolist()}")
    nseg = sum(f.n_segments for f in fps)
    own_n = sum(len(s) for s in cs)
    print(f"{style} em {em:g}: {nseg}/{own_n} = {nseg / own_n:.3f}x; extra joints inside "
          f"design segments {extra_total}: by design kind {dict(kinds)}; why {dict(why)}")
    for ln_ in lines:
        print(ln_)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--styles", default="cantarell,cantarell-thin")
    ap.add_argument("--em", default="1500,2048,3000")
    ap.add_argument("--text", default=TEXT)
    ap.add_argument("--near", type=int, default=3)
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--contours", action="store_true",
                    help="per contour: design kinds and where the fitted joints fall")
    a = ap.parse_args()
    fitmod.warm_up()
    for st in a.styles.split(","):
        for em in [float(e) for e in a.em.split(",")]:
            census(st, em, a.text, a.near, a.list)
            if a.contours:
                per_contour(st, em, a.text)




def per_contour(style: str, em: float, text: str) -> None:
    """Per contour: own segments (lines, curves), fitted (lines, cubics), and the fitted
    joints as design-segment positions (k + fraction along design segment k)."""
    cs = contours(font_file(style), text, em)
    pts, owners = zip(*[contour_points(s) for s in cs], strict=True)
    fps = fitmod.fit_paths(list(pts), [True] * len(pts))
    for ci, (segs, own, fp) in enumerate(zip(cs, owners, fps, strict=True)):
        nl = sum(s[0] == "line" for s in segs)
        ex = fp.n_segments - len(segs)
        pos = []
        for j in np.asarray(fp.first).tolist():
            jj = min(j, len(own) - 1)
            k = int(own[jj])
            idx = np.flatnonzero(own == k)
            pos.append(f"{k}+{(jj - idx[0]) / max(len(idx), 1):.2f}"
                       + ("c" if fp.is_cubic[len(pos)] else "l"))
        kinds = "".join("l" if s[0] == "line" else "c" for s in segs)
        print(f"c{ci} own {len(segs)} ({nl}l) fitted {fp.n_segments} ({fp.n_lines}l) "
              f"excess {ex:+d} design {kinds}\n    {' '.join(pos)}")


if __name__ == "__main__":
    main()
