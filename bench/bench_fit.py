"""Fitting benchmark: segment counts at equal TRUE max error against fit-curve and Paper.js,
against the fewest cubics for a circle, speed, and paper 000 Table 1.

Error measure (the same for us and the peers, "check_fit style"): every cubic is flattened
to a polyline within ``e_per / 200`` (:func:`galvo_core.geometry.flatten_cubic`), then

* in -> curve: each input point's distance to the flattened fitted path (all its cubics and
  lines), true Euclidean distance (R-tree for large inputs);
* curve -> in: each vertex of the flattened fitted path (spacing <= e_per / 4 enforced by
  subdividing) to the input polyline.

The reported error is the larger of the two, to within e_per / 200 of the exact value. For
ours, :func:`galvo_core.fit.check_fit` (independent dense sampling) is run as well.

Peers: their tolerance conventions differ (both compare a *squared* distance, at their own
parameterisation, with their tolerance; Paper.js skips refinement when tolerance² < 1), so
coordinates are scaled (x ``SCALE``) and each peer's tolerance is searched (a geometric grid,
then bisection) for the largest value whose result's TRUE max error is <= e_per; its segment
count there is compared with ours.

Speed on whole drawings (``--speed-only`` runs just that part): ``fit_drawing`` per drawing,
best of ``--reps``, with the thinning (``thin_many`` on the same points) timed on its own so
the fitting proper can be read off; with ``--baseline REV`` the fitter of git revision REV
(its runs.py, fit.py and geometry.py, with today's thinning) is timed interleaved with the
current one and checked to give the same segments. The load average is printed with every
row (the box is shared; compare old and new only within one run).

Usage: python bench/bench_fit.py [--json out.json] [--speed-only] [--baseline REV] [--reps N]
"""

from __future__ import annotations

import argparse
import functools
import importlib
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

from bench_thin import sines  # noqa: E402  (the same speed curve as the thinning bench)

from galvo_core.drawing import Drawing, Path  # noqa: E402
from galvo_core.fit import (  # noqa: E402
    check_fit,
    control_points,
    fit_drawing,
    fit_path,
    fit_report,
)
from galvo_core.geometry import cubic_eval, flatten_cubic, point_polyline_distance  # noqa: E402
from galvo_core.hpgl import read_file  # noqa: E402
from galvo_core.thin import dedup_indices, thin_many  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..")
E_PER = 0.02
SCALE = 1000.0


# --- error measurement -----------------------------------------------------------------


def _dense(cubics: list[np.ndarray], lines: list[np.ndarray], h: float) -> list[np.ndarray]:
    out = []
    for c in cubics:
        f = flatten_cubic(c, h / 50.0)
        out.append(_subdivide(f, h))
    for ln in lines:
        out.append(_subdivide(np.asarray(ln, float), h))
    return out


def _subdivide(poly: np.ndarray, h: float) -> np.ndarray:
    seg = np.hypot(*np.diff(poly, axis=0).T)
    k = np.maximum(1, np.ceil(seg / h)).astype(int)
    t = np.concatenate([np.arange(m) / m for m in k])
    a = np.repeat(poly[:-1], k, axis=0)
    b = np.repeat(poly[1:], k, axis=0)
    return np.vstack([a + t[:, None] * (b - a), poly[-1:]])


def true_error(points: np.ndarray, cubics, lines=(), e_per: float = E_PER) -> float:
    """max(in -> fitted path, fitted path -> input polyline), see module doc."""
    pts = np.asarray(points, float)
    parts = _dense([np.asarray(c, float) for c in cubics], list(lines), e_per / 4.0)
    if not parts:
        return math.inf
    # the parts follow each other along the path, so they chain into one polyline
    allp = np.vstack(parts)
    d_in = point_polyline_distance(pts, allp)
    d_out = point_polyline_distance(allp, pts) if len(pts) >= 2 else np.hypot(*(allp - pts[0]).T)
    return float(max(d_in.max(), d_out.max()))


# --- peers ------------------------------------------------------------------------------


def run_peer(lib: str, paths: list[tuple[np.ndarray, bool]], tols: list[float]) -> dict:
    send = []
    for p, closed in paths:
        q = p[dedup_indices(p)]
        if closed and len(q) > 2 and np.array_equal(q[0], q[-1]) and lib == "paper":
            q = q[:-1]
        send.append(dict(closed=bool(closed and lib == "paper"), points=q.tolist()))
    inp = json.dumps(dict(lib=lib, scale=SCALE, tols=tols, paths=send))
    out = subprocess.run(
        ["node", os.path.join(HERE, "js", "peers.js")],
        input=inp,
        capture_output=True,
        text=True,
        check=True,
        cwd=os.path.join(HERE, "js"),
    )
    return json.loads(out.stdout)


