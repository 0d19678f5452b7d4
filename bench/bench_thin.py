"""Line thinning benchmark: vertex counts against Douglas–Peucker (shapely) and the optimum.

The optimum is Imai–Iri's min-# polyline approximation with the SAME criterion as
:func:`galvo_core.thin.thin`: a shortcut P_i -> P_j (i < j, vertices are input points) is
valid when every point strictly between lies within eps of the *segment* [P_i, P_j]; the
fewest vertices is a shortest path in the DAG of valid shortcuts. The valid j of each i are
found exactly: a direction test against the intersection of the points' wedges (necessary
for the segment, since the segment lies on the ray) prunes, and the exact point-to-segment
distance decides every candidate whose in-between points are not all closer to P_i than P_j.

Usage: python bench/bench_thin.py [--json out.json]
       python bench/bench_thin.py --old OLD_THIN.py [--reps N] [--json out.json]

With ``--old`` only the speed curves are run, the given frozen copy of galvo_core/thin.py
and the current one interleaved (best of N each, same process), with the load average
before and after; every path's kept indices are compared too (the speed rows of
bench/RESULTS.md come from this).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

from galvo_core.hpgl import read_file  # noqa: E402
from galvo_core.thin import dedup_indices, thin, thin_many  # noqa: E402

ROOT = os.path.join(os.path.dirname(__file__), "..")
CORPUS = os.environ.get("GALVO_CORPUS", os.path.join(ROOT, "..", "shared", "corpus", "plt"))
if not os.path.isdir(CORPUS):
    CORPUS = "/work/shared/corpus/plt"
#: corpus files with runs of dense curves (chosen by their thinning ratio, see RESULTS.md)
CORPUS_FILES = [
    "vk2bea__hpgl-plotter__tektronix.hpgl",
    "hpgl-buddy__hpgl-buddy__demo-g.hpgl",
    "drepetto__chiplotle__foal_release-0.1.hpgl",
    "dgtlrift__hp2xx__ci.hp",
    "drepetto__chiplotle__bird_by_brian_whitman_and_kelly_dobson.hpgl",
    "dgtlrift__hp2xx__spectrum.plt",
    "vk2bea__hpgl-plotter__space-shuttle.hpgl",
    "dylanvanassche__java-hpgl2gcode__randomledcontroller_pen3.plt",
    "bblanchon__hpglviewer__gl-c-f.plt",
]


def _seg_dist_max(q: np.ndarray, i: int, j: int) -> float:
    a = q[i]
    ab = q[j] - a
    ap = q[i + 1 : j] - a
    den = float(ab @ ab)
    s = np.clip((ap @ ab) / den, 0.0, 1.0) if den > 0 else np.zeros(len(ap))
    e = ap - s[:, None] * ab
    return float(np.sqrt((e * e).sum(axis=1).max()))


def valid_ends(q: np.ndarray, i: int, eps: float) -> np.ndarray:
    """Every j > i with [q_i, q_j] within eps of all points between (exact)."""
    n = len(q)
    w = 64
    while True:
        e = min(n - 1, i + w)
        v = q[i + 1 : e + 1] - q[i]
        r = np.hypot(v[:, 0], v[:, 1])
        far = r > eps
        if not far.any():
            if e == n - 1:
                return np.arange(i + 1, n)
            w *= 2
            continue
        f0 = int(np.argmax(far))
        d0 = v[f0] / r[f0]
        theta = np.arctan2(d0[0] * v[:, 1] - d0[1] * v[:, 0], v @ d0)
        wd = np.arcsin(np.minimum(eps / np.where(far, r, 1.0), 1.0))
        lo = np.maximum.accumulate(np.where(far, theta - wd, -np.inf))
        hi = np.minimum.accumulate(np.where(far, theta + wd, np.inf))
        empty = lo > hi
        m_stop = int(np.argmax(empty)) if empty.any() else len(r)
        if m_stop >= len(r) and e < n - 1:
            w *= 2
            continue
        mm = min(m_stop + 1, len(r))
        rmax = np.maximum.accumulate(r)
        th = theta[1:mm]
        slack = 1e-9
        inw = (th >= lo[: mm - 1] - slack) & (th <= hi[: mm - 1] + slack)
        out = [i + 1]
        sure = inw & (rmax[: mm - 1] <= r[1:mm]) & far[1:mm]
        sure &= (th >= lo[: mm - 1] + slack) & (th <= hi[: mm - 1] - slack)
        for m in np.flatnonzero(inw | ~far[1:mm]) + 1:
            j = i + 1 + int(m)
            if sure[m - 1] or _seg_dist_max(q, i, j) <= eps:
                out.append(j)
        return np.asarray(out)


def imai_iri(q: np.ndarray, eps: float) -> int:
    """Fewest vertices (distinct consecutive points ``q``) for tolerance eps."""
    n = len(q)
    if n <= 2:
        return n
    best = np.full(n, np.iinfo(np.int64).max)
    best[0] = 1
    for i in range(n - 1):
        js = valid_ends(q, i, eps)
        np.minimum.at(best, js, best[i] + 1)
    return int(best[-1])


def shapely_dp(points: np.ndarray, eps: float) -> int:
    import shapely

    p = points[dedup_indices(points)]
    if len(p) < 2:
        return len(p)
    ls = shapely.LineString(p)
    return len(shapely.get_coordinates(shapely.simplify(ls, eps, preserve_topology=False)))


def circles() -> list[np.ndarray]:
    out = []
    rng = np.random.default_rng(5)
    for r, n, noise in [(50, 400, 0.0), (400, 1181, 0.0), (2000, 20000, 0.0), (400, 3000, 0.004)]:
        t = np.linspace(0, 2 * np.pi, n)
        p = np.c_[r * np.cos(t), r * np.sin(t)] + rng.normal(0, noise, (n, 2))
        p[-1] = p[0]
        out.append(p)
    return out


def paths_of(path: str) -> list[np.ndarray]:
    return [np.asarray(p.points, float) for p in read_file(path).paths if len(p.points) >= 2]


def corpus_paths() -> list[np.ndarray]:
    """The paths of every CORPUS_FILES file present (none when the corpus is not beside)."""
    corp: list[np.ndarray] = []
    for f in CORPUS_FILES:
        fp = os.path.join(CORPUS, f)
        if os.path.exists(fp):
            corp += paths_of(fp)
    return corp


def datasets() -> list[tuple[str, list[np.ndarray], list[float]]]:
    sets = [("circles", circles(), [0.02, 0.1])]
    glyph = os.path.join(ROOT, "resources", "samples", "text_outline.plt")
    sets.append(("glyph outlines (text_outline.plt)", paths_of(glyph), [0.02, 0.5]))
    corp = corpus_paths()
    if corp:
        sets.append((f"corpus ({len(CORPUS_FILES)} files)", corp, [0.02, 1.0]))
    return sets


def sines(n: int = 100_000, seed: int = 1) -> np.ndarray:
    """The speed curve: a sum of three sines, 100k points over x in [0, 3000]."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(0, 3000, n))
    y = sum(
        rng.uniform(5, 60) * np.sin(x / rng.uniform(8, 80) + rng.uniform(0, 6)) for _ in range(3)
    )
    return np.c_[x, y]


