"""Peers side by side with the project's fit (issue 16), on the typeface outlines of
bench_precision.py (six styles, whole-unit and exact) and on the corpus files with curves.

Peers (each given the same points; the curve fitters are given corner-to-corner runs, the
corners being the typeface's own, see bench/peers_tools.py):
* Paper.js ``Path.simplify`` and fit-curve (Schneider), node, bench/js/peers.js;
* FontForge ``layer.simplify`` (flags mergelines, ignoreslopes, ignoreextrema,
  smoothcurves), Debian python3-fontforge;
* Inkscape ``path-simplify`` (batch ``--actions``; threshold = tolerance / selection
  diagonal);
* Potrace (CLI, defaults but ``-O``): the even-odd fill of each glyph's outline rendered at
  ``s`` pixels per unit, traced, scaled back (it traces bitmaps: no corners handed over).

Each peer runs at a grid of tolerances including our stated bound (e_per + q/sqrt 2:
0.727 on whole units, 0.02 on exact). Measured per row: segments, x the typeface's own
count, distance to the true design curve both ways (``fonts.curve_distance`` per contour,
as bench_precision; per glyph for Potrace, whose contours are its own), and time (CPU s of
the peer's own process or call; node: the CPU seconds of the node process, shared among the
tolerances in proportion to node's own wall-clock ms of each; before the sixth session: the
wall-clock ms).

Corpus (``--corpus``): every file of ../shared/corpus/plt where our fit at the defaults
gives at least one cubic: detected quantum, input points, our segments, our worst error
(check_fit, both sides) against the stated bound, and the peers' segments at a tolerance
equal to that bound with their worst distance to the input polyline (both ways, per path;
no true curve there). Corners there: the turn-angle rule of peers_tools.turn_corners.

Held-out typefaces (``--set heldout``, ``--font F``, ``--text``, ``--em``: bench_precision's
options, fonts.py): the same rows per typeface and em (tables name them "style em E").

Ours only, the peers' rows stored (``--ours-only --peers-json A.json [B.json ...]``): re-runs
only ours (the fit as it is in this checkout) on the typefaces and corpus files of the stored
runs and prints the side-by-side tables again with the stored peer rows (several CPU minutes;
the peers' inputs and corners do not depend on our fit). bench/precision_peers_s6.json
holds the sixth session's peer rows (training set whole + exact, held-out whole, corpus).

Usage: python bench/bench_precision_peers.py [--styles sans,serif] [--json out.json]
       [--corpus] [--no-fonts] [--peers paper,fit-curve,fontforge,inkscape,potrace]
       [--inputs whole,exact] [--set heldout] [--em 700,1500]
       python bench/bench_precision_peers.py --ours-only --peers-json bench/precision_peers_s6.json
       python bench/bench_precision_peers.py --summary A.json [B.json] [--tables]
"""

from __future__ import annotations

import argparse
import functools
import glob
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
sys.path.insert(0, HERE)

import peers_tools as pt  # noqa: E402
from bench_fit import SCALE, run_peer  # noqa: E402
from bench_precision import run as run_ours  # noqa: E402
from fonts import TEXT, add_font_options, curve_distance, font_errors, font_options  # noqa: E402

from galvo_core import fit as fitmod  # noqa: E402
from galvo_core.errors import GalvoError  # noqa: E402
from galvo_core.hpgl import read_file  # noqa: E402
from galvo_core.precision import path_quanta  # noqa: E402