def peer_error(paths, result) -> tuple[float, int]:
    err = 0.0
    n = 0
    for (p, _), cs in zip(paths, result["paths"], strict=True):
        n += len(cs)
        if len(cs):
            err = max(err, true_error(p, cs))
    return err, n


def best_peer(lib: str, paths, e_per: float = E_PER) -> dict:
    """Largest tolerance (grid, then bisection) whose TRUE max error <= e_per."""
    s = SCALE
    grid = (
        [(e_per * s) ** 2 * f for f in np.geomspace(0.05, 4.0, 9)]
        if lib == "fit-curve"
        else [e_per * s * f for f in np.geomspace(0.1, 3.0, 9)]
    )
    grid = [max(g, 1.0001) for g in grid]
    res = run_peer(lib, paths, grid)
    evals = [(t, *peer_error(paths, r), r["ms"]) for t, r in zip(grid, res["results"], strict=True)]
    ok = [e for e in evals if e[1] <= e_per]
    bad = [e for e in evals if e[1] > e_per]
    if not ok:
        return dict(lib=lib, version=res["version"], ok=False, evals=evals)
    lo = max(ok, key=lambda e: e[0])
    his = [e for e in bad if e[0] > lo[0]]
    if his:
        hi = min(his, key=lambda e: e[0])
        for _ in range(4):  # bisection between the last good and first bad tolerance
            mid = math.sqrt(lo[0] * hi[0])
            r = run_peer(lib, paths, [mid])["results"][0]
            e = (mid, *peer_error(paths, r), r["ms"])
            if e[1] <= e_per:
                lo = e
            else:
                hi = e
    ok_all = [e for e in evals if e[1] <= e_per] + [lo]
    best = min(ok_all, key=lambda e: (e[2], -e[0]))
    return dict(
        lib=lib,
        version=res["version"],
        ok=True,
        tol=best[0],
        err=best[1],
        segments=best[2],
        ms=best[3],
    )


# --- circle optimum ---------------------------------------------------------------------


def circle_arc_error(theta: float) -> float:
    """Relative max radial error of the best symmetric cubic for an arc of angle theta
    (handle length k·r along the end tangents, k chosen to minimise the max |r(u)/r − 1|,
    golden-section search over k, u sampled at 2001 points)."""
    u = np.linspace(0, 1, 2001)

    def err(k: float) -> float:
        c = np.array(
            [
                [1.0, 0.0],
                [1.0, k],
                [math.cos(theta) + k * math.sin(theta), math.sin(theta) - k * math.cos(theta)],
                [math.cos(theta), math.sin(theta)],
            ]
        )
        p = cubic_eval(c, u)
        return float(np.abs(np.hypot(p[:, 0], p[:, 1]) - 1.0).max())

    k0 = 4.0 / 3.0 * math.tan(theta / 4.0)
    a, b = 0.8 * k0, 1.2 * k0
    g = (math.sqrt(5) - 1) / 2
    for _ in range(60):
        c1, c2 = b - g * (b - a), a + g * (b - a)
        if err(c1) < err(c2):
            b = c2
        else:
            a = c1
    return err(0.5 * (a + b))


def circle_min_cubics(r: float, e_per: float) -> int:
    n = 1
    while circle_arc_error(2 * math.pi / n) > e_per / r:
        n += 1
    return n


# --- data -------------------------------------------------------------------------------


def circle(r: float, n: int) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n)
    p = np.c_[r * np.cos(t), r * np.sin(t)]
    p[-1] = p[0]
    return p


def drawing_paths(path: str) -> list[tuple[np.ndarray, bool]]:
    return [(np.asarray(p.points, float), p.closed) for p in read_file(path).paths]


