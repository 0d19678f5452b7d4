"""Fitting a path with lines and cubic Béziers (paper 000 §2–3).

Pipeline per path: drop duplicates and thin with ``eps_line`` (:mod:`galvo_core.thin`), find
curve runs and split them at < 90° turning (:mod:`galvo_core.runs`), then fit each curve
piece with the paper's *triangular dichotomy*: with end tangents T0, T3 meeting in Q,

    P0 = B_first, P3 = B_last, P1 = P0 + t·(Q − P0), P2 = P3 + t·(Q − P3),

and one parameter t ∈ [0, 1] chosen so that the signed error sum Σε_i crosses zero
(|Σε_i| < ``eps_sum``). ε_i = ±e_i where e_i is the TRUE distance of data point i to the
curve (nearest point, not the point at some parameter); it is positive when the point lies on
Q's side of the curve (the curve is inside, t too small), negative when the curve lies beyond
the point. t = 0 (the chord) gives Σ > 0, t = 1 gives Σ < 0; the bracket is narrowed by
bisection accelerated with false-position steps (Illinois), which finds the same root as the
paper's halving in far fewer curve evaluations.

Guarantee (checked for every cubic before it is accepted, and by :func:`check_fit`):

* every input point replaced by a cubic lies within ``e_per`` of it; every input point
  replaced by a line within ``eps_line`` of it (true distances);
* no point of a cubic lies farther than ``e_per`` from the input polyline it replaces: the
  check bounds, for every pair of consecutive input points, the distance of the curve stretch
  between their nearest points to the segment joining them (extremes of the perpendicular
  and along-segment coordinates, both polynomials in the curve parameter), so a curve cannot
  bulge between sparse points. A line replacing thinned points is within ``eps_line`` of the
  polyline by construction of the thinning.

A piece that fails is split at the crossing of data and curve (the interior thinned point
with the smallest error, away from the ends) and both halves are fitted again; a piece of
two thinned points is a line (always within ``eps_line``). So the guarantee holds whatever
the dichotomy does, and lines are the last resort.

All curve pieces of a path are fitted together, round by round (:class:`_BatchFitter`): one
set of array operations per dichotomy step for every open piece, one vectorised acceptance
test, the failures split for the next round. The bisection uses up to 128 of the piece's
input points (every k-th); the acceptance test uses every input point, with nearest points
from Newton steps seeded by arc length (a seeded search only for points over the bound).
Any curve parameter gives an upper bound of the true distance, so the acceptance is never
too lenient; ``max_error`` is made exact by re-measuring the worst cubics with the seeded
nearest-point search.

``eps_sum`` default: 0.002 input units (one tenth of the paper's e_per). The paper gives no
value; it only decides when the bisection stops, the acceptance is decided by ``e_per``. A
bracket on t narrower than 1e-9 also stops it.

Units: input units (HP-GL plotter units) throughout.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from galvo_core.drawing import Drawing
from galvo_core.errors import ParamError
from galvo_core.geometry import (
    cubic_eval,
    cubic_length,
    gather_coeffs,
    nearest_on_cubic,
    nearest_on_cubics,
    newton_nearest_many,
    point_polyline_distance,
    point_segment_distance,
    power_coeffs_many,
)
from galvo_core.runs import split_pieces
from galvo_core.thin import check_positive, thin_many

__all__ = [
    "DEFAULT_EPS_LINE",
    "DEFAULT_E_PER",
    "DEFAULT_EPS_SUM",
    "Segment",
    "FittedPath",
    "fit_path",
    "fit_paths",
    "FitCancelled",
    "fit_drawing",
    "fit_report",
    "check_fit",
    "control_points",
]

DEFAULT_EPS_LINE = 0.02
DEFAULT_E_PER = 0.02
DEFAULT_EPS_SUM = 0.002

_BISECT_SAMPLE = 128
_MAX_BISECT = 40


@dataclass(frozen=True, slots=True, eq=False)
class Segment:
    """One fitted segment.

    kind: "line" (``points`` (2, 2)) or "cubic" (``points`` (4, 2): P0, P1, P2, P3), float64
    input units, read-only. ``first``..``last`` (inclusive) are the indices into the path's
    points that this segment replaces; consecutive segments share the boundary index. For a
    closed path given without its closing point, index N stands for point 0 again.
    """

    kind: str
    points: np.ndarray
    first: int
    last: int

    @property
    def start(self) -> np.ndarray:
        return self.points[0]

    @property
    def end(self) -> np.ndarray:
        return self.points[-1]


@dataclass(frozen=True, eq=False)
class FittedPath:
    """The fitted form of one :class:`~galvo_core.drawing.Path`.

    ``segments`` are continuous (each starts exactly where the previous ended; a closed
    path's last ends exactly at the first's start). ``max_error`` is the largest true
    distance from an input point to its segment (input units). ``n_thinned`` is the number of
    points left by the line thinning.
    """

    source_index: int
    pen: int
    closed: bool
    segments: tuple[Segment, ...]
    max_error: float
    n_input: int
    n_thinned: int = 0

    @property
    def n_lines(self) -> int:
        return sum(1 for s in self.segments if s.kind == "line")

    @property
    def n_cubics(self) -> int:
        return sum(1 for s in self.segments if s.kind == "cubic")


def control_points(fp: FittedPath) -> int:
    """Control points of a fitted path, counted as stored: the start point plus, per segment,
    its points minus the shared start (1 per line, 3 per cubic); a closed path's closing
    point counts again (as in paper 000: a circle of 13 cubics = 40 points). A dot is 1."""
    if not fp.segments:
        return 0
    if len(fp.segments) == 1 and fp.segments[0].kind == "line":
        s = fp.segments[0]
        if np.array_equal(s.points[0], s.points[1]):
            return 1
    return 1 + sum(len(s.points) - 1 for s in fp.segments)


def _check_params(eps_line: object, e_per: object, eps_sum: object) -> tuple[float, float, float]:
    return (
        check_positive("eps_line", eps_line),
        check_positive("e_per", e_per),
        check_positive("eps_sum", eps_sum),
    )


def _seg(kind: str, pts: np.ndarray, first: int, last: int) -> Segment:
    arr = np.array(pts, dtype=np.float64)
    arr.setflags(write=False)
    return Segment(kind, arr, int(first), int(last))


def _curve_to_polyline_bound_many(
    cf: tuple[np.ndarray, ...], a: np.ndarray, b: np.ndarray, u0: np.ndarray, u1: np.ndarray
) -> np.ndarray:
    """Per pair k: an upper bound of the distance from the curve stretch u0[k]..u1[k] of
    cubic ``cf`` (per-pair power coefficients) to the segment [a[k], b[k]] (see module doc).

    |perpendicular| and overshoot beyond the segment's ends are maximised exactly over the
    stretch (end values and roots of their derivatives, quadratics in u).
    """
    ax, ay, bx, by, dx, dy, ex, ey = cf
    lo = np.minimum(u0, u1)
    hi = np.maximum(u0, u1)
    abx = b[:, 0] - a[:, 0]
    aby = b[:, 1] - a[:, 1]
    ln = np.hypot(abx, aby)
    good = ln > 0.0
    inv = 1.0 / np.where(good, ln, 1.0)
    tx, ty = abx * inv, aby * inv  # direction
    nx, ny = -ty, tx  # normal
    # B'(u) = 3a u^2 + 2b u + d
    cands = [lo, hi, 0.5 * (lo + hi)]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for vx, vy in ((nx, ny), (tx, ty)):
            qa = 3.0 * (ax * vx + ay * vy)
            qb = 2.0 * (bx * vx + by * vy)
            qc = dx * vx + dy * vy
            disc = qb * qb - 4.0 * qa * qc
            sq = np.sqrt(np.maximum(disc, 0.0))
            lin = np.abs(qa) <= 1e-14 * (np.abs(qb) + np.abs(qc) + 1e-300)
            for sgn in (1.0, -1.0):
                r = np.where(lin, -qc / qb, (-qb + sgn * sq) / (2.0 * qa))
                r = np.where((np.isfinite(r) & (disc >= 0.0)) | lin, r, lo)
                cands.append(np.clip(np.nan_to_num(r, nan=0.0), lo, hi))
    perp = np.zeros(len(a))
    over = np.zeros(len(a))
    for uu in cands:
        px = ((ax * uu + bx) * uu + dx) * uu + ex - a[:, 0]
        py = ((ay * uu + by) * uu + dy) * uu + ey - a[:, 1]
        s = px * tx + py * ty
        p = np.abs(px * nx + py * ny)
        o = np.maximum(np.maximum(-s, s - ln), 0.0)
        # a zero-length segment is its point
        p = np.where(good, p, np.hypot(px, py))
        o = np.where(good, o, 0.0)
        np.maximum(perp, p, out=perp)
        np.maximum(over, o, out=over)
    return np.sqrt(perp * perp + over * over)


def _ragged(starts: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(owner, offset) of the flattened ranges: item j of range r -> (r, j)."""
    total = int(counts.sum())
    owner = np.repeat(np.arange(len(counts)), counts)
    off = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    return owner, off