HALF_DIAG = math.sqrt(0.5)
E_PER = 0.02
#: tolerances (units) handed to the curve-fitting peers; the stated bound is added
TOLS = {True: (0.25, 0.5, 1.0, 2.0), False: (0.01, 0.05)}
#: the node peers take seconds to a minute per tolerance on a loaded box: fewer there
NODE_TOLS = {True: (1.0, 2.0), False: (0.01, 0.05)}
#: Inkscape's threshold is no distance bound (it stays close at 2 units): larger ones too
INK_TOLS = {True: (3.0, 4.0, 6.0, 8.0), False: (0.1, 0.2, 0.4)}
#: Potrace: (pixels per unit, -O opttolerance in pixels)
POTRACE = ((1.0, 0.2), (2.0, 0.2), (4.0, 0.2))
PEERS = ("paper", "fit-curve", "fontforge", "inkscape", "potrace")
CORPUS = os.environ.get("GALVO_CORPUS",
                        os.path.join(HERE, "..", "..", "shared", "corpus", "plt"))


def node_tols(lib: str, tols) -> list[float]:
    # both compare squared distances with the number handed over (Paper.js too: PathFitter
    # findMaxError returns a squared distance); coordinates are scaled by SCALE (bench_fit)
    return [(t * SCALE) ** 2 for t in tols]


def runs_of(paths, corners, closed):
    """Flat list of (run, closed) handed to a peer and, per path, its slice."""
    flat, where = [], []
    for p, c, cl in zip(paths, corners, closed, strict=True):
        runs, whole_closed = pt.split_runs(p, c, cl)
        where.append((len(flat), len(flat) + len(runs)))
        flat += [(r, whole_closed) for r in runs]
    return flat, where


def regroup(per_run, where):
    return [[s for k in range(a, b) for s in per_run[k]] for a, b in where]


def run_fitters(peers, paths, corners, closed, tols, tols_node=None, tols_ink=()):
    """Each curve-fitting peer at each tolerance (``tols_node`` for Paper.js and
    fit-curve, default ``tols``): yields (peer, version, tol, per-path segments, seconds)."""
    flat, where = runs_of(paths, corners, closed)
    for lib in ("paper", "fit-curve"):
        if lib not in peers:
            continue
        tols_all, tols = tols, (tols if tols_node is None else tols_node)
        # every run open, a corner-less closed contour too (from its first point round to
        # it): Paper.js's own closed mode leaves an excursion at the closing point
        c0 = pt.child_cpu()
        res = run_peer(lib, [(r, False) for r, _ in flat], node_tols(lib, tols))
        cpu = pt.child_cpu() - c0
        # node's CPU seconds (start-up and JSON included) shared among the tolerances in
        # proportion to node's own wall-clock ms of each tolerance's fits
        total_ms = sum(r["ms"] for r in res["results"]) or 1.0
        for t, r in zip(tols, res["results"], strict=True):
            per_run = [[np.asarray(c, float) for c in cs] for cs in r["paths"]]
            yield lib, res["version"], t, regroup(per_run, where), cpu * r["ms"] / total_ms
        tols = tols_all
    if "fontforge" in peers:
        res = pt.fontforge_simplify(flat, list(tols))
        for t, r in zip(tols, res["results"], strict=True):
            yield "fontforge", res["version"], t, regroup(r["paths"], where), r["cpu_s"]
    if "inkscape" in peers:
        groups = [[r for r, _ in flat[a:b]] for a, b in where]
        gclosed = [bool(flat[a][1]) if b - a == 1 else False for a, b in where]
        ver = pt.inkscape_version()
        for t in sorted(set(tols) | set(tols_ink)):
            got = pt.inkscape_simplify(groups, gclosed, t)
            if got is None:  # over pt.INKSCAPE_TIMEOUT s
                yield "inkscape", ver, t, None, pt.INKSCAPE_TIMEOUT
            else:
                yield "inkscape", ver, t, got[0], got[1]


def case_name(style: str, em: float, text: str) -> str:
    """A typeface run's name in the tables: the style, with its em unless the training
    set's (TEXT, em 1000)."""
    return style if (em == 1000.0 and text == TEXT) else f"{style} em {em:g}"