def ours(paths, e_per: float = E_PER, reps: int = 3) -> dict:
    best = math.inf
    fits = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fits = [fit_path(p, closed=c, e_per=e_per, eps_line=e_per) for p, c in paths]
        best = min(best, time.perf_counter() - t0)
    err = 0.0
    viol = 0
    for (p, _), f in zip(paths, fits, strict=True):
        e_in, e_out = check_fit(p, f, e_per, e_per)
        cub = [s.points for s in f.segments if s.kind == "cubic"]
        lin = [s.points for s in f.segments if s.kind == "line"]
        te = true_error(p, cub, lin) if len(p) >= 2 else 0.0
        err = max(err, e_in, e_out, te)
        viol += int(max(e_in, e_out) > e_per * (1 + 1e-9))
    n = sum(len(p) for p, _ in paths)
    return dict(
        segments=sum(len(f.segments) for f in fits),
        cubics=sum(f.n_cubics for f in fits),
        lines=sum(f.n_lines for f in fits),
        control_points=sum(control_points(f) for f in fits),
        err=err,
        violations=viol,
        seconds=best,
        pts_per_s=n / best,
        points=n,
    )


# --- speed on whole drawings -------------------------------------------------------------

#: (name, file, e_per, eps_line): drawings of many small paths and one of a few long ones
SPEED_SET = [
    ("seal.plt", "samples/seal.plt", E_PER, E_PER),
    ("text_outline.plt", "samples/text_outline.plt", 0.75, 0.5),
    ("noten.hpgl", "corpus/h42i__monoplots__noten.hpgl", E_PER, E_PER),
    ("noten.hpgl", "corpus/h42i__monoplots__noten.hpgl", 0.75, E_PER),
    ("curve_1181.plt", "samples/curve_1181.plt", E_PER, E_PER),
    ("sines 100k", "generated/sines", E_PER, E_PER),
]


