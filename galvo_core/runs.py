"""Curve runs in a thinned polyline and their split into pieces of < 90° turning.

Paper 000 §2.2, with the digest's corrections. Works on the *thinned* points ``q`` (M, 2),
consecutive points distinct (see :func:`galvo_core.thin.thin`). Indices below are into ``q``.

Rules
-----
* Vertex k (between segments k-1 = q[k-1]→q[k] and k = q[k]→q[k+1]) is *smooth* when
  cos β > ``cos_join`` (0.95) and neither segment is more than ``length_ratio`` (3) times as
  long as the other. The paper only excludes |P2P3| > 3|P1P2| (a long thinned line coming
  after a curve); we exclude it both ways, so that a long straight line running *into* a
  curve (rounded rectangle) is not swallowed by the curve either: long lines stay lines.
  Exception: the path's last segment may be shorter than that (the greedy thinning's
  leftover tail is not a line of its own).
* An inflection — the sign of the turn (cross product) differs from the previous turn in the
  run — ends the run at that point and starts the next one there (the point is shared).
* A run of at least 4 points is a curve run; shorter runs become plain line segments.
  Non-smooth vertices (real corners) always end a run, so corners stay corners.
* Each curve run is split into pieces whose end tangents differ by less than
  ``max_turn_deg`` (default 80°, a margin under the paper's 90° so that the end tangents
  meet in a point Q in front of both ends for every piece). The split is balanced (equal
  turning per piece) instead of greedy, so no short tail is left over.

Tangents
--------
:func:`point_tangents` gives two unit tangents per point, ``t_in`` (for a piece ending there)
and ``t_out`` (for a piece starting there). At a smooth vertex both are the Bessel
(three-point parabola) estimate from the neighbours on both sides, so the pieces on either
side of a split share the tangent (G1 joins). At a corner or at an open end they are one-sided
parabola estimates from the two neighbours on that side, never one segment alone. A closed
path whose seam vertex is smooth gets the two-sided estimate at the seam.

Many paths at once
------------------
:func:`split_pieces_many` does all of the above for many thinned paths concatenated into one
array (path boundaries respected: no vertex, run or piece crosses one), with a fixed number
of array operations whatever the number of paths. Its result is exactly (bit for bit) that of
:func:`split_pieces` per path; the single-path functions are the many-path ones applied to
one path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Piece",
    "smooth_vertices",
    "find_runs",
    "point_tangents",
    "split_pieces",
    "split_pieces_many",
    "segmented_cumsum",
]

#: np.unwrap's default period (numpy's pi is math.pi)
_PERIOD = 2.0 * math.pi
_SQRT2 = math.sqrt(2.0)
#: segments up to this length go into one padded table in :func:`segmented_cumsum`
_SHORT_SEGMENT = 64


@dataclass(frozen=True, slots=True)
class Piece:
    """A stretch of thinned points, ``a``..``b`` inclusive: ``kind`` "line" (b == a + 1) or
    "curve" (a candidate for one cubic, b >= a + 2)."""

    kind: str
    a: int
    b: int


@dataclass(frozen=True, slots=True)
class _Layout:
    """Where each point of a concatenation of paths sits: per point its index in its path
    (``pos``) and its path's length (``m``); per path its first point (``starts``) and
    length (``lens``)."""

    starts: np.ndarray
    lens: np.ndarray
    pos: np.ndarray
    m: np.ndarray

    @staticmethod
    def of(lens: object) -> _Layout:
        ln = np.asarray(lens, dtype=np.intp).reshape(-1)
        starts = np.cumsum(ln) - ln
        m = np.repeat(ln, ln)
        pos = np.arange(len(m)) - np.repeat(starts, ln)
        return _Layout(starts, ln, pos, m)

    @property
    def interior(self) -> np.ndarray:
        """Per point: neither the first nor the last point of its path."""
        return (self.pos > 0) & (self.pos < self.m - 1)


def segmented_cumsum(x: object, lens: object) -> np.ndarray:
    """``np.cumsum`` restarted at every segment of ``x`` (consecutive segments of lengths
    ``lens``, summing to ``len(x)``): bit for bit what ``np.cumsum`` gives on each segment
    alone (the same sequential additions; short segments are summed as rows of one padded
    table, long ones one at a time)."""
    v = np.asarray(x, dtype=np.float64).reshape(-1)
    ln = np.asarray(lens, dtype=np.intp).reshape(-1)
    out = np.empty_like(v)
    starts = np.cumsum(ln) - ln
    short = (ln > 0) & (ln <= _SHORT_SEGMENT)
    if short.any():
        sl = ln[short]
        rows = np.repeat(np.arange(len(sl)), sl)
        cols = np.arange(len(rows)) - np.repeat(np.cumsum(sl) - sl, sl)
        src = starts[short][rows] + cols
        tab = np.zeros((len(sl), int(sl.max())))
        tab[rows, cols] = v[src]
        np.cumsum(tab, axis=1, out=tab)
        out[src] = tab[rows, cols]
    long_ = ln > _SHORT_SEGMENT
    for s0, n in zip(starts[long_].tolist(), ln[long_].tolist(), strict=True):
        np.cumsum(v[s0 : s0 + n], out=out[s0 : s0 + n])
    return out


def _segments(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    s = np.diff(q, axis=0)
    return s, np.hypot(s[:, 0], s[:, 1])


def _vertex_rules(
    q: np.ndarray,
    lay: _Layout,
    cos_join: float,
    length_ratio: float,
    *,
    want_turn: bool = False,
    seg: tuple[np.ndarray, np.ndarray] | None = None,
    rounding: np.ndarray | None = None,
    steps: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per point of the concatenation: (smooth, turn angle or zeros, cross sign); only a
    path's interior points can be smooth or have a turn (the rules of the module doc).
    ``seg``: the segment vectors and lengths of ``q`` when already known. ``rounding``: per
    point (eps, quantum) rows of its path, for rounded input (see :func:`_rounded_rules`);
    ``steps``: per point the input steps of the segment starting there (None: unknown).
    """
    n = len(q)
    smooth = np.zeros(n, dtype=bool)
    turn = np.zeros(n)
    sign = np.zeros(n)
    if n < 3:
        return smooth, turn, sign
    s, ln = _segments(q) if seg is None else seg
    a, b = s[:-1], s[1:]
    la, lb = ln[:-1], ln[1:]
    dot = (a * b).sum(axis=1)
    cr = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    pos, m = lay.pos[1:-1], lay.m[1:-1]
    inner = (pos > 0) & (pos < m - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = dot / (la * lb)
        ratio_ok = (lb <= length_ratio * la) & (la <= length_ratio * lb)
        # the greedy thinning leaves a short last segment (the tail of the path): it is not
        # a long thinned line, so the length rule does not cut it off
        ratio_ok |= (pos == m - 2) & (lb < la)
        smooth[1:-1] = inner & (cos > cos_join) & ratio_ok
        if want_turn:
            turn[1:-1] = np.where(inner, np.arctan2(cr, dot), 0.0)
        # a turn below ~1e-12 rad is numerically straight: no sign
        sign[1:-1] = np.where(inner & (np.abs(cr) > 1e-12 * la * lb), np.sign(cr), 0.0)
        if rounding is not None:
            _rounded_rules(smooth, sign, rounding, inner, dot, cr, la, lb, length_ratio,
                           cos_join, s, steps)
    return smooth, turn, sign


#: a vertex of rounded input turning up to this many times what a thinned circle through
#: its segments turns is smooth (see :func:`_rounded_rules`)
_ROUNDED_TURN_MARGIN = 1.5
#: ... but never more than this (radians)
_ROUNDED_TURN_CAP = math.radians(50.0)


#: rounded input: a thinned segment up to this many quanta long between a curve run and a
#: corner is the run's end, not a line (see :func:`_rounded_rules`)
_SHORT_END = 16.0
_WIGGLE = True  # (the rounding-wiggle rule below; False: off, for measurements)
#: a short segment of at most this many quanta after a straight line is a rounding wiggle
#: too (the rule below without its curve-before and length-ratio conditions) ...
_JOG = 1.5
#: ... where that line runs diagonally: |sin 2a| of its angle a at least this (15-75 degrees
#: from the axes). A 45-degree staircase shifts its phase where the design's slope drifts;
#: kept as two corners, the joint stayed on the rounded point (sparse bench path 21: 0.67
#: from the design). An axis-parallel run's jog (a flat top) stays a corner: one cubic over
#: the flat run sagged to the far side of its points (path 507: 0.87)
_JOG_DIAG = 0.5


def _smooth_turn(total: np.ndarray, longest: np.ndarray, eps: np.ndarray) -> np.ndarray:
    """The turn (radians) a thinned smooth curve may make over segments of summed length
    ``total``, the longest ``longest``, thinned with ``eps``: ``_ROUNDED_TURN_MARGIN`` times
    total 4 eps / longest^2, at most ``_ROUNDED_TURN_CAP`` (:func:`_rounded_rules`)."""
    return np.minimum(_ROUNDED_TURN_MARGIN * total * 4.0 * eps / (longest * longest),
                      _ROUNDED_TURN_CAP)


def _diagonal(v: np.ndarray, least: float) -> np.ndarray:
    """Per vector: |sin 2a| of its angle a at least ``least`` (0.5: 15-75 degrees from the
    axes; 0: every vector)."""
    return 2.0 * np.abs(v[:, 0] * v[:, 1]) >= least * (v * v).sum(axis=1)


def _rounded_rules(smooth, sign, rounding, inner, dot, cr, la, lb, length_ratio,
                   cos_join, seg, steps=None) -> None:
    """The vertex rules on rounded input (quantum q > 0, thinned with tolerance eps), in
    place. Thinning a smooth curve of radius R with eps leaves chords of sagitta about eps,
    so each turns about l / R <= 8 eps / l: on a tight curve the chords turn more than
    cos_join allows although nothing is a corner. A vertex whose turn is at most
    ``_ROUNDED_TURN_MARGIN`` times (la + lb) 4 eps / max(la, lb)^2 (and at most
    ``_ROUNDED_TURN_CAP``) is smooth too, if its segments pass the length rule; a real
    corner turns more than that. A turn smaller than the rounding can make it (q / the
    longer segment) has no sign: rounding wiggles are not inflections. A segment of up to
    ``_SHORT_END`` quanta between a curve run (the vertex on its other side smooth) and a
    corner is what the thinning leaves of the curve's end before the corner: the vertex
    between it and the run is smooth when it turns as a smooth vertex may (the length
    rule aside), so that the run ends at the corner; where the corner's other side is a
    curve too, the segment is rather a wiggle of the rounding inside one curve (the
    thinning cut a curve's stretch into long, short, long): both of its ends are smooth
    where the two long segments around it meet as a smooth vertex may, and so are the ends
    of a unit jog (``_JOG``) after a diagonal line (``_JOG_DIAG``). Such vertices have
    no sign (their turn is the rounding's). Then the stretches of several short segments
    (:func:`_short_clusters`). ``cos_join``: the plain rule's threshold; ``seg``: the
    segment vectors of the points."""
    rnd = inner & (rounding[1:-1, 1] > 0.0)
    if not rnd.any():
        return
    _wiggle_rules(smooth, sign, rounding, rnd, dot, cr, la, lb, length_ratio, cos_join, seg)
    if _CLUSTERS:
        _short_clusters(smooth, sign, rounding, rnd, dot, cr, la, lb, length_ratio, cos_join,
                        seg, steps)


def _wiggle_rules(smooth, sign, rounding, rnd, dot, cr, la, lb, length_ratio, cos_join,
                  seg) -> None:
    """:func:`_rounded_rules` up to the stretches of several short segments (``rnd``: the
    interior vertices of rounded paths; the other arguments as there)."""
    eps = rounding[1:-1, 0]
    qq = rounding[1:-1, 1]
    ang = np.abs(np.arctan2(cr, dot))
    lmax = np.maximum(la, lb)
    with np.errstate(invalid="ignore", divide="ignore"):
        lim = _smooth_turn(la + lb, lmax, eps)
        ratio_ok = (lb <= length_ratio * la) & (la <= length_ratio * lb)
        add = rnd & ratio_ok & (ang <= lim)
        flat = rnd & (ang < qq / lmax)
    smooth[1:-1] |= add
    sign[1:-1][flat] = 0.0
    # the vertices beside a short segment that is not smooth yet (few: the rest of this on
    # those only; sm[k + 2] is smooth[k], False beyond the ends)
    short_b = rnd & (lb <= _SHORT_END * qq) & ~smooth[1:-1]
    short_a = rnd & (la <= _SHORT_END * qq) & ~smooth[1:-1]
    cand = np.flatnonzero(short_a | short_b)
    if len(cand) == 0:
        return
    sm = np.concatenate([[False, False], smooth, [False, False]])
    prev_s, next_s = sm[cand + 2], sm[cand + 4]
    prev2, next2 = sm[cand + 1], sm[cand + 5]
    ca, cb = la[cand], lb[cand]
    # a short segment between a run and a corner whose other side is not a curve: the
    # run's end (see above)
    with np.errstate(invalid="ignore", divide="ignore"):
        turn_ok = (dot[cand] > cos_join * ca * cb) | (ang[cand] <= lim[cand])
    end_b = short_b[cand] & (cb < ca) & prev_s & ~next_s & ~next2
    end_a = short_a[cand] & (ca < cb) & next_s & ~prev_s & ~prev2
    ext = cand[turn_ok & (end_a | end_b)]
    # a short segment between two corners inside a curve (a rounding wiggle: the vertices
    # beyond its ends smooth) whose neighbouring segments meet as a smooth vertex would:
    # both of its ends smooth (see above)
    # (a unit jog, _JOG quanta or shorter, also after a line that runs diagonally, 15-75
    # degrees from the axes: a staircase shifting phase at a straight run's end)
    jog = short_b[cand] & (cb <= _JOG * qq[cand]) & _diagonal(seg[cand], _JOG_DIAG)
    w = np.flatnonzero(short_b[cand] & ~next_s & (prev_s | jog) & next2 & (cb < ca))
    if _WIGGLE and len(w):
        k = cand[w]  # vertex index - 1; next2 true: segment k + 2 exists
        a_, c_ = seg[k], seg[k + 2]  # segments before the vertex and after the next one
        wa, wc = la[k], lb[k + 1]
        with np.errstate(invalid="ignore", divide="ignore"):
            dot2 = (a_ * c_).sum(axis=1)
            cr2 = a_[:, 0] * c_[:, 1] - a_[:, 1] * c_[:, 0]
            lim2 = _smooth_turn(wa + wc, np.maximum(wa, wc), eps[k])
            ok2 = (dot2 > cos_join * wa * wc) | (np.abs(np.arctan2(cr2, dot2)) <= lim2)
            ok2 &= ((wc <= length_ratio * wa) & (wa <= length_ratio * wc)
                    | jog[w]) & (lb[k] < wc)
        k = k[ok2]
        ext = np.concatenate([ext, k, k + 1])
    smooth[1:-1][ext] = True
    sign[1:-1][ext] = 0.0


#: rounded input: clusters of short thinned segments are looked at as a whole (see
#: :func:`_short_clusters`)
_CLUSTERS = True  # (False: off, for measurements)
#: ... and a cluster between two parallel segments is a jog of the staircase: its ends
#: smooth too (see :func:`_short_clusters`)
_CLUSTER_JOG = True
#: ... (|sin 2a| of one of the two segments' angle a at least this; 0: any direction) ...
_CLUSTER_DIAG = 0.5
#: ... where the cluster shifts the run across by at most this many quanta (a staircase
#: changing its phase shifts it by up to sqrt 2; a step of the design shifts it more: a
#: 2-unit step between two long diagonal lines taken for a jog came out 0.92 from the design)
_CLUSTER_SHIFT = 1.5
#: ... and not beside a design line written as its two rounded ends (one input step) where
#: the input steps are known (False: also there, for measurements)
_CLUSTER_STEPS = True
#: ... and no vertex of it turning more than a smooth curve's thinning and the rounding can
#: make it (False: any turn, for measurements)
_CLUSTER_TURNS = True
#: ... a cluster that is a unit jog (its short segments at most this many quanta together:
#: one diagonal step of the staircase) needs no length ratio between its two longer segments
#: (the thinning's: a long design line, then the first chord of the curve it runs into; URW
#: Z003 Medium Italic "f" at em 2048, a 100-unit line flowing into a flat curve, the jog's two
#: vertices kept as corners and moved 0.4 off their input points, 0.90 from the design where
#: the rounded input is 0.50)
_CLUSTER_UNIT = 1.5


def _short_clusters(smooth, sign, rounding, rnd, dot, cr, la, lb, length_ratio, cos_join,
                    seg, steps=None) -> None:
    """Rounded input: a cluster of consecutive short thinned segments (each up to
    ``_SHORT_END`` quanta, all its vertices inside a rounded path) between two longer
    ones is what the thinning leaves of a stretch where the rounding zigzags (the design
    passing a grid line, a tangent point on a half unit) or of a curve's end at a corner.
    Where the two longer segments meet as a smooth vertex would (the turn over the
    cluster's length of a thinned circle, :func:`_rounded_rules`; their lengths within
    ``length_ratio``, unless the cluster is a unit jog, ``_CLUSTER_UNIT``) and no vertex of
    the cluster turns more than a thinned smooth curve and the rounding of its own two
    segments can make it (``_CLUSTER_TURNS``: a corner whose turn the others undo), every
    vertex of the cluster is smooth; else the vertex that turns
    most is a corner and the vertices on either side of it are smooth where the turn they
    add up to is within what the rounding of the short segments on that side can make
    (q sqrt2 over their length) or a smooth vertex may turn. A cluster's end vertex is
    made smooth only where the vertex beyond it is smooth already (a long line running
    into the cluster stays a line). A cluster is a jog of the rounding where its two longer
    segments are parallel up to the rounding (q sqrt2 over each length), whatever their
    lengths, it shifts the run across by at most ``_CLUSTER_SHIFT`` quanta, and neither
    longer segment is one input step (``steps``): then its vertices are smooth and so is
    each end whose longer segment runs diagonally (``_CLUSTER_DIAG``; a staircase changing
    its phase, P052 Bold Italic "Q" at em 2048: kept as two corners, the cubic before them
    bent into the jog, 0.83 from the design; axis-parallel, URW C059 "M" at em 2048: the
    stems' flat runs taken into cubics sagged). The vertices of a zigzag, and those made
    smooth beside a corner, have no sign (their turns are the rounding's; a vertex beside a
    corner that was smooth already keeps its sign). In place; the arrays as in
    :func:`_rounded_rules`."""
    n = len(smooth)
    ln = np.hypot(seg[:, 0], seg[:, 1])  # segment s: point s -> s + 1
    qp = rounding[:, 1]
    ep = rounding[:, 0]
    iv = np.zeros(n, dtype=bool)  # interior vertices of rounded paths
    iv[1:-1] = rnd
    short = (ln <= _SHORT_END * qp[:-1]) & iv[:-1] & iv[1:]
    if not short.any():
        return
    # maximal stretches of short segments i..j; the segments i - 1 and j + 1 exist (the
    # ends i and j + 1 are interior vertices) and must be longer
    edge = np.diff(np.r_[0, short.astype(np.int8), 0])
    i = np.flatnonzero(edge == 1)
    j = np.flatnonzero(edge == -1) - 1
    ok = (ln[i - 1] > _SHORT_END * qp[i - 1]) & (ln[j + 1] > _SHORT_END * qp[j + 1])
    i, j = i[ok], j[ok]
    if len(i) == 0:
        return
    # per vertex v (point index) its signed turn; per cluster its vertices i .. j + 1
    turn = np.zeros(n)
    turn[1:-1] = np.arctan2(cr, dot)
    cnt = j - i + 2
    own = np.repeat(np.arange(len(i)), cnt)
    v = np.repeat(i, cnt) + (np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt))
    a_, c_ = seg[i - 1], seg[j + 1]
    wa, wc = ln[i - 1], ln[j + 1]
    gap = np.add.reduceat(ln[v], np.cumsum(cnt) - cnt) - ln[j + 1]  # the short segments
    dot2 = (a_ * c_).sum(axis=1)
    net = np.arctan2(a_[:, 0] * c_[:, 1] - a_[:, 1] * c_[:, 0], dot2)
    with np.errstate(invalid="ignore", divide="ignore"):
        lim = _smooth_turn(wa + wc + 2.0 * gap, np.maximum(wa, wc), ep[i])
        wig = ((dot2 > cos_join * wa * wc) | (np.abs(net) <= lim))
        # (the two longer segments' lengths within length_ratio, or a unit jog between them,
        # _CLUSTER_UNIT)
        wig &= (wc <= length_ratio * wa) & (wa <= length_ratio * wc) | (
            gap <= _CLUSTER_UNIT * qp[i])
        # a jog of the rounding: the two longer segments parallel up to the rounding (one of
        # them diagonal where _CLUSTER_DIAG asks it), whatever their lengths (_CLUSTER_JOG)
        da = _diagonal(a_, _CLUSTER_DIAG)
        dc = _diagonal(c_, _CLUSTER_DIAG)
        # ... and the cluster shifts the run across by at most _CLUSTER_SHIFT quanta (a
        # staircase's phase, not a step of the design)
        # (point i to point j + 1: the cluster's own segments summed, each path alone)
        inner_v = v[v <= np.repeat(j, cnt)]
        across = np.add.reduceat(seg[inner_v], np.cumsum(cnt - 1) - (cnt - 1), axis=0)
        shift = np.abs(a_[:, 0] * across[:, 1] - a_[:, 1] * across[:, 0]) / wa
        jog = (np.abs(net) <= _SQRT2 * qp[i] * (1.0 / wa + 1.0 / wc)) & (da | dc) & (
            shift <= _CLUSTER_SHIFT * qp[i]) if _CLUSTER_JOG else np.zeros(len(i), dtype=bool)
        if steps is not None and _CLUSTER_STEPS:
            # ... not beside a design line written as its two rounded ends (one input step):
            # the cluster after it is a curve's start (serif-bolditalic "Q" at em 400: a
            # 30-unit line taken into the cubic after it, 0.68 from the design)
            jog &= (steps[i - 1] > 1) & (steps[j + 1] > 1)
        wig |= jog
        if _CLUSTER_TURNS:
            # ... but not where one of its vertices turns more than a thinned smooth curve
            # and the rounding of its two segments together can make it turn: a corner
            # whose turn the cluster's other vertices undo (FreeMono Bold "c" at em 1000: a
            # 95-degree cusp between segments of 12 and 26 units after four turning 12-19
            # degrees the other way, made smooth, 0.68 from the design on its input point)
            la_v, lb_v = ln[v - 1], ln[v]
            allow = (_smooth_turn(la_v + lb_v, np.maximum(la_v, lb_v), ep[v])
                     + _SQRT2 * qp[v] * (1.0 / la_v + 1.0 / lb_v))
            sharp = np.zeros(len(i), dtype=bool)
            sharp[own[np.abs(turn[v]) > allow]] = True
            wig &= ~sharp
    make = np.zeros(n, dtype=bool)
    make[v[wig[own]]] = True
    # a zigzag's vertices have no sign where they turn as the rounding can make them
    zig = make.copy()
    zig[1:-1] &= np.abs(turn[1:-1]) <= _SQRT2 * qp[1:-1] * (1.0 / la + 1.0 / lb)
    # a corner in the cluster: the vertex turning most; the turns on each side of it
    ca = np.flatnonzero(~wig)
    if len(ca):
        sel = ~wig[own]
        vv, oo = v[sel], own[sel]
        at = np.abs(turn[vv])
        top = np.zeros(len(i))
        np.maximum.at(top, oo, at)
        # the first vertex turning most
        is_top = at == top[oo]
        first_top = np.full(len(i), n, dtype=np.intp)
        np.minimum.at(first_top, oo[is_top], vv[is_top])
        corner = first_top[oo]
        before = vv < corner
        after = vv > corner
        tb = np.zeros(len(i))
        ta = np.zeros(len(i))
        lb_ = np.zeros(len(i))
        la_ = np.zeros(len(i))
        np.add.at(tb, oo[before], turn[vv[before]])
        np.add.at(ta, oo[after], turn[vv[after]])
        # the short segments on each side: those starting before the corner / after it
        np.add.at(lb_, oo[before], ln[vv[before]])
        np.add.at(la_, oo[after], ln[vv[after] - 1])
        with np.errstate(invalid="ignore", divide="ignore"):
            tol_b = np.maximum(_SQRT2 * qp[i] / lb_, lim)
            tol_a = np.maximum(_SQRT2 * qp[i] / la_, lim)
        side_ok = np.where(before, (np.abs(tb) <= tol_b)[oo], False)
        side_ok |= np.where(after, (np.abs(ta) <= tol_a)[oo], False)
        make[vv[side_ok]] = True
    # the cluster's ends only where the vertex beyond them is smooth
    end_i = np.zeros(n, dtype=bool)
    end_i[i] = True
    end_j = np.zeros(n, dtype=bool)
    end_j[j + 1] = True
    beyond_prev = np.r_[False, smooth[:-1]]
    beyond_next = np.r_[smooth[1:], False]
    # ... or where the cluster is a jog (and the segment beyond that end diagonal where
    # _CLUSTER_DIAG asks it)
    beyond_prev[i[jog & da]] = True
    beyond_next[j[jog & dc] + 1] = True
    make &= (~end_i | beyond_prev) & (~end_j | beyond_next)
    unsigned = make & (zig | ~smooth)
    smooth |= make
    sign[unsigned] = 0.0