@functools.lru_cache(maxsize=1)
def code_version() -> str:
    """The commit of the galvo_core measured as ours (``+`` when the tree has changes)."""
    root = os.path.join(HERE, "..")
    try:
        h = subprocess.run(["git", "-C", root, "rev-parse", "--short", "HEAD"],
                           capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", root, "status", "--porcelain", "--",
                                "galvo_core"], capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return h + ("+" if dirty else "")


def ours_row(font: str, whole: bool, em: float, text: str, base: dict | None = None) -> dict:
    """Ours at the defaults on one typeface run (bench_precision.run), as a peers' row; its
    time the least CPU of two runs (the first run of a process also compiles kernels)."""
    ours = run_ours(font, whole, em, text)
    again = run_ours(font, whole, em, text)
    if again["segments"] != ours["segments"]:
        raise RuntimeError(f"{font}: two fits of the same points differ")
    ours["cpu_s"] = min(ours["cpu_s"], again["cpu_s"])
    if base is None:
        base = {"style": ours["style"], "font": font, "em": em, "text": text,
                "case": case_name(ours["style"], em, text),
                "input": "whole" if whole else "exact", "own": ours["own"]}
    bound = E_PER + (HALF_DIAG if whole else 0.0)
    return dict(base, points=ours["points"], peer="ours (defaults)", tol=bound,
                segments=ours["segments"], dist_true=ours["dist_true"],
                dist_away=ours["dist_away"], violations=ours["violations"],
                secs=ours["cpu_s"], code=code_version(), ratio=ours["segments"] / base["own"],
                at_bound=True)


def font_rows(style: str, whole: bool, peers, em: float, text: str = TEXT) -> list[dict]:
    fc = pt.font_case(style, whole, em, text=text)
    bound = E_PER + (HALF_DIAG if whole else 0.0)
    ours = ours_row(style, whole, em, text)
    base = {k: ours[k] for k in ("style", "font", "em", "text", "case", "input", "own",
                                 "points")}
    rows = [ours]
    tols = sorted(set(TOLS[whole]) | {bound})
    ntols = sorted(set(NODE_TOLS[whole]) | {bound})
    for lib, ver, t, segs, secs in run_fitters(peers, fc.points, fc.corners,
                                               [True] * len(fc.points), tols, ntols,
                                               INK_TOLS[whole]):
        if segs is None:
            continue
        dist = max((curve_distance(pt.seg_dense(s), tr) if s else math.inf)
                   for s, tr in zip(segs, fc.truth, strict=True))
        rows.append(dict(base, peer=f"{lib} {ver}", tol=t, segments=sum(map(len, segs)),
                         dist_true=dist, secs=secs))
    if "potrace" in peers:
        ver = pt.potrace_version()
        for scale, opt in POTRACE:
            n, dist, secs = 0, 0.0, 0.0
            for g in sorted(set(fc.glyph)):
                ks = [k for k, gg in enumerate(fc.glyph) if gg == g]
                out, s = pt.potrace_glyph([fc.points[k] for k in ks], scale, opt)
                secs += s
                n += sum(map(len, out))
                dist = max(dist, pt.set_distance([pt.seg_dense(o) for o in out],
                                                 [fc.truth[k] for k in ks]))
            rows.append(dict(base, peer=f"potrace {ver} ({scale:g} px/unit, -O {opt})",
                             tol=opt / scale, segments=n, dist_true=dist, secs=secs))
    for r in rows:
        r["ratio"] = r["segments"] / r["own"]
        r["at_bound"] = abs(r["tol"] - bound) < 1e-3
    return rows


# --- corpus -----------------------------------------------------------------------------------


def corpus_files() -> list[str]:
    fs = sorted(glob.glob(os.path.join(CORPUS, "*")))
    return [f for f in fs if os.path.isfile(f) and "__expected" not in os.path.basename(f)
            and not f.endswith((".tsv", ".md", ".svg", ".png"))]