def sparse_walk(n: int = 20_000, seed: int = 2) -> np.ndarray:
    """Few points per kept line: a random walk with steps ~25x the tolerance."""
    rng = np.random.default_rng(seed)
    return np.cumsum(rng.normal(0, 0.5, (n, 2)), axis=0)


def timed(paths: list[np.ndarray], eps: float, reps: int = 5, many: bool = False):
    """Best wall time of thinning all ``paths`` (one thin() per path, or one thin_many())."""
    best = math.inf
    kept = 0
    for _ in range(reps):
        t0 = time.perf_counter()
        if many:
            kept = sum(len(k) for k in thin_many(paths, eps))
        else:
            kept = sum(len(thin(p, eps)) for p in paths)
        best = min(best, time.perf_counter() - t0)
    return best, kept


def speed_inputs() -> list[tuple[str, list[np.ndarray], float]]:
    """The speed curves: (name, paths, eps) as the fitter thins them (one thin_many call)."""
    t = np.linspace(0, 2 * np.pi, 200_000)
    out = [
        ("sines 100k", [sines()], 0.02),
        ("ellipse 200k", [np.c_[400 * np.cos(t), 300 * np.sin(t)]], 0.02),
        ("sparse walk 20k", [sparse_walk()], 0.02),
        ("sparse walk 20k", [sparse_walk()], 1.0),
    ]
    corp = corpus_paths()
    if corp:
        out += [(f"corpus {len(CORPUS_FILES)} files", corp, e) for e in (0.02, 1.0)]
    samples = os.path.join(ROOT, "resources", "samples")
    seal = paths_of(os.path.join(samples, "seal.plt"))
    out += [("seal.plt", seal, e) for e in (0.02, 0.5)]
    out.append(("curve_1181.plt", paths_of(os.path.join(samples, "curve_1181.plt")), 0.02))
    glyphs = paths_of(os.path.join(samples, "text_outline.plt"))
    out += [("text_outline.plt", glyphs, e) for e in (0.02, 0.5)]
    noten = os.path.join(CORPUS, "h42i__monoplots__noten.hpgl")
    if os.path.exists(noten):
        out += [("noten.hpgl", paths_of(noten), e) for e in (0.02, 0.5)]
    return out