def _runs(smooth: np.ndarray, sign: np.ndarray, lay: _Layout) -> tuple[np.ndarray, np.ndarray]:
    """Curve runs of all paths: inclusive point ranges (ra, rb), rb - ra >= 3, in order.

    A run ends at every interior vertex that is not smooth (a corner) and at every smooth
    vertex whose turn has the opposite sign of the previous signed smooth vertex with no
    corner in between (an inflection); path ends end runs too.
    """
    if len(smooth) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    wall = ~smooth  # corners and path ends
    stretch = np.cumsum(wall)
    ends = wall.copy()
    signed = np.flatnonzero(smooth & (sign != 0.0))
    if len(signed) > 1:
        p, c = signed[:-1], signed[1:]
        flip = (stretch[p] == stretch[c]) & (sign[p] == -sign[c])
        ends[c[flip]] = True
    e = np.flatnonzero(ends)
    s0, s1 = e[:-1], e[1:]
    keep = (lay.pos[s0] != lay.m[s0] - 1) & (s1 - s0 >= 3)
    return s0[keep], s1[keep]


def _bessel(q0: np.ndarray, q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Unit tangent at q1 of the parabola through three points (chord-length weights)."""
    d0 = q1 - q0
    d1 = q2 - q1
    return _bessel_of(d0, np.hypot(d0[..., 0], d0[..., 1]), d1, np.hypot(d1[..., 0], d1[..., 1]))


def _bessel_of(d0: np.ndarray, h0: np.ndarray, d1: np.ndarray, h1: np.ndarray) -> np.ndarray:
    """:func:`_bessel` from the two segment vectors around the point and their lengths."""
    h0 = h0[..., None]
    h1 = h1[..., None]
    t = (h1 / (h0 + h1)) * d0 / h0 + (h0 / (h0 + h1)) * d1 / h1
    return t / np.hypot(t[..., 0], t[..., 1])[..., None]


def _tangents(
    q: np.ndarray,
    lay: _Layout,
    smooth: np.ndarray,
    closed: np.ndarray,
    cos_join: float,
    length_ratio: float,
    seg: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(t_in, t_out) of every point of the concatenation (see :func:`point_tangents`).

    ``seg``: the segment vectors and lengths of ``q`` when already known.
    """
    n = len(q)
    t_in = np.zeros((n, 2))
    t_out = np.zeros((n, 2))
    if n < 2:
        return t_in, t_out
    s, ln = _segments(q) if seg is None else seg
    nonempty = lay.lens > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        u = s / ln[:, None]
        # one segment's direction, none across two paths
        t_out[:-1] = u
        t_out[(lay.starts + lay.lens - 1)[nonempty]] = 0.0
        t_in[1:] = u
        t_in[lay.starts[nonempty]] = 0.0
        mid = np.flatnonzero(lay.interior)
        if len(mid) == 0:
            return t_in, t_out
        central = np.zeros((n, 2))
        central[mid] = _bessel_of(s[mid - 1], ln[mid - 1], s[mid], ln[mid])
        # one-sided parabola estimates where no two-sided one replaces them: direction at
        # angle 2·angle(segment) − angle(central tangent of the neighbour)
        au = np.arctan2(u[:, 1], u[:, 0])
        ac = np.zeros(n)
        ac[mid] = np.arctan2(central[mid, 1], central[mid, 0])
        f = np.flatnonzero((lay.pos <= lay.m - 3) & ~smooth)  # start at k: q[k], q[k+1], q[k+2]
        ang = 2.0 * au[f] - ac[f + 1]
        t_out[f, 0] = np.cos(ang)
        t_out[f, 1] = np.sin(ang)
        g = np.flatnonzero((lay.pos >= 2) & ~smooth)  # end at k: q[k-2], q[k-1], q[k]
        ang = 2.0 * au[g - 1] - ac[g - 1]
        t_in[g, 0] = np.cos(ang)
        t_in[g, 1] = np.sin(ang)
        sm = np.flatnonzero(smooth)
        t_out[sm] = central[sm]
        t_in[sm] = central[sm]
        _seam_tangents(q, s, ln, lay, closed, cos_join, length_ratio, t_in, t_out)
    return t_in, t_out


def _seam_tangents(q, s, ln, lay, closed, cos_join, length_ratio, t_in, t_out) -> None:
    """A closed path (first point == last point, >= 4 points) whose seam vertex is smooth
    gets the two-sided estimate at both ends (in place)."""
    cand = np.flatnonzero(np.asarray(closed, dtype=bool) & (lay.lens >= 4))
    if len(cand) == 0:
        return
    s0 = lay.starts[cand]
    e0 = s0 + lay.lens[cand] - 1
    same = (q[s0] == q[e0]).all(axis=1)
    s0, e0 = s0[same], e0[same]
    a, b = s[e0 - 1], s[s0]
    la, lb = ln[e0 - 1], ln[s0]
    cos = (a * b).sum(axis=1) / (la * lb)
    # the single-path rule computed a @ b (BLAS dot, may round differently in the last
    # bit): decide values within rounding of the threshold exactly as it did
    for i in np.flatnonzero(~(np.abs(cos - cos_join) > 1e-9)).tolist():
        cos[i] = float(a[i] @ b[i]) / (la[i] * lb[i])
    ok = (cos > cos_join) & (lb <= length_ratio * la) & (la <= length_ratio * lb)
    s0, e0 = s0[ok], e0[ok]
    if len(s0):
        c = _bessel(q[e0 - 1], q[s0], q[s0 + 1])
        t_out[s0] = c
        t_in[e0] = c


def _unwrap_each(p: np.ndarray, first: np.ndarray, cnt: np.ndarray) -> np.ndarray:
    """``np.unwrap`` (period 2π) of every run ``p[first[r] : first[r] + cnt[r]]`` (runs
    consecutive, each >= 2 long), bit for bit as on each run alone."""
    up = p.copy()
    if len(p) < 2:
        return up
    dd = np.diff(p)
    inner = np.ones(len(dd), dtype=bool)
    inner[first[1:] - 1] = False  # differences across two runs
    j = np.flatnonzero(inner)
    d = dd[j]
    high = _PERIOD / 2
    low = -high
    ddmod = np.mod(d - low, _PERIOD) + low
    np.copyto(ddmod, high, where=(ddmod == low) & (d > 0))
    ph = ddmod - d
    np.copyto(ph, 0, where=abs(d) < high)
    up[j + 1] = p[j + 1] + segmented_cumsum(ph, cnt - 1)
    return up


def _split_runs(
    ra: np.ndarray, rb: np.ndarray, t_in: np.ndarray, t_out: np.ndarray, limit: float
) -> tuple[np.ndarray, np.ndarray]:
    """Every run cut into pieces of total turning < ``limit`` (radians): (pa, pb) in order.

    Turning is measured on the unwrapped tangent angle (out-tangent at the run's start, the
    in-tangents after it); a run turning more is cut into n balanced pieces.
    """
    if len(ra) == 0:
        return ra, rb
    cnt = rb - ra + 1
    first = np.cumsum(cnt) - cnt
    own = np.repeat(np.arange(len(ra)), cnt)
    off = np.arange(int(cnt.sum())) - first[own]
    gi = ra[own] + off
    tang = np.where((off == 0)[:, None], t_out[gi], t_in[gi])
    ang = _unwrap_each(np.arctan2(tang[:, 1], tang[:, 0]), first, cnt)
    total = np.abs(ang[first + cnt - 1] - ang[first])
    with np.errstate(invalid="ignore"):
        many = np.flatnonzero(np.ceil(total / limit * (1.0 + 1e-9)) > 1.0)
    if len(many) == 0:
        return ra, rb
    pa: list[np.ndarray] = [ra]
    pb: list[np.ndarray] = [rb]
    drop = np.zeros(len(ra), dtype=bool)
    drop[many] = True
    for r in many.tolist():
        a, b = int(ra[r]), int(rb[r])
        cuts = _balanced_cuts(a, b, ang[first[r] : first[r] + cnt[r]], total[r], limit)
        pa.append(np.asarray(cuts[:-1], dtype=np.intp))
        pb.append(np.asarray(cuts[1:], dtype=np.intp))
    pa[0], pb[0] = ra[~drop], rb[~drop]
    a_all = np.concatenate(pa)
    order = np.argsort(a_all, kind="stable")
    return a_all[order], np.concatenate(pb)[order]


def _balanced_cuts(a: int, b: int, ang: np.ndarray, total: float, limit: float) -> list[int]:
    """Cut points a < c1 < ... < b of one run: n = ceil(total / limit) pieces of about equal
    turning, each stepped back until it turns less than ``limit`` (when it can)."""
    n = max(1, math.ceil(total / limit * (1.0 + 1e-9)))
    cuts = [a]
    rel = np.abs(ang - ang[0])
    for i in range(1, n):
        k = a + int(np.searchsorted(rel, total * i / n))
        k = min(max(k, cuts[-1] + 1), b - 1)
        # keep the piece under the limit: step back while it turns too much
        while k - 1 > cuts[-1] and abs(ang[k - a] - ang[cuts[-1] - a]) >= limit:
            k -= 1
        if cuts[-1] < k < b:
            cuts.append(k)
    cuts.append(b)
    return cuts


def split_pieces_many(
    q: object,
    lens: object,
    closed: object,
    *,
    max_turn_deg: float = 80.0,
    cos_join: float = 0.95,
    length_ratio: float = 3.0,
    rounding: object = None,
    return_smooth: bool = False,
    steps: object = None,
) -> tuple[np.ndarray, ...]:
    """:func:`split_pieces` of many thinned paths at once.

    ``q`` (N, 2) is the concatenation of the paths, ``lens`` their point counts (sum N),
    ``closed`` one flag per path. With ``return_smooth`` the per-point smooth flags come
    sixth. ``rounding``: optional (eps, quantum) per path, the thinning tolerance and the
    grid of rounded input (:func:`_rounded_rules`; rows with quantum 0 follow the plain
    rules). ``steps``: optional, per point of ``q`` the input steps of the thinned segment
    starting there (the rounded rules leave a segment of one step, a design line written as
    its two rounded ends, out of the jogs). Returns ``(a, b, curve, t_in, t_out)``: the
    pieces of every path in path order, as inclusive ranges ``a[i]..b[i]`` of indices into
    ``q`` (never crossing a path), ``curve[i]`` True for a "curve" piece, False for a line,
    and the (N, 2) tangents. Exactly (bit for bit) what each path gives alone, offset by
    its first index: without ``rounding`` the pieces and tangents of :func:`split_pieces`;
    with it, this function's on that path with its row of ``rounding`` and its slice of
    ``steps`` (a path's last entry of ``steps`` is never read).
    """
    qq = np.asarray(q, dtype=np.float64).reshape(-1, 2)
    lay = _Layout.of(lens)
    if lay.m.size != len(qq):
        raise ValueError("split_pieces_many: lens must sum to len(q)")
    cl = np.asarray(closed, dtype=bool).reshape(-1)
    if len(cl) != len(lay.lens):
        raise ValueError("split_pieces_many: one closed flag per path")
    seg = _segments(qq) if len(qq) >= 2 else None
    rnd = None
    if rounding is not None:
        rr = np.asarray(rounding, dtype=np.float64).reshape(-1, 2)
        if len(rr) != len(lay.lens):
            raise ValueError("split_pieces_many: one (eps, quantum) row per path")
        if (rr[:, 1] > 0.0).any():
            rnd = np.repeat(rr, lay.lens, axis=0)
    st = None if steps is None or rnd is None else np.asarray(steps).reshape(-1)
    if st is not None and len(st) != len(qq):
        raise ValueError("split_pieces_many: steps must have one entry per point")
    smooth, _, sign = _vertex_rules(qq, lay, cos_join, length_ratio, seg=seg, rounding=rnd,
                                    steps=st)
    t_in, t_out = _tangents(qq, lay, smooth, cl, cos_join, length_ratio, seg=seg)
    ra, rb = _runs(smooth, sign, lay)
    ca, cb = _split_runs(ra, rb, t_in, t_out, math.radians(max_turn_deg))
    # every segment outside the runs is a line; so is a run's piece of one segment
    cover = np.zeros(len(qq) + 1, dtype=np.intp)
    np.add.at(cover, ra, 1)
    np.add.at(cover, rb, -1)
    covered = np.cumsum(cover[:-1])[:-1] > 0 if len(qq) else np.zeros(0, dtype=bool)
    inside = lay.pos[:-1] < lay.m[:-1] - 1
    la = np.flatnonzero(inside & ~covered)
    a = np.concatenate([la, ca])
    b = np.concatenate([la + 1, cb])
    order = np.argsort(a, kind="stable")
    a, b = a[order], b[order]
    if return_smooth:
        return a, b, b - a >= 2, t_in, t_out, smooth
    return a, b, b - a >= 2, t_in, t_out


def smooth_vertices(
    q: np.ndarray, *, cos_join: float = 0.95, length_ratio: float = 3.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per point k: (smooth (M,) bool, turn angle (M,) radians signed, cross sign (M,)).

    End points (k = 0, M-1) are not smooth here (see :func:`point_tangents` for the seam).
    """
    qq = np.asarray(q, dtype=np.float64).reshape(-1, 2)
    return _vertex_rules(qq, _Layout.of([len(qq)]), cos_join, length_ratio, want_turn=True)


def find_runs(
    q: np.ndarray, *, cos_join: float = 0.95, length_ratio: float = 3.0
) -> list[tuple[int, int]]:
    """Curve runs as inclusive point ranges (a, b) with b - a >= 3 (at least 4 points)."""
    qq = np.asarray(q, dtype=np.float64).reshape(-1, 2)
    lay = _Layout.of([len(qq)])
    smooth, _, sign = _vertex_rules(qq, lay, cos_join, length_ratio)
    ra, rb = _runs(smooth, sign, lay)
    return list(zip(ra.tolist(), rb.tolist(), strict=True))


def point_tangents(
    q: np.ndarray, *, closed: bool = False, cos_join: float = 0.95, length_ratio: float = 3.0
) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangents ``(t_in, t_out)``, each (M, 2), following the path direction."""
    qq = np.asarray(q, dtype=np.float64).reshape(-1, 2)
    lay = _Layout.of([len(qq)])
    smooth, _, _ = _vertex_rules(qq, lay, cos_join, length_ratio)
    return _tangents(qq, lay, smooth, np.array([closed]), cos_join, length_ratio)


def split_pieces(
    q: np.ndarray,
    *,
    closed: bool = False,
    max_turn_deg: float = 80.0,
    cos_join: float = 0.95,
    length_ratio: float = 3.0,
) -> tuple[list[Piece], np.ndarray, np.ndarray]:
    """The thinned path as ordered pieces covering every segment once.

    Returns ``(pieces, t_in, t_out)``: consecutive pieces share their end point
    (``pieces[i].b == pieces[i+1].a``); "curve" pieces have end tangents (``t_out[a]``,
    ``t_in[b]``) that differ by less than ``max_turn_deg`` unless a single segment of the
    thinned path already turns more (then it is still marked "curve" and the fitter falls
    back to lines).
    """
    qq = np.asarray(q, dtype=np.float64).reshape(-1, 2)
    a, b, curve, t_in, t_out = split_pieces_many(
        qq,
        [len(qq)],
        [closed],
        max_turn_deg=max_turn_deg,
        cos_join=cos_join,
        length_ratio=length_ratio,
    )
    pieces = [
        Piece("curve" if c else "line", i, j)
        for i, j, c in zip(a.tolist(), b.tolist(), curve.tolist(), strict=True)
    ]
    return pieces, t_in, t_out
