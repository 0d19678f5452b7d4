"""Fit throughput with the precision detection (issue 16): 1 M input points of the speed
curve (bench_thin.sines) as 10 paths, exact and rounded to whole units; CPU time
(time.process_time; also wall time, which the kernel threads of galvo_core.parallel
shorten: ``GALVO_THREADS=1`` for one), best of N, fit_drawing with the defaults (quantum
detected) against quantum_units=0 given (no detection, the rounding ignored: today's fit).
``--nesting``: the refit of the corpus's fabric nesting file (40,705 paths) at e_per 0.05 and 0.02.

``--code DIR`` imports galvo_core from another checkout (e.g. ``git worktree add /tmp/wt-66c
66c99cd``), to measure two versions side by side in the same minutes (alternate the runs).

``--plt FILE`` (issue 16, third round): ``fit_drawing`` on that file's drawing (e.g.
``python bench/gen_plt.py 1000000 /tmp/g1m.plt``), best of N after a warm-up, the module
actually imported and a hash of the fitted arrays (kinds, points, first/last, max_error,
counts: equal hashes = the same fit bit for bit). ``--profile`` adds a cProfile of one run.

``--sparse`` (issue 16, fifth round): the same on 1 M whole-unit points of font-like smooth
closed outlines (516 ellipses with a k-lobed wobble, points 1-2 units apart, seeded).

``--sparse --truth`` (s14): no timing; each sparse path's fit against its unrounded curve.

Usage: python bench/bench_precision_speed.py [--reps 3] [--code DIR] [--only exact|whole]
       [--nesting] [--plt FILE | --sparse [--profile | --truth]]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
NESTING = os.path.join(HERE, "..", "..", "shared", "corpus", "plt",
                       "straight-coding__gcode-hpgl-viewer__b_fabric_nesting.plt")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--code", help="import galvo_core from this checkout")
    ap.add_argument("--only", choices=("exact", "whole"))
    ap.add_argument("--nesting", action="store_true", help="the nesting refit only")
    ap.add_argument("--plt", help="fit_drawing on this file only")
    ap.add_argument("--sparse", action="store_true",
                    help="fit_drawing on 1 M whole-unit points of font-like outlines only")
    ap.add_argument("--profile", action="store_true",
                    help="with --plt/--sparse: cProfile one run")
    ap.add_argument("--truth", action="store_true",
                    help="with --sparse: each path's fit against its unrounded curve (both "
                         "ways), no timing")
    a = ap.parse_args()
    root = os.path.abspath(a.code) if a.code else os.path.join(HERE, "..")
    sys.path.insert(0, root)
    sys.path.insert(1, os.path.join(root, "bench"))  # (its bench_thin puts its root first)
    from bench_thin import sines

    from galvo_core.drawing import Drawing, Path
    from galvo_core.fit import fit_drawing, warm_up

    def segments(f) -> int:
        return sum(len(x.is_cubic) if hasattr(x, "is_cubic") else len(x.segments) for x in f)

    warm_up()
    tag = a.code or "this checkout"
    if a.plt or a.sparse:
        import hashlib

        import galvo_core
        from galvo_core import hpgl

        truths: list = []
        d = hpgl.read_file(a.plt) if a.plt else sparse_outlines(Drawing, Path, truths=truths)
        if a.truth and a.sparse:
            sparse_truth(d, truths, fit_drawing)
            return
        try:
            from galvo_core.parallel import THREADS as threads
        except ImportError:  # (older code: one thread)
            threads = 1
        n = sum(len(p.points) for p in d.paths)
        times = []
        walls = []
        for _ in range(a.reps):
            w0 = time.perf_counter()
            t0 = time.process_time()
            f = fit_drawing(d)
            times.append(time.process_time() - t0)
            walls.append(time.perf_counter() - w0)
        h = hashlib.sha256()
        for x in f:
            if hasattr(x, "is_cubic"):
                arrs = (x.is_cubic, x.points, x.first, x.last)
            else:  # (older code: segments only)
                arrs = (np.array([s.kind == "cubic" for s in x.segments]),
                        np.concatenate([s.points for s in x.segments]) if x.segments
                        else np.zeros((0, 2)),
                        np.array([s.first for s in x.segments], dtype=np.int64),
                        np.array([s.last for s in x.segments], dtype=np.int64))
            for arr in arrs:
                h.update(np.ascontiguousarray(arr).tobytes())
            h.update(np.float64(x.max_error).tobytes())
            h.update(np.int64([x.n_input, x.n_thinned]).tobytes())
        best = min(times)
        name = os.path.basename(a.plt) if a.plt else "sparse"
        print(f"{galvo_core.__file__}: {name} {len(d.paths)} paths {n} "
              f"points  best {best:.3f} s CPU (all: {' '.join(f'{t:.3f}' for t in times)})  "
              f"{n / best / 1e3:.0f} k points/s  wall best {min(walls):.3f} s "
              f"({n / min(walls) / 1e3:.0f} k/s, {threads} threads)  {segments(f)} segments  "
              f"sha256 {h.hexdigest()[:16]}  load {os.getloadavg()[0]:.1f}", flush=True)
        if a.profile:
            import cProfile
            import pstats

            pr = cProfile.Profile()
            pr.enable()
            fit_drawing(d)
            pr.disable()
            pstats.Stats(pr).sort_stats("tottime").print_stats(25)
        return
    if a.nesting:
        from galvo_core import hpgl

        d = hpgl.read_file(NESTING)
        n = sum(len(p.points) for p in d.paths)
        for e_per in (0.05, 0.02):
            best = np.inf
            for _ in range(a.reps):
                t0 = time.process_time()
                f = fit_drawing(d, e_per=e_per)
                best = min(best, time.process_time() - t0)
            print(f"{tag}: nesting {len(d.paths)} paths {n} points e_per {e_per}  "
                  f"{best:.3f} s CPU  {segments(f)} segments", flush=True)
        return
    paths = [sines(100_000, seed=s) + [0.0, 200.0 * s] for s in range(10)]
    for label, pts in (("exact", paths), ("whole units", [np.round(p) for p in paths])):
        if a.only and not label.startswith(a.only):
            continue
        d = Drawing(tuple(Path(p, 1, False) for p in pts), name=label)
        n = sum(len(p) for p in pts)
        for qu in (None, 0.0):
            if a.only and qu is not None:
                continue
            best = wall = np.inf
            for _ in range(a.reps):
                w0 = time.perf_counter()
                t0 = time.process_time()
                f = fit_drawing(d, quantum_units=qu) if qu is not None else fit_drawing(d)
                best = min(best, time.process_time() - t0)
                wall = min(wall, time.perf_counter() - w0)
            print(f"{tag}: {label:12s} quantum {'detected' if qu is None else 'given 0':9s} "
                  f"{n} points  {best:.2f} s CPU  {n / best / 1e3:.0f} k points/s  "
                  f"wall {wall:.2f} s  {segments(f)} segments", flush=True)


def _sparse_params(rng):
    """One outline's parameters, drawn from ``rng`` (in the generator's order)."""
    ax, ay = rng.uniform(60, 400, 2)
    cx, cy = rng.uniform(0, 3000, 2)
    rot = rng.uniform(0, np.pi)
    k = rng.integers(2, 6)
    amp = rng.uniform(0.0, 0.2)
    return ax, ay, cx, cy, rot, k, amp


def _sparse_curve(ax, ay, cx, cy, rot, k, amp):
    """(rounded points, unrounded curve closed) of one outline."""
    t = np.linspace(0, 2 * np.pi, 40000, endpoint=False)
    r = 1.0 + amp * np.cos(k * t)
    x, y = ax * r * np.cos(t), ay * r * np.sin(t)
    c, s = np.cos(rot), np.sin(rot)
    tr = np.stack([cx + c * x - s * y, cy + s * x + c * y], axis=1)
    w = np.round(tr)
    w = w[np.r_[True, (w[1:] != w[:-1]).any(axis=1)]]
    if (w[-1] == w[0]).all():
        w = w[:-1]
    return w, np.vstack([tr, tr[:1]])


def sparse_outline(i: int):
    """Outline i of :func:`sparse_outlines`: (rounded points, unrounded curve closed)."""
    rng = np.random.default_rng(5)
    for _ in range(i):
        _sparse_params(rng)
    return _sparse_curve(*_sparse_params(rng))


def sparse_outlines(Drawing, Path, n_points: int = 1_000_000,  # noqa: N803 (the classes)
                    truths: list | None = None):
    """Closed smooth outlines rounded to whole units, font-like spacing (1-2 units between
    points): ellipses (axes 60-400) with a k-lobed radial wobble, seeded. ``truths``: gets
    each outline's unrounded curve (40,000 points, closed)."""
    rng = np.random.default_rng(5)
    paths = []
    n = 0
    while n < n_points:
        w, tr = _sparse_curve(*_sparse_params(rng))
        if truths is not None:
            truths.append(tr)
        paths.append(w)
        n += len(w)
    return Drawing(tuple(Path(p, 1, True) for p in paths), name="sparse")