def compare_old(old_path: str, reps: int) -> list[dict]:
    """Old (frozen copy at ``old_path``) against current ``thin_many``, interleaved."""
    spec = importlib.util.spec_from_file_location("thin_old", old_path)
    assert spec is not None and spec.loader is not None
    old = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(old)
    rows = []
    print(f"load average before: {os.getloadavg()}", flush=True)
    for name, paths, eps in speed_inputs():
        n = sum(len(p) for p in paths)
        best = {"old": math.inf, "new": math.inf}
        res = {}
        for _ in range(reps):
            for lab, fn in (("old", old.thin_many), ("new", thin_many)):
                t0 = time.perf_counter()
                res[lab] = fn(paths, eps)
                best[lab] = min(best[lab], time.perf_counter() - t0)
        same = all(np.array_equal(a, b) for a, b in zip(res["old"], res["new"], strict=True))
        row = dict(
            set=name,
            eps=eps,
            paths=len(paths),
            points=n,
            kept=sum(len(k) for k in res["new"]),
            old_pts_per_s=n / best["old"],
            new_pts_per_s=n / best["new"],
            identical=same,
            load=os.getloadavg()[0],
        )
        rows.append(row)
        print(
            f"{name:18s} eps={eps:<5} paths={len(paths):5d} n={n:7d} kept={row['kept']:6d} "
            f"old {n / best['old'] / 1e6:6.3f}M  new {n / best['new'] / 1e6:6.3f}M pts/s  "
            f"x{best['old'] / best['new']:.2f}  identical={same}  load {row['load']:.2f}",
            flush=True,
        )
    print(f"load average after: {os.getloadavg()}", flush=True)
    return rows


def main() -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--json")
    ap.add_argument("--old", help="frozen copy of galvo_core/thin.py to time against")
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    if args.old:
        cmp = compare_old(args.old, args.reps)
        if args.json:
            with open(args.json, "w") as f:
                json.dump(dict(compare=cmp), f, indent=1)
        return dict(compare=cmp)
    rows = []
    for name, paths, epss in datasets():
        n_in = sum(len(p) for p in paths)
        for eps in epss:
            ours = sum(len(thin(p, eps)) for p in paths)
            dp = sum(shapely_dp(p, eps) for p in paths)
            opt = sum(imai_iri(p[dedup_indices(p)], eps) for p in paths)
            dt, _ = timed(paths, eps, reps=3)
            dtm, _ = timed(paths, eps, reps=3, many=True)
            row = dict(
                set=name,
                eps=eps,
                paths=len(paths),
                points=n_in,
                ours=ours,
                dp=dp,
                opt=opt,
                ratio=ours / opt,
                dp_ratio=dp / opt,
                pts_per_s=n_in / dt,
                pts_per_s_many=n_in / dtm,
            )
            rows.append(row)
            print(
                f"{name:38s} eps={eps:<5} n={n_in:7d} ours={ours:6d} DP={dp:6d} "
                f"opt={opt:6d} ours/opt={ours / opt:.4f} DP/opt={dp / opt:.3f} "
                f"{n_in / dt:,.0f} pts/s (thin_many {n_in / dtm:,.0f})",
                flush=True,
            )
    speed = []
    for name, p in [
        ("sines 100k", sines()),
        ("ellipse 200k", None),
        ("sparse walk 20k", sparse_walk()),
    ]:
        if p is None:
            t = np.linspace(0, 2 * np.pi, 200_000)
            p = np.c_[400 * np.cos(t), 300 * np.sin(t)]
        dt, kept = timed([p], 0.02)
        best_n = imai_iri(p[dedup_indices(p)], 0.02) if len(p) <= 100_000 else None
        speed.append(dict(set=name, points=len(p), kept=kept, opt=best_n, pts_per_s=len(p) / dt))
        print(f"speed {name:18s} kept={kept:6d} opt={best_n} {len(p) / dt:,.0f} pts/s", flush=True)
    # whole drawings through thin_many (how the fitter thins): many small paths
    for name, fp, eps in [
        ("seal.plt", os.path.join(ROOT, "resources", "samples", "seal.plt"), 0.02),
        ("text_outline.plt", os.path.join(ROOT, "resources", "samples", "text_outline.plt"), 0.5),
        ("noten.hpgl", os.path.join(CORPUS, "h42i__monoplots__noten.hpgl"), 0.02),
    ]:
        if not os.path.exists(fp):
            continue
        ps = paths_of(fp)
        n = sum(len(p) for p in ps)
        dt, kept = timed(ps, eps, reps=3, many=True)
        speed.append(dict(set=name, eps=eps, paths=len(ps), points=n, kept=kept, pts_per_s=n / dt))
        print(
            f"speed {name:18s} eps={eps} paths={len(ps)} kept={kept} {n / dt:,.0f} pts/s",
            flush=True,
        )
    res = dict(rows=rows, speed=speed)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(res, f, indent=1)
    return res


if __name__ == "__main__":
    main()