def corpus_paths(path: str):
    """A corpus file's paths of two points or more (points, closed), or None."""
    try:
        dr = read_file(path)
    except GalvoError:
        return None
    paths = [p for p in dr.paths if len(p.points) >= 2]
    if not paths:
        return None
    return [np.asarray(p.points, float) for p in paths], [bool(p.closed) for p in paths]


def corpus_ours(path: str, keep_all: bool = False) -> dict | None:
    """Ours at the defaults on a corpus file: the row without its peers; None when the file
    has no path or (unless ``keep_all``) our fit gives no cubic."""
    got = corpus_paths(path)
    if got is None:
        return None
    pts, closed = got
    qs = path_quanta(pts)
    t0 = time.process_time()
    fps = fitmod.fit_paths(pts, closed, quantum_units=qs)
    secs = time.process_time() - t0
    ncubic = sum(f.n_cubics for f in fps)
    if not ncubic and not keep_all:
        return None
    worst, excess, bound_max = 0.0, -math.inf, 0.0
    for p, f, q in zip(pts, fps, qs.tolist(), strict=True):
        rep = fitmod.check_fit(p, f, E_PER, E_PER, quantum_units=q, report=True)
        w = max(rep["max_in_to_curve"], rep["max_curve_to_polyline"])
        worst = max(worst, w)
        excess = max(excess, w - rep["bound"])
        bound_max = max(bound_max, rep["bound"])
    return {"file": os.path.basename(path), "quantum": float(qs.max()),
            "points": int(sum(map(len, pts))), "paths": len(pts),
            "segments": sum(len(f.segments) for f in fps), "cubics": ncubic,
            "worst": worst, "bound": bound_max, "excess": excess, "secs": secs,
            "code": code_version(), "peers": {}}


def corpus_row(path: str, peers) -> dict | None:
    row = corpus_ours(path)
    if row is None:
        return None
    pts, closed = corpus_paths(path)
    bound_max = row["bound"]
    # peers at the stated bound; closed paths' polylines closed for them; dots (all points
    # equal) left out
    keep = [k for k, p in enumerate(pts) if (p != p[0]).any()]
    closed = [closed[k] for k in keep]
    work = [np.vstack([p, p[:1]]) if c and not np.array_equal(p[0], p[-1]) else p
            for p, c in zip((pts[k] for k in keep), closed, strict=True)]
    row["dots"] = len(pts) - len(keep)
    corners = [pt.turn_corners(p, c, reach=4.0 * bound_max) for p, c in zip(work, closed,
                                                                            strict=True)]
    row["corners"] = int(sum(map(len, corners)))
    for lib, ver, _t, segs, s in run_fitters(peers, work, corners, closed, [bound_max]):
        if segs is None:
            row["peers"][lib] = {"version": ver, "timeout": s}
            continue
        h = max(1e-3, bound_max / 20.0)
        ds = [(pt.both_ways(pt.seg_dense(sg, h), p) if sg else math.inf)
              for sg, p in zip(segs, work, strict=True)]
        # paths farther than the bound from their input polyline (the input vertices'
        # distances to the flattened curve may read up to h too high: h of slack)
        over = sum(d > bound_max + h for d in ds)
        row["peers"][lib] = {"version": ver, "segments": sum(map(len, segs)),
                             "dist_input": max(ds), "over": int(over), "secs": s}
    return row


# --- output -------------------------------------------------------------------------------------


def print_font(rows):
    print("| style | input | peer | tolerance | segments | x own | to true curve | s |")
    print("| --- | --- | --- | ---: | ---: | ---: | ---: | ---: |")
    for r in rows:
        b = " (bound)" if r["at_bound"] else ""
        print(f"| {case(r)} | {r['input']} | {r['peer']} | {r['tol']:.3g}{b} | "
              f"{r['segments']} | {r['ratio']:.2f} | {r['dist_true']:.3f} | "
              f"{r['secs']:.2f} |", flush=True)