def _baseline_fit_drawing(rev: str):
    """``fit_drawing`` of git revision ``rev``: its runs.py, fit.py and geometry.py copied
    into a temporary package (imports rewritten), today's galvo_core for everything else."""
    tmp = tempfile.mkdtemp(prefix="fit_baseline_")
    pkg = os.path.join(tmp, "fit_baseline")
    os.makedirs(pkg)
    open(os.path.join(pkg, "__init__.py"), "w").close()
    for name in ("runs", "fit", "geometry"):
        src = subprocess.run(
            ["git", "show", f"{rev}:galvo_core/{name}.py"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        for mod in ("runs", "geometry"):
            src = src.replace(f"from galvo_core.{mod} import", f"from fit_baseline.{mod} import")
        with open(os.path.join(pkg, f"{name}.py"), "w") as f:
            f.write(src)
    sys.path.insert(0, tmp)
    return importlib.import_module("fit_baseline.fit").fit_drawing


def _same_segments(a, b) -> bool:
    return all(
        fa.max_error == fb.max_error
        and fa.n_thinned == fb.n_thinned
        and len(fa.segments) == len(fb.segments)
        and all(
            sa.kind == sb.kind
            and (sa.first, sa.last) == (sb.first, sb.last)
            and np.array_equal(sa.points, sb.points)
            for sa, sb in zip(fa.segments, fb.segments, strict=True)
        )
        for fa, fb in zip(a, b, strict=True)
    )


def drawing_speeds(baseline: str | None, reps: int) -> list[dict]:
    """Input points/s of ``fit_drawing`` on SPEED_SET (best of ``reps``, thinning timed
    on its own; old and new interleaved when ``baseline`` is given)."""
    corpus = os.environ.get("GALVO_CORPUS", "/work/shared/corpus/plt")
    where = dict(samples=os.path.join(ROOT, "resources", "samples"), corpus=corpus)
    old_fit = _baseline_fit_drawing(baseline) if baseline else None
    rows = []
    for name, rel, e_per, eps_line in SPEED_SET:
        top, fn = rel.split("/")
        if top == "generated":  # the thinning bench's speed curve, one open path
            d = Drawing((Path.from_points(sines()),))
        elif os.path.exists(os.path.join(where[top], fn)):
            d = read_file(os.path.join(where[top], fn))
        else:
            continue
        works = []
        for p in d.paths:
            w = np.asarray(p.points, float).reshape(-1, 2)
            if p.closed and len(w) >= 2 and not np.array_equal(w[0], w[-1]):
                w = np.vstack([w, w[:1]])
            works.append(w)
        runs = dict(
            thin=functools.partial(thin_many, works, eps_line),
            new=functools.partial(fit_drawing, d, e_per=e_per, eps_line=eps_line),
        )
        if old_fit is not None:
            runs["old"] = functools.partial(old_fit, d, e_per=e_per, eps_line=eps_line)
        load0 = os.getloadavg()[0]
        best = {k: math.inf for k in runs}
        out = {}
        for _ in range(reps):
            for k, f in runs.items():
                t0 = time.perf_counter()
                out[k] = f()
                best[k] = min(best[k], time.perf_counter() - t0)
        n = d.n_points
        fits = out["new"]
        row = dict(
            set=name,
            e_per=e_per,
            eps_line=eps_line,
            paths=len(d.paths),
            points=n,
            segments=sum(len(f.segments) for f in fits),
            cubics=sum(f.n_cubics for f in fits),
            max_error=max((f.max_error for f in fits), default=0.0),
            load=(load0, os.getloadavg()[0]),
            thin_s=best["thin"],
            seconds=best["new"],
            pts_per_s=n / best["new"],
            fit_only_pts_per_s=n / max(best["new"] - best["thin"], 1e-9),
        )
        if old_fit is not None:
            row.update(
                old_seconds=best["old"],
                old_pts_per_s=n / best["old"],
                same_as_old=_same_segments(out["old"], fits),
            )
        rows.append(row)
        old = (
            f"  old {row['old_pts_per_s']:,.0f} pts/s (same: {row['same_as_old']})"
            if old_fit is not None
            else ""
        )
        print(
            f"drawing {name:17s} e_per={e_per} eps_line={eps_line}: {row['paths']} paths, "
            f"{n} pts, {row['segments']} segs ({row['cubics']} cubics), "
            f"max err {row['max_error']:.4f} | thin {best['thin'] * 1e3:.1f} ms | new "
            f"{row['pts_per_s']:,.0f} pts/s (without thinning {row['fit_only_pts_per_s']:,.0f})"
            f"{old} | load {row['load'][0]:.2f}-{row['load'][1]:.2f}",
            flush=True,
        )
    return rows


def main() -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--json")
    ap.add_argument("--speed-only", action="store_true")
    ap.add_argument("--baseline", help="git revision whose fitter is timed alongside")
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    if args.speed_only:
        res = dict(drawings=drawing_speeds(args.baseline, args.reps))
        if args.json:
            with open(args.json, "w") as f:
                json.dump(res, f, indent=1, default=float)
        return res
    samples = os.path.join(ROOT, "resources", "samples")
    sets = [
        ("circle r=50, 400 pts", [(circle(50, 400), True)], 50.0),
        ("circle r=400, 1181 pts", [(circle(400, 1181), True)], 400.0),
        ("circle r=2000, 20000 pts", [(circle(2000, 20000), True)], 2000.0),
        ("curve_1181.plt", drawing_paths(os.path.join(samples, "curve_1181.plt")), None),
        (
            "text_outline.plt (glyphs)",
            drawing_paths(os.path.join(samples, "text_outline.plt")),
            None,
        ),
        ("sines 100k", [(sines(), False)], None),
    ]
    rows = []
    for name, paths, r in sets:
        o = ours(paths)
        row = dict(set=name, ours=o)
        if r is not None:
            row["circle_min"] = circle_min_cubics(r, E_PER)
        big = sum(len(p) for p, _ in paths) > 15_000
        for lib in ("fit-curve", "paper"):
            if big:  # large sets: the peers' error search would take many minutes
                continue
            row[lib] = best_peer(lib, paths)
        rows.append(row)
        peers = "  ".join(
            f"{lib}: {row[lib].get('segments', '-')} (err {row[lib].get('err', math.nan):.4f})"
            for lib in ("fit-curve", "paper")
            if lib in row
        )
        cm = f"  circle min: {row['circle_min']}" if "circle_min" in row else ""
        print(
            f"{name:28s} ours: {o['segments']} segs ({o['cubics']} cubics, {o['lines']} lines), "
            f"err {o['err']:.4f}, viol {o['violations']}, {o['pts_per_s']:,.0f} pts/s  "
            f"{peers}{cm}",
            flush=True,
        )
    drawings = drawing_speeds(args.baseline, args.reps)
    # paper 000 Table 1
    d = read_file(os.path.join(samples, "curve_1181.plt"))
    fit_report(d)
    reps = [fit_report(d) for _ in range(5)]
    rep = min(reps, key=lambda x: x["seconds"])
    print(f"Table 1: {rep}", flush=True)
    res = dict(rows=rows, table1=rep, drawings=drawings)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(res, f, indent=1, default=float)
    return res


if __name__ == "__main__":
    main()