def sparse_truth(d, truths, fit_drawing) -> None:
    """Per path of the sparse outlines: the fit's both-ways distance to the unrounded
    curve (the fit flattened at 0.01 units; :func:`fonts.curve_distance`); the largest,
    the 99th percentile and mean of the per-path largest, the paths over 0.6, and the
    worst paths with the place and the design's direction there (degrees from the
    nearest axis: 0 axis-parallel, 45 diagonal)."""
    from bench_precision import fitted_dense
    from fonts import curve_distance

    from galvo_core.geometry import point_polyline_distance

    f = fit_drawing(d)
    res = []
    for fp, tr in zip(f, truths, strict=True):
        res.append(curve_distance(fitted_dense(fp, 0.01), tr))
    r = np.array(res)
    print(f"sparse: {len(r)} paths, {sum(len(x.is_cubic) for x in f)} segments; distance to the "
          f"design per path: max {r.max():.3f}, p99 {np.percentile(r, 99):.3f}, mean "
          f"{r.mean():.3f}; paths over 0.6: {int((r > 0.6).sum())}")
    for i in np.argsort(-r)[:8].tolist():
        dd = fitted_dense(f[i], 0.01)
        tr = truths[i]
        a = point_polyline_distance(dd, tr)
        p = dd[int(np.argmax(a))]
        j = int(np.argmin(((tr - p) ** 2).sum(axis=1)))
        v = tr[(j + 20) % len(tr)] - tr[j - 20]
        ang = float(np.degrees(np.arctan2(v[1], v[0])) % 90)
        print(f"  path {i}: {r[i]:.3f} (fit to design {a.max():.3f} at "
              f"({p[0]:.1f}, {p[1]:.1f}), {min(ang, 90 - ang):.0f} deg from an axis)")


if __name__ == "__main__":
    main()