def case(r) -> str:
    """A font row's typeface run (older runs' JSON: the style)."""
    return r.get("case", r["style"])


def _peer_cell(r, p) -> str:
    """A corpus row's cell for peer ``p``: segments / distance to the input / paths over the
    bound, "over N s" when it timed out, "–" when it did not run."""
    q = r["peers"].get(p)
    if q is None:
        return "–"
    if "segments" not in q:
        return f"over {q['timeout']:g} s"
    return f"{q['segments']} / {q['dist_input']:.3f} / {q['over']}"


def print_corpus_row(r, peers):
    ps = " | ".join(_peer_cell(r, p) for p in peers)
    print(f"| {r['file']} | {r['quantum']:g} | {r['points']} | {r['segments']} | "
          f"{r['worst']:.3f} / {r['bound']:.3f} | {r['corners']} | {ps} |", flush=True)


def _rng(v, fmt):
    a, b = fmt.format(min(v)), fmt.format(max(v))
    return a if a == b else f"{a}–{b}"


def kind(r) -> str:
    """A font row's program: "ours", "paper 0.12.20", ..., "potrace"."""
    if r["peer"].startswith("potrace"):
        return "potrace"
    return r["peer"].split(" (")[0]


def groups(rows) -> list[tuple[str, list[dict]]]:
    """Font rows by test set: the training set (TEXT, em 1000) and the others by text."""
    out: dict[str, list[dict]] = {}
    for r in rows:
        text, em = r.get("text", TEXT), r.get("em", 1000.0)
        g = ("training set (six DejaVu styles, TEXT, em 1000)" if text == TEXT and em == 1000.0
             else f"text {text!r}")
        out.setdefault(g, []).append(r)
    return list(out.items())


def summary(rows) -> None:
    """Over the typeface runs, per input and peer: the peer at our stated bound, and its
    fewest segments among the tolerances tried whose distance to the true curve is no larger
    than ours on the same run (ranges over the runs; time summed)."""
    for title, grp in groups(rows):
        _summary(title, grp)


def _summary(title, rows) -> None:
    cases = sorted({case(r) for r in rows})
    print(f"\n{title}: {len(cases)} typeface runs\n")
    print("| input | peer | at | x own | to true curve | s (sum) |")
    print("| --- | --- | --- | ---: | ---: | ---: |")
    for inp in ("whole", "exact"):
        rs = [r for r in rows if r["input"] == inp]
        ours = {case(r): r for r in rs if r["peer"].startswith("ours")}
        kinds = []
        for r in rs:
            if kind(r) not in kinds:
                kinds.append(kind(r))
        for k in kinds:
            mine = [r for r in rs if kind(r) == k]
            for r in mine:  # (tolerance written rounded to 0.001 in older runs' JSON)
                r["at_bound"] = abs(r["tol"] - E_PER - (HALF_DIAG if inp == "whole" else 0)) < 1e-3
            if k.startswith("ours"):
                sel = {"defaults": mine}
            else:
                sel = {}
                at_b = [r for r in mine if r["at_bound"]]
                if at_b:
                    sel["the bound"] = at_b
                best = []
                for st in sorted({case(r) for r in mine} & set(ours)):
                    ok = [r for r in mine if case(r) == st
                          and r["dist_true"] <= ours[st]["dist_true"] + 1e-9]
                    if ok:
                        best.append(min(ok, key=lambda r: r["segments"]))
                    else:
                        best.append(min((r for r in mine if case(r) == st),
                                        key=lambda r: r["dist_true"]))
                sel["ours' distance (else its closest)"] = best
            for what, sub in sel.items():
                tol = _rng([r["tol"] for r in sub], "{:.3g}")
                reach = sum(r["dist_true"] <= ours[case(r)]["dist_true"] + 1e-9 for r in sub)
                extra = ("" if what in ("defaults", "the bound")
                         else f" (tol {tol}; {reach}/{len(sub)} reach it)")
                print(f"| {inp} | {k} | {what}{extra} | "
                      f"{_rng([r['ratio'] for r in sub], '{:.2f}')} | "
                      f"{_rng([r['dist_true'] for r in sub], '{:.3f}')} | "
                      f"{sum(r['secs'] for r in sub):.2f} |")


