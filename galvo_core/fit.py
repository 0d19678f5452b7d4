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

The bisection uses the thinned points of the piece plus up to 256 of its input points; the
acceptance test uses every input point.

``eps_sum`` default: 0.002 input units (one tenth of the paper's e_per). The paper gives no
value; it only decides when the bisection stops, the acceptance is decided by ``e_per``. A
bracket on t narrower than 1e-9 also stops it.

Units: input units (HP-GL plotter units) throughout.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from galvo_core.drawing import Drawing
from galvo_core.errors import ParamError
from galvo_core.geometry import (
    cubic_derivative,
    cubic_eval,
    cubic_length,
    nearest_on_cubic,
    nearest_on_cubic_warm,
    point_polyline_distance,
    point_segment_distance,
)
from galvo_core.runs import split_pieces
from galvo_core.thin import check_positive, thin

__all__ = [
    "DEFAULT_EPS_LINE",
    "DEFAULT_E_PER",
    "DEFAULT_EPS_SUM",
    "Segment",
    "FittedPath",
    "fit_path",
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


def _curve_to_polyline_bound(c: np.ndarray, poly: np.ndarray, u: np.ndarray) -> float:
    """Upper bound of the distance from the curve to ``poly`` (see module doc).

    ``poly`` (n, 2) the input points the cubic replaces, in order; ``u`` (n,) their nearest
    parameters. For each consecutive pair, the curve over [u_i, u_(i+1)] is compared with
    segment i: |perpendicular| and overshoot beyond the segment's ends are maximised exactly
    (end values and roots of their derivatives, quadratics in u).
    """
    if len(poly) < 2:
        return 0.0
    lo = np.minimum(u[:-1], u[1:])
    hi = np.maximum(u[:-1], u[1:])
    a = poly[:-1]
    ab = poly[1:] - a
    ln = np.hypot(ab[:, 0], ab[:, 1])
    good = ln > 0.0
    dirn = ab / np.where(good, ln, 1.0)[:, None]
    nrm = np.stack([-dirn[:, 1], dirn[:, 0]], axis=1)
    d = np.diff(c, axis=0)  # (3, 2): B'(u) = 3[(1-u)^2 d0 + 2(1-u)u d1 + u^2 d2]

    def roots(v: np.ndarray) -> list[np.ndarray]:
        g0, g1, g2 = v @ d[0], v @ d[1], v @ d[2]
        qa = g0 - 2.0 * g1 + g2
        qb = 2.0 * (g1 - g0)
        qc = g0
        out = []
        disc = qb * qb - 4.0 * qa * qc
        sq = np.sqrt(np.maximum(disc, 0.0))
        lin = np.abs(qa) <= 1e-14 * (np.abs(qb) + np.abs(qc) + 1e-300)
        with np.errstate(divide="ignore", invalid="ignore"):
            r1 = np.where(lin, -qc / qb, (-qb + sq) / (2.0 * qa))
            r2 = np.where(lin, -qc / qb, (-qb - sq) / (2.0 * qa))
        for r in (r1, r2):
            r = np.where(np.isfinite(r) & (disc >= 0.0) | lin, r, lo)
            out.append(np.clip(np.nan_to_num(r, nan=0.0), lo, hi))
        return out

    cands = [lo, hi, 0.5 * (lo + hi), *roots(nrm), *roots(dirn)]
    perp = np.zeros(len(a))
    over = np.zeros(len(a))
    for uu in cands:
        pt = cubic_eval(c, uu) - a
        s = (pt * dirn).sum(axis=1)
        p = np.abs((pt * nrm).sum(axis=1))
        o = np.maximum(np.maximum(-s, s - ln), 0.0)
        # a zero-length segment is its point
        p = np.where(good, p, np.hypot(pt[:, 0], pt[:, 1]))
        o = np.where(good, o, 0.0)
        np.maximum(perp, p, out=perp)
        np.maximum(over, o, out=over)
    return float(np.sqrt(perp * perp + over * over).max())


class _PieceFitter:
    """Fits the curve pieces of one path (shared state: points, thinned indices, tangents)."""

    def __init__(
        self,
        work: np.ndarray,
        kept: np.ndarray,
        t_in: np.ndarray,
        t_out: np.ndarray,
        e_per: float,
        eps_sum: float,
    ) -> None:
        self.work = work
        self.kept = kept
        self.q = work[kept]
        self.t_in = t_in
        self.t_out = t_out
        self.e_per = e_per
        self.eps_sum = eps_sum
        self.max_err = 0.0  # largest input-point error of the accepted cubics

    def _triangle(self, a: int, b: int) -> tuple[np.ndarray, float] | None:
        p0, p3 = self.q[a], self.q[b]
        t0, t3 = self.t_out[a], self.t_in[b]
        det = t0[0] * t3[1] - t0[1] * t3[0]
        chord = p3 - p0
        lc = math.hypot(*chord)
        if lc == 0.0 or abs(det) < 1e-9:
            return None
        # p0 + al*t0 = p3 - be*t3  ->  al*t0 + be*t3 = chord
        al = (chord[0] * t3[1] - chord[1] * t3[0]) / det
        be = (t0[0] * chord[1] - t0[1] * chord[0]) / det
        if not (al > 1e-9 * lc and be > 1e-9 * lc) or al > 1e3 * lc or be > 1e3 * lc:
            return None
        return p0 + al * t0, math.copysign(1.0, det)

    def _data(self, a: int, b: int) -> np.ndarray:
        i0, i1 = int(self.kept[a]), int(self.kept[b])
        inner = np.arange(i0 + 1, i1)
        if len(inner) > _BISECT_SAMPLE:
            inner = inner[:: math.ceil(len(inner) / _BISECT_SAMPLE)]
        idx = np.union1d(inner, self.kept[a + 1 : b])
        return self.work[idx]

    def _dichotomy(self, p0: np.ndarray, p3: np.ndarray, qq: np.ndarray, sig: float, data):
        chord = p3 - p0

        def ctrl(t: float) -> np.ndarray:
            return np.array([p0, p0 + t * (qq - p0), p3 + t * (qq - p3), p3])

        state: dict[str, np.ndarray] = {}

        def ssum(t: float) -> float:
            c = ctrl(t)
            if "u" in state:
                u, dist = nearest_on_cubic_warm(c, data, state["u"], iters=3)
            else:
                u, dist = nearest_on_cubic(c, data, seeds=32)
            state["u"] = u
            tv = cubic_derivative(c, u)
            bad = (tv * tv).sum(axis=1) <= 1e-18 * float(chord @ chord)
            tv[bad] = chord
            diff = data - cubic_eval(c, u)
            side = np.sign(tv[:, 0] * diff[:, 1] - tv[:, 1] * diff[:, 0])
            return float(-sig * (side * dist).sum())

        if len(data) == 0:
            return ctrl(0.5)
        tl, th = 0.0, 1.0
        sl, sh = ssum(tl), ssum(th)
        if sl <= 0.0:
            return ctrl(tl)
        if sh >= 0.0:
            return ctrl(th)
        t = 0.5
        side = 0
        for _ in range(_MAX_BISECT):
            # false position, Illinois-weighted, kept inside the bracket
            t = (tl * sh - th * sl) / (sh - sl)
            if not (tl < t < th):
                t = 0.5 * (tl + th)
            s = ssum(t)
            if abs(s) < self.eps_sum or th - tl < 1e-9:
                break
            if s > 0.0:
                tl, sl = t, s
                if side == 1:
                    sh *= 0.5
                side = 1
            else:
                th, sh = t, s
                if side == -1:
                    sl *= 0.5
                side = -1
        return ctrl(t)

    def _try(self, a: int, b: int) -> tuple[np.ndarray | None, np.ndarray | None]:
        """A cubic for piece a..b that meets the guarantee, or (None, errors at thinned
        interior points) to choose a split."""
        tri = self._triangle(a, b)
        if tri is None:
            return None, None
        qq, sig = tri
        p0, p3 = self.q[a], self.q[b]
        c = self._dichotomy(p0, p3, qq, sig, self._data(a, b))
        i0, i1 = int(self.kept[a]), int(self.kept[b])
        pts = self.work[i0 : i1 + 1]
        u, dist = nearest_on_cubic(c, pts)
        e_in = float(dist.max())
        if e_in <= self.e_per and _curve_to_polyline_bound(c, pts, u) <= self.e_per:
            self.max_err = max(self.max_err, e_in)
            return c, None
        return None, dist[self.kept[a + 1 : b] - i0]

    def fit(self, a: int, b: int) -> list[Segment]:
        out: list[Segment] = []
        stack = [(a, b)]
        while stack:
            a, b = stack.pop()
            if b - a == 1:
                out.append(_seg("line", self.q[[a, b]], self.kept[a], self.kept[b]))
                continue
            c, err = self._try(a, b)
            if c is not None:
                out.append(_seg("cubic", c, self.kept[a], self.kept[b]))
                continue
            k = self._split_point(a, b, err)
            stack.append((k, b))
            stack.append((a, k))
        return out

    def _split_point(self, a: int, b: int, err: np.ndarray | None) -> int:
        ks = np.arange(a + 1, b)
        if err is None or len(ks) <= 2:
            return (a + b) // 2
        # away from the ends: the middle 60 % of the piece by input index, else the middle
        i0, i1 = self.kept[a], self.kept[b]
        frac = (self.kept[ks] - i0) / max(1, i1 - i0)
        mid = (frac >= 0.2) & (frac <= 0.8)
        if not mid.any():
            return (a + b) // 2
        cand = ks[mid]
        return int(cand[np.argmin(err[mid])])


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
    eps_line, e_per, eps_sum = _check_params(eps_line, e_per, eps_sum)
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    n = len(pts)
    if not np.isfinite(pts).all():
        raise ParamError("points must be finite numbers (found NaN or infinity)")
    if n == 0:
        return FittedPath(source_index, pen, bool(closed), (), 0.0, 0, 0)
    work = pts
    if closed and n >= 2 and not np.array_equal(pts[0], pts[-1]):
        work = np.vstack([pts, pts[:1]])
    kept = thin(work, eps_line, closed=closed)
    if len(kept) == 1:
        seg = _seg("line", work[[0, 0]], 0, len(work) - 1)
        return FittedPath(source_index, pen, bool(closed), (seg,), 0.0, n, 1)
    q = work[kept]
    pieces, t_in, t_out = split_pieces(q, closed=closed)
    fitter = _PieceFitter(work, kept, t_in, t_out, e_per, eps_sum)
    segs: list[Segment] = []
    for pc in pieces:
        if pc.kind == "line":
            segs.append(_seg("line", q[[pc.a, pc.b]], kept[pc.a], kept[pc.b]))
        else:
            segs.extend(fitter.fit(pc.a, pc.b))
    last = segs[-1]
    if last.last != len(work) - 1:  # trailing repeats of the end point
        segs[-1] = Segment(last.kind, last.points, last.first, len(work) - 1)
    max_err = max(_max_error(work, segs, cubics=False), fitter.max_err)
    return FittedPath(source_index, pen, bool(closed), tuple(segs), max_err, n, len(kept))


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
) -> tuple[FittedPath, ...]:
    """:func:`fit_path` for every path of the drawing, in order (``source_index`` = position)."""
    _check_params(eps_line, e_per, eps_sum)
    return tuple(
        fit_path(
            p.points,
            closed=p.closed,
            eps_line=eps_line,
            e_per=e_per,
            eps_sum=eps_sum,
            source_index=i,
            pen=p.pen,
        )
        for i, p in enumerate(drawing.paths)
    )


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
