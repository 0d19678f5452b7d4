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

Where the triangle's cubic fails (or the tangents do not meet), a second candidate is tried
under the same test: the cubic with two free handle lengths minimising the points' squared
distances, by Gauss-Newton on the distances along the normal (a typeface's cubic whose two
handles are different fractions of its triangle is not in the one-parameter family); on
rounded input whose rounding is a fair share of the bound, also one whose end tangents may
turn a few degrees (they are estimates from rounded points).

A piece that fails is split at the crossing of data and curve (the interior thinned point
with the smallest error, away from the ends) and both halves are fitted again; a piece of
two thinned points is a line (always within ``eps_line``). So the guarantee holds whatever
the dichotomy does, and lines are the last resort.

All curve pieces of all paths of a batch are fitted together, round by round
(:class:`_BatchFitter`): one compiled call runs the dichotomy of every open piece, one the
acceptance test, the failures split for the next round. Each piece's
result does not depend on the other pieces in the batch. The bisection uses up to 128 of the piece's
input points (every k-th); the acceptance test uses every input point, with nearest points
from Newton steps seeded by arc length (a seeded search only for points over the bound).
Any curve parameter gives an upper bound of the true distance, so the acceptance is never
too lenient; ``max_error`` is made exact by re-measuring the worst cubics with the seeded
nearest-point search.

Rounded input (issue 16): points on a grid of step q (whole plotter units, decimal steps,
an SC/IP grid; :mod:`galvo_core.precision`, detected per path unless ``quantum_units`` is
given) are the design rounded by up to q/√2. Each point stands for its rounding square: the
bounds above become ``eps_line + q/√2`` and ``e_per + q/√2`` from the input points and
polyline, i.e. the user's tolerances beyond the rounding (exactly them when q is 0). Then
the vertices inside curve runs move, within their rounding squares, onto a local
least-squares quadratic of the input points (joints on the design, not on the grid) and take
its tangent; least-squares handle lengths are used where they pass the same test; a single
thinned segment whose points bulge to one side is tried as a cubic; a line whose moved ends
would break its bound becomes the thinned line plus connectors inside the rounding squares.
For every input, after the fit, adjacent cubics meeting at a smooth vertex are refitted as
one where one cubic passes the same test (up to ``_MERGE_ROUNDS`` rounds); so are two
adjacent segments (lines too) at a vertex turning less than ``_ABSORB_TURN``; three
adjacent cubics become two where two pass, split at another thinned point (the
dichotomy's splits fall on the data's crossings, not on the design's joints). A merge's
cubic is screened first (a coarse dichotomy on a few points) and a range that failed is
not tried again. Rounded input: corners move inside their rounding squares onto the
intersection of the two sides' least-squares lines (or quadratics), and a long input
segment (over ``_LONG_SEGMENT`` quanta) leaves a curve only part of the slack beside it,
unless it is a chord of a coarsely flattened curve (:func:`_coarse_chords`).
The vertices move onto the design only on paths where q/√2 is at least ``_MOVE_SHARE`` of
e_per (a move gains at most q/√2); there a line over a bulging stretch of the design is
split on the design estimate (:func:`_split_bulging_lines`).

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
from typing import cast

import numpy as np
from numba import njit

from galvo_core.drawing import Drawing, Path
from galvo_core.errors import Cancelled, ParamError
from galvo_core.geometry import (
    bernstein_point,
    bernstein_samples,
    bernstein_weights,
    cubic_eval,
    cubic_length,
    hypot_into,
    nearest_on_cubic,
    nearest_on_cubic_each,
    newton_param,
    point_polyline_distance,
    point_segment_distance,
    power_coeffs_many,
    sampled_upper_d2,
    seed_basis,
    seeded_nearest,
)
from galvo_core.job import gc_paused
from galvo_core.minimax import minimax_cubics
from galvo_core.parallel import run_chunks
from galvo_core.precision import path_quanta
from galvo_core.runs import segmented_cumsum, split_pieces_many
from galvo_core.thin import check_positive, thin, thin_many
from galvo_core.turns import turn_deg

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

#: the rounding square's half diagonal per unit of side
_HALF_DIAGONAL = math.sqrt(0.5)
_BISECT_SAMPLE = 128
#: rounds of merging adjacent cubics after the fit
_MERGE_ROUNDS = 1
#: points per piece in a merge's dichotomy (a candidate; the full test decides)
_MERGE_SAMPLE = 32
_MAX_BISECT = 40
#: a merge's screening cubic: points, dichotomy steps, and how far over the bound a
#: sample point may be for the real fit to be tried
_SCREEN_SAMPLE = 12
_SCREEN_STEPS = 8
_SCREEN_SLACK = 2.0
#: rounds of absorbing lines into cubics on rounded input, and the largest turn (radians)
#: between the one-sided tangents at the vertex where that may happen
_ABSORB_ROUNDS = 3
#: rounded input: rounds of replacing a short line and its two neighbours by one cubic
#: (:meth:`_BatchFitter._bridge_round`)
_BRIDGE_ROUNDS = 2
#: rounds of replacing three adjacent cubics by two, and the split points tried per triple
_RESPLIT_ROUNDS = 1
#: Gauss-Newton rounds of the second candidate cubic (:meth:`_BatchFitter._gauss_newton`)
_GN_ROUNDS = 4
#: rounded input: the candidate with free end tangents too, each turned at most this much
_GN_FREE = True
_GN_TURN = math.radians(5.0)
#: rounded input: a failing candidate is refined towards the least worst error
#: (galvo_core.minimax) only where every sampled input point of its start is within this many
#: times the bound (the near misses: the refinement rarely brings a farther start under it)
_MINIMAX_NEAR = 1.3
#: rounded input: after the fit, rounds of merging two adjacent cubics at a smooth vertex
#: by the refinement (:meth:`_BatchFitter._minimax_merge_round`; 0: off)
_MINIMAX_MERGE = 2
#: ... a merged cubic kept only where it stays within this many quanta of the two it
#: replaces (both ways, sampled): the refinement corrects near misses by little. (0.35 until
#: the joints' moves were made order-free, :func:`_joint_rounds`: one merge then flipped the
#: order of two joint moves 670 units away; at 1.0 no training, held-out, CFF or em 400
#: distance is worse and the CFF counts drop, bench/RESULTS.md "CFF counts, ninth session")
_MERGE_DEV = 1.0
#: ... lines (not the design's, :meth:`_BatchFitter._fixed_lines`) merged so too
_MINIMAX_LINES = True
#: rounded input, after the merge pass: the greedy chain refit and the three-into-two
#: resplit once more, where the ranges they tried before come back at no cost (a pass keeps
#: its cubic, a failure is tried only by the refinement of its cached start,
#: :meth:`_BatchFitter._refined_rounds`; new ranges fail: fitting them in full, with the
#: refinement, in the chains a refined cubic opened took a few segments fewer on cubic
#: typefaces for over a tenth more CPU on sparse outlines, bench/RESULTS.md "CFF counts,
#: ninth session")
_REFINED_ROUNDS = True
#: ... the start's Gauss-Newton rounds, and the near misses refined (as ``_MINIMAX_NEAR``)
_MERGE_GN_ROUNDS = 4
_MERGE_NEAR = 1.2
_RESPLIT_CANDIDATES = 3
#: ... in this order (the middle one first)
_RESPLIT_ORDER = (1, 0, 2)
#: ... and the most lines among the three
_RESPLIT_LINES = 2
#: chains of this many adjacent cubics or more are fitted again greedily (farthest reach)
_GREEDY_MIN = 3
#: ... each new cubic reaching at most this many old ones on
_GREEDY_SPAN = 3
#: rounded input: the vertices move onto the design (:func:`_on_the_design`) only on paths
#: whose rounding half diagonal q/√2 is at least this share of e_per. Below, a move (at most
#: q/√2) is small against the tolerance the user asked for: on typeface outlines rounded to
#: 0.01 unit (e_per 0.02) the moves gave 10 % more segments and no nearer a fit (0.029 against
#: 0.028 unit from the true curve), and they were a third of the fit's time on a 1 M-point
#: file at q = 0.01 (bench/RESULTS.md, "Precision, third round"); at q = 0.02 (share 0.71)
#: they bring the fit nearer (0.034 against 0.040)
_MOVE_SHARE = 0.5
#: rounded input: an input segment longer than ``_LONG_SEGMENT`` quanta allows the curve
#: only that share of the rounding slack beside it (at least ``_LONG_FLOOR``)
_LONG_SEGMENT = 10.0
_LONG_FLOOR = 0.5
#: ... unless it is a chord of a coarsely flattened curve (:func:`_coarse_chords`): its
#: neighbour at a gentle vertex at most this many times longer or shorter, the turn there
#: more than this many quanta across the shorter side
_COARSE_RATIO = 3.0
_COARSE_NOISE = 1.5
_ABSORB_TURN = math.radians(30)
#: ... but on rounded input a line without input points between its ends, longer than this
#: many times the bound, is the design's and stays
_ABSORB_SHORT = 4.0


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


def _read_only(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


_EMPTY_POINTS = _read_only(np.zeros((0, 2)))
_EMPTY_BOOL = _read_only(np.zeros(0, dtype=bool))
_EMPTY_INT = _read_only(np.zeros(0, dtype=np.int64))


def segment_point_offsets(is_cubic: np.ndarray) -> np.ndarray:
    """Row of each segment's first control point in a path's shared ``points`` array: the
    start point is row 0, a line adds one row (its end), a cubic three (P1, P2, P3)."""
    step = np.where(is_cubic, 3, 1)
    return np.cumsum(step) - step


@dataclass(frozen=True, slots=True, eq=False, init=False)
class FittedPath:
    """The fitted form of one :class:`~galvo_core.drawing.Path`, stored as arrays.

    ``is_cubic`` (S,) bool: the segment kinds in order (False: a line). ``points`` (C, 2)
    float64 input units, read-only: the control points shared between segments, the start
    point then per segment its points after the start (a line: its end; a cubic: P1, P2,
    P3), so C = 1 + lines + 3·cubics (0 without segments); segment k spans
    ``points[o_k : o_k + 2]`` (line) or ``points[o_k : o_k + 4]`` (cubic), o_k from
    :func:`segment_point_offsets`. ``first``/``last`` (S,) int64: the input point indices
    each segment replaces (see :class:`Segment`).

    The segments are continuous by construction (each starts exactly where the previous
    ended; a closed path's last ends exactly at the first's start). ``max_error`` is the
    largest true distance from an input point to its segment (input units). ``n_thinned``
    is the number of points left by the line thinning.

    ``segments``: the same geometry as a tuple of :class:`Segment` objects (views of
    ``points``), built on first use, for code that wants one object per segment (the
    GUI's selected path, tests). ``FittedPath(source_index, pen, closed, segments, ...)``
    still accepts such a tuple (continuous segments; else ValueError).
    """

    source_index: int
    pen: int
    closed: bool
    is_cubic: np.ndarray
    points: np.ndarray
    first: np.ndarray
    last: np.ndarray
    max_error: float
    n_input: int
    n_thinned: int
    _segments: tuple[Segment, ...] | None

    def __init__(self, source_index: int, pen: int, closed: bool,
                 segments: Sequence[Segment] = (), max_error: float = 0.0, n_input: int = 0,
                 n_thinned: int = 0) -> None:
        segs = tuple(segments)
        if segs:
            kinds = np.array([s.kind == "cubic" for s in segs], dtype=bool)
            parts = [np.asarray(segs[0].points, dtype=np.float64)[:1]]
            prev = parts[0][0]
            for k, s in enumerate(segs):
                p = np.asarray(s.points, dtype=np.float64)
                if p.shape != ((4, 2) if kinds[k] else (2, 2)):
                    raise ValueError(f"segment {k}: a line has 2 points, a cubic 4")
                if not np.array_equal(p[0], prev):
                    raise ValueError(f"segment {k} does not start where segment {k - 1} ended")
                parts.append(p[1:])
                prev = p[-1]
            pts = np.concatenate(parts)
            first = np.array([s.first for s in segs], dtype=np.int64)
            last = np.array([s.last for s in segs], dtype=np.int64)
            _init_fitted(self, int(source_index), int(pen), bool(closed), _read_only(kinds),
                         _read_only(pts), _read_only(first), _read_only(last),
                         float(max_error), int(n_input), int(n_thinned))
        else:
            _init_fitted(self, int(source_index), int(pen), bool(closed), _EMPTY_BOOL,
                         _EMPTY_POINTS, _EMPTY_INT, _EMPTY_INT, float(max_error), int(n_input),
                         int(n_thinned))

    @classmethod
    def from_arrays(cls, source_index: int, pen: int, closed: bool, is_cubic: np.ndarray,
                    points: np.ndarray, first: np.ndarray, last: np.ndarray,
                    max_error: float, n_input: int, n_thinned: int) -> FittedPath:
        """A fitted path from its arrays as they are (read-only, of the documented shapes and
        types: not checked, not copied): the fitter's fast path, one object per path."""
        fp = _new(cls)
        _init_fitted(fp, source_index, pen, closed, is_cubic, points, first, last, max_error,
                     n_input, n_thinned)
        return fp

    @property
    def n_segments(self) -> int:
        return len(self.is_cubic)

    @property
    def n_lines(self) -> int:
        return len(self.is_cubic) - int(np.count_nonzero(self.is_cubic))

    @property
    def n_cubics(self) -> int:
        return int(np.count_nonzero(self.is_cubic))

    @property
    def segments(self) -> tuple[Segment, ...]:
        segs = self._segments
        if segs is None:
            cub = self.is_cubic.tolist()
            off = segment_point_offsets(self.is_cubic).tolist()
            pts = self.points
            segs = tuple(map(_make_segment, [_KINDS[c] for c in cub],
                             [pts[o:o + (4 if c else 2)] for o, c in zip(off, cub, strict=True)],
                             self.first.tolist(), self.last.tolist()))
            _set_fp_segments(self, segs)
        return segs


_KINDS = ("line", "cubic")
_DOT_KIND = _read_only(np.zeros(1, dtype=bool))
_ZERO_FIRST = _read_only(np.zeros(1, dtype=np.int64))
_ONE_LAST = _read_only(np.ones(1, dtype=np.int64))
_KEPT_TWO = _read_only(np.array([0, 1], dtype=np.int64))
_fp_setters = [FittedPath.__dict__[f].__set__ for f in (
    "source_index", "pen", "closed", "is_cubic", "points", "first", "last", "max_error",
    "n_input", "n_thinned", "_segments")]
_set_fp_segments = _fp_setters[-1]


(_s_src, _s_pen, _s_closed, _s_kinds, _s_points, _s_first, _s_last, _s_err, _s_nin, _s_nth,
 _s_segs) = _fp_setters


def _init_fitted(fp: FittedPath, source_index, pen, closed, is_cubic, points, first, last,
                 max_error, n_input, n_thinned) -> None:  # type: ignore[no-untyped-def]
    _s_src(fp, source_index)
    _s_pen(fp, pen)
    _s_closed(fp, closed)
    _s_kinds(fp, is_cubic)
    _s_points(fp, points)
    _s_first(fp, first)
    _s_last(fp, last)
    _s_err(fp, max_error)
    _s_nin(fp, n_input)
    _s_nth(fp, n_thinned)
    _s_segs(fp, None)


def _new_fitted(source_index, pen, closed, is_cubic, points, first, last, max_error, n_input,
                n_thinned) -> FittedPath:  # type: ignore[no-untyped-def]
    """:meth:`FittedPath.from_arrays` (the fitter's loop over paths calls this)."""
    fp = _new(FittedPath)
    _init_fitted(fp, source_index, pen, closed, is_cubic, points, first, last, max_error,
                 n_input, n_thinned)
    return fp


def with_source_index(fp: FittedPath, source_index: int) -> FittedPath:
    """``fp`` as the fit of the path at ``source_index`` (the same arrays)."""
    if fp.source_index == source_index:
        return fp
    return _new_fitted(source_index, fp.pen, fp.closed, fp.is_cubic, fp.points, fp.first,
                       fp.last, fp.max_error, fp.n_input, fp.n_thinned)


def control_points(fp: FittedPath) -> int:
    """Control points of a fitted path, counted as stored: the start point plus, per segment,
    its points minus the shared start (1 per line, 3 per cubic); a closed path's closing
    point counts again (as in paper 000: a circle of 13 cubics = 40 points). A dot is 1."""
    n = len(fp.is_cubic)
    if n == 0:
        return 0
    if n == 1 and not fp.is_cubic[0] and np.array_equal(fp.points[0], fp.points[1]):
        return 1
    return len(fp.points)


def _check_params(eps_line: object, e_per: object, eps_sum: object) -> tuple[float, float, float]:
    return (
        check_positive("eps_line", eps_line),
        check_positive("e_per", e_per),
        check_positive("eps_sum", eps_sum),
    )


_new = object.__new__
_set_kind, _set_points, _set_first, _set_last = (
    Segment.__dict__[f].__set__ for f in ("kind", "points", "first", "last")
)


def _make_segment(kind: str, points: np.ndarray, first: int, last: int) -> Segment:
    """``Segment(kind, points, first, last)`` for arguments already of the right types
    (``points`` a read-only float64 array), about 1.6x faster than the frozen dataclass's
    ``__init__`` (it sets the slots directly): :attr:`FittedPath.segments` builds one per
    segment when asked."""
    s = _new(Segment)
    _set_kind(s, kind)
    _set_points(s, points)
    _set_first(s, first)
    _set_last(s, last)
    return s


def _curve_to_polyline_bound_many(
    cf: np.ndarray, a: np.ndarray, b: np.ndarray, u0: np.ndarray, u1: np.ndarray
) -> np.ndarray:
    """Per pair k: an upper bound of the distance from the curve stretch u0[k]..u1[k] of
    cubic ``cf`` (per-pair power coefficients, a (4, 2, K) block as in
    :func:`galvo_core.geometry.newton_nearest_many`) to the segment [a[k], b[k]] (see
    module doc).

    |perpendicular| and overshoot beyond the segment's ends are maximised exactly over the
    stretch (end values and roots of their derivatives, quadratics in u): all seven
    candidate parameters of a pair are evaluated in one compiled loop (:func:`_bound_kernel`).
    """
    out = np.empty(len(a))
    if len(a):
        _bound_kernel(cf, np.ascontiguousarray(a, dtype=np.float64),
                      np.ascontiguousarray(b, dtype=np.float64),
                      np.ascontiguousarray(u0, dtype=np.float64),
                      np.ascontiguousarray(u1, dtype=np.float64), out)
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def _bound_kernel(cf, a, b, u0, u1, out) -> None:  # pragma: no cover (compiled)
    """:func:`_curve_to_polyline_bound_many`'s maths, one pair at a time (compiled)."""
    uu = np.empty(7)
    for k in range(len(out)):
        out[k] = _bound_pair(cf[0, 0, k], cf[0, 1, k], cf[1, 0, k], cf[1, 1, k], cf[2, 0, k],
                             cf[2, 1, k], cf[3, 0, k], cf[3, 1, k], a[k, 0], a[k, 1], b[k, 0],
                             b[k, 1], u0[k], u1[k], uu)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _bound_pair(ax, ay, bx, by, dx, dy, ex, ey, a0, a1, b0, b1, u0, u1,
                uu):  # pragma: no cover (compiled)
    """:func:`_bound_kernel` for one pair: the cubic ((a u + b) u + d) u + e between u0 and
    u1 against the segment (a0, a1)-(b0, b1); ``uu`` a work array of 7."""
    lo = min(u0, u1)
    hi = max(u0, u1)
    abx = b0 - a0
    aby = b1 - a1
    ln = math.hypot(abx, aby)
    good = ln > 0.0
    inv = 1.0 / ln if good else 1.0
    tx = abx * inv
    ty = aby * inv
    nx = -ty
    ny = tx
    uu[0] = lo
    uu[1] = hi
    uu[2] = 0.5 * (lo + hi)
    j = 3
    for row in range(2):
        vx = nx if row == 0 else tx
        vy = ny if row == 0 else ty
        qa = 3.0 * (ax * vx + ay * vy)
        qb = 2.0 * (bx * vx + by * vy)
        qc = dx * vx + dy * vy
        disc = qb * qb - 4.0 * qa * qc
        sq = math.sqrt(max(disc, 0.0))
        lin = abs(qa) <= 1e-14 * (abs(qb) + abs(qc) + 1e-300)
        for sg in (1.0, -1.0):
            if lin:
                r = -qc / qb
            else:
                r = (-qb + sg * sq) / (2.0 * qa)
                if not (np.isfinite(r) and disc >= 0.0):
                    r = lo
            if np.isnan(r):
                r = 0.0
            uu[j] = min(max(r, lo), hi)
            j += 1
    perp = 0.0
    over = 0.0
    for i in range(7):
        u = uu[i]
        px = ((ax * u + bx) * u + dx) * u + ex - a0
        py = ((ay * u + by) * u + dy) * u + ey - a1
        if good:
            sa = px * tx + py * ty
            pp = abs(px * nx + py * ny)
            oo = max(max(-sa, sa - ln), 0.0)
        else:
            pp = math.hypot(px, py)
            oo = 0.0
        perp = max(perp, pp)
        over = max(over, oo)
    return math.sqrt(perp * perp + over * over)


@njit(cache=True, nogil=True, inline="always")
def _piece_start(cm, r, i0, i1, starts, arc, u, dist):  # pragma: no cover (compiled)
    """The acceptance tests' per-piece set-up: piece r's power coefficients (ax, ay, bx, by,
    dx, dy, ex, ey), its first input point, its first flat index, its point count and arc
    span (1 where none); its ends' parameters and distances set (0 and 1, distance 0)."""
    base = i0[r]
    s = starts[r]
    cnt = i1[r] - base + 1
    span = arc[i1[r]] - arc[base]
    u[s] = 0.0
    dist[s] = 0.0
    u[s + cnt - 1] = 1.0
    dist[s + cnt - 1] = 0.0
    return (cm[r, 0, 0], cm[r, 0, 1], cm[r, 1, 0], cm[r, 1, 1], cm[r, 2, 0], cm[r, 2, 1],
            cm[r, 3, 0], cm[r, 3, 1], base, s, cnt, span if span > 0 else 1.0)


@njit(cache=True, nogil=True)
def _accept_points(cm, i0, i1, starts, work, arc, e2, u, dist, emax0,
                   far) -> int:  # pragma: no cover (compiled)
    """:meth:`_BatchFitter._accept`'s point side (compiled): per piece r (power
    coefficients ``cm[r]`` (4, 2), input points i0[r] .. i1[r], flat from ``starts[r]``) each
    interior point's parameter (6 Newton steps from arc length, as :func:`_newton_kernel`,
    bit for bit) and distance into ``u``, ``dist`` (the ends: 0 and 1, distance 0), the
    piece's largest distance into ``emax0`` (NaN if any is), and the flat indices of the
    points over ``e2[r]`` in pieces within 4 e2[r] into ``far``; returns their number
    (:func:`_accept_kernel` in full)."""
    return _accept_kernel(np.empty((0, 4, 2)), cm, i0, i1, starts, work, arc, e2,
                          np.empty(0), np.empty((0, 4)), u, dist, emax0,
                          np.empty(0, dtype=np.bool_), far, False)


@njit(cache=True, nogil=True, error_model="numpy")
def _accept_pairs(cm, i0, i1, starts, work, u, e2, qa, coarse, ok) -> None:  # pragma: no cover
    """:meth:`_BatchFitter._accept`'s curve-to-polyline side (compiled): for each piece r
    still ``ok``, the bound (:func:`_bound_pair`) of every pair of consecutive input
    points, plus on rounded input (``qa[r]`` > 0, else qa of length 0) the rounding slack
    the curve may not use beside a long input segment (all of it beside one that
    ``coarse`` marks, per point of ``work``: :func:`_coarse_chords`; length 0 with qa);
    ``ok[r]`` False where one is over ``e2[r]``.

    A cheap upper bound first, for a chunk of pairs at a time (the loop vectorises); the
    exact bound only where it does not pass. Over u0..u1 the cubic keeps within S =
    (u1 - u0)² / 8 · max |B''| of its chord (B'' is linear in u: its largest length is at
    an end), and along the chord both the perpendicular distance to the segment's line and
    the overshoot beyond its ends are largest at the chord's ends: each of the two maxima
    that :func:`_bound_pair` combines is at most its value at u0 or u1 plus S (plus a
    margin for the rounding; at a repeated input point: the distance to it at u0 or u1 plus
    S). Where that passes (with a little more slack than the exact one), the exact bound
    does too."""
    uu = np.empty(7)
    ch = _ACCEPT_CHUNK
    fb = np.empty(ch, dtype=np.bool_)
    quant = len(qa) > 0
    for r in range(len(i0)):
        if not ok[r]:
            continue
        base = i0[r]
        s = starts[r]
        lim = e2[r]
        q = qa[r] if quant else 0.0
        sl = q * _HALF_DIAGONAL
        ax = cm[r, 0, 0]
        ay = cm[r, 0, 1]
        bx = cm[r, 1, 0]
        by = cm[r, 1, 1]
        dx = cm[r, 2, 0]
        dy = cm[r, 2, 1]
        ex = cm[r, 3, 0]
        ey = cm[r, 3, 1]
        npair = i1[r] - base
        for c0 in range(0, npair, ch):
            n = min(npair, c0 + ch) - c0
            for j in range(n):
                k = base + c0 + j
                a0 = work[k, 0]
                a1 = work[k, 1]
                abx = work[k + 1, 0] - a0
                aby = work[k + 1, 1] - a1
                u0 = u[s + c0 + j]
                u1 = u[s + c0 + j + 1]
                l2 = abx * abx + aby * aby
                ln = math.sqrt(l2)
                zero = (abx == 0.0) & (aby == 0.0)  # (a repeated point: the distance to it)
                lns = 1.0 if zero else ln
                tx = abx / lns
                ty = aby / lns
                px0 = ((ax * u0 + bx) * u0 + dx) * u0 + ex - a0
                py0 = ((ay * u0 + by) * u0 + dy) * u0 + ey - a1
                px1 = ((ax * u1 + bx) * u1 + dx) * u1 + ex - a0
                py1 = ((ay * u1 + by) * u1 + dy) * u1 + ey - a1
                perp = max(abs(py0 * tx - px0 * ty), abs(py1 * tx - px1 * ty))
                sa0 = px0 * tx + py0 * ty
                sa1 = px1 * tx + py1 * ty
                over = max(max(-sa0, sa0 - ln), max(-sa1, sa1 - ln), 0.0)
                pz = max(math.sqrt(px0 * px0 + py0 * py0), math.sqrt(px1 * px1 + py1 * py1))
                perp = pz if zero else perp
                over = 0.0 if zero else over
                c0x = 6.0 * ax * u0 + 2.0 * bx
                c0y = 6.0 * ay * u0 + 2.0 * by
                c1x = 6.0 * ax * u1 + 2.0 * bx
                c1y = 6.0 * ay * u1 + 2.0 * by
                du = u1 - u0
                sag = 0.125 * du * du * math.sqrt(max(c0x * c0x + c0y * c0y,
                                                      c1x * c1x + c1y * c1y))
                marg = 1e-9 * (1.0 + abs(a0) + abs(a1) + abs(ex) + abs(ey) + ln) + 1e-6 * sag
                perp += sag + marg
                over += sag + marg
                # the slack (0 on short segments), a little over
                f = 1.0 if quant and coarse[k] else min(max(_LONG_SEGMENT * q / lns,
                                                             _LONG_FLOOR), 1.0)
                room = lim - (sl * (1.0 - f) + 1e-9 * sl)
                chk = px0 + py0 + px1 + py1 + tx + ty + sag + room  # (NaN, inf: no pass)
                fb[j] = ((perp * perp + over * over <= room * room) & (room >= 0.0)
                         & (chk - chk == 0.0))
            for j in range(n):
                if fb[j]:
                    continue
                k = base + c0 + j
                a0 = work[k, 0]
                a1 = work[k, 1]
                b0 = work[k + 1, 0]
                b1 = work[k + 1, 1]
                bnd = _bound_pair(ax, ay, bx, by, dx, dy, ex, ey, a0, a1, b0, b1,
                                  u[s + c0 + j], u[s + c0 + j + 1], uu)
                if quant:
                    f = 1.0
                    if q > 0.0 and not coarse[k]:
                        f = min(max(_LONG_SEGMENT * q / math.hypot(b0 - a0, b1 - a1),
                                    _LONG_FLOOR), 1.0)
                    bnd = bnd + sl * (1.0 - f)
                if not (bnd <= lim):
                    ok[r] = False
                    break
            if not ok[r]:
                break


#: points per chunk of :func:`_accept_points` (its Newton steps run over a chunk at a time)
_ACCEPT_CHUNK = 512
#: the samples of :func:`_accept_far`'s seeded search (nearest_on_cubics' defaults)
_SEED_U, _SEED_BASIS = seed_basis(48)
_SEED_ITERS = 6
#: no quanta (:func:`_accept_pairs` on exact input)
_NO_QUANTA = np.zeros(0)
_NO_COARSE = np.zeros(0, dtype=np.bool_)


#: points per chunk of :func:`_accept_quick` (each chunk strided over the whole piece)
_QUICK_CHUNK = 64
#: ... of :func:`_sample_kernel`
_SAMPLE_CHUNK = 16


@njit(cache=True, nogil=True)
def _accept_quick(ctrl, cm, i0, i1, starts, work, arc, e2, su, basis, u, dist, emax,
                  ok) -> None:  # pragma: no cover (compiled)
    """:func:`_accept_points` and :func:`_accept_far` for a verdict only (compiled): per
    piece r, its interior points in strided chunks of at most ``_QUICK_CHUNK`` (every
    chunk spread over the whole piece), each point's parameter and distance as
    :func:`_accept_points` has them (the same numbers: the 6 Newton steps of a point do
    not depend on its chunk); a point over e2[r] gets the seeded search of
    :func:`_accept_far` at once, and the piece fails (``ok[r]`` False) at its first point
    that stays over, or that Newton leaves over 4 e2[r] (or NaN): :func:`_accept_points`
    and :func:`_accept_far` fail it then too. A passing piece ends with the numbers of
    both (its points' ``u``, ``dist``, and ``emax[r]`` their largest); a failing piece's
    others are left unset (:func:`_accept_kernel` with ``quick``)."""
    _accept_kernel(ctrl, cm, i0, i1, starts, work, arc, e2, su, basis, u, dist, emax, ok,
                   np.empty(0, dtype=np.intp), True)


@njit(cache=True, nogil=True)
def _accept_kernel(ctrl, cm, i0, i1, starts, work, arc, e2, su, basis, u, dist, emax, ok,
                   far, quick) -> int:  # pragma: no cover (compiled)
    """The point side of the acceptance test, both ways: :func:`_accept_points` (contiguous
    chunks of ``_ACCEPT_CHUNK`` points, every point's numbers, the far points listed) and,
    with ``quick``, :func:`_accept_quick` (strided chunks of ``_QUICK_CHUNK``, the seeded
    search at once, a piece stopped at its first point left over). One per-piece set-up
    and one chunk loop (each point's 6 Newton steps and distance) serve both."""
    nc = _QUICK_CHUNK if quick else _ACCEPT_CHUNK
    ub = np.empty(nc)
    qxb = np.empty(nc)
    qyb = np.empty(nc)
    db = np.empty(nc)
    ib = np.empty(nc, dtype=np.intp)
    samp = np.empty((basis.shape[0], 2))
    nfar = 0
    for r in range(len(i0)):
        ax, ay, bx, by, dx, dy, ex, ey, base, s, cnt, den = _piece_start(
            cm, r, i0, i1, starts, arc, u, dist)
        lim = e2[r]
        nck = max(1, -(-(cnt - 2) // nc))
        worst = 0.0
        good = True
        nan = False
        sampled = False
        for c in range(nck):
            if quick:  # (chunk c: every nck-th point from 1 + c)
                j0, stop, step = 1 + c, cnt - 1, nck
            else:
                j0, step = 1 + c * nc, 1
                stop = min(cnt - 1, j0 + nc)
            n = 0
            for jj in range(j0, stop, step):
                k = base + jj
                ib[n] = jj
                qxb[n] = work[k, 0] - ex
                qyb[n] = work[k, 1] - ey
                ub[n] = (arc[k] - arc[base]) / den
                n += 1
            for _ in range(6):  # (step by step over the chunk: the loop vectorises)
                for j in range(n):
                    uk = ub[j]
                    ub[j] = newton_param(ax, ay, bx, by, dx, dy, qxb[j], qyb[j], uk)
            for j in range(n):
                k = base + ib[j]
                uk = ub[j]
                rx = ((ax * uk + bx) * uk + dx) * uk - (work[k, 0] - ex)
                ry = ((ay * uk + by) * uk + dy) * uk - (work[k, 1] - ey)
                db[j] = math.sqrt(rx * rx + ry * ry)
            if not quick:
                for j in range(n):
                    d = db[j]
                    u[s + ib[j]] = ub[j]
                    dist[s + ib[j]] = d
                    if d > worst:
                        worst = d
                    elif d != d:
                        nan = True
                continue
            for j in range(n):
                d = db[j]
                f = s + ib[j]
                uk = ub[j]
                if not d <= lim:
                    if not d <= 4.0 * lim:
                        good = False
                        emax[r] = d
                        break
                    if not sampled:
                        bernstein_samples(basis, ctrl, r, samp)
                        sampled = True
                    k = base + ib[j]
                    t, ds = seeded_nearest(cm, r, samp, su, _SEED_ITERS, work[k, 0],
                                           work[k, 1])
                    if not ds <= lim:
                        good = False
                        emax[r] = d
                        break
                    uk = t  # (nearer than Newton's: ds <= lim < d)
                    d = ds
                u[f] = uk
                dist[f] = d
                if d > worst:
                    worst = d
            if not good:
                break
        if quick:
            if good:
                emax[r] = worst
            ok[r] = good
            continue
        emax[r] = np.nan if nan else worst
        if not nan and worst > lim and worst <= 4.0 * lim:
            for j in range(1, cnt - 1):
                if dist[s + j] > lim:
                    far[nfar] = s + j
                    nfar += 1
    return nfar


@njit(cache=True, nogil=True)
def _accept_far(ctrl, cm, i0, i1, starts, work, e2, far, su, basis, u, dist, emax,
                ok) -> None:  # pragma: no cover (compiled)
    """:meth:`_BatchFitter._accept`'s seeded search (compiled) for the points ``far`` (flat
    indices, ascending: :func:`_accept_points` left them over the bound e2[r] of their piece
    r): each point's :func:`galvo_core.geometry.nearest_on_cubics` (its numbers: the samples
    of the piece's cubic at ``su``, the nearest, Newton from there), kept where nearer than
    Newton's; then the piece's largest error into ``emax[r]`` and ``ok[r]`` whether it is
    within e2[r]."""
    samp = np.empty((basis.shape[0], 2))
    nf = far.shape[0]
    m = starts.shape[0]
    r = 0
    k = 0
    while k < nf:
        while r + 1 < m and starts[r + 1] <= far[k]:
            r += 1
        s0 = starts[r]
        s1 = s0 + i1[r] - i0[r] + 1
        k1 = k
        while k1 < nf and far[k1] < s1:
            k1 += 1
        bernstein_samples(basis, ctrl, r, samp)
        base = i0[r] - s0
        for j in range(k, k1):
            f = far[j]
            t, d = seeded_nearest(cm, r, samp, su, _SEED_ITERS, work[base + f, 0],
                                  work[base + f, 1])
            if d < dist[f]:
                u[f] = t
                dist[f] = d
        worst = 0.0
        for j in range(s0, s1):
            if dist[j] > worst:
                worst = dist[j]
        emax[r] = worst
        ok[r] = worst <= e2[r]
        k = k1


@njit(cache=True, nogil=True, error_model="numpy")
def _sample_kernel(cm, i0, i1, work, arc, e2, sample, ok) -> None:  # pragma: no cover
    """:meth:`_BatchFitter._sample_ok` one piece at a time (compiled): ``sample`` evenly
    strided interior points, 4 Newton steps from arc length each (as :func:`_newton_kernel`),
    ``ok[r]``: every squared distance within e2[r]² (none NaN)."""
    ub = np.empty(sample)
    qxb = np.empty(sample)
    qyb = np.empty(sample)
    ib = np.empty(sample, dtype=np.intp)
    for r in range(len(i0)):
        a = i0[r]
        L = i1[r] - a - 1
        stride = max(1, -(-L // sample))
        n = -(-L // stride)
        span = arc[i1[r]] - arc[a]
        den = span if span > 0 else 1.0
        ax = cm[r, 0, 0]
        ay = cm[r, 0, 1]
        bx = cm[r, 1, 0]
        by = cm[r, 1, 1]
        dx = cm[r, 2, 0]
        dy = cm[r, 2, 1]
        ex = cm[r, 3, 0]
        ey = cm[r, 3, 1]
        lim = e2[r] * e2[r]
        good = 0.0 <= lim
        # in strided chunks (each spread over the piece): a failing piece mostly stops
        # after the first (each point's Newton steps are its own: the same verdict)
        nck = max(1, -(-n // _SAMPLE_CHUNK))
        for c in range(nck):
            if not good:
                break
            m = 0
            for j in range(c, n, nck):
                k = a + 1 + stride * j
                ib[m] = k
                qxb[m] = work[k, 0] - ex
                qyb[m] = work[k, 1] - ey
                ub[m] = (arc[k] - arc[a]) / den
                m += 1
            for _ in range(4):
                for j in range(m):
                    uk = ub[j]
                    ub[j] = newton_param(ax, ay, bx, by, dx, dy, qxb[j], qyb[j], uk)
            for j in range(m):
                k = ib[j]
                uk = ub[j]
                rx = ((ax * uk + bx) * uk + dx) * uk - (work[k, 0] - ex)
                ry = ((ay * uk + by) * uk + dy) * uk - (work[k, 1] - ey)
                if not rx * rx + ry * ry <= lim:
                    good = False
                    break
        ok[r] = good


@njit(cache=True, nogil=True, error_model="numpy")
def _dichotomy_kernel(p0, qq, p3, sig, i0, i1, work, arc, sample, max_iter, eps_s,
                      t_out) -> None:  # pragma: no cover (compiled)
    """:meth:`_BatchFitter._dichotomy` one piece at a time (compiled): the Illinois false
    position on t of each piece (its own iterations, as the batch's were), its signed error
    sums over its sample points: 3 Newton steps per evaluation from each point's last
    parameter, its distance signed by the side of the curve it lies on (the chord's
    direction where the tangent vanishes) times the piece's orientation ``sig``, summed in
    the order of the points (the numbers of the former batch version, bit for bit)."""
    ub = np.empty(sample)
    u0 = np.empty(sample)
    pxb = np.empty(sample)
    pyb = np.empty(sample)
    qxb = np.empty(sample)
    qyb = np.empty(sample)
    wb = np.empty(sample)
    for r in range(len(i0)):
        a = i0[r]
        L = i1[r] - a - 1
        stride = max(1, -(-L // sample))
        n = -(-L // stride)
        span = arc[i1[r]] - arc[a]
        den = span if span > 0 else 1.0
        for j in range(n):
            k = a + 1 + stride * j
            pxb[j] = work[k, 0]
            pyb[j] = work[k, 1]
            u0[j] = (arc[k] - arc[a]) / den
            ub[j] = u0[j]
        p0x = p0[r, 0]
        p0y = p0[r, 1]
        p3x = p3[r, 0]
        p3y = p3[r, 1]
        q0x = qq[r, 0] - p0x
        q0y = qq[r, 1] - p0y
        q3x = qq[r, 0] - p3x
        q3y = qq[r, 1] - p3y
        chx = p3x - p0x
        chy = p3y - p0y
        tiny = 1e-18 * (chx * chx + chy * chy)
        sg = sig[r]
        tl = 0.0
        th = 1.0
        sl = 0.0
        sh = 0.0
        hside = 0
        t = 0.0
        for e in range(2 + max_iter):
            if e == 0:
                t = 0.0
            elif e == 1:
                t = 1.0
            else:
                tn = (tl * sh - th * sl) / (sh - sl)
                if not (tl < tn and tn < th):
                    tn = 0.5 * (tl + th)
                t = tn
            # the signed error sum at t
            p1x = p0x + t * q0x
            p1y = p0y + t * q0y
            p2x = p3x + t * q3x
            p2y = p3y + t * q3y
            ax = -p0x + 3.0 * (p1x - p2x)
            ax += p3x
            ay = -p0y + 3.0 * (p1y - p2y)
            ay += p3y
            bx = 3.0 * (p0x + p2x) - 6.0 * p1x
            by = 3.0 * (p0y + p2y) - 6.0 * p1y
            dx = 3.0 * (p1x - p0x)
            dy = 3.0 * (p1y - p0y)
            ex = p0x
            ey = p0y
            for j in range(n):
                qxb[j] = pxb[j] - ex
                qyb[j] = pyb[j] - ey
            for _ in range(3):
                for j in range(n):
                    uk = ub[j]
                    ub[j] = newton_param(ax, ay, bx, by, dx, dy, qxb[j], qyb[j], uk)
            for j in range(n):
                uk = ub[j]
                px = pxb[j]
                py = pyb[j]
                nx = ((ax * uk + bx) * uk + dx) * uk - (px - ex)
                ny = ((ay * uk + by) * uk + dy) * uk - (py - ey)
                d2 = nx * nx + ny * ny
                tgx = (3.0 * ax * uk + 2.0 * bx) * uk + dx
                tgy = (3.0 * ay * uk + 2.0 * by) * uk + dy
                if tgx * tgx + tgy * tgy <= tiny:
                    tgx = chx
                    tgy = chy
                rx = px - (((ax * uk + bx) * uk + dx) * uk + ex)
                ry = py - (((ay * uk + by) * uk + dy) * uk + ey)
                cr = tgx * ry - tgy * rx
                if cr > 0.0:
                    side = 1.0
                elif cr < 0.0:
                    side = -1.0
                elif cr == 0.0:
                    side = 0.0
                else:
                    side = cr  # (NaN)
                wb[j] = sg * side * math.sqrt(d2)
            acc = 0.0
            for j in range(n):
                acc += wb[j]
            sv = -acc
            if e == 0:
                sl = sv
                continue
            if e == 1:
                sh = sv
                for j in range(n):
                    ub[j] = u0[j]
                t = 0.5
                if sl <= 0.0:
                    t = 0.0
                    break
                if sh >= 0.0:
                    t = 1.0
                    break
                hside = 0
                continue
            if abs(sv) < eps_s or th - tl < 1e-9:
                break
            if sv > 0.0:
                if hside == 1:
                    sh = 0.5 * sh
                tl = t
                sl = sv
                hside = 1
            else:
                if hside == -1:
                    sl = 0.5 * sl
                th = t
                sh = sv
                hside = -1
        t_out[r] = t


def _handles_in_order(ctrl: np.ndarray) -> np.ndarray:
    """Per cubic: its inner control points come in order along the chord (P1 before P2: the
    handles do not cross). Asked of both least-squares candidates: over a short corner
    they may cross them (a zigzag) and still pass the bound, farther from the design than
    the lines (serif-cond-italic "z", em 700: 0.618 against 0.612)."""
    c = np.ascontiguousarray(ctrl, dtype=np.float64)
    out = np.empty(len(c), dtype=bool)
    _in_order_kernel(c, out)
    return out


@njit(cache=True, nogil=True)
def _in_order_kernel(c, out):  # pragma: no cover (compiled)
    """:func:`_handles_in_order` per cubic: (P2 - P1) . (P3 - P0) > 0, the x product plus
    the y product (numpy's sum over the pair: the same number)."""
    for r in range(c.shape[0]):
        dx = (c[r, 2, 0] - c[r, 1, 0]) * (c[r, 3, 0] - c[r, 0, 0])
        dy = (c[r, 2, 1] - c[r, 1, 1]) * (c[r, 3, 1] - c[r, 0, 1])
        out[r] = dx + dy > 0.0


def _ragged(starts: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(owner, offset) of the flattened ranges: item j of range r -> (r, j)."""
    total = int(counts.sum())
    owner = np.repeat(np.arange(len(counts)), counts)
    off = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    return owner, off


def _sampled_weights(i0: np.ndarray, i1: np.ndarray, sample: int) -> np.ndarray:
    """Per piece i0..i1: how many of its interior points a kernel sampling at most
    ``sample`` of them treats (the work weight of :func:`galvo_core.parallel.run_chunks`)."""
    return np.minimum(np.maximum(i1 - i0 - 1, 0), sample)


def _halves(a: np.ndarray, b: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Pieces (a, k) and (k, b) for every split piece, in order: (2n, 2)."""
    return np.stack([np.stack([a, k], axis=1), np.stack([k, b], axis=1)], axis=1).reshape(-1, 2)


#: :func:`_pair_deviation`'s samples per cubic
_DEV_SAMPLES = 33


def _pair_deviation(c, ca, cb) -> np.ndarray:
    """Per row: the largest distance (both ways, on samples) between the cubic ``c`` and
    the two cubics ``ca``, ``cb`` it replaces (a polyline of ``_DEV_SAMPLES`` samples
    against one of twice as many; compiled: :func:`_pair_dev_kernel`)."""
    out = np.empty(len(c))
    _pair_dev_kernel(np.ascontiguousarray(c, dtype=np.float64),
                     np.ascontiguousarray(ca, dtype=np.float64),
                     np.ascontiguousarray(cb, dtype=np.float64), _DEV_SAMPLES, out)
    return out


@njit(cache=True, nogil=True)
def _bez_samples(c, r, n, out, at):  # pragma: no cover (compiled)
    """n samples of the cubic c[r] ((M, 4, 2)) at parameters k / (n - 1) into
    out[at:at + n] (the kernels' Bernstein arithmetic: geometry.bernstein_point)."""
    for k in range(n):
        b0, b1, b2, b3 = bernstein_weights(k / (n - 1))
        for j in range(2):
            out[at + k, j] = bernstein_point(b0, b1, b2, b3, c, r, j)


@njit(cache=True, nogil=True)
def _to_polyline(p, poly):  # pragma: no cover (compiled)
    """The largest distance of the points p to the polyline poly (:func:`_seg_d2`)."""
    worst = 0.0
    for i in range(len(p)):
        best = math.inf
        for j in range(len(poly) - 1):
            best = min(best, _seg_d2(p[i, 0], p[i, 1], poly, j, False))
        worst = max(worst, best)
    return math.sqrt(worst)


@njit(cache=True, nogil=True)
def _pair_dev_kernel(c, ca, cb, n, out):  # pragma: no cover (compiled)
    new = np.empty((n, 2))
    old = np.empty((2 * n - 1, 2))
    for r in range(len(c)):
        _bez_samples(c, r, n, new, 0)
        _bez_samples(ca, r, n, old, 0)
        _bez_samples(cb, r, n, old, n - 1)
        out[r] = max(_to_polyline(new, old), _to_polyline(old, new))


def _chain_phase(idx: np.ndarray, k: int) -> np.ndarray:
    """Per sorted index of a group of ``k`` consecutive segments (idx .. idx + k - 1) its
    offset mod ``k`` from the first index of its chain (indices less than ``k`` apart, so
    whose groups overlap): the merge rounds take one phase at a time, so no two picks
    overlap. (Chains of consecutive indices alone would let two triples two apart, with
    the one between them not a candidate, both be picked and share a segment: a range of
    the path was then lost.)"""
    brk = np.r_[True, idx[1:] >= idx[:-1] + k]
    chain_start = np.maximum.accumulate(np.where(brk, np.arange(len(idx)), 0))
    return (idx - idx[chain_start]) % k


@njit(cache=True, nogil=True, inline="always")
def _piece_points(a, b, work, arc, sample, pxb, pyb, ub):  # pragma: no cover (compiled)
    """The input points strictly inside the piece a..b (input indices; at most ``sample``,
    evenly strided: the least-squares fits' sample) into ``pxb``, ``pyb`` and their
    chord-length parameters (arc length over the piece's) into ``ub``; returns their
    number."""
    L = b - a - 1
    stride = max(1, -(-L // sample))
    n = -(-L // stride)
    span = arc[b] - arc[a]
    den = span if span > 0 else 1.0
    for j in range(n):
        ix = a + 1 + stride * j
        pxb[j] = work[ix, 0]
        pyb[j] = work[ix, 1]
        ub[j] = (arc[ix] - arc[a]) / den
    return n


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _handle_solve(n, pxb, pyb, ub, p0x, p0y, p3x, p3y, t0x, t0y, t3x,
                  t3y):  # pragma: no cover (compiled)
    """Schneider's handle lengths of one piece: the cubic p0, p0 + al t0, p3 - be t3, p3
    nearest (least squares) to the points at the parameters ``ub`` (sums in the order of
    the points): (al, be, det, c11, c22) of the 2x2 normal equations (al, be inf/NaN where
    det is 0)."""
    c11 = 0.0
    c12 = 0.0
    c22 = 0.0
    x1 = 0.0
    x2 = 0.0
    for j in range(n):
        uk = ub[j]
        s = 1.0 - uk
        b0 = s * s * s
        b1 = 3 * s * s * uk
        b2 = 3 * s * uk * uk
        b3 = uk * uk * uk
        a1x = b1 * t0x
        a1y = b1 * t0y
        a2x = -b2 * t3x
        a2y = -b2 * t3y
        rx = pxb[j] - (b0 + b1) * p0x - (b2 + b3) * p3x
        ry = pyb[j] - (b0 + b1) * p0y - (b2 + b3) * p3y
        c11 += a1x * a1x + a1y * a1y
        c12 += a1x * a2x + a1y * a2y
        c22 += a2x * a2x + a2y * a2y
        x1 += rx * a1x + ry * a1y
        x2 += rx * a2x + ry * a2y
    det = c11 * c22 - c12 * c12
    al = (x1 * c22 - x2 * c12) / det
    be = (c11 * x2 - c12 * x1) / det
    return al, be, det, c11, c22


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _nearest_params(p0x, p0y, p1x, p1y, p2x, p2y, p3x, p3y, n, pxb, pyb, ub, qxb, qyb,
                    steps):  # pragma: no cover (compiled)
    """The power coefficients (a, b, d, e: x, y each) of the cubic p0..p3 (power_coeffs'
    arithmetic), and ``steps`` Newton steps of each point's parameter ``ub`` (in place,
    step by step over the points: the loop vectorises) towards its nearest point (as
    :func:`_newton_kernel`); ``qxb``, ``qyb`` get the points relative to the start."""
    ax = -p0x + 3.0 * (p1x - p2x)
    ax += p3x
    ay = -p0y + 3.0 * (p1y - p2y)
    ay += p3y
    bx = 3.0 * (p0x + p2x) - 6.0 * p1x
    by = 3.0 * (p0y + p2y) - 6.0 * p1y
    dx = 3.0 * (p1x - p0x)
    dy = 3.0 * (p1y - p0y)
    for j in range(n):
        qxb[j] = pxb[j] - p0x
        qyb[j] = pyb[j] - p0y
    for _ in range(steps):
        for j in range(n):
            uk = ub[j]
            ub[j] = newton_param(ax, ay, bx, by, dx, dy, qxb[j], qyb[j], uk)
    return ax, ay, bx, by, dx, dy


@njit(cache=True, nogil=True, error_model="numpy")
def _ls_kernel(i0, i1, work, arc, sample, p0, p3, t0, t3, chord, ctrl,
               ok) -> None:  # pragma: no cover (compiled)
    """:meth:`_BatchFitter._least_squares` one piece at a time (compiled): Schneider's
    handle lengths at chord-length parameters, twice 2 Newton steps of the parameters and
    the handles again; a handle not positive or over twice the chord (or a singular
    system) is a third of the chord, ``ok[r]`` False. The numbers of the former numpy
    version (:func:`_handle_sums`, :func:`_newton_kernel`), bit for bit."""
    pxb = np.empty(sample)
    pyb = np.empty(sample)
    ub = np.empty(sample)
    qxb = np.empty(sample)
    qyb = np.empty(sample)
    for r in range(i0.shape[0]):
        n = _piece_points(i0[r], i1[r], work, arc, sample, pxb, pyb, ub)
        p0x = p0[r, 0]
        p0y = p0[r, 1]
        p3x = p3[r, 0]
        p3y = p3[r, 1]
        t0x = t0[r, 0]
        t0y = t0[r, 1]
        t3x = t3[r, 0]
        t3y = t3[r, 1]
        c = chord[r]
        good = False
        for it in range(3):
            al, be, det, c11, c22 = _handle_solve(n, pxb, pyb, ub, p0x, p0y, p3x, p3y, t0x,
                                                  t0y, t3x, t3y)
            good = ((abs(det) > 1e-12 * (c11 * c22 + 1e-300)) and al > 0 and be > 0
                    and al < 2.0 * c and be < 2.0 * c)
            if not good:
                al = c / 3.0
                be = c / 3.0
            p1x = p0x + al * t0x
            p1y = p0y + al * t0y
            p2x = p3x - be * t3x
            p2y = p3y - be * t3y
            ctrl[r, 0, 0] = p0x
            ctrl[r, 0, 1] = p0y
            ctrl[r, 1, 0] = p1x
            ctrl[r, 1, 1] = p1y
            ctrl[r, 2, 0] = p2x
            ctrl[r, 2, 1] = p2y
            ctrl[r, 3, 0] = p3x
            ctrl[r, 3, 1] = p3y
            if it == 2:
                break
            _nearest_params(p0x, p0y, p1x, p1y, p2x, p2y, p3x, p3y, n, pxb, pyb, ub, qxb,
                            qyb, 2)
        ok[r] = good


@njit(cache=True, nogil=True, error_model="numpy")
def _gn_kernel(i0, i1, work, arc, sample, p0, p3, t0, t3, chord, rounds, ctrl,
               ok) -> None:  # pragma: no cover (compiled)
    """:meth:`_BatchFitter._gauss_newton` one piece at a time (compiled): Schneider's
    handle lengths at chord-length parameters to start (a third of the chord where not
    positive or over twice the chord), then per round the cubic's power coefficients, 2
    Newton steps per point, the unit normal at the nearest point and the signed distance
    along it, the 2x2 normal equations of the handle lengths, a damped step; ``ok[r]``:
    both handles positive and under twice the chord (else a third of it). The numbers of
    the former numpy version, bit for bit."""
    pxb = np.empty(sample)
    pyb = np.empty(sample)
    ub = np.empty(sample)
    qxb = np.empty(sample)
    qyb = np.empty(sample)
    rxb = np.empty(sample)
    ryb = np.empty(sample)
    txb = np.empty(sample)
    tyb = np.empty(sample)
    nb = np.empty(sample)
    resb = np.empty(sample)
    j1b = np.empty(sample)
    j2b = np.empty(sample)
    fb = np.empty(sample, dtype=np.bool_)
    for r in range(i0.shape[0]):
        n = _piece_points(i0[r], i1[r], work, arc, sample, pxb, pyb, ub)
        p0x = p0[r, 0]
        p0y = p0[r, 1]
        p3x = p3[r, 0]
        p3y = p3[r, 1]
        t0x = t0[r, 0]
        t0y = t0[r, 1]
        t3x = t3[r, 0]
        t3y = t3[r, 1]
        c = chord[r]
        a_, b_, _d, _c11, _c22 = _handle_solve(n, pxb, pyb, ub, p0x, p0y, p3x, p3y, t0x,
                                               t0y, t3x, t3y)
        if not (a_ > 0 and b_ > 0 and a_ < 2.0 * c and b_ < 2.0 * c):
            a_ = c / 3.0
            b_ = c / 3.0
        lim = 0.25 * c
        for _ in range(rounds):
            p1x = p0x + a_ * t0x
            p1y = p0y + a_ * t0y
            p2x = p3x - b_ * t3x
            p2y = p3y - b_ * t3y
            ax, ay, bx, by, dx, dy = _nearest_params(p0x, p0y, p1x, p1y, p2x, p2y, p3x, p3y,
                                                     n, pxb, pyb, ub, qxb, qyb, 2)
            ex = p0x
            ey = p0y
            for j in range(n):
                uk = ub[j]
                rxb[j] = ((ax * uk + bx) * uk + dx) * uk + ex - pxb[j]
                ryb[j] = ((ay * uk + by) * uk + dy) * uk + ey - pyb[j]
                txb[j] = (3.0 * ax * uk + 2.0 * bx) * uk + dx
                tyb[j] = (3.0 * ay * uk + 2.0 * by) * uk + dy
            hypot_into(txb, tyb, n, nb, fb)
            for j in range(n):
                dn = nb[j]
                nb[j] = dn if dn > 0.0 else 1.0
            for j in range(n):
                uk = ub[j]
                dn = nb[j]
                nx = -tyb[j] / dn
                ny = txb[j] / dn
                resb[j] = nx * rxb[j] + ny * ryb[j]
                sk = 1.0 - uk
                j1b[j] = 3 * sk * sk * uk * (nx * t0x + ny * t0y)
                j2b[j] = -3 * sk * uk * uk * (nx * t3x + ny * t3y)
            c11 = 0.0
            c12 = 0.0
            c22 = 0.0
            x1 = 0.0
            x2 = 0.0
            for j in range(n):
                j1 = j1b[j]
                j2 = j2b[j]
                res = resb[j]
                c11 += j1 * j1
                c12 += j1 * j2
                c22 += j2 * j2
                x1 += j1 * res
                x2 += j2 * res
            x1 = -x1
            x2 = -x2
            det = c11 * c22 - c12 * c12
            da = (x1 * c22 - x2 * c12) / det
            db = (c11 * x2 - c12 * x1) / det
            if (np.isfinite(da) and np.isfinite(db)
                    and abs(det) > 1e-12 * (c11 * c22 + 1e-300)):
                # damped: at most a quarter chord per round, a handle at most halved
                v = a_ + min(max(da, -lim), lim)
                h = 0.5 * a_
                a_ = v if (v >= h or v != v) else h
                v = b_ + min(max(db, -lim), lim)
                h = 0.5 * b_
                b_ = v if (v >= h or v != v) else h
        good = (np.isfinite(a_) and np.isfinite(b_) and a_ > 0 and b_ > 0 and a_ < 2.0 * c
                and b_ < 2.0 * c)
        if not good:
            a_ = c / 3.0
            b_ = c / 3.0
        ok[r] = good
        ctrl[r, 0, 0] = p0x
        ctrl[r, 0, 1] = p0y
        ctrl[r, 1, 0] = p0x + a_ * t0x
        ctrl[r, 1, 1] = p0y + a_ * t0y
        ctrl[r, 2, 0] = p3x - b_ * t3x
        ctrl[r, 2, 1] = p3y - b_ * t3y
        ctrl[r, 3, 0] = p3x
        ctrl[r, 3, 1] = p3y


@njit(cache=True, nogil=True, error_model="numpy")
def _gn_free_sums(i0, i1, work, arc, sample, ps, pts, u, ctrl, first, N,
                  g) -> None:  # pragma: no cover (compiled)
    """:meth:`_BatchFitter._gauss_newton_free`'s normal equations of one round (compiled),
    per piece r (its sample points: :func:`_piece_points`, kept in pts[ps[r]] ..
    pts[ps[r + 1] - 1] on the ``first`` round, their parameters in ``u``, chord length ones
    on the first round; cubic ``ctrl[r]``): 2 Newton steps
    per point from ``u`` (updated; as :func:`_newton_kernel`), the unit normal at the
    nearest point and the signed distance along it, the Jacobian of the distance in the two
    inner control points; sums in the order of the points (as the former np.bincount) into
    ``N`` (m, 4, 4) and ``g`` (m, 4, 1) (minus the gradient), made ready for the solve."""
    pxb = np.empty(sample)
    pyb = np.empty(sample)
    ub = np.empty(sample)
    qxb = np.empty(sample)
    qyb = np.empty(sample)
    jb = np.empty((4, sample))
    resb = np.empty(sample)
    txb = np.empty(sample)
    tyb = np.empty(sample)
    nb = np.empty(sample)
    fb = np.empty(sample, dtype=np.bool_)
    for r in range(i0.shape[0]):
        k0 = ps[r]
        n = ps[r + 1] - k0
        if first:
            _piece_points(i0[r], i1[r], work, arc, sample, pxb, pyb, ub)
            for j in range(n):
                pts[k0 + j, 0] = pxb[j]
                pts[k0 + j, 1] = pyb[j]
        else:
            for j in range(n):
                pxb[j] = pts[k0 + j, 0]
                pyb[j] = pts[k0 + j, 1]
                ub[j] = u[k0 + j]
        p0x = ctrl[r, 0, 0]
        p0y = ctrl[r, 0, 1]
        ax, ay, bx, by, dx, dy = _nearest_params(
            p0x, p0y, ctrl[r, 1, 0], ctrl[r, 1, 1], ctrl[r, 2, 0], ctrl[r, 2, 1],
            ctrl[r, 3, 0], ctrl[r, 3, 1], n, pxb, pyb, ub, qxb, qyb, 2)
        ex = p0x
        ey = p0y
        for j in range(n):
            uk = ub[j]
            u[k0 + j] = uk
            txb[j] = (3.0 * ax * uk + 2.0 * bx) * uk + dx
            tyb[j] = (3.0 * ay * uk + 2.0 * by) * uk + dy
        hypot_into(txb, tyb, n, nb, fb)
        for j in range(n):
            uk = ub[j]
            rx = ((ax * uk + bx) * uk + dx) * uk + ex - pxb[j]
            ry = ((ay * uk + by) * uk + dy) * uk + ey - pyb[j]
            tx = txb[j]
            ty = tyb[j]
            dn = nb[j]
            if not dn > 0.0:
                dn = 1.0
            nx = -ty / dn
            ny = tx / dn
            resb[j] = nx * rx + ny * ry
            sk = 1.0 - uk
            b1 = 3 * sk * sk * uk
            b2 = 3 * sk * uk * uk
            jb[0, j] = b1 * nx
            jb[1, j] = b1 * ny
            jb[2, j] = b2 * nx
            jb[3, j] = b2 * ny
        # the 14 sums in one pass (each in the order of the points, as before; their
        # chains of additions independent of each other, so they overlap)
        n00 = 0.0
        n01 = 0.0
        n02 = 0.0
        n03 = 0.0
        n11 = 0.0
        n12 = 0.0
        n13 = 0.0
        n22 = 0.0
        n23 = 0.0
        n33 = 0.0
        g0 = 0.0
        g1 = 0.0
        g2 = 0.0
        g3 = 0.0
        for j in range(n):
            j0 = jb[0, j]
            j1 = jb[1, j]
            j2 = jb[2, j]
            j3 = jb[3, j]
            rs = resb[j]
            n00 += j0 * j0
            n01 += j0 * j1
            n02 += j0 * j2
            n03 += j0 * j3
            n11 += j1 * j1
            n12 += j1 * j2
            n13 += j1 * j3
            n22 += j2 * j2
            n23 += j2 * j3
            n33 += j3 * j3
            g0 += j0 * rs
            g1 += j1 * rs
            g2 += j2 * rs
            g3 += j3 * rs
        N[r, 0, 0] = n00
        N[r, 0, 1] = n01
        N[r, 1, 0] = n01
        N[r, 0, 2] = n02
        N[r, 2, 0] = n02
        N[r, 0, 3] = n03
        N[r, 3, 0] = n03
        N[r, 1, 1] = n11
        N[r, 1, 2] = n12
        N[r, 2, 1] = n12
        N[r, 1, 3] = n13
        N[r, 3, 1] = n13
        N[r, 2, 2] = n22
        N[r, 2, 3] = n23
        N[r, 3, 2] = n23
        N[r, 3, 3] = n33
        g[r, 0, 0] = -g0
        g[r, 1, 0] = -g1
        g[r, 2, 0] = -g2
        g[r, 3, 0] = -g3
        # non-finite sums are 0; the diagonal gets 1e-9 of the trace (summed in order, as
        # np.trace) + 1e-12 (as N + reg * eye(4): the others + reg * 0)
        for i in range(4):
            if not np.isfinite(g[r, i, 0]):
                g[r, i, 0] = 0.0
            for i2 in range(4):
                if not np.isfinite(N[r, i, i2]):
                    N[r, i, i2] = 0.0
        reg = 1e-9 * (((N[r, 0, 0] + N[r, 1, 1]) + N[r, 2, 2]) + N[r, 3, 3]) + 1e-12
        for i in range(4):
            for i2 in range(4):
                N[r, i, i2] = N[r, i, i2] + reg * (1.0 if i == i2 else 0.0)


@njit(cache=True, nogil=True)
def _gn_free_step(ctrl, d, chord) -> None:  # pragma: no cover (compiled)
    """:meth:`_BatchFitter._gauss_newton_free`'s step of one round (compiled): the solution
    ``d`` (m, 4, 1) where finite (else 0), clipped to a quarter of the chord either way (as
    np.clip), added to the two inner control points."""
    for r in range(ctrl.shape[0]):
        lim = 0.25 * chord[r]
        nlim = -lim
        for i in range(4):
            v = d[r, i, 0]
            if not np.isfinite(v):
                v = 0.0
            v = v if v > nlim else nlim  # (np.clip: max, then min)
            v = v if v < lim else lim
            ctrl[r, 1 + i // 2, i % 2] += v


@njit(cache=True, nogil=True, error_model="numpy")
def _triangle_kernel(A, B, q, t_out, t_in, ok, p0, qq, p3,
                     sig) -> None:  # pragma: no cover (compiled)
    """:meth:`_BatchFitter._triangle` per piece (compiled; the numbers of the former numpy
    version): the tangents' determinant, the chord's length (libm's hypot), the handle
    lengths along the tangents to their meeting point, ok where both are positive (over
    1e-9 of the chord, at most 1e3 chords) on a non-degenerate chord and determinant, the
    apex p0 + al t0 (p0 where not ok), the determinant's sign."""
    for r in range(A.shape[0]):
        a = A[r]
        b = B[r]
        p0x = q[a, 0]
        p0y = q[a, 1]
        p3x = q[b, 0]
        p3y = q[b, 1]
        t0x = t_out[a, 0]
        t0y = t_out[a, 1]
        t3x = t_in[b, 0]
        t3y = t_in[b, 1]
        det = t0x * t3y - t0y * t3x
        chx = p3x - p0x
        chy = p3y - p0y
        lc = math.hypot(chx, chy)
        al = (chx * t3y - chy * t3x) / det
        be = (t0x * chy - t0y * chx) / det
        good = ((lc > 0.0) and (abs(det) >= 1e-9) and (al > 1e-9 * lc) and (be > 1e-9 * lc)
                and (al <= 1e3 * lc) and (be <= 1e3 * lc))
        w = al if good else 0.0
        ok[r] = good
        p0[r, 0] = p0x
        p0[r, 1] = p0y
        p3[r, 0] = p3x
        p3[r, 1] = p3y
        qq[r, 0] = p0x + w * t0x
        qq[r, 1] = p0y + w * t0y
        if det > 0.0:
            sig[r] = 1.0
        elif det < 0.0:
            sig[r] = -1.0
        elif det == 0.0:
            sig[r] = 0.0
        else:
            sig[r] = det  # (NaN, as np.sign)


def _sorted_find(sorted_keys: np.ndarray, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per key: (a position in the non-empty sorted array ``sorted_keys``, whether the key is
    there), by binary search."""
    pos = np.minimum(np.searchsorted(sorted_keys, keys), len(sorted_keys) - 1)
    return pos, sorted_keys[pos] == keys


class _BatchFitter:
    """Fits curve pieces together (of one path, or of many concatenated paths: ``work`` the
    input points, ``kept`` the thinned indices into it, ``arc`` the cumulative arc length
    restarted at every path), round by round.

    Each round takes every piece still to do, runs the dichotomy for all of them at once
    (one compiled call, each piece its own iterations), tests them all at once, keeps the
    cubics that pass and splits the others for the next round. The work per round is
    linear in the points of the pieces still open.
    """

    def __init__(
        self,
        work: np.ndarray,
        kept: np.ndarray,
        t_in: np.ndarray,
        t_out: np.ndarray,
        e_per: float | np.ndarray,
        eps_sum: float,
        arc: np.ndarray,
        q: np.ndarray | None = None,
    ) -> None:
        self.work = work
        self.kept = kept
        self.q = work[kept] if q is None else q
        #: per thinned point its path's quantum (None: exact input everywhere)
        self.quant: np.ndarray | None = None
        #: per input segment work[k] -> work[k + 1]: a chord of a coarsely flattened curve
        #: (:func:`_coarse_chords`), no design line
        self.coarse = np.zeros(len(work), dtype=np.bool_)
        self.t_in = t_in
        self.t_out = t_out
        # the bound of a piece starting at thinned point k (its path's): e_per + rounding
        self.e_per = np.broadcast_to(np.asarray(e_per, dtype=np.float64), (len(kept),))
        self.eps_sum = eps_sum
        self.arc = arc
        self._cubics: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self._lines: list[np.ndarray] = []
        # :meth:`_all_segments` as :meth:`_store` left it (and its :meth:`_fixed_lines`),
        # valid while _lines and _cubics are the lists it stored
        self._all: tuple | None = None
        self._all_fixed: np.ndarray | None = None
        self._barely_turns: np.ndarray | None = None
        # the candidate pairs / triples of the merge rounds for the segments starting at A
        # (the array itself): (A, idx, position in its chain)
        self._pairs: tuple | None = None
        self._triples: tuple | None = None
        #: keys a (M + 1) + b of the ranges a..b that :meth:`_try` found no cubic for
        self._failed = np.zeros(0, dtype=np.int64)
        #: keys (as ``_failed``) of the ranges :meth:`_minimax_merge_round` tried
        self._merge_tried = np.zeros(0, dtype=np.int64)
        #: rounded input: the refinement's starts of the failed ranges (keys as ``_failed``,
        #: free Gauss-Newton cubics), gathered by :meth:`_second_candidate`
        self._start_keys: list[np.ndarray] = []
        self._start_ctrl: list[np.ndarray] = []
        #: during the refined rounds: (sorted keys, their starts, refined yet)
        self._starts: tuple | None = None
        #: rounded input: the ranges :meth:`_try` passed (keys, cubics, bounds), and during
        #: the refined rounds the same sorted
        self._pass_keys: list[np.ndarray] = []
        self._pass_ctrl: list[np.ndarray] = []
        self._pass_em: list[np.ndarray] = []
        self._passes: tuple = ()

    # -- the one-parameter family ---------------------------------------------------------
    def _triangle(self, A: np.ndarray, B: np.ndarray):
        """Per piece A..B: whether its end tangents meet in front of both ends (the
        triangle exists), the ends, the apex (p0 where not) and the orientation (compiled,
        :func:`_triangle_kernel`)."""
        A = np.ascontiguousarray(A, dtype=np.intp)
        B = np.ascontiguousarray(B, dtype=np.intp)
        m = len(A)
        ok = np.empty(m, dtype=bool)
        p0 = np.empty((m, 2))
        qq = np.empty((m, 2))
        p3 = np.empty((m, 2))
        sig = np.empty(m)
        _triangle_kernel(A, B, self.q, self.t_out, self.t_in, ok, p0, qq, p3, sig)
        return ok, p0, qq, p3, sig

    @staticmethod
    def _ctrl(p0, qq, p3, t):
        t = t[:, None]
        return np.stack([p0, p0 + t * (qq - p0), p3 + t * (qq - p3), p3], axis=1)

    def _dichotomy(self, p0, qq, p3, sig, i0, i1, sample: int = _BISECT_SAMPLE,
                   max_iter: int = _MAX_BISECT, eps_sum: float | None = None) -> np.ndarray:
        """t per piece: the signed error sum over a sample of each piece's input points
        crosses zero (Illinois false position inside the bracket [0, 1]); each piece on its
        own, compiled (:func:`_dichotomy_kernel`). Returns the pieces' cubics (m, 4, 2)."""
        t = np.empty(len(p0))
        f0, fq, f3, fs = (np.ascontiguousarray(a, dtype=np.float64) for a in (p0, qq, p3, sig))
        j0, j1 = (np.ascontiguousarray(a, dtype=np.intp) for a in (i0, i1))
        eps_s = self.eps_sum if eps_sum is None else eps_sum

        def chunk(lo: int, hi: int) -> None:
            _dichotomy_kernel(f0[lo:hi], fq[lo:hi], f3[lo:hi], fs[lo:hi], j0[lo:hi], j1[lo:hi],
                              self.work, self.arc, sample, max_iter, eps_s, t[lo:hi])

        run_chunks(chunk, _sampled_weights(j0, j1, sample) * max_iter)
        return self._ctrl(p0, qq, p3, t)

    def _accept(self, ctrl: np.ndarray, i0: np.ndarray, i1: np.ndarray, e2: np.ndarray,
                A: np.ndarray | None = None, full: bool = False):
        """Per piece: bound of the max input-point error, pass/fail of both sides of the
        guarantee, and the flat per-point errors (with the offsets of each piece).

        Points: 6 Newton steps from arc length per point (the ends are the curve's ends).
        Newton may stop in a local minimum: a seeded search for the points over the bound,
        in pieces that miss it by little (a piece far off is a bad fit anyway; the check
        only decides between keeping and splitting, never weakens the guarantee). Then the
        curve-to-polyline side for the pieces that passed so far; on rounded input a long
        input segment is the design up to the rounding of its ends, so the curve keeps
        closer to it than the rounding allows. Both sides compiled, one piece at a time
        (:func:`_accept_points`, :func:`_accept_pairs`); a piece stops at its first pair
        over the bound.

        Only the passing pieces' bounds and errors are final unless ``full``: a failing
        piece stops at its first point that the seeded search leaves over the bound
        (:func:`_accept_quick`: the same verdicts); with ``full`` every point's error is
        (for the split points)."""
        m = len(ctrl)
        i0 = np.ascontiguousarray(i0, dtype=np.intp)
        i1 = np.ascontiguousarray(i1, dtype=np.intp)
        e2 = np.ascontiguousarray(e2, dtype=np.float64)
        cnt = i1 - i0 + 1
        starts = np.cumsum(cnt) - cnt
        total = int(cnt.sum())
        cm = power_coeffs_many(ctrl)
        u = np.empty(total)
        dist = np.empty(total)
        emax = np.empty(m)
        ctrl = np.ascontiguousarray(ctrl, dtype=np.float64)
        if full:
            # (chunks of pieces on the kernel threads: each piece's numbers are its own; a
            # chunk lists its far points in its own part of ``far``, in order)
            far = np.empty(total, dtype=np.intp)

            def points(lo: int, hi: int) -> tuple[int, int]:
                f0 = int(starts[lo]) if lo < m else 0
                nf = _accept_points(cm[lo:hi], i0[lo:hi], i1[lo:hi], starts[lo:hi], self.work,
                                    self.arc, e2[lo:hi], u, dist, emax[lo:hi], far[f0:])
                return f0, nf

            parts = cast("list[tuple[int, int]]", run_chunks(points, cnt))
            far = np.concatenate([far[f0:f0 + nf] for f0, nf in parts])
            ok = emax <= e2
            if len(far):
                def far_chunk(lo: int, hi: int) -> None:
                    a = np.searchsorted(far, starts[lo])
                    b = np.searchsorted(far, starts[hi - 1] + cnt[hi - 1])
                    if b > a:
                        _accept_far(ctrl[lo:hi], cm[lo:hi], i0[lo:hi], i1[lo:hi],
                                    starts[lo:hi], self.work, e2[lo:hi], far[a:b], _SEED_U,
                                    _SEED_BASIS, u, dist, emax[lo:hi], ok[lo:hi])

                run_chunks(far_chunk, cnt)
        else:
            ok = np.empty(m, dtype=bool)
        qa, coarse = _NO_QUANTA, _NO_COARSE
        if self.quant is not None and A is not None:
            qa = np.ascontiguousarray(self.quant[A], dtype=np.float64)
            coarse = self.coarse

        def chunk(lo: int, hi: int) -> None:
            if not full:
                _accept_quick(ctrl[lo:hi], cm[lo:hi], i0[lo:hi], i1[lo:hi], starts[lo:hi],
                              self.work, self.arc, e2[lo:hi], _SEED_U, _SEED_BASIS, u, dist,
                              emax[lo:hi], ok[lo:hi])
            _accept_pairs(cm[lo:hi], i0[lo:hi], i1[lo:hi], starts[lo:hi], self.work, u,
                          e2[lo:hi], qa[lo:hi] if len(qa) else qa, coarse, ok[lo:hi])

        run_chunks(chunk, cnt)
        return ok, emax, dist, starts

    def fit(self, curve_pieces: np.ndarray, line_pieces: np.ndarray | None = None) -> None:
        """Fit the curve pieces (P, 2) (inclusive thinned index ranges a, b); the results
        are in :meth:`results`. ``line_pieces``: the starts of the one-segment pieces that
        are lines already (some may be absorbed into cubics, :meth:`_absorb_round`; the
        others come back among the lines). After the fit: merges of cubics at smooth
        vertices (:meth:`_merge_round`), of segments at vertices that barely turn
        (:meth:`_absorb_round`), three cubics into two (:meth:`_resplit_round`)."""
        if line_pieces is not None:
            self._lines.append(np.asarray(line_pieces, dtype=np.intp))
        ab = np.asarray(curve_pieces, dtype=np.intp).reshape(-1, 2)
        while len(ab):
            line = ab[:, 1] - ab[:, 0] == 1
            if self.quant is not None and line.any():
                as_cubic = self._bulging_segments(ab, line)
                ab = ab[~as_cubic]
                line = line[~as_cubic]
            self._lines.append(ab[line, 0])
            ab = ab[~line]
            if len(ab) == 0:
                break
            A, B = ab[:, 0], ab[:, 1]
            ok, p0, qq, p3, sig = self._triangle(A, B)
            # no triangle (tangents do not meet in front of both ends): the second candidate
            # (it needs none), else split in the middle
            nt = np.flatnonzero(~ok)
            nt = nt[self._exact(A[nt])]
            if len(nt):
                g2, c2, e2 = self._second_candidate(A[nt], B[nt])
                if g2.any():
                    self._cubics.append((A[nt[g2]], B[nt[g2]], c2[g2], e2[g2]))
                    keep = np.ones(len(A), dtype=bool)
                    keep[nt[g2]] = False
                    A, B, p0, qq, p3, sig, ok = (A[keep], B[keep], p0[keep], qq[keep],
                                                 p3[keep], sig[keep], ok[keep])
            todo = [_halves(A[~ok], B[~ok], (A[~ok] + B[~ok]) // 2)]
            A, B = A[ok], B[ok]
            if len(A):
                i0, i1 = self.kept[A], self.kept[B]
                ctrl = self._dichotomy(p0[ok], qq[ok], p3[ok], sig[ok], i0, i1)
                good, emax, dist, starts = self._accept(ctrl, i0, i1, self.e_per[A], A,
                                                        full=True)
                if self.quant is not None:
                    rq = np.flatnonzero(self.quant[A] > 0.0)
                    if len(rq):
                        self._prefer_least_squares(rq, A, B, ctrl, good, emax, dist, starts)
                sc = np.flatnonzero(~good & self._exact(A))
                if len(sc):
                    g2, c2, e2 = self._second_candidate(A[sc], B[sc])
                    ctrl[sc[g2]] = c2[g2]
                    emax[sc[g2]] = e2[g2]
                    good[sc[g2]] = True
                self._cubics.append((A[good], B[good], ctrl[good], emax[good]))
                bad = ~good
                k = self._split_points(A[bad], B[bad], dist, starts[bad])
                todo.append(_halves(A[bad], B[bad], k))
            ab = np.concatenate(todo)
        for _ in range(_MERGE_ROUNDS):
            if not self._merge_round():
                break
        if line_pieces is not None:
            for _ in range(_ABSORB_ROUNDS):
                if not (self._absorb_round(0) | self._absorb_round(1)):
                    break
        if self.quant is not None:
            for _ in range(_BRIDGE_ROUNDS):
                if not self._bridge_round():
                    break
        for _ in range(_RESPLIT_ROUNDS):
            if not (self._resplit_round(0) | self._resplit_round(1) | self._resplit_round(2)):
                break
        self._greedy_round()
        if _MINIMAX_MERGE and self.quant is not None:
            for _ in range(_MINIMAX_MERGE):
                if not (self._minimax_merge_round(0) | self._minimax_merge_round(1)):
                    break
            if _REFINED_ROUNDS:
                self._refined_rounds()

    def _refined_rounds(self) -> None:
        """Rounded input, after the merge pass: :meth:`_greedy_round` and
        :meth:`_resplit_round` once more, their :meth:`_try` answering the ranges tried
        before from what it found then (a pass: its cubic; a failure: only the refinement
        of the free Gauss-Newton start :meth:`_second_candidate` cached for it, where that
        start is a near miss, :meth:`_refine_cached`). New ranges fail. The merge pass
        changed the segments:
        chains and triples the first rounds could not shorten may shorten now, and a near
        miss of theirs may now pass."""
        def cat(parts, empty):
            return np.concatenate(parts) if parts else empty

        ks = cat(self._start_keys, np.zeros(0, dtype=np.int64))
        cs = cat(self._start_ctrl, np.zeros((0, 4, 2)))
        ks, first = np.unique(ks, return_index=True)
        self._starts = (ks, cs[first], np.zeros(len(ks), dtype=bool))
        pk = cat(self._pass_keys, np.zeros(0, dtype=np.int64))
        pc = cat(self._pass_ctrl, np.zeros((0, 4, 2)))
        pe = cat(self._pass_em, np.zeros(0))
        pk, first = np.unique(pk, return_index=True)
        self._passes = (pk, pc[first], pe[first])
        self._greedy_round()
        self._resplit_round(0) | self._resplit_round(1) | self._resplit_round(2)
        self._starts = None
        self._passes = ()

    def _barely_turning(self) -> np.ndarray:
        """Per thinned point: its two tangents differ by less than ``_ABSORB_TURN`` (cached:
        the tangents stay as they are after the fit's first pass)."""
        if self._barely_turns is None:
            cosv = (self.t_in * self.t_out).sum(axis=1)
            self._barely_turns = cosv > math.cos(_ABSORB_TURN)
        return self._barely_turns

    def _minimax_merge_round(self, parity: int) -> bool:
        """Rounded input whose rounding is a fair share of the bound (:meth:`_exact`), after
        the fit: two adjacent cubics at a vertex that barely turns (``_ABSORB_TURN``) are
        replaced by one cubic over both where the refinement
        (:func:`galvo_core.minimax.minimax_cubics`) brings a near miss within the bound,
        under the same test (:meth:`_accept`). The start: the free Gauss-Newton cubic
        (:meth:`_gauss_newton_free`) from the cubic the two would be pieces of (their outer
        handles stretched by the shares of their lengths); refined only where its sampled
        points are all within ``_MINIMAX_NEAR`` times the bound; kept only where it stays
        within ``_MERGE_DEV`` quanta of the two cubics it replaces. One try per range (the
        refinement inside every candidate of the fit cost a tenth more time on sparse
        outlines): non-overlapping pairs from ``parity``; True when
        something merged."""
        A, B, C, E, isl = self._all_segments()
        if len(A) < 2:
            return False
        assert self.quant is not None  # (called on rounded input only)
        barely = self._barely_turning()
        if _MINIMAX_LINES:
            # a line that is no design line (:meth:`_fixed_lines`) may take part too, as the
            # cubic with its handles at its thirds
            fixed = self._fixed_lines(A, B, isl)
            adj = ~fixed[:-1] & ~fixed[1:] & (B[:-1] == A[1:]) & barely[B[:-1]]
        else:
            adj = ~isl[:-1] & ~isl[1:] & (B[:-1] == A[1:]) & barely[B[:-1]]
        idx = np.flatnonzero(adj)
        idx = idx[(self.quant[A[idx]] > 0.0) & self._exact(A[idx])]
        if len(idx) == 0:
            return False
        pick = idx[_chain_phase(idx, 2) == parity]
        # a range tried before is not tried again (the next round's new pairs only)
        key = self._range_keys(A[pick], B[pick + 1])
        tried = self._merge_tried
        if len(tried):
            fresh = ~_sorted_find(tried, key)[1]
            pick, key = pick[fresh], key[fresh]
        if len(pick) == 0:
            return False
        self._merge_tried = np.union1d(tried, key)
        ca = self._as_cubics(A, B, C, isl, pick)
        cb = self._as_cubics(A, B, C, isl, pick + 1)
        la = np.hypot(*np.diff(ca, axis=1).transpose(2, 0, 1)).sum(axis=1)
        lb = np.hypot(*np.diff(cb, axis=1).transpose(2, 0, 1)).sum(axis=1)
        t = (la / np.maximum(la + lb, 1e-300))[:, None]
        start = ca.copy()
        start[:, 3] = cb[:, 3]
        start[:, 1] = ca[:, 0] + (ca[:, 1] - ca[:, 0]) / np.maximum(t, 1e-9)
        start[:, 2] = cb[:, 3] + (cb[:, 2] - cb[:, 3]) / np.maximum(1.0 - t, 1e-9)
        a, b = A[pick], B[pick + 1]
        i0, i1 = self.kept[a], self.kept[b]
        cf_, okf = self._gauss_newton_free(a, b, i0, i1, start, _MERGE_GN_ROUNDS)
        start = np.where(okf[:, None, None], cf_, start)
        v = np.flatnonzero(self._sample_ok(start, i0, i1, _MERGE_NEAR * self.e_per[a]))
        if len(v) == 0:
            return False
        cm, okm = minimax_cubics(self.work, self.arc, i0[v], i1[v], start[v],
                                 self.e_per[a[v]])
        okm &= _handles_in_order(cm)
        v, cm = v[okm], cm[okm]
        if len(v):
            near = _pair_deviation(cm, ca[v], cb[v]) <= _MERGE_DEV * self.quant[a[v]]
            v, cm = v[near], cm[near]
        if len(v) == 0:
            return False
        g, e, _, _ = self._accept(cm, i0[v], i1[v], self.e_per[a[v]], a[v])
        if not g.any():
            return False
        i = pick[v[g]]
        isl = isl.copy()
        isl[i] = False  # (a line merged: the cubic's)
        B[i] = B[i + 1]
        C[i] = cm[g]
        E[i] = e[g]
        keep = np.ones(len(A), dtype=bool)
        keep[i + 1] = False
        self._store(A[keep], B[keep], C[keep], E[keep], isl[keep])
        return True

    def _as_cubics(self, A, B, C, isl, s):
        """The control points of the segments ``s`` (rows of ``A``, ``B``, ``C``, ``isl``), a
        line's as the cubic with its handles at its thirds (a copy)."""
        c = C[s].copy()
        li = np.flatnonzero(isl[s])
        p0, p3 = self.q[A[s[li]]], self.q[B[s[li]]]
        c[li] = np.stack([p0, (2.0 * p0 + p3) / 3.0, (p0 + 2.0 * p3) / 3.0, p3], axis=1)
        return c

    def _bridge_round(self) -> bool:
        """Rounded input: a line that is no line of the design (:meth:`_fixed_lines`) between
        two segments, at vertices that barely turn (``_ABSORB_TURN``), is replaced with both
        neighbours by one cubic where one passes the same test (the rounding leaves short
        lines in curves, their thinned tangents off the design's: no cubic may end at them,
        so neither the pairs of :meth:`_absorb_round` nor the chains of
        :meth:`_greedy_round` get past them). Every such triple is tried; those that pass are
        taken from the first on, none overlapping one taken. True when something changed."""
        A, B, C, E, isl = self._all_segments()
        if len(A) < 3:
            return False
        assert self.quant is not None  # (called on rounded input only)
        barely = self._barely_turning()
        fixed = self._fixed_lines(A, B, isl)
        i = np.arange(1, len(A) - 1)
        tri = (isl[i] & ~fixed[i - 1] & ~fixed[i] & ~fixed[i + 1]
               & (B[i - 1] == A[i]) & (B[i] == A[i + 1])
               & barely[A[i]] & barely[B[i]]
               & (self.quant[A[i]] > 0.0))
        i = i[tri]
        if len(i) == 0:
            return False
        ok, ctrl, em = self._try(A[i - 1], B[i + 1])
        i, ctrl, em = i[ok], ctrl[ok], em[ok]
        if len(i) == 0:
            return False
        take = np.zeros(len(i), dtype=bool)
        last = -10
        for k in range(len(i)):  # (sorted by position: the first of overlapping triples)
            if i[k] - 1 > last:
                take[k] = True
                last = i[k] + 1
        i, ctrl, em = i[take], ctrl[take], em[take]
        B[i - 1] = B[i + 1]
        C[i - 1] = ctrl
        E[i - 1] = em
        isl[i - 1] = False
        keep = np.ones(len(A), dtype=bool)
        keep[i] = False
        keep[i + 1] = False
        self._store(A[keep], B[keep], C[keep], E[keep], isl[keep], fixed[keep])
        return True

    def _greedy_round(self) -> bool:
        """Chains of at least ``_GREEDY_MIN`` adjacent cubics meeting at smooth vertices
        (one tangent at the joint: no corner between them) are fitted again from the
        chain's start, each cubic reaching the farthest thinned point where one passes the
        same test (binary search over at most ``_GREEDY_SPAN`` old segments on; where none
        passes from an old joint, the old segment from there stays), and replaced where
        that takes fewer segments. The dichotomy splits a failing piece at the
        data's worst point, not at the design's joints, and the merge rounds only join
        neighbours: a chain of n design pieces could stay at n + 1 or more cubics, each
        joint a little off the design's. Reaching as far as possible each time takes the
        fewest pieces when a cubic that fits a range fits every range inside it. All
        chains are searched together (one :meth:`_try` per step); a chain stops as soon as
        it cannot end with fewer cubics than it had. True when something changed."""
        A, B, C, E, isl = self._all_segments()
        n = len(A)
        if n < _GREEDY_MIN:
            return False
        cub = ~isl
        smooth = (self.t_in[B[:-1]] == self.t_out[B[:-1]]).all(axis=1)
        adj = cub[:-1] & cub[1:] & (B[:-1] == A[1:]) & smooth
        head = np.r_[True, ~adj]  # a segment that starts a chain
        cid = np.cumsum(head) - 1
        size = np.bincount(cid)
        first = np.flatnonzero(head)
        last = first + size - 1
        pick = np.flatnonzero(size >= _GREEDY_MIN)
        if len(pick) == 0:
            return False
        old = size[pick]
        cur = A[first[pick]].copy()
        end = B[last[pick]]
        lastseg = last[pick]
        def cap(c, i):  # the farthest end tried from c: _GREEDY_SPAN old segments on
            cs = np.searchsorted(A, c, side="right") - 1
            return B[np.minimum(cs + _GREEDY_SPAN - 1, lastseg[i])]

        bnd = cap(cur, np.arange(len(cur)))
        lo = cur.copy()  # the farthest end found to pass from cur (cur: none yet)
        hi = bnd + 1  # the nearest end known to fail (bnd + 1: none)
        made = np.zeros(len(pick), dtype=np.intp)  # cubics finished so far
        live = np.ones(len(pick), dtype=bool)
        done = np.zeros(len(pick), dtype=bool)
        best_c = np.zeros((len(pick), 4, 2))
        best_e = np.zeros(len(pick))
        out_k: list[np.ndarray] = []
        out_a: list[np.ndarray] = []
        out_b: list[np.ndarray] = []
        out_c: list[np.ndarray] = []
        out_e: list[np.ndarray] = []
        while live.any():
            w = np.flatnonzero(live)
            # the first try of a cubic is its farthest end; then halve the bracket
            mid = np.where(hi[w] > bnd[w], bnd[w], (lo[w] + hi[w]) // 2)
            ok, ctrl, em = self._try(cur[w], mid)
            g = w[ok]
            lo[g] = mid[ok]
            best_c[g] = ctrl[ok]
            best_e[g] = em[ok]
            hi[w[~ok]] = mid[~ok]
            settled = w[(hi[w] - lo[w] <= 1) | (lo[w] == bnd[w])]
            if len(settled) == 0:
                continue
            none = settled[lo[settled] == cur[settled]]
            # no cubic from cur: the old segment starting there stays (else the chain)
            os_ = np.searchsorted(A, cur[none])
            has = (os_ < n) & (A[np.minimum(os_, n - 1)] == cur[none])
            live[none[~has]] = False
            none, os_ = none[has], os_[has]
            lo[none] = B[os_]
            best_c[none] = C[os_]
            best_e[none] = E[os_]
            s = settled[lo[settled] > cur[settled]]
            out_k.append(s)
            out_a.append(cur[s].copy())
            out_b.append(lo[s].copy())
            out_c.append(best_c[s].copy())
            out_e.append(best_e[s].copy())
            made[s] += 1
            fin = s[lo[s] == end[s]]
            done[fin] = made[fin] < old[fin]
            live[fin] = False
            go = s[lo[s] < end[s]]
            live[go[made[go] + 1 >= old[go]]] = False  # cannot end below the old count
            go = go[live[go]]
            cur[go] = lo[go]
            bnd[go] = cap(cur[go], go)
            hi[go] = bnd[go] + 1
        if not done.any():
            return False
        k = np.concatenate(out_k)
        keep_new = done[k]
        drop = np.isin(cid, pick[done])
        A2 = np.concatenate([A[~drop], np.concatenate(out_a)[keep_new]])
        B2 = np.concatenate([B[~drop], np.concatenate(out_b)[keep_new]])
        C2 = np.concatenate([C[~drop], np.concatenate(out_c)[keep_new]])
        E2 = np.concatenate([E[~drop], np.concatenate(out_e)[keep_new]])
        # (every segment of a chain, new or kept, is a cubic)
        L2 = np.concatenate([isl[~drop], np.zeros(int(keep_new.sum()), dtype=bool)])
        o = np.argsort(A2, kind="stable")
        self._store(A2[o], B2[o], C2[o], E2[o], L2[o])
        return True

    def _resplit_round(self, phase: int) -> bool:
        """Three adjacent segments (cubics, at most ``_RESPLIT_LINES`` lines, no line of the
        design: :meth:`_fixed_lines`) are replaced by two cubics where two pass the same
        test, split at one of up to ``_RESPLIT_CANDIDATES`` thinned points between them
        (evenly spread; the first in ``_RESPLIT_ORDER`` where both pass): the dichotomy
        split a chain of design pieces at the data's crossings, not at its joints, and
        rounding leaves short lines in curves. Non-overlapping triples (every third of a
        chain, from ``phase``); True when something changed."""
        A, B, C, E, isl = self._all_segments()
        if len(A) < 3:
            return False
        fixed = self._fixed_lines(A, B, isl)
        if self._triples is not None and self._triples[0] is A:  # (phases of one state)
            idx, pos = self._triples[1], self._triples[2]
        else:
            adj = B[:-1] == A[1:]
            nl = isl[:-2].astype(np.int8) + isl[1:-1] + isl[2:]
            tri = (adj[:-1] & adj[1:] & (nl <= _RESPLIT_LINES)
                   & ~fixed[:-2] & ~fixed[1:-1] & ~fixed[2:])
            idx = np.flatnonzero(tri)
            pos = _chain_phase(idx, 3)
            self._triples = (A, idx, pos)
        if len(idx) == 0:
            return False
        pick = idx[pos == phase]
        if len(pick) == 0:
            return False
        a0, d0 = A[pick], B[pick + 2]
        inner = d0 - a0 - 1  # thinned points strictly inside
        nc = np.minimum(inner, _RESPLIT_CANDIDATES)
        # candidates tried in turn (the middle one first), each triple until one passes;
        # the second cubic only where the first passed
        found = np.zeros(len(pick), dtype=bool)
        vv = np.zeros(len(pick), dtype=np.intp)
        cc1 = np.zeros((len(pick), 4, 2))
        cc2 = np.zeros((len(pick), 4, 2))
        ee1 = np.zeros(len(pick))
        ee2 = np.zeros(len(pick))
        for j in _RESPLIT_ORDER:
            g = np.flatnonzero(~found & (j < nc))
            if len(g) == 0:
                continue
            v = a0[g] + 1 + ((j + 0.5) * inner[g] / nc[g]).astype(np.intp)
            hope = self._screen(a0[g], v) & self._screen(v, d0[g])
            g, v = g[hope], v[hope]
            if len(g) == 0:
                continue
            ok1, c1, e1 = self._try(a0[g], v, screened=True)
            h = np.flatnonzero(ok1)
            if len(h) == 0:
                continue
            ok2, c2, e2 = self._try(v[h], d0[g[h]], screened=True)
            h = h[ok2]
            gh = g[h]
            found[gh] = True
            vv[gh] = v[h]
            cc1[gh] = c1[h]
            ee1[gh] = e1[h]
            cc2[gh] = c2[ok2]
            ee2[gh] = e2[ok2]
        if not found.any():
            return False
        grp = np.flatnonzero(found)
        t = pick[grp]
        c1, e1, c2, e2, v = cc1[grp], ee1[grp], cc2[grp], ee2[grp], vv[grp]
        # the triple t, t+1, t+2 becomes: t = a0..v, t+1 = v..d0, t+2 dropped
        B[t] = v
        C[t] = c1
        E[t] = e1
        A[t + 1] = v
        B[t + 1] = d0[grp]
        C[t + 1] = c2
        E[t + 1] = e2
        isl[t] = False
        isl[t + 1] = False
        keep = np.ones(len(A), dtype=bool)
        keep[t + 2] = False
        # (the triples held no design line: the others' stay as they were)
        self._store(A[keep], B[keep], C[keep], E[keep], isl[keep], fixed[keep])
        return True

    def _all_segments(self):
        """All segments so far, lines and cubics, sorted by start: (A, B, C, E, is_line)
        (a line's C and E are zeros). The rounds that change them write into these
        arrays, then :meth:`_store` them."""
        if self._all is not None and self._all_valid():
            return self._all[2]
        la = np.concatenate(self._lines) if self._lines else np.zeros(0, dtype=np.intp)
        cub = self._cubics
        nC = sum(len(c[0]) for c in cub)
        A = np.concatenate([la] + [c[0] for c in cub])
        B = np.concatenate([la + 1] + [c[1] for c in cub])
        C = np.concatenate([np.zeros((len(la), 4, 2))] + [c[2] for c in cub])
        E = np.concatenate([np.zeros(len(la))] + [c[3] for c in cub])
        isl = np.r_[np.ones(len(la), dtype=bool), np.zeros(nC, dtype=bool)]
        o = np.argsort(A, kind="stable")
        out = (A[o], B[o], C[o], E[o], isl[o])
        self._all = (self._lines, self._cubics, out, len(self._lines), len(self._cubics))
        self._all_fixed = None
        return out

    def _all_valid(self) -> bool:
        """The cached segments are still all of them (the lists are only appended to or
        replaced)."""
        if self._all is None:
            return False
        lines, cubics, _, n_lines, n_cubics = self._all
        return (self._lines is lines and self._cubics is cubics and len(lines) == n_lines
                and len(cubics) == n_cubics)

    def _store(self, A, B, C, E, isl, fixed: np.ndarray | None = None) -> None:
        """The segments (sorted by start, as :meth:`_all_segments` gives them) kept as the
        lines and cubics; the arrays themselves are what :meth:`_all_segments` returns next
        (the same values it would build: one segment per start, a line's B = A + 1 and its
        C, E zeros). ``fixed``: their :meth:`_fixed_lines` where known."""
        self._lines = [A[isl]]
        c = ~isl
        self._cubics = [(A[c], B[c], C[c], E[c])]
        self._all = (self._lines, self._cubics, (A, B, C, E, isl), 1, 1)
        self._all_fixed = fixed

    def _fixed_lines(self, A, B, isl) -> np.ndarray:
        """Rounded input: the lines with no input point between their ends, longer than
        ``_ABSORB_SHORT`` times the bound: lines of the design (a cubic over one could stray
        by the rounding), never merged into a cubic. (Cached for the stored segments.)"""
        cached = self._all is not None and self._all[2][0] is A and self._all_valid()
        if cached and self._all_fixed is not None:
            return self._all_fixed
        fixed = self._fixed_lines_of(A, B, isl)
        if cached:
            self._all_fixed = fixed
        return fixed

    def _fixed_lines_of(self, A, B, isl) -> np.ndarray:
        fixed = np.zeros(len(A), dtype=bool)
        if self.quant is not None:
            ch = self.q[B] - self.q[A]
            fixed = isl & (self.quant[A] > 0.0) & (self.kept[B] - self.kept[A] < 2) & (
                np.hypot(ch[:, 0], ch[:, 1]) > _ABSORB_SHORT * self.e_per[A])
        return fixed

    def _absorb_round(self, parity: int) -> bool:
        """Two adjacent segments (lines or cubics) at a vertex whose two tangents differ by
        less than ``_ABSORB_TURN`` (no corner of the design: rounding made the thinning
        leave a short segment or a length jump there, or the curve-run rules cut a smooth
        stretch) are merged into one cubic where one passes the same test. Non-overlapping
        pairs (every other pair of a chain, from ``parity``), one array pass; True when
        something merged."""
        A, B, C, E, isl = self._all_segments()
        if len(A) < 2:
            return False
        barely = self._barely_turning()
        fixed = self._fixed_lines(A, B, isl)
        if self._pairs is not None and self._pairs[0] is A:  # (both parities of one state)
            idx, pos = self._pairs[1], self._pairs[2]
        else:
            adj = ((B[:-1] == A[1:]) & ~fixed[:-1] & ~fixed[1:]
                   & barely[B[:-1]])
            idx = np.flatnonzero(adj)
            pos = _chain_phase(idx, 2)
            self._pairs = (A, idx, pos)
        if len(idx) == 0:
            return False
        pick = idx[pos == parity]
        if len(pick) == 0:
            return False
        ok, ctrl, em = self._try(A[pick], B[pick + 1])
        if not ok.any():
            return False
        i = pick[ok]
        B[i] = B[i + 1]
        C[i] = ctrl[ok]
        E[i] = em[ok]
        isl[i] = False
        keep = np.ones(len(A), dtype=bool)
        keep[i + 1] = False
        # (the merged segments were no design lines: the others' stay as they were)
        self._store(A[keep], B[keep], C[keep], E[keep], isl[keep], fixed[keep])
        return True

    def _try(self, A: np.ndarray, B: np.ndarray, screened: bool = False):
        """One cubic per piece A..B (no split): (passed, ctrl, bound) (:meth:`_try_full`).
        In the refined rounds (:meth:`_refined_rounds`) the ranges tried before are not
        fitted again: one that passed has its cubic back, one that failed is tried only by
        the refinement of its cached start (:meth:`_refine_cached`); a new range fails.
        ``screened``: every piece passed :meth:`_screen` (its coarse screening is not
        repeated)."""
        if self._starts is None:
            out = self._try_full(A, B, screened)
            if _REFINED_ROUNDS and self.quant is not None and out[0].any():
                p = out[0]
                self._pass_keys.append(self._range_keys(A[p], B[p]))
                self._pass_ctrl.append(out[1][p])
                self._pass_em.append(out[2][p])
            return out
        passed, ctrl_all, em_all, key = self._try_arrays(A, B)
        fresh = ~self._failed_before(key)
        if not fresh.all():
            self._refine_cached(A, key, fresh, passed, ctrl_all, em_all)
        pk, pc, pe = self._passes
        f = np.flatnonzero(fresh)
        if len(pk) and len(f):
            pos, hit = _sorted_find(pk, key[f])
            passed[f[hit]] = True
            ctrl_all[f[hit]] = pc[pos[hit]]
            em_all[f[hit]] = pe[pos[hit]]
        return passed, ctrl_all, em_all

    def _try_arrays(self, A: np.ndarray, B: np.ndarray):
        """:meth:`_try`'s empty answers for the pieces A..B (passed, control points, bound)
        and each range's cache key."""
        m = len(A)
        key = self._range_keys(A, B)
        return np.zeros(m, dtype=bool), np.zeros((m, 4, 2)), np.zeros(m), key

    def _try_full(self, A: np.ndarray, B: np.ndarray, screened: bool = False):
        """One cubic per piece A..B (no split): (passed, ctrl, bound) for the pieces whose
        end tangents meet (the others fail). ``screened``: as :meth:`_try`."""
        passed, ctrl_all, em_all, key = self._try_arrays(A, B)
        # a range that failed before fails again (same ends, tangents and points): skipped
        fresh = ~self._failed_before(key)
        ok, p0, qq, p3, sig = self._triangle(A, B)
        ok &= fresh
        w = np.flatnonzero(ok)
        if len(w) == 0:
            self._second_try(A, B, fresh, fresh, passed, ctrl_all, em_all)
            self._remember_failed(key[fresh & ~passed])
            return passed, ctrl_all, em_all
        a, b = A[w], B[w]
        i0, i1 = self.kept[a], self.kept[b]
        # a coarse cubic (few points, few steps) screens out the hopeless pieces (a loose
        # test: over twice the bound on a small sample) before the real one (:meth:`_screen`
        # did, where ``screened``: each piece's own numbers, the same verdicts)
        hope = np.ones(len(w), dtype=bool)
        if not screened:
            cc = self._dichotomy(p0[w], qq[w], p3[w], sig[w], i0, i1, _SCREEN_SAMPLE,
                                 _SCREEN_STEPS, 10.0 * self.eps_sum)
            hope = self._sample_ok(cc, i0, i1, _SCREEN_SLACK * self.e_per[a], _SCREEN_SAMPLE)
        if not hope.all():
            w, a, b, i0, i1 = w[hope], a[hope], b[hope], i0[hope], i1[hope]
            if len(w) == 0:
                self._second_try(A, B, fresh, fresh, passed, ctrl_all, em_all)
                self._remember_failed(key[fresh & ~passed])
                return passed, ctrl_all, em_all
        ctrl = self._dichotomy(p0[w], qq[w], p3[w], sig[w], i0, i1, _MERGE_SAMPLE)
        # screen on a sample of the points first: the full test only where it can pass
        # (not on rounded input: the least-squares cubic may pass where this fails)
        if self.quant is None:
            lk = self._sample_ok(ctrl, i0, i1, self.e_per[a])
        else:
            lk = self.quant[a] > 0.0
            ex = np.flatnonzero(~lk)
            if len(ex):
                lk[ex] = self._sample_ok(ctrl[ex], i0[ex], i1[ex], self.e_per[a[ex]])
        if not lk.any():
            self._second_try(A, B, fresh, fresh, passed, ctrl_all, em_all)
            self._remember_failed(key[fresh & ~passed])
            return passed, ctrl_all, em_all
        w, a, b, i0, i1, ctrl = w[lk], a[lk], b[lk], i0[lk], i1[lk], ctrl[lk]
        good, emax, dist, starts = self._accept(ctrl, i0, i1, self.e_per[a], a)
        if self.quant is not None:
            rq = np.flatnonzero((self.quant[a] > 0.0) & ~good)
            if len(rq):
                self._prefer_least_squares(rq, a, b, ctrl, good, emax, dist, starts)
        passed[w] = good
        ctrl_all[w] = ctrl
        em_all[w] = emax
        self._second_try(A, B, fresh, fresh, passed, ctrl_all, em_all)
        self._remember_failed(key[fresh & ~passed])
        return passed, ctrl_all, em_all

    def _cached_starts(self, key: np.ndarray) -> np.ndarray:
        """Per key: the index of its cached refinement start not refined yet, else -1."""
        assert self._starts is not None
        ks, _, used = self._starts
        out = np.full(len(key), -1, dtype=np.intp)
        if len(ks) == 0:
            return out
        pos, hit = _sorted_find(ks, key)
        hit &= ~used[pos]
        out[hit] = pos[hit]
        return out

    def _refine_cached(self, A, key, fresh, passed, ctrl_all, em_all) -> None:
        """The refined rounds: a range that failed before (its candidates fail again) is
        tried once more only by the refinement of its cached start, where that start is a
        near miss; in place."""
        assert self._starts is not None
        r = np.flatnonzero(~fresh)
        at = self._cached_starts(key[r])
        has = at >= 0
        r, at = r[has], at[has]
        if len(r) == 0:
            return
        _, sc, used = self._starts
        used[at] = True
        start = sc[at]
        a = A[r]
        i0, i1 = self.kept[a], self.kept[self._key_end(key[r])]
        near = self._sample_ok(start, i0, i1, _MINIMAX_NEAR * self.e_per[a])
        r, start, a, i0, i1 = r[near], start[near], a[near], i0[near], i1[near]
        if len(r) == 0:
            return
        cm, okm = minimax_cubics(self.work, self.arc, i0, i1, start, self.e_per[a])
        okm &= _handles_in_order(cm)
        r, cm, a, i0, i1 = r[okm], cm[okm], a[okm], i0[okm], i1[okm]
        if len(r) == 0:
            return
        g, e, _, _ = self._accept(cm, i0, i1, self.e_per[a], a)
        passed[r[g]] = True
        ctrl_all[r[g]] = cm[g]
        em_all[r[g]] = e[g]

    def _range_keys(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """One int64 key per range A..B of thinned points (the caches' keys)."""
        return A.astype(np.int64) * (len(self.kept) + 1) + B

    def _key_end(self, key: np.ndarray) -> np.ndarray:
        """The range end B of keys from :meth:`_range_keys`."""
        return (key % (len(self.kept) + 1)).astype(np.intp)

    def _second_try(self, A, B, fresh, ok, passed, ctrl_all, em_all) -> None:
        """:meth:`_try`'s exact pieces whose triangle cubic failed (no triangle, or at the
        screening or the test): the second candidate, in place."""
        sc = np.flatnonzero(fresh & ok & ~passed & self._exact(A))
        if len(sc):
            g2, c2, e2 = self._second_candidate(A[sc], B[sc])
            passed[sc[g2]] = True
            ctrl_all[sc[g2]] = c2[g2]
            em_all[sc[g2]] = e2[g2]

    def _screen(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """Per piece A..B: False where :meth:`_try` will not be tried in earnest (the
        triangle does not exist, the range failed before, or the coarse screening cubic
        misses by over ``_SCREEN_SLACK`` times the bound); True otherwise."""
        key = self._range_keys(A, B)
        if self._starts is not None:  # (the refined rounds: :meth:`_try` decides cheaply)
            return np.ones(len(A), dtype=bool)
        hope = ~self._failed_before(key)
        ok, p0, qq, p3, sig = self._triangle(A, B)
        hope &= ok
        w = np.flatnonzero(hope)
        if len(w) == 0:
            return hope
        a = A[w]
        i0, i1 = self.kept[a], self.kept[B[w]]
        cc = self._dichotomy(p0[w], qq[w], p3[w], sig[w], i0, i1, _SCREEN_SAMPLE,
                             _SCREEN_STEPS, 10.0 * self.eps_sum)
        hope[w] = self._sample_ok(cc, i0, i1, _SCREEN_SLACK * self.e_per[a], _SCREEN_SAMPLE)
        return hope

    def _failed_before(self, keys: np.ndarray) -> np.ndarray:
        """np.isin(keys, self._failed) by binary search (the failed keys are sorted and
        unique: :meth:`_remember_failed` keeps them so)."""
        f = self._failed
        if len(f) == 0:
            return np.zeros(len(keys), dtype=bool)
        return _sorted_find(f, keys)[1]

    def _remember_failed(self, keys: np.ndarray) -> None:
        if len(keys):
            new = np.unique(keys)
            new = new[~self._failed_before(new)]
            if len(new):  # (two sorted runs: the stable sort merges them)
                self._failed = np.sort(np.concatenate([self._failed, new]), kind="stable")

    def _sample_ok(self, ctrl, i0, i1, e2, sample: int = _BISECT_SAMPLE // 2) -> np.ndarray:
        """Per piece: every point of a sample (at most ``_BISECT_SAMPLE`` // 2, evenly
        strided) within ``e2`` of the cubic (Newton from arc length; a cheap necessary
        condition of :meth:`_accept`, up to Newton's local minima)."""
        ok = np.empty(len(ctrl), dtype=bool)
        cm = power_coeffs_many(ctrl)
        i0 = np.ascontiguousarray(i0, dtype=np.intp)
        i1 = np.ascontiguousarray(i1, dtype=np.intp)
        e2 = np.ascontiguousarray(e2, dtype=np.float64)

        def chunk(lo: int, hi: int) -> None:
            _sample_kernel(cm[lo:hi], i0[lo:hi], i1[lo:hi], self.work, self.arc, e2[lo:hi],
                           sample, ok[lo:hi])

        run_chunks(chunk, _sampled_weights(i0, i1, sample))
        return ok

    def _merge_round(self) -> bool:
        """Two accepted cubics meeting at a smooth vertex (shared tangent) are replaced by
        one cubic over both pieces where one passes the same test (the split that made them
        was at the data's crossing, not at a joint of the design). Non-overlapping pairs,
        one array pass; True when something merged."""
        if len(self._cubics) == 0:
            return False
        A = np.concatenate([c[0] for c in self._cubics])
        B = np.concatenate([c[1] for c in self._cubics])
        C = np.concatenate([c[2] for c in self._cubics])
        E = np.concatenate([c[3] for c in self._cubics])
        o = np.argsort(A, kind="stable")
        A, B, C, E = A[o], B[o], C[o], E[o]
        adj = (B[:-1] == A[1:]) & (self.t_in[B[:-1]] == self.t_out[B[:-1]]).all(axis=1)
        if not adj.any():
            self._cubics = [(A, B, C, E)]
            return False
        # non-overlapping: in every chain of adjacent pairs, every other pair
        idx = np.flatnonzero(adj)
        brk = np.r_[True, idx[1:] != idx[:-1] + 1]
        chain_start = np.maximum.accumulate(np.where(brk, np.arange(len(idx)), 0))
        pick = idx[(np.arange(len(idx)) - chain_start) % 2 == 0]
        ok, ctrl, em = self._try(A[pick], B[pick + 1])
        if not ok.any():
            self._cubics = [(A, B, C, E)]
            return False
        i = pick[ok]
        B[i] = B[i + 1]
        C[i] = ctrl[ok]
        E[i] = em[ok]
        keep = np.ones(len(A), dtype=bool)
        keep[i + 1] = False
        self._cubics = [(A[keep], B[keep], C[keep], E[keep])]
        return True

    def _least_squares(self, A: np.ndarray, B: np.ndarray, i0: np.ndarray, i1: np.ndarray):
        """Per piece: the cubic with the piece's end points and end tangents whose two
        handle lengths minimise the squared distances of (a sample of) its input points at
        their parameters (chord length, then twice the nearest point's), Schneider's
        fit; (ctrl (m, 4, 2), ok (m,): positive handles no longer than twice the chord).
        Compiled, one piece at a time (:func:`_ls_kernel`)."""
        m = len(A)
        p0, p3 = self.q[A], self.q[B]
        chord = np.hypot(*(p3 - p0).T)
        ctrl = np.empty((m, 4, 2))
        ok = np.empty(m, dtype=bool)
        j0, j1 = (np.ascontiguousarray(a, dtype=np.intp) for a in (i0, i1))
        f0, f3, g0, g3 = (np.ascontiguousarray(a, dtype=np.float64)
                          for a in (p0, p3, self.t_out[A], self.t_in[B]))

        def chunk(lo: int, hi: int) -> None:
            _ls_kernel(j0[lo:hi], j1[lo:hi], self.work, self.arc, _BISECT_SAMPLE, f0[lo:hi],
                       f3[lo:hi], g0[lo:hi], g3[lo:hi], chord[lo:hi], ctrl[lo:hi], ok[lo:hi])

        run_chunks(chunk, _sampled_weights(j0, j1, _BISECT_SAMPLE) * 3)
        return ctrl, ok

    def _gauss_newton(self, A: np.ndarray, B: np.ndarray, i0: np.ndarray, i1: np.ndarray,
                      rounds: int = _GN_ROUNDS):
        """Per piece: the cubic with the piece's end points and end tangents whose two
        handle lengths minimise the squared distances of (a sample of) its input points to
        the curve, by Gauss-Newton on the distances along the curve's normal at each
        point's nearest point (tangent-distance minimisation). Schneider's alternation
        (:meth:`_least_squares`: handles for fixed parameters, then new parameters) creeps
        towards that minimum (a design cubic sampled exactly, handles 102 / 81: still 91 /
        92 after 50 rounds); this reaches it in 3. Returns (ctrl (m, 4, 2), ok (m,):
        positive handles no longer than twice the chord). Compiled, one piece at a time
        (:func:`_gn_kernel`)."""
        m = len(A)
        p0, p3 = self.q[A], self.q[B]
        chord = np.hypot(*(p3 - p0).T)
        ctrl = np.empty((m, 4, 2))
        ok = np.empty(m, dtype=bool)
        j0, j1 = (np.ascontiguousarray(a, dtype=np.intp) for a in (i0, i1))
        f0, f3, g0, g3 = (np.ascontiguousarray(a, dtype=np.float64)
                          for a in (p0, p3, self.t_out[A], self.t_in[B]))

        def chunk(lo: int, hi: int) -> None:
            _gn_kernel(j0[lo:hi], j1[lo:hi], self.work, self.arc, _BISECT_SAMPLE, f0[lo:hi],
                       f3[lo:hi], g0[lo:hi], g3[lo:hi], chord[lo:hi], rounds, ctrl[lo:hi],
                       ok[lo:hi])

        run_chunks(chunk, _sampled_weights(j0, j1, _BISECT_SAMPLE) * (rounds + 1))
        return ctrl, ok

    def _bulging_segments(self, ab: np.ndarray, line: np.ndarray) -> np.ndarray:
        """Rounded input: the one-segment pieces (``line``) whose input points bulge to one
        side of the segment (mean signed distance over a fifth of the quantum, at least 4
        points between: a curve stretch, not a rounded straight line) and that a
        least-squares cubic with the end tangents fits within the bound; those cubics are
        accepted here. Returns the mask of such pieces (over ``ab``)."""
        out = np.zeros(len(ab), dtype=bool)
        assert self.quant is not None  # only called on rounded input
        cand = np.flatnonzero(line & (self.quant[ab[:, 0]] > 0.0))
        if len(cand) == 0:
            return out
        A, B = ab[cand, 0], ab[cand, 1]
        i0, i1 = self.kept[A], self.kept[B]
        enough = i1 - i0 - 1 >= 4
        cand, A, B, i0, i1 = cand[enough], A[enough], B[enough], i0[enough], i1[enough]
        if len(cand) == 0:
            return out
        own, off = _ragged(np.zeros(len(A), dtype=np.intp), i1 - i0 - 1)
        idx = i0[own] + 1 + off
        p0, p3 = self.q[A], self.q[B]
        ch = p3 - p0
        ln = np.hypot(ch[:, 0], ch[:, 1])
        ln = np.where(ln > 0, ln, 1.0)
        rel = self.work[idx] - p0[own]
        sd = (rel[:, 0] * ch[own, 1] - rel[:, 1] * ch[own, 0]) / ln[own]
        mean = np.bincount(own, sd, len(A)) / np.bincount(own, minlength=len(A))
        bulge = np.abs(mean) > 0.2 * self.quant[A]
        if not bulge.any():
            return out
        cand, A, B, i0, i1 = cand[bulge], A[bulge], B[bulge], i0[bulge], i1[bulge]
        cl, okl = self._least_squares(A, B, i0, i1)
        passed = np.zeros(len(A), dtype=bool)
        if okl.any():
            g, e, _, _ = self._accept(cl[okl], i0[okl], i1[okl], self.e_per[A[okl]], A[okl])
            sel = np.flatnonzero(okl)[g]
            self._cubics.append((A[sel], B[sel], cl[sel], e[g]))
            passed[sel] = True
        # where the least-squares cubic misses (its largest error is not what it minimises),
        # the dichotomy's balanced cubic may pass
        rest = np.flatnonzero(~passed)
        if len(rest):
            g2, c2, e2 = self._try(A[rest], B[rest])
            sel2 = rest[g2]
            self._cubics.append((A[sel2], B[sel2], c2[g2], e2[g2]))
            passed[sel2] = True
        out[cand[passed]] = True
        return out

    def _gauss_newton_free(self, A, B, i0, i1, ctrl, rounds: int = _GN_ROUNDS):
        """Rounded input: from ``ctrl`` (:meth:`_gauss_newton`), both inner control points
        free (the end tangents too: they are estimates from rounded points), Gauss-Newton on
        the normal distances; ok where each end tangent turned at most ``_GN_TURN``."""
        i0 = np.ascontiguousarray(i0, dtype=np.intp)
        i1 = np.ascontiguousarray(i1, dtype=np.intp)
        L = i1 - i0 - 1
        cnt = -(-L // np.maximum(1, -(-L // _BISECT_SAMPLE)))
        ps = np.r_[0, np.cumsum(cnt)]
        ctrl = np.array(ctrl, dtype=np.float64)
        chord = np.hypot(*(ctrl[:, 3] - ctrl[:, 0]).T)
        u = np.empty(int(ps[-1]))
        pts = np.empty((len(u), 2))

        def chunk(lo: int, hi: int) -> None:
            # (every piece's rounds on its own: a chunk of pieces runs all of them)
            c = ctrl[lo:hi]
            N = np.empty((hi - lo, 4, 4))
            g = np.empty((hi - lo, 4, 1))
            with np.errstate(divide="ignore", invalid="ignore"):
                for it in range(rounds):
                    _gn_free_sums(i0[lo:hi], i1[lo:hi], self.work, self.arc, _BISECT_SAMPLE,
                                  ps[lo:hi + 1], pts, u, c, it == 0, N, g)
                    d = np.linalg.solve(N, g)
                    _gn_free_step(c, d, chord[lo:hi])

        run_chunks(chunk, cnt * rounds)
        h0 = ctrl[:, 1] - ctrl[:, 0]
        h3 = ctrl[:, 3] - ctrl[:, 2]
        t0, t3 = self.t_out[A], self.t_in[B]
        n0 = np.hypot(*h0.T)
        n3 = np.hypot(*h3.T)
        cos_turn = math.cos(_GN_TURN)
        with np.errstate(divide="ignore", invalid="ignore"):
            ok = ((h0 * t0).sum(1) >= cos_turn * n0) & ((h3 * t3).sum(1) >= cos_turn * n3)
        ok &= (n0 > 0) & (n3 > 0) & (n0 < 2.0 * chord) & (n3 < 2.0 * chord)
        ok &= np.isfinite(ctrl).all(axis=(1, 2))
        return ctrl, ok

    def _second_candidate(self, A: np.ndarray, B: np.ndarray):
        """Per piece A..B (its triangle cubic failed): (passed, ctrl, bound) of the
        Gauss-Newton cubic (:meth:`_gauss_newton`: two free handle lengths; the paper's
        family has one shared fraction t, so a design cubic whose handles are different
        fractions of its triangle is not in it), under the same test (:meth:`_accept`),
        screened on a sample of the points first."""
        m = len(A)
        passed = np.zeros(m, dtype=bool)
        ctrl_all = np.zeros((m, 4, 2))
        em_all = np.zeros(m)
        if m == 0:
            return passed, ctrl_all, em_all
        i0, i1 = self.kept[A], self.kept[B]
        cg, okg = self._gauss_newton(A, B, i0, i1)
        okg &= _handles_in_order(cg)
        w = np.flatnonzero(okg)
        if len(w):
            w = w[self._sample_ok(cg[w], i0[w], i1[w], self.e_per[A[w]])]
        if len(w):
            g, e, _, _ = self._accept(cg[w], i0[w], i1[w], self.e_per[A[w]], A[w])
            w = w[g]
            passed[w] = True
            ctrl_all[w] = cg[w]
            em_all[w] = e[g]
        if _GN_FREE and self.quant is not None:
            v = np.flatnonzero(okg & ~passed & (self.quant[A] > 0.0))
            if len(v):
                cf_, okf = self._gauss_newton_free(A[v], B[v], i0[v], i1[v], cg[v])
                okf &= _handles_in_order(cf_)
                # (the minimax refinement's starts: the free cubic, else the other)
                free_v, free_c = v, np.where(okf[:, None, None], cf_, cg[v])
                v, cf_ = v[okf], cf_[okf]
                if len(v):
                    sk = self._sample_ok(cf_, i0[v], i1[v], self.e_per[A[v]])
                    v, cf_ = v[sk], cf_[sk]
                if len(v):
                    g, e, _, _ = self._accept(cf_, i0[v], i1[v], self.e_per[A[v]], A[v])
                    passed[v[g]] = True
                    ctrl_all[v[g]] = cf_[g]
                    em_all[v[g]] = e[g]
                if _REFINED_ROUNDS and len(free_v):
                    rest = ~passed[free_v]
                    fv = free_v[rest]
                    self._start_keys.append(self._range_keys(A[fv], B[fv]))
                    self._start_ctrl.append(free_c[rest])
        return passed, ctrl_all, em_all

    def _exact(self, A: np.ndarray) -> np.ndarray:
        """Per piece starting at thinned point A: True on exact input (no rounding) and on
        rounded input whose rounding is a fair share of the bound (``_MOVE_SHARE``)."""
        if self.quant is None:
            return np.ones(len(A), dtype=bool)
        # (as the vertices' moves onto the design: the bound here is e_per + q/√2)
        q = self.quant[A]
        sl = q * _HALF_DIAGONAL
        return (q == 0.0) | ((q > 0.0) & (sl >= _MOVE_SHARE * (self.e_per[A] - sl)))

    def _prefer_least_squares(self, rq, A, B, ctrl, good, emax, dist, starts) -> None:
        """Rounded input: where the least-squares cubic (:meth:`_least_squares`) passes the
        same acceptance test, it replaces the dichotomy's (it follows the middle of the
        rounding noise, not just its signed balance), in place; a piece the dichotomy
        failed that the least-squares cubic passes is accepted."""
        a, b = A[rq], B[rq]
        i0, i1 = self.kept[a], self.kept[b]
        cl, okl = self._least_squares(a, b, i0, i1)
        if not okl.any():
            return
        sel = rq[okl]
        g2, e2, d2, s2 = self._accept(cl[okl], i0[okl], i1[okl], self.e_per[a[okl]], a[okl])
        use = sel[g2]
        ctrl[use] = cl[okl][g2]
        emax[use] = e2[g2]
        good[use] = True
        # the failed pieces keep the dichotomy's errors for choosing their split point

    def results(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(a, b, ctrl, bound, line_a)``: the accepted cubics (thinned index ranges a..b,
        control points (C, 4, 2), an upper bound of each one's largest input-point error)
        and the pieces that ended as lines (line_a .. line_a + 1)."""
        cub = self._cubics
        line_a = np.concatenate(self._lines) if self._lines else np.zeros(0, dtype=np.intp)
        if not cub:
            e = np.zeros(0, dtype=np.intp)
            return e, e, np.zeros((0, 4, 2)), np.zeros(0), line_a
        return (
            np.concatenate([c[0] for c in cub]),
            np.concatenate([c[1] for c in cub]),
            np.concatenate([c[2] for c in cub]),
            np.concatenate([c[3] for c in cub]),
            line_a,
        )

    def _split_points(
        self, A: np.ndarray, B: np.ndarray, dist: np.ndarray, starts: np.ndarray
    ) -> np.ndarray:
        """Where to split each failed piece A..B (thinned indices): the interior thinned
        point with the smallest error (``dist``, the piece's input points from ``starts``)
        in the middle 60 % of the piece by input index (the crossing of data and curve),
        the first such point on ties; else, and for pieces of <= 3 segments, the middle."""
        k = (A + B) // 2
        big = np.flatnonzero(B - A > 3)
        if len(big) == 0:
            return k
        a, b = A[big], B[big]
        i0, i1 = self.kept[a], self.kept[b]
        own, off = _ragged(a, b - a - 1)
        kk = self.kept[a[own] + 1 + off]
        frac = (kk - i0[own]) / np.maximum(1, i1 - i0)[own]
        mid = (frac >= 0.2) & (frac <= 0.8)
        err = dist[starts[big][own] + kk - i0[own]]
        gmin = np.full(len(big), np.inf)
        np.minimum.at(gmin, own[mid], err[mid])  # NaN wins, as in argmin
        g = gmin[own]
        cand = np.flatnonzero(mid & ((err == g) | (np.isnan(err) & np.isnan(g))))
        grp, first = np.unique(own[cand], return_index=True)
        k[big[grp]] = a[grp] + 1 + off[cand[first]]
        return k


def fit_path(
    points: object,
    *,
    closed: bool,
    eps_line: float = DEFAULT_EPS_LINE,
    e_per: float = DEFAULT_E_PER,
    eps_sum: float = DEFAULT_EPS_SUM,
    source_index: int = 0,
    pen: int = 1,
    quantum_units: float | None = None,
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
        quantum_units=None if quantum_units is None else [quantum_units],
    )[0]


def fit_paths(
    paths: Sequence[object],
    closed: Sequence[bool],
    *,
    eps_line: float = DEFAULT_EPS_LINE,
    e_per: float = DEFAULT_E_PER,
    eps_sum: float = DEFAULT_EPS_SUM,
    source_indices: Sequence[int] | None = None,
    pens: Sequence[int] | None = None,
    quantum_units: float | Sequence[float] | np.ndarray | None = None,
) -> list[FittedPath]:
    """:func:`fit_path` for many paths at once (the same result as one call per path).

    Every stage runs for all paths together on their concatenated points: the thinning
    (:func:`galvo_core.thin.thin_many`), the curve runs and their pieces
    (:func:`galvo_core.runs.split_pieces_many`), the fit of every curve piece (one
    :class:`_BatchFitter`; pieces never cross a path), the errors of all lines and the exact
    errors of the cubics that decide a path's ``max_error``. The fixed cost per path is a
    few Python operations (building its segments), not a few hundred array calls.

    ``quantum_units``: the grid the points were rounded to (input units; one value for all
    paths or one per path; 0 for exact input). Default: detected from each path's points
    (:func:`galvo_core.precision.path_quanta`). The bounds are then ``eps_line`` and
    ``e_per`` beyond the rounding (see :func:`rounding_slack`).
    """
    eps_line, e_per, eps_sum = _check_params(eps_line, e_per, eps_sum)
    npth = len(paths)
    if len(closed) != npth:
        raise ValueError("fit_paths: one closed flag per path")
    src = list(range(npth)) if source_indices is None else [int(i) for i in source_indices]
    pen = [1] * npth if pens is None else [int(p) for p in pens]
    cl = [bool(c) for c in closed]
    works, ns = _closed_works(paths, cl)
    slack = rounding_slack(works, quantum_units)
    wlen = np.fromiter(map(len, works), dtype=np.intp, count=npth)
    # a path of two distinct points (most paths of a nesting file) is its line, with no
    # error: built directly, not thinned nor fitted (the same result)
    two = np.zeros(npth, dtype=bool)
    i2 = np.flatnonzero(wlen == 2)
    if len(i2):
        p2 = np.stack([works[k] for k in i2.tolist()])
        d2 = (p2[:, 0] != p2[:, 1]).any(axis=1)
        two[i2[d2]] = True
        pts2 = _read_only(p2[d2])
    if two.any():
        rest = np.flatnonzero(~two).tolist()
        kept_rest = thin_many([works[k] for k in rest], eps_line,
                              per_path=(eps_line + slack)[rest])
        kept_all = [_KEPT_TWO] * npth
        for j, k in enumerate(rest):
            kept_all[k] = kept_rest[j]
    else:
        kept_all = thin_many(works, eps_line, per_path=eps_line + slack)
    klen = np.fromiter(map(len, kept_all), dtype=np.intp, count=npth)
    out: list[FittedPath | None] = [None] * npth
    mk = FittedPath.from_arrays
    todo = np.flatnonzero((wlen > 0) & (klen != 1) & ~two)
    if len(todo):
        rounding = np.stack([eps_line + slack[todo], slack[todo] / _HALF_DIAGONAL], axis=1)
        is_cubic, points, first, last, seg_cut, pt_cut, worst = _fit_concatenated(
            works, kept_all, todo, cl, e_per + slack[todo], eps_sum, rounding)
    with gc_paused():  # one object per path (and its array views), no cycles
        for k in np.flatnonzero(klen == 1).tolist():  # a dot: all points equal
            out[k] = mk(src[k], pen[k], cl[k], _DOT_KIND, _read_only(works[k][[0, 0]]),
                        _ZERO_FIRST, _read_only(np.array([len(works[k]) - 1], dtype=np.int64)),
                        0.0, ns[k], 1)
        for k in np.flatnonzero(wlen == 0).tolist():
            out[k] = FittedPath(src[k], pen[k], cl[k], (), 0.0, 0, 0)
        k2 = np.flatnonzero(two)
        if len(k2):
            for t, k in enumerate(k2.tolist()):
                out[k] = _new_fitted(src[k], pen[k], cl[k], _DOT_KIND, pts2[t], _ZERO_FIRST,
                                     _ONE_LAST, 0.0, ns[k], 2)
        if len(todo):
            kl = klen.tolist()
            for t, k in enumerate(todo.tolist()):
                a, b = seg_cut[t], seg_cut[t + 1]
                out[k] = _new_fitted(src[k], pen[k], cl[k], is_cubic[a:b],
                                     points[pt_cut[t]:pt_cut[t + 1]], first[a:b], last[a:b],
                                     worst[t], ns[k], kl[k])
    return out  # type: ignore[return-value]


def rounding_slack(
    paths: Sequence[object], quantum_units: float | Sequence[float] | np.ndarray | None = None
) -> np.ndarray:
    """Per path: how far the design may lie from an input point, ``q / √2`` (the rounding
    square's half diagonal) for the path's quantum ``q`` (``quantum_units``: one value, one
    per path, or None to detect each path's from its points). The fit's bounds on a path
    are ``eps_line + slack`` and ``e_per + slack`` from the input points and polyline, i.e.
    ``eps_line`` / ``e_per`` beyond the rounding; exactly the user's values when q is 0."""
    n = len(paths)
    if quantum_units is None:
        q = path_quanta(paths)
    else:
        q = np.broadcast_to(np.asarray(quantum_units, dtype=np.float64).reshape(-1), (n,))
        if not (np.isfinite(q) & (q >= 0.0)).all():
            raise ParamError(f"quantum_units must be finite numbers >= 0, got {quantum_units!r}")
    return q * _HALF_DIAGONAL


def _closed_works(
    paths: Sequence[object], closed: list[bool]
) -> tuple[list[np.ndarray], list[int]]:
    """The paths as float (N, 2) arrays, a closed path whose last point differs from its
    first with that point appended, and their input point counts N; non-finite
    coordinates refused (ParamError)."""
    works = [np.asarray(p, dtype=np.float64).reshape(-1, 2) for p in paths]
    n = np.array([len(w) for w in works], dtype=np.intp)
    if not works:
        return works, []
    allp = np.concatenate(works)
    if not np.isfinite(allp).all():
        raise ParamError("points must be finite numbers (found NaN or infinity)")
    last = np.cumsum(n) - 1
    cand = np.flatnonzero(np.asarray(closed, dtype=bool) & (n >= 2))
    open_ends = cand[(allp[last[cand] - n[cand] + 1] != allp[last[cand]]).any(axis=1)]
    for k in open_ends.tolist():
        works[k] = np.vstack([works[k], works[k][:1]])
    return works, n.tolist()


def _coarse_chords(W: np.ndarray, starts: np.ndarray, lens: np.ndarray,
                   quanta: np.ndarray) -> np.ndarray:
    """Per input segment W[k] -> W[k + 1] (the last entry False): True where it is a chord
    of a coarsely flattened curve rather than a line of the design. Rounded input only:
    the paths W[starts[i]:starts[i] + lens[i]] whose quantum ``quanta[i]`` is over 0.

    Typeface outlines and most CAD exports flatten curves finely, so an input segment over
    ``_LONG_SEGMENT`` quanta is a line of the design, and a curve beside it may use only
    part of the rounding slack (:func:`_accept_pairs`) and never swallow it
    (:meth:`_BatchFitter._fixed_lines`). Files that flatten curves coarsely (chords of tens
    or hundreds of units, each a few degrees from the next: engraving spoolers, old
    plotter drivers) write long chords whose design is the curve bulging beside them, by
    up to the whole bound: a curve beside such a chord may use all the slack. A long
    segment is such a chord where at one of its ends it meets a segment of similar length
    (within ``_COARSE_RATIO``) at a turn that is gentle (under ``_ABSORB_TURN``) yet more
    than the rounding can make of a straight line (over ``_COARSE_NOISE`` quanta across the
    shorter of the two). (A chord left as a line is still not absorbed into a cubic: trying
    that on every chord of a noisy coarse walk doubled the fit's time on the generated
    1 M-point file for 0.6 % fewer segments.)"""
    out = np.zeros(len(W), dtype=np.bool_)
    _coarse_kernel(np.ascontiguousarray(W, dtype=np.float64),
                   np.ascontiguousarray(starts, dtype=np.intp),
                   np.ascontiguousarray(lens, dtype=np.intp),
                   np.ascontiguousarray(quanta, dtype=np.float64), out)
    return out


@njit(cache=True, nogil=True)
def _coarse_kernel(W, starts, lens, quanta, out) -> None:  # pragma: no cover (compiled)
    """:func:`_coarse_chords` (compiled): one pass per path over its segments."""
    for i in range(len(starts)):
        q = quanta[i]
        if not q > 0.0:
            continue
        s = starts[i]
        e = s + lens[i] - 1  # the path's segments: s .. e - 1
        for k in range(s, e):
            dx = W[k + 1, 0] - W[k, 0]
            dy = W[k + 1, 1] - W[k, 1]
            ln = math.sqrt(dx * dx + dy * dy)
            if not ln > _LONG_SEGMENT * q:
                continue
            for j in (k - 1, k + 1):  # the neighbour at its start, at its end
                if j < s or j >= e:
                    continue
                ex = W[j + 1, 0] - W[j, 0]
                ey = W[j + 1, 1] - W[j, 1]
                lj = math.sqrt(ex * ex + ey * ey)
                lo = min(ln, lj)
                hi = max(ln, lj)
                if not (lo > 0.0 and hi <= _COARSE_RATIO * lo):
                    continue
                turn = abs(math.atan2(dx * ey - dy * ex, dx * ex + dy * ey))
                if turn < _ABSORB_TURN and turn * lo > _COARSE_NOISE * q:
                    out[k] = True
                    break


def _fit_concatenated(
    works: list[np.ndarray],
    kept_all: list[np.ndarray],
    todo: np.ndarray,
    closed: list[bool],
    e_per: np.ndarray,
    eps_sum: float,
    rounding: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[int], list[int],
           list[float]]:
    """Segments and max_error of the paths ``todo`` (>= 2 thinned points each), all at once
    on the concatenation of every path's points (global indices below). Returns, over all
    those paths in order, the segment kinds (is_cubic), the shared control points, the
    first/last input indices (each path's own), the cuts of each path's segments and
    points in those arrays (len(todo) + 1 each) and each path's max_error."""
    wlen = np.array([len(w) for w in works], dtype=np.intp)
    woff = np.cumsum(wlen) - wlen
    klen = np.array([len(k) for k in kept_all], dtype=np.intp)
    W = np.concatenate(works) if len(works) > 1 else works[0]
    K = np.concatenate(kept_all).astype(np.intp, copy=False) + np.repeat(woff, klen)
    in_todo = np.zeros(len(works), dtype=bool)
    in_todo[todo] = True
    K = K[np.repeat(in_todo, klen)]
    tlen = klen[todo]
    coarse = None
    wstep = _step_lengths(W)  # (once: the passes below all read it)
    if rounding is not None and (rounding[:, 1] > 0.0).any():
        coarse = _coarse_chords(W, woff[todo], wlen[todo], rounding[:, 1])
        K, tlen = _gap_ends_kept(W, K, tlen, rounding[:, 1], rounding[:, 0], coarse, wstep)
    arc = _arc_per_path(W, wlen, wstep)
    move_q = None
    if rounding is not None:
        # the vertices move onto the design where the rounding is a fair share of the bound
        slack = rounding[:, 1] * _HALF_DIAGONAL
        move_q = np.where(slack >= _MOVE_SHARE * (e_per - slack), rounding[:, 1], 0.0)
    closed_t = np.asarray(closed)[todo]
    Q = W[K]
    pa, pb, curve, t_in, t_out, smooth = split_pieces_many(
        Q, tlen, closed_t, rounding=rounding, return_smooth=True, steps=np.diff(K, append=0)
    )
    if move_q is not None and (move_q > 0.0).any():
        assert rounding is not None  # (move_q comes from it)
        Q = Q.copy()
        found: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        _on_the_design(W, K, Q, arc, t_in, t_out, smooth, np.repeat(move_q, tlen), tlen,
                       np.repeat(rounding[:, 0], tlen), found, coarse, wstep)
        if found and len(found[0][0]):
            # corners the thinning kept beside the design's: their input points kept instead
            # (or too), and those paths' pieces split again
            K2, tlen2, touched = _corners_kept_right(W, K, tlen, *found[0],
                                                     np.repeat(rounding[:, 0], tlen))
            if touched.any():
                K, tlen, Q, pa, pb, curve, t_in, t_out, smooth = _split_again(
                    W, arc, K, tlen, K2, tlen2, touched, Q, pa, pb, t_in, t_out, smooth,
                    closed_t, rounding, move_q, coarse, wstep)
    kend = np.cumsum(tlen) - 1  # each path's last thinned point
    is_kend = np.zeros(len(Q), dtype=bool)
    is_kend[kend] = True
    fitter = _BatchFitter(W, K, t_in, t_out, np.repeat(e_per, tlen), eps_sum, arc, q=Q)
    if rounding is not None and (rounding[:, 1] > 0.0).any():
        fitter.quant = np.repeat(rounding[:, 1], tlen)
        assert coarse is not None  # (set above with the same condition)
        fitter.coarse = coarse
    with np.errstate(invalid="ignore", divide="ignore"):
        fitter.fit(np.stack([pa[curve], pb[curve]], axis=1), pa[~curve])
    ca, cb, ctrl, bound, fla = fitter.results()
    if move_q is not None and (move_q > 0.0).any():
        assert rounding is not None  # (move_q comes from it)
        ca, cb, ctrl, bound, fla = _lone_lines_out(
            W, K, Q, arc, t_in, t_out, np.repeat(e_per, tlen), eps_sum,
            np.repeat(move_q, tlen), np.repeat(rounding[:, 0], tlen), ca, cb, ctrl, bound, fla,
            coarse=fitter.coarse, wstep=wstep, line_pieces=pa[~curve])
    la = fla
    lb = la + 1
    owner = np.repeat(np.arange(len(todo)), tlen)  # thinned index -> position in todo
    o_w = woff[todo]
    end_w = o_w + wlen[todo] - 1  # each path's last input point (trailing repeats included)
    # line points (read-only views of one array) and their true max error
    lpts = np.stack([Q[la], Q[lb]], axis=1)
    lfirst = K[la]
    llast = np.where(is_kend[lb], end_w[owner[lb]], K[lb])
    lerr = _line_errors(W, lpts, lfirst, llast)
    lkey = 3 * la
    if rounding is not None:
        la, lpts, lfirst, llast, lerr, lkey = _valid_lines(
            W, K, Q, la, lb, lpts, lfirst, llast, lerr, np.repeat(rounding[:, 0], tlen)
        )
        assert move_q is not None  # set with rounding above
        for _ in range(_BULGE_ROUNDS if bool((move_q > 0.0).any()) else 0):
            la, lpts, lfirst, llast, lerr, lkey, more = _split_bulging_lines(
                W, arc, la, lpts, lfirst, llast, lerr, lkey, np.repeat(move_q, tlen),
                np.repeat(rounding[:, 0], tlen))
            if not more:
                break
        if _GAP_JOINTS and fitter.coarse is not None:
            for _ in range(_GAP_SPLITS):
                la, lpts, lfirst, llast, lerr, lkey, more = _split_gap_joints(
                    W, la, lpts, lfirst, llast, lerr, lkey, np.repeat(rounding[:, 1], tlen),
                    np.repeat(rounding[:, 0], tlen), fitter.coarse, woff, wlen)
                if not more:
                    break
    lpts.setflags(write=False)
    worst = np.zeros(len(todo))
    np.fmax.at(worst, owner[la], lerr)  # NaN (overflow) ignored, as max() did
    # cubics: a segment ending at the path's last thinned point takes its trailing repeats
    ctrl = np.ascontiguousarray(ctrl)
    ctrl.setflags(write=False)
    cfirst = K[ca]
    clast = np.where(is_kend[cb], end_w[owner[cb]], K[cb])
    if len(ca):
        worst = _cubic_worst(W, ctrl, cfirst, clast, bound, owner[ca], worst)
    # all segments in path order, as arrays: kinds, shared control points (each path's
    # start, then per segment its points after the start), replaced input point ranges
    seg_a = np.concatenate([la, ca])
    order = np.argsort(np.concatenate([lkey, 3 * ca]), kind="stable")
    nl = len(la)
    is_cubic = order >= nl
    seg_owner = owner[seg_a[order]]
    first = np.concatenate([lfirst, cfirst])[order] - o_w[seg_owner]
    last = np.concatenate([llast, clast])[order] - o_w[seg_owner]
    seg_cut = np.searchsorted(seg_owner, np.arange(len(todo) + 1))
    step = np.where(is_cubic, 3, 1)
    tail = np.cumsum(step) - step + seg_owner + 1  # row of each segment's point after P0
    points = np.empty((int(step.sum()) + len(todo), 2))
    fs = seg_cut[:-1]  # each path's first segment (every path here has one)
    fl = fs[~is_cubic[fs]]
    points[tail[fl] - 1] = lpts[order[fl], 0]
    fc = fs[is_cubic[fs]]
    points[tail[fc] - 1] = ctrl[order[fc] - nl, 0]
    lrow = np.flatnonzero(~is_cubic)
    points[tail[lrow]] = lpts[order[lrow], 1]
    crow = np.flatnonzero(is_cubic)
    cidx = order[crow] - nl
    for j in range(3):
        points[tail[crow] + j] = ctrl[cidx, j + 1]
    pt_cut = np.r_[0, np.cumsum(np.bincount(seg_owner, weights=step, minlength=len(todo))
                                .astype(np.int64) + 1)]
    if move_q is not None and (move_q > 0.0).any():
        gf = first + o_w[seg_owner]
        gl = last + o_w[seg_owner]
        assert rounding is not None  # move_q is set with rounding
        bound = np.minimum(e_per, rounding[:, 0])
        changed = _joints_on_the_design(W, arc, points, is_cubic, tail, step, gf, gl,
                                        seg_owner, move_q, bound, wstep)
        is_cubic, points, tail, step, gf, gl, seg_owner, changed = _smooth_stretches(
            W, arc, points, is_cubic, tail, step, gf, gl, seg_owner, move_q, bound, changed)
        is_cubic, points, tail, step, gf, gl, seg_owner, changed = _connectors_out(
            W, points, is_cubic, tail, step, gf, gl, seg_owner, move_q, bound, changed, wstep)
        is_cubic, points, tail, step, gf, gl, seg_owner, changed = _tips_joined(
            W, points, is_cubic, tail, step, gf, gl, seg_owner, move_q, bound, changed, wstep,
            arc)
        if changed.any():
            worst = _changed_errors(W, points, is_cubic, tail, gf, gl, seg_owner, changed,
                                    worst)
        worst = _moved_ends_error(W, points, is_cubic, tail, step, gf, gl, seg_owner, worst)
        first = gf - o_w[seg_owner]
        last = gl - o_w[seg_owner]
        seg_cut = np.searchsorted(seg_owner, np.arange(len(todo) + 1))
        pt_cut = np.r_[0, np.cumsum(np.bincount(seg_owner, weights=step, minlength=len(todo))
                                    .astype(np.int64) + 1)]
    for x in (is_cubic, points, first, last):
        x.setflags(write=False)
    return is_cubic, points, first, last, seg_cut.tolist(), pt_cut.tolist(), worst.tolist()


#: rounded input: the ends of a gap of at least ``_LONE_LENGTH`` quanta between two input
#: points (a design line written as its two rounded ends) inside a thinned segment are kept
#: as thinned points where some input point of that segment lies this many quanta or more off
#: the gap's line (the segment holds a curve's end beside the line)
_GAP_OFF = 0.75
#: ... and that is at least this many times as long as the input steps beside it
_GAP_RATIO = 3.0
#: ... and the rest of the segment at least this many input steps (a curve's dense end: a
#: polyline's few short strokes beside a long one are lines of the design, and one thinned
#: line within the bound serves them; vk2bea tektronix.hpgl: 761 -> 957 segments without)
_GAP_REST = 5
#: ... or at least this many (as long as that many quanta or line bounds), each at most
#: ``_GAP_SHORT_STEP`` quanta long, where an input point of the rest lies ``_GAP_SHORT_OFF``
#: quanta or more off the gap's line (the curve after a design line bends away at once: URW
#: Z003 "3" at em 2048, a 59-unit line meeting a curve at 15 degrees, two of the curve's
#: steps taken into the line, 0.80 from the design where the rounded input is 0.23; not a
#: polyline's strokes, nor a scaled file's jitter at a corner: lectra_astm_test.hpgl,
#: tektronix.hpgl the same)
_GAP_SHORT_REST = 2
_GAP_SHORT_OFF = 0.6
_GAP_SHORT_STEP = 3.0
#: ... and where that rest is no line within the bound, it is split at its farthest input
#: point up to this many times (each piece a line within the bound) or the gap's end is not kept
_GAP_SPLITS = 2


def _gap_ends_kept(W, K, tlen, quanta, eps, coarse, wstep=None):
    """Rounded input (``quanta`` per path, 0: exact): ``K`` (the thinned points, global
    indices, each path's in order; ``tlen`` per path) with the ends of each long gap
    (``_LONE_LENGTH``; not a chord of a coarse curve, ``coarse``) added where the thinning
    left one of them inside a thinned segment (the gap at its other end) that also holds
    points off the gap's line (``_GAP_OFF``; or a few dense steps of which one lies
    ``_GAP_SHORT_OFF`` off, ``_GAP_SHORT_REST``), the gap at least ``_GAP_RATIO`` times the
    input step beside it inside the segment, and the rest of the segment within ``eps`` (per path,
    the line bound) of its chord, or of the chords of its pieces where it is split at its
    farthest input points (``_GAP_SPLITS``; those points are kept too): the thinning keeps a
    curve's end and the design line after it in one segment where they are nearly collinear,
    and the curve piece then swallows the line (a cubic through its two rounded ends may bulge
    over it by the rounding; Cantarell "a" at em 1500: 0.75 from the design where the rounded
    input is 0.5). ``wstep``: the step lengths of W (:func:`_step_lengths`) where known.
    Returns (K, tlen)."""
    q_k = np.repeat(quanta, tlen)
    eps_k = np.repeat(eps, tlen)
    if len(K) < 2 or not (q_k > 0.0).any():
        return K, tlen
    qmin = float(quanta[quanta > 0.0].min())
    lo, hi = int(K[0]), int(K[-1])
    d = np.diff(W[lo:hi + 1], axis=0)
    g = np.flatnonzero(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] >= (_LONE_LENGTH * qmin) ** 2) + lo
    if len(g) == 0:
        return K, tlen
    g = g[~coarse[g]]
    seg = np.searchsorted(K, g, side="right") - 1  # the thinned segment K[seg]..K[seg + 1]
    last = np.cumsum(tlen) - 1
    ok = (seg >= 0) & (seg < len(K) - 1)
    seg = np.clip(seg, 0, len(K) - 2)
    ok &= ~np.isin(seg, last)  # not across two paths
    ok &= (K[seg] != g) | (K[seg + 1] != g + 1)  # not a thinned segment already
    g, seg = g[ok], seg[ok]
    # the gap's end kept: g + 1 where the gap starts the segment (its rest after the gap), g
    # where it ends it (its rest before); a gap inside the segment (a design line between two
    # curves' ends, all three nearly collinear) is tried at both of its ends, each with the
    # rest on its side (NimbusRoman-Italic "U" at em 2048: a 104-unit line between two gently
    # curved stretches, one 480-unit thinned line over all three, 0.97 from the design where
    # the rounded input is 0.46)
    inside = (K[seg] != g) & (K[seg + 1] != g + 1)
    g = np.concatenate([g, g[inside]])
    seg = np.concatenate([seg, seg[inside]])
    after = np.concatenate([K[seg[:len(inside)]] == g[:len(inside)],
                            np.ones(int(inside.sum()), dtype=bool)])
    q = q_k[seg]
    ok = (q > 0.0) & (np.hypot(*(W[g + 1] - W[g]).T) >= _LONE_LENGTH * q)
    # ... a design line beside dense points: at least _GAP_RATIO times the input step beside
    # it inside the thinned segment (a walk of long steps, each like the next, has no such
    # gap; the step on its other side may be another design line: serif-bolditalic "Q" at em
    # 400, a 30-unit line after a 49-unit one, its cubic 0.66 from the design where the
    # rounded input is 0.48)
    nb = np.where(after, np.hypot(*(W[np.minimum(g + 2, len(W) - 1)] - W[g + 1]).T),
                  np.hypot(*(W[np.maximum(g - 1, 0)] - W[g]).T))
    ok &= np.hypot(*(W[g + 1] - W[g]).T) >= _GAP_RATIO * nb
    g, seg, q, after = g[ok], seg[ok], q[ok], after[ok]
    if len(g) == 0:
        return K, tlen
    a, b = K[seg], K[seg + 1]
    own, off = _ragged(np.arange(len(g)), b - a + 1)
    e = W[g + 1] - W[g]
    e = e / np.hypot(e[:, 0], e[:, 1])[:, None]
    r = W[a[own] + off] - W[g][own]
    across = np.abs(r[:, 0] * e[own, 1] - r[:, 1] * e[own, 0])
    top = np.maximum.reduceat(across, np.cumsum(b - a + 1) - (b - a + 1))
    rest = np.where(after, b - g - 1, g - a)  # the input steps of the rest
    far = (top >= _GAP_OFF * q) & (rest >= _GAP_REST)
    # ... or a short rest (_GAP_SHORT_REST) of a dense curve's steps bending away from the
    # line by more than the rounding's noise (_GAP_SHORT_OFF)
    short = (rest >= _GAP_SHORT_REST) & (top >= _GAP_SHORT_OFF * q) & ~far
    if short.any():
        # ... its input steps all dense (_GAP_SHORT_STEP quanta at most: a finely flattened
        # curve's, not a polyline's strokes)
        sh = np.flatnonzero(short)
        _, _, sl, at = _range_steps(_step_lengths(W) if wstep is None else wstep,
                                    np.where(after, g + 1, a)[sh], np.where(after, b, g)[sh])
        # (and as long as that many quanta or line bounds, the larger: repeated points are no
        # steps, and a scaled file's jitter at a polyline's corner is far shorter than its
        # bound: vk2bea tektronix.hpgl, q 0.0056, the bound 0.024)
        far[sh] = (np.maximum.reduceat(sl, at) <= _GAP_SHORT_STEP * q[sh]) & (
            np.add.reduceat(sl, at) >= _GAP_SHORT_REST * np.maximum(q, eps_k[seg])[sh])
    if not far.any():
        return K, tlen
    # the point kept: the gap's end inside the segment; the rest of the segment, a line from
    # its other end to that point, must still hold its input points within eps (the thinning's
    # promise for the whole segment)
    g, seg, a, b, after = g[far], seg[far], a[far], b[far], after[far]
    v = np.where(after, g + 1, g)
    r0 = np.where(after, v, a)
    r1 = np.where(after, b, v)
    err = _line_errors(W, np.stack([W[r0], W[r1]], axis=1), r0, r1)
    held = err <= eps_k[seg]
    # ... or, where it does not (the curve's end bends away from the chord), the rest split
    # at its farthest input point, up to _GAP_SPLITS times (Douglas-Peucker): each piece then
    # holds the bound (Cantarell "a" at em 1500: a curve's last 12 points beside a 48-unit
    # design line; its cubic bulged 0.25 over the line's rounded chord, 0.75 from the design)
    extra: list[np.ndarray] = []
    todo = np.flatnonzero(~held)
    pa, pb, own = r0[todo], r1[todo], todo
    for _ in range(_GAP_SPLITS if len(todo) else 0):
        cnt = pb - pa - 1
        has = cnt > 0
        pa, pb, own, cnt = pa[has], pb[has], own[has], cnt[has]
        if len(pa) == 0:
            break
        o2, off = _ragged(np.arange(len(pa)), cnt)
        idx = pa[o2] + 1 + off
        d = point_segment_distance(W[idx], W[pa][o2], W[pb][o2])
        st = np.cumsum(cnt) - cnt
        dm = np.maximum.reduceat(d, st)
        bad = dm > eps_k[seg[own]]
        if not bad.any():
            break
        # the farthest point (the first of equal ones) of each failing piece
        at = np.flatnonzero(d >= dm[o2])
        at = at[np.r_[True, o2[at][1:] != o2[at][:-1]]]
        m = idx[at][bad[o2[at]]]
        pa, pb, own = pa[bad], pb[bad], own[bad]
        extra.append(np.stack([own, m], axis=1))
        pa, pb, own = np.concatenate([pa, m]), np.concatenate([m, pb]), np.concatenate([own, own])
    if len(pa):
        # pieces still over the bound after the last split: that gap's end is not kept
        cnt = pb - pa - 1
        e2 = _line_errors(W, np.stack([W[pa], W[pb]], axis=1), pa, pb)
        fail = np.unique(own[(cnt > 0) & (e2 > eps_k[seg[own]])])
    else:
        fail = np.zeros(0, dtype=np.intp)
    ok2 = np.zeros(len(v), dtype=bool)
    ok2[todo] = True
    ok2[fail] = False
    # ... and where the splits at the farthest points leave a piece over the bound (a curve's
    # end whose farthest point is next to the gap each time), the rest thinned on its own:
    # every piece a line within the bound (NimbusRoman-Italic "l" at em 1000: a curve's 37
    # points beside a 598-unit design line, the gap's end 0.67 off the thinned segment, on
    # the design)
    more = [e[ok2[e[:, 0]], 1] for e in extra]
    for f in fail.tolist():
        a0, a1 = int(r0[f]), int(r1[f])
        e_f = float(eps_k[seg[f]])
        t = thin(W[a0:a1 + 1], e_f).astype(np.intp) + a0
        if len(t) >= 2 and t[0] == a0 and t[-1] == a1 and (_line_errors(
                W, np.stack([W[t[:-1]], W[t[1:]]], axis=1), t[:-1], t[1:]) <= e_f).all():
            ok2[f] = True
            more.append(t[1:-1])
    keep = held | ok2
    add = np.setdiff1d(np.concatenate([v[keep]] + more), K)
    # every thinned segment beside an added point keeps within eps of its input points (the
    # thinning's promise; a gap inside a segment has the segment's rest beyond its other end
    # too, which the tests above do not see: Z003 Medium Italic "I" at em 2048, a kept gap
    # end left a 28-point line 1.03 off its points, over the stated bound): an added point
    # beside a segment that misses it is dropped, until none does
    while len(add):
        K2 = np.sort(np.concatenate([K, add]))
        pth = np.searchsorted(last, np.searchsorted(K, K2, side="right") - 1)
        isadd = np.isin(K2, add)
        i = np.flatnonzero((isadd[:-1] | isadd[1:]) & (pth[:-1] == pth[1:]))
        err = _line_errors(W, np.stack([W[K2[i]], W[K2[i + 1]]], axis=1), K2[i], K2[i + 1])
        miss = i[err > eps[pth[i]]]
        if len(miss) == 0:
            break
        add = np.setdiff1d(add, np.concatenate([K2[miss], K2[miss + 1]]))
    if len(add) == 0:
        return K, tlen
    # (K2: K with add, from the last round above)
    path = np.searchsorted(last, np.searchsorted(K, add) - 1)  # (the segment's start's path)
    return K2, tlen + np.bincount(path, minlength=len(tlen))


def _corners_kept_right(W, K, tlen, v, j, both, eps):
    """Rounded input: ``K`` (the thinned points, global indices; ``tlen`` per path) with the
    input point ``j`` kept for the corner at thinned index ``v`` (:func:`_misplaced_corners`:
    the design's corner lies at ``j``, beside ``K[v]``, inside one of the two thinned segments
    at ``v``), while every thinned segment stays a line within ``eps`` (per thinned point) of
    its input points (the thinning's promise): ``K[v]`` is replaced by ``j`` where the
    segment from the neighbour across ``K[v]`` to ``j`` holds that bound; else that segment
    is split at its farthest input point (not next to ``j``) where both parts hold it; else
    ``K[v]`` is kept too where ``both`` (per pair) allows it. Nothing changes where the
    segment from ``j`` to the neighbour on its
    own side misses the bound. Returns (K, tlen, the paths changed (bool per path))."""
    n = len(K)
    last = np.cumsum(tlen) - 1
    path = np.searchsorted(last, np.arange(n))
    drop, add = [], []  # (thinned points dropped, input points added)
    done = np.zeros(n + 1, dtype=bool)

    def valid(a: int, b: int, e: float) -> bool:
        return bool(_line_errors(W, W[[a, b]][None], np.array([a]), np.array([b]))[0] <= e)

    for vv, jj, bb in zip(v.tolist(), j.tolist(), both.tolist(), strict=True):
        if done[vv] or done[vv - 1] or done[vv + 1]:
            continue  # (a neighbour's segments already changed)
        k = int(K[vv])
        e = float(eps[vv])
        # the neighbour across k (its segment then spans k) and the one on j's side
        across, own = (int(K[vv - 1]), int(K[vv + 1])) if jj > k else (int(K[vv + 1]),
                                                                        int(K[vv - 1]))
        lo, hi = min(jj, own), max(jj, own)
        if not valid(lo, hi, e):
            continue
        lo, hi = min(across, jj), max(across, jj)
        if valid(lo, hi, e):
            drop.append(k)
            add.append(jj)
        else:
            # (split near its middle, away from both ends: a corner's neighbours are short
            # segments the curve-run rules take for rounding)
            mid = (lo + hi) // 2
            ms = [m for m in (mid, mid + 1, mid - 1, mid + 2, mid - 2)
                  if min(m - lo, hi - m) > _MISPLACED_STEPS]
            m = next((m for m in ms if valid(lo, m, e) and valid(m, hi, e)), -1)
            if m >= 0:
                drop.append(k)
                add += [jj, m]
            elif bb and valid(min(k, jj), max(k, jj), e):
                add.append(jj)
            else:
                continue
        done[vv] = True
    touched = np.zeros(len(tlen), dtype=bool)
    if not add:
        return K, tlen, touched
    touched[path[np.flatnonzero(done[:n])]] = True
    keep = ~np.isin(K, np.array(drop, dtype=K.dtype))
    Kd = K[keep]
    pd = path[keep]
    a = np.array(add, dtype=K.dtype)
    # (each added point's path: that of the thinned segment it lies in)
    pa = pd[np.clip(np.searchsorted(Kd, a) - 1, 0, len(Kd) - 1)]
    order = np.argsort(np.concatenate([Kd, a]), kind="stable")
    K2 = np.concatenate([Kd, a])[order]
    cnt = np.bincount(np.concatenate([pd, pa]), minlength=len(tlen))
    return K2, cnt.astype(tlen.dtype), touched


def _split_again(W, arc, K, tlen, K2, tlen2, touched, Q, pa, pb, t_in, t_out, smooth,
                 closed, rounding, move_q, coarse, wstep=None):
    """The pieces, tangents, smooth flags and moved vertices (:func:`_on_the_design`) of the
    thinned points ``K2`` (``tlen2`` per path), where only the paths ``touched`` differ from
    ``K`` (``tlen``), whose results ``Q``, ``pa``, ``pb``, ``t_in``, ``t_out``, ``smooth`` are
    kept for the other paths (each path's are its own: the same numbers as all paths again).
    Returns (K2, tlen2, Q, pa, pb, curve, t_in, t_out, smooth)."""
    P = np.flatnonzero(touched)
    sel = np.repeat(touched, tlen2)
    Ks = K2[sel]
    ts = tlen2[P]
    Qs = W[Ks]
    sa, sb, _, si, so, ss = split_pieces_many(Qs, ts, closed[P], rounding=rounding[P],
                                              return_smooth=True, steps=np.diff(Ks, append=0))
    Qs = Qs.copy()
    _on_the_design(W, Ks, Qs, arc, si, so, ss, np.repeat(move_q[P], ts), ts,
                   np.repeat(rounding[P, 0], ts), None, coarse, wstep)
    # per thinned point: the old rows of the other paths, the new rows of the touched ones
    src = np.empty(len(K2), dtype=np.intp)
    src[~sel] = np.flatnonzero(~np.repeat(touched, tlen))
    src[sel] = len(K) + np.arange(len(Ks))
    Q2 = np.concatenate([Q, Qs])[src]
    ti2 = np.concatenate([t_in, si])[src]
    to2 = np.concatenate([t_out, so])[src]
    sm2 = np.concatenate([smooth, ss])[src]
    # the pieces (thinned index ranges), moved to the new numbering, in order
    o_old = np.cumsum(tlen) - tlen
    o_new = np.cumsum(tlen2) - tlen2
    o_sub = np.cumsum(ts) - ts
    pp = np.searchsorted(np.cumsum(tlen) - 1, pa)
    kp = ~touched[pp]
    sh = (o_new - o_old)[pp[kp]]
    ps = np.searchsorted(np.cumsum(ts) - 1, sa)
    shs = o_new[P[ps]] - o_sub[ps]
    a = np.concatenate([pa[kp] + sh, sa + shs])
    b = np.concatenate([pb[kp] + sh, sb + shs])
    order = np.argsort(a, kind="stable")
    a, b = a[order], b[order]
    return K2, tlen2, Q2, a, b, b - a >= 2, ti2, to2, sm2


#: rounded input: a cubic's end segment (thinned) with a gap between two of its input
#: points of at least ``_LONE_LENGTH`` quanta and this share of the segment's length (a
#: design line, written as its two rounded ends) ...
_LONE_SHARE = 0.5
#: ... over which the cubic strays this many quanta or more from the gap's chord (the design
#: line is within q/sqrt(2) of that chord: a cubic held only by the bound may end up the
#: rounding's width on the other side of it), is re-fitted without that segment, which
#: becomes a line (the cubic's tangent there the line's direction)
_LONE_BULGE = 0.3
#: ... or this many where that segment is the gap's one input step alone (the line then
#: holds no other input points: P052 Bold Italic "r" at em 2048, a 149-unit design line,
#: the cubic 0.298 off the chord and 0.77 off the design; with any segment, 0.15-0.2 broke
#: NimbusRoman-Italic "w", a segment holding a curve's points beside the gap)
_LONE_BULGE_GAP = 0.2
#: ... the cubic sampled at this many parameters
_LONE_SAMPLES = 65
#: ... and replaced where the re-fit of the rest takes at most this many segments (serif-italic
#: "R" at em 400: the rest of a cubic over a 44-unit design line needed a cubic and a line)
_LONE_REFIT = 2
_LONE_BASIS = seed_basis(_LONE_SAMPLES - 1)[1]
#: ... and a line piece of the curve-run rules between two of a cubic's segments (the fitter's
#: merge rounds took it in) holding a long gap, the cubic straying ``_LONE_BULGE`` quanta from
#: its chord, is made a line too, the cubic's two rests re-fitted apart
_LONE_MIDDLE = True
#: ... and so is a cubic's end segment that is a line piece of the curve-run rules at least
#: this many quanta long, its three or more input points collinear (``_collinear``) with a
#: step between them of ``_LONE_ROW_STEP`` quanta or more (a design line written as a row of
#: rounded points with no gap of ``_LONE_LENGTH``: Z003 Medium Italic "l" at em 1000, a
#: 16-unit row of ten points with a 6-unit step, one cubic over it and the curve after it
#: 0.70 from the design where the rounded input is on it; a curve's flat stretch, densely
#: flattened, is a row of unit steps and stays)
_LONE_ROW = 8.0
_LONE_ROW_STEP = 3.0


def _lone_lines_out(W, K, Q, arc, t_in, t_out, e_per, eps_sum, quant, eps, ca, cb, ctrl,
                    bound, la, coarse=None, wstep=None, line_pieces=None):
    """Rounded input (``quant`` per thinned point, 0: not moved): the cubics that swallow a
    design line at one of their ends (``_LONE_SHARE``, ``_LONE_BULGE``, ``_LONE_BULGE_GAP``;
    a long gap, or a row of collinear points, ``_LONE_ROW``) or between two of their segments
    (``_LONE_MIDDLE``) are re-fitted over their other
    segments, that segment made a line (there, only a line piece of the curve-run rules,
    ``line_pieces``: their first thinned indices, that the fitter's merge rounds took into a
    cubic). Returns (ca, cb, ctrl, bound, la) with those cubics replaced; ``t_in``, ``t_out``
    changed in place at the new joints. ``coarse``: the fitter's chords of coarse curves
    (:func:`_coarse_chords`), for the re-fit."""
    if len(ca) == 0:
        return ca, cb, ctrl, bound, la
    q = quant[ca]
    cand = (q > 0.0) & (cb - ca >= 2)
    if not cand.any():
        return ca, cb, ctrl, bound, la
    step = np.r_[_step_lengths(W) if wstep is None else wstep, 0.0]
    # the gaps long enough for any path (few: a design line's two rounded ends), not the
    # chords of a coarsely flattened curve (no design lines)
    long_ = step >= _LONE_LENGTH * float(q[cand].min())
    if coarse is not None:
        long_ &= ~coarse
    big = np.flatnonzero(long_)
    # the line pieces inside candidate cubics that are rows of collinear input points
    row = np.zeros(len(K), dtype=bool)
    if _LONE_ROW and line_pieces is not None and len(line_pieces):
        inc = np.zeros(len(K) + 1, dtype=np.intp)
        np.add.at(inc, ca[cand], 1)
        np.add.at(inc, cb[cand], -1)
        j = np.asarray(line_pieces, dtype=np.intp)
        j = j[(np.cumsum(inc)[j] > 0) & (j + 1 < len(K))]
        j = j[(K[j + 1] - K[j] >= 2) & (quant[j] > 0.0)]
        d = W[K[j + 1]] - W[K[j]]
        ln = np.hypot(d[:, 0], d[:, 1])
        long_row = ln >= _LONE_ROW * quant[j]
        j, d, ln = j[long_row], d[long_row], ln[long_row]
        if len(j):
            col = _collinear(W, K[j], K[j + 1], W[K[j]], d / ln[:, None], quant[j])
            _, _, sl, at = _range_steps(step, K[j], K[j + 1])
            row[j[col & (np.maximum.reduceat(sl, at) >= _LONE_ROW_STEP * quant[j])]] = True
    if len(big) == 0 and not row.any():
        return ca, cb, ctrl, bound, la

    def longest(lo, hi):
        # the longest gap in each range big[lo:hi] (the first of equal ones)
        return np.array([big[a + int(np.argmax(step[big[a:b]]))] for a, b in
                         zip(lo.tolist(), hi.tolist(), strict=True)], dtype=np.intp)

    def swallowed(u, r):
        # per cubic r: its segment u..u+1 (thinned) holds a long gap that the cubic bulges
        # over
        ok = np.zeros(len(ca), dtype=bool)
        ku, kv = K[u[r]], K[u[r] + 1]
        lo = np.searchsorted(big, ku)
        hi = np.searchsorted(big, kv)
        has = (hi > lo) | row[u[r]]
        r, ku, kv, lo, hi = r[has], ku[has], kv[has], lo[has], hi[has]
        if len(r) == 0:
            return ok
        g = np.zeros(len(r), dtype=np.intp)
        hg = hi > lo
        g[hg] = longest(lo[hg], hi[hg])
        d = W[kv] - W[ku]
        ln = np.hypot(d[:, 0], d[:, 1])
        inner = (u[r] > ca[r]) & (u[r] + 1 < cb[r])
        # (a segment between two of the cubic's, a line piece: the curve-run rules found it
        # a line whatever the share of its long gap)
        gap = hg & (step[g] >= _LONE_LENGTH * q[r]) & (inner | (step[g] >= _LONE_SHARE * ln))
        seg = inner | ~gap
        keep = gap | row[u[r]]
        r, g, seg, ku, kv, gap = r[keep], g[keep], seg[keep], ku[keep], kv[keep], gap[keep]
        if len(r) == 0:
            return ok
        # the chord: the gap's, or the segment's where it lies between two of the cubic's
        # or is a row
        a0 = np.where(seg[:, None], Q[u[r]], W[g])
        a1 = np.where(seg[:, None], Q[u[r] + 1], W[g + 1])
        e = a1 - a0
        e2 = (e * e).sum(axis=1)
        rel = np.einsum("tj,cjd->ctd", _LONE_BASIS, ctrl[r]) - a0[:, None, :]
        s = (rel * e[:, None, :]).sum(axis=2) / e2[:, None]
        perp = np.abs(rel[:, :, 0] * e[:, None, 1] - rel[:, :, 1] * e[:, None, 0])
        perp /= np.sqrt(e2)[:, None]
        inside = (s > 0.05) & (s < 0.95)
        bul = np.where(inside, perp, 0.0).max(axis=1)
        # (a smaller bulge where the segment is the gap alone: made a line, it holds no
        # other points)
        lim = np.where(gap & (kv - ku == 1), _LONE_BULGE_GAP, _LONE_BULGE)
        r = r[bul >= lim * q[r]]
        # ... where the line between the segment's (moved) ends holds its input points
        ur = u[r]
        err = _line_errors(W, np.stack([Q[ur], Q[ur + 1]], axis=1), K[ur], K[ur + 1])
        ok[r[err <= eps[ur]]] = True
        return ok

    rc = np.flatnonzero(cand)
    ce = swallowed(cb - 1, rc)
    cs = swallowed(ca, rc) & ((cb - ca - ce) >= 2)
    # ... or a design line between two of the cubic's segments (Z003 Medium Italic "l" at em
    # 2048: a 37-unit line written as three rounded points between two dense curves, one
    # cubic over all three 0.76 from the design where the rounded input is 0.42)
    mid = np.full(len(ca), -1, dtype=np.intp)
    cm = np.zeros(len(ca), dtype=bool)
    if _LONE_MIDDLE and line_pieces is not None and len(line_pieces):
        rm = np.flatnonzero(cand & ~ce & ~cs & (cb - ca >= 3))
        lo = np.searchsorted(big, K[ca[rm]])
        hi = np.searchsorted(big, K[cb[rm]])
        rm, lo, hi = rm[hi > lo], lo[hi > lo], hi[hi > lo]
        if len(rm):
            mid[rm] = np.searchsorted(K, longest(lo, hi), side="right") - 1
            rm = rm[(mid[rm] > ca[rm]) & (mid[rm] + 1 < cb[rm])]
            # (a line piece between two curve pieces: a curve run's own segment, the cubic
            # over its smooth joints, may place a design line better than its rounded ends)
            rm = rm[np.isin(mid[rm], line_pieces)]
            cm = swallowed(mid, rm)
    fix = ce | cs | cm
    if not fix.any():
        return ca, cb, ctrl, bound, la
    fi = np.flatnonzero(fix)
    # each fixed cubic's rests (one, or two either side of a middle line), in path order;
    # ``ro`` the cubic each rest belongs to
    na = np.concatenate([(ca + cs)[fi], (mid + 1)[fi[cm[fi]]]])
    nb = np.concatenate([np.where(cm, mid, cb - ce)[fi], cb[fi[cm[fi]]]])
    ro = np.concatenate([fi, fi[cm[fi]]])
    o = np.argsort(na, kind="stable")
    na, nb, ro = na[o], nb[o], ro[o]
    # the re-fit with the tangents at the new joints made the lines' directions (on a copy:
    # a re-fit that does not hold leaves the cubic and its tangents as they were)
    lines = np.concatenate([(cb - 1)[ce], ca[cs], mid[cm]])  # the segments made lines
    lc = np.concatenate([np.flatnonzero(ce), np.flatnonzero(cs), np.flatnonzero(cm)])  # cubics
    # the new joints (a middle line has two), each with its line and cubic
    joints = np.concatenate([(cb - 1)[ce], (ca + 1)[cs], mid[cm], (mid + 1)[cm]])
    jl = np.concatenate([lines, mid[cm]])
    jo = np.concatenate([lc, np.flatnonzero(cm)])
    ti2, to2 = t_in.copy(), t_out.copy()
    d = Q[jl + 1] - Q[jl]
    t = d / np.hypot(d[:, 0], d[:, 1])[:, None]
    ti2[joints] = t
    to2[joints] = t
    one = nb - na == 1
    f2 = _BatchFitter(W, K, ti2, to2, e_per, eps_sum, arc, q=Q)
    f2.quant = quant
    if coarse is not None:
        f2.coarse = coarse
    with np.errstate(invalid="ignore", divide="ignore"):
        f2.fit(np.stack([na[~one], nb[~one]], axis=1), None)
    a3, b3, c3, bd3, l3 = f2.results()
    # per rest: the re-fit holds where its segments (at most _LONE_REFIT of them, cubics and
    # lines) cover exactly that rest (or the one segment left a line); per cubic, where all
    # of its rests hold. (The re-fit's own merge rounds may join two neighbouring rests: such
    # a cubic lies in neither, and both cubics stay as they were.)
    pos = np.flatnonzero(~one)
    sa = np.concatenate([a3, l3]).astype(np.intp)
    sb = np.concatenate([b3, l3 + 1]).astype(np.intp)
    pc = np.searchsorted(na[pos], sa, side="right") - 1  # the rest each one starts in
    inside = (pc >= 0) & (sb <= nb[pos][np.maximum(pc, 0)])
    pc = np.where(inside, pc, len(pos))
    cover = np.bincount(pc, weights=sb - sa, minlength=len(pos) + 1)[:len(pos)]
    count = np.bincount(pc, minlength=len(pos) + 1)[:len(pos)]
    good = one.copy()
    good[pos] = (cover == (nb - na)[pos]) & (count <= _LONE_REFIT)
    bad = np.zeros(len(ca), dtype=bool)
    bad[ro[~good]] = True
    fix &= ~bad
    if not fix.any():
        return ca, cb, ctrl, bound, la
    took_j = fix[jo]
    t_in[joints[took_j]] = ti2[joints[took_j]]
    t_out[joints[took_j]] = to2[joints[took_j]]
    took = np.zeros(len(pos) + 1, dtype=bool)
    took[:len(pos)] = fix[ro[pos]]
    held = took[pc[:len(a3)]]
    held_l = took[pc[len(a3):]]
    extra = np.concatenate([la, lines[fix[lc]], na[one & fix[ro]], l3[held_l]])
    keep = ~fix
    ca2 = np.concatenate([ca[keep], a3[held]])
    cb2 = np.concatenate([cb[keep], b3[held]])
    ctrl2 = np.concatenate([ctrl[keep], c3[held]])
    bound2 = np.concatenate([bound[keep], bd3[held]])
    o = np.argsort(ca2, kind="stable")
    return ca2[o], cb2[o], ctrl2[o], bound2[o], np.sort(extra)


def _moved_ends_error(W, points, is_cubic, tail, step, gfirst, glast, seg_owner, worst):
    """Rounded input: ``max_error`` with the input points of moved vertices (segment ends
    moved off their input point; the segments' errors count their inside points only):
    such a point's distance to the nearer of the segments that end there (as
    :func:`check_fit` measures a boundary point), per path the larger of it and ``worst``
    (a list, per path)."""
    start = points[tail - 1]
    end = points[tail + step - 1]
    ms = np.flatnonzero((start != W[gfirst]).any(axis=1))
    me = np.flatnonzero((end != W[glast]).any(axis=1))
    if len(ms) == 0 and len(me) == 0:
        return worst
    seg = np.concatenate([ms, me])
    idx = np.concatenate([gfirst[ms], glast[me]])
    d = np.empty(len(seg))
    ln = ~is_cubic[seg]
    if ln.any():
        s = seg[ln]
        d[ln] = point_segment_distance(W[idx[ln]], points[tail[s] - 1], points[tail[s]])
    if (~ln).any():
        s = seg[~ln]
        ctrl = np.stack([points[tail[s] - 1 + j] for j in range(4)], axis=1)
        _, d[~ln] = nearest_on_cubic_each(ctrl, np.arange(len(s)), W[idx[~ln]], seeds=128,
                                          iters=10)
    # (per distinct point: its nearest distance and its path; no arrays over all of W)
    u, inv = np.unique(idx, return_inverse=True)
    near = np.full(len(u), np.inf)
    np.minimum.at(near, inv, d)
    out = np.asarray(worst, dtype=np.float64).copy()
    own = np.zeros(len(u), dtype=np.intp)
    own[inv] = seg_owner[seg]
    np.fmax.at(out, own, near)
    return out


#: rounded input: a joint's design estimate is a least-squares quadratic over this many
#: input points on each side of it
_JOINT_SIDE = 8
#: ... kept only where every one of those points lies within this many quanta of it (a
#: rounded smooth stretch: up to q/√2 plus the estimate's own error; a corner misses more)
_JOINT_SMOOTH = 1.0
#: ... and the joint moved there only when it is this many quanta or more away
_JOINT_MOVE = 0.15
#: ... by this share of the way to it, the first that keeps both segments within the bound
_JOINT_SHARES = (1.0, 2.0 / 3.0, 1.0 / 3.0)
#: curve-to-polyline checks sample the moved segments at most this far apart (units of q)
_JOINT_STEP = 0.05
#: a line at least this many quanta long beside a joint only lets the joint move along it
#: (cantarell "m" at em 1500: the joint of a vertical design line and the curve it runs into
#: moved 0.18 across the line, tilting it 0.67 from the design; the rounded input is 0.5)
_JOINT_LINE = 8.0


def _joint_estimates(W, arc, g, ps, pe, k, side=4):
    """Least-squares quadratics x(s), y(s) in arc length over the input points g - k ..
    g + k (clipped to ps..pe, global indices) of each joint ``g``: (position at g (V, 2),
    unit tangent (V, 2), the largest distance of a window point to its quadratic (V,),
    ok (V,): at least ``side`` points on each side and a well-conditioned fit)."""
    off = np.arange(-k, k + 1)
    idx = g[:, None] + off[None, :]
    m = (idx >= ps[:, None]) & (idx <= pe[:, None])
    idx = np.clip(idx, ps[:, None], pe[:, None])
    s = (arc[idx] - arc[g][:, None]) * m
    ok = (m[:, :k].sum(axis=1) >= side) & (m[:, k + 1:].sum(axis=1) >= side)
    wm = m.astype(np.float64)
    V = np.stack([wm, s * wm, s * s * wm], axis=2)  # (V, 2k+1, 3)
    A = np.einsum("vni,vnj->vij", V, V)
    P = W[idx] - W[g][:, None, :]
    rhs = np.einsum("vni,vnc->vic", V, P)
    det = np.linalg.det(A)
    good = ok & (np.abs(det) > 1e-12 * np.maximum(np.abs(A).max(axis=(1, 2)), 1.0) ** 3)
    coef = np.zeros((len(g), 3, 2))
    if good.any():
        coef[good] = np.linalg.solve(A[good], rhs[good])
    fitv = coef[:, 0, None, :] + s[:, :, None] * coef[:, 1, None, :] \
        + (s * s)[:, :, None] * coef[:, 2, None, :]
    res = np.where(m, np.hypot(*(fitv - P).transpose(2, 0, 1)), 0.0).max(axis=1)
    t = coef[:, 1]
    ln = np.hypot(t[:, 0], t[:, 1])
    good &= ln > 0.0
    tan = t / np.where(ln > 0.0, ln, 1.0)[:, None]
    return W[g] + coef[:, 0], tan, res, good


def _joints_on_the_design(W, arc, points, is_cubic, tail, step, gfirst, glast, seg_owner,
                          quant, bound, wstep=None):
    """Rounded input: the joints between two segments of a path that still sit on their
    input point inside a smooth stretch (the points around lie within ``_JOINT_SMOOTH``
    quanta of their least-squares quadratic) move onto that design estimate (inside the
    point's rounding square), the segments' inner control points moved along with them,
    where both segments then stay within ``bound`` (per path) of their input points and of
    their input polyline. ``quant`` per path (0: not moved). Joints of even and of odd
    segment index in two rounds (two moves never share a segment). In place on
    ``points``; returns the segments changed."""
    ns = len(is_cubic)
    changed = np.zeros(ns, dtype=bool)
    if ns < 2:
        return changed
    j = np.flatnonzero(seg_owner[1:] == seg_owner[:-1]) + 1  # segment j starts at a joint
    j = j[quant[seg_owner[j]] > 0.0]
    g = gfirst[j]
    j = j[(points[tail[j] - 1] == W[g]).all(axis=1)]
    if len(j) == 0:
        return changed
    g = gfirst[j]
    own = seg_owner[j]
    ps = gfirst[np.searchsorted(seg_owner, own)]
    pe = glast[np.searchsorted(seg_owner, own, side="right") - 1]
    q = quant[own]
    est, tan, res, ok = _joint_estimates(W, arc, g, ps, pe, _JOINT_SIDE)
    h = 0.5 * q[:, None]
    v = np.clip(est, W[g] - h, W[g] + h)
    # a long line beside the joint (``_JOINT_LINE``) keeps its direction: only the move
    # along it (a move across tilts the whole line, its far end fixed, off the design line
    # its input points were rounded from); a joint between two long lines stays
    da = W[g] - points[tail[j - 1] - 1]
    db = points[tail[j]] - W[g]
    la = ~is_cubic[j - 1] & (np.hypot(da[:, 0], da[:, 1]) >= _JOINT_LINE * q)
    lb = ~is_cubic[j] & (np.hypot(db[:, 0], db[:, 1]) >= _JOINT_LINE * q)
    if (la | lb).any():
        d = np.where(la[:, None], da, db)
        ln = np.hypot(d[:, 0], d[:, 1])
        d = d / np.where(ln > 0.0, ln, 1.0)[:, None]
        along = W[g] + ((v - W[g]) * d).sum(axis=1)[:, None] * d
        v = np.where((la | lb)[:, None], np.clip(along, W[g] - h, W[g] + h), v)
        v = np.where((la & lb)[:, None], W[g], v)
    mv = np.hypot(*(v - W[g]).T)
    keep = ok & (res <= _JOINT_SMOOTH * q) & (mv >= _JOINT_MOVE * q)
    j, g, v, q, own = j[keep], g[keep], v[keep], q[keep], own[keep]
    if len(j) == 0:
        return changed
    if wstep is None:
        wstep = _step_lengths(W)
    bj = np.asarray(bound, dtype=np.float64)[own]
    for sel in _joint_rounds(j, mv[keep]):
        _try_joints(W, wstep, points, is_cubic, tail, gfirst, glast, sel, j, v, bj, q,
                    changed)
    return changed


def _joint_rounds(j: np.ndarray, mv: np.ndarray) -> list[np.ndarray]:
    """The joints ``j`` (sorted segment indices) in rounds of which no two share a segment
    (adjacent indices), in an order that depends on each joint's neighbourhood only: each
    round takes the joints whose move ``mv`` is the largest among their remaining
    neighbours (of equal moves the earlier), so a change of the segment count elsewhere
    on the path leaves the order here as it was (an even/odd split of the segment index
    flipped it: bench/RESULTS.md, "CFF counts, eighth session")."""
    left = np.ones(len(j), dtype=bool)
    prev = np.r_[False, j[1:] == j[:-1] + 1]  # joint i - 1 shares segment j[i] - 1
    nxt = np.r_[prev[1:], False]
    out = []
    while left.any():
        lp = prev & np.r_[False, left[:-1]]
        ln = nxt & np.r_[left[1:], False]
        mp = np.r_[-np.inf, mv[:-1]]
        mn = np.r_[mv[1:], -np.inf]
        top = left & (~lp | (mv > mp)) & (~ln | (mv >= mn))
        out.append(np.flatnonzero(top))
        left &= ~top
    return out


def _try_joints(W, wstep, points, is_cubic, tail, gfirst, glast, sel, j, v, bj, q, changed):
    """The joints ``j[sel]`` (no two sharing a segment) moved by the first share of the
    way to ``v`` (``_JOINT_SHARES``) that keeps both of their segments (the inner control
    points moved along) within the bound (:func:`_seg_fits`, steps of ``_JOINT_STEP`` q);
    per share the segments of every joint still unmoved checked in one batch
    (:func:`_seg_fits_many`)."""
    rem = sel
    ca0 = {int(i): _seg_ctrl(points, is_cubic, tail, int(j[i]) - 1) for i in rem.tolist()}
    cb0 = {int(i): _seg_ctrl(points, is_cubic, tail, int(j[i])) for i in rem.tolist()}
    for share in _JOINT_SHARES:
        if len(rem) == 0:
            return
        ctrls = []
        cand_b = []
        for i in rem.tolist():
            c0a, c0b = ca0[i], cb0[i]
            dv = share * (v[i] - c0b[0])
            ca = _end_moved(c0a, False, dv)
            cb = _end_moved(c0b, True, dv)
            ctrls.append(ca)
            cand_b.append(cb)
        ctrls.extend(cand_b)
        r = len(rem)
        jr = j[rem]
        segs = np.r_[jr - 1, jr]
        h = np.tile(_JOINT_STEP * q[rem], 2)
        bs = np.tile(bj[rem], 2)
        # a pair's line first where it has one (cheap), its other segment only where that
        # one fits (the pair moves only when both do)
        lead = np.where(is_cubic[jr - 1] & ~is_cubic[jr], r, 0) + np.arange(r)
        partner = (lead + r) % (2 * r)
        fits = np.zeros(2 * r, dtype=bool)
        x = lead
        for _ in range(2):
            if len(x):
                fits[x] = _seg_fits_many(W, wstep, [ctrls[k] for k in x.tolist()],
                                         gfirst[segs[x]], glast[segs[x]], bs[x], h[x])
            x = partner[fits[lead]]
        both = fits[:r] & fits[r:]
        for t in np.flatnonzero(both).tolist():
            a, b = int(jr[t]) - 1, int(jr[t])
            ca, cb = ctrls[t], ctrls[r + t]
            points[tail[a] - 1:tail[a] - 1 + len(ca)] = ca
            points[tail[b] - 1:tail[b] - 1 + len(cb)] = cb
            changed[a] = changed[b] = True
        rem = rem[~both]


def _seg_fits_many(W, wstep, ctrls, first, last, bound, h):
    """:func:`_seg_fits` for many segments (``ctrls`` a list of (2, 2) or (4, 2) control
    points, ``first``, ``last``, ``bound``, ``h`` per segment; ``wstep`` the lengths of the
    input's steps W[i]..W[i + 1]): the same arithmetic, so the same decisions, batched (the
    nearest points of all cubics in one call, the polyline checks in one compiled loop)."""
    n = len(ctrls)
    if n == 0:
        return np.ones(n, dtype=bool)
    cub = np.array([len(c) == 4 for c in ctrls], dtype=bool)
    C4 = np.zeros((n, 4, 2))
    for r, c in enumerate(ctrls):
        C4[r, :len(c)] = c
    return _seg_fits_arrays(W, wstep, C4, cub, first, last, bound, h)


def _seg_fits_arrays(W, wstep, C4, cub, first, last, bound, h):
    """:func:`_seg_fits_many` on arrays: ``C4`` (n, 4, 2) the control points (a line's in
    its first two rows, the others zeros), ``cub`` which are cubics."""
    n = len(C4)
    ok = np.ones(n, dtype=bool)
    if n == 0:
        return ok
    first = np.asarray(first, dtype=np.int64)
    last = np.asarray(last, dtype=np.int64)
    cnt = last - first + 1
    m = np.empty(n, dtype=np.int64)
    li = np.flatnonzero(~cub)
    ci = np.flatnonzero(cub)
    if len(li):
        L = C4[li, :2]
        lc = cnt[li]
        st = np.cumsum(lc) - lc
        pid = np.repeat(np.arange(len(li)), lc)
        idx = first[li][pid] + np.arange(int(lc.sum())) - st[pid]
        d = point_segment_distance(W[idx], L[:, 0][pid], L[:, 1][pid])
        ok[li] &= ~(np.maximum.reduceat(d, st) > bound[li])
        length = np.hypot(*(L[:, 1] - L[:, 0]).T)
        m[li] = np.maximum(2, np.ceil(length / h[li]).astype(np.int64) + 1)
    if len(ci):
        C = C4[ci]
        cc = cnt[ci]
        st = np.cumsum(cc) - cc
        pid = np.repeat(np.arange(len(ci)), cc)
        idx = first[ci][pid] + np.arange(int(cc.sum())) - st[pid]
        P = W[idx]
        bp = bound[ci][pid]
        # (a point within the bound at its nearest sample is within it: no Newton there)
        need = np.flatnonzero(~(np.sqrt(sampled_upper_d2(C, pid, P, seeds=64)) <= bp))
        if len(need):
            _, d = nearest_on_cubic_each(C, pid[need], P[need], seeds=64, iters=8)
            over = np.zeros(len(ci), dtype=bool)
            over[pid[need][d > bp[need]]] = True
            ok[ci] &= ~over
        length = np.hypot(*np.diff(C, axis=1).transpose(2, 0, 1)).sum(axis=1)
        m[ci] = np.maximum(16, np.ceil(length / h[ci]).astype(np.int64) + 1)
    go = np.flatnonzero(ok)
    if len(go) == 0:
        return ok
    C4 = C4[go]
    lim = bound[go] - 0.5 * h[go]
    res = np.empty(len(go), dtype=np.bool_)
    cg, mg, fg, lg = cub[go], m[go], first[go], last[go]

    def chunk(lo: int, hi: int) -> None:
        _polyline_checks(C4[lo:hi], cg[lo:hi], mg[lo:hi], W, wstep, fg[lo:hi], lg[lo:hi],
                         lim[lo:hi], _NEAR_SEGMENTS, res[lo:hi])

    run_chunks(chunk, mg + lg - fg)
    ok[go] = res
    return ok


def _changed_errors(W, points, is_cubic, tail, gfirst, glast, seg_owner, changed, worst):
    """``worst`` (per path) raised to the largest input-point error of the changed segments
    (their points first..last, true distances)."""
    out = np.asarray(worst, dtype=np.float64).copy()
    s = np.flatnonzero(changed & ~is_cubic)
    if len(s):
        pts = np.stack([points[tail[s] - 1], points[tail[s]]], axis=1)
        np.fmax.at(out, seg_owner[s], _line_errors(W, pts, gfirst[s], glast[s]))
    s = np.flatnonzero(changed & is_cubic)
    if len(s):
        ctrl = np.stack([points[tail[s] - 1 + k] for k in range(4)], axis=1)
        cnt = glast[s] - gfirst[s] + 1
        starts = np.cumsum(cnt) - cnt
        pid = np.repeat(np.arange(len(s)), cnt)
        idx = gfirst[s][pid] + np.arange(int(cnt.sum())) - starts[pid]
        _, d = nearest_on_cubic_each(ctrl, pid, W[idx])
        np.fmax.at(out, seg_owner[s], np.maximum.reduceat(d, starts))
    return out


def _seg_ctrl(points, is_cubic, tail, s):
    r = tail[s] - 1
    return points[r:r + (4 if is_cubic[s] else 2)].copy()


def _end_moved(ctrl, start, dv):
    """A segment's control points ``ctrl`` (2 or 4) with its start (``start``) or its end
    moved by ``dv``, a cubic's inner control point there moved along (a copy)."""
    c = ctrl.copy()
    if start:
        c[0] += dv
        if len(c) == 4:
            c[1] += dv
    else:
        c[-1] += dv
        if len(c) == 4:
            c[2] += dv
    return c


def _seg_fits(W, ctrl, first, last, bound, h) -> bool:
    """Whether the segment ``ctrl`` (2 or 4 points) stays within ``bound`` of the input
    points first..last and its samples (at most h apart; the check keeps h / 2 spare)
    within ``bound`` of their polyline."""
    loc = W[first:last + 1]
    ctrl = np.ascontiguousarray(ctrl, dtype=np.float64)
    if len(ctrl) == 2:
        if not _points_near_line(ctrl, W, first, last, bound):
            return False
    else:
        near = _points_near_cubic(ctrl, h, W, first, last, bound)
        if near < 0:
            _, d = nearest_on_cubic(ctrl, loc, seeds=64, iters=8)
            near = int(d.max() <= bound)
        if not near:
            return False
    return bool(_samples_within(ctrl, h, W, first, last, bound - 0.5 * h))


@njit(cache=True, nogil=True)
def _points_near_line(ctrl, W, first, last, bound):  # pragma: no cover (compiled)
    """Whether the input points first..last all lie within ``bound`` of the line ``ctrl``
    (:func:`point_segment_distance`'s arithmetic; NaN fails)."""
    abx = ctrl[1, 0] - ctrl[0, 0]
    aby = ctrl[1, 1] - ctrl[0, 1]
    den = abx * abx + aby * aby
    for g in range(first, last + 1):
        apx = W[g, 0] - ctrl[0, 0]
        apy = W[g, 1] - ctrl[0, 1]
        u = (apx * abx + apy * aby) / den if den > 0.0 else 0.0
        if u != u:
            return False
        u = min(max(u, 0.0), 1.0)
        if not math.hypot(apx - u * abx, apy - u * aby) <= bound:
            return False
    return True


#: :func:`_points_near_cubic` samples the cubic this many times h apart (the sagitta of
#: its chords stays a few thousandths of the bound)
_NEAR_CUBIC_STEP = 4.0


@njit(cache=True, nogil=True)
def _points_near_cubic(ctrl, h, W, first, last, bound):  # pragma: no cover (compiled)
    """Whether the input points first..last lie within ``bound`` of the cubic ``ctrl``:
    1 where all lie within bound less the chords' sagitta of its samples' polyline
    (:func:`_seg_samples` at ``_NEAR_CUBIC_STEP`` h; the sagitta at most |B''| du² / 8,
    |B''| at most 6 x the largest second difference of the control points), 0 where one
    lies farther than bound plus the sagitta from it, -1 where neither is shown
    (measure)."""
    samp = _seg_samples(ctrl, _NEAR_CUBIC_STEP * h)
    dd = 0.0
    for k in range(2):
        dd = max(dd, math.hypot(ctrl[k + 2, 0] - 2.0 * ctrl[k + 1, 0] + ctrl[k, 0],
                                ctrl[k + 2, 1] - 2.0 * ctrl[k + 1, 1] + ctrl[k, 1]))
    du = 1.0 / (samp.shape[0] - 1)
    sag = 0.75 * dd * du * du + 1e-9 * (1.0 + bound)
    lim = bound - sag
    if not lim > 0.0:
        return -1
    d, over = _max_over(W[first:last + 1], samp, lim, _NEAR_SEGMENTS, lim, bound + sag,
                        _WITHIN_STRIDE)
    if over:
        return 0
    return 1 if d <= lim else -1


#: samples in order along a polyline are measured first against this many of its segments
#: on either side of their share of its length
_NEAR_SEGMENTS = 8


def _polyline_distance_over(samp, poly, lim, k=_NEAR_SEGMENTS):
    """The distance of each of the samples ``samp`` (in order along ``poly``) to the
    polyline where it is over ``lim``, else a distance within ``lim`` (each sample measured
    against the segments near its share of the length, those over ``lim`` against all;
    compiled, :func:`_over_kernel`)."""
    n = len(poly)
    if n <= 2 * k + 2:
        if n < 2:
            return point_polyline_distance(samp, poly)
        d = np.empty(len(samp))
        _brute_kernel(np.ascontiguousarray(samp, dtype=np.float64),
                      np.ascontiguousarray(poly, dtype=np.float64), d)
        return d
    samp = np.ascontiguousarray(samp, dtype=np.float64)
    poly = np.ascontiguousarray(poly, dtype=np.float64)
    d = np.empty(len(samp))
    if len(samp):
        _over_kernel(samp, np.hypot(*np.diff(samp, axis=0).T), poly,
                     np.hypot(*np.diff(poly, axis=0).T), float(lim), k, d)
    return d


@njit(cache=True, nogil=True)
def _brute_kernel(samp, poly, out):  # pragma: no cover (compiled)
    """:func:`point_polyline_distance` of the samples to a short polyline (2 points or
    more) compiled: :func:`_brute_d`, its arithmetic."""
    for t in range(samp.shape[0]):
        out[t] = _brute_d(samp[t, 0], samp[t, 1], poly, 0, poly.shape[0])


@njit(cache=True, nogil=True)
def _over_kernel(samp, sstep, poly, pstep, lim, k, out):  # pragma: no cover (compiled)
    """:func:`_polyline_distance_over` of the samples to the polyline (more than 2k + 2
    points; ``sstep``/``pstep`` their step lengths): each sample's place along the polyline
    by its share of the length (np.searchsorted of the scaled cumulated lengths), the
    distance to the 2k + 1 segments there, where over ``lim`` to 32k + 1 (on polylines of
    over 16k + 2 points), where still over to all of them."""
    _over_kernel_upto(samp, sstep, poly, pstep, lim, k, out, np.inf)


@njit(cache=True, nogil=True, inline="always")
def _share_at(cum, n, val):  # pragma: no cover (compiled)
    """The segment of a polyline (``cum`` its n cumulated lengths) at its share ``val`` of
    the length: the index before np.searchsorted(cum[:n], val) (side left)."""
    lo = 0
    hi = n
    while lo < hi:
        mid = (lo + hi) >> 1
        if cum[mid] < val:
            lo = mid + 1
        else:
            hi = mid
    return lo - 1


@njit(cache=True, nogil=True)
def _over_kernel_upto(samp, sstep, poly, pstep, lim, k, out,
                      stop):  # pragma: no cover (compiled)
    """:func:`_over_kernel` up to the first sample farther than ``stop`` (each sample's
    distance is its own: the same numbers); returns how many samples it measured."""
    n = poly.shape[0]
    ms = samp.shape[0]
    cum = np.empty(n)
    cum[0] = 0.0
    for t in range(n - 1):
        cum[t + 1] = cum[t] + pstep[t]
    cs = np.empty(ms)
    cs[0] = 0.0
    for t in range(ms - 1):
        cs[t + 1] = cs[t] + sstep[t]
    scale = cs[ms - 1] > 0.0
    r = cum[n - 1] / cs[ms - 1] if scale else 1.0
    for t in range(ms):
        at = _share_at(cum, n, cs[t] * r if scale else cs[t])
        px = samp[t, 0]
        py = samp[t, 1]
        d = _win_d(px, py, poly, 0, n - 1, at, k, cum, np.inf)
        if d > lim and n > 16 * k + 2:  # (the narrower window's distance bounds these)
            d = _win_d(px, py, poly, 0, n - 1, at, 16 * k, cum, d)
        if d > lim:
            d = _full_d(px, py, poly, 0, n, at, cum, d)
        out[t] = d
        if d > stop:
            return t + 1
    return ms


@njit(cache=True, nogil=True)
def _polyline_checks(C4, cub, msz, W, wstep, first, last, lim, k,
                     out):  # pragma: no cover (compiled)
    """out[i]: whether the samples of segment i (``msz[i]`` at np.linspace(0, 1, m) on the
    cubic C4[i], or the line C4[i, 0]..C4[i, 1] where not cub[i]; the arithmetic of
    cubic_eval and of ctrl[0] + t (ctrl[1] - ctrl[0])) stay within lim[i] of the polyline
    W[first[i]..last[i]] by :func:`_polyline_distance_over` (window ``k``; its arithmetic:
    the windowed, wider and full distances in turn, the brute force for short polylines;
    ``wstep`` the step lengths of W)."""
    mmax = 2
    for i in range(msz.shape[0]):
        mmax = max(mmax, msz[i])
    sx = np.empty(mmax)
    sy = np.empty(mmax)
    cs = np.empty(mmax)
    dxb = np.empty(mmax)
    dyb = np.empty(mmax)
    hb = np.empty(mmax)
    fb = np.empty(mmax, dtype=np.bool_)
    for i in range(first.shape[0]):
        ms = msz[i]
        step = 1.0 / (ms - 1)
        for t in range(ms):
            u = t * step if t < ms - 1 else 1.0
            if cub[i]:
                b0, b1, b2, b3 = bernstein_weights(u)
                sx[t] = bernstein_point(b0, b1, b2, b3, C4, i, 0)
                sy[t] = bernstein_point(b0, b1, b2, b3, C4, i, 1)
            else:
                sx[t] = C4[i, 0, 0] + u * (C4[i, 1, 0] - C4[i, 0, 0])
                sy[t] = C4[i, 0, 1] + u * (C4[i, 1, 1] - C4[i, 0, 1])
        f = first[i]
        n = last[i] - f + 1
        lm = lim[i]
        good = True
        if n == 1:
            for t in range(ms):
                if math.hypot(sx[t] - W[f, 0], sy[t] - W[f, 1]) > lm:
                    good = False
                    break
        elif n <= 2 * k + 2:
            for t in range(ms):
                if _brute_d(sx[t], sy[t], W, f, n) > lm:
                    good = False
                    break
        else:
            cum = np.empty(n)
            cum[0] = 0.0
            for t in range(n - 1):
                cum[t + 1] = cum[t] + wstep[f + t]
            for t in range(ms - 1):
                dxb[t] = sx[t + 1] - sx[t]
                dyb[t] = sy[t + 1] - sy[t]
            hypot_into(dxb, dyb, ms - 1, hb, fb)
            cs[0] = 0.0
            for t in range(ms - 1):
                cs[t + 1] = cs[t] + hb[t]
            scale = cs[ms - 1] > 0.0
            r = cum[n - 1] / cs[ms - 1] if scale else 1.0
            nseg = n - 1
            for t in range(ms):
                at = _share_at(cum, n, cs[t] * r if scale else cs[t])
                px = sx[t]
                py = sy[t]
                d = _win_d(px, py, W, f, nseg, at, k, cum, np.inf)
                if d > lm and n > 16 * k + 2:
                    d = _win_d(px, py, W, f, nseg, at, 16 * k, cum, d)
                if d > lm:
                    d = _full_d(px, py, W, f, n, at, cum, d)
                if d > lm:
                    good = False
                    break
        out[i] = good


@njit(cache=True, nogil=True, inline="always")
def _seg_d2(px, py, W, j, brute):  # pragma: no cover (compiled)
    """The squared distance of (px, py) to the segment W[j]..W[j + 1]: the windowed
    arithmetic (a division by the squared length), or with ``brute`` that of
    :func:`point_polyline_distance` (1 / the squared length)."""
    ax = W[j, 0]
    ay = W[j, 1]
    vx = W[j + 1, 0] - ax
    vy = W[j + 1, 1] - ay
    dx = px - ax
    dy = py - ay
    den = vx * vx + vy * vy
    if brute:
        inv = 1.0 / den if den > 1e-300 else 0.0
        u = min(max((dx * vx + dy * vy) * inv, 0.0), 1.0)
    else:
        u = 0.0
        if den > 0.0:
            u = min(1.0, max(0.0, (dx * vx + dy * vy) / den))
    ex = dx - u * vx
    ey = dy - u * vy
    return ex * ex + ey * ey


@njit(cache=True, nogil=True, inline="always")
def _scan_d(px, py, W, f, lo, hi, at, cum, brute, ub):  # pragma: no cover (compiled)
    """The distance of (px, py) to the nearest of the segments lo .. hi of the polyline
    W[f..] (``cum`` its cumulated step lengths from W[f]; :func:`_seg_d2`'s arithmetic):
    from the segment at ``at`` (clipped) outwards, and segments that cannot be nearer than
    the nearest so far (or than ``ub``, a known upper bound of the answer up to the
    rounding) are skipped: a point X of segment i lies within the polyline's length
    between W[f + j] and X of W[f + j], so its distance is at least |p - W[f + j]| minus
    that length (with a margin for the rounding; the skipped run found by bisection of
    ``cum``). The smallest squared distance is the same number as over all of them."""
    c = min(max(at, lo), hi)
    best = np.inf
    sb = np.inf
    tol = 1e-9 * (1.0 + cum[hi + 1] - cum[lo])
    j = c
    while j <= hi:
        bound = min(sb, ub)
        if bound < np.inf:
            dx = px - W[f + j, 0]
            dy = py - W[f + j, 1]
            e = math.sqrt(dx * dx + dy * dy)
            room = e - bound - tol - 1e-9 * e
            if room > 0.0:  # segments j .. i - 1 are all farther than the nearest
                a = j
                b = hi + 1
                while a < b:  # the first i with cum[i + 1] - cum[j] >= room
                    mid = (a + b) >> 1
                    if cum[mid + 1] - cum[j] < room:
                        a = mid + 1
                    else:
                        b = mid
                if a > j:
                    j = a
                    continue
        d2 = _seg_d2(px, py, W, f + j, brute)
        if d2 < best:
            best = d2
            sb = math.sqrt(best)
        j += 1
    j = c - 1
    while j >= lo:
        bound = min(sb, ub)
        dx = px - W[f + j + 1, 0]
        dy = py - W[f + j + 1, 1]
        e = math.sqrt(dx * dx + dy * dy)
        room = e - bound - tol - 1e-9 * e
        if room > 0.0:  # segments i + 1 .. j are all farther than the nearest
            a = lo
            b = j + 1
            while a < b:  # the first i with cum[j + 1] - cum[i] < room
                mid = (a + b) >> 1
                if cum[j + 1] - cum[mid] < room:
                    b = mid
                else:
                    a = mid + 1
            if a <= j:
                j = a - 1
                continue
        d2 = _seg_d2(px, py, W, f + j, brute)
        if d2 < best:
            best = d2
            sb = math.sqrt(best)
        j -= 1
    return math.sqrt(best)


@njit(cache=True, nogil=True, inline="always")
def _win_d(px, py, W, f, ns, at, k, cum, ub):  # pragma: no cover (compiled)
    """One sample's distance to the segments at - k .. at + k (clipped) of the polyline
    W[f..f + ns] (1 / the squared length not taken: the windowed arithmetic); ``cum`` its
    cumulated step lengths from W[f], ``ub`` an upper bound of the answer (or inf)
    (:func:`_scan_d`)."""
    lo = max(0, min(at - k, ns - 1))
    hi = min(ns - 1, max(at + k, 0))
    return _scan_d(px, py, W, f, lo, hi, at, cum, False, ub)


@njit(cache=True, nogil=True, inline="always")
def _brute_d(px, py, W, f, n):  # pragma: no cover (compiled)
    """One sample's :func:`point_polyline_distance` to the polyline W[f..f + n - 1],
    n >= 2: its arithmetic (1 / the squared length)."""
    best = np.inf
    for j in range(n - 1):
        d2 = _seg_d2(px, py, W, f + j, True)
        if d2 < best:
            best = d2
    return math.sqrt(best)


@njit(cache=True, nogil=True, inline="always")
def _full_d(px, py, W, f, n, at, cum, ub):  # pragma: no cover (compiled)
    """:func:`_brute_d` (the same number) from the segment at ``at`` outwards
    (:func:`_scan_d`; ``cum`` the cumulated step lengths from W[f], ``ub`` an upper bound
    of the answer up to the rounding, or inf)."""
    return _scan_d(px, py, W, f, 0, n - 2, at, cum, True, ub)


#: rounded input, after the joints: a segment is repaired where the design estimate (the
#: joints' least-squares quadratic) of one of its input points lies this many quanta or more
#: from it (inside a smooth stretch: the estimates are about 0.1-0.2 quanta from the design)
_STRETCH_OFF = 0.45
#: ... a repair kept only when it brings that distance down by this many quanta
_STRETCH_GAIN = 0.05
#: ... the least-squares cubic of a repair follows its input polyline sampled at most this
#: far apart (units of q), with this many re-parametrisations
_STRETCH_STEP = 1.0
_STRETCH_ITERS = 4
_STRETCH_TARGETS = 128
#: ... the estimates' windows end at a gap between input points longer than this (units of
#: q: a design line between two rounded points)
_STRETCH_GAP = 8.0
#: ... a segment split in two (one more segment) only when no repair keeps the count, at
#: most this share of each path's segments (rounded: a path of 25 segments or more may
#: take one) ...
_STRETCH_SPLITS = 0.02
#: ... or where the segment lies this many quanta or more from the estimates (the estimates
#: are within about 0.1-0.2 q of the design: such a segment is off the design by more than
#: the rounding; FreeSans "&" at em 1000, a 6-segment contour, a line 0.71 off a curve
#: whose rounded input is 0.03 from it)
_STRETCH_SPLIT_FAR = 0.55
#: ... at input points at least this many points from either end of the segment
_STRETCH_PIECE = 4
#: ... an estimate holds with this many input points on either side of it in its window
_STRETCH_SIDE = 4
#: ... and with its window reaching this many quanta of arc length on either side (over
#: fewer the rounding's staircase can move a quadratic half a quantum: input points much
#: closer than the quantum, where the fit's least squares average the rounding anyway)
_STRETCH_SPAN = 3.0
#: ... a least-squares cubic is fitted over at least this many input points
_STRETCH_CUBIC = 8
#: ... a joint left on its input point this many quanta or more from its estimate is moved
#: there with both of its segments re-fitted
_STRETCH_JOINT = 0.3
#: ... a corner's two one-sided estimates used only when they are this close (quanta)
_STRETCH_CORNER_AGREE = 0.5
#: ... at most this many re-fits per path, plus one per this many of its input points (the
#: worst segments first, then the joints: the pass's time stays a fraction of the fit's).
#: Both budgets are each path's own: one budget shared by all paths of a call made a path's
#: fit depend on the paths fitted with it (DejaVu Sans ExtraLight at em 2048: 11 of 98
#: contours fitted differently alone; the later contours of a long text got no repair)
_STRETCH_BUDGET = 256
_STRETCH_PER = 20_000
#: ... the distance of a segment to the estimates' polyline sampled this far apart (q)
_STRETCH_LOOK = 0.25
#: ... distances over this many samples' spacings measured exactly (below: an upper bound)
_STRETCH_EXACT = 1.2


def _stretch_estimates(W, arc, ps, pe, quant):
    """Per input point (global index) of the rounded paths ps..pe (quantum ``quant`` each):
    the design estimate of :func:`_joint_estimates` (compiled) and whether it holds (a smooth
    stretch: enough points on both sides, the window's points within ``_JOINT_SMOOTH``
    quanta of it, the window reaching ``_STRETCH_SPAN`` quanta of arc length on either
    side). The windows stop at gaps longer than ``_STRETCH_GAP`` quanta."""
    est = np.zeros_like(W)
    valid = np.zeros(len(W), dtype=np.bool_)
    if len(ps):
        ps = np.asarray(ps, dtype=np.int64)
        pe = np.asarray(pe, dtype=np.int64)
        quant = np.asarray(quant, dtype=np.float64)

        def chunk(lo: int, hi: int) -> None:  # (each path writes only its own points)
            _quad_estimates(W, arc, ps[lo:hi], pe[lo:hi], quant[lo:hi], _JOINT_SIDE,
                            _STRETCH_SIDE, _JOINT_SMOOTH, _STRETCH_GAP, _STRETCH_SPAN, est,
                            valid)

        run_chunks(chunk, pe - ps + 1)
    return est, valid


@njit(cache=True, nogil=True)
def _quad_estimates(W, arc, ps, pe, quant, k, side, smooth, gap, span, est,
                    ok):  # pragma: no cover (compiled)
    """:func:`_joint_estimates` compiled, per input point c of each path ps..pe over the
    window of up to ``k`` points on either side (ending at a step over ``gap`` quanta):
    est[c] the quadratic's position at c, ok[c] at least ``side`` points and ``span``
    quanta of arc length on either side, a well-conditioned fit and every window point
    within ``smooth`` quanta of the quadratic."""
    for p in range(ps.shape[0]):
        q = quant[p]
        lim2 = (gap * q) ** 2
        reach = span * q
        for c in range(ps[p], pe[p] + 1):
            est[c, 0] = W[c, 0]
            est[c, 1] = W[c, 1]
            if c - ps[p] < side or pe[p] - c < side:
                continue
            lo = max(ps[p], c - k)
            hi = min(pe[p], c + k)
            if arc[c] - arc[lo] < reach or arc[hi] - arc[c] < reach:
                continue  # (the gaps below only shorten the window)
            j = c
            while j > lo and (W[j, 0] - W[j - 1, 0]) ** 2 + (W[j, 1] - W[j - 1, 1]) ** 2 <= lim2:
                j -= 1
            lo = j
            j = c
            while j < hi and (W[j + 1, 0] - W[j, 0]) ** 2 + (W[j + 1, 1] - W[j, 1]) ** 2 <= lim2:
                j += 1
            hi = j
            if c - lo < side or hi - c < side or arc[c] - arc[lo] < reach \
                    or arc[hi] - arc[c] < reach:
                continue
            good, ex, ey = _quad_one(W, arc, c, lo, hi, smooth * q)
            if good:
                est[c, 0] = ex
                est[c, 1] = ey
                ok[c] = True


@njit(cache=True, nogil=True)
def _quad_one(W, arc, c, lo, hi, tol):  # pragma: no cover (compiled)
    """The least-squares quadratic x(s), y(s) over the window lo..hi: (whether it is well
    conditioned and every window point lies within ``tol`` of it, its position at c)."""
    m0 = m1 = m2 = m3 = m4 = 0.0
    rx0 = rx1 = rx2 = ry0 = ry1 = ry2 = 0.0
    for j in range(lo, hi + 1):
        t = arc[j] - arc[c]
        px = W[j, 0] - W[c, 0]
        py = W[j, 1] - W[c, 1]
        t2 = t * t
        t3 = t2 * t
        m0 += 1.0
        m1 += t
        m2 += t2
        m3 += t3
        m4 += t3 * t
        rx0 += px
        rx1 += t * px
        rx2 += t2 * px
        ry0 += py
        ry1 += t * py
        ry2 += t2 * py
    a00, a01, a02, a11, a12, a22 = m0, m1, m2, m2, m3, m4
    c00 = a11 * a22 - a12 * a12
    c01 = a02 * a12 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    det = a00 * c00 + a01 * c01 + a02 * c02
    big = max(abs(a00), abs(a01), abs(a02), abs(a11), abs(a12), abs(a22), 1.0)
    if not abs(det) > 1e-12 * big * big * big:
        return False, 0.0, 0.0
    c11 = a00 * a22 - a02 * a02
    c12 = a01 * a02 - a00 * a12
    c22 = a00 * a11 - a01 * a01
    cx0 = (c00 * rx0 + c01 * rx1 + c02 * rx2) / det
    cx1 = (c01 * rx0 + c11 * rx1 + c12 * rx2) / det
    cx2 = (c02 * rx0 + c12 * rx1 + c22 * rx2) / det
    cy0 = (c00 * ry0 + c01 * ry1 + c02 * ry2) / det
    cy1 = (c01 * ry0 + c11 * ry1 + c12 * ry2) / det
    cy2 = (c02 * ry0 + c12 * ry1 + c22 * ry2) / det
    if cx1 == 0.0 and cy1 == 0.0:
        return False, 0.0, 0.0
    tol2 = tol * tol
    for j in range(lo, hi + 1):
        t = arc[j] - arc[c]
        ex = cx0 + t * (cx1 + t * cx2) - (W[j, 0] - W[c, 0])
        ey = cy0 + t * (cy1 + t * cy2) - (W[j, 1] - W[c, 1])
        if ex * ex + ey * ey > tol2:
            return False, 0.0, 0.0
    return True, W[c, 0] + cx0, W[c, 1] + cy0


@njit(cache=True, nogil=True)
def _side_estimates(W, arc, g, ps, pe, quant, k, side, smooth, gap, span,
                    out):  # pragma: no cover (compiled)
    """Per joint g[i] (input point, path ps[i]..pe[i], quantum quant[i]): the least-squares
    quadratics over up to ``k`` points before it (out[i, 0]) and after it (out[i, 1]), the
    joint included, each evaluated at the joint: (x, y, 1.0) where the window has at least
    ``side`` points besides the joint, reaches ``span`` quanta of arc, has no step over
    ``gap`` quanta and every point within ``smooth`` quanta of its quadratic, else
    (0, 0, 0)."""
    for i in range(g.shape[0]):
        c = g[i]
        q = quant[i]
        lim2 = (gap * q) ** 2
        for sd in range(2):
            out[i, sd, 0] = 0.0
            out[i, sd, 1] = 0.0
            out[i, sd, 2] = 0.0
            if sd == 0:
                j = c
                while j > max(ps[i], c - k) and (W[j, 0] - W[j - 1, 0]) ** 2 \
                        + (W[j, 1] - W[j - 1, 1]) ** 2 <= lim2:
                    j -= 1
                lo, hi = j, c
            else:
                j = c
                while j < min(pe[i], c + k) and (W[j + 1, 0] - W[j, 0]) ** 2 \
                        + (W[j + 1, 1] - W[j, 1]) ** 2 <= lim2:
                    j += 1
                lo, hi = c, j
            if hi - lo < side or arc[hi] - arc[lo] < span * q:
                continue
            good, ex, ey = _quad_one(W, arc, c, lo, hi, smooth * q)
            if good:
                out[i, sd, 0] = ex
                out[i, sd, 1] = ey
                out[i, sd, 2] = 1.0


@njit(cache=True, nogil=True)
def _targets_kernel(W, est, valid, f, e, step, most):  # pragma: no cover (compiled)
    """:func:`_stretch_targets` compiled, the same numbers: the points (estimates
    where valid) with each step cut into ceil(length / step) (at least 1) equal parts
    (libm's hypot; (i - start) / n, then d0 + frac (d1 - d0)), the last point; more than
    ``most`` thinned to the rows np.linspace(0, len - 1, most).round() (halves to even)."""
    n = e - f + 1
    d = np.empty((n, 2))
    for g in range(f, e + 1):
        src = est if valid[g] else W
        d[g - f, 0] = src[g, 0]
        d[g - f, 1] = src[g, 1]
    cnt = np.empty(n - 1, dtype=np.int64)
    tot = 0
    for i in range(n - 1):
        gap = math.hypot(d[i + 1, 0] - d[i, 0], d[i + 1, 1] - d[i, 1])
        cnt[i] = max(int(math.ceil(gap / step)), 1)
        tot += cnt[i]
    pts = np.empty((tot + 1, 2))
    r = 0
    for i in range(n - 1):
        for j in range(cnt[i]):
            fr = j / cnt[i]
            pts[r, 0] = d[i, 0] + fr * (d[i + 1, 0] - d[i, 0])
            pts[r, 1] = d[i, 1] + fr * (d[i + 1, 1] - d[i, 1])
            r += 1
    pts[tot, 0] = d[n - 1, 0]
    pts[tot, 1] = d[n - 1, 1]
    if tot + 1 <= most:
        return pts
    out = np.empty((most, 2))
    sp = tot / (most - 1)
    for i in range(most):
        x = i * sp if i < most - 1 else float(tot)
        k = math.floor(x)
        h = x - k
        if h > 0.5 or (h == 0.5 and k % 2 == 1):
            k += 1
        out[i, 0] = pts[int(k), 0]
        out[i, 1] = pts[int(k), 1]
    return out


def _stretch_targets(W, est, valid, f, e, q):
    """The design polyline of the input points f..e: each smooth point's estimate (else the
    point), the long gaps filled every ``_STRETCH_STEP`` quanta (at most
    ``_STRETCH_TARGETS`` points, evenly taken)."""
    return _targets_kernel(W, est, valid, f, e, _STRETCH_STEP * q, _STRETCH_TARGETS)


@njit(cache=True, nogil=True)
def _ls_step(ctrl, t, tg, s, b1, b2) -> None:  # pragma: no cover (compiled)
    """:func:`_ls_cubic`'s elementwise part (the former numpy arithmetic, the same
    numbers): where ``ctrl`` is a cubic, a Newton step of each target's parameter ``t``
    (in place) towards its nearest point on it (no step where the second derivative is
    not positive; clipped to [0, 1]); then s = 1 - t and the weights b1 = 3 s² t,
    b2 = 3 s t²."""
    n = t.shape[0]
    if ctrl.shape[0] == 4:
        ex1x = ctrl[1, 0] - ctrl[0, 0]
        ex1y = ctrl[1, 1] - ctrl[0, 1]
        ex2x = ctrl[2, 0] - ctrl[1, 0]
        ex2y = ctrl[2, 1] - ctrl[1, 1]
        ex3x = ctrl[3, 0] - ctrl[2, 0]
        ex3y = ctrl[3, 1] - ctrl[2, 1]
        q0x = (ctrl[2, 0] - 2.0 * ctrl[1, 0]) + ctrl[0, 0]
        q0y = (ctrl[2, 1] - 2.0 * ctrl[1, 1]) + ctrl[0, 1]
        q1x = (ctrl[3, 0] - 2.0 * ctrl[2, 0]) + ctrl[1, 0]
        q1y = (ctrl[3, 1] - 2.0 * ctrl[2, 1]) + ctrl[1, 1]
        c3 = ctrl.reshape(1, 4, 2)
        for k in range(n):
            tk = t[k]
            sk = 1.0 - tk
            w0 = sk * sk
            w1 = 2.0 * sk * tk
            w2 = tk * tk
            d1x = 3.0 * ((w0 * ex1x + w1 * ex2x) + w2 * ex3x)
            d1y = 3.0 * ((w0 * ex1y + w1 * ex2y) + w2 * ex3y)
            d2x = 6.0 * (sk * q0x + tk * q1x)
            d2y = 6.0 * (sk * q0y + tk * q1y)
            b0, bb1, bb2, b3 = bernstein_weights(tk)
            rx = bernstein_point(b0, bb1, bb2, b3, c3, 0, 0) - tg[k, 0]
            ry = bernstein_point(b0, bb1, bb2, b3, c3, 0, 1) - tg[k, 1]
            den = (d1x * d1x + d1y * d1y) + (rx * d2x + ry * d2y)
            dt = (rx * d1x + ry * d1y) / den if den > 0.0 else 0.0
            v = tk - dt
            if v == v:  # (np.clip's: NaN kept, else max(v, 0) then min(v, 1), ties to the bound)
                v = v if v > 0.0 else 0.0
                v = v if v < 1.0 else 1.0
            t[k] = v
    for k in range(n):
        tk = t[k]
        sk = 1.0 - tk
        s[k] = sk
        b1[k] = 3.0 * sk * sk * tk
        b2[k] = 3.0 * sk * tk * tk


def _ls_cubic(p0, p3, tg):
    """The cubic from p0 to p3 whose inner control points fit the targets ``tg`` best
    (least squares, parameters re-fitted by Newton steps towards the nearest points); None
    when degenerate (compiled: :func:`_ls_cubic_kernel`)."""
    out = np.empty((4, 2))
    if not _ls_cubic_kernel(np.asarray(p0, dtype=np.float64), np.asarray(p3, dtype=np.float64),
                            np.ascontiguousarray(tg, dtype=np.float64), out):
        return None
    return out


@njit(cache=True, nogil=True)
def _ls_cubic_kernel(p0, p3, tg, out):  # pragma: no cover (compiled)
    """:func:`_ls_cubic` compiled: the chord-length parameters, then ``_STRETCH_ITERS``
    rounds of (a Newton step of each target's parameter towards its nearest point on the
    cubic so far, :func:`_ls_step`; the 2x2 normal equations of the inner control points
    with the ends fixed); out gets the cubic; False when there is none (fewer than 4
    targets, no length, the first system singular). A singular later system keeps the
    cubic before it."""
    n = tg.shape[0]
    if n < 4:
        return False
    t = np.empty(n)
    t[0] = 0.0
    for k in range(1, n):
        t[k] = t[k - 1] + math.hypot(tg[k, 0] - tg[k - 1, 0], tg[k, 1] - tg[k - 1, 1])
    tot = t[n - 1]
    if not tot > 0.0:
        return False
    for k in range(n):
        t[k] /= tot
    s = np.empty(n)
    b1 = np.empty(n)
    b2 = np.empty(n)
    ctrl = np.zeros((4, 2))
    none = np.zeros((0, 2))
    have = False
    for it in range(_STRETCH_ITERS + 1):
        _ls_step(ctrl if have else none, t, tg, s, b1, b2)
        if it == _STRETCH_ITERS:
            break
        a11 = a12 = a22 = 0.0
        r1x = r1y = r2x = r2y = 0.0
        for k in range(n):
            s3 = s[k] * s[k] * s[k]
            t3 = t[k] * t[k] * t[k]
            rx = (tg[k, 0] - s3 * p0[0]) - t3 * p3[0]
            ry = (tg[k, 1] - s3 * p0[1]) - t3 * p3[1]
            a11 += b1[k] * b1[k]
            a12 += b1[k] * b2[k]
            a22 += b2[k] * b2[k]
            r1x += b1[k] * rx
            r1y += b1[k] * ry
            r2x += b2[k] * rx
            r2y += b2[k] * ry
        det = a11 * a22 - a12 * a12
        if not det > 1e-12 * max(a11 * a22, 1e-300):
            break
        ctrl[0, 0], ctrl[0, 1] = p0[0], p0[1]
        ctrl[1, 0] = (a22 * r1x - a12 * r2x) / det
        ctrl[1, 1] = (a22 * r1y - a12 * r2y) / det
        ctrl[2, 0] = (a11 * r2x - a12 * r1x) / det
        ctrl[2, 1] = (a11 * r2y - a12 * r1y) / det
        ctrl[3, 0], ctrl[3, 1] = p3[0], p3[1]
        have = True
    out[:] = ctrl
    return have


def _design_off(W, est, valid, ctrl, f, e, h, limit=math.inf):
    """How far the segment ``ctrl`` lies from the design estimates of its input points
    f..e: (d1, d2), d1 the largest distance of a smooth point's estimate (or of the middle
    between two smooth neighbours' estimates) to it, d2 the largest distance of its samples
    (at most h apart) to the polyline of the estimates (else the points); None when d1 is
    over ``limit``. Both measured against polylines (the samples, the estimates), exactly
    where over ``_STRETCH_EXACT`` h."""
    r = np.empty(2)  # (compiled: :func:`_design_off_kernel`)
    if not _design_off_kernel(W, est, valid, np.ascontiguousarray(ctrl, dtype=np.float64), f, e,
                              h, limit, r):
        return None
    return float(r[0]), float(r[1])


#: :func:`_samples_within` and :func:`_points_near_cubic` bound at least every this many
#: points by a walk (:func:`_max_over`; the points between by the path length where that
#: keeps them within the floor)
_WITHIN_STRIDE = 8


@njit(cache=True, nogil=True)
def _seg_samples(ctrl, h):  # pragma: no cover (compiled)
    """The samples of the segment ``ctrl`` (2 or 4 points) at most h apart that
    :func:`_seg_fits` and :func:`_design_off` take: m = max(2 (16 for a cubic),
    ceil(length / h) + 1) (the length the chord's, or the control polygon's summed in
    order) at np.linspace(0, 1, m), cubic_eval's arithmetic or the line's ctrl[0] +
    t (ctrl[1] - ctrl[0]) (the same numbers)."""
    cub = ctrl.shape[0] == 4
    if cub:
        length = (math.hypot(ctrl[1, 0] - ctrl[0, 0], ctrl[1, 1] - ctrl[0, 1])
                  + math.hypot(ctrl[2, 0] - ctrl[1, 0], ctrl[2, 1] - ctrl[1, 1])) \
            + math.hypot(ctrl[3, 0] - ctrl[2, 0], ctrl[3, 1] - ctrl[2, 1])
        m = max(16, int(math.ceil(length / h)) + 1)
    else:
        length = math.hypot(ctrl[1, 0] - ctrl[0, 0], ctrl[1, 1] - ctrl[0, 1])
        m = max(2, int(math.ceil(length / h)) + 1)
    samp = np.empty((m, 2))
    c3 = ctrl.reshape(1, ctrl.shape[0], 2)
    step = 1.0 / (m - 1)
    for t in range(m):
        u = t * step if t < m - 1 else 1.0
        if cub:
            b0, b1, b2, b3 = bernstein_weights(u)
            samp[t, 0] = bernstein_point(b0, b1, b2, b3, c3, 0, 0)
            samp[t, 1] = bernstein_point(b0, b1, b2, b3, c3, 0, 1)
        else:
            samp[t, 0] = ctrl[0, 0] + u * (ctrl[1, 0] - ctrl[0, 0])
            samp[t, 1] = ctrl[0, 1] + u * (ctrl[1, 1] - ctrl[0, 1])
    return samp


@njit(cache=True, nogil=True)
def _samples_within(ctrl, h, W, first, last, lim):  # pragma: no cover (compiled)
    """:func:`_seg_fits`' polyline side compiled: whether the samples
    (:func:`_seg_samples`) all lie within ``lim`` of the polyline W[first..last]
    (:func:`_polyline_distance_over`'s numbers; NaN fails)."""
    # (the samples near a measured one that lie within lim by the distance between them
    # are not measured: the same answer, :func:`_max_over`)
    d, over = _max_over(_seg_samples(ctrl, h), W[first:last + 1], lim, _NEAR_SEGMENTS, lim, lim,
                        _WITHIN_STRIDE)
    return not over and d <= lim


@njit(cache=True, nogil=True)
def _design_off_kernel(W, est, valid, ctrl, f, e, h, limit, out):  # pragma: no cover
    """:func:`_design_off` compiled: its samples (np.linspace's and cubic_eval's
    arithmetic, the line's ctrl[0] + t (ctrl[1] - ctrl[0])), its targets in the same order
    and :func:`_polyline_distance_over` (the brute force or :func:`_over_kernel`, the step
    lengths libm's hypot), so the same numbers; out[0], out[1] get (d1, d2); returns
    False when d1 is over ``limit``."""
    samp = _seg_samples(ctrl, h)
    m = samp.shape[0]
    lim = _STRETCH_EXACT * h
    n = e - f + 1
    tp = np.empty((2 * n, 2))
    nt = 0
    for g in range(f, e + 1):
        if valid[g]:
            tp[nt, 0] = est[g, 0]
            tp[nt, 1] = est[g, 1]
            nt += 1
            if g < e and valid[g + 1]:
                tp[nt, 0] = 0.5 * (est[g, 0] + est[g + 1, 0])
                tp[nt, 1] = 0.5 * (est[g, 1] + est[g + 1, 1])
                nt += 1
    d1 = 0.0
    if nt:
        # (finite, moderate coordinates give no NaN distance: a target over ``limit``
        # decides, the others need not be measured; only the targets that can be the
        # largest are, :func:`_max_over`)
        stop = limit if _moderate(tp, nt) and _moderate(samp, m) else np.inf
        d1, over = _max_over(tp[:nt], samp, lim, 64, -np.inf, stop, 1)
        if over:
            return False
    out[0] = d1
    if d1 > limit:
        return False
    poly = np.empty((n, 2))
    for g in range(f, e + 1):
        src = est if valid[g] else W
        poly[g - f, 0] = src[g, 0]
        poly[g - f, 1] = src[g, 1]
    out[1] = _max_over(samp, poly, lim, _NEAR_SEGMENTS, -np.inf, np.inf, 1)[0]
    return True


@njit(cache=True, nogil=True, inline="always")
def _moderate(a, n):  # pragma: no cover (compiled)
    """Every coordinate of a[:n] finite and under 1e100 in size (squares and sums of them
    stay finite: no NaN from these points' distances)."""
    for i in range(n):
        if not (abs(a[i, 0]) < 1e100 and abs(a[i, 1]) < 1e100):
            return False
    return True


@njit(cache=True, nogil=True)
def _distance_over(samp, poly, lim, k):  # pragma: no cover (compiled)
    """:func:`_polyline_distance_over` compiled (a one-point polyline: the distance to it,
    libm's hypot, as :func:`point_polyline_distance`)."""
    return _distance_over_upto(samp, poly, lim, k, np.inf)[0]


@njit(cache=True, nogil=True)
def _distance_over_upto(samp, poly, lim, k, stop):  # pragma: no cover (compiled)
    """:func:`_distance_over` up to the first sample farther than ``stop`` (the same
    numbers): (the distances, how many were measured)."""
    n = poly.shape[0]
    ms = samp.shape[0]
    d = np.empty(ms)
    if n == 1:
        for t in range(ms):
            d[t] = math.hypot(samp[t, 0] - poly[0, 0], samp[t, 1] - poly[0, 1])
            if d[t] > stop:
                return d, t + 1
        return d, ms
    if n <= 2 * k + 2:
        for t in range(ms):
            d[t] = _brute_d(samp[t, 0], samp[t, 1], poly, 0, n)
            if d[t] > stop:
                return d, t + 1
        return d, ms
    fl = np.empty(max(n, ms), dtype=np.bool_)
    dx = np.empty(max(n, ms))
    dy = np.empty(max(n, ms))
    pstep = np.empty(n - 1)
    for t in range(n - 1):
        dx[t] = poly[t + 1, 0] - poly[t, 0]
        dy[t] = poly[t + 1, 1] - poly[t, 1]
    hypot_into(dx, dy, n - 1, pstep, fl)
    sstep = np.empty(max(ms - 1, 0))
    for t in range(ms - 1):
        dx[t] = samp[t + 1, 0] - samp[t, 0]
        dy[t] = samp[t + 1, 1] - samp[t, 1]
    hypot_into(dx, dy, ms - 1, sstep, fl)
    cnt = 0
    if ms:
        cnt = _over_kernel_upto(samp, sstep, poly, pstep, lim, k, d, stop)
    return d, cnt


@njit(cache=True, nogil=True)
def _max_over(samp, poly, lim, k, floor, stop, stride):  # pragma: no cover (compiled)
    """The largest distance of the points ``samp`` (in order along ``poly``) to the
    polyline ``poly`` as :func:`_distance_over_upto` measures each (the segments near its
    share of the length, exactly where over ``lim``: an upper bound, exact when over
    ``lim``), measured only where it can matter. First an upper bound of each point's
    distance: its distance to the segment a walk along the polyline reaches from the
    previous point's (a local nearest), or, where within ``floor`` (at most ``lim``) by
    the path length from the last point so bounded (the distance to a fixed polyline
    moves no more than the point does; every ``stride``-th point bounded anyway); then
    the point of the largest bound measured, and every point whose bound is over the
    largest so far and ``floor`` (a point whose bound is over ``stop``: at once).
    Returns (a distance over ``stop``, True) where there is one, else (the largest,
    False); NaN or huge coordinates: every point measured, in order (np.max's NaN).
    With ``floor`` at ``lim`` only the verdict "all within lim" is exact (points under the
    floor are not measured: the largest may be missed below it); ``stop`` at least
    ``floor``. Values at or under ``lim`` are upper bounds, and may differ from measuring
    every point (its windows): a ``stop`` under ``lim`` compares such bounds."""
    n = poly.shape[0]
    ms = samp.shape[0]
    if ms == 0:
        return -np.inf, False
    if not (_moderate(samp, ms) and _moderate(poly, n)):
        d, cnt = _distance_over_upto(samp, poly, lim, k, stop)
        best = d[0]
        for t in range(1, cnt):
            if not d[t] <= best and best == best:
                best = d[t]
        return (d[cnt - 1], True) if cnt < ms else (best, False)
    # (moderate coordinates: sqrt of the squares, not libm's slower hypot; the lengths
    # place the windows and bound the moves, both with room for the rounding)
    cs = np.empty(ms)
    cs[0] = 0.0
    for t in range(ms - 1):
        dx = samp[t + 1, 0] - samp[t, 0]
        dy = samp[t + 1, 1] - samp[t, 1]
        cs[t + 1] = cs[t] + math.sqrt(dx * dx + dy * dy)
    cum = np.empty(n)
    cum[0] = 0.0
    for t in range(n - 1):
        dx = poly[t + 1, 0] - poly[t, 0]
        dy = poly[t + 1, 1] - poly[t, 1]
        cum[t + 1] = cum[t] + math.sqrt(dx * dx + dy * dy)
    scale = cs[ms - 1] > 0.0
    r = cum[n - 1] / cs[ms - 1] if scale else 1.0
    tol = 1e-9 * (1.0 + cs[ms - 1] + cum[n - 1])
    fl = min(floor, lim)
    ub = np.empty(ms)
    top = 0
    j = 0
    la = -1
    for t in range(ms):
        px = samp[t, 0]
        py = samp[t, 1]
        if la >= 0 and t - la < stride:
            b = ub[la] + (cs[t] - cs[la]) + tol
            if b <= fl:
                ub[t] = b
                continue
        if n == 1:
            ub[t] = math.hypot(px - poly[0, 0], py - poly[0, 1])
        else:
            dj = _seg_d2(px, py, poly, j, True)
            while j + 2 < n:
                dn = _seg_d2(px, py, poly, j + 1, True)
                if dn > dj:
                    break
                j += 1
                dj = dn
            while j > 0:
                dn = _seg_d2(px, py, poly, j - 1, True)
                if dn >= dj:
                    break
                j -= 1
                dj = dn
            ub[t] = math.sqrt(dj) * (1.0 + 1e-12) + tol
        la = t
        if ub[t] > stop:  # (a point possibly over the stop: measured at once)
            d = _one_over(px, py, poly, n, cum, cs[t] * r if scale else cs[t], k, lim,
                          min(fl, stop))
            if d > stop:
                return d, True
            ub[t] = d
        if ub[t] > ub[top]:
            top = t
    best = -np.inf
    for rnd in range(2):
        for t in range(ms):
            if rnd == 0 and t != top or rnd == 1 and (t == top or ub[t] <= max(best, fl)):
                continue
            d = _one_over(samp[t, 0], samp[t, 1], poly, n, cum, cs[t] * r if scale else cs[t],
                          k, lim, min(max(best, fl), stop))
            if d > stop:
                return d, True
            best = max(best, d)
    return best, False


@njit(cache=True, nogil=True)
def _one_over(px, py, poly, n, cum, val, k, lim, need):  # pragma: no cover (compiled)
    """One point's distance to the polyline as :func:`_over_kernel_upto` measures it
    (``val`` its share of the polyline's length ``cum``), or where the window's distance
    is ``need`` or less, that (an upper bound: the exact one changes nothing there)."""
    if n == 1:
        return math.hypot(px - poly[0, 0], py - poly[0, 1])
    if n <= 2 * k + 2:
        return _brute_d(px, py, poly, 0, n)
    at = _share_at(cum, n, val)
    d = _win_d(px, py, poly, 0, n - 1, at, k, cum, np.inf)
    if d > lim and d > need:
        d = _full_d(px, py, poly, 0, n, at, cum, d)
    return d


def _estimates_off(points, is_cubic, tail, gfirst, glast, sr, est, valid):
    """Per segment of ``sr``: the largest distance of a smooth point's estimate (or of the
    middle between two smooth neighbours' estimates) to it."""
    n = glast[sr] - gfirst[sr] + 1
    pid = np.repeat(np.arange(len(sr)), n)
    idx = np.repeat(gfirst[sr], n) + np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
    pair = np.flatnonzero(valid[idx[:-1]] & valid[idx[:-1] + 1] & (pid[1:] == pid[:-1]))
    keep = valid[idx]
    tp = np.concatenate([est[idx[keep]], 0.5 * (est[idx[pair]] + est[idx[pair] + 1])])
    pid = np.concatenate([pid[keep], pid[pair]])
    off = np.zeros(len(sr))
    ln = ~is_cubic[sr[pid]]
    if ln.any():
        s = sr[pid[ln]]
        d = point_segment_distance(tp[ln], points[tail[s] - 1], points[tail[s]])
        np.maximum.at(off, pid[ln], d)
    if (~ln).any():
        cs = np.flatnonzero(is_cubic[sr])
        ctrl = np.stack([points[tail[sr[cs]] - 1 + k] for k in range(4)], axis=1)
        loc = np.full(len(sr), -1)
        loc[cs] = np.arange(len(cs))
        _, d = nearest_on_cubic_each(ctrl, loc[pid[~ln]], tp[~ln], seeds=12, iters=3)
        np.maximum.at(off, pid[~ln], d)
    return off


@njit(cache=True, nogil=True)
def _screen_segments(points, tail, is_cubic, gfirst, glast, sr, est, valid, lim,
                     out):  # pragma: no cover (compiled)
    """out[i]: an upper bound of :func:`_estimates_off` for segment sr[i], exact for a
    line; for a cubic, each target's distance to the point Newton finds from the previous
    target's parameter when under lim[i], else to the nearest of 17 samples or the point
    Newton finds from there (so out[i] >= lim[i] whenever the measure is)."""
    sx = np.empty(17)
    sy = np.empty(17)
    for i in range(sr.shape[0]):
        s = sr[i]
        r = tail[s] - 1
        cubic = is_cubic[s]
        x0, y0 = points[r, 0], points[r, 1]
        ax = ay = bx = by = cx = cy = vx = vy = den = 0.0
        if cubic:
            ax = -x0 + 3.0 * points[r + 1, 0] - 3.0 * points[r + 2, 0] + points[r + 3, 0]
            ay = -y0 + 3.0 * points[r + 1, 1] - 3.0 * points[r + 2, 1] + points[r + 3, 1]
            bx = 3.0 * x0 - 6.0 * points[r + 1, 0] + 3.0 * points[r + 2, 0]
            by = 3.0 * y0 - 6.0 * points[r + 1, 1] + 3.0 * points[r + 2, 1]
            cx = 3.0 * (points[r + 1, 0] - x0)
            cy = 3.0 * (points[r + 1, 1] - y0)
            for k in range(17):
                u = k / 16.0
                sx[k] = ((ax * u + bx) * u + cx) * u + x0
                sy[k] = ((ay * u + by) * u + cy) * u + y0
        else:
            vx = points[r + 1, 0] - x0
            vy = points[r + 1, 1] - y0
            den = vx * vx + vy * vy
        worst = 0.0
        lim2 = lim[i] * lim[i]
        up = 0.0
        for g in range(gfirst[s], glast[s] + 1):
            if not valid[g]:
                continue
            for half in range(2):
                if half == 0:
                    px, py = est[g, 0], est[g, 1]
                elif g < glast[s] and valid[g + 1]:
                    px = 0.5 * (est[g, 0] + est[g + 1, 0])
                    py = 0.5 * (est[g, 1] + est[g + 1, 1])
                else:
                    continue
                if not cubic:
                    t = 0.0
                    if den > 0.0:
                        t = min(1.0, max(0.0, ((px - x0) * vx + (py - y0) * vy) / den))
                    d2 = (x0 + t * vx - px) ** 2 + (y0 + t * vy - py) ** 2
                else:
                    # first Newton from the previous target's parameter: enough when it
                    # finds a point nearer than ``lim`` (the bound is only compared to it)
                    u = up
                    for _ in range(3):
                        rx = ((ax * u + bx) * u + cx) * u + x0 - px
                        ry = ((ay * u + by) * u + cy) * u + y0 - py
                        d1x = (3.0 * ax * u + 2.0 * bx) * u + cx
                        d1y = (3.0 * ay * u + 2.0 * by) * u + cy
                        fp = (6.0 * ax * u + 2.0 * bx) * rx + (6.0 * ay * u + 2.0 * by) * ry \
                            + d1x * d1x + d1y * d1y
                        if not fp > 0.0:
                            break
                        u = min(1.0, max(0.0, u - (d1x * rx + d1y * ry) / fp))
                    rx = ((ax * u + bx) * u + cx) * u + x0 - px
                    ry = ((ay * u + by) * u + cy) * u + y0 - py
                    d2 = rx * rx + ry * ry
                    if d2 < lim2:
                        up = u
                        worst = max(worst, d2)
                        continue
                    uw = u
                    kb = 0
                    db = np.inf
                    for k in range(17):
                        e2 = (sx[k] - px) ** 2 + (sy[k] - py) ** 2
                        if e2 < db:
                            db = e2
                            kb = k
                    if db < d2:
                        d2 = db
                        uw = kb / 16.0
                    u = kb / 16.0
                    for _ in range(4):
                        rx = ((ax * u + bx) * u + cx) * u + x0 - px
                        ry = ((ay * u + by) * u + cy) * u + y0 - py
                        d1x = (3.0 * ax * u + 2.0 * bx) * u + cx
                        d1y = (3.0 * ay * u + 2.0 * by) * u + cy
                        fp = (6.0 * ax * u + 2.0 * bx) * rx + (6.0 * ay * u + 2.0 * by) * ry \
                            + d1x * d1x + d1y * d1y
                        if not fp > 0.0:
                            break
                        u = min(1.0, max(0.0, u - (d1x * rx + d1y * ry) / fp))
                    rx = ((ax * u + bx) * u + cx) * u + x0 - px
                    ry = ((ay * u + by) * u + cy) * u + y0 - py
                    up = uw
                    if rx * rx + ry * ry < d2:
                        d2 = rx * rx + ry * ry
                        up = u
                worst = max(worst, d2)
        out[i] = math.sqrt(worst)


@njit(cache=True, nogil=True)
def _split_candidates(W, est, valid, f, e, p0, p1, gap, lo, hi,
                      out):  # pragma: no cover (compiled)
    """:meth:`_Stretch.split`'s split points (compiled), ascending, those in lo..hi into
    ``out``; returns their number: both ends of every step of W[f..e] longer than ``gap``,
    the first and the last smooth point (``valid``), the smooth point whose estimate lies
    farthest from the chord p0-p1 (:func:`point_segment_distance`'s arithmetic; the first
    of equals, a NaN first, as np.argmax), the middle (f + e) // 2."""
    n = e - f + 1
    take = np.zeros(n, dtype=np.bool_)
    for i in range(n - 1):
        if math.hypot(W[f + i + 1, 0] - W[f + i, 0], W[f + i + 1, 1] - W[f + i, 1]) > gap:
            take[i] = True
            take[i + 1] = True
    abx = p1[0] - p0[0]
    aby = p1[1] - p0[1]
    den = abx * abx + aby * aby
    first = -1
    last = -1
    far = -1
    dmax = 0.0
    for i in range(n):
        if not valid[f + i]:
            continue
        if first < 0:
            first = i
        last = i
        apx = est[f + i, 0] - p0[0]
        apy = est[f + i, 1] - p0[1]
        t = (apx * abx + apy * aby) / den if den > 0.0 else 0.0
        if t == t:  # (np.clip: NaN kept)
            t = min(max(t, 0.0), 1.0)
        d = math.hypot(apx - t * abx, apy - t * aby)
        if far < 0 or (d > dmax and dmax == dmax) or (d != d and dmax == dmax):
            far = i
            dmax = d
    if first >= 0:
        take[first] = True
        take[last] = True
        take[far] = True
    take[(f + e) // 2 - f] = True
    nc = 0
    for i in range(max(lo - f, 0), min(hi - f, n - 1) + 1):
        if take[i]:
            out[nc] = f + i
            nc += 1
    return nc


class _Stretch:
    """The state of :func:`_smooth_stretches` on one call: the input, the estimates, the
    bound and step per path."""

    def __init__(self, W, est, valid, bound, quant, budget):
        self.W, self.est, self.valid, self.bound, self.quant = W, est, valid, bound, quant
        self.budget = budget  # re-fits left, per path (each path's own: the same result
        # whatever other paths are fitted with it)

    def spend(self, o) -> None:
        """One re-fit of path o's budget used without making it (as :meth:`shapes`)."""
        if self.budget[o] > 0:
            self.budget[o] -= 1

    def shapes(self, p0, p1, f, e, o, limit, line_ok, old=None):
        """The best piece from p0 to p1 over the input points f..e: the line (when
        ``line_ok``), the least-squares cubic, the cubic ``old`` with its ends moved (its
        inner control points along): ((d1, d2), ctrl) or None (also when the budget is
        spent)."""
        if self.budget[o] <= 0:
            return None
        self.budget[o] -= 1
        q = float(self.quant[o])
        alts = []
        if line_ok:
            alts.append(np.array([p0, p1], dtype=np.float64))
        if e - f + 1 >= _STRETCH_CUBIC:
            c = _ls_cubic(p0, p1, _stretch_targets(self.W, self.est, self.valid, f, e, q))
            if c is not None:
                alts.append(c)
        if old is not None and len(old) == 4:
            c = old.copy()
            c[:2] += p0 - old[0]
            c[2:] += p1 - old[3]
            alts.append(c)
        scored = []
        for c in alts:
            r = _design_off(self.W, self.est, self.valid, c, f, e, _STRETCH_LOOK * q, limit)
            if r is not None:
                scored.append((max(r), len(scored), r, c))
        for _, _, r, c in sorted(scored, key=lambda x: x[:2]):
            if _seg_fits(self.W, c, f, e, float(self.bound[o]), _JOINT_STEP * q):
                return r, c
        return None

    def split(self, p0, p1, f, e, o, limit):
        """The best two pieces from p0 to p1 over f..e, split at an input point m (its
        estimate when smooth): at the ends of long gaps, at the smooth stretch's ends, at
        the estimate farthest from the chord: ((d1, d2), [(ctrl, f, m), (ctrl, m, e)])."""
        W, est, valid = self.W, self.est, self.valid
        lo, hi = f + _STRETCH_PIECE, e - _STRETCH_PIECE
        if hi < lo:
            return None
        q = float(self.quant[o])
        cand = np.empty(e - f + 1, dtype=np.int64)
        nc = _split_candidates(W, est, valid, f, e, np.asarray(p0, dtype=np.float64),
                               np.asarray(p1, dtype=np.float64), _STRETCH_GAP * q, lo, hi,
                               cand)
        best = None
        for m in cand[:nc].tolist():
            pm = (np.clip(est[m], W[m] - 0.5 * q, W[m] + 0.5 * q) if valid[m]
                  else W[m].astype(np.float64))
            a = self.shapes(p0, pm, f, m, o, limit, True)
            if a is None:
                continue
            b = self.shapes(pm, p1, m, e, o, limit, True)
            if b is None:
                continue
            r = (max(a[0][0], b[0][0]), max(a[0][1], b[0][1]))
            if best is None or max(r) < max(best[0]):
                best = (r, [(a[1], f, m), (b[1], m, e)])
        return best


#: rounded input: the smooth-stretch repair does not move a joint where the fit's segments
#: turn this many degrees or more onto its estimate (a corner inside the estimate's window:
#: its quadratic rounds the corner off; FreeMono Bold "$" at em 2048, a 32-degree corner
#: between two curves moved 0.6 off the design's corner, where the corner's own estimate had
#: put it at 0.06 and the rounded input is 0.45). Only the joint's own estimate is dropped:
#: a false corner of the rounding (a design line's end rounded a unit off the curve after
#: it) keeps the estimates of its segments' points, which repair a cubic twisted there
#: (Cantarell "a" at em 1500: 1.08 from the design with the window's estimates dropped too)
_STRETCH_CORNER_DEG = 15.0


def _joint_tangents(points, tail, step, a, b):
    """The end tangent of each segment ``a`` and the start tangent of each segment ``b``
    (unnormalised: a line's chord, a cubic's end handle), from the shared control points."""
    e = tail[a] + step[a]
    return points[e - 1] - points[e - 2], points[tail[b]] - points[tail[b] - 1]


def _no_estimates_at_corners(points, tail, step, gfirst, seg_owner, valid):
    """``valid`` (per input point, in place) False at each joint of the segments
    (``points``, ``tail``, ``step``; ``gfirst`` their first input points, ``seg_owner`` their
    paths) where they turn ``_STRETCH_CORNER_DEG`` degrees or more."""
    jb = np.flatnonzero(seg_owner[1:] == seg_owner[:-1]) + 1
    if len(jb) == 0:
        return
    t_end, t_start = _joint_tangents(points, tail, step, jb - 1, jb)
    with np.errstate(invalid="ignore", divide="ignore"):
        corner = turn_deg(t_end, t_start) >= _STRETCH_CORNER_DEG
    jb = jb[corner]
    if len(jb) == 0:
        return
    valid[gfirst[jb]] = False


def _smooth_stretches(W, arc, points, is_cubic, tail, step, gfirst, glast, seg_owner, quant,
                      bound, changed):
    """Rounded input, after :func:`_joints_on_the_design`: the segments that lie
    ``_STRETCH_OFF`` quanta or more from the design estimate of one of their input points
    inside a smooth stretch (a line over a gently curved stretch, a joint left on its
    rounded point) are repaired, worst first: the segment re-fitted between its ends (a
    line made the least-squares cubic), or a joint of it moved onto its estimate (inside
    its rounding square) with the two segments there re-fitted (a line kept a line or made
    a least-squares cubic, a cubic's inner control points fitted by least squares with its
    ends fixed or moved along); where none of those helps, the segment (or, with the
    joint moved, one of the two) split in two at an input point (``_STRETCH_SPLITS``). A
    repair is kept only when every new segment stays within ``bound`` (per path) of its
    input points and polyline (:func:`_seg_fits`) and it brings the distance to the
    estimates down by ``_STRETCH_GAIN`` quanta; at most ``_STRETCH_BUDGET`` re-fits (and
    one per ``_STRETCH_PER`` input points). Returns the segments (is_cubic, points,
    tail, step, gfirst, glast, seg_owner, changed) rebuilt, or the inputs when none
    changed."""
    ns = len(is_cubic)
    unchanged = (is_cubic, points, tail, step, gfirst, glast, seg_owner, changed)
    if ns == 0:
        return unchanged
    # the rounded paths with enough input points for an estimate
    cut = np.searchsorted(seg_owner, np.arange(len(quant) + 1))
    has = cut[1:] > cut[:-1]
    ps = gfirst[np.minimum(cut[:-1], ns - 1)]
    pe = glast[np.maximum(cut[1:] - 1, 0)]
    paths = np.flatnonzero(has & (quant > 0.0) & (pe - ps >= 2 * _STRETCH_SIDE))
    if len(paths) == 0:
        return unchanged
    take = np.zeros(len(quant), dtype=bool)
    take[paths] = True
    rp = take[seg_owner]
    est, valid = _stretch_estimates(W, arc, ps[paths], pe[paths], quant[paths])
    _no_estimates_at_corners(points, tail, step, gfirst, seg_owner, valid)
    # per segment: the largest distance of a smooth point's estimate (or of the middle
    # between two smooth neighbours' estimates) to it
    sr = np.flatnonzero(rp)
    thr = _STRETCH_OFF * quant[seg_owner[sr]]
    # screened first with a compiled upper bound (the nearest of 17 samples, then Newton),
    # measured as below only where that reaches the threshold
    ub = np.empty(len(sr))

    def chunk(lo: int, hi: int) -> None:
        _screen_segments(points, tail, is_cubic, gfirst, glast, sr[lo:hi], est, valid,
                         thr[lo:hi], ub[lo:hi])

    run_chunks(chunk, glast[sr] - gfirst[sr] + 1)
    off = np.zeros(len(sr))
    cand = np.flatnonzero(ub >= thr)
    if len(cand):
        off[cand] = _estimates_off(points, is_cubic, tail, gfirst, glast, sr[cand], est, valid)
    bad = off >= _STRETCH_OFF * quant[seg_owner[sr]]
    # the budgets are each path's own (a path's result does not depend on the paths fitted
    # with it): re-fits, and splits at most a share of its segments
    budget = np.zeros(len(quant), dtype=np.int64)
    budget[paths] = _STRETCH_BUDGET + (pe[paths] - ps[paths] + 1) // _STRETCH_PER
    st = _Stretch(W, est, valid, bound, quant, budget)
    splits = np.rint(_STRETCH_SPLITS * np.bincount(seg_owner[sr], minlength=len(quant))
                     ).astype(np.int64)
    rep: dict[int, list] = {}
    done = np.zeros(ns, dtype=bool)
    oldoff: dict[int, tuple[float, float]] = {}

    def before(x: int) -> tuple[float, float]:
        """Segment x's distances to the estimates as fitted (:func:`_design_off`; once)."""
        r = oldoff.get(x)
        if r is None:
            r = oldoff[x] = cast(tuple[float, float], _design_off(
                W, est, valid, _seg_ctrl(points, is_cubic, tail, x), gfirst[x], glast[x],
                _STRETCH_LOOK * float(quant[seg_owner[x]])))
        return r

    offb = off[bad]
    bs = sr[bad]
    # worst first, each path's own list: a repair touches only its own path's segments,
    # budget and splits, so the lists of chunks of paths run at once on the kernel threads
    # (the compiled checks release the GIL; the same result whatever the chunks)
    order = np.argsort(-offb, kind="stable")
    owner = seg_owner[bs[order]]
    by_path = np.argsort(owner, kind="stable")
    order = order[by_path]
    pcut = np.searchsorted(owner[by_path], np.arange(len(quant) + 1))

    def repairs(lo: int, hi: int) -> None:  # (the paths lo..hi - 1)
        for k in order[pcut[lo]:pcut[hi]].tolist():
            s = int(bs[k])
            o = int(seg_owner[s])
            if done[s] or st.budget[o] <= 0:
                continue
            # a split beyond the path's share where the segment lies far off the estimates
            may_split = splits[o] > 0 or offb[k] >= _STRETCH_SPLIT_FAR * quant[o]
            q = float(quant[o])
            best = None  # (split used, (d1, d2), {segment: [(ctrl, first, last)]})

            def consider(new, used, q=q):
                nonlocal best
                segs = list(new)
                o1 = max(before(x)[0] for x in segs)
                o2 = max(before(x)[1] for x in segs)
                n1 = max(r[0] for r, _ in new.values())
                n2 = max(r[1] for r, _ in new.values())
                if n1 > o1 - _STRETCH_GAIN * q or n2 > max(o2, n1):
                    return
                if best is None or (used, max(n1, n2)) < (best[0], max(best[1])):
                    best = (used, (n1, n2), {x: p for x, (_, p) in new.items()})

            c0 = _seg_ctrl(points, is_cubic, tail, s)
            f, e = int(gfirst[s]), int(glast[s])
            lim = before(s)[0] - _STRETCH_GAIN * q
            r = st.shapes(c0[0], c0[-1], f, e, o, lim, False, None)
            if r is not None:
                consider({s: (r[0], [(r[1], f, e)])}, 0)
            joints = []
            for a, b in ((s - 1, s), (s, s + 1)):
                if a < 0 or b >= ns or seg_owner[a] != o or seg_owner[b] != o or done[a] \
                        or done[b] or glast[a] <= gfirst[a] or glast[b] <= gfirst[b]:
                    continue
                j = int(gfirst[b])
                if valid[j]:
                    joints.append((a, b, np.clip(est[j], W[j] - 0.5 * q, W[j] + 0.5 * q)))
            for a, b, v in joints:
                ca = _seg_ctrl(points, is_cubic, tail, a)
                cb = _seg_ctrl(points, is_cubic, tail, b)
                fa, ea, fb, eb = int(gfirst[a]), int(glast[a]), int(gfirst[b]), int(glast[b])
                lim = max(before(a)[0], before(b)[0]) - _STRETCH_GAIN * q
                ra = st.shapes(ca[0], v, fa, ea, o, lim, not is_cubic[a], ca)
                if ra is None and (best is not None and best[0] == 0 or not may_split):
                    # (rb could serve nothing: no pair without ra, no split here; its re-fit
                    # is counted all the same, so the budget and the result stay the same)
                    st.spend(o)
                    continue
                rb = st.shapes(v, cb[-1], fb, eb, o, lim, not is_cubic[b], cb)
                if ra is not None and rb is not None:
                    consider({a: (ra[0], [(ra[1], fa, ea)]), b: (rb[0], [(rb[1], fb, eb)])}, 0)
                if best is not None and best[0] == 0 or not may_split:
                    continue
                if rb is not None:
                    sa = st.split(ca[0], v, fa, ea, o, lim)
                    if sa is not None:
                        consider({a: (sa[0], sa[1]), b: (rb[0], [(rb[1], fb, eb)])}, 1)
                if ra is not None:
                    sb = st.split(v, cb[-1], fb, eb, o, lim)
                    if sb is not None:
                        consider({a: (ra[0], [(ra[1], fa, ea)]), b: (sb[0], sb[1])}, 1)
            if (best is None or best[0] == 1) and may_split:
                r = st.split(c0[0], c0[-1], f, e, o, before(s)[0] - _STRETCH_GAIN * q)
                if r is not None:
                    consider({s: (r[0], r[1])}, 1)
            if best is not None:
                splits[o] -= best[0]
                for x, p in best[2].items():
                    rep[x] = p
                    done[x] = True

    run_chunks(repairs, np.bincount(seg_owner[bs], (glast - gfirst + 1)[bs], len(quant)))
    # the joints still on their input point, ``_STRETCH_JOINT`` quanta or more from their
    # estimate: moved onto it with both segments re-fitted, where neither of them gets
    # farther from the estimates
    jb = np.flatnonzero((seg_owner[1:] == seg_owner[:-1]) & rp[1:]) + 1
    jb = jb[(glast[jb] > gfirst[jb]) & (glast[jb - 1] > gfirst[jb - 1])]
    g = gfirst[jb]
    jb = jb[valid[g] & (points[tail[jb] - 1] == W[g]).all(axis=1)]
    g = gfirst[jb]
    qj = quant[seg_owner[jb]][:, None]
    vj = np.clip(est[g], W[g] - 0.5 * qj, W[g] + 0.5 * qj)
    far = np.hypot(*(vj - W[g]).T) >= _STRETCH_JOINT * qj[:, 0]
    for b, v in zip(jb[far].tolist(), vj[far], strict=True):
        a = b - 1
        o = int(seg_owner[b])
        if done[a] or done[b] or st.budget[o] <= 0:
            continue
        ca = _seg_ctrl(points, is_cubic, tail, a)
        cb = _seg_ctrl(points, is_cubic, tail, b)
        fa, ea, fb, eb = int(gfirst[a]), int(glast[a]), int(gfirst[b]), int(glast[b])
        oa, ob = before(a), before(b)
        ra = st.shapes(ca[0], v, fa, ea, o, oa[0], not is_cubic[a], ca)
        if ra is None or ra[0][1] > max(oa[1], ra[0][0]):
            continue
        rb = st.shapes(v, cb[-1], fb, eb, o, ob[0], not is_cubic[b], cb)
        if rb is None or rb[0][1] > max(ob[1], rb[0][0]):
            continue
        rep[a] = [(ra[1], fa, ea)]
        rep[b] = [(rb[1], fb, eb)]
        done[a] = done[b] = True
    # the joints still on their input point where no estimate holds (a corner, the end of
    # a smooth stretch): moved onto the one-sided estimates of the smooth stretches that
    # end there (their mean where both sides have one and they agree within
    # ``_STRETCH_CORNER_AGREE`` quanta), inside the rounding square, where both segments
    # then fit and the one that has estimates gets no farther from them
    jb = np.flatnonzero((seg_owner[1:] == seg_owner[:-1]) & rp[1:]) + 1
    jb = jb[(glast[jb] > gfirst[jb]) & (glast[jb - 1] > gfirst[jb - 1])]
    g = gfirst[jb]
    jb = jb[~valid[g] & (points[tail[jb] - 1] == W[g]).all(axis=1) & ~done[jb] & ~done[jb - 1]]
    if len(jb) and (st.budget > 0).any():
        g = gfirst[jb]
        own = seg_owner[jb]
        q1 = quant[own]
        pfirst = gfirst[np.searchsorted(seg_owner, own)]
        plast = glast[np.searchsorted(seg_owner, own, side="right") - 1]
        side = np.zeros((len(jb), 2, 3))
        _side_estimates(W, arc, g, pfirst, plast, q1, _JOINT_SIDE, _STRETCH_SIDE,
                        _JOINT_SMOOTH, _STRETCH_GAP, _STRETCH_SPAN, side)
        has = side[:, :, 2] > 0.0
        both = has.all(axis=1)
        agree = np.hypot(*(side[:, 0, :2] - side[:, 1, :2]).T) <= _STRETCH_CORNER_AGREE * q1
        use = has.any(axis=1) & (~both | agree)
        n = np.maximum(has.sum(axis=1), 1)
        vc = (side[:, :, :2] * has[:, :, None]).sum(axis=1) / n[:, None]
        qc = q1[:, None]
        vc = np.clip(vc, W[g] - 0.5 * qc, W[g] + 0.5 * qc)
        use &= np.hypot(*(vc - W[g]).T) >= _STRETCH_JOINT * q1
        for b, v in zip(jb[use].tolist(), vc[use], strict=True):
            a = b - 1
            o = int(seg_owner[b])
            if done[a] or done[b] or st.budget[o] <= 0:
                continue
            ca = _seg_ctrl(points, is_cubic, tail, a)
            cb = _seg_ctrl(points, is_cubic, tail, b)
            fa, ea, fb, eb = int(gfirst[a]), int(glast[a]), int(gfirst[b]), int(glast[b])
            oa, ob = before(a), before(b)
            ra = st.shapes(ca[0], v, fa, ea, o, oa[0], not is_cubic[a], ca)
            if ra is None:
                continue
            rb = st.shapes(v, cb[-1], fb, eb, o, ob[0], not is_cubic[b], cb)
            if rb is None:
                continue
            rep[a] = [(ra[1], fa, ea)]
            rep[b] = [(rb[1], fb, eb)]
            done[a] = done[b] = True
    if not rep:
        return unchanged
    return _rebuilt(points, is_cubic, tail, step, gfirst, glast, seg_owner, changed, rep)


#: rounded input: a connector (a line over no input step, from a moved vertex to its input
#: point, :func:`_valid_lines`) is taken out where the vertex can sit at one place for both
#: of its neighbours: the first of these shares of the way from the input point to the
#: moved vertex that keeps both within the bound (1: the line beside it takes the moved
#: vertex; 0: the other segment's end goes back to the input point)
_CONNECTOR_SHARES = (1.0, 0.75, 0.5, 0.25, 0.0)
#: ... the segments' curve-to-polyline checks sampled at most this far apart (units of q;
#: the check keeps half of it spare: coarser than the joints' moves, ``_JOINT_STEP``, for a
#: fraction of the time, at the cost of a few connectors kept)
_CONNECTOR_STEP = 0.1


def _ends_moved_many(points, is_cubic, tail, segs, at_start, dv, along=True):
    """:func:`_end_moved` on arrays: the control points (n, 4, 2) of the segments ``segs``
    (a line's in its first two rows, the others zeros), each with its start (``at_start``)
    or its end moved by ``dv``, a cubic's inner control point there moved along (``along``;
    else it stays)."""
    C4 = np.zeros((len(segs), 4, 2))
    r0 = tail[segs] - 1
    cb = is_cubic[segs]
    C4[:, :2] = points[r0[:, None] + np.arange(2)]
    C4[cb, 2:] = points[r0[cb, None] + np.arange(2, 4)]
    C4[at_start, 0] += dv[at_start]
    if along:
        C4[at_start & cb, 1] += dv[at_start & cb]
    e = ~at_start & ~cb
    C4[e, 1] += dv[e]
    e = ~at_start & cb
    C4[e, 3] += dv[e]
    if along:
        C4[e, 2] += dv[e]
    return C4


def _connectors_out(W, points, is_cubic, tail, step, gfirst, glast, seg_owner, quant, bound,
                    changed, wstep=None):
    """Rounded input: the connectors :func:`_valid_lines` left (a line over no input step
    between a moved vertex and its input point: a segment of its own, 35 of them on
    FreeSerif Italic at em 2048) taken out where the joint can sit at one point for both
    segments beside it (``_CONNECTOR_SHARES`` of the way from the input point to the moved
    vertex), both then within ``bound`` (per path) of their input points and polyline
    (:func:`_seg_fits_many`, as the joints' moves). A connector at a path's first or last
    segment stays. Returns the segments (is_cubic, points, tail, step, gfirst, glast,
    seg_owner, changed) rebuilt, or the inputs when none changed."""
    ns = len(is_cubic)
    unchanged = (is_cubic, points, tail, step, gfirst, glast, seg_owner, changed)
    if ns < 3:
        return unchanged
    c = np.flatnonzero(~is_cubic & (gfirst == glast))
    c = c[(c > 0) & (c < ns - 1)]
    c = c[(seg_owner[c - 1] == seg_owner[c]) & (seg_owner[c + 1] == seg_owner[c])]
    c = c[quant[seg_owner[c]] > 0.0]
    # (no two connectors share a neighbour: every other one of a run of them)
    c = c[np.r_[True, c[1:] > c[:-1] + 2]] if len(c) else c
    if len(c) == 0:
        return unchanged
    p0 = points[tail[c] - 1]
    p1 = points[tail[c]]
    g = gfirst[c]
    # the input point end X and the moved vertex end Y; ``lin`` the segment at X (the
    # thinned line), ``oth`` the one at Y
    x_first = (p0 == W[g]).all(axis=1)
    x_last = (p1 == W[g]).all(axis=1)
    ok = x_first ^ x_last
    c, p0, p1, g, x_first = c[ok], p0[ok], p1[ok], g[ok], x_first[ok]
    if len(c) == 0:
        return unchanged
    X = np.where(x_first[:, None], p0, p1)
    Y = np.where(x_first[:, None], p1, p0)
    lin = np.where(x_first, c - 1, c + 1)
    oth = np.where(x_first, c + 1, c - 1)
    if wstep is None:
        wstep = _step_lengths(W)
    bj = np.asarray(bound, dtype=np.float64)[seg_owner[c]]
    h = _CONNECTOR_STEP * quant[seg_owner[c]]
    rep: dict[int, list] = {}
    rem = np.arange(len(c))
    # per connector its two segments: 0 the one at X (``lin``), 1 the one at Y (``oth``);
    # the one checked first is a line where one is (lines are cheap and mostly fail), the
    # other only where that one fits (a pair passes only when both do)
    segs2 = np.stack([lin, oth])
    at2 = np.stack([X, Y])
    after2 = segs2 > c
    cub2 = is_cubic[segs2]
    first_k = (cub2[0] & ~cub2[1]).astype(np.intp)
    for share in _CONNECTOR_SHARES:
        if len(rem) == 0:
            break
        # the two segments with the joint at the new place; only those that change are
        # checked (at share 1 the segment at the moved vertex stays as it is, at share 0
        # the thinned line)
        v = X[rem] + share * (Y[rem] - X[rem])
        C4 = np.zeros((2, len(rem), 4, 2))
        moved = np.empty((2, len(rem)), dtype=bool)
        for k in (0, 1):
            dv = v - at2[k, rem]
            moved[k] = (dv != 0.0).any(axis=1)
            # the segment after the connector starts at the joint, the one before ends there
            C4[k] = _ends_moved_many(points, is_cubic, tail, segs2[k, rem], after2[k, rem], dv)
        fits = np.ones((2, len(rem)), dtype=bool)
        fk = first_k[rem]
        todo = np.arange(len(rem))
        for stage in (0, 1):
            kk = fk[todo] if stage == 0 else 1 - fk[todo]
            sel = moved[kk, todo]
            t_, k_ = todo[sel], kk[sel]
            if len(t_):
                sg = segs2[k_, rem[t_]]
                fits[k_, t_] = _seg_fits_arrays(W, wstep, C4[k_, t_], cub2[k_, rem[t_]],
                                                gfirst[sg], glast[sg], bj[rem[t_]],
                                                h[rem[t_]])
            todo = todo[fits[kk, todo]]
        both = fits[0] & fits[1]
        for t in np.flatnonzero(both).tolist():
            i = int(rem[t])
            ci = int(c[i])
            rep[ci] = []
            for k in (0, 1):
                x = int(segs2[k, i])
                rep[x] = [(C4[k, t] if cub2[k, i] else C4[k, t, :2], int(gfirst[x]),
                           int(glast[x]))]
        rem = rem[~both]
    if not rep:
        return unchanged
    return _rebuilt(points, is_cubic, tail, step, gfirst, glast, seg_owner, changed, rep)


#: rounded input: a short line (at most ``_TIP_SHORT`` quanta, over 1 to ``_TIP_STEPS`` input
#: steps) between two corners that turn the same way, ``_TIP_TURN_DEG`` degrees or more together,
#: is a tip the thinning cut (its point within the bound of the chord of its neighbours)
_TIP_SHORT = 2.0
_TIP_STEPS = 3
_TIP_TURN_DEG = 90.0
#: ... and a line over 2 or more input steps (no design line: that is written as one step
#: between its two rounded ends) up to ``_TIP_SHORT_MANY`` quanta long between corners that
#: turn ``_TIP_TURN_MANY`` degrees or more together: the thinning kept the input points on
#: either side of a corner's and dropped the corner's own (P052 Bold Italic "$" at em 2048,
#: a 107-degree corner between two curves: a 3.2-unit line over 2 steps, 0.82 from the
#: design where the rounded input is 0.39)
_TIP_SHORT_MANY = 4.0
_TIP_TURN_MANY = 60.0
#: ... the two segments' curve-to-polyline checks sampled this far apart (units of q; the
#: check keeps half of it spare: at the connectors' coarser step a cubic the fitter passed
#: near the bound fails before it moves, P052 Bold Italic "7" at em 2048)
_TIP_STEP = 0.02


def _moved_end_refits(W, wstep, arc, points, is_cubic, tail, segs, at_start, dv, first, last,
                      bound, h, C4, ok):
    """The cubics among ``segs`` not ``ok`` with their start (``at_start``) or end moved by
    ``dv`` (:func:`_ends_moved_many`, whose control points with the handle moved along are
    ``C4``, changed in place) tried again: with that handle left where it was, then with both
    handle lengths re-fitted over their input points first..last (Gauss-Newton, the end
    tangents' directions kept; ``arc`` given). A move of over a unit carries a long cubic's
    side off its points when the handle moves along. Returns ``ok`` with those that now fit
    within ``bound`` (:func:`_seg_fits_arrays`)."""
    ok = ok.copy()
    r = np.flatnonzero(~ok & is_cubic[segs])
    if len(r):
        C2 = _ends_moved_many(points, is_cubic, tail, segs[r], at_start[r], dv[r], along=False)
        f2 = _seg_fits_arrays(W, wstep, C2, is_cubic[segs[r]], first[r], last[r], bound[r],
                              h[r])
        C4[r[f2]] = C2[f2]
        ok[r[f2]] = True
        r = r[~f2]
    if len(r) and arc is not None:
        C2 = C4[r]
        t0 = C2[:, 1] - C2[:, 0]
        t3 = C2[:, 3] - C2[:, 2]
        t0 = t0 / np.hypot(*t0.T)[:, None]
        t3 = t3 / np.hypot(*t3.T)[:, None]
        p0 = np.ascontiguousarray(C2[:, 0])
        p3 = np.ascontiguousarray(C2[:, 3])
        chord = np.hypot(*(p3 - p0).T)
        ctrl = np.empty((len(r), 4, 2))
        good = np.empty(len(r), dtype=bool)
        with np.errstate(invalid="ignore", divide="ignore"):
            _gn_kernel(np.ascontiguousarray(first[r], dtype=np.intp),
                       np.ascontiguousarray(last[r], dtype=np.intp), W, arc, _BISECT_SAMPLE,
                       p0, p3, np.ascontiguousarray(t0), np.ascontiguousarray(t3), chord,
                       _GN_ROUNDS, ctrl, good)
        good &= np.isfinite(ctrl).all(axis=(1, 2))
        r, ctrl = r[good], ctrl[good]
        if len(r):
            f2 = _seg_fits_arrays(W, wstep, ctrl, np.ones(len(r), dtype=bool), first[r],
                                  last[r], bound[r], h[r])
            C4[r[f2]] = ctrl[f2]
            ok[r[f2]] = True
    return ok


def _straight_cubics(points, is_cubic, tail) -> np.ndarray:
    """Per segment: a cubic whose two handles are on its ends (a straight line)."""
    out = np.zeros(len(is_cubic), dtype=bool)
    cu = np.flatnonzero(is_cubic)
    r = tail[cu] - 1
    out[cu] = ((points[r] == points[r + 1]).all(axis=1)
               & (points[r + 2] == points[r + 3]).all(axis=1))
    return out


def _tips_joined(W, points, is_cubic, tail, step, gfirst, glast, seg_owner, quant, bound,
                 changed, wstep=None, arc=None):
    """Rounded input: a short line (or a cubic with both handles on its ends, the same line)
    the thinning left across an acute tip (``_TIP_SHORT``,
    ``_TIP_STEPS``, ``_TIP_TURN_DEG``: the tip's own input point within the bound of the chord
    between its neighbours, the corners kept one step before and after it) taken out where
    the two segments beside it, their ends moved onto the crossing of their end tangents
    (kept inside the rounding square of the line's input point nearest to it), both keep
    within ``bound`` (per path) of their input points and polyline (:func:`_seg_fits_arrays`);
    the joint's input point is that one. Returns the segments as :func:`_connectors_out`."""
    ns = len(is_cubic)
    unchanged = (is_cubic, points, tail, step, gfirst, glast, seg_owner, changed)
    if ns < 3:
        return unchanged
    # (a cubic with both handles on its ends is that line: fifteenth session, P052 Bold
    # Italic "7" at em 2048, the fitter left one between two corners cut from one)
    c = np.flatnonzero(~is_cubic | _straight_cubics(points, is_cubic, tail))
    c = c[(c > 0) & (c < ns - 1)]
    c = c[(seg_owner[c - 1] == seg_owner[c]) & (seg_owner[c + 1] == seg_owner[c])]
    q = quant[seg_owner[c]]
    n_in = glast[c] - gfirst[c]
    A = points[tail[c] - 1]
    B = points[np.where(is_cubic[c], tail[c] + 2, tail[c])]
    ln = np.hypot(*(B - A).T)
    many = n_in >= 2
    short = (q > 0.0) & (n_in >= 1) & (n_in <= _TIP_STEPS) & (
        (ln <= _TIP_SHORT * q) | (many & (ln <= _TIP_SHORT_MANY * q)))
    c, A, B = c[short], A[short], B[short]
    turn_min = np.where(many[short], _TIP_TURN_MANY, _TIP_TURN_DEG)
    if len(c) == 0:
        return unchanged
    a, b = c - 1, c + 1
    # the segment before: its end tangent; the one after: its start tangent
    ta, tb = _joint_tangents(points, tail, step, a, b)
    u = B - A

    def cross(x, y):
        return x[:, 0] * y[:, 1] - x[:, 1] * y[:, 0]

    den = cross(ta, tb)
    with np.errstate(invalid="ignore", divide="ignore"):
        sa = cross(B - A, tb) / den
        sb = cross(B - A, ta) / den
    ok = ((np.sign(cross(ta, u)) == np.sign(cross(u, tb))) & (cross(ta, u) != 0.0)
          & (turn_deg(ta, tb) >= turn_min) & np.isfinite(sa) & (sa >= 0.0) & (sb <= 0.0))
    c, A, B, ta, sa = c[ok], A[ok], B[ok], ta[ok], sa[ok]
    if len(c) == 0:
        return unchanged
    # (no two share a neighbour: every other one of a run of them)
    one = np.r_[True, c[1:] > c[:-1] + 2]
    c, A, B, ta, sa = c[one], A[one], B[one], ta[one], sa[one]
    X = A + sa[:, None] * ta
    # the joint's input point: the line's input point nearest to the crossing; the crossing
    # kept inside its rounding square
    own, off = _ragged(np.arange(len(c)), glast[c] - gfirst[c] + 1)
    idx = gfirst[c][own] + off
    d = np.hypot(*(W[idx] - X[own]).T)
    st = np.cumsum(glast[c] - gfirst[c] + 1) - (glast[c] - gfirst[c] + 1)
    dm = np.minimum.reduceat(d, st)
    at = np.flatnonzero(d <= dm[own])
    at = at[np.r_[True, own[at][1:] != own[at][:-1]]]
    m = idx[at]
    h2 = 0.5 * quant[seg_owner[c]][:, None]
    X = np.clip(X, W[m] - h2, W[m] + h2)
    a, b = c - 1, c + 1
    start = np.ones(len(c), dtype=bool)
    C4 = np.stack([_ends_moved_many(points, is_cubic, tail, a, ~start, X - A),
                   _ends_moved_many(points, is_cubic, tail, b, start, X - B)])
    if wstep is None:
        wstep = _step_lengths(W)
    bj = np.asarray(bound, dtype=np.float64)[seg_owner[c]]
    h = _TIP_STEP * quant[seg_owner[c]]
    fa = _seg_fits_arrays(W, wstep, C4[0], is_cubic[a], gfirst[a], m, bj, h)
    # ... a cubic whose end moved with its handle along misses: its handle left where it
    # was (a move of over a unit carries the handle's side of a long cubic off its points;
    # the tangent barely turns)
    fa = _moved_end_refits(W, wstep, arc, points, is_cubic, tail, a, ~start, X - A, gfirst[a],
                           m, bj, h, C4[0], fa)
    fb = np.zeros(len(c), dtype=bool)
    if fa.any():
        fb[fa] = _seg_fits_arrays(W, wstep, C4[1, fa], is_cubic[b][fa], m[fa], glast[b][fa],
                                  bj[fa], h[fa])
    fb = _moved_end_refits(W, wstep, arc, points, is_cubic, tail, b, start, X - B, m,
                           glast[b], bj, h, C4[1], fb | ~fa)
    both = fa & fb
    if not both.any():
        return unchanged
    rep: dict[int, list] = {}
    for t in np.flatnonzero(both).tolist():
        ci = int(c[t])
        rep[ci] = []
        rep[ci - 1] = [(C4[0, t] if is_cubic[ci - 1] else C4[0, t, :2], int(gfirst[ci - 1]),
                        int(m[t]))]
        rep[ci + 1] = [(C4[1, t] if is_cubic[ci + 1] else C4[1, t, :2], int(m[t]),
                        int(glast[ci + 1]))]
    return _rebuilt(points, is_cubic, tail, step, gfirst, glast, seg_owner, changed, rep)


def _rebuilt(points, is_cubic, tail, step, gfirst, glast, seg_owner, changed, rep):
    """The segments with ``rep`` (segment -> its new pieces (ctrl, first, last)) in place."""
    ns = len(is_cubic)
    cnt = np.ones(ns, dtype=np.intp)
    for x, p in rep.items():
        cnt[x] = len(p)
    at = np.cumsum(cnt) - cnt
    n_cubic = np.repeat(is_cubic, cnt)
    n_first = np.repeat(gfirst, cnt)
    n_last = np.repeat(glast, cnt)
    n_owner = np.repeat(seg_owner, cnt)
    n_changed = np.repeat(changed, cnt)
    for x, p in rep.items():
        for i, (c, f, e) in enumerate(p):
            n_cubic[at[x] + i] = len(c) == 4
            n_first[at[x] + i] = f
            n_last[at[x] + i] = e
            n_changed[at[x] + i] = True
    nstep = np.where(n_cubic, 3, 1)
    ntail = np.cumsum(nstep) - nstep + n_owner + 1
    npts = np.empty((int(nstep.sum()) + int(seg_owner[-1]) + 1, 2))
    fs = np.flatnonzero(np.r_[True, seg_owner[1:] != seg_owner[:-1]])
    npts[ntail[at[fs]] - 1] = points[tail[fs] - 1]
    same = np.ones(ns, dtype=bool)
    same[list(rep)] = False
    same = np.flatnonzero(same)
    c = step[same]
    o = np.arange(int(c.sum())) - np.repeat(np.cumsum(c) - c, c)
    npts[np.repeat(ntail[at[same]], c) + o] = points[np.repeat(tail[same], c) + o]
    for x, p in rep.items():
        for i, (cx, _, _) in enumerate(p):
            r = ntail[at[x] + i] - 1
            npts[r:r + len(cx)] = cx
    return n_cubic, npts, ntail, nstep, n_first, n_last, n_owner, n_changed


#: rounded input: a line over at least this many input points is checked for a bulge
_BULGE_POINTS = 8
#: ... and split where the design estimate at its middle is this many quanta off it
_BULGE_SHARE = 0.5
#: rounds of that split (a half may bulge again)
_BULGE_ROUNDS = 2


#: ... the farthest input point's estimate is fitted over the input points within this many
#: quanta of arc of it (a short side of a hidden corner, not the line's far end)
_BULGE_WINDOW = 8.0


def _farthest_estimates(W, arc, p0, p1, first, last, q):
    """Per line (ends ``p0``, ``p1`` over the input points first..last): the input point
    between its ends farthest from it, and the least-squares quadratic estimate of the design
    there over the line's input points within ``_BULGE_WINDOW`` q of arc of it: (position,
    that input point's index, ok) as :func:`_local_fits`."""
    cnt = last - first - 1
    v = len(first)
    own, off = _ragged(np.arange(v), np.maximum(cnt, 0))
    idx = first[own] + 1 + off
    dd = point_segment_distance(W[idx], p0[own], p1[own])
    starts = np.cumsum(cnt) - cnt
    has = cnt > 0
    mx = np.full(v, -1.0)
    mx[has] = np.maximum.reduceat(dd, starts[has])
    top = np.flatnonzero(dd >= mx[own])
    _, one = np.unique(own[top], return_index=True)
    far = first.copy()
    far[own[top[one]]] = idx[top[one]]
    # the window: the line's input points (ends included) within the arc radius
    allc = last - first + 1
    own2, off2 = _ragged(np.arange(v), allc)
    idx2 = first[own2] + off2
    near = np.abs(arc[idx2] - arc[far[own2]]) <= _BULGE_WINDOW * q[own2]
    big = np.iinfo(np.intp).max
    lo = np.minimum.reduceat(np.where(near, idx2, big), np.cumsum(allc) - allc)
    hi = np.maximum.reduceat(np.where(near, idx2, -1), np.cumsum(allc) - allc)
    pos, _, ok = _local_fits(W, arc, lo, hi, far)
    return pos, far, ok & has


def _split_bulging_lines(W, arc, la, lpts, lfirst, llast, lerr, lkey, quant, eps):
    """Rounded input: a line over a gently curved stretch of the design may keep within
    its bound of the rounded points while the design bulges up to that bound away from it
    (a thinned line along a staircase). Per line over at least ``_BULGE_POINTS`` input
    points of a rounded path: the least-squares quadratic of its input points (the design
    estimate of :func:`_on_the_design`) at its middle input point; where that lies more
    than ``_BULGE_SHARE`` quanta from the line, the line is split there into two lines
    meeting at the estimate (kept inside the middle point's rounding square), or at the
    middle input point where the two lines from the estimate would miss their points by
    more than ``eps`` (the line's bound); not split where both miss. Where the middle's
    estimate is on the line, the line's input point farthest from it is tried the same way
    (:func:`_farthest_estimates`: a corner hidden beside the line's end). Returns the lines as
    :func:`_valid_lines` does (a split line's two halves in order under its sort key) and
    whether any line was split."""
    q = quant[la]
    m = (lfirst + llast) // 2
    cand = np.flatnonzero((q > 0.0) & (llast - lfirst + 1 >= _BULGE_POINTS))
    if len(cand) == 0:
        return la, lpts, lfirst, llast, lerr, lkey, False
    pos, _, ok = _local_fits(W, arc, lfirst[cand], llast[cand], m[cand])
    p0, p1 = lpts[cand, 0], lpts[cand, 1]
    d = point_segment_distance(pos, p0, p1)
    hit = ok & (d > _BULGE_SHARE * q[cand])
    at = m[cand]
    # ... else at the input point farthest from the line, over the input points within
    # _BULGE_WINDOW quanta of arc of it (a corner the thinning hid beside a line's end: its
    # short side's points all within the bound of a line from the far end)
    wpos, wat, wok = _farthest_estimates(W, arc, p0, p1, lfirst[cand], llast[cand], q[cand])
    dw = point_segment_distance(wpos, p0, p1)
    better = wok & (dw > _BULGE_SHARE * q[cand]) & ~hit
    pos[better], at[better], hit[better] = wpos[better], wat[better], True
    if not hit.any():
        return la, lpts, lfirst, llast, lerr, lkey, False
    c = cand[hit]
    mc = at[hit]
    h = 0.5 * q[c][:, None]
    v = np.clip(pos[hit], W[mc] - h, W[mc] + h)
    e = eps[la[c]] * (1.0 + 1e-9)
    for attempt in range(2):
        halves = _split_halves(W, lpts, lfirst, llast, c, mc, v)
        fine = (halves[2] <= e) & (halves[3] <= e)
        if attempt == 0:
            v = np.where(fine[:, None], v, W[mc])
    return _lines_split(la, lpts, lfirst, llast, lerr, lkey, c, mc, halves, fine)


def _split_halves(W, lpts, lfirst, llast, c, mc, v):
    """The lines ``c`` (points ``lpts``, input points ``lfirst``..``llast``) each split at
    its input point ``mc`` into two lines meeting at ``v``: (first halves' points, second
    halves' points, their errors, :func:`_line_errors`)."""
    a_pts = np.stack([lpts[c, 0], v], axis=1)
    b_pts = np.stack([v, lpts[c, 1]], axis=1)
    return (a_pts, b_pts, _line_errors(W, a_pts, lfirst[c], mc),
            _line_errors(W, b_pts, mc, llast[c]))


def _lines_split(la, lpts, lfirst, llast, lerr, lkey, c, mc, halves, keep):
    """The lines (start thinned index ``la``, points, first/last input points, errors, sort
    keys) with each line ``c[keep]`` replaced by its two ``halves`` (:func:`_split_halves`,
    meeting at input point ``mc``): the first half in the line's place, the second right
    after it. Returns them and whether any line was split."""
    if not keep.any():
        return la, lpts, lfirst, llast, lerr, lkey, False
    a_pts, b_pts, ea, eb = (x[keep] for x in halves)
    c, mc = c[keep], mc[keep]
    n = len(la)
    rep = np.ones(n, dtype=np.intp)
    rep[c] = 2
    pos_new = np.cumsum(rep) - rep  # each old line's first row
    la2 = np.repeat(la, rep)
    key2 = np.repeat(lkey, rep)
    pts2 = np.repeat(lpts, rep, axis=0)
    f2 = np.repeat(lfirst, rep)
    l2 = np.repeat(llast, rep)
    e2 = np.repeat(lerr, rep)
    r = pos_new[c]
    pts2[r] = a_pts
    pts2[r + 1] = b_pts
    l2[r] = mc
    f2[r + 1] = mc
    e2[r] = ea
    e2[r + 1] = eb
    return la2, pts2, f2, l2, e2, key2, True


#: rounded input: a fitted line over an input point that joins two long input steps (at least
#: ``_LONE_LENGTH`` quanta each, neither a chord of a coarse curve: two design lines, each
#: written as its two rounded ends, meeting at a vertex of the design that turns a few
#: degrees) is split at that point where it passes this many quanta or more from it (the
#: design's vertex lies anywhere in the point's rounding square: the line may miss it by the
#: rounding and this offset together, where the rounded polyline misses it by the rounding)
_GAP_JOINT_OFF = 0.25
#: ... and where one of the two long steps continues, on its far side, as a curve written
#: as its dense points: at least this many input steps in a row, each under
#: ``_LONE_LENGTH`` quanta and not zero (a typeface's design lines end at its curves; on a
#: real polyline, where every step is long and every vertex such a joint, the rule split
#: the thinned lines at their merged vertices: +6,420 segments over the PLT corpus)
_GAP_JOINT_RUN = 6
_GAP_JOINTS = True
#: ... and at an input point between one long step and a row of this many short input steps
#: on one line of the grid (a design line after a curve's straight end: P052 Bold Italic "$"
#: at em 2048, a 123-unit line after a 10-unit row, the line over both 0.89 from their
#: joint where the rounded input is 0.43); 0: off
_GAP_ROW = 4


def _dense_run_beyond(W, start, step, lo, hi, qg, n=None):
    """Per point ``start``: True where the ``n`` (default ``_GAP_JOINT_RUN``) input steps
    from it in the direction ``step`` (+1: W[i] -> W[i + 1] for i from ``start`` on; -1:
    W[i] -> W[i - 1] for i from ``start`` down) all lie within ``lo``..``hi`` (the path's
    first and last point indices) and are each shorter than ``_LONE_LENGTH`` quanta ``qg``
    and not zero."""
    n = _GAP_JOINT_RUN if n is None else n
    end = start + step * n
    ok = (end >= lo) & (end <= hi)
    for k in range(n):
        if not ok.any():
            break
        i = np.where(ok, start + step * k, start)
        j = np.where(ok, i + step, start)
        s = np.hypot(*(W[j] - W[i]).T)
        ok &= (s > 0.0) & (s < _LONE_LENGTH * qg)
    return ok


def _collinear_row(W, g, step, lo, hi, qg):
    """Per point ``g``: are the ``_GAP_ROW`` input steps from it in the direction ``step``
    (+1 / -1) a dense run within ``lo``..``hi`` (:func:`_dense_run_beyond`) whose points lie
    on one line (exactly, up to the arithmetic's error: a row of the rounding grid)?"""
    ok = _dense_run_beyond(W, g, step, lo, hi, qg, _GAP_ROW)
    d = W[np.where(ok, g + step * _GAP_ROW, g)] - W[g]
    ln = np.hypot(d[:, 0], d[:, 1])
    ok &= ln > 0.0
    for k in range(1, _GAP_ROW):
        r = W[np.where(ok, g + step * k, g)] - W[g]
        ok &= np.abs(r[:, 0] * d[:, 1] - r[:, 1] * d[:, 0]) <= 1e-9 * qg * np.maximum(ln, 1.0)
    return ok


def _split_gap_joints(W, la, lpts, lfirst, llast, lerr, lkey, quant, eps, coarse, woff, wlen):
    """Rounded input (``quant`` per thinned point, 0: exact): each line (start thinned index
    ``la``, points ``lpts``, input points ``lfirst``..``llast``) split at its input point
    farthest from it among those between two long input steps (``_LONE_LENGTH`` quanta each,
    not ``coarse`` chords, one of them followed on its far side by ``_GAP_JOINT_RUN`` short
    steps of a curve on the same path: W[``woff[i]``:``woff[i] + wlen[i]``] is path i; or
    between one such step and a row of the grid, :func:`_collinear_row`) that
    lie ``_GAP_JOINT_OFF`` quanta or more from it, into two lines meeting at that input
    point, where both keep within ``eps`` (the line's bound) of their input points. The
    thinning keeps two nearly collinear design lines in one segment, which then misses their
    common vertex by up to the rounding's width beyond its offset (Cantarell Thin "g" at em
    2048: a 4-degree joint of a 152-unit and an 8-unit line, 0.77 from the design where the
    rounded input is 0.50; FreeSans "3" at em 2048: 2 degrees between a 22.5-unit and a
    76-unit line, the thinned line on into the curve 0.79 from their vertex, rounded input
    0.40). Returns the lines as :func:`_split_bulging_lines` does."""
    q = quant[la]
    cand = np.flatnonzero((q > 0.0) & (llast - lfirst >= 2))
    if len(cand) == 0:
        return la, lpts, lfirst, llast, lerr, lkey, False
    cnt = llast[cand] - lfirst[cand] - 1
    own, off = _ragged(np.arange(len(cand)), cnt)
    g = lfirst[cand][own] + 1 + off
    qg = q[cand][own]
    s0 = np.hypot(*(W[g] - W[g - 1]).T)
    s1 = np.hypot(*(W[g + 1] - W[g]).T)
    sel = (s0 >= _LONE_LENGTH * qg) & (s1 >= _LONE_LENGTH * qg) & ~coarse[g - 1] & ~coarse[g]
    row = np.zeros(len(g), dtype=bool)
    if _GAP_ROW:
        # ... or between one long step and a row of collinear short steps inside the line
        # (the row: a curve's straight end, or a design line of its own)
        lo, hi = lfirst[cand][own], llast[cand][own]
        row = (s1 >= _LONE_LENGTH * qg) & ~coarse[g] & _collinear_row(W, g, -1, lo, hi, qg)
        row |= (s0 >= _LONE_LENGTH * qg) & ~coarse[g - 1] & _collinear_row(W, g, 1, lo, hi, qg)
        row &= ~sel
        sel |= row
    if not sel.any():
        return la, lpts, lfirst, llast, lerr, lkey, False
    own, g, qg, row = own[sel], g[sel], qg[sel], row[sel]
    # (the far side of one of the two long steps: a curve's dense points, on the same path;
    # a row is such points itself)
    p = np.searchsorted(woff, g, side="right") - 1
    lo, hi = woff[p], woff[p] + wlen[p] - 1
    sel = (row | _dense_run_beyond(W, g + 1, 1, lo, hi, qg)
           | _dense_run_beyond(W, g - 1, -1, lo, hi, qg))
    if not sel.any():
        return la, lpts, lfirst, llast, lerr, lkey, False
    own, g, qg = own[sel], g[sel], qg[sel]
    c = cand[own]
    t = point_segment_distance(W[g], lpts[c, 0], lpts[c, 1])
    far = t >= _GAP_JOINT_OFF * qg
    if not far.any():
        return la, lpts, lfirst, llast, lerr, lkey, False
    c, g, t = c[far], g[far], t[far]
    # (per line its farthest such point)
    order = np.lexsort((-t, c))
    one = order[np.r_[True, c[order][1:] != c[order][:-1]]]
    c, mc = c[one], g[one]
    e = eps[la[c]] * (1.0 + 1e-9)
    halves = _split_halves(W, lpts, lfirst, llast, c, mc, W[mc].astype(np.float64))
    fine = (halves[2] <= e) & (halves[3] <= e)
    return _lines_split(la, lpts, lfirst, llast, lerr, lkey, c, mc, halves, fine)


def _valid_lines(W, K, Q, la, lb, lpts, lfirst, llast, lerr, eps):
    """Rounded input: a line between thinned vertices that :func:`_on_the_design` moved may
    miss its input points by more than the thinning's tolerance ``eps`` (per thinned
    point); such a line is replaced by the thinned line between the input points (valid by
    construction of the thinning) and short connectors from the moved vertices to them
    (inside the rounding square, no input point between). A moved vertex between two lines
    (no cubic ends there) that one of them misses by it goes back to its input point instead,
    where the other line keeps its bound so (no connector there). Returns the lines (start
    thinned index, points, first, last, error, sort key 3 a + 0/1/2) with the replacements."""
    tol = eps[la] * (1.0 + 1e-9)
    bad = lerr > tol
    if not bad.any():
        return la, lpts, lfirst, llast, lerr, 3 * la
    orig = W[K]
    # a moved end of a missing line between two lines (no cubic's end) goes back to its
    # input point where the other line keeps its bound so (no connector there)
    v = np.intersect1d(np.concatenate([la[bad], lb[bad]]), np.intersect1d(la, lb))
    v = v[(Q[v] != orig[v]).any(axis=1)]
    if len(v):
        # the line starting at v and the one ending there (each line is one thinned segment)
        srt = np.argsort(la, kind="stable")
        las = la[srt]
        i1 = np.minimum(np.searchsorted(las, v), len(la) - 1)
        i0 = np.minimum(np.searchsorted(las, v - 1), len(la) - 1)
        ok = (las[i1] == v) & (las[i0] == v - 1)
        v, li, lo = v[ok], srt[i1[ok]], srt[i0[ok]]
    if len(v):
        pin = np.stack([lpts[lo, 0], orig[v]], axis=1)
        pout = np.stack([orig[v], lpts[li, 1]], axis=1)
        ein = _line_errors(W, pin, lfirst[lo], llast[lo])
        eout = _line_errors(W, pout, lfirst[li], llast[li])
        go = ((ein <= tol[lo]) | bad[lo]) & ((eout <= tol[li]) | bad[li])
        # (two neighbouring vertices both going back: their shared line is recomputed)
        v, li, lo = v[go], li[go], lo[go]
    if len(v):
        lpts = lpts.copy()
        lpts[lo, 1] = orig[v]
        lpts[li, 0] = orig[v]
        ch = np.unique(np.concatenate([lo, li]))
        lerr = lerr.copy()
        lerr[ch] = _line_errors(W, lpts[ch], lfirst[ch], llast[ch])
        bad = lerr > tol
        if not bad.any():
            return la, lpts, lfirst, llast, lerr, 3 * la
    b = np.flatnonzero(bad)
    a0, b0 = la[b], lb[b]
    parts = [(la[~bad], lpts[~bad], lfirst[~bad], llast[~bad], 3 * la[~bad] + 1)]
    mid = np.stack([orig[a0], orig[b0]], axis=1)
    parts.append((a0, mid, lfirst[b], llast[b], 3 * a0 + 1))
    pa, pb = lpts[b, 0], lpts[b, 1]
    ma = (pa != orig[a0]).any(axis=1)
    parts.append((a0[ma], np.stack([pa[ma], orig[a0[ma]]], axis=1), lfirst[b][ma],
                  lfirst[b][ma], 3 * a0[ma]))
    mb = (pb != orig[b0]).any(axis=1)
    parts.append((a0[mb], np.stack([orig[b0[mb]], pb[mb]], axis=1), llast[b][mb],
                  llast[b][mb], 3 * a0[mb] + 2))
    la2 = np.concatenate([p[0] for p in parts])
    pts2 = np.concatenate([p[1] for p in parts])
    f2 = np.concatenate([p[2] for p in parts])
    l2 = np.concatenate([p[3] for p in parts])
    key = np.concatenate([p[4] for p in parts])
    return la2, pts2, f2, l2, _line_errors(W, pts2, f2, l2), key


@njit(cache=True, nogil=True)
def _pairwise_block(a, s, n):  # pragma: no cover (compiled)
    """numpy's pairwise sum of a[s : s + n] for n <= 128 (one unrolled block)."""
    if n < 8:
        res = 0.0
        for i in range(s, s + n):
            res += a[i]
        return res
    r0 = a[s]
    r1 = a[s + 1]
    r2 = a[s + 2]
    r3 = a[s + 3]
    r4 = a[s + 4]
    r5 = a[s + 5]
    r6 = a[s + 6]
    r7 = a[s + 7]
    i = 8
    m = n - n % 8
    while i < m:
        r0 += a[s + i]
        r1 += a[s + i + 1]
        r2 += a[s + i + 2]
        r3 += a[s + i + 3]
        r4 += a[s + i + 4]
        r5 += a[s + i + 5]
        r6 += a[s + i + 6]
        r7 += a[s + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[s + i]
        i += 1
    return res


@njit(cache=True, nogil=True)
def _pairwise_sum(a, s, n):  # pragma: no cover (compiled)
    """numpy's pairwise sum of a[s : s + n] (its float64 add reduction), bit for bit: blocks
    of <= 128 terms, a longer range the sum of its two halves (split at a multiple of 8),
    evaluated with an explicit stack (a recursive compiled function does not load from
    numba's cache)."""
    if n <= 128:
        return _pairwise_block(a, s, n)
    st_s = np.empty(64, dtype=np.int64)
    st_n = np.empty(64, dtype=np.int64)
    st_k = np.empty(64, dtype=np.int64)  # 0: left half next, 1: right half next, 2: add
    vals = np.empty(64)
    top = 0
    nv = 0
    st_s[0] = s
    st_n[0] = n
    st_k[0] = 0
    while top >= 0:
        cs = st_s[top]
        cn = st_n[top]
        if cn <= 128:
            vals[nv] = _pairwise_block(a, cs, cn)
            nv += 1
            top -= 1
            continue
        h = cn // 2
        h -= h % 8
        k = st_k[top]
        st_k[top] = k + 1
        if k == 0:
            top += 1
            st_s[top] = cs
            st_n[top] = h
            st_k[top] = 0
        elif k == 1:
            top += 1
            st_s[top] = cs + h
            st_n[top] = cn - h
            st_k[top] = 0
        else:
            nv -= 1
            vals[nv - 1] = vals[nv - 1] + vals[nv]
            top -= 1
    return vals[0]


@njit(cache=True, nogil=True)
def _window_sums(arc, W, lo, hi, at, mom, rx, ry):  # pragma: no cover (compiled)
    """:func:`_local_fits`'s sums per window j (the input points lo[j] .. hi[j], inclusive
    global indices, at arc length s scaled to sv = (s - arc[at[j]]) / max(arc[hi[j]] -
    arc[lo[j]], 1e-300)): mom[r] of sv^r (r = 0 .. 4), rx[r], ry[r] of sv^r times the x, y
    of the input point; each as np.add.reduceat sums them (the first term plus numpy's
    pairwise sum of the rest). The powers are products (s^3 = s^2 s, s^4 = s^2 s^2), the
    same on every machine (numpy's ``**`` takes a vector path on AVX-512 machines and a 28x
    slower scalar one for negative bases, with different last bits)."""
    v = lo.shape[0]
    big = 0
    for j in range(v):
        big = max(big, hi[j] - lo[j] + 1)
    buf = np.empty((10, big))
    for j in range(v):
        s = lo[j]
        n = hi[j] - s + 1
        a0 = arc[at[j]]
        scale = max(arc[hi[j]] - arc[s], 1e-300)
        for k in range(n):
            u = (arc[s + k] - a0) / scale  # in [-1, 1]: well scaled
            u2 = u * u
            x = W[s + k, 0]
            y = W[s + k, 1]
            buf[0, k] = u
            buf[1, k] = u2
            buf[2, k] = u2 * u
            buf[3, k] = u2 * u2
            buf[4, k] = x
            buf[5, k] = u * x
            buf[6, k] = u2 * x
            buf[7, k] = y
            buf[8, k] = u * y
            buf[9, k] = u2 * y
        mom[0, j] = float(n)  # (a sum of ones is exact)
        for r in range(4):
            mom[r + 1, j] = buf[r, 0] + _pairwise_sum(buf[r], 1, n - 1)
        for r in range(3):
            rx[r, j] = buf[4 + r, 0] + _pairwise_sum(buf[4 + r], 1, n - 1)
            ry[r, j] = buf[7 + r, 0] + _pairwise_sum(buf[7 + r], 1, n - 1)


@njit(cache=True, nogil=True)
def _lu3_one(a, piv) -> None:  # pragma: no cover (compiled)
    """LU with partial pivoting of the 3x3 ``a`` in place (unit lower L below the diagonal,
    U on and above; row j swapped with piv[j]), in LAPACK getf2's left-looking order as
    the bundled OpenBLAS runs it (the multipliers scaled by the pivot's reciprocal)."""
    for j in range(3):
        for i in range(j):
            ip = piv[i]
            if ip != i:
                t = a[i, j]
                a[i, j] = a[ip, j]
                a[ip, j] = t
        for i in range(1, j):
            s = 0.0
            for k in range(i):
                s += a[i, k] * a[k, j]
            a[i, j] -= s
        for i in range(j, 3):
            s = 0.0
            for k in range(j):
                s += a[i, k] * a[k, j]
            a[i, j] -= s
        jp = j
        mx = abs(a[j, j])
        for i in range(j + 1, 3):
            if abs(a[i, j]) > mx:
                mx = abs(a[i, j])
                jp = i
        piv[j] = jp
        t1 = a[jp, j]
        if t1 != 0.0:
            rcp = 1.0 / t1
            if jp != j:
                for k in range(j + 1):
                    t = a[j, k]
                    a[j, k] = a[jp, k]
                    a[jp, k] = t
            for i in range(j + 1, 3):
                a[i, j] *= rcp


@njit(cache=True, nogil=True)
def _det3(a, p) -> float:  # pragma: no cover (compiled)
    """The determinant of the matrix whose LU (:func:`_lu3_one`) is ``a``, ``p`` as
    np.linalg.det gives it: sign times exp of the sum of the logs of the pivots'
    magnitudes (0 with a zero pivot)."""
    sign = 1.0
    logdet = 0.0
    zero = False
    for i in range(3):
        if p[i] != i:
            sign = -sign
    for i in range(3):
        d = a[i, i]
        if d == 0.0:
            zero = True
        if d < 0.0:
            sign = -sign
            d = -d
        logdet += np.log(d)
    return 0.0 if zero else sign * np.exp(logdet)


@njit(cache=True, nogil=True)
def _lu3(A, lu, piv, lim, good) -> None:  # pragma: no cover (compiled)
    """Per 3x3 matrix A[m]: its LU (:func:`_lu3_one`) and good[m] = |det| > lim[m] for
    np.linalg.det's determinant (:func:`_det3`). The product of the pivots decides where it
    is clear of lim by a relative 1e-9 (np.linalg.det's log-exp path differs from it by a
    few 1e-16 relative); only the others take the logs."""
    for m in range(A.shape[0]):
        a = lu[m]
        a[:, :] = A[m]
        p = piv[m]
        _lu3_one(a, p)
        prod = abs(a[0, 0] * a[1, 1] * a[2, 2])
        if prod > lim[m] * (1.0 + 1e-9):
            good[m] = True
        elif prod < lim[m] * (1.0 - 1e-9):
            good[m] = False
        else:
            good[m] = abs(_det3(a, p)) > lim[m]


@njit(cache=True, nogil=True)
def _solve3(lu, piv, good, rx, ry, cx, cy) -> None:  # pragma: no cover (compiled)
    """cx[m], cy[m]: the solutions of A[m] c = rx[:, m], ry[:, m] from its LU, in
    np.linalg.solve's order (getrs: the row swaps, L forward, U backward from the last
    column); the identity's solution (the right side) where not good[m]."""
    eye = np.eye(3)
    ep = np.empty(3, dtype=np.intp)
    _lu3_one(eye, ep)
    x = np.empty(3)
    for m in range(lu.shape[0]):
        a = lu[m] if good[m] else eye
        p = piv[m] if good[m] else ep
        for side in range(2):
            r = rx if side == 0 else ry
            for i in range(3):
                x[i] = r[i, m]
            for i in range(3):
                ip = p[i]
                if ip != i:
                    t = x[i]
                    x[i] = x[ip]
                    x[ip] = t
            for i in range(3):
                s = x[i]
                for k in range(i):
                    s -= a[i, k] * x[k]
                x[i] = s
            for i in range(2, -1, -1):
                s = x[i]
                for k in range(2, i, -1):
                    s -= a[i, k] * x[k]
                x[i] = s / a[i, i]
            c = cx if side == 0 else cy
            for i in range(3):
                c[m, i] = x[i]


def _local_fits(
    W: np.ndarray, arc: np.ndarray, lo: np.ndarray, hi: np.ndarray, at: np.ndarray,
    res: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares quadratics x(s), y(s) in arc length s through the input points lo..hi
    (inclusive global indices) of each window, evaluated at the point ``at``: (position
    (V, 2), unit tangent (V, 2) in the path's direction, ok (V,): at least 4 points and a
    well-conditioned fit). ``res`` (V,): filled with the largest distance of a window's
    input point to its quadratic where ok (inf elsewhere)."""
    cnt = hi - lo + 1
    v = len(lo)
    pos = np.zeros((v, 2))
    tan = np.zeros((v, 2))
    ok = cnt >= 4
    if res is not None:
        res[:] = np.inf
    if not ok.any():
        return pos, tan, ok
    okk = np.flatnonzero(ok)
    # the sums of 1, s .. s^4 and of x, y times 1, s, s^2 per window (compiled, in
    # np.add.reduceat's order)
    mom = np.empty((5, len(okk)))
    rx = np.empty((3, len(okk)))
    ry = np.empty((3, len(okk)))
    _window_sums(arc, W, lo[okk], hi[okk], at[okk], mom, rx, ry)
    A = np.stack([mom[0:3], mom[1:4], mom[2:5]]).transpose(2, 0, 1)  # (V', 3, 3)
    # (compiled: np.linalg.det's and np.linalg.solve's numbers, one factorization)
    lu = np.empty_like(A)
    piv = np.empty((len(A), 3), dtype=np.intp)
    good = np.empty(len(A), dtype=np.bool_)
    _lu3(A, lu, piv, 1e-9 * np.abs(A).max(axis=(1, 2)) ** 3, good)
    cx = np.empty((len(A), 3))
    cy = np.empty((len(A), 3))
    _solve3(lu, piv, good, rx, ry, cx, cy)
    pos[okk] = np.stack([cx[:, 0], cy[:, 0]], axis=1)
    t = np.stack([cx[:, 1], cy[:, 1]], axis=1)
    ln = np.hypot(t[:, 0], t[:, 1])
    good &= ln > 0.0
    tan[okk] = t / np.where(ln > 0.0, ln, 1.0)[:, None]
    ok[okk] = good
    if res is not None and good.any():
        g = np.flatnonzero(good)
        a, b, c = lo[okk[g]], hi[okk[g]], at[okk[g]]
        own, off = _ragged(np.arange(len(g)), b - a + 1)
        i = a[own] + off
        u = (arc[i] - arc[c[own]]) / np.maximum(arc[b] - arc[a], 1e-300)[own]
        fx = cx[g, 0][own] + u * (cx[g, 1][own] + u * cx[g, 2][own])
        fy = cy[g, 0][own] + u * (cy[g, 1][own] + u * cy[g, 2][own])
        d = np.hypot(W[i, 0] - fx, W[i, 1] - fy)
        res[okk[g]] = np.maximum.reduceat(d, np.cumsum(b - a + 1) - (b - a + 1))
    return pos, tan, ok


@njit(cache=True, nogil=True)
def _line_moments(W, lo, hi, at, ok, mx, my, sxx, syy, sxy):  # pragma: no cover (compiled)
    """:func:`_local_lines`' sums per window j where ok[j] (the input points lo[j] ..
    hi[j] as offsets d from W[at[j]]): mx, my the means of d, sxx, syy, sxy the sums of the
    products of d minus its mean, each summed in order from 0 (as np.bincount does)."""
    for j in range(lo.shape[0]):
        if not ok[j]:
            continue
        rx = W[at[j], 0]
        ry = W[at[j], 1]
        n = hi[j] - lo[j] + 1
        sx = 0.0
        sy = 0.0
        for i in range(lo[j], hi[j] + 1):
            sx += W[i, 0] - rx
            sy += W[i, 1] - ry
        ax = sx / n
        ay = sy / n
        a = 0.0
        b = 0.0
        c = 0.0
        for i in range(lo[j], hi[j] + 1):
            dx = (W[i, 0] - rx) - ax
            dy = (W[i, 1] - ry) - ay
            a += dx * dx
            b += dy * dy
            c += dx * dy
        mx[j] = ax
        my[j] = ay
        sxx[j] = a
        syy[j] = b
        sxy[j] = c


def _local_lines(
    W: np.ndarray, lo: np.ndarray, hi: np.ndarray, at: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares lines (principal axis) through the input points lo..hi (inclusive
    global indices) of each window: (the point ``at`` projected onto the line (V, 2), unit
    direction (V, 2) from lo to hi, ok (V,): at least 3 points)."""
    cnt = hi - lo + 1
    v = len(lo)
    ok = cnt >= 3
    pos = W[at].astype(np.float64, copy=True)
    tan = np.zeros((v, 2))
    if not ok.any():
        return pos, tan, ok
    ref = W[at]
    # the mean offset from the reference point and the second moments about the mean per
    # window (compiled: the sums in np.bincount's order, the same numbers)
    mx = np.zeros(v)
    my = np.zeros(v)
    sxx = np.zeros(v)
    syy = np.zeros(v)
    sxy = np.zeros(v)
    _line_moments(W, lo, hi, at, ok, mx, my, sxx, syy, sxy)
    ang = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)
    tx, ty = np.cos(ang), np.sin(ang)
    ch = W[hi] - W[lo]
    flip = tx * ch[:, 0] + ty * ch[:, 1] < 0.0
    tx = np.where(flip, -tx, tx)
    ty = np.where(flip, -ty, ty)
    s = -(mx * tx + my * ty)  # the reference point's coordinate along the line
    pos[ok] = (ref + np.stack([mx + s * tx, my + s * ty], axis=1))[ok]
    tan[ok] = np.stack([tx, ty], axis=1)[ok]
    return pos, tan, ok


#: rounded input: a smooth vertex's design estimate is fitted over at least this many input
#: points on each side of it
_SMOOTH_HALF = 6
#: ... on a side whose thinned segment is at most this many quanta long
_SMOOTH_SHORT = 4.0
#: ... and elsewhere, on a side whose half window (from the vertex to the middle of its
#: thinned segment) has fewer than this many input points, where at least _SMOOTH_HALF are
#: there up to the thinned point beyond (s10-bias; ``_SMOOTH_ALWAYS`` False: off, for
#: measurements)
_SMOOTH_FEW = 3
_SMOOTH_ALWAYS = True
#: a smooth vertex beside a design line written as its two rounded ends (one input step of
#: at least ``_JOINT_LINE`` quanta) moves only along that line
_SMOOTH_ALONG = True
#: ... also beside a thinned segment of more input steps whose longest step (at least
#: ``_JOINT_LINE`` quanta) is this share of its chord or more (0: off)
_SMOOTH_ALONG_SHARE = 0.75
#: rounded input: a corner's line side (its other end a corner too) whose first input step
#: from the corner is a design line written as its two rounded ends (``_LONE_LENGTH`` quanta
#: or more) and at least ``_FIRST_SHARE`` of the side's length, with more input points after
#: it, takes its direction from that step (``_FIRST_STEP`` False: its least-squares line)
_FIRST_STEP = True
_FIRST_SHARE = 0.75
#: ... and also where every input step of the side is that long (``_FIRST_STEP`` needed)
_FIRST_CHAIN = True
#: a smooth vertex next to a corner moves only where its window holds at least this many
#: input points on that side of it, or beside a design line (along it, above; 0: always)
_SMOOTH_SIDES = 2


def _range_steps(wstep, a, b):
    """The input steps of the ranges a[r]..b[r] (a < b): per step its range and its first
    point, their lengths (from ``wstep``, :func:`_step_lengths`), and each range's first
    position among them."""
    own, off = _ragged(np.arange(len(a)), b - a)
    st = a[own] + off
    return own, st, wstep[st], np.cumsum(b - a) - (b - a)


def _line_steps(W, wstep, a, b, quant):
    """Per thinned segment a[r]..b[r] (input indices, a < b): is it a design line
    written as its two rounded ends (:func:`_on_the_design`'s ``_SMOOTH_ALONG``): its longest
    input step at least ``_JOINT_LINE`` quanta, the whole segment or
    (``_SMOOTH_ALONG_SHARE``) that share of its chord or more; and, where it is, that step's
    vector (its first occurrence; zeros elsewhere). ``wstep``: the step lengths of W."""
    if len(a) == 0:
        return np.zeros(0, dtype=bool), np.zeros((0, 2))
    lo = int(a.min())
    # (each range's longest step by a reduction over its slice of the span's steps)
    sl = np.append(wstep[lo:int(b.max())], 0.0)
    top = np.maximum.reduceat(sl, np.column_stack([a - lo, b - lo]).ravel())[::2]
    chord = np.hypot(*(W[b] - W[a]).T)
    share = (b - a == 1) | ((_SMOOTH_ALONG_SHARE > 0.0) & (top >= _SMOOTH_ALONG_SHARE * chord))
    along = (top >= _JOINT_LINE * quant) & share
    dirs = np.zeros((len(a), 2))
    al = np.flatnonzero(along)
    if len(al):
        own, st, sla, _ = _range_steps(wstep, a[al], b[al])
        at = np.flatnonzero(sla == top[al][own])
        j0 = st[at[np.unique(own[at], return_index=True)[1]]]
        dirs[al] = W[j0 + 1] - W[j0]
    return along, dirs


def _on_the_design(W, K, Q, arc, t_in, t_out, smooth, quant, tlen, eps, found=None,
                   coarse=None, wstep=None) -> None:
    """Rounded input (per thinned point its path's quantum ``quant``): the smooth thinned
    vertices (inside curve runs) moved onto a least-squares estimate of the design curve
    (a quadratic in arc length through the input points between the middles of the two
    thinned segments around it, at least ``_SMOOTH_HALF`` points on a side beside a short
    segment or where that half has fewer than ``_SMOOTH_FEW``), kept inside the point's
    rounding square, with the fit's
    tangent as both of its tangents; the ends of curve runs keep their place and get
    one-sided fitted tangents. In place on ``Q``, ``t_in``, ``t_out``. ``wstep``: the step
    lengths of W (:func:`_step_lengths`) where known."""
    n = len(Q)
    last = np.cumsum(tlen) - 1
    first = last - tlen + 1
    is_first = np.zeros(n, dtype=bool)
    is_first[first] = True
    is_last = np.zeros(n, dtype=bool)
    is_last[last] = True
    rnd = quant > 0.0
    sm = np.flatnonzero(smooth & rnd & ~is_first & ~is_last)
    if len(sm):
        lo = (K[sm - 1] + K[sm] + 1) // 2
        hi = (K[sm] + K[sm + 1]) // 2
        # beside a thinned segment of a few quanta (a rounding wiggle): at least
        # _SMOOTH_HALF input points on that side, up to the thinned point beyond it
        ln = np.hypot(*(W[K[1:]] - W[K[:-1]]).T)
        short = _SMOOTH_SHORT * quant[sm]
        lo_min = np.where(smooth[sm - 1], K[np.maximum(sm - 2, 0)], K[sm - 1])
        hi_max = np.where(smooth[sm + 1], K[np.minimum(sm + 2, n - 1)], K[sm + 1])
        lo_w = np.maximum(lo_min, np.minimum(lo, K[sm] - _SMOOTH_HALF))
        hi_w = np.minimum(hi_max, np.maximum(hi, K[sm] + _SMOOTH_HALF))
        # (elsewhere too where that reaches _SMOOTH_HALF points: a window of a few points
        # of a curve flattened into long steps, near a lattice slope, gives a tangent several
        # degrees off)
        wide_lo = (ln[sm - 1] <= short) | (_SMOOTH_ALWAYS & (K[sm] - lo_w >= _SMOOTH_HALF)
                                           & (K[sm] - lo < _SMOOTH_FEW))
        wide_hi = (ln[sm] <= short) | (_SMOOTH_ALWAYS & (hi_w - K[sm] >= _SMOOTH_HALF)
                                       & (hi - K[sm] < _SMOOTH_FEW))
        lo = np.where(wide_lo, lo_w, lo)
        hi = np.where(wide_hi, hi_w, hi)
        pos, tan, ok = _local_fits(W, arc, np.minimum(lo, K[sm]), np.maximum(hi, K[sm]), K[sm])
        k = sm[ok]
        h = 0.5 * quant[k][:, None]
        est = pos[ok]
        if _SMOOTH_ALONG:
            # beside a design line written as its two rounded ends (one input step of at
            # least _JOINT_LINE quanta: the thinned segment), only the move along that line
            # (a move across tilts the line, its far end fixed, off the design line its ends
            # were rounded from: sans "B" at em 400, a 63-unit line into a tangent curve,
            # 0.63 from the design where the rounded input is 0.44)
            wk = W[K[k]]
            # (also where that line is most of a thinned segment of more steps, the rest a
            # few short steps of the curve's start at the vertex, _SMOOTH_ALONG_SHARE: URW
            # Bookman Light Italic "m" at em 2048, a 78-unit line meeting a curve at 13
            # degrees, the line tilted 0.4 off its row, 0.69 from the design where the
            # rounded input is 0.33); each thinned segment beside the vertices once
            sg = np.unique(np.concatenate([k - 1, k]))
            if wstep is None:
                wstep = _step_lengths(W)
            along, dirs = _line_steps(W, wstep, K[sg], K[sg + 1], quant[sg])
            gi = along[np.searchsorted(sg, k - 1)]
            go = along[np.searchsorted(sg, k)]
            one = gi ^ go
            if one.any():
                d = np.where(gi[:, None], dirs[np.searchsorted(sg, k - 1)],
                             dirs[np.searchsorted(sg, k)])[one]
                d = d / np.hypot(d[:, 0], d[:, 1])[:, None]
                est[one] = wk[one] + ((est[one] - wk[one]) * d).sum(axis=1)[:, None] * d
            est[gi & go] = wk[gi & go]
        if _SMOOTH_SIDES:
            # (beside a design line the move along it above stays)
            two = (((K[k] - np.minimum(lo, K[sm])[ok] >= _SMOOTH_SIDES) | smooth[k - 1]
                    | (ln[k - 1] > short[ok]))
                   & ((np.maximum(hi, K[sm])[ok] - K[k] >= _SMOOTH_SIDES) | smooth[k + 1]
                      | (ln[k] > short[ok])))
            if _SMOOTH_ALONG:
                two |= gi | go
            est = np.where(two[:, None], est, W[K[k]])
        Q[k] = np.clip(est, W[K[k]] - h, W[K[k]] + h)
        t_in[k] = tan[ok]
        t_out[k] = tan[ok]
    # one-sided tangents at the other vertices (corners, ends of runs)
    # (over at least _SIDE_POINTS input points: a short thinned segment is rounding)
    k_first = np.repeat(K[first], tlen)
    k_last = np.repeat(K[last], tlen)
    # (and within _CORNER_ARC quanta of arc, as the corners' sides)
    co = np.flatnonzero(~smooth & rnd & ~is_last)
    if len(co):
        hi = np.maximum(K[co + 1], _window_hi(W, arc, K[co], np.minimum(
            K[co] + _SIDE_POINTS - 1, k_last[co]), quant[co]))
        _, tan, ok = _local_fits(W, arc, K[co], hi, K[co])
        t_out[co[ok]] = tan[ok]
    ci = np.flatnonzero(~smooth & rnd & ~is_first)
    if len(ci):
        lo = np.minimum(K[ci - 1], _window_lo(W, arc, K[ci], np.maximum(
            K[ci] - _SIDE_POINTS + 1, k_first[ci]), quant[ci]))
        _, tan, ok = _local_fits(W, arc, lo, K[ci], K[ci])
        t_in[ci[ok]] = tan[ok]
    _corners_on_the_design(W, K, Q, arc, smooth, rnd, first, last, quant, eps, found, coarse,
                           wstep)


#: one-sided tangents of rounded input are fitted over at least this many input points
_SIDE_POINTS = 20
#: a corner's two sides meet at this angle or more (sine): their fitted lines are
#: intersected; below, the corner is the mean of the two sides' estimates
_CORNER_SINE = 0.25
#: a corner's sides are fitted over at least this many input points (a curve side; a line
#: side is its thinned segment): the position at a sharp tip between two curves is then
#: nearer the design (sans-bold "8": 0.64 -> under 0.63 from the true curve)
_CORNER_POINTS = _SIDE_POINTS
#: ... and over at most this many quanta of arc length (20 points of a densely flattened
#: curve, about 2 quanta apart once rounded): input flattened coarser, at a few quanta
#: between points, then fits the same stretch of the design (20 of its points would reach
#: 80-160 quanta around the corner, where a quadratic no longer follows the curve: the tip
#: of sans "R" at chord height 0.01 0.667 from the design, serif "8" 0.642), down to
#: ``_WINDOW_MIN`` points
_CORNER_ARC = 60.0
#: an arc-limited window keeps at least this many input points (a quadratic over 4 points of
#: a coarse circle, 70-unit chords, follows their rounding: test_fit_coarse.py)
_WINDOW_MIN = 6


#: ... where the input is coarse only: the window's curve part (its points past its last
#: long step: a corner's window may run along a line first, in dense input too) has at least
#: ``_CURVE_POINTS`` points and bends off the chord between its ends by more than this many
#: quanta, scaled to 20 points by ((n - 1) / 19)^2 (20 points of a curve flattened at chord
#: height h bend about 361 h off their chord whatever the curve's radius: 0.7 quanta for
#: h = 0.002 quanta, dense input, whose windows then stay as they are (bench_fit_hash.py
#: bit-identical); 3.6 for h = 0.01; the step length alone does not tell them apart: dense
#: DejaVu Sans Bold has 3-4 unit steps on its flatter curves)
_COARSE_BEND = 2.0
#: a long step: over this many times the mean of the window's steps after it
_EVEN_STEP = 2.0
#: fewer points of a curve part than this bend too little to tell its flattening from the
#: rounding: the window stays
_CURVE_POINTS = 15


def _arc_window(W, arc, k, end, quant, step):
    """The window of input points from ``k`` to ``end`` (global indices, ``end`` at most
    ``_CORNER_POINTS`` - 1 before k (``step`` -1) or after it (+1), in k's path; ``arc`` per
    path) cut to those within ``_CORNER_ARC`` quanta of arc of k, keeping at least
    ``_WINDOW_MIN`` points (not past ``end``), where the input is coarse (the window's curve
    part bends more than ``_COARSE_BEND`` quanta off its chord, scaled to 20 points); elsewhere
    ``end``. Returns the window's far end."""
    out = end.copy()
    # (only windows reaching farther than _CORNER_ARC quanta can be cut: few on dense input)
    sub = np.flatnonzero(np.abs(arc[end] - arc[k]) > _CORNER_ARC * quant)
    if len(sub) == 0:
        return out
    k, end, quant = k[sub], end[sub], quant[sub]
    idx = k[:, None] + step * np.arange(_CORNER_POINTS)[None, :]
    inw = (idx - end[:, None]) * step <= 0
    idx = np.clip(idx, 0, len(arc) - 1)
    span = np.abs(arc[idx] - arc[k][:, None])
    near = inw & (span <= _CORNER_ARC * quant[:, None])
    cut = k + step * np.maximum(near.sum(axis=1) - 1, _WINDOW_MIN - 1)
    cut = np.where((cut - end) * step < 0, cut, end)
    c = np.flatnonzero(cut != end)
    if len(c):
        # (the curve part of the window: its points past its last long step, one over
        # _EVEN_STEP times the mean step of the steps after it)
        sc = span[c]
        st = np.where(inw[c, 1:], np.diff(sc, axis=1), 0.0)
        cnt = np.abs(end[c] - k[c])
        rest = (sc[np.arange(len(c)), cnt][:, None] - sc[:, 1:]).clip(0)
        after = cnt[:, None] - np.arange(1, _CORNER_POINTS)[None, :]
        long = (st > _EVEN_STEP * rest / np.maximum(after, 1)) & (after >= 1)
        start = np.where(long.any(axis=1), _CORNER_POINTS - 1 - np.argmax(long[:, ::-1], axis=1),
                         0)
        n_c = cnt - start + 1
        # (its bend: the largest distance of its points to its chord)
        a = W[idx[c, start]]
        ch = W[end[c]] - a
        rel = W[idx[c]] - a[:, None, :]
        off = np.abs(rel[..., 0] * ch[:, None, 1] - rel[..., 1] * ch[:, None, 0])
        part = inw[c] & (np.arange(_CORNER_POINTS)[None, :] >= start[:, None])
        off = np.where(part, off, 0.0).max(axis=1)
        # (coarse: 20 points of it would bend more than _COARSE_BEND quanta)
        lim = _COARSE_BEND * quant[c] * ((n_c - 1) / (_CORNER_POINTS - 1)) ** 2
        keep = (n_c < _CURVE_POINTS) | (off <= lim * np.hypot(ch[:, 0], ch[:, 1]))
        cut[c[keep]] = end[c[keep]]
    out[sub] = cut
    return out


def _window_lo(W, arc, k, lo, quant):
    """:func:`_arc_window` backwards from ``k``: the window's first index (>= ``lo``)."""
    return _arc_window(W, arc, k, lo, quant, -1)


def _window_hi(W, arc, k, hi, quant):
    """:func:`_arc_window` forwards from ``k``: the window's last index (<= ``hi``)."""
    return _arc_window(W, arc, k, hi, quant, 1)

#: ... and give no estimate where one of its input points lies this many quanta or more off
#: its quadratic (the window spans another corner: sans-light "J" at em 400, a 16-unit side
#: fitted across its far corner moved the corner 0.5 away from the design's, 0.90 from it)
_CORNER_RES = 1.0
#: ... and a curve side beside a side of two input points (:func:`_lone_sides`) gives no
#: crossing where one of its input points lies this many quanta or more off its quadratic:
#: the crossing slides along the line by the curve's error there (Inconsolata "5" at em 700,
#: a quadratic over a short S-shaped cubic's inflection, 0.84 quanta off: the corner 0.67
#: from the design where the rounded input is 0.49); the corner stays
_LONE_RES = 0.75
#: a curve side whose run has more input points than its window: a second quadratic over up
#: to this many points (within ``_LONG_ARC`` quanta of arc), averaged with the first where
#: its points too stay within ``_LONG_RES`` quanta of it: the rounding's error at a window's
#: end falls with its count, a quadratic's bias grows with its span (fifteenth session, the
#: curve sides at the corners of ten typefaces, whole units, em 400-2048: the distance of the
#: design corner from the estimated tangent line over 99 % of them 0.49 -> 0.47 and
#: 0.46 -> 0.42, over 0.4 quanta 68 -> 53 and 80 -> 44 of 2456 and 3433; 30 or 40 points
#: alone give a larger worst); 0: off
_CORNER_LONG = 30
#: ... (the arc length, in quanta, that second window may reach from the corner)
_LONG_ARC = 90.0
#: ... (rounding alone keeps the points within q/sqrt(2) of the design; with 1.0 instead the
#: worst of those distances on the second set 0.69, with 0.75 0.58; C059 "X" at em 1000, a
#: wiggle, 0.64 -> 0.74 from the design with 1.0)
_LONG_RES = 0.75
#: ... also at tips (turns over 120 degrees, ``_TIP_COS``) if True (for measurements)
_LONG_AT_TIPS = False


#: a side written as its two rounded ends only gives the corner a direction where it is at
#: least this many quanta long (the direction then within about 1/this radian)
_LONE_LENGTH = 8.0
#: ... and meets the curve's tangent there at this angle or more (sine): the intersection
#: then; below, an error in the line's offset would move it far along the line
_LONE_SINE = 0.9
#: ... and moves it by at least this many half quanta (less is within the estimate's
#: own error: the input point stays)
_LONE_MIN_MOVE = 0.2
#: a corner whose move makes a line beside it miss its input points goes back half its move
#: at a time, this many times, before it goes back to its input point
_CORNER_HALVINGS = 2
#: ... a line beside it: a thinned segment whose other end is a corner too. A segment of
#: short input steps to a smooth vertex is not held to that: it lies in a curve run, fitted
#: by cubics that the fitter holds to the bound (and where it stays a line,
#: :func:`_valid_lines` makes it valid). URW Z003 Medium Italic "z" at em 2048: a 77-degree
#: corner kept one point late whose curve side misses its points by 0.82 as a line wherever
#: the corner is went back to its input point, 0.92 from the design where the rounded input
#: is 0.48. Still held: a segment with an input step of ``_LONE_LENGTH`` quanta or more (a
#: design line that :func:`_lone_lines_out` may give back as a line: P052 Bold Italic "$" at
#: em 2048, a 123-unit line after a curve's straight end, 0.89 from their joint) and a row of
#: the grid, its input points on their chord (a design line), and those beside a closed
#: path's seam (serif "g" at em 400, a seam 6 degrees from smooth moved 0.15 off a design
#: line by its sides' mean position, the cubic to it 0.70 from the design where the rounded
#: input is 0.45) or beside two corners a short segment apart (P052 Bold Italic "$" at em
#: 2048: both moved, the cubics failed, three lines 0.82 from the design where the rounded
#: input is 0.39). False: every segment beside a corner, for measurements
_CORNER_LINES_ONLY = True
#: a corner turning by more than 120 degrees (the cosine of its turn below this) is a tip: an
#: error d in either side's estimated offset moves the tangents' crossing by d / sin(interior
#: angle) along the tip's axis, more than the rounding ...
_TIP_COS = -0.5
#: ... so a crossing that cuts the tip (moves the corner inward along its axis) by more than
#: this many quanta moves across the axis only (serif "g" at em 400: the crossing cut the
#: tip by 0.55 quanta, the fit 1.055 from the design; a tip's rounded point is within
#: q/sqrt(2) of the design's outline, and smaller cuts and moves outward hold; C059 "2" at
#: em 2048, a 134-degree tip on a design line written as a row of the grid, whose offset is
#: the rounding's: a cut of 0.36 quanta put the fit 0.78 from the design where the rounded
#: input is 0.53; P052 Bold Italic "n", a 166-degree tip, 0.40 quanta, 0.75 against 0.52)
_TIP_CUT = 0.3
#: ... and one that stretches the tip (moves the corner outward along its axis) by more than
#: this many quanta too (sans-light "g" at em 400, a 160-degree tip: the crossing 1.0 beyond
#: the input point, the fit 0.73 from the design where the rounded input is 0.36)
_TIP_OUT = 0.45


def _lone_sides(W, K, smooth, v, w, quant, p, t, ok, ok_other, after=False) -> np.ndarray:
    """:func:`_corners_on_the_design`'s sides (position ``p``, tangent ``t``, ``ok``, in
    place) at the corners ``v`` (the vertex as the end of the side, the next one's start
    ``w``) whose side before them (``after``: after them) is a line over two input points
    (its ends, no least-squares line) while the other side is a curve (its fit ``ok_other``):
    the line through those two rounded ends, where it is at least ``_LONE_LENGTH`` quanta
    long. Its intersection with the curve's tangent puts the corner where the design line
    meets the design curve, up to the rounding of the line's offset."""
    near = v
    far, other = (v + 1, w - 1) if after else (v - 1, w + 1)
    sel = ~ok & ok_other & ~smooth[far] & smooth[other] & (np.abs(K[near] - K[far]) == 1)
    if not sel.any():
        return sel
    a, b = W[K[far][sel]], W[K[near][sel]]
    d = (b - a) if not after else (a - b)
    ln = np.hypot(d[:, 0], d[:, 1])
    p[sel] = b
    t[sel] = d / np.maximum(ln, 1e-300)[:, None]
    ok[sel] = ln >= _LONE_LENGTH * quant[near][sel]
    return sel & ok


#: a least-squares line's input points are collinear where none lies farther than this many
#: quanta from it
_STRAIGHT_SLACK = 0.1


def _collinear(W, a, b, p, t, quant) -> np.ndarray:
    """Per line through ``p`` along the unit ``t``: do the input points a..b (global
    indices, ends included) all lie on it (within ``_STRAIGHT_SLACK`` quanta)? Rounded points
    of a slightly curved stretch scatter about their least-squares line by up to the rounding
    as those of a straight line do; points that are collinear are a straight design line (or
    a curve that stays inside one row of rounding squares: its points are then on that line
    too)."""
    if len(a) == 0:
        return np.zeros(0, dtype=bool)
    return _line_residuals(W, a, b, p, t) <= _STRAIGHT_SLACK * quant


def _line_residuals(W, a, b, p, t) -> np.ndarray:
    """Per line through ``p`` along the unit ``t``: the largest distance of the input points
    a..b (global indices, ends included, at least one) to it."""
    own, off = _ragged(np.arange(len(a)), b - a + 1)
    d = W[a[own] + off] - p[own]
    across = np.abs(d[:, 0] * t[own, 1] - d[:, 1] * t[own, 0])
    return np.maximum.reduceat(across, np.cumsum(b - a + 1) - (b - a + 1))


#: rounded input: two corners with a thinned segment of at most this many input steps ...
_SPLIT_STEPS = 3
#: ... and at most this many quanta between them are one design corner that the thinning
#: split (the corner's rounded point between them, or on one of them)
_SPLIT_LENGTH = 4.0
#: ... where their sides' crossing is within this many quanta of an input point between them
_SPLIT_NEAR = 1.5


def _split_corners(W, K, vi, vo, quant, p_in, t_in, ok_in, p_out, t_out, ok_out, est,
                   both) -> None:
    """:func:`_corners_on_the_design`'s estimates (``est``, ``both``, in place; per corner
    as the end ``vi`` and start ``vo`` of its segments, their sides' estimates) at two
    corners that the thinning split out of one (``_SPLIT_STEPS``, ``_SPLIT_LENGTH``): each
    estimated alone takes the short segment between them as a side and cuts the design's
    corner (Cantarell "&" at em 1500, an 85-degree corner between two curves: 0.84 from the
    design where the rounded input is 0.5). Both move toward the one corner where the side
    before the first and the side after the second cross, at an angle (``_CORNER_SINE``, not
    a tip), near the input points between them (``_SPLIT_NEAR``)."""
    n = int(max(vi.max(), vo.max())) + 2
    at = np.full(n, -1, dtype=np.intp)
    at[vi] = np.arange(len(vi))
    b = at[vo + 1]
    a = np.flatnonzero(b >= 0)
    if len(a) == 0:
        return
    b = b[a]
    v = vo[a]
    ka, kb = K[v], K[v + 1]
    q = quant[v]
    pair = (kb - ka <= _SPLIT_STEPS) & (np.hypot(*(W[kb] - W[ka]).T) <= _SPLIT_LENGTH * q)
    # (not a chain of three or more such corners)
    chain = np.zeros(len(vo), dtype=bool)
    chain[a[pair]] = True
    pair &= ~chain[b]
    chain_b = np.zeros(len(vo), dtype=bool)
    chain_b[b[pair]] = True
    pair &= ~chain_b[a]
    pair &= ok_in[a] & ok_out[b]
    if not pair.any():
        return
    a, b, ka, kb, q = a[pair], b[pair], ka[pair], kb[pair], q[pair]
    ti, to = t_in[a], t_out[b]
    cr = ti[:, 0] * to[:, 1] - ti[:, 1] * to[:, 0]
    good = (np.abs(cr) >= _CORNER_SINE) & ((ti * to).sum(axis=1) >= _TIP_COS)
    # ... and the short segment's direction between the two sides' (one turn split in two;
    # not a short design line between two tips: Cantarell Thin "8" at em 2048, 2.9 units)
    m = W[kb] - W[ka]
    c1 = ti[:, 0] * m[:, 1] - ti[:, 1] * m[:, 0]
    c2 = m[:, 0] * to[:, 1] - m[:, 1] * to[:, 0]
    good &= (c1 * cr >= 0.0) & (c2 * cr >= 0.0) & ((ti * m).sum(axis=1) > 0.0)
    good &= (m * to).sum(axis=1) > 0.0
    d = p_out[b] - p_in[a]
    s = (d[:, 0] * to[:, 1] - d[:, 1] * to[:, 0]) / np.where(good, cr, 1.0)
    c = p_in[a] + s[:, None] * ti
    # ... near the input points of the short segment (the corner is among them)
    own, off = _ragged(np.arange(len(a)), kb - ka + 1)
    dd = np.hypot(*(W[ka[own] + off] - c[own]).T)
    near = np.minimum.reduceat(dd, np.cumsum(kb - ka + 1) - (kb - ka + 1)) <= _SPLIT_NEAR * q
    good &= near
    est[a[good]] = c[good]
    est[b[good]] = c[good]
    both[a[good]] = True
    both[b[good]] = True


#: rounded input: a corner whose design estimate lies more than this many quanta outside its
#: input point's rounding square may be kept on the wrong input point (the thinning kept a
#: point beside the design's corner) ...
_MISPLACED_OFF = 0.25
#: ... its sides are then fitted again without this many input points on each side of it
#: (they may belong to the other side), and the design's corner looked for among the input
#: points this many steps around it
_MISPLACED_STEPS = 3
#: ... the input point whose rounding square is nearest the sides' crossing (within this many
#: quanta outside it) and nearer it than the kept one's by at least this many quanta
_MISPLACED_NEAR = 0.5
_MISPLACED_GAIN = 0.5
#: ... where the crossing lies at least this many quanta outside the kept point's square (a
#: tight smooth bend that the curve-run rules split also gives its sides a crossing, 1.0
#: quanta outside: serif-italic "R" at em 400, two more segments and 0.05 farther from the
#: design; the corners moved here lay 1.6 (Cantarell "8" at em 2048) and 2.7 quanta out)
_MISPLACED_FAR = 1.25
#: ... the same where the corner's own estimate (its full windows' crossing) lies in that
#: input point's square, the sides fitted again or not (URW Z003 Medium Italic "b" at em 2048:
#: a 19-degree corner between two curves kept three points late; the sides fitted again
#: without the three points beside it cross past the kept point, while the estimate lies
#: 0.4 q outside the design corner's square: 0.78 from the design where the rounded input is
#: 0.54; False: off, for measurements)
_MISPLACED_EST = True


def _misplaced_corners(W, K, arc, vi, vo, lo_i, hi_o, line_in, line_out, est, cand, quant):
    """:func:`_corners_on_the_design`'s corners (``vi``, ``vo``; their windows ``lo_i``,
    ``hi_o``; ``line_in``/``line_out``: that side is a line) kept on an input point beside the
    design's corner: where the estimate ``est`` (``cand``: a crossing of two sides) lies over
    ``_MISPLACED_OFF`` quanta outside the thinned point's rounding square, the sides are fitted
    again without the ``_MISPLACED_STEPS`` input points next to the thinned point, and where
    their crossing lies in (within ``_MISPLACED_NEAR`` quanta of) the rounding square of
    another input point up to ``_MISPLACED_STEPS`` steps away inside the two thinned segments,
    nearer by ``_MISPLACED_GAIN`` quanta than the kept one's, and at least ``_MISPLACED_FAR``
    quanta outside the kept one's, that point is the corner (or where ``est`` itself lies so,
    ``_MISPLACED_EST``).
    Returns (thinned index of the corner, global index of the input point)."""
    none = (np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp))
    k = K[vo]
    q = quant[vo]
    off = np.abs(est - W[k]).max(axis=1) - 0.5 * q
    sel = cand & (vi == vo) & (off > _MISPLACED_OFF * q)
    if not sel.any():
        return none
    c = np.flatnonzero(sel)
    v, k, q = vo[c], k[c], q[c]
    S = _MISPLACED_STEPS
    lo, hi = lo_i[c], k - S
    lo2, hi2 = k + S, hi_o[c]
    li, lo_ = line_in[c], line_out[c]
    ok = (hi - lo + 1 >= np.where(li, 3, _WINDOW_MIN)) & (hi2 - lo2 + 1 >= np.where(lo_, 3,
                                                                                    _WINDOW_MIN))
    if not ok.any():
        return none
    v, k, q, lo, hi, lo2, hi2, li, lo_ = (x[ok] for x in (v, k, q, lo, hi, lo2, hi2, li, lo_))
    x, good = _sides_crossing(W, arc, lo, hi, lo2, hi2, k, li, lo_)
    # the candidates: the input points k - S .. k + S strictly inside the two segments
    cands = k[:, None] + np.arange(-S, S + 1)[None, :]
    inside = (cands > K[v - 1][:, None]) & (cands < K[v + 1][:, None])
    cands = np.clip(cands, 0, len(W) - 1)

    def nearest(p):
        # per corner: the candidate whose rounding square lies nearest p, and whether that
        # point is the corner (near p, nearer than the kept one's, which lies far from p)
        dist = np.abs(W[cands] - p[:, None, :]).max(axis=2) - 0.5 * q[:, None]
        dist = np.where(inside, dist, np.inf)
        best = np.argmin(dist, axis=1)
        db = dist[np.arange(len(v)), best]
        d0 = dist[:, S]
        return best, ((best != S) & (db <= _MISPLACED_NEAR * q)
                      & (d0 - db >= _MISPLACED_GAIN * q) & (d0 >= _MISPLACED_FAR * q))

    best, hit = nearest(x)
    good &= hit
    if _MISPLACED_EST:
        # ... or the estimate itself (the crossing of the full windows) in such a square
        best2, hit2 = nearest(est[np.flatnonzero(sel)[ok]])
        use = ~good & hit2
        best = np.where(use, best2, best)
        good |= use
    return v[good], cands[np.flatnonzero(good), best[good]]


#: rounded input: a sharp corner kept up to this many input points beside the design's
#: (:func:`_corners_shifted`) ...
_SHIFT_STEPS = 2
#: ... where the sides fitted with the corner at another input point c (their windows ending
#: and starting there) fit their points better, their largest residuals summed lower by this
#: many quanta, and cross inside c's rounding square, while those of the kept point cross
#: outside its own (C059 "5" at em 2048, a 28-degree corner kept one point late, 0.73 from
#: the design where the rounded input is 0.50)
_SHIFT_GAIN = 0.1
#: ... (inside: up to this many quanta outside it, the crossing's own error; the kept point's
#: crossing lies farther out than that)
_SHIFT_NEAR = 0.1
#: (False: off, for measurements)
_SHIFT = True


def _sides_crossing(W, arc, lo1, hi1, lo2, hi2, at, line1, line2, res=None):
    """A corner's two sides at the input points ``at``: least-squares quadratics over the
    input points lo1..hi1 and lo2..hi2 (:func:`_local_fits`; a least-squares line where
    ``line1`` / ``line2``, :func:`_local_lines`) and the crossing of their tangent lines:
    (crossing (V, 2), ok: both sides fitted, meeting at ``_CORNER_SINE`` or more). ``res``:
    two arrays (V,) filled with each side's largest residual."""
    r1, r2 = res if res is not None else (None, None)
    p1, t1, g1 = _local_fits(W, arc, lo1, hi1, at, r1)
    p2, t2, g2 = _local_fits(W, arc, lo2, hi2, at, r2)
    for m, lo, hi, p, t, g, r in ((line1, lo1, hi1, p1, t1, g1, r1),
                                  (line2, lo2, hi2, p2, t2, g2, r2)):
        if m.any():
            p[m], t[m], g[m] = _local_lines(W, lo[m], hi[m], at[m])
            if r is not None:
                r[m] = _line_residuals(W, lo[m], hi[m], p[m], t[m])
    cr = t1[:, 0] * t2[:, 1] - t1[:, 1] * t2[:, 0]
    good = g1 & g2 & (np.abs(cr) >= _CORNER_SINE)
    d = p2 - p1
    s = (d[:, 0] * t2[:, 1] - d[:, 1] * t2[:, 0]) / np.where(good, cr, 1.0)
    return p1 + s[:, None] * t1, good


def _found_added(gv, gj, gm, v, j):
    """The corners found so far (thinned index ``gv``, input point ``gj``, whether both may
    be kept ``gm``) with the corners ``v`` (their input points ``j``, both allowed) that are
    not among them yet."""
    keep = ~np.isin(v, gv)
    return (np.concatenate([gv, v[keep]]), np.concatenate([gj, j[keep]]),
            np.concatenate([gm, np.ones(int(keep.sum()), dtype=bool)]))


def _beside_short(W, K, smooth, vi, vo, quant, length=np.inf):
    """Per corner (``vi`` as the end of the segment before it, ``vo`` as the start of the
    next): is it one of two corners at most ``_SPLIT_STEPS`` input steps and ``length``
    quanta apart (one design corner the thinning split, :func:`_split_corners`)?"""
    out = np.zeros(len(vo), dtype=bool)
    for a, b, other in ((vo, vo + 1, vo + 1), (vi - 1, vi, vi - 1)):
        out |= (~smooth[other] & (K[b] - K[a] <= _SPLIT_STEPS)
                & (np.hypot(*(W[K[b]] - W[K[a]]).T) <= length * quant[vo]))
    return out


def _corners_shifted(W, K, arc, vo, lo_i, hi_o, line_in, line_out, cand, quant):
    """:func:`_corners_on_the_design`'s sharp corners ``vo`` (where ``cand``; their windows
    ``lo_i``, ``hi_o``; ``line_in``/``line_out``: that side is a line, fitted over its thinned
    segment) kept on an input point beside the design's corner, found by the sides' fit: with
    the corner at each input point c up to ``_SHIFT_STEPS`` steps away inside its two thinned
    segments, the sides are fitted again up to c (each side's largest residual; the crossing
    of their tangent lines); c is the corner where that crossing lies in c's rounding square
    (within ``_SHIFT_NEAR`` quanta) while the kept point's crossing lies outside its own, and
    c's residuals sum lower by ``_SHIFT_GAIN`` quanta (the least sum of those).
    Returns (thinned index of the corner, global index of the input point)."""
    sel = np.flatnonzero(cand)
    v = vo[sel]
    k = K[v]
    q = quant[v]
    li, lo_ = line_in[sel], line_out[sel]
    a_in = np.where(li, K[v - 1], lo_i[sel])
    b_out = np.where(lo_, K[v + 1], hi_o[sel])

    def sides(c):
        # per corner: (valid, crossing off c's square in quanta, residuals summed)
        ok = (c > K[v - 1]) & (c < K[v + 1])
        ok &= c - a_in + 1 >= np.where(li, 3, 4)
        ok &= b_out - c + 1 >= np.where(lo_, 3, 4)
        c = np.where(ok, c, k)
        r1 = np.empty(len(v))
        r2 = np.empty(len(v))
        x, good = _sides_crossing(W, arc, a_in, c, c, b_out, c, li, lo_, (r1, r2))
        ok &= good
        off = (np.abs(x - W[c]).max(axis=1) - 0.5 * q) / q
        return ok, off, (r1 + r2) / q

    ok0, off0, sum0 = sides(k)
    best = k.copy()
    best_sum = np.where(ok0 & (off0 > _SHIFT_NEAR), sum0 - _SHIFT_GAIN, -np.inf)
    for s in range(-_SHIFT_STEPS, _SHIFT_STEPS + 1):
        if s == 0:
            continue
        ok, off, sm = sides(k + s)
        take = ok & (off <= _SHIFT_NEAR) & (sm <= best_sum)
        best = np.where(take, k + s, best)
        best_sum = np.where(take, sm, best_sum)
    moved = best != k
    return v[moved], best[moved]


#: ... (:func:`_corners_beside_gaps`) where the input steps between the thinned corner and the
#: line's end are at most this many quanta each (a curve's steps; a longer one is a short
#: design line of its own, whose ends are both corners: Cantarell Thin "g" at em 1500, a
#: 6-unit line between a long one and the curve)
_GAP_STEP = 4.0


#: ... and the thinned corner is kept beside the line's end only where the line from its far
#: end to the thinned corner misses the line's end by this many quanta or more (else that
#: line serves the design nearly as well, and a second vertex only adds a segment: Cantarell
#: "@" at em 1500, 0.13). The miss adds to the rounding of the line's end (up to q/sqrt(2)
#: the other way): Z003 Medium Italic "G" at em 2048, a miss of 0.46 put the fit 0.99 from
#: the design's corner where the rounded input is 0.56 (0.5 let it stand)
_GAP_MISS = 0.3
#: ... and the line (its two rounded ends) at least this many quanta long, under
#: ``_LONE_LENGTH``: beside a curve's steps (each at most a third of it, ``_GAP_RATIO``) a
#: shorter step is a design line too (FreeSerif Italic "n" at em 2048: a 7.2-unit line kept
#: one step into the curve, 0.74 from the design where the rounded input is 0.30)
_BESIDE_LENGTH = 6.0


def _corners_beside_gaps(W, K, vo, smooth, quant, coarse, t_in, ok_in, t_out, ok_out):
    """Rounded input: the corners ``vo`` (thinned indices) between a curve and a design line
    written as its two rounded ends (a step of at least ``_BESIDE_LENGTH`` quanta, not a chord of
    a coarse curve, ``coarse``) that the thinning kept up to ``_MISPLACED_STEPS`` short input
    steps (each under 1 / ``_GAP_RATIO`` of the line and ``_GAP_STEP`` quanta) into the curve
    past the line's end: the
    line's end is the design's corner (sans "Q" at em 400: kept one step into the curve, the
    fit 0.78 from the design where the rounded input is 0.42; serif-italic "a", two steps,
    0.81 against 0.44), where the curve's tangent there (``t_out`` after the line, ``t_in``
    before it, where ``ok_out`` / ``ok_in``) turns from the line by ``_CORNER_SINE`` or more
    (a curve running tangentially into the line is no corner: serif-italic "R" at em 1000,
    its corner estimate at the line's end then left the line's row, 0.67 from the design
    where the rounded input is 0.45). Returns (thinned index of the corner, global index of
    the line's end, whether both may be kept: ``_GAP_MISS``)."""
    out_v, out_j, out_m = [], [], []
    if len(vo) == 0:
        return (np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp),
                np.zeros(0, dtype=bool))
    k = K[vo]
    q = quant[vo]
    n = len(W)
    for side in (-1, 1):
        # the line's end j = k + side * s, the line from j to j + side
        # (the other side a curve: a curve run, or a thinned segment of at least _GAP_REST
        # input steps; not a polyline's few short strokes)
        other = smooth[vo + 1] if side < 0 else smooth[vo - 1]
        other |= (K[vo + 1] - k if side < 0 else k - K[vo - 1]) >= _GAP_REST
        nb = K[vo - 1] if side < 0 else K[vo + 1]  # the thinned neighbour on this side
        found = np.zeros(len(vo), dtype=bool)
        for s in range(1, _MISPLACED_STEPS + 1):
            j = k + side * s
            f = j + side  # the line's far end
            ok = other & ~found & ((f - nb) * side <= 0)
            jj = np.clip(j, 0, n - 1)
            ff = np.clip(f, 0, n - 1)
            ln = np.hypot(*(W[ff] - W[jj]).T)
            ok &= ln >= _BESIDE_LENGTH * q
            ok &= ~coarse[np.minimum(jj, ff)]
            # (a corner: the curve's tangent turns from the line)
            tc, okc = (t_out, ok_out) if side < 0 else (t_in, ok_in)
            u = (W[jj] - W[ff]) * -side  # the line's direction along the path
            cr = (u[:, 0] * tc[:, 1] - u[:, 1] * tc[:, 0]) / np.maximum(ln, 1e-300)
            dt = (u * tc).sum(axis=1)
            ok &= okc & ((np.abs(cr) >= _CORNER_SINE) | (dt < 0.0))
            # (the steps from k to j short beside the line, and a curve's: at most
            # _GAP_STEP quanta)
            for t in range(s):
                a = np.clip(k + side * t, 0, n - 1)
                b = np.clip(k + side * (t + 1), 0, n - 1)
                st = np.hypot(*(W[b] - W[a]).T)
                ok &= (st * _GAP_RATIO <= ln) & (st <= _GAP_STEP * q)
            found |= ok
            out_v.append(vo[ok])
            out_j.append(j[ok])
            # (how far the line from its far end to the kept point misses the line's end)
            d = W[k] - W[ff]
            r = W[jj] - W[ff]
            miss = np.abs(d[:, 0] * r[:, 1] - d[:, 1] * r[:, 0]) / np.maximum(
                np.hypot(d[:, 0], d[:, 1]), 1e-300)
            out_m.append((miss >= _GAP_MISS * q)[ok])
    return np.concatenate(out_v), np.concatenate(out_j), np.concatenate(out_m)


def _side_directions(W, a, b, t, ok) -> np.ndarray:
    """Unit directions of corner sides from input point b to a: ``t`` where ``ok``, else the
    chord's (a side without a usable quadratic)."""
    d = W[a] - W[b]
    ln = np.hypot(d[:, 0], d[:, 1])
    d = d / np.where(ln > 0.0, ln, 1.0)[:, None]
    return np.where(ok[:, None], t, d)


def _longer_sides(W, arc, k, end, bound, quant, p, t, ok, step) -> None:
    """:func:`_corners_on_the_design`'s curve sides at the input points ``k`` (window to
    ``end``, ``step`` -1: before k, +1: after it) with more input points up to ``bound`` (the
    run's other corner or the path's end): a second quadratic over up to ``_CORNER_LONG``
    points within ``_LONG_ARC`` quanta of arc of k, averaged with the first (``p``, ``t`` in
    place) where both are good and its points stay within ``_LONG_RES`` quanta of it."""
    cnt = (k - end) * -step + 1
    far = k + step * (_CORNER_LONG - 1)
    far = np.where((far - bound) * step > 0, bound, far)
    sel = np.flatnonzero(ok & (cnt >= _CORNER_POINTS) & ((far - end) * step > 0))
    if len(sel) == 0:
        return
    k, far, quant = k[sel], far[sel], quant[sel]
    # (cut to _LONG_ARC quanta of arc)
    idx = k[:, None] + step * np.arange(_CORNER_LONG)[None, :]
    inw = (idx - far[:, None]) * step <= 0
    idx = np.clip(idx, 0, len(arc) - 1)
    near = inw & (np.abs(arc[idx] - arc[k][:, None]) <= _LONG_ARC * quant[:, None])
    far = k + step * (near.sum(axis=1) - 1)
    lo, hi = (far, k) if step < 0 else (k, far)
    res = np.empty(len(sel))
    p2, t2, ok2 = _local_fits(W, arc, lo, hi, k, res)
    ok2 &= (res <= _LONG_RES * quant) & (np.abs(far - k) + 1 > cnt[sel])
    g = sel[ok2]
    if len(g) == 0:
        return
    p[g] = 0.5 * (p[g] + p2[ok2])
    tt = t[g] + t2[ok2]
    ln = np.hypot(tt[:, 0], tt[:, 1])
    t[g] = tt / np.where(ln > 0.0, ln, 1.0)[:, None]


def _corners_on_the_design(W, K, Q, arc, smooth, rnd, first, last, quant, eps,
                           found=None, coarse=None, wstep=None) -> None:
    """Rounded input: the corners (thinned vertices that are not smooth; a closed path's seam too)
    move inside their rounding squares onto an estimate of the design's corner. Per side, the
    input points of the thinned segment on that side give a position and a tangent at the
    corner: their least-squares line where the segment is a line (its other end a corner too),
    else a least-squares quadratic (over at least ``_CORNER_POINTS`` input points of the path).
    The corner is the intersection of the two tangent lines where they cross at an angle, else
    the mean of the two positions; at a tip (a turn of more than 120 degrees, ``_TIP_COS``) a
    crossing that cuts the tip by more than ``_TIP_CUT`` quanta keeps only its move across
    the tip's axis, and so does one that stretches it by more than ``_TIP_OUT`` quanta. A
    corner between two long input steps (two design lines written as their rounded ends)
    stays; two corners with a short segment between them are one corner the thinning split
    (:func:`_split_corners`).
    A side that is a line over two input points only (no least-squares line) beside a curve side
    is the line through its two rounded ends (:func:`_lone_sides`), intersected with the curve's
    tangent where they cross at ``_LONE_SINE`` or more; at a middling angle (``_CORNER_SINE`` to
    ``_LONE_SINE``: an error in the line's offset would move the intersection far) the corner
    stays. A corner goes back toward its input point (half its move at a time, then all of
    it) where a line from it to a neighbouring thinned point would miss its input points by
    more than ``eps`` (per thinned point), so the lines keep their bound (the
    curve side of a corner with a two-point side is not held to that: the fitter tests its
    cubics against the bound, and a line there is made valid by :func:`_valid_lines`). In place
    on ``Q``; ``wstep`` as in :func:`_on_the_design`."""
    n = len(Q)
    is_first = np.zeros(n, dtype=bool)
    is_first[first] = True
    is_last = np.zeros(n, dtype=bool)
    is_last[last] = True
    # vi: the vertex as the end of the segment before it, vo: as the start of the next one
    vo = np.flatnonzero(~smooth & rnd & ~is_first & ~is_last)
    vi = vo.copy()
    seam = (last - first >= 3) & (W[K[first]] == W[K[last]]).all(axis=1) & rnd[first]
    seam &= ~smooth[first]
    if seam.any():
        vi = np.concatenate([vi, last[seam]])
        vo = np.concatenate([vo, first[seam]])
    if len(vo) == 0:
        return
    k = K[vo]
    # a curve side: over at least _CORNER_POINTS input points (within the path)
    pid_i = np.searchsorted(last, vi)
    pid_o = np.searchsorted(last, vo)
    # (and within _CORNER_ARC quanta of arc: coarser input, the same stretch of the design)
    lo_i = np.minimum(K[vi - 1], _window_lo(W, arc, K[vi], np.maximum(
        K[vi] - _CORNER_POINTS + 1, K[first[pid_i]]), quant[vo]))
    hi_o = np.maximum(K[vo + 1], _window_hi(W, arc, k, np.minimum(
        k + _CORNER_POINTS - 1, K[last[pid_o]]), quant[vo]))
    # ... but not past the corner at the run's other end (a short run of lines that barely
    # turn: a window across other corners estimates nothing)
    idx = np.arange(n)
    stop = ~smooth | is_first | is_last
    prev_c = np.maximum.accumulate(np.where(stop, idx, 0))
    next_c = np.minimum.accumulate(np.where(stop, idx, n - 1)[::-1])[::-1]
    lo_i = np.maximum(lo_i, K[prev_c[vi - 1]])
    hi_o = np.minimum(hi_o, K[next_c[vo + 1]])
    r_in = np.empty(len(vi))
    r_out = np.empty(len(vo))
    p_in, t_in, ok_in = _local_fits(W, arc, lo_i, K[vi], K[vi], r_in)
    p_out, t_out, ok_out = _local_fits(W, arc, k, hi_o, k, r_out)
    # a curve side whose points miss their quadratic by more than _CORNER_RES quanta spans
    # another corner (a run the curve-run rules left smooth across one): no estimate
    ok_in &= r_in <= _CORNER_RES * quant[vi]
    ok_out &= r_out <= _CORNER_RES * quant[vo]
    if _CORNER_LONG:
        # (not at a tip: there the longer window's bias moves the crossing by its error over
        # the sine of the small interior angle, sans "g" at em 400 0.62 -> 0.75 from the
        # design; a side without a quadratic, a line of 2 or 3 input points, turns by its
        # thinned segment's direction)
        long = _LONG_AT_TIPS | (
            (_side_directions(W, K[vi], K[vi - 1], t_in, ok_in)
             * _side_directions(W, K[vo + 1], K[vo], t_out, ok_out)).sum(axis=1) >= _TIP_COS)
        # (prev_c / next_c stop at the path's first / last point too)
        _longer_sides(W, arc, K[vi], lo_i, K[prev_c[vi - 1]], quant[vi], p_in, t_in,
                      ok_in & long, -1)
        _longer_sides(W, arc, k, hi_o, K[next_c[vo + 1]], quant[vo], p_out, t_out,
                      ok_out & long, 1)
    # a side that is a line (its other end a corner too): its least-squares line
    lin_in = ~smooth[vi - 1]
    if lin_in.any():
        p, t, ok = _local_lines(W, K[vi - 1][lin_in], K[vi][lin_in], K[vi][lin_in])
        p_in[lin_in], t_in[lin_in], ok_in[lin_in] = p, t, ok
    lin_out = ~smooth[vo + 1]
    if lin_out.any():
        p, t, ok = _local_lines(W, k[lin_out], K[vo + 1][lin_out], k[lin_out])
        p_out[lin_out], t_out[lin_out], ok_out[lin_out] = p, t, ok
    # a line side whose first input step from the corner is a design line written as its
    # two rounded ends, most of the side's length, with more points after it: that step's
    # line (the points after it are another stretch of the design)
    if _FIRST_STEP:
        for side in (0, 1):
            v = vi if side == 0 else vo
            nb = K[v - 1] if side == 0 else K[v + 1]
            lin = ~smooth[v - 1] if side == 0 else ~smooth[v + 1]
            j = K[v] - 1 if side == 0 else K[v] + 1
            st = np.hypot(*(W[j] - W[K[v]]).T)
            seg_len = np.hypot(*(W[nb] - W[K[v]]).T)
            base = lin & (np.abs(nb - K[v]) > 1) & (st >= _LONE_LENGTH * quant[v])
            sel = base & (st >= _FIRST_SHARE * seg_len)
            if _FIRST_CHAIN:
                # ... or a side whose every input step is that long: a chain of design lines
                # each written as its rounded ends (their least-squares line is none of them)
                cand = np.flatnonzero(base & ~sel)
                if len(cand):
                    if wstep is None:
                        wstep = _step_lengths(W)
                    _, _, sl, at = _range_steps(wstep, np.minimum(nb, K[v])[cand],
                                                np.maximum(nb, K[v])[cand])
                    sel[cand] = np.minimum.reduceat(sl, at) >= _LONE_LENGTH * quant[v][cand]
            if sel.any():
                d = (W[K[v]] - W[j])[sel] if side == 0 else (W[j] - W[K[v]])[sel]
                d = d / np.hypot(d[:, 0], d[:, 1])[:, None]
                if side == 0:
                    p_in[sel], t_in[sel], ok_in[sel] = W[K[v]][sel], d, True
                else:
                    p_out[sel], t_out[sel], ok_out[sel] = W[K[v]][sel], d, True
    # a side that is a line written as its two ends only (no least-squares line) beside a
    # curve side: the line through those two rounded ends, long enough to give a direction
    # (the curve side of such a corner is not checked as a line below: the fitter checks
    # its cubics against the bound, and a line there is made valid by _valid_lines)
    lone_in = _lone_sides(W, K, smooth, vi, vo, quant, p_in, t_in, ok_in, ok_out)
    lone_out = _lone_sides(W, K, smooth, vo, vi, quant, p_out, t_out, ok_out, ok_in,
                           after=True)
    both = ok_in & ok_out
    est = 0.5 * (p_in + p_out)
    cr = t_in[:, 0] * t_out[:, 1] - t_in[:, 1] * t_out[:, 0]
    lone = lone_in | lone_out
    # a side of two points meeting a curve at a middling angle: neither estimate is good
    both &= ~lone | (np.abs(cr) >= _LONE_SINE) | (np.abs(cr) < _CORNER_SINE)
    # ... nor a curve side beside a side of two points whose points miss its quadratic by
    # _LONE_RES quanta or more (the crossing slides along the line by the curve's error)
    both &= ~(lone_out & (r_in >= _LONE_RES * quant[vi]))
    both &= ~(lone_in & (r_out >= _LONE_RES * quant[vo]))
    tip = both & ((t_in * t_out).sum(axis=1) < _TIP_COS)
    # a tip beside a design line written as its two rounded ends (one long input step) that
    # the curve-run rules put in a curve run: the quadratic over that side spans the line's
    # far end, and its tangent's error moves the crossing by the error over the sine of the
    # small interior angle (serif-italic "g" at em 400, 155 degrees: 0.78 from the design's
    # tip where the input point is 0.46): the tip stays (a side of two points taken as the
    # line through them, _lone_sides, is no quadratic: it moves)
    gap_in = ((K[vi] - K[vi - 1]) == 1) & (
        np.hypot(*(W[K[vi]] - W[K[vi - 1]]).T) >= _LONE_LENGTH * quant[vi])
    gap_out = ((K[vo + 1] - K[vo]) == 1) & (
        np.hypot(*(W[K[vo + 1]] - W[K[vo]]).T) >= _LONE_LENGTH * quant[vo])
    both &= ~(tip & ((gap_in & ~lone_in) | (gap_out & ~lone_out)))
    # a corner between two long input steps (two design lines, each written as its two rounded
    # ends: the input point is all the input says of the corner) stays, also where the
    # curve-run rules put one of those lines in a curve run and the side's quadratic, fitted
    # across the line into the curve, would move it (serif-bolditalic "3" at em 400: 0.67 from
    # the design where the rounded input is 0.53; sans-bold "@": 0.77 against 0.63)
    long_in = np.hypot(*(W[K[vi]] - W[K[vi] - 1]).T) >= _LONE_LENGTH * quant[vi]
    long_out = np.hypot(*(W[K[vo] + 1] - W[K[vo]]).T) >= _LONE_LENGTH * quant[vo]
    both &= ~(long_in & long_out)
    tip &= both
    sharp = both & (np.abs(cr) >= _CORNER_SINE)
    # a shallow corner between a curve and a least-squares line whose points are collinear:
    # on that line (the mean would tilt the whole line by the curve's error at its end)
    lin_in &= ok_in & ~lone_in
    lin_out &= ok_out & ~lone_out
    lin_in[lin_in] = _collinear(W, K[vi - 1][lin_in], K[vi][lin_in], p_in[lin_in],
                                t_in[lin_in], quant[vi][lin_in])
    lin_out[lin_out] = _collinear(W, k[lin_out], K[vo + 1][lin_out], p_out[lin_out],
                                  t_out[lin_out], quant[vo][lin_out])
    est = np.where((both & ~sharp & lin_in & ~lin_out)[:, None], p_in, est)
    est = np.where((both & ~sharp & lin_out & ~lin_in)[:, None], p_out, est)
    if sharp.any():
        d = p_out[sharp] - p_in[sharp]
        ti, to = t_in[sharp], t_out[sharp]
        s = (d[:, 0] * to[:, 1] - d[:, 1] * to[:, 0]) / cr[sharp]
        est[sharp] = p_in[sharp] + s[:, None] * ti
    if tip.any():
        # a tip cut by more than _TIP_CUT quanta: only the move across the tip's axis kept
        ax = t_in[tip] - t_out[tip]
        ax /= np.hypot(*ax.T)[:, None]
        mv = est[tip] - W[K[vo[tip]]]
        al = (mv * ax).sum(axis=1)
        cut = al < -_TIP_CUT * quant[vo[tip]]
        # ... and so is one that stretches it by more than _TIP_OUT quanta
        cut |= al > _TIP_OUT * quant[vo[tip]]
        est[tip] -= np.where(cut, al, 0.0)[:, None] * ax
    _split_corners(W, K, vi, vo, quant, p_in, t_in, ok_in & ~lone_in, p_out, t_out,
                   ok_out & ~lone_out, est, both)
    if found is not None:
        one = vi == vo  # (not a closed path's seam)
        gv, gj, gm = _corners_beside_gaps(W, K, vo[one], smooth, quant, coarse, t_in[one],
                                      ok_in[one] & ~lone_in[one], t_out[one],
                                      ok_out[one] & ~lone_out[one])
        mv, mj = _misplaced_corners(W, K, arc, vi, vo, lo_i, hi_o, ~smooth[vi - 1],
                                    ~smooth[vo + 1], est, sharp & ~lone, quant)
        gv, gj, gm = _found_added(gv, gj, gm, mv, mj)
        if _SHIFT:
            # (not a tip, nor one of two corners a short segment apart: _split_corners)
            sv, sj = _corners_shifted(W, K, arc, vo, lo_i, hi_o, ~smooth[vi - 1],
                                      ~smooth[vo + 1], sharp & ~lone & ~tip & (vi == vo)
                                      & ~_beside_short(W, K, smooth, vi, vo, quant,
                                                       _SPLIT_LENGTH), quant)
            gv, gj, gm = _found_added(gv, gj, gm, sv, sj)
        found.append((gv, gj, gm))
    vi, vo, est = vi[both], vo[both], est[both]
    lone_in, lone_out = lone_in[both], lone_out[both]
    wk = W[K[vo]]
    h = 0.5 * quant[vo][:, None]
    new = np.clip(est, wk - h, wk + h)
    # an estimate on the input point up to rounding errors is the input point
    same = np.abs(new - wk).max(axis=1) <= 1e-9 * (h[:, 0] + np.abs(wk).max(axis=1))
    # ... and so is one by a side of two points moving it less than its own uncertainty
    same |= (lone_in | lone_out) & (np.hypot(*(new - wk).T) < _LONE_MIN_MOVE * h[:, 0])
    new[same] = wk[same]
    old = Q[vo].copy()
    Q[vo] = new
    Q[vi] = new
    moved = np.zeros(n, dtype=bool)
    moved[vo] = True
    moved[vi] = True
    # a corner whose line misses its points goes back toward its input point, half its move
    # at a time (_CORNER_HALVINGS times), then to the input point (each round moves at
    # least one corner back: at most _CORNER_HALVINGS + 1 rounds per corner)
    mv = new - old
    frac = np.ones(len(vo))
    # each segment's error as last measured (``known``: its ends have not moved since)
    errs = np.empty(n)
    known = np.zeros(n, dtype=bool)
    # the thinned segments beside the corners not held to that (_CORNER_LINES_ONLY)
    free = np.zeros(n, dtype=bool)
    # (not a closed path's seam, nor one of two corners a short segment apart: the thinning
    # split one corner there, _split_corners)
    one = (vi == vo) & ~_beside_short(W, K, smooth, vi, vo, quant)
    sg = np.unique(np.concatenate([vi[one] - 1, vo[one]]))
    sg = sg[smooth[sg] | smooth[sg + 1]] if _CORNER_LINES_ONLY else sg[:0]
    if len(sg):
        if wstep is None:
            wstep = _step_lengths(W)
        _, _, sl, at = _range_steps(wstep, K[sg], K[sg + 1])
        free[sg] = np.maximum.reduceat(sl, at) < _LONE_LENGTH * quant[sg]
        # (not a row of the grid: its input points on their chord)
        a, b = K[sg], K[sg + 1]
        d = W[b] - W[a]
        t = d / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)[:, None]
        free[sg] &= ~_collinear(W, a, b, W[a], t, quant[sg])
    while True:
        # the thinned segments next to a moved corner, as lines: within eps of their points?
        seg = np.unique(np.concatenate([vi[~lone_out] - 1, vo[~lone_in]]))
        seg = seg[moved[seg] | moved[seg + 1]]
        seg = seg[~free[seg]]
        if len(seg) == 0:
            break
        new_s = seg[~known[seg]]
        errs[new_s] = _line_errors(W, np.stack([Q[new_s], Q[new_s + 1]], axis=1), K[new_s],
                                   K[new_s + 1])
        known[new_s] = True
        bad = seg[errs[seg] > eps[seg]]
        if len(bad) == 0:
            break
        hit = np.zeros(n, dtype=bool)
        hit[bad] = True
        hit[bad + 1] = True
        back = (hit[vi] | hit[vo]) & moved[vo]
        if not back.any():
            break
        frac[back] *= 0.5
        frac[back & (frac < 0.5 ** _CORNER_HALVINGS)] = 0.0
        part = old[back] + frac[back, None] * mv[back]
        Q[vo[back]] = part
        Q[vi[back]] = part
        for v in (vo[back], vi[back]):  # (the segments at those points measured again)
            known[v] = False
            known[v[v > 0] - 1] = False
        gone = back & (frac == 0.0)
        moved[vo[gone]] = False
        moved[vi[gone]] = False
        keep = ~gone
        vi, vo, old, mv, frac = vi[keep], vo[keep], old[keep], mv[keep], frac[keep]
        lone_in, lone_out = lone_in[keep], lone_out[keep]


def _step_lengths(W: np.ndarray) -> np.ndarray:
    """The lengths of the steps W[i]..W[i + 1] of the concatenated input (libm's hypot)."""
    return np.hypot(*np.diff(W, axis=0).T)


def _arc_per_path(W: np.ndarray, wlen: np.ndarray,
                  seg: np.ndarray | None = None) -> np.ndarray:
    """Cumulative arc length along the concatenated paths, restarted at 0 at every path's
    first point (the same numbers as ``cumsum`` on each path alone). ``seg``: the step
    lengths (:func:`_step_lengths`) when known."""
    arc = np.zeros(len(W))
    if len(W) < 2:
        return arc
    if seg is None:
        seg = _step_lengths(W)
    inside = np.ones(len(seg), dtype=bool)
    starts = np.cumsum(wlen) - wlen
    inside[starts[(starts > 0) & (wlen > 0)] - 1] = False  # from one path to the next
    j = np.flatnonzero(inside)
    arc[j + 1] = segmented_cumsum(seg[j], np.maximum(wlen - 1, 0))
    return arc


def _line_errors(
    work: np.ndarray, pts: np.ndarray, first: np.ndarray, last: np.ndarray
) -> np.ndarray:
    """Per line segment: the largest distance of the input points first..last (indices into
    ``work``) to the segment ``pts[k]`` (true distances, all segments at once). The first
    and last of those points are the segment's own end points (or repeats of its end), at
    distance 0, so only the points between them are measured."""
    err = np.zeros(len(first))
    cnt = last - first - 1
    has = np.flatnonzero(cnt > 0)
    if len(has) == 0:
        return err
    c = cnt[has]
    own, off = _ragged(has, c)
    idx = first[has][own] + 1 + off
    seg = pts[has][own]
    d = point_segment_distance(work[idx], seg[:, 0], seg[:, 1])
    err[has] = np.maximum.reduceat(d, np.cumsum(c) - c)
    return err


def _cubic_worst(
    work: np.ndarray,
    ctrl: np.ndarray,
    first: np.ndarray,
    last: np.ndarray,
    bound: np.ndarray,
    path: np.ndarray,
    worst: np.ndarray,
) -> np.ndarray:
    """Per path: ``worst`` raised to the largest true input-point error of its cubics.

    The fitter's per-cubic values (``bound``) are upper bounds (distances to some curve
    point). A cubic is measured exactly (seeded nearest point, input points first..last of
    ``work``) only while its bound can beat its path's largest value so far: first the
    cubic with the largest bound of every path, then all cubics still above their path's
    value; a cubic's error is the smaller of its exact value and its bound. The result is
    the largest error over all cubics whatever the order of measuring.
    """
    worst = worst.copy()
    order = np.lexsort((-bound, path))  # by path, largest bound first
    head = order[np.r_[True, path[order][1:] != path[order][:-1]]]
    done = np.zeros(len(bound), dtype=bool)
    for pick in (head, None):
        if pick is None:
            pick = np.flatnonzero(~done & (bound > worst[path]))
        pick = pick[bound[pick] > worst[path[pick]]]
        if len(pick) == 0:
            continue
        done[pick] = True
        cnt = last[pick] - first[pick] + 1
        starts = np.cumsum(cnt) - cnt
        own = np.repeat(np.arange(len(pick)), cnt)
        idx = first[pick][own] + np.arange(int(cnt.sum())) - starts[own]
        _, d = nearest_on_cubic_each(ctrl[pick], own, work[idx])
        e = np.minimum(np.maximum.reduceat(d, starts), bound[pick])
        np.maximum.at(worst, path[pick], e)
    return worst


def fit_drawing(
    drawing: Drawing,
    *,
    eps_line: float = DEFAULT_EPS_LINE,
    e_per: float = DEFAULT_E_PER,
    eps_sum: float = DEFAULT_EPS_SUM,
    batch: int = 16384,
    batch_points: int | None = None,
    cancel: Callable[[], bool] | None = None,
    quantum_units: float | Sequence[float] | np.ndarray | None = None,
) -> tuple[FittedPath, ...]:
    """:func:`fit_path` for every path of the drawing, in order (``source_index`` = position),
    fitted ``batch`` paths at a time (:func:`fit_paths`; the fixed cost per batch is a few
    hundred array calls: 512 paths per batch fit the 40,705 paths of a nesting file in 2x
    the time of 16,384); with ``batch_points`` a batch also ends once it holds that many
    input points, so a few long paths do not make one long batch. The batches do not change
    the result. ``cancel`` is called between batches; when it returns True,
    :class:`FitCancelled` is raised. ``quantum_units``: as in
    :func:`fit_paths`; default: detected on the whole drawing, per path where a path is off
    the drawing's grid (:func:`galvo_core.precision.path_quanta`)."""
    _check_params(eps_line, e_per, eps_sum)
    paths = drawing.paths
    if quantum_units is None:
        qs = path_quanta([p.points for p in paths])
    else:
        qs = np.broadcast_to(np.asarray(quantum_units, dtype=np.float64).reshape(-1),
                             (len(paths),))
    out: list[FittedPath] = []
    for b0, b1 in _batches(paths, max(1, int(batch)), batch_points):
        if cancel is not None and cancel():
            raise FitCancelled()
        chunk = paths[b0:b1]
        out += fit_paths(
            [p.points for p in chunk],
            [p.closed for p in chunk],
            eps_line=eps_line,
            e_per=e_per,
            eps_sum=eps_sum,
            source_indices=range(b0, b0 + len(chunk)),
            pens=[p.pen for p in chunk],
            quantum_units=qs[b0 : b0 + len(chunk)],
        )
    return tuple(out)


def _batches(paths: Sequence[Path], batch: int, batch_points: int | None
             ) -> list[tuple[int, int]]:
    """[b0, b1) ranges of at most ``batch`` paths each, a range also ending at the path
    that brings it to ``batch_points`` input points or more (see :func:`fit_drawing`)."""
    n = len(paths)
    if batch_points is None or n == 0:
        return [(b0, min(n, b0 + batch)) for b0 in range(0, n, batch)]
    ends = np.cumsum(np.fromiter((len(p) for p in paths), dtype=np.int64, count=n))
    out = []
    b0 = 0
    while b0 < n:
        base = int(ends[b0 - 1]) if b0 else 0
        # the first path whose end reaches base + batch_points closes the batch
        b1 = int(np.searchsorted(ends, base + batch_points, side="left")) + 1
        b1 = max(b0 + 1, min(b1, b0 + batch, n))
        out.append((b0, b1))
        b0 = b1
    return out


#: what :func:`fit_drawing` raises when its ``cancel`` callback says stop
FitCancelled = Cancelled


def warm_up() -> None:
    """Load (or, the first time on a machine, compile) the fitter's compiled kernels (the
    thinning, the Newton refinement, the local fits of rounded input) now, so that a timed
    first fit does not pay for it."""
    t = np.linspace(0.0, 2.0 * np.pi, 97)
    e = np.c_[40.0 * np.cos(t), 25.0 * np.sin(t)]
    fit_paths([e, np.round(8.0 * e)], [True, True])
    _polyline_distance_over(e, e, 0.0)  # (the smooth-stretch pass's windowed distance)


def fit_report(
    drawing: Drawing,
    *,
    eps_line: float = DEFAULT_EPS_LINE,
    e_per: float = DEFAULT_E_PER,
    eps_sum: float = DEFAULT_EPS_SUM,
    quantum_units: float | Sequence[float] | np.ndarray | None = None,
    per_path: bool = False,
) -> dict[str, object]:
    """Paper 000 Table 1 row for a drawing: input_points, thinned_points, control_points
    (see :func:`control_points`), lines, cubics, max_error (input units), seconds (wall
    time of the fit; the one-time load of the compiled thinning is not counted), and the
    precision in effect: quantum_units (the drawing's grid, 0 for exact input; the largest
    of the paths'), eps_line_in_effect / e_per_in_effect (the bounds from the input points:
    the user's values plus the rounding, :func:`rounding_slack`).

    With ``per_path``: "paths", one dict per path (index, pen, closed, input_points,
    segments, lines, cubics, quantum_units, bound, max_error) with the path's own bound
    (max of the two tolerances in effect) and worst true input-point error."""
    warm_up()
    pts = [p.points for p in drawing.paths]
    if quantum_units is None:
        qs = path_quanta(pts)
    else:
        qs = np.broadcast_to(np.asarray(quantum_units, dtype=np.float64).reshape(-1),
                             (len(pts),))
    t0 = time.perf_counter()
    fitted = fit_drawing(drawing, eps_line=eps_line, e_per=e_per, eps_sum=eps_sum,
                         quantum_units=qs)
    secs = time.perf_counter() - t0
    qmax = float(qs.max()) if len(qs) else 0.0
    slack = qmax * _HALF_DIAGONAL
    out: dict[str, object] = {
        "input_points": drawing.n_points,
        "thinned_points": sum(f.n_thinned for f in fitted),
        "control_points": sum(control_points(f) for f in fitted),
        "lines": sum(f.n_lines for f in fitted),
        "cubics": sum(f.n_cubics for f in fitted),
        "max_error": max((f.max_error for f in fitted), default=0.0),
        "seconds": secs,
        "quantum_units": qmax,
        "eps_line_in_effect": float(eps_line) + slack,
        "e_per_in_effect": float(e_per) + slack,
    }
    if per_path:
        out["paths"] = [
            {
                "index": f.source_index,
                "pen": f.pen,
                "closed": f.closed,
                "input_points": f.n_input,
                "segments": len(f.segments),
                "lines": f.n_lines,
                "cubics": f.n_cubics,
                "quantum_units": float(q),
                "bound": max(float(eps_line), float(e_per)) + float(q) * _HALF_DIAGONAL,
                "max_error": f.max_error,
            }
            for f, q in zip(fitted, qs.tolist(), strict=True)
        ]
    return out


def check_fit(
    points: object,
    fitted: FittedPath,
    e_per: float,
    eps_line: float,
    *,
    quantum_units: float | None = None,
    report: bool = False,
) -> tuple[float, float] | dict[str, float]:
    """Measure both sides of the fitting guarantee with true distances (input units).

    With ``report``: a dict with those two numbers ("max_in_to_curve",
    "max_curve_to_polyline"), "segments", "quantum_units" (given, or detected from the
    points when None) and "bound" (max(e_per, eps_line) + q/√2: the guarantee measured from
    the points themselves) and "violation" (1.0 when either side exceeds the bound, else 0.0).

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
        if report:
            return {"max_in_to_curve": 0.0, "max_curve_to_polyline": 0.0, "segments": 0.0,
                    "quantum_units": 0.0, "bound": max(float(e_per), float(eps_line)),
                    "violation": 0.0}
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
    if not report:
        return float(best.max()), out_max
    q = float(path_quanta([pts])[0]) if quantum_units is None else float(quantum_units)
    bound = max(float(e_per), float(eps_line)) + q * _HALF_DIAGONAL
    e_in = float(best.max())
    return {
        "max_in_to_curve": e_in,
        "max_curve_to_polyline": out_max,
        "segments": float(len(fitted.segments)),
        "quantum_units": q,
        "bound": bound,
        "violation": float(max(e_in, out_max) > bound * (1.0 + 1e-9)),
    }