def per_style_table(rows) -> None:
    """One line per typeface run and input: ours, each peer at our stated bound, Potrace at
    1 and 4 px per unit, and the best peer row at ours' distance or closer (fewest segments
    of any peer at any tolerance tried); cells "segments (x own) / distance to the true
    curve"."""
    kinds = ["paper", "fit-curve", "fontforge", "inkscape"]
    print("| style | input | ours | " + " | ".join(f"{k} at the bound" for k in kinds)
          + " | potrace 1 px/unit | potrace 4 px/unit | best peer at ours' distance |")
    print("| --- | --- | " + " | ".join("---:" for _ in range(len(kinds) + 4)) + " |")

    def cell(r):
        return "–" if r is None else f"{r['segments']} ({r['ratio']:.2f}) / {r['dist_true']:.3f}"

    keys = []
    for r in rows:
        if (r["input"], case(r)) not in keys:
            keys.append((r["input"], case(r)))
    for inp, st in sorted(keys, key=lambda k: k[0] != "whole"):
        rs = [r for r in rows if case(r) == st and r["input"] == inp]
        bound = E_PER + (HALF_DIAG if inp == "whole" else 0.0)

        def pick(pred, rs=rs):
            return next((r for r in rs if pred(r)), None)

        ours = pick(lambda r: r["peer"].startswith("ours"))
        cells = [cell(ours)]
        for k in kinds:
            cells.append(cell(pick(lambda r, k=k, bound=bound: r["peer"].split(" ")[0] == k
                                   and abs(r["tol"] - bound) < 1e-3)))
        for sc in ("(1 px", "(4 px"):
            cells.append(cell(pick(lambda r, sc=sc: r["peer"].startswith("potrace")
                                   and sc in r["peer"])))
        others = [r for r in rs if not r["peer"].startswith("ours")]
        ok = [r for r in others if ours and r["dist_true"] <= ours["dist_true"] + 1e-9]
        if ok:
            b = min(ok, key=lambda r: (r["segments"], r["dist_true"]))
            cells.append(f"{b['peer'].split(' (')[0]} at {b['tol']:.3g}: {cell(b)}")
        elif others:
            b = min(others, key=lambda r: r["dist_true"])
            cells.append(f"none (closest: {b['peer'].split(' (')[0]} at {b['tol']:.3g}: "
                         f"{cell(b)})")
        else:
            cells.append("–")
        print(f"| {st} | {inp} | " + " | ".join(cells) + " |")


def grid_table(rows) -> None:
    """Every peer at every tolerance tried: ranges over the typeface runs."""
    for title, grp in groups(rows):
        print(f"\n{title}\n")
        _grid_table(grp)


def _grid_table(rows) -> None:
    print("| input | peer | tolerance | runs | x own | to true curve | s (mean) |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: |")
    keys = []
    for r in rows:
        k = (r["input"], r["peer"], round(r["tol"], 3))
        if k not in keys:
            keys.append(k)
    keys.sort(key=lambda k: (k[0] != "whole", k[1] != "ours (defaults)", k[1], k[2]))
    for inp, peer, tol in keys:
        sub = [r for r in rows if (r["input"], r["peer"], round(r["tol"], 3)) == (inp, peer, tol)]
        print(f"| {inp} | {peer} | {tol:g} | {len(sub)} | "
              f"{_rng([r['ratio'] for r in sub], '{:.2f}')} | "
              f"{_rng([r['dist_true'] for r in sub], '{:.3f}')} | "
              f"{sum(r['secs'] for r in sub) / len(sub):.2f} |")