class _BatchFitter:
    """Fits all curve pieces of one path together, round by round.

    Each round takes every piece still to do, runs the dichotomy for all of them at once
    (one set of array operations per step, whatever the number of pieces), tests them all
    at once, keeps the cubics that pass and splits the others for the next round. The
    work per round is linear in the points of the pieces still open.
    """

    def __init__(
        self,
        work: np.ndarray,
        kept: np.ndarray,
        t_in: np.ndarray,
        t_out: np.ndarray,
        e_per: float,
        eps_sum: float,
        arc: np.ndarray | None = None,
    ) -> None:
        self.work = work
        self.kept = kept
        self.q = work[kept]
        self.t_in = t_in
        self.t_out = t_out
        self.e_per = e_per
        self.eps_sum = eps_sum
        if arc is None:
            seg = np.hypot(*np.diff(work, axis=0).T)
            arc = np.concatenate(([0.0], np.cumsum(seg)))
        #: cumulative arc length (per path when several paths are concatenated)
        self.arc = arc
        #: accepted cubics: (a, b, ctrl, bound of the max input error)
        self.cubics: list[tuple[int, int, np.ndarray, float]] = []
        self.lines: list[int] = []  # a of line pieces (a, a + 1)

    # -- the one-parameter family ---------------------------------------------------------
    def _triangle(self, A: np.ndarray, B: np.ndarray):
        p0, p3 = self.q[A], self.q[B]
        t0, t3 = self.t_out[A], self.t_in[B]
        det = t0[:, 0] * t3[:, 1] - t0[:, 1] * t3[:, 0]
        ch = p3 - p0
        lc = np.hypot(ch[:, 0], ch[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            al = (ch[:, 0] * t3[:, 1] - ch[:, 1] * t3[:, 0]) / det
            be = (t0[:, 0] * ch[:, 1] - t0[:, 1] * ch[:, 0]) / det
        ok = (
            (lc > 0.0)
            & (np.abs(det) >= 1e-9)
            & (al > 1e-9 * lc)
            & (be > 1e-9 * lc)
            & (al <= 1e3 * lc)
            & (be <= 1e3 * lc)
        )
        qq = p0 + np.where(ok, al, 0.0)[:, None] * t0
        return ok, p0, qq, p3, np.sign(det)

    @staticmethod
    def _ctrl(p0, qq, p3, t):
        t = t[:, None]
        return np.stack([p0, p0 + t * (qq - p0), p3 + t * (qq - p3), p3], axis=1)

    def _dichotomy(self, p0, qq, p3, sig, i0, i1) -> np.ndarray:
        """t per piece: the signed error sum over a sample of each piece's input points
        crosses zero (Illinois false position inside the bracket [0, 1])."""
        m = len(p0)
        L = i1 - i0 - 1
        stride = np.maximum(1, -(-L // _BISECT_SAMPLE))
        cnt = -(-L // stride)
        pid, off = _ragged(np.zeros(m, dtype=np.intp), cnt)
        idx = i0[pid] + 1 + stride[pid] * off
        pts = self.work[idx]
        px, py = pts[:, 0].copy(), pts[:, 1].copy()
        span = self.arc[i1] - self.arc[i0]
        u = (self.arc[idx] - self.arc[i0][pid]) / np.where(span > 0, span, 1.0)[pid]
        chord = (p3 - p0)[pid]
        chord2 = (chord * chord).sum(axis=1)
        sg = sig[pid]
        ustate = u.copy()

        def ssum(t: np.ndarray, pm: np.ndarray | None = None) -> np.ndarray:
            """Signed error sums of all pieces at ``t`` (only pieces with points ``pm``
            are evaluated, the others come back 0)."""
            pp = pid if pm is None else pid[pm]
            qx = px if pm is None else px[pm]
            qy = py if pm is None else py[pm]
            cf = gather_coeffs(power_coeffs_many(self._ctrl(p0, qq, p3, t)), pp)
            u0 = ustate if pm is None else ustate[pm]
            uu, d2 = newton_nearest_many(cf, qx, qy, u0, 3)
            if pm is None:
                ustate[:] = uu
            else:
                ustate[pm] = uu
            ch = chord if pm is None else chord[pm]
            ax, ay, bx, by, dx, dy, ex, ey = cf
            tx = (3.0 * ax * uu + 2.0 * bx) * uu + dx
            ty = (3.0 * ay * uu + 2.0 * by) * uu + dy
            bad = tx * tx + ty * ty <= 1e-18 * (chord2 if pm is None else chord2[pm])
            tx = np.where(bad, ch[:, 0], tx)
            ty = np.where(bad, ch[:, 1], ty)
            rx = qx - (((ax * uu + bx) * uu + dx) * uu + ex)
            ry = qy - (((ay * uu + by) * uu + dy) * uu + ey)
            side = np.sign(tx * ry - ty * rx)
            w = (sg if pm is None else sg[pm]) * side * np.sqrt(d2)
            return -np.bincount(pp, weights=w, minlength=m)

        tl = np.zeros(m)
        th = np.ones(m)
        sl = ssum(tl)
        sh = ssum(th)
        t = np.full(m, 0.5)
        done = np.zeros(m, dtype=bool)
        t[sl <= 0.0] = 0.0
        done |= sl <= 0.0
        hi_case = ~done & (sh >= 0.0)
        t[hi_case] = 1.0
        done |= hi_case
        ustate[:] = u
        side = np.zeros(m)
        for _ in range(_MAX_BISECT):
            if done.all():
                break
            with np.errstate(divide="ignore", invalid="ignore"):
                tn = (tl * sh - th * sl) / (sh - sl)
            bad = ~((tl < tn) & (tn < th))
            tn = np.where(bad, 0.5 * (tl + th), tn)
            tn = np.where(done, t, tn)
            s = ssum(tn, np.flatnonzero(~done[pid]))
            t = tn
            stop = ~done & ((np.abs(s) < self.eps_sum) | (th - tl < 1e-9))
            upd = ~done & ~stop
            pos = upd & (s > 0.0)
            neg = upd & ~(s > 0.0)
            sh = np.where(pos & (side == 1), 0.5 * sh, sh)
            tl = np.where(pos, t, tl)
            sl = np.where(pos, s, sl)
            sl = np.where(neg & (side == -1), 0.5 * sl, sl)
            th = np.where(neg, t, th)
            sh = np.where(neg, s, sh)
            side = np.where(pos, 1.0, np.where(neg, -1.0, side))
            done |= stop
        return self._ctrl(p0, qq, p3, t)

    def _accept(self, ctrl: np.ndarray, i0: np.ndarray, i1: np.ndarray):
        """Per piece: bound of the max input-point error, pass/fail of both sides of the
        guarantee, and the flat per-point errors (with the offsets of each piece)."""
        m = len(ctrl)
        cnt = i1 - i0 + 1
        pid, off = _ragged(np.zeros(m, dtype=np.intp), cnt)
        starts = np.cumsum(cnt) - cnt
        idx = i0[pid] + off
        pts = self.work[idx]
        px, py = pts[:, 0].copy(), pts[:, 1].copy()
        span = self.arc[i1] - self.arc[i0]
        u = (self.arc[idx] - self.arc[i0][pid]) / np.where(span > 0, span, 1.0)[pid]
        cf = gather_coeffs(power_coeffs_many(ctrl), pid)
        u, d2 = newton_nearest_many(cf, px, py, u, 6)
        # ends of each piece are the curve's ends
        ends = np.concatenate([starts, starts + cnt - 1])
        u[starts] = 0.0
        u[starts + cnt - 1] = 1.0
        d2[ends] = 0.0
        dist = np.sqrt(d2)
        e2 = self.e_per
        # Newton may have stopped in a local minimum: seeded search for the points over the
        # bound, in pieces that miss it by little (a piece far off is a bad fit anyway; the
        # check only decides between keeping and splitting, never weakens the guarantee)
        emax0 = np.maximum.reduceat(dist, starts)
        far = np.flatnonzero((dist > e2) & (emax0[pid] <= 4.0 * e2))
        if len(far):
            tu, td = nearest_on_cubics(ctrl, pid[far], pts[far])
            better = td < dist[far]
            u[far[better]] = tu[better]
            dist[far[better]] = td[better]
        emax = np.maximum.reduceat(dist, starts)
        ok = emax <= e2
        # curve-to-polyline side, for the pieces that passed so far
        pair = np.ones(len(idx), dtype=bool)
        pair[starts + cnt - 1] = False
        pair &= ok[pid]
        j = np.flatnonzero(pair)
        if len(j):
            pcf = tuple(c[j] for c in cf)
            bnd = _curve_to_polyline_bound_many(pcf, pts[j], pts[j + 1], u[j], u[j + 1])
            worst = np.zeros(m)
            np.maximum.at(worst, pid[j], bnd)
            ok &= worst <= e2
        return ok, emax, dist, starts

    def fit(self, curve_pieces: list[tuple[int, int]]) -> None:
        todo = [(a, b) for a, b in curve_pieces]
        while todo:
            ab = np.asarray(todo, dtype=np.intp).reshape(-1, 2)
            todo = []
            line = ab[:, 1] - ab[:, 0] == 1
            self.lines.extend(int(a) for a in ab[line, 0])
            ab = ab[~line]
            if len(ab) == 0:
                break
            A, B = ab[:, 0], ab[:, 1]
            ok, p0, qq, p3, sig = self._triangle(A, B)
            for a, b in ab[~ok]:
                k = (int(a) + int(b)) // 2
                todo += [(int(a), k), (k, int(b))]
            A, B = A[ok], B[ok]
            if len(A) == 0:
                continue
            i0, i1 = self.kept[A], self.kept[B]
            ctrl = self._dichotomy(p0[ok], qq[ok], p3[ok], sig[ok], i0, i1)
            good, emax, dist, starts = self._accept(ctrl, i0, i1)
            for r in range(len(A)):
                a, b = int(A[r]), int(B[r])
                if good[r]:
                    self.cubics.append((a, b, ctrl[r], float(emax[r])))
                    continue
                k = self._split_point(a, b, dist, int(starts[r]))
                todo += [(a, k), (k, b)]

    def _split_point(self, a: int, b: int, dist: np.ndarray, start: int) -> int:
        if b - a <= 3:
            return (a + b) // 2
        # the interior thinned point with the smallest error, in the middle 60 % of the
        # piece by input index (the crossing of data and curve), else the middle
        i0, i1 = int(self.kept[a]), int(self.kept[b])
        kk = self.kept[a + 1 : b]
        frac = (kk - i0) / max(1, i1 - i0)
        mid = (frac >= 0.2) & (frac <= 0.8)
        if not mid.any():
            return (a + b) // 2
        err = dist[start + kk[mid] - i0]
        return int(a + 1 + np.flatnonzero(mid)[int(np.argmin(err))])


def fit_path(
    points: object,
    *,
    closed: bool,
    eps_line: float = DEFAULT_EPS_LINE,
    e_per: float = DEFAULT_E_PER,
    eps_sum: float = DEFAULT_EPS_SUM,
    source_index: int = 0,
    pen: int = 1,
) -> FittedPath:
    """Fit one path's points (N, 2) (input units) with lines and cubics.

    Parameters are positive finite numbers in input units (else :class:`ParamError` naming
    the parameter). A single point (or all points equal) gives one zero-length line [p, p]
    (a dot). A closed path whose last point differs from its first is closed with an extra
    segment ending exactly at the first point (its ``last`` index is N, meaning point 0).
    """
    return fit_paths(
        [points],
        [closed],
        eps_line=eps_line,
        e_per=e_per,
        eps_sum=eps_sum,
        source_indices=[source_index],
        pens=[pen],
    )[0]


def _maybe_curvy(
    qs: list[np.ndarray], cos_join: float = 0.95, length_ratio: float = 3.0
) -> list[bool]:
    """Per thinned path: False when it certainly has no curve run (no two consecutive
    smooth interior vertices, the rule of :func:`galvo_core.runs.smooth_vertices`), so
    every piece is a line; one vectorised pass over all paths."""
    lens = np.array([len(q) for q in qs], dtype=np.intp)
    out = [False] * len(qs)
    if not len(qs) or lens.max() < 4:
        return out
    q = np.concatenate(qs)
    s = np.diff(q, axis=0)
    ln = np.hypot(s[:, 0], s[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = (s[:-1] * s[1:]).sum(axis=1) / (ln[:-1] * ln[1:])  # at vertex k + 1
    ends = np.cumsum(lens)
    firsts = ends - lens
    bad = np.zeros(len(q), dtype=bool)  # vertex index k not interior
    bad[firsts] = True
    bad[ends - 1] = True
    la, lb = ln[:-1], ln[1:]
    ratio_ok = (lb <= length_ratio * la) & (la <= length_ratio * lb)
    # the path's last vertex: a short tail does not count (as in runs.smooth_vertices)
    tail = np.zeros(len(q), dtype=bool)
    tail[ends - 2] = True
    ratio_ok |= tail[1:-1] & (lb < la)
    sm = np.zeros(len(q), dtype=bool)
    sm[1:-1] = (cos > cos_join) & ratio_ok
    sm &= ~bad
    pair = sm[:-1] & sm[1:]
    owner = np.repeat(np.arange(len(qs)), lens)[:-1]
    hit = np.bincount(owner[pair], minlength=len(qs)) > 0
    return (hit & (lens >= 4)).tolist()


def fit_paths(
    paths: Sequence[object],
    closed: Sequence[bool],
    *,
    eps_line: float = DEFAULT_EPS_LINE,
    e_per: float = DEFAULT_E_PER,
    eps_sum: float = DEFAULT_EPS_SUM,
    source_indices: Sequence[int] | None = None,
    pens: Sequence[int] | None = None,
) -> list[FittedPath]:
    """:func:`fit_path` for many paths at once (the same result as one call per path).

    The thinning runs for all paths in one go (:func:`galvo_core.thin.thin_many`), paths
    without any curve run skip the tangents, and the curve pieces of ALL paths are fitted
    together by one :class:`_BatchFitter` (concatenated points; pieces never cross a path),
    so the fixed cost per path is a few Python operations, not a few hundred array calls.
    """
    eps_line, e_per, eps_sum = _check_params(eps_line, e_per, eps_sum)
    npth = len(paths)
    if len(closed) != npth:
        raise ValueError("fit_paths: one closed flag per path")
    src = list(range(npth)) if source_indices is None else [int(i) for i in source_indices]
    pen = [1] * npth if pens is None else [int(p) for p in pens]
    works: list[np.ndarray] = []
    ns: list[int] = []
    for pts0 in paths:
        pts = np.asarray(pts0, dtype=np.float64).reshape(-1, 2)
        if not np.isfinite(pts).all():
            raise ParamError("points must be finite numbers (found NaN or infinity)")
        ns.append(len(pts))
        works.append(pts)
    for k in range(npth):
        pts = works[k]
        if closed[k] and len(pts) >= 2 and not np.array_equal(pts[0], pts[-1]):
            works[k] = np.vstack([pts, pts[:1]])
    kept_all = thin_many(works, eps_line)
    out: list[FittedPath | None] = [None] * npth
    todo: list[int] = []
    for k in range(npth):
        if ns[k] == 0:
            out[k] = FittedPath(src[k], pen[k], bool(closed[k]), (), 0.0, 0, 0)
        elif len(kept_all[k]) == 1:
            w = works[k]
            seg = _seg("line", w[[0, 0]], 0, len(w) - 1)
            out[k] = FittedPath(src[k], pen[k], bool(closed[k]), (seg,), 0.0, ns[k], 1)
        else:
            todo.append(k)
    if not todo:
        return out  # type: ignore[return-value]
    qs = [works[k][kept_all[k]] for k in todo]
    curvy = _maybe_curvy(qs)
    # one concatenated work array; kept indices and thinned indices made global
    wlen = np.array([len(works[k]) for k in todo], dtype=np.intp)
    woff = np.concatenate(([0], np.cumsum(wlen)))
    klen = np.array([len(kept_all[k]) for k in todo], dtype=np.intp)
    koff = np.concatenate(([0], np.cumsum(klen)))
    W = np.concatenate([works[k] for k in todo]) if len(todo) > 1 else works[todo[0]]
    K = np.concatenate([kept_all[k] + woff[t] for t, k in enumerate(todo)])
    Q = W[K]
    t_in = np.zeros((len(K), 2))
    t_out = np.zeros((len(K), 2))
    # per path: (a, b) pieces in global thinned indices; lines and curves
    line_pieces: list[list[tuple[int, int]]] = [[] for _ in todo]
    curve_pieces: list[tuple[int, int]] = []
    for t, k in enumerate(todo):
        o = int(koff[t])
        m = int(klen[t])
        if not curvy[t]:
            line_pieces[t] = [(o + i, o + i + 1) for i in range(m - 1)]
            continue
        pieces, ti, to = split_pieces(qs[t], closed=bool(closed[k]))
        t_in[o : o + m] = ti
        t_out[o : o + m] = to
        for pc in pieces:
            if pc.kind == "curve":
                curve_pieces.append((o + pc.a, o + pc.b))
            else:
                line_pieces[t].append((o + pc.a, o + pc.b))
    # arc length restarted at every path (the same numbers as for one path alone)
    arc = np.zeros(len(W))
    for t in range(len(todo)) if curve_pieces else ():
        if not curvy[t]:
            continue
        w = W[woff[t] : woff[t + 1]]
        np.cumsum(np.hypot(*np.diff(w, axis=0).T), out=arc[woff[t] + 1 : woff[t + 1]])
    fitter = _BatchFitter(W, K, t_in, t_out, e_per, eps_sum, arc)
    owner_of = np.repeat(np.arange(len(todo)), klen)
    if curve_pieces:
        with np.errstate(invalid="ignore", divide="ignore"):
            fitter.fit(curve_pieces)
    # distribute the fitter's results to their paths (global thinned index -> path)
    cub_by: list[list[tuple[int, int, np.ndarray, float]]] = [[] for _ in todo]
    for c in fitter.cubics:
        cub_by[int(owner_of[c[0]])].append(c)
    for a in fitter.lines:
        line_pieces[int(owner_of[a])].append((a, a + 1))
    # all line segments at once: their points (read-only views) and their true max error
    la = np.array([a for lp in line_pieces for a, _ in lp], dtype=np.intp)
    lb = np.array([b for lp in line_pieces for _, b in lp], dtype=np.intp)
    lpts = np.stack([Q[la], Q[lb]], axis=1) if len(la) else np.zeros((0, 2, 2))
    lpts.setflags(write=False)
    lfirst = K[la]
    llast = K[lb]
    # a line ending at the path's last thinned point also takes its trailing repeats
    is_end = np.isin(lb, koff[1:] - 1)
    llast[is_end] = woff[owner_of[lb[is_end]] + 1] - 1
    lerr = _line_errors(W, lpts, lfirst, llast)
    lfirst_l = lfirst.tolist()
    llast_l = llast.tolist()
    la_l = la.tolist()
    lerr_l = lerr.tolist()
    pos = 0
    for t, k in enumerate(todo):
        o_w = int(woff[t])
        items: list[tuple[int, Segment]] = []
        worst = 0.0
        for _ in range(len(line_pieces[t])):
            items.append(
                (la_l[pos], Segment("line", lpts[pos], lfirst_l[pos] - o_w, llast_l[pos] - o_w))
            )
            worst = max(worst, lerr_l[pos])
            pos += 1
        bounds: dict[int, float] = {}
        for a, b, ctl, e in cub_by[t]:
            sg = _seg("cubic", ctl, int(K[a]) - o_w, int(K[b]) - o_w)
            items.append((a, sg))
            bounds[sg.first] = e
        items.sort(key=lambda it: it[0])
        segs = [it[1] for it in items]
        work = works[k]
        last = segs[-1]
        if last.last != len(work) - 1:  # trailing repeats of the end point
            segs[-1] = Segment(last.kind, last.points, last.first, len(work) - 1)
        if bounds:
            worst = max(worst, _cubic_max_error(work, segs, bounds))
        out[k] = FittedPath(
            src[k], pen[k], bool(closed[k]), tuple(segs), worst, ns[k], int(klen[t])
        )
    return out  # type: ignore[return-value]


def _line_errors(
    work: np.ndarray, pts: np.ndarray, first: np.ndarray, last: np.ndarray
) -> np.ndarray:
    """Per line segment: the largest distance of the input points first..last (indices into
    ``work``) to the segment ``pts[k]`` (true distances, all segments at once)."""
    if len(first) == 0:
        return np.zeros(0)
    cnt = last - first + 1
    starts = np.cumsum(cnt) - cnt
    own = np.repeat(np.arange(len(first)), cnt)
    idx = first[own] + np.arange(int(cnt.sum())) - starts[own]
    d = point_segment_distance(work[idx], pts[own, 0], pts[own, 1])
    return np.maximum.reduceat(d, starts)


def _cubic_max_error(work: np.ndarray, segs: list[Segment], bound: dict[int, float]) -> float:
    """Largest true input-point error over the cubics. The fitter's per-cubic values
    (``bound``, by first index) are upper bounds (distances to some curve point); the cubics
    are measured exactly (seeded nearest point) in decreasing order of their bound until no
    bound left can beat the largest exact value."""
    cubics = [s for s in segs if s.kind == "cubic"]
    if not cubics:
        return 0.0
    bounds = np.array([bound[s.first] for s in cubics])
    order = np.argsort(-bounds)
    worst = 0.0
    for i in order:
        if bounds[i] <= worst:
            break
        s = cubics[int(i)]
        _, d = nearest_on_cubic(s.points, work[s.first : s.last + 1])
        worst = max(worst, float(min(d.max(), bounds[i])))
    return worst


def _max_error(work: np.ndarray, segs: list[Segment], *, cubics: bool = True) -> float:
    """Largest distance of an input point to the segment that replaces it (lines only
    when ``cubics`` is False: the fitter already measured its cubics)."""
    worst = 0.0
    lines = [s for s in segs if s.kind == "line"]
    if lines:
        firsts = np.array([s.first for s in lines])
        lasts = np.array([s.last for s in lines])
        counts = lasts - firsts + 1
        idx = np.repeat(firsts, counts) + (
            np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        )
        a = np.repeat(np.array([s.points[0] for s in lines]), counts, axis=0)
        b = np.repeat(np.array([s.points[1] for s in lines]), counts, axis=0)
        worst = float(point_segment_distance(work[idx], a, b).max())
    for s in segs if cubics else ():
        if s.kind == "cubic":
            _, d = nearest_on_cubic(s.points, work[s.first : s.last + 1])
            worst = max(worst, float(d.max()))
    return worst


def fit_drawing(
    drawing: Drawing,
    *,
    eps_line: float = DEFAULT_EPS_LINE,
    e_per: float = DEFAULT_E_PER,
    eps_sum: float = DEFAULT_EPS_SUM,
    batch: int = 4096,
    cancel: Callable[[], bool] | None = None,
) -> tuple[FittedPath, ...]:
    """:func:`fit_path` for every path of the drawing, in order (``source_index`` = position),
    fitted ``batch`` paths at a time (:func:`fit_paths`). ``cancel`` is called between
    batches; when it returns True, :class:`FitCancelled` is raised."""
    _check_params(eps_line, e_per, eps_sum)
    paths = drawing.paths
    out: list[FittedPath] = []
    for b0 in range(0, len(paths), max(1, int(batch))):
        if cancel is not None and cancel():
            raise FitCancelled()
        chunk = paths[b0 : b0 + batch]
        out += fit_paths(
            [p.points for p in chunk],
            [p.closed for p in chunk],
            eps_line=eps_line,
            e_per=e_per,
            eps_sum=eps_sum,
            source_indices=range(b0, b0 + len(chunk)),
            pens=[p.pen for p in chunk],
        )
    return tuple(out)


class FitCancelled(Exception):
    """Raised by :func:`fit_drawing` when its ``cancel`` callback says stop."""


def fit_report(
    drawing: Drawing,
    *,
    eps_line: float = DEFAULT_EPS_LINE,
    e_per: float = DEFAULT_E_PER,
    eps_sum: float = DEFAULT_EPS_SUM,
) -> dict[str, object]:
    """Paper 000 Table 1 row for a drawing: input_points, thinned_points, control_points
    (see :func:`control_points`), lines, cubics, max_error (input units), seconds (wall
    time of the fit)."""
    t0 = time.perf_counter()
    fitted = fit_drawing(drawing, eps_line=eps_line, e_per=e_per, eps_sum=eps_sum)
    secs = time.perf_counter() - t0
    return {
        "input_points": drawing.n_points,
        "thinned_points": sum(f.n_thinned for f in fitted),
        "control_points": sum(control_points(f) for f in fitted),
        "lines": sum(f.n_lines for f in fitted),
        "cubics": sum(f.n_cubics for f in fitted),
        "max_error": max((f.max_error for f in fitted), default=0.0),
        "seconds": secs,
    }


def check_fit(
    points: object, fitted: FittedPath, e_per: float, eps_line: float
) -> tuple[float, float]:
    """Measure both sides of the fitting guarantee with true distances (input units).

    Returns ``(max_in_to_curve, max_curve_to_polyline)``:

    * ``max_in_to_curve``: over input points, the distance to the nearest of the segments
      whose index range contains the point (a boundary point belongs to two);
    * ``max_curve_to_polyline``: every segment is sampled with arc-length spacing at most
      min(e_per, eps_line) / 4 and each sample's distance to the input polyline over the
      segment's index range is taken (an upper bound of its distance to the whole polyline;
      the true maximum is at most the spacing / 2 above the sampled one).

    Independent of the fitter's own acceptance test (dense sampling, brute-force or R-tree
    polyline distance), so tests can use it as a referee.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    n = len(pts)
    if n == 0 or not fitted.segments:
        return 0.0, 0.0
    ext = np.vstack([pts, pts[:1]]) if fitted.segments[-1].last >= n else pts
    h = min(float(e_per), float(eps_line)) / 4.0
    best = np.full(len(ext), np.inf)
    out_max = 0.0
    for s in fitted.segments:
        loc = ext[s.first : s.last + 1]
        if s.kind == "line":
            d = point_segment_distance(loc, s.points[0], s.points[1])
            length = float(np.hypot(*(s.points[1] - s.points[0])))
            m = max(2, min(200_000, math.ceil(length / h) + 1))
            tt = np.linspace(0.0, 1.0, m)[:, None]
            samp = s.points[0] + tt * (s.points[1] - s.points[0])
        else:
            _, d = nearest_on_cubic(s.points, loc, seeds=128, iters=10)
            length = cubic_length(s.points)
            m = max(16, min(200_000, math.ceil(length / h) + 1))
            samp = cubic_eval(s.points, np.linspace(0.0, 1.0, m))
        best[s.first : s.last + 1] = np.minimum(best[s.first : s.last + 1], d)
        out_max = max(out_max, float(point_polyline_distance(samp, loc).max()))
    return float(best.max()), out_max