def corpus_table(rows, peers=("paper", "fit-curve", "fontforge", "inkscape")) -> None:
    print("| file | q | points | ours: segments | ours: worst / bound | "
          + " | ".join(f"{p}: segments / dist / paths over" for p in peers) + " |")
    print("| --- | ---: | ---: | ---: | ---: | " + " | ".join("---:" for _ in peers) + " |")
    for r in rows:
        print(f"| {r['file']} | {r['quantum']:g} | {r['points']} | {r['segments']} | "
              f"{r['worst']:.3f} / {r['bound']:.3f} | "
              + " | ".join(_peer_cell(r, p) for p in peers) + " |")
    tot = [str(sum(r["segments"] for r in rows))]
    for p in peers:
        ok = [r for r in rows if "segments" in r["peers"].get(p, {})]
        tot.append(f"{sum(r['peers'][p]['segments'] for r in ok)} (ours on these "
                   f"{len(ok)} files: {sum(r['segments'] for r in ok)}); "
                   f"{sum(r['peers'][p]['over'] > 0 for r in ok)} files with paths over, "
                   f"{sum(r['peers'][p]['over'] for r in ok)} paths")
    over_ours = sum(r["worst"] > r["bound"] * (1 + 1e-9) for r in rows)
    print(f"| **{len(rows)} files** | | {sum(r['points'] for r in rows)} | {tot[0]} | "
          f"{over_ours} files over | " + " | ".join(tot[1:]) + " |")


def load_runs(files) -> dict:
    """Font and corpus rows of stored runs (a row stored twice: its first copy kept)."""
    out: dict = {"fonts": [], "corpus": []}
    seen, seen_files = set(), set()
    for fn in files:
        try:
            with open(fn) as f:
                d = json.load(f)
        except (OSError, ValueError) as e:
            raise SystemExit(f"error: {fn}: {getattr(e, 'strerror', None) or e}") from None
        for r in d.get("fonts", []):
            k = (case(r), r["input"], r["peer"], r["tol"])
            if k not in seen:
                seen.add(k)
                out["fonts"].append(r)
        for r in d.get("corpus", []):
            if r["file"] not in seen_files:
                seen_files.add(r["file"])
                out["corpus"].append(r)
    return out


def ours_only(stored: dict, with_corpus: bool) -> dict:
    """Our rows re-run (this checkout's fit) beside the stored peer rows: per typeface run
    and input its "ours" row replaced; per corpus file our columns re-measured (files where
    ours now gives a cubic and none was stored: added, without peers)."""
    fitmod.warm_up()
    rows, done = [], {}
    for r in stored["fonts"]:
        k = (case(r), r["input"])
        if k not in done:
            font = r.get("font", r["style"])
            with font_errors(font):
                done[k] = ours_row(font, r["input"] == "whole", r.get("em", 1000.0),
                                   r.get("text", TEXT))
            rows.append(done[k])
        if not r["peer"].startswith("ours"):
            if r["own"] != done[k]["own"] or r.get("points", done[k]["points"]) != \
                    done[k]["points"]:
                raise SystemExit(f"error: {case(r)} {r['input']}: the stored peers saw other "
                                 "points than ours now (fonts.py or the font changed)")
            rows.append(r)
    out = {"fonts": rows, "corpus": []}
    if with_corpus and stored["corpus"]:
        by_name = {os.path.basename(f): f for f in corpus_files()}
        names = [r["file"] for r in stored["corpus"]]
        for r in stored["corpus"]:
            if r["file"] not in by_name:
                raise SystemExit(f"error: {r['file']}: stored corpus file not in {CORPUS}")
            new = corpus_ours(by_name[r["file"]], keep_all=True)
            if new is None:
                raise SystemExit(f"error: {by_name[r['file']]}: no path read any more")
            if new["points"] != r["points"]:
                raise SystemExit(f"error: {by_name[r['file']]}: the stored peers saw "
                                 f"{r['points']} points, ours now {new['points']}")
            new.update({k: r[k] for k in ("peers", "dots", "corners") if k in r})
            out["corpus"].append(new)
        for name, f in by_name.items():
            if name not in names:
                new = corpus_ours(f)
                if new is not None:
                    new["corners"] = 0
                    out["corpus"].append(new)
    return out


def print_tables(out: dict) -> None:
    if out["fonts"]:
        summary(out["fonts"])
        print()
        per_style_table(out["fonts"])
        grid_table(out["fonts"])
    if out["corpus"]:
        print()
        corpus_table(out["corpus"])


def main() -> None:
    ap = argparse.ArgumentParser()
    add_font_options(ap)
    ap.add_argument("--peers", default=",".join(PEERS))
    ap.add_argument("--corpus", action="store_true", help="also the corpus table")
    ap.add_argument("--no-fonts", action="store_true")
    ap.add_argument("--inputs", default="whole,exact")
    ap.add_argument("--json")
    ap.add_argument("--tables", action="store_true",
                    help="with --summary: per style, every tolerance and the corpus too")
    ap.add_argument("--corpus-table", metavar="JSON", help="only print a run's corpus table")
    ap.add_argument("--summary", metavar="JSON", nargs="+",
                    help="only print the summary of the font rows of these runs' JSON "
                         "(with --json: write them merged)")
    ap.add_argument("--ours-only", action="store_true",
                    help="re-run only ours beside the peer rows of --peers-json")
    ap.add_argument("--peers-json", metavar="JSON", nargs="+",
                    help="with --ours-only: stored runs (their font and corpus rows)")
    a = ap.parse_args()
    if a.ours_only:
        if not a.peers_json:
            raise SystemExit("error: --ours-only: give the stored runs with --peers-json")
        out = ours_only(load_runs(a.peers_json), with_corpus=True)
        print(f"ours: galvo_core at {code_version()}; peers: stored rows of "
              f"{', '.join(a.peers_json)}")
        print_tables(out)
        dump(out, a.json)
        return
    if a.summary:
        out = load_runs(a.summary)
        if a.tables:  # per style, every tolerance, the corpus
            print_tables(out)
        elif out["fonts"]:
            summary(out["fonts"])
        dump(out, a.json)  # the runs merged into one file (--peers-json takes it)
        return
    if a.corpus_table:
        with open(a.corpus_table) as f:
            corpus_table(json.load(f)["corpus"])
        return
    peers = a.peers.split(",")
    styles, text, ems = font_options(a)
    fitmod.warm_up()
    out = {"fonts": [], "corpus": []}
    if not a.no_fonts:
        for whole in [i == "whole" for i in a.inputs.split(",")]:
            for em in ems:
                for st in styles:
                    with font_errors(st):
                        rows = font_rows(st, whole, peers, em, text)
                    out["fonts"] += rows
                    print_font(rows)
                    dump(out, a.json)
    if out["fonts"]:
        summary(out["fonts"])
    if a.corpus:
        cp = [p for p in peers if p != "potrace"]
        print("\n| file | q | points | segments | worst / bound | corners | "
              + " | ".join(f"{p} segs / dist / paths over" for p in cp) + " |")
        print("| --- | ---: | ---: | ---: | ---: | ---: | " + " | ".join("---:" for _ in cp)
              + " |")
        for f in corpus_files():
            r = corpus_row(f, cp)
            if r is not None:
                out["corpus"].append(r)
                print_corpus_row(r, cp)
                dump(out, a.json)
    dump(out, a.json)


def dump(out, fn) -> None:
    if fn:
        with open(fn + ".tmp", "w") as f:
            json.dump(out, f, indent=1, default=float)
        os.replace(fn + ".tmp", fn)


if __name__ == "__main__":
    main()
