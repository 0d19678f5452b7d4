"""Marking points: from fitted lines and cubics to integer galvo bits (paper 000 §4, 004, 001).

Three methods (``Params.interpolation``):

``adaptive`` (default)
    Every cubic is cut into chords whose *chord height* — the largest distance between the
    chord and the curve stretch it replaces — stays within ``chord_tol_bits``, each chord as
    long as the bound allows (paper 004's step search, see :func:`sample_curve`). Cubics
    that meet smoothly (no corner at the joint) are searched as one curve, so a chord may
    run across their joint — no mark is forced there and no short chord is left at the end
    of every cubic (runs are cut every :data:`_CHAIN_MARKS` marks or so, see
    :func:`_smooth_chains`). Lines are sent as their end points. The chord height is
    measured for real, not at the parameter midpoint as paper 000 eq. (5) does: for a 2-D
    cubic the distance of the curve to the chord's line is a cubic polynomial of the
    parameter, so its extremes come in closed form
    (:func:`chord_heights`).
``fixed``
    Paper 001's legacy method, kept to show the improvement: walk the curve in fixed steps
    of ``fixed_step_bits`` and end a chord when the slope of A→P_i differs from that of the
    first chord A→P_1 by more than ``fixed_slope_tol`` (k0). Adapted so that it works where
    the curve goes vertical (the paper steps in x and compares dy/dx, which breaks there):
    the step is taken along the axis the curve currently advances on most (the Chebyshev
    arc length max(|dx|, |dy|) grows by the step — exactly the paper's x step wherever
    |dy/dx| <= 1), and the slope difference is measured in the frame of the first chord,
    tan(angle(A→P_i) − angle(A→P_1)), which equals the paper's k_i − k_1 for a horizontal
    first chord and stays finite everywhere.
``raw``
    The original input points, mapped to bits (what a controller fed the PLT would mark).

The step search (:func:`sample_curve`, shared by the 2-D path and by curves in 3-D)
-----------------------------------------------------------------------------------------
Paper 004: at the current point take the curvature k (r = 1/k), the target chord height
H_p = (E_min + E_max)/2, the curvature-circle angle θ = 2·arccos((r − H_p)/r) and the first
step R = 2r·sin(θ/2); measure the true chord height H of that step (dL/dt = 0, eq. 8) and
accept it when E_min <= H <= E_max, else double or halve R. Two changes, same guarantee:

* The step is searched in the curve parameter rather than in the sphere radius R: both are
  monotone along a short arc, and the parameter needs no sphere-curve intersection solve.
  The first trial is the paper's R turned into a parameter step (R / |P'|).
* Doubling/halving can jump over the window (H grows like R², so doubling R multiplies H by
  about 4, more than E_max/E_min): the search keeps a bracket (longest step known to hold,
  shortest known to fail) and rescales with the measured growth law,
  Δt ← Δt·(H_p/H)^(1/p), p = 2 at first and then the local exponent of the last two trials,
  bisecting whenever that leaves the bracket. It needs about 1.5 measurements per mark.

E_max = ``chord_tol_bits``; E_min = :data:`E_MIN_RATIO` · E_max (0.97), so every chord is
within about 1.5 % of the longest allowed one (the count grows like 1/sqrt(H)): within a
few per cent of the fewest possible and of the integral bound (see bench/RESULTS.md), for
about 1.3 height measurements per mark. A step that reaches the curve's end with H <= E_max ends it.

Minimum and maximum step
------------------------
No chord is shorter than ``min_step_bits`` except the last one of a stroke and those ending
at a corner (a segment joint whose direction turns by more than :data:`CORNER_DEG`): where
the tolerance would want a shorter step (radius of curvature about a bit) the step is set to
the minimum instead and counted as a *min-step override* (its chord height is measured and
reported like any other). A curve's last chord shorter than the minimum is avoided by moving
the previous mark to the middle of the last two chords; a mark still closer than the minimum
to its predecessor (tiny segments, joints with lines) is dropped unless it is a protected
mark (stroke ends, corners) — or, when the longer chord that dropping it leaves would break
the tolerance, its unprotected predecessor is dropped instead; when neither can go the
minimum step wins and the mark is counted as a min-step override. ``max_step_bits``
(optional) caps every chord and splits lines.

Rounding
--------
The chord heights above are for the marks before rounding (``max_chord_height_bits``,
guaranteed <= ``chord_tol_bits`` except at min-step overrides and where two protected marks
within a bit of each other round to the same integer mark, so that one of them goes and the
chord from its neighbour passes it: both are measured and reported). Rounding each mark to the
nearest integer bit moves it by at most √2/2 bit, so every point of a rounded chord lies
within √2/2 of the unrounded chord (a convex combination of two such moves): the chord
height of the integer marks is at most the unrounded one + √2/2 ≈ 0.707 bit. It is measured
too (``max_chord_height_int_bits``) and reported separately.

Measuring every chord costs about as much as the search, so it shares the search's work: a
chord that is exactly a chord the search measured (same segment, same parameters) reports
that measurement (the same closed form on the same numbers), a chord on a line segment has
height 0, and only the others (moved by the minimum step or the short-end fix, spanning a
joint, merged by rounding) are measured again. For the integer chords the bound
unrounded height + the larger rounding move of its two ends is refined by exact
measurement of the chords of largest bound until no bound exceeds the largest exact value:
the reported maximum is exact.

Units: galvo bits (float before rounding); curve parameters in [0, 1].
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
from numba import njit

from galvo_core.errors import Cancelled, ParamError
from galvo_core.field import FieldMap
from galvo_core.fit import FittedPath
from galvo_core.geometry import power_coeffs_into
from galvo_core.turns import CORNER_DEG, turn_deg

__all__ = [
    "E_MIN_RATIO",
    "ROUNDING_BOUND_BITS",
    "CurveSample",
    "SampleReport",
    "SampleResult",
    "chord_heights",
    "segment_heights",
    "sample_curve",
    "sample_paths",
    "sample_path",
]

#: E_min / E_max of the step search window
E_MIN_RATIO = 0.97
#: the most that rounding a mark to whole bits adds to a chord height
ROUNDING_BOUND_BITS = math.sqrt(2.0) / 2.0
#: trials of one chord's step before the search takes the longest chord found to pass
_MAX_TRIALS = 60
#: a chord this close to ``max_step`` (as a share of it) is long enough to be accepted even
#: below E_min: asking for more would only shave the last few percent of the step
_MAX_STEP_ACCEPT = 0.98
#: when the step would break ``max_step``, the next trial aims this far below it
_MAX_STEP_AIM = 0.99
#: the bracket [lo, hi] of a chord's step is collapsed when narrower than this share of hi
_BRACKET_REL = 1e-9
#: the height grows as step**p between two trials; p is kept in this range (2: a smooth
#: curve's chord height, 1: a corner's, up to 4 near an inflection) and is 2 until measured
_GROWTH_MIN, _GROWTH_MAX, _GROWTH_DEFAULT = 1.0, 4.0, 2.0
#: a chord stretched to the minimum step: corrections of its length (the length is not
#: linear in the parameter) and the largest stretch per correction
_MIN_STEP_FIXES, _MIN_STEP_GROWTH = 3, 4.0
#: the search looks at ``cancel`` every this many rounds
_CANCEL_EVERY = 64
_OVER_SAMPLES = 64
#: the sampler works on whole paths in chunks of about this many segments (bounded temporaries)
CHUNK_SEGMENTS = 1 << 18
#: the field-mapped geometry (96 bytes a segment) is kept for a re-sample up to this size;
#: a larger one is made again when asked (about 0.3 s CPU per million segments): not held
#: through the rest of a job of millions of points
FIELDED_KEEP_BYTES = 128 << 20
#: about how many marks a chain of smoothly joined cubics gathers before it is cut
_CHAIN_MARKS = 64
_TINY = 1e-300


# =========================================================================== measurement
def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return (u * v).sum(axis=1)


def _quad_roots(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Real roots of a τ² + b τ + c, stable form, clipped to [0, 1] (0 where none)."""
    disc = b * b - 4.0 * a * c
    real = disc >= 0.0
    sq = np.sqrt(np.where(real, disc, 0.0))
    q = -0.5 * (b + np.where(b >= 0.0, sq, -sq))
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = q / a
        r2 = c / q
    r1 = np.where(real & np.isfinite(r1), np.clip(r1, 0.0, 1.0), 0.0)
    r2 = np.where(real & np.isfinite(r2), np.clip(r2, 0.0, 1.0), 0.0)
    return r1, r2


CF = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
           np.ndarray, np.ndarray]


def _cf(coef: np.ndarray) -> CF:
    """(K, 4, 2) power coefficients -> eight contiguous (K,) arrays ax, ay, bx, by, dx, dy,
    ex, ey (element-wise work on strided views is several times slower)."""
    c = np.asarray(coef, dtype=np.float64)
    return tuple(np.ascontiguousarray(c[:, i, j]) for i in range(4) for j in range(2))  # type: ignore[return-value]


def _taylor(cf: CF, ta: np.ndarray, tb: np.ndarray) -> tuple[np.ndarray, ...]:
    """x and y of B(ta), q1, q2, q3 with B(ta + hτ) = B(ta) + q1 τ + q2 τ² + q3 τ³."""
    t = ta
    h = tb - ta
    h2 = h * h
    h3 = h2 * h
    out = []
    for a, b, d, e in ((cf[0], cf[2], cf[4], cf[6]), (cf[1], cf[3], cf[5], cf[7])):
        a3t = 3.0 * a * t
        out.append((((a * t + b) * t + d) * t + e, ((a3t + 2.0 * b) * t + d) * h,
                    (a3t + b) * h2, a * h3))
    (b0x, q1x, q2x, q3x), (b0y, q1y, q2y, q3y) = out
    return b0x, b0y, q1x, q1y, q2x, q2y, q3x, q3y


def chord_heights(coef: np.ndarray | CF, ta: np.ndarray, tb: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """True chord heights of 2-D cubic stretches, in closed form.

    ``coef`` (K, 4, 2): power coefficients [a, b, d, e] of the cubic of each chord
    (B(t) = a t³ + b t² + d t + e; a line is a = b = 0); ``ta``, ``tb`` (K,) the chord's
    parameters (``coef`` may also be the eight (K,) arrays ax, ay, bx, by, dx, dy, ex, ey).
    Returns ``(H, L)``: H the largest distance of B([ta, tb]) to the chord
    B(ta)B(tb), L the chord length (units of ``coef``).

    With t = ta + hτ, D(τ) = B(t) − B(ta) = q1 τ + q2 τ² + q3 τ³ and the chord c = D(1), the
    signed distance to the chord's line is s(τ) = τ(τ − 1)(c3 τ + c2 + c3) / |c| with
    c_i = q_i × c; its extremes are the roots of a quadratic. When the curve stays over the
    chord (its projection on the chord within [0, |c|]) H is exact: the distance to the
    segment then equals the distance to the line, and the chord is within H of the curve
    too (the projection passes every point of the chord). When it overshoots an end by o,
    H = sqrt(H_line² + o²), an upper bound. A chord of zero length gets the bound
    |q1| + |q2| + |q3|.
    """
    cf = coef if isinstance(coef, tuple) else _cf(coef)
    _, _, q1x, q1y, q2x, q2y, q3x, q3y = _taylor(cf, ta, tb)
    cx = q1x + q2x + q3x
    cy = q1y + q2y + q3y
    L = np.hypot(cx, cy)
    c2 = q2x * cy - q2y * cx
    c3 = q3x * cy - q3y * cx
    r1, r2 = _quad_roots(3.0 * c3, 2.0 * c2, -(c2 + c3))
    s1 = np.abs(r1 * (r1 - 1.0) * (c3 * r1 + c2 + c3))
    s2 = np.abs(r2 * (r2 - 1.0) * (c3 * r2 + c2 + c3))
    good = L > 0.0
    Ls = np.where(good, L, 1.0)
    H = np.maximum(s1, s2) / Ls
    # overshoot of the projection beyond the chord's ends (scaled by |c|): the projection
    # d1 τ + d2 τ² + d3 τ³ runs from 0 to |c|² and is monotone (no overshoot) wherever its
    # derivative d1 + 2 d2 τ + 3 d3 τ² >= d1 − 2|d2| − 3|d3| stays positive on [0, 1]: the
    # usual case for a short chord; only the others need the extremes
    d1 = q1x * cx + q1y * cy
    d2 = q2x * cx + q2y * cy
    d3 = q3x * cx + q3y * cy
    maybe = ~(d1 > 2.0 * np.abs(d2) + 3.0 * np.abs(d3))
    if maybe.any():
        i = np.flatnonzero(maybe)
        e1, e2, e3 = d1[i], d2[i], d3[i]
        p1, p2 = _quad_roots(3.0 * e3, 2.0 * e2, e1)
        pv1 = ((e3 * p1 + e2) * p1 + e1) * p1
        pv2 = ((e3 * p2 + e2) * p2 + e1) * p2
        Li = L[i]
        over = np.maximum(np.maximum(np.maximum(-pv1, -pv2), np.maximum(pv1, pv2) - Li * Li),
                          0.0) / Ls[i]
        H[i] = np.where(over > 0.0, np.hypot(H[i], over), H[i])
    if not good.all():  # a chord of zero length: the bound
        i = np.flatnonzero(~good)
        H[i] = (np.hypot(q1x[i], q1y[i]) + np.hypot(q2x[i], q2y[i])
                + np.hypot(q3x[i], q3y[i]))
    return H, L


def segment_heights(coef: np.ndarray | CF, ta: np.ndarray, tb: np.ndarray, A: np.ndarray,
                    C: np.ndarray) -> np.ndarray:
    """Largest distance of cubic stretches B([ta, tb]) to arbitrary segments A→C (K,).

    For chords whose ends are not on the curve: rounded marks, or chords spanning a joint
    (evaluated piece by piece). The distance is evaluated exactly at τ = 0, 1 and at the
    critical points of both the perpendicular and the along-chord coordinate (roots of two
    quadratics); that is the true maximum wherever the curve stays over the segment (the
    rounding of the ends lets it pass an end by less than a bit; near the end the distance
    to the end point is then monotone, so the ends and critical points still give it).
    Where the curve passes an end by more than a bit, :data:`_OVER_SAMPLES` + 1 evenly spaced
    parameters are added.
    """
    cf = coef if isinstance(coef, tuple) else _cf(coef)
    b0x, b0y, q1x, q1y, q2x, q2y, q3x, q3y = _taylor(cf, ta, tb)
    q0x = b0x - A[:, 0]
    q0y = b0y - A[:, 1]
    cx = C[:, 0] - A[:, 0]
    cy = C[:, 1] - A[:, 1]
    cc = cx * cx + cy * cy
    inv = np.where(cc > 0.0, 1.0 / np.where(cc > 0.0, cc, 1.0), 0.0)
    cands = [np.zeros(len(ta)), np.ones(len(ta))]
    cands += list(_quad_roots(3.0 * (q3x * cy - q3y * cx), 2.0 * (q2x * cy - q2y * cx),
                              q1x * cy - q1y * cx))
    cands += list(_quad_roots(3.0 * (q3x * cx + q3y * cy), 2.0 * (q2x * cx + q2y * cy),
                              q1x * cx + q1y * cy))
    out = np.zeros(len(ta))
    over = np.zeros(len(ta))
    for u in cands:
        dx = ((q3x * u + q2x) * u + q1x) * u + q0x
        dy = ((q3y * u + q2y) * u + q1y) * u + q0y
        raw = (dx * cx + dy * cy) * inv
        np.maximum(over, np.maximum(-raw, raw - 1.0), out=over)
        sc = np.clip(raw, 0.0, 1.0)
        np.maximum(out, np.hypot(dx - sc * cx, dy - sc * cy), out=out)
    big = over * np.sqrt(cc) > 1.0
    if big.any():  # beyond an end the distance is to the end point: sample densely there
        i = np.flatnonzero(big)
        u = np.linspace(0.0, 1.0, _OVER_SAMPLES + 1)[None, :]
        dx = ((q3x[i, None] * u + q2x[i, None]) * u + q1x[i, None]) * u + q0x[i, None]
        dy = ((q3y[i, None] * u + q2y[i, None]) * u + q1y[i, None]) * u + q0y[i, None]
        sc = np.clip((dx * cx[i, None] + dy * cy[i, None]) * inv[i, None], 0.0, 1.0)
        e = np.hypot(dx - sc * cx[i, None], dy - sc * cy[i, None]).max(axis=1)
        out[i] = np.maximum(out[i], e)
    return out


# =========================================================================== curves
def _speed_curvature(cf: CF, t: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """(|B'(t)|, curvature at t) of cubics in power form (curvature NaN or inf where the
    speed is 0)."""
    ax, ay, bx, by, dx, dy, _, _ = cf
    d1x = (3.0 * ax * t + 2.0 * bx) * t + dx
    d1y = (3.0 * ay * t + 2.0 * by) * t + dy
    d2x = 6.0 * ax * t + 2.0 * bx
    d2y = 6.0 * ay * t + 2.0 * by
    sp = np.hypot(d1x, d1y)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.abs(d1x * d2y - d1y * d2x) / (sp * sp * sp)
    return sp, k


class _CubicSet:
    """Many 2-D cubics in power form (lines are cubics with a = b = 0), stored as eight
    contiguous coefficient arrays."""

    def __init__(self, coef: np.ndarray, cf: CF | None = None) -> None:
        self.cf = cf if cf is not None else _cf(coef)

    def gather(self, ids: np.ndarray) -> CF:
        return tuple(x[ids] for x in self.cf)  # type: ignore[return-value]

    def guess_terms(self, ids: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(|B'|, curvature) at t."""
        return _speed_curvature(self.gather(ids), t)

    def height(self, ids: np.ndarray, ta: np.ndarray, tb: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
        return chord_heights(self.gather(ids), ta, tb)

    def point(self, ids: np.ndarray, t: np.ndarray) -> np.ndarray:
        ax, ay, bx, by, dx, dy, ex, ey = self.gather(ids)
        return np.stack((((ax * t + bx) * t + dx) * t + ex, ((ay * t + by) * t + dy) * t + ey),
                        axis=1)


class _ChainSet:
    """Chains of cubics that meet smoothly (no corner at their joints), each searched as one
    curve, so that a chord may run across a joint: chain k is made of the cubics
    ``first[k]`` … ``first[k] + n[k] − 1`` of a :class:`_CubicSet`, with the parameter
    s in [0, n[k]] (cubic ``first[k] + j`` for s in [j, j + 1]). A chord within one cubic
    is measured by the closed form (:func:`chord_heights`); one across joints piece by piece
    against the chord (:func:`segment_heights`), as the final measurement does."""

    def __init__(self, cs: _CubicSet, first: np.ndarray, n: np.ndarray) -> None:
        self.cs, self.first, self.n = cs, first, n

    def locate(self, ids: np.ndarray, s: np.ndarray, *, ending: bool
               ) -> tuple[np.ndarray, np.ndarray]:
        """(cubic id, t) of chain parameters ``s``: at a joint the cubic that ends there
        (``ending``, for a chord's end) or the one that starts there."""
        last = self.n[ids] - 1
        j = np.ceil(s) - 1.0 if ending else np.floor(s)
        j = np.clip(j, 0, last).astype(np.int64)
        return self.first[ids] + j, s - j

    def guess_terms(self, ids: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.cs.guess_terms(*self.locate(ids, s, ending=False))

    def point(self, ids: np.ndarray, s: np.ndarray) -> np.ndarray:
        return self.cs.point(*self.locate(ids, s, ending=True))

    def height(self, ids: np.ndarray, sa: np.ndarray, sb: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
        ga, ta = self.locate(ids, sa, ending=False)
        gb, tb = self.locate(ids, sb, ending=True)
        gb = np.maximum(gb, ga)  # a chord of zero length at a joint
        tb = np.where(gb == ga, sb - (ga - self.first[ids]), tb)
        one = gb == ga
        if one.all():
            return chord_heights(self.cs.gather(ga), ta, tb)
        H = np.empty(len(sa))
        L = np.empty(len(sa))
        i = np.flatnonzero(one)
        H[i], L[i] = chord_heights(self.cs.gather(ga[i]), ta[i], tb[i])
        i = np.flatnonzero(~one)
        A = self.cs.point(ga[i], ta[i])
        B = self.cs.point(gb[i], tb[i])
        H[i] = _span_heights(self.cs, ga[i], ta[i], gb[i], tb[i], A, B)
        L[i] = np.hypot(B[:, 0] - A[:, 0], B[:, 1] - A[:, 1])
        return H, L


def _span_heights(cs: _CubicSet, ga: np.ndarray, ta: np.ndarray, gb: np.ndarray,
                  tb: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Largest distance to the segments A→B (K,) of the curve from (cubic ``ga``, ``ta``)
    to (cubic ``gb`` > ``ga``, ``tb``): the first cubic from ``ta``, the last up to ``tb``,
    every cubic between them whole (one vectorised pass per position in the span)."""
    one, zero = np.ones(len(ga)), np.zeros(len(ga))
    H = np.maximum(segment_heights(cs.gather(ga), ta, one, A, B),
                   segment_heights(cs.gather(gb), zero, tb, A, B))
    off = 1
    while True:
        i = np.flatnonzero(ga + off < gb)
        if not len(i):
            return H
        H[i] = np.maximum(H[i], segment_heights(cs.gather(ga[i] + off), zero[i], one[i],
                                                A[i], B[i]))
        off += 1


def _smooth_chains(cf: CF, is_cubic: np.ndarray, corner: np.ndarray, seg_path: np.ndarray,
                   tol: float) -> tuple[np.ndarray, np.ndarray]:
    """``(first, n)`` of the runs of consecutive cubics of one path whose joints are not
    corners (segment ids in the order of the fit), cut where a run has gathered about
    :data:`_CHAIN_MARKS` marks: the search advances all curves in lock-step, one mark per
    curve per round, so a few long chains would cost many rounds over short arrays; a cut
    costs at most one partial chord in that many. Marks are estimated per cubic by the
    integral N = ∫ sqrt(κ) ds / sqrt(8 tol) (4-point Gauss–Legendre)."""
    g = len(is_cubic)
    joined = np.zeros(g, dtype=bool)  # segment i continues into i + 1
    if g > 1:
        joined[:-1] = (is_cubic[:-1] & is_cubic[1:] & ~corner[:-1]
                       & (seg_path[:-1] == seg_path[1:]))
    if joined.any():
        x, w = np.polynomial.legendre.leggauss(4)
        # a line (a = b = 0) has curvature 0: its estimate is exactly 1, only the cubics
        # are evaluated
        cub = np.flatnonzero(is_cubic)
        cfc = tuple(x[cub] for x in cf)
        ec = np.zeros(len(cub))
        for xi, wi in zip(0.5 * (x + 1.0), 0.5 * w, strict=True):
            sp, k = _speed_curvature(cfc, float(xi))  # type: ignore[arg-type]
            with np.errstate(invalid="ignore"):
                ec += wi * np.nan_to_num(np.sqrt(k) * sp, posinf=0.0)  # sqrt(κ)·|B'|
        est = np.ones(g)
        est[cub] = ec / math.sqrt(8.0 * tol) + 1.0
        # marks gathered before each cubic since the start of its run; cut at multiples
        start = ~np.r_[False, joined[:-1]]
        cum = np.cumsum(est) - est
        run_base = np.maximum.accumulate(np.where(start, cum, 0.0))
        bucket = np.floor((cum - run_base) / _CHAIN_MARKS)
        joined[:-1] &= bucket[1:] == bucket[:-1]
    starts = np.flatnonzero(is_cubic & ~np.r_[False, joined[:-1]])
    ends = np.flatnonzero(is_cubic & ~joined)
    return starts, ends - starts + 1


Func = Callable[[np.ndarray], np.ndarray]


class _FuncCurve:
    """One parametric curve in any dimension, given as vectorised f, f', f''.

    Chord heights are measured numerically as paper 004 eq. (7)–(8): the distance L(t) of the
    curve to the chord's line is sampled at :attr:`seeds` + 1 parameters, and the best
    sample is refined by Newton steps on dL²/dt = 0 (using f''); an overshoot of the chord's
    ends adds to H as in :func:`chord_heights`.
    """

    seeds = 16

    def __init__(self, f: Func, df: Func, ddf: Func) -> None:
        self.f, self.df, self.ddf = f, df, ddf

    def _v(self, fn: Func, t: np.ndarray) -> np.ndarray:
        out = np.asarray(fn(np.asarray(t, dtype=np.float64)), dtype=np.float64)
        return out.reshape(len(t), -1)

    def guess_terms(self, ids: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d1 = self._v(self.df, t)
        d2 = self._v(self.ddf, t)
        s2 = (d1 * d1).sum(axis=1)
        cr2 = np.maximum(s2 * (d2 * d2).sum(axis=1) - (d1 * d2).sum(axis=1) ** 2, 0.0)
        sp = np.sqrt(s2)
        with np.errstate(divide="ignore", invalid="ignore"):
            k = np.sqrt(cr2) / (sp * s2)
        return sp, k

    def point(self, ids: np.ndarray, t: np.ndarray) -> np.ndarray:
        return self._v(self.f, t)

    def height(self, ids: np.ndarray, ta: np.ndarray, tb: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
        n, ks = len(ta), self.seeds
        A = self._v(self.f, ta)
        C = self._v(self.f, tb)
        c = C - A
        L = np.sqrt((c * c).sum(axis=1))
        u = c / np.where(L > 0, L, 1.0)[:, None]
        tau = np.linspace(0.0, 1.0, ks + 1)
        tt = (ta[:, None] + (tb - ta)[:, None] * tau[None, :]).ravel()
        P = self._v(self.f, tt).reshape(n, ks + 1, -1)
        D = P - A[:, None, :]
        along = (D * u[:, None, :]).sum(axis=2)
        perp = D - along[:, :, None] * u[:, None, :]
        dist = np.sqrt((perp * perp).sum(axis=2))
        j = np.argmax(dist, axis=1)
        H = dist[np.arange(n), j]
        # Newton on g(t) = perp(t)·P'(t) = 0 (dL²/dt = 0) inside the bracket of the seed
        h = tb - ta
        lo = ta + h * tau[np.maximum(j - 1, 0)]
        hi = ta + h * tau[np.minimum(j + 1, ks)]
        t = ta + h * tau[j]
        for _ in range(4):
            p = self._v(self.f, t) - A
            p1 = self._v(self.df, t)
            p2 = self._v(self.ddf, t)
            al = (p * u).sum(axis=1)
            pr = p - al[:, None] * u
            g = (pr * p1).sum(axis=1)
            gp = (p1 * p1).sum(axis=1) - (p1 * u).sum(axis=1) ** 2 + (pr * p2).sum(axis=1)
            with np.errstate(divide="ignore", invalid="ignore"):
                step = np.where(gp < 0.0, g / gp, 0.0)  # a maximum: g' < 0
            t = np.clip(t - np.nan_to_num(step), lo, hi)
        p = self._v(self.f, t) - A
        al = (p * u).sum(axis=1)
        pr = p - al[:, None] * u
        H = np.maximum(H, np.sqrt((pr * pr).sum(axis=1)))
        over = np.maximum(np.maximum(-along.min(axis=1), along.max(axis=1) - L), 0.0)
        H = np.where(over > 0.0, np.hypot(H, over), H)
        return H, L


_Curves = _CubicSet | _ChainSet | _FuncCurve


# =========================================================================== step search
def _first_step(curves: _Curves, ids: np.ndarray, t: np.ndarray,
                hp: float, max_step: float) -> np.ndarray:
    """Paper 004's first trial: R = 2r·sin(θ/2), θ = 2·arccos((r − H_p)/r), r = 1/k, as a
    parameter step R/|P'| (R = the diameter 2r when H_p > r; the whole rest for k = 0)."""
    sp, k = curves.guess_terms(ids, t)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        r = 1.0 / k
        R = np.where(hp < r, 2.0 * np.sqrt(np.maximum(2.0 * r * hp - hp * hp, 0.0)), 2.0 * r)
        R = np.minimum(R, max_step)
        dt = R / sp
    return np.where(np.isfinite(dt) & (dt > 0.0), dt, np.inf)


def _search(curves: _Curves, ids0: np.ndarray, t0: np.ndarray,
            t1: np.ndarray, *, e_min: float, e_max: float, min_step: float, max_step: float,
            cancel: Callable[[], bool] | None = None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Greedy chords along many curves at once (lock-step, one trial per curve per round).

    Returns ``(k, t, override, trials)``: for every mark after the start, the index k of its
    curve in ``ids0`` and its parameter, sorted by (k, t); the last mark of curve k is at
    t1[k]. ``override`` marks steps set by the minimum step instead of the tolerance.
    """
    return _search_h(curves, ids0, t0, t1, e_min=e_min, e_max=e_max, min_step=min_step,
                     max_step=max_step, cancel=cancel)[:4]  # type: ignore[return-value]


def _search_h(curves: _Curves, ids0: np.ndarray, t0: np.ndarray,
              t1: np.ndarray, *, e_min: float, e_max: float, min_step: float,
              max_step: float, cancel: Callable[[], bool] | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, np.ndarray, np.ndarray]:
    """:func:`_search`, also returning ``(h, ta)`` per mark: the chord height measured for
    the chord ta → t that ended at the mark (the very value :meth:`height` gives for it),
    both NaN where the mark's parameter was set otherwise (minimum step, bracket
    fallback)."""
    n = len(ids0)
    hp = 0.5 * (e_min + e_max)
    k = np.arange(n)
    ta = np.asarray(t0, dtype=np.float64).copy()
    t1 = np.asarray(t1, dtype=np.float64)
    live = t1 > ta
    k, ta = k[live], ta[live]
    dt = _first_step(curves, ids0[k], ta, hp, max_step)
    lo = np.zeros(len(k))
    hi = np.full(len(k), np.inf)
    pdt = np.zeros(len(k))
    pH = np.full(len(k), np.nan)
    it = np.zeros(len(k), dtype=np.int64)
    out_k: list[np.ndarray] = []
    out_t: list[np.ndarray] = []
    out_o: list[np.ndarray] = []
    out_h: list[np.ndarray] = []
    out_a: list[np.ndarray] = []
    trials = 0
    rounds = 0
    while len(k):
        rounds += 1
        if cancel is not None and rounds % _CANCEL_EVERY == 0 and cancel():
            raise Cancelled()
        ids = ids0[k]
        te = t1[k]
        rem = te - ta
        trial = np.minimum(dt, rem)
        end = trial >= rem
        tb = np.where(end, te, ta + trial)
        H, L = curves.height(ids, ta, tb)
        trials += len(k)
        ok = (H <= e_max) & (L <= max_step)
        acc = ok & (end | (H >= e_min) | (L >= _MAX_STEP_ACCEPT * max_step))
        it += 1
        lo = np.where(ok, np.maximum(lo, trial), lo)
        hi = np.where(ok, hi, np.minimum(hi, trial))
        # the minimum step: a chord shorter than it is only taken at the curve's end
        short_fail = ~ok & (L < min_step)
        short_acc = acc & ~end & (L < min_step)
        stuck = ~acc & ~short_fail & ((np.isfinite(hi) & ((hi - lo) <= _BRACKET_REL * hi))
                                       | (it >= _MAX_TRIALS))
        ovr = short_fail | short_acc | (stuck & (lo <= 0.0))
        take_lo = stuck & (lo > 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            stretch = trial * (min_step / np.where(L > 0.0, L, 0.0))
        stretch = np.where(np.isfinite(stretch), stretch, rem)
        t_new = tb.copy()
        t_new[take_lo] = (ta + lo)[take_lo]
        if ovr.any():
            io = np.flatnonzero(ovr)
            t_new[io] = _min_step_end(curves, ids[io], ta[io], te[io],
                                      np.maximum(stretch, trial)[io], min_step)
        done = acc | ovr | take_lo
        if done.any():
            out_k.append(k[done])
            out_t.append(t_new[done])
            out_o.append(ovr[done])
            # the measured height belongs to the chord ta -> tb: only where t_new is tb
            out_h.append(np.where(ovr | take_lo, np.nan, H)[done])
            out_a.append(np.where(ovr | take_lo, np.nan, ta)[done])
        nxt = _next_trial(trial, H, L, pdt, pH, lo, hi, hp, max_step)
        pdt, pH, dt = trial, H, nxt
        # accepted: move on (curves that reached their end leave)
        ta = np.where(done, t_new, ta)
        fin = done & (t_new >= te)
        cont = ~fin
        restart = done & cont
        if restart.any():
            dt[restart] = _first_step(curves, ids[restart], ta[restart], hp, max_step)
            lo[restart] = 0.0
            hi[restart] = np.inf
            pH[restart] = np.nan
            it[restart] = 0
        k, ta, dt, lo, hi, pdt, pH, it = (x[cont] for x in (k, ta, dt, lo, hi, pdt, pH, it))
    if not out_k:
        z = np.zeros(0)
        return z.astype(np.int64), z, z.astype(bool), trials, z, z
    kk = np.concatenate(out_k)
    tt = np.concatenate(out_t)
    oo = np.concatenate(out_o)
    hh = np.concatenate(out_h)
    aa = np.concatenate(out_a)
    order = np.argsort(kk, kind="stable")  # rounds emit increasing t per curve
    return kk[order], tt[order], oo[order], trials, hh[order], aa[order]


def _min_step_end(curves: _Curves, ids: np.ndarray, ta: np.ndarray, te: np.ndarray,
                  dto: np.ndarray, min_step: float) -> np.ndarray:
    """The end parameter of a chord from ``ta`` stretched to ``min_step`` long (not past
    ``te``), from the first guess ``ta + dto``: the chord's length is not linear in the
    parameter, so the guess is corrected a few times."""
    for _ in range(_MIN_STEP_FIXES):
        t_try = np.minimum(ta + dto, te)
        d = curves.point(ids, t_try) - curves.point(ids, ta)
        length = np.sqrt((d * d).sum(axis=1))
        with np.errstate(divide="ignore", invalid="ignore"):
            f = min_step / length
        grow = np.isfinite(f) & (f > 1.0) & (t_try < te)
        if not grow.any():
            break
        dto = np.where(grow, dto * np.minimum(f, _MIN_STEP_GROWTH), dto)
    return np.minimum(ta + dto, te)


def _next_trial(trial: np.ndarray, H: np.ndarray, L: np.ndarray, pdt: np.ndarray,
                pH: np.ndarray, lo: np.ndarray, hi: np.ndarray, hp: float,
                max_step: float) -> np.ndarray:
    """The next step to try for the chords not yet accepted: the last step rescaled by the
    growth law measured between the last two trials (height ~ step**p) to hit the middle
    of the window ``hp``, kept under ``max_step`` and inside the bracket [lo, hi] of steps
    known to pass and to fail (else the bracket's middle, or twice ``lo`` when nothing has
    failed yet)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.log(H / pH) / np.log(trial / pdt)
    p = np.where(np.isfinite(p), np.clip(p, _GROWTH_MIN, _GROWTH_MAX), _GROWTH_DEFAULT)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        nxt = trial * (hp / np.maximum(H, _TINY)) ** (1.0 / p)
        nxt = np.where(L > max_step, np.minimum(nxt, trial * _MAX_STEP_AIM * max_step / L),
                       nxt)
    inside = (nxt > lo) & (nxt < hi) & np.isfinite(nxt)
    mid = np.where(np.isfinite(hi), np.where(lo > 0.0, 0.5 * (lo + hi), 0.5 * hi), 2.0 * lo)
    return np.where(inside, nxt, mid)


def _fix_short_ends(curves: _Curves, ids0: np.ndarray, t0: np.ndarray,
                    k: np.ndarray, t: np.ndarray, *, e_max: float, min_step: float,
                    h: np.ndarray | None = None, a: np.ndarray | None = None) -> None:
    """A curve's last chord shorter than ``min_step``: move the previous mark to the
    parameter midpoint of the last two chords when both halves then hold (in place). ``h``,
    ``a`` (from :func:`_search_h`): the two chords' measured heights and starts follow."""
    if min_step <= 0.0 or len(k) < 2:
        return
    last = np.flatnonzero(np.r_[k[1:] != k[:-1], True])
    prev = last - 1
    has = (prev >= 0) & (k[np.maximum(prev, 0)] == k[last])
    last, prev = last[has], prev[has]
    if not len(last):
        return
    pp = prev - 1
    t_start = np.where((pp >= 0) & (k[np.maximum(pp, 0)] == k[prev]), t[np.maximum(pp, 0)],
                       t0[k[prev]])
    ids = ids0[k[last]]
    _, Llast = curves.height(ids, t[prev], t[last])
    bad = Llast < min_step
    if not bad.any():
        return
    last, prev, t_start, ids = last[bad], prev[bad], t_start[bad], ids[bad]
    tm = 0.5 * (t_start + t[last])
    H1, L1 = curves.height(ids, t_start, tm)
    H2, L2 = curves.height(ids, tm, t[last])
    good = (H1 <= e_max) & (H2 <= e_max) & (L1 >= min_step) & (L2 >= min_step)
    t[prev[good]] = tm[good]
    if h is not None and a is not None:
        h[prev[good]] = H1[good]
        h[last[good]] = H2[good]
        a[last[good]] = tm[good]


@dataclass(frozen=True)
class CurveSample:
    """Marks of one curve: parameters ``t`` (N,), points (N, D), measured chord heights
    (N − 1,), chord lengths (N − 1,), and the number of min-step overrides and trials."""

    t: np.ndarray
    points: np.ndarray
    heights: np.ndarray
    lengths: np.ndarray
    overrides: int
    trials: int


def sample_curve(f: Func, df: Func, ddf: Func, t0: float, t1: float, *, e_min: float,
                 e_max: float, min_step: float = 0.0, max_step: float | None = None
                 ) -> CurveSample:
    """Paper 004's step search on a parametric curve in any dimension (2-D, 3-D, ...).

    ``f``, ``df``, ``ddf``: vectorised position, first and second derivative, (K,) -> (K, D).
    Every chord has a measured chord height <= ``e_max`` and, except the last, >= ``e_min``
    (or is capped by ``max_step``, or set by ``min_step`` where the curve is tighter than the
    minimum allows — counted in ``overrides``). The same search cuts the 2-D cubics of
    :func:`sample_paths`, there with the closed-form chord height.
    """
    if not (0.0 <= e_min <= e_max and e_max > 0.0 and math.isfinite(e_max)):
        raise ParamError("sample_curve: need 0 <= e_min <= e_max, e_max > 0 and finite")
    if not (math.isfinite(t0) and math.isfinite(t1) and t1 >= t0):
        raise ParamError("sample_curve: need finite t0 <= t1")
    ms = math.inf if max_step is None else float(max_step)
    curve = _FuncCurve(f, df, ddf)
    ids = np.zeros(1, dtype=np.int64)
    kk, tt, oo, trials = _search(curve, ids, np.array([t0]), np.array([t1]), e_min=e_min,
                                 e_max=e_max, min_step=min_step, max_step=ms)
    _fix_short_ends(curve, ids, np.array([t0]), kk, tt, e_max=e_max, min_step=min_step)
    t = np.concatenate(([float(t0)], tt))
    pts = curve.point(np.zeros(len(t), dtype=np.int64), t)
    if len(t) >= 2:
        H, L = curve.height(np.zeros(len(t) - 1, dtype=np.int64), t[:-1], t[1:])
    else:
        H = L = np.zeros(0)
    return CurveSample(t, pts, H, L, int(oo.sum()), trials)


# =========================================================================== paths
@dataclass
class SampleReport:
    """What the sampler measured, for the job's stats (all in galvo bits)."""

    interpolation: str
    chord_tol_bits: float
    max_chord_height_bits: float | None = None  # before rounding; None for raw marks
    max_chord_height_int_bits: float | None = None  # of the integer marks
    chords: int = 0
    chord_violations: int = 0  # chords above chord_tol_bits before rounding
    min_step_overrides: int = 0
    trials: int = 0  # chord-height measurements made by the step search
    outside_points: int = 0  # marks outside 0..field_bits-1 (before any clamping)
    rounding_bound_bits: float = ROUNDING_BOUND_BITS

    def as_dict(self) -> dict[str, object]:
        return {
            "interpolation": self.interpolation,
            "chord_tol_bits": self.chord_tol_bits,
            "max_chord_height_bits": self.max_chord_height_bits,
            "max_chord_height_int_bits": self.max_chord_height_int_bits,
            "chord_height_violations": self.chord_violations,
            "min_step_overrides": self.min_step_overrides,
            "rounding_bound_bits": self.rounding_bound_bits,
            "outside_points": self.outside_points,
        }


@dataclass
class SampleResult:
    marks: list[np.ndarray]
    report: SampleReport
    coef: np.ndarray | None = None
    # per chunk of paths: float marks, segment ids (of the chunk), parameters, the first
    # segment of the chunk and where each path's rows start (one more: the end)
    chunks: list[tuple[np.ndarray, np.ndarray, np.ndarray, int, np.ndarray]] = (
        field(default_factory=list))

    @property
    def float_marks(self) -> list[np.ndarray]:
        """Per stroke, the float marks (bits, before rounding) — for tests and benchmarks,
        made when asked (not one array per path while the job is built)."""
        return [x for pos, _, _, _, pc in self.chunks for x in _split_rows(pos, pc)]

    @property
    def params(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Per stroke, the marks' (global segment id, t), made when asked."""
        out = []
        for _, sid, st, g0, pc in self.chunks:
            sg = sid + g0
            out += [(sg[a:b], st[a:b]) for a, b in zip(pc[:-1].tolist(), pc[1:].tolist(),
                                                        strict=True)]
        return out


def _round(p: np.ndarray) -> np.ndarray:
    """Nearest integer, halves away from zero: floor(p + 0.5) for p >= 0, ceil(p − 0.5)
    below (the same numbers: p ± 0.5 is rounded once either way, and truncation is floor
    on the positive side and ceil on the negative one)."""
    return np.trunc(p + np.copysign(0.5, p)).astype(np.int64)


def _dedup(marks: np.ndarray) -> np.ndarray:
    """Drop consecutive repeats of the same integer mark (a dot keeps one mark)."""
    if len(marks) < 2:
        return marks
    keep = np.ones(len(marks), dtype=bool)
    keep[1:] = (marks[1:] != marks[:-1]).any(axis=1)
    return marks[keep]


def _min_step_filter(pts: np.ndarray, prot: np.ndarray, min_step: float,
                     first: np.ndarray | None = None, d: np.ndarray | None = None,
                     merge_ok: Callable[[int, int], bool] | None = None,
                     forced: list[int] | None = None) -> np.ndarray:
    """Indices to keep so that consecutive kept marks are >= min_step apart, protected marks
    (stroke ends, corners) always kept.

    Greedy along the marks: a mark is kept when it is at least ``min_step`` from the last
    kept one; a protected mark closer than that is kept anyway and drops the unprotected
    kept marks before it that are too close to it. ``first`` (optional) marks the first
    mark of each stroke when ``pts`` holds several strokes one after the other: each stroke
    is filtered on its own (its ends must be protected). ``d``: the distances between
    consecutive marks, when the caller has them. Only the stretches around chords shorter
    than ``min_step`` are walked one mark at a time; between them every mark is kept (its
    predecessor is kept and far enough).

    ``merge_ok(a, b)`` (optional): whether the chord from mark a to mark b keeps within the
    chord tolerance. An unprotected mark i too close to the kept mark j before it is then
    dropped only when the chord j → i + 1 that replaces j → i → i + 1 holds; otherwise j is
    dropped instead when j is unprotected, the chord from the kept mark before j to i
    holds and is long enough; when neither holds i is dropped (the minimum step wins) and
    i is appended to ``forced``. A protected mark i whose chord from the kept mark before
    it no longer holds after the marks too close to it were dropped is appended too."""
    n = len(pts)
    if min_step <= 0.0 or n < 3:
        return np.arange(n)
    if d is None:
        d = np.hypot(*np.diff(pts, axis=0).T)
    short = d < min_step
    if first is not None:
        short &= ~first[1:]  # no chord from one stroke to the next
    if not short.any():
        return np.arange(n)
    sq = np.flatnonzero(short).tolist()  # chords q -> q + 1 shorter than min_step
    ns = len(sq)
    sh = short.tolist()
    x = pts[:, 0].tolist()
    y = pts[:, 1].tolist()
    pr = prot.tolist()
    fs = first.tolist() if first is not None else None
    hyp = math.hypot
    keep = [0]
    i = 1
    p = 0  # sq[p] is the next short chord that may matter
    while i < n:
        if keep[-1] == i - 1 and not sh[i - 1]:
            # fast: i is kept, and so is every mark up to the next short chord's start
            while p < ns and sq[p] < i:
                p += 1
            q = sq[p] if p < ns else n - 1
            keep.extend(range(i, q + 1))
            i = q + 1
            continue
        if fs is not None and fs[i]:  # a stroke's first mark
            keep.append(i)
            i += 1
            continue
        j = keep[-1]
        if hyp(x[i] - x[j], y[i] - y[j]) >= min_step:
            keep.append(i)
        elif pr[i]:
            popped = False
            while len(keep) > 1 and not pr[keep[-1]] and hyp(
                    x[i] - x[keep[-1]], y[i] - y[keep[-1]]) < min_step:
                keep.pop()
                popped = True
            if popped and forced is not None and merge_ok is not None \
                    and not merge_ok(keep[-1], i):
                forced.append(i)
            keep.append(i)
        elif merge_ok is not None and not merge_ok(j, i + 1):
            k = keep[-2] if len(keep) > 1 else -1
            if (k >= 0 and not pr[j] and (fs is None or not fs[j])
                    and hyp(x[i] - x[k], y[i] - y[k]) >= min_step and merge_ok(k, i)):
                keep[-1] = i
            elif forced is not None:
                forced.append(i)
        i += 1
    return np.asarray(keep, dtype=np.int64)


def _fixed_params(cs: _CubicSet, gid: int, step: float, k0: float) -> np.ndarray:
    """Paper 001 on one cubic: parameters of the chord ends (without t = 0, with t = 1)."""
    # points P_i every ``step`` of Chebyshev arc length, found on a dense sampling
    dense_n = 64
    for _ in range(8):
        td = np.linspace(0.0, 1.0, dense_n + 1)
        pd = cs.point(np.full(len(td), gid), td)
        dd = np.abs(np.diff(pd, axis=0)).max(axis=1)
        if dd.max() <= step / 8.0 or dense_n >= 1 << 16:
            break
        dense_n = min(1 << 16, int(dense_n * max(2.0, 8.0 * dd.max() / step)))
    cheb = np.concatenate(([0.0], np.cumsum(dd)))
    total = cheb[-1]
    if total <= step:
        return np.array([1.0])
    targets = np.arange(step, total, step)
    ti = np.interp(targets, cheb, td)
    ti = np.concatenate((ti, [1.0])) if ti[-1] < 1.0 else ti
    pi = cs.point(np.full(len(ti), gid), ti)
    allp = np.vstack((pd[:1], pi))  # index 0 = the start A
    ends: list[int] = []
    a = 0
    m = len(allp)
    while a < m - 1:
        first = allp[a + 1] - allp[a]
        rest = allp[a + 2:] - allp[a]
        if len(rest) == 0:
            ends.append(m - 1)
            break
        cr = first[0] * rest[:, 1] - first[1] * rest[:, 0]
        dt_ = first[0] * rest[:, 0] + first[1] * rest[:, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = np.abs(cr / dt_)
        bad = ~(slope <= k0)  # includes turns of 90° or more (dt_ <= 0, nan)
        if not bad.any():
            ends.append(m - 1)
            break
        i = int(np.argmax(bad)) + a + 2  # the first P_i that breaks the slope threshold
        ends.append(i - 1)
        a = i - 1
    return np.concatenate(([0.0], ti))[ends]


class _Geometry:
    """The segments of a sequence of fitted paths as flat arrays (input units), gathered
    once per sequence (a Python loop over the segments), and what depends only on them and
    the field mapping (end points in bits, power form, corner joints), kept for the
    latest mapping: a re-sample at another tolerance maps nothing again."""

    def __init__(self, fitted: Sequence[FittedPath]) -> None:
        # the paths' own arrays (FittedPath: kinds and shared control points), concatenated
        self.path_n = np.fromiter((len(fp.is_cubic) for fp in fitted), dtype=np.int64,
                                  count=len(fitted))
        self.path_first = np.cumsum(self.path_n) - self.path_n
        g = int(self.path_n.sum())
        self.seg_path = np.repeat(np.arange(len(fitted)), self.path_n)
        # the shared control points of every path (input units) and the row of each
        # segment's P0 among them (a line: P0, P1 in rows row, row + 1; a cubic: P0..P3 in
        # rows row..row + 3): 16 bytes per point and 8 per segment, not a (G, 4, 2) copy
        if g:
            self.is_cubic = np.concatenate([fp.is_cubic for fp in fitted])
            self.points = np.concatenate([fp.points for fp in fitted]).astype(np.float64,
                                                                              copy=False)
            npts = np.fromiter((len(fp.points) for fp in fitted), dtype=np.int64,
                               count=len(fitted))
            step = np.where(self.is_cubic, 3, 1)
            # row of each segment's P0: its path's first row + the steps before it in the path
            cs = np.cumsum(step)
            row = cs - step
            base = (np.cumsum(npts) - npts) - np.r_[row, cs[-1:]][self.path_first]
            row += np.repeat(base, self.path_n)
            self.row = row
        else:
            self.is_cubic = np.zeros(0, dtype=bool)
            self.points = np.zeros((0, 2))
            self.row = np.zeros(0, dtype=np.int64)
            npts = np.zeros(len(fitted), dtype=np.int64)
        #: control points per path (rows of ``points``; 0 for a path without segments)
        self.path_npts = npts
        self._fielded: OrderedDict[tuple[float, ...], tuple[Any, ...]] = OrderedDict()
        self._lock = threading.Lock()

    def fielded(self, fm: FieldMap) -> tuple[Any, ...]:
        """``(ends, coef, corner, cf)`` for ``fm`` (read-only arrays): the end points in
        bits (G, 2, 2), power coefficients (G, 4, 2; a line exactly a = b = 0), for each
        segment whether its joint with the next one (same path) is a corner, and the
        coefficients as the eight flat arrays of :func:`_cf`."""
        key = (fm.magnification, *fm.offset_bits)
        with self._lock:
            hit = self._fielded.get(key)
            if hit is not None:
                self._fielded.move_to_end(key)
                return hit
        # in chunks of CHUNK_SEGMENTS segments: the outputs are allocated once, every
        # temporary is a chunk's (reused from the heap, not mapped afresh at every size)
        g = len(self.row)
        block = np.empty((4, 2, g))
        ends = np.empty((g, 2, 2))
        corner = np.zeros(g, dtype=bool)
        for a in range(0, g, CHUNK_SEGMENTS):
            b = min(a + CHUNK_SEGMENTS, g)
            # one segment more than the chunk: the corner at the chunk's last joint
            self._fielded_chunk(fm, a, min(b + 1, g), b, block, ends, corner)
        coef = block.transpose(2, 0, 1)  # (G, 4, 2) view
        cf = tuple(block[i, j] for i in range(4) for j in range(2))
        for x in (ends, coef, corner, *cf):
            x.setflags(write=False)
        out = (ends, coef, corner, cf)
        with self._lock:  # only the latest mapping: these arrays are as large as the fit
            self._fielded.clear()
            if block.nbytes + ends.nbytes <= FIELDED_KEEP_BYTES:  # else made again if asked
                self._fielded[key] = out
        return out

    def _fielded_chunk(self, fm: FieldMap, a: int, b1: int, b: int, block: np.ndarray,
                       ends: np.ndarray, corner: np.ndarray) -> None:
        """Segments a..b-1 of :meth:`fielded`'s arrays, from segments a..b1-1 (b1 = b + 1
        but at the end: the corner of joint b-1 needs segment b)."""
        row, is_cubic = self.row[a:b1], self.is_cubic[a:b1]
        # control points in float bits, gathered from the shared points: P0 and P3 of every
        # segment, P1 and P2 of the cubics; a line P0→P1 is the cubic with its inner control
        # points at 1/3 and 2/3 (computed in bits; used for its end tangents)
        r0 = int(row[0])
        pb = fm.to_bits_float(self.points[r0:int(row[-1]) + 4])
        row = row - r0
        p0 = pb[row]
        p3 = pb[row + np.where(is_cubic, 3, 1)]
        ic = np.flatnonzero(is_cubic)
        il = np.flatnonzero(~is_cubic)
        p1 = np.empty_like(p0)
        p2 = np.empty_like(p0)
        if len(ic):
            p1[ic] = pb[row[ic] + 1]
            p2[ic] = pb[row[ic] + 2]
        if len(il):
            c0 = p0[il]
            d = p3[il]
            d -= c0
            t = d / 3.0
            t += c0
            p1[il] = t
            np.multiply(d, 2.0, out=t)
            t /= 3.0
            t += c0
            p2[il] = t
        # power coefficients laid out (4, 2, G): each of a, b, d, e in x and y is one
        # contiguous row, so the eight flat arrays the kernels want are views, not copies;
        # a line exactly a = b = 0, d = P3 − P0, e = P0
        m = b - a
        out = block[:, :, a:b]
        out[0] = 0.0
        out[1] = 0.0
        np.subtract(p3[:m].T, p0[:m].T, out=out[2])
        out[3] = p0[:m].T
        icm = ic[ic < m]
        if len(icm):
            sub = np.empty((4, 2, len(icm)))
            power_coeffs_into(sub, p0[icm].T, p1[icm].T, p2[icm].T, p3[icm].T)
            out[:, :, icm] = sub
        ends[a:b, 0] = p0[:m]
        ends[a:b, 1] = p3[:m]
        # end tangents: the first non-zero control leg at each end
        ts = _first_nonzero(p1 - p0, (lambda z: p2[z] - p0[z], lambda z: p3[z] - p0[z]))
        te = _first_nonzero(p3 - p2, (lambda z: p3[z] - p1[z], lambda z: p3[z] - p0[z]))
        if b1 - a > 1:
            u, v = te[:-1], ts[1:]
            ang = turn_deg(u, v)
            deg = ~((u != 0).any(axis=1) & (v != 0).any(axis=1))
            sp = self.seg_path[a:b1]
            corner[a:b1 - 1] = ((ang > CORNER_DEG) | deg) & (sp[:-1] == sp[1:])

def sample_geometry(fitted: Sequence[FittedPath]) -> _Geometry:
    """Every segment of ``fitted`` gathered for the sampler (paths, kinds, control points):
    made once per fit and passed to :func:`sample_paths` again (``geometry=``) when the same
    fit is re-sampled at another magnification or tolerance (the pipeline keeps it with
    its cached fit)."""
    return _Geometry(fitted)


def sample_paths(
    fitted: Sequence[FittedPath],
    fm: FieldMap,
    *,
    interpolation: str = "adaptive",
    chord_tol_bits: float = 1.0,
    min_step_bits: float = 2.0,
    max_step_bits: float | None = None,
    fixed_step_bits: float = 16.0,
    fixed_slope_tol: float = 0.05,
    raw_points: Sequence[np.ndarray] | None = None,
    cancel: Callable[[], bool] | None = None,
    geometry: _Geometry | None = None,
    keep_chunks: bool = True,
) -> SampleResult:
    """Marks of many fitted paths at once (one stroke each, (M, 2) int64 bits, in the
    direction of the segments; empty for a path without segments), and what was measured.

    All cubics of all paths are searched together, so the cost per mark stays low however
    many paths there are. ``raw_points[i]`` are the input points of ``fitted[i]`` (needed for
    ``raw``). The steps: the marks' curve parameters (cubics by the search or paper 001's
    fixed step, lines by their ends), merged in path order; the minimum step; rounding to
    whole bits; every chord measured against the true curve; one stroke per path.
    ``keep_chunks=False``: the result without the float marks and parameters behind
    :attr:`SampleResult.float_marks` and :attr:`SampleResult.params` (32 bytes per mark
    fewer held while sampling, for callers that keep only the marks: the pipeline).
    """
    if interpolation not in ("adaptive", "fixed", "raw"):
        raise ParamError(f"interpolation must be adaptive, fixed or raw; got {interpolation!r}")
    tol = float(chord_tol_bits)
    report = SampleReport(interpolation, tol)
    res = SampleResult([], report)
    if interpolation == "raw":
        res.marks = _raw_marks(fitted, fm, raw_points, report)
        return res
    ms_max = math.inf if max_step_bits is None else float(max_step_bits)
    min_step = float(min_step_bits)
    # every segment of every path, in bits, in power form (a line's: a = b = 0)
    geo = geometry if geometry is not None else sample_geometry(fitted)
    if not len(geo.is_cubic):
        res.marks = [np.empty((0, 2), dtype=np.int64) for _ in fitted]
        return res
    ends, coef, corner, cf = geo.fielded(fm)
    res.coef = coef
    # whole paths in chunks of about CHUNK_SEGMENTS segments: each chunk's temporaries stay
    # a few MB, reused from the heap chunk after chunk instead of mapped (and zeroed by the
    # kernel) afresh at every size; the paths are independent, so are the chunks
    seg_end = np.cumsum(geo.path_n)
    cuts = [0]
    while cuts[-1] < len(fitted):
        p0 = cuts[-1]
        base = int(seg_end[p0] - geo.path_n[p0])
        cuts.append(max(p0 + 1, int(np.searchsorted(seg_end, base + CHUNK_SEGMENTS,
                                                     side="right"))))
    chords = 0
    hmax: list[float] = []
    himax: list[float] = []
    for p0, p1 in zip(cuts[:-1], cuts[1:], strict=True):
        g0 = int(seg_end[p0] - geo.path_n[p0])
        g1 = int(seg_end[p1 - 1])
        sl = slice(g0, g1)
        view = _GeoView(geo.is_cubic[sl], geo.seg_path[sl] - p0,
                        geo.path_first[p0:p1] - g0, geo.path_n[p0:p1])
        cfs = tuple(c[sl] for c in cf)
        cs = _CubicSet(coef[sl], cf=cfs)
        part = SampleReport(interpolation, tol)
        blocks = _cubic_params(cs, cfs, view, corner[sl], interpolation, tol, min_step, ms_max,
                               float(fixed_step_bits), float(fixed_slope_tol), part, cancel)
        blocks.append(_line_params(np.flatnonzero(~view.is_cubic), ends[sl], ms_max))
        mk = _merged_marks(cs, view, ends[sl], corner[sl], blocks)
        if min_step > 0.0:
            mk = _min_step_pass(mk, cs, tol, min_step, part)
        r, mk = _rounded(mk)
        part.outside_points = int(((r < 0) | (r > fm.max_bit)).any(axis=1).sum())
        _measure_into(part, mk, r, cs, view.is_cubic, tol)
        report.min_step_overrides += part.min_step_overrides
        report.trials += part.trials
        report.outside_points += part.outside_points
        report.chord_violations += part.chord_violations
        if part.chords:
            chords += part.chords
            hmax.append(part.max_chord_height_bits)  # type: ignore[arg-type]
            himax.append(part.max_chord_height_int_bits)  # type: ignore[arg-type]
        # one stroke per path
        pc = np.searchsorted(mk.pid, np.arange(p1 - p0 + 1))
        pc[-1] = len(mk.pid)
        res.marks += _split_rows(r, pc)
        if keep_chunks:
            res.chunks.append((mk.pos, mk.sid, mk.st, g0, pc))
    report.chords = chords
    report.max_chord_height_bits = max(hmax, default=0.0)
    report.max_chord_height_int_bits = max(himax, default=0.0)
    return res


#: a run of at least this many strokes of the same number of marks is split by a reshape
_SAME_RUN = 16


def _split_rows(r: np.ndarray, pc: np.ndarray) -> list[np.ndarray]:
    """``[r[pc[i]:pc[i + 1]] for i]`` (views): a run of many strokes of the same length is
    one reshape whose rows numpy hands out itself (files of 10^4–10^5 two-mark strokes),
    the rest slices made by ``map`` (no Python loop per stroke)."""
    ln = np.diff(pc)
    if not len(ln):
        return []
    # runs of equal length: start of each, and the long ones
    br = np.flatnonzero(np.r_[True, ln[1:] != ln[:-1], True])
    long_ = np.flatnonzero((np.diff(br) >= _SAME_RUN) & (ln[br[:-1]] > 0))
    pl = pc.tolist()
    out: list[np.ndarray] = []
    at = 0  # next stroke to hand out
    for s, e in zip(br[long_].tolist(), br[long_ + 1].tolist(), strict=True):
        if at < s:
            out += map(r.__getitem__, map(slice, pl[at:s], pl[at + 1:s + 1]))
        out.extend(r[pl[s]:pl[e]].reshape(e - s, pl[s + 1] - pl[s], r.shape[1]))
        at = e
    m = len(ln)
    if at < m:
        out += map(r.__getitem__, map(slice, pl[at:m], pl[at + 1:m + 1]))
    return out


@dataclass
class _GeoView:
    """The part of a :class:`_Geometry` that a chunk of whole paths needs (its segments
    and paths numbered from 0)."""

    is_cubic: np.ndarray
    seg_path: np.ndarray
    path_first: np.ndarray
    path_n: np.ndarray


def _raw_marks(fitted: Sequence[FittedPath], fm: FieldMap,
               raw_points: Sequence[np.ndarray] | None, report: SampleReport
               ) -> list[np.ndarray]:
    """``raw``: the input points themselves, rounded, consecutive repeats dropped."""
    out = []
    for i, _fp in enumerate(fitted):
        pts = raw_points[i] if raw_points is not None else np.empty((0, 2))
        m = _dedup(fm.to_bits(np.asarray(pts, dtype=np.float64).reshape(-1, 2)))
        out.append(m)
        report.outside_points += (int(((m < 0) | (m > fm.max_bit)).any(axis=1).sum())
                                  if len(m) else 0)
    return out


@dataclass
class _ParamBlock:
    """Marks as (segment id, t) with t in (0, 1], and, where the search measured it, the
    chord ending at each mark (height ``h`` and its start parameter ``a``; NaN: unknown)."""

    ids: np.ndarray
    ts: np.ndarray
    h: np.ndarray | None = None
    a: np.ndarray | None = None


def _cubic_params(cs: _CubicSet, cf: CF, geo: _Geometry | _GeoView, corner: np.ndarray,
                  interpolation: str, tol: float, min_step: float, ms_max: float,
                  fixed_step: float, fixed_slope_tol: float, report: SampleReport,
                  cancel: Callable[[], bool] | None) -> list[_ParamBlock]:
    """The marks on the cubics: the adaptive search (paper 000 §4, 004) over chains of
    cubics that meet smoothly (no mark forced at their joints, no partial chord left at the
    end of each cubic), or paper 001's fixed step cubic by cubic."""
    cub = np.flatnonzero(geo.is_cubic)
    if not len(cub):
        return []
    if interpolation != "adaptive":
        return [_ParamBlock(np.full(len(tf), g), tf) for g in cub.tolist()
                for tf in (_fixed_params(cs, g, fixed_step, fixed_slope_tol),)]
    first, n = _smooth_chains(cf, geo.is_cubic, corner, geo.seg_path, tol)
    chains = _ChainSet(cs, first, n)
    ck = np.arange(len(first))
    s0 = np.zeros(len(first))
    kk, ss, oo, trials, hh, aa = _search_h(
        chains, ck, s0, n.astype(np.float64), e_min=E_MIN_RATIO * tol, e_max=tol,
        min_step=min_step, max_step=ms_max, cancel=cancel)
    _fix_short_ends(chains, ck, s0, kk, ss, e_max=tol, min_step=min_step, h=hh, a=aa)
    report.min_step_overrides = int(oo.sum())
    report.trials = trials
    gid, tt = chains.locate(kk, ss, ending=True)
    # the search's measurement is reused for chords within one cubic only
    aa = aa - (gid - first[kk])
    within = aa >= 0.0  # NaN compares False
    return [_ParamBlock(gid, tt, np.where(within, hh, np.nan), np.where(within, aa, np.nan))]


def _line_params(lines: np.ndarray, ends: np.ndarray, ms_max: float) -> _ParamBlock:
    """The marks on the lines: their ends, and steps of at most ``ms_max`` between."""
    if not math.isfinite(ms_max) or not len(lines):
        return _ParamBlock(lines, np.ones(len(lines)))
    ln = np.hypot(*(ends[lines, 1] - ends[lines, 0]).T)
    nseg = np.maximum(1, np.ceil(ln / ms_max - 1e-9)).astype(np.int64)
    start = np.cumsum(nseg) - nseg
    idx = np.arange(int(nseg.sum())) - np.repeat(start, nseg) + 1
    return _ParamBlock(np.repeat(lines, nseg), idx / np.repeat(nseg, nseg))


@dataclass
class _MarkRows:
    """Every mark of every path in path order: segment id, parameter, float position
    (bits), path, the search's chord height and start (NaN: unknown), first/last of a
    stroke, protected (stroke ends and corner joints: never merged)."""

    sid: np.ndarray
    st: np.ndarray
    pos: np.ndarray
    pid: np.ndarray
    hm: np.ndarray
    am: np.ndarray
    first_of: np.ndarray
    last_of: np.ndarray
    prot: np.ndarray

    def keep(self, keep: np.ndarray) -> _MarkRows:
        idx = np.flatnonzero(keep)  # once, not once per column
        return _MarkRows(*(getattr(self, f.name)[idx] for f in fields(self)))


def _merged_marks(cs: _CubicSet, geo: _Geometry | _GeoView, ends: np.ndarray, corner: np.ndarray,
                  blocks: list[_ParamBlock]) -> _MarkRows:
    """The blocks and the start mark of every non-empty path (first segment, t = 0; every
    other mark has t > 0), in path order, with their positions."""
    firsts = geo.path_first[geo.path_n > 0]
    sid = np.concatenate([firsts] + [b.ids for b in blocks]).astype(np.int64)
    st = np.concatenate([np.zeros(len(firsts))] + [b.ts for b in blocks])
    hm = np.concatenate([np.full(len(firsts), np.nan)] + [
        b.h if b.h is not None else np.full(len(b.ids), np.nan) for b in blocks])
    am = np.concatenate([np.full(len(firsts), np.nan)] + [
        b.a if b.a is not None else np.full(len(b.ids), np.nan) for b in blocks])
    # each block is sorted by (segment, t) and starts come first: a stable sort by segment
    # merges the runs (timsort, about linear here)
    order = np.argsort(sid, kind="stable")
    sid, st, hm, am = sid[order], st[order], hm[order], am[order]
    pos = cs.point(sid, st)
    at1 = st >= 1.0
    pos[at1] = ends[sid[at1], 1]  # segment ends exactly (continuity)
    at0 = st <= 0.0
    pos[at0] = ends[sid[at0], 0]
    pid = geo.seg_path[sid]
    first_of = np.r_[True, pid[1:] != pid[:-1]]
    last_of = np.r_[pid[1:] != pid[:-1], True]
    prot = first_of | last_of | (at1 & corner[sid])
    return _MarkRows(sid, st, pos, pid, hm, am, first_of, last_of, prot)


def _min_step_pass(mk: _MarkRows, cs: _CubicSet, tol: float, min_step: float,
                   report: SampleReport) -> _MarkRows:
    """Marks closer than ``min_step`` merged (rarely needed after the search), every stroke
    at once; a merge that would leave a chord above the tolerance is refused (counted)."""
    if len(mk.pid) <= 2:
        return mk
    pos = mk.pos
    dd = np.hypot(pos[1:, 0] - pos[:-1, 0], pos[1:, 1] - pos[:-1, 1])
    short = (dd < min_step) & ~mk.last_of[:-1]
    if not short.any():
        return mk
    sid, st, pid = mk.sid, mk.st, mk.pid
    # the filter asks, around the short chords q -> q + 1, whether a chord that would
    # replace a few marks holds (q -> q + 2 mostly, q -> q + 3 after a drop, q - 1 -> q + 1,
    # q - 1 -> q + 2 when the mark before is dropped instead): measured here for all of them
    # at once (a chord's height does not depend on the others measured with it), any other
    # question one by one
    n = len(pid)
    q = np.flatnonzero(short)
    # step (2 or 3) -> per mark a: -1 not measured, else whether a -> a + step holds
    known: dict[int, np.ndarray] = {}
    # q and q - 1, sorted, each once (a mask: np.unique sorts and hashes)
    qm = np.zeros(n, dtype=bool)
    qm[q] = True
    qm[q[q > 0] - 1] = True
    qq = np.flatnonzero(qm)
    for step in (2, 3):
        a = qq[qq + step < n]
        a = a[pid[a] == pid[a + step]]
        res = np.full(n, -1, dtype=np.int8)
        for c in range(0, len(a), 1 << 16):  # in pieces: the height temporaries stay small
            ac = a[c:c + (1 << 16)]
            bc = ac + step
            hq = _chords_heights(cs, sid[ac], st[ac], sid[bc], st[bc], pos[ac], pos[bc])
            res[ac] = hq <= tol
        known[step] = res

    def merge_ok(a: int, b: int) -> bool:
        """The chord from mark a to mark b keeps within the tolerance."""
        res = known.get(b - a)
        if res is not None and res[a] >= 0:
            return bool(res[a])
        h = _chords_heights(cs, sid[[a]], st[[a]], sid[[b]], st[[b]], pos[[a]], pos[[b]])
        return bool(h[0] <= tol)

    keep, nforced = _min_step_keep(pos, mk.prot, mk.first_of, dd, min_step, known[2],
                                   known[3], merge_ok)
    report.min_step_overrides += nforced
    return mk.keep(keep)


def _min_step_keep(pos: np.ndarray, prot: np.ndarray, first: np.ndarray, dd: np.ndarray,
                   min_step: float, ok2: np.ndarray, ok3: np.ndarray,
                   merge_ok: Callable[[int, int], bool]) -> tuple[np.ndarray, int]:
    """:func:`_min_step_filter` over many strokes (``first``: each one's first mark) as a
    mask of the marks kept, and the number of forced marks: the walk compiled over every
    stroke at once (``ok2``/``ok3``: the answers of ``merge_ok`` measured beforehand, -1
    where not); a stroke that asks another question, or meets a distance within rounding
    of ``min_step`` (math.hypot and the compiled hypot may differ in the last bit), is left
    to the Python walk, stroke by stroke: the result is the Python walk's."""
    n = len(pos)
    kept, nforced, redo = _min_step_walk(
        np.ascontiguousarray(pos[:, 0]), np.ascontiguousarray(pos[:, 1]),
        (dd < min_step) & ~first[1:], prot, first, min_step, ok2, ok3)
    keep = np.zeros(n, dtype=bool)
    keep[kept] = True
    nforced = int(nforced)
    if len(redo):
        starts = np.flatnonzero(first)
        nxt = np.r_[starts[1:], n]
        for s0 in redo.tolist():
            e0 = int(nxt[np.searchsorted(starts, s0)])
            forced: list[int] = []

            def shifted_ok(a: int, b: int, s0: int = s0) -> bool:
                return merge_ok(a + s0, b + s0)

            sub = _min_step_filter(pos[s0:e0], prot[s0:e0], min_step, first=first[s0:e0],
                                   d=dd[s0:e0 - 1], merge_ok=shifted_ok, forced=forced)
            keep[sub + s0] = True
            nforced += len(forced)
    return keep, nforced


@njit(cache=True, nogil=True)
def _known(ok2: np.ndarray, ok3: np.ndarray, a: int, b: int) -> int:
    """Whether chord a -> b holds as measured beforehand: 1 / 0, -1 not measured."""
    if a < 0 or a >= len(ok2):
        return -1
    if b - a == 2:
        return ok2[a]
    if b - a == 3:
        return ok3[a]
    return -1


@njit(cache=True, nogil=True)
def _min_step_walk(x: np.ndarray, y: np.ndarray, sh: np.ndarray, pr: np.ndarray,
                   fs: np.ndarray, min_step: float, ok2: np.ndarray, ok3: np.ndarray
                   ) -> tuple[np.ndarray, int, np.ndarray]:
    """:func:`_min_step_filter` with ``first`` and ``merge_ok`` compiled, every stroke in
    one pass (mark 0 starts a stroke). ``sh``: the short chords; ``ok2``/``ok3``: per mark
    a, whether chord a -> a + 2 / a + 3 holds (-1: not measured). Returns (kept marks,
    number of forced marks, first marks of the strokes not done: a question not measured,
    or a distance within 1e-9 of ``min_step``, where the Python walk's math.hypot may
    differ from this one in the last bit)."""
    n = len(x)
    keep = np.empty(n, dtype=np.int64)
    redo = np.empty(n, dtype=np.int64)
    nr = 0
    keep[0] = 0
    nk = 1
    nf = 0
    s_keep = 0
    s_forced = 0
    s_first = 0
    near = 1e-9 * min_step
    i = 1
    while i < n:
        if fs[i]:  # a stroke's first mark
            s_keep = nk
            s_forced = nf
            s_first = i
            keep[nk] = i
            nk += 1
            i += 1
            continue
        if keep[nk - 1] == i - 1 and not sh[i - 1]:
            keep[nk] = i
            nk += 1
            i += 1
            continue
        bad = False
        j = keep[nk - 1]
        dj = math.hypot(x[i] - x[j], y[i] - y[j])
        if abs(dj - min_step) <= near:
            bad = True
        elif dj >= min_step:
            keep[nk] = i
            nk += 1
        elif pr[i]:
            popped = False
            while nk > 1 and not pr[keep[nk - 1]]:
                m = keep[nk - 1]
                dm = math.hypot(x[i] - x[m], y[i] - y[m])
                if abs(dm - min_step) <= near:
                    bad = True
                    break
                if dm >= min_step:
                    break
                nk -= 1
                popped = True
            if not bad:
                if popped:
                    v = _known(ok2, ok3, keep[nk - 1], i)
                    if v < 0:
                        bad = True
                    elif v == 0:
                        nf += 1
                if not bad:
                    keep[nk] = i
                    nk += 1
        else:
            v = _known(ok2, ok3, j, i + 1)
            if v < 0:
                bad = True
            elif v == 0:
                k = keep[nk - 2] if nk > 1 else -1
                alt = False
                if k >= 0 and not pr[j] and not fs[j]:
                    dk = math.hypot(x[i] - x[k], y[i] - y[k])
                    if abs(dk - min_step) <= near:
                        bad = True
                    elif dk >= min_step:
                        v2 = _known(ok2, ok3, k, i)
                        if v2 < 0:
                            bad = True
                        else:
                            alt = v2 == 1
                if not bad:
                    if alt:
                        keep[nk - 1] = i
                    else:
                        nf += 1
        if bad:  # this stroke is left to the caller: undo it, go to the next stroke
            nk = s_keep
            nf = s_forced
            redo[nr] = s_first
            nr += 1
            i = s_first + 1
            while i < n and not fs[i]:
                i += 1
            continue
        i += 1
    return keep[:nk], nf, redo[:nr]


def _rounded(mk: _MarkRows) -> tuple[np.ndarray, _MarkRows]:
    """Marks rounded to whole bits, consecutive repeats dropped (a stroke's true end is
    kept: its twin before it goes instead, unless that twin is the start)."""
    r = _round(mk.pos)
    first_of, last_of = mk.first_of, mk.last_of
    same = np.r_[False, (r[1:, 0] == r[:-1, 0]) & (r[1:, 1] == r[:-1, 1]) & ~first_of[1:]]
    if not same.any():
        return r, mk
    drop = same.copy()
    e = np.flatnonzero(same & last_of)
    if len(e):
        # j: the twin's run start, the last mark before e that repeats nothing (a stroke's
        # first never does: j stays in e's stroke, so the strokes do not interact)
        idx = np.arange(len(same))
        j = np.maximum.accumulate(np.where(same, 0, idx))[e - 1]
        move = ~first_of[j]
        drop[e[move]] = False
        drop[j[move]] = True
    keep = ~drop
    out = mk.keep(keep)
    out.last_of = out.last_of | np.r_[out.pid[1:] != out.pid[:-1], True]
    return r[keep], out


def _measure_into(report: SampleReport, mk: _MarkRows, r: np.ndarray, cs: _CubicSet,
                  is_cubic: np.ndarray, tol: float) -> None:
    """Every chord between consecutive marks of a stroke measured against the true curve
    (float and rounded marks), into ``report``."""
    pair = ~mk.last_of[:-1] if len(mk.pid) > 1 else np.zeros(0, dtype=bool)
    if not pair.any():
        report.max_chord_height_bits = 0.0
        report.max_chord_height_int_bits = 0.0
        return
    hf, hi_max = _measure_marks(cs, mk.sid, mk.st, mk.pos, r, mk.hm, mk.am, pair, is_cubic)
    report.chords = int(np.count_nonzero(pair))
    report.max_chord_height_bits = float(hf.max())
    report.max_chord_height_int_bits = hi_max
    report.chord_violations = int(np.count_nonzero(hf > tol * (1.0 + 1e-9)))


def _first_nonzero(first: np.ndarray,
                   alternatives: tuple[Callable[[np.ndarray], np.ndarray], ...]) -> np.ndarray:
    """Rows of ``first`` (N, 2), a row that is (0, 0) replaced by the next alternative's
    row there (each alternative a function of the row indices, evaluated only on them)."""
    out = first
    for alt in alternatives:
        zero = np.flatnonzero((out[:, 0] == 0) & (out[:, 1] == 0))
        if len(zero):
            out[zero] = alt(zero)
    return out


def _measure_marks(cs: _CubicSet, sid: np.ndarray, st: np.ndarray, pos: np.ndarray,
                   r: np.ndarray, hm: np.ndarray, am: np.ndarray, pair: np.ndarray,
                   is_cubic: np.ndarray) -> tuple[np.ndarray, float]:
    """Chord heights of the chords between consecutive marks against the true curve.

    Marks: (segment ``sid``, parameter ``st``), float position ``pos``, rounded ``r``; the
    chord from mark i to i + 1 counts where ``pair[i]`` (not across strokes). ``hm[i]``,
    ``am[i]``: a height the step search already measured, by the same closed form, for the
    chord (sid[i], am[i]) → (sid[i], st[i]) (NaN: none); it is taken where the chord is
    exactly that one (same segment, same start parameter), so the result is what measuring
    again would give. A chord on one line segment (``is_cubic`` False) has height 0: the
    closed form gives exactly 0 there too (q2 = q3 = 0). Returns the float chords' heights
    (those of ``pair``) and the largest height of the integer chords (exact, see
    :func:`_max_int_heights`).

    Works on views of the per-mark arrays (chord i: marks i, i + 1) and gathers only the
    chords that still need a measurement."""
    sa, ta, sb, tb = sid[:-1], st[:-1], sid[1:], st[1:]
    # a chord starting at a segment's end starts at the next segment's start
    mv = (ta >= 1.0) & (sb > sa)
    if mv.any():
        sa = sa + mv
        ta = np.where(mv, 0.0, ta)
    simple = sb == sa
    known = pair & simple & (ta == am[1:])  # NaN never compares equal
    hf = np.where(known, hm[1:], 0.0)
    todo = np.flatnonzero(pair & simple & ~known & is_cubic[sa])
    if len(todo):  # within one segment (float ends on the curve): the closed form, exact
        hf[todo], _ = chord_heights(cs.gather(sa[todo]), ta[todo], tb[todo])
    multi = np.flatnonzero(pair & ~simple)
    if len(multi):  # across joints: piece by piece against the float chord
        npieces = sb[multi] - sa[multi] + 1
        chord = np.repeat(multi, npieces)
        start = np.cumsum(npieces) - npieces
        off = np.arange(len(chord)) - np.repeat(start, npieces)
        seg = sa[chord] + off
        t_lo = np.where(off == 0, ta[chord], 0.0)
        t_hi = np.where(seg == sb[chord], tb[chord], 1.0)
        h = segment_heights(cs.gather(seg), t_lo, t_hi, pos[chord], pos[chord + 1])
        np.maximum.at(hf, chord, h)
    # how far rounding moved each mark: every point of an integer chord is within the
    # larger of its two ends' moves of the float chord
    rf = r.astype(np.float64)
    dr = np.hypot(rf[:, 0] - pos[:, 0], rf[:, 1] - pos[:, 1])
    bound = hf + np.maximum(dr[:-1], dr[1:])
    bound[~pair] = -np.inf
    hi_max = _max_int_heights(cs, bound, sa, ta, sb, tb, rf, int(np.count_nonzero(pair)))
    return hf[pair], hi_max


def _chords_heights(cs: _CubicSet, sa: np.ndarray, ta: np.ndarray, sb: np.ndarray,
                    tb: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Heights of the chords A → B between curve points (segment ``sa``, ``ta``) and
    (``sb``, ``tb``) with ``sb`` >= ``sa``: the closed form within one segment (exact, A and
    B on the curve), piece by piece across joints."""
    mv = (ta >= 1.0) & (sb > sa)  # a chord from a segment's end starts on the next one
    sa = sa + mv
    ta = np.where(mv, 0.0, ta)
    out = np.zeros(len(sa))
    one = sa == sb
    if one.any():
        i = np.flatnonzero(one)
        out[i], _ = chord_heights(cs.gather(sa[i]), ta[i], tb[i])
    if not one.all():
        i = np.flatnonzero(~one)
        out[i] = _span_heights(cs, sa[i], ta[i], sb[i], tb[i], A[i], B[i])
    return out


def _max_int_heights(cs: _CubicSet, bound: np.ndarray, sa: np.ndarray, ta: np.ndarray,
                     sb: np.ndarray, tb: np.ndarray, rf: np.ndarray, n: int) -> float:
    """The largest chord height of the integer chords i → i + 1 (marks ``rf``), exact.

    ``bound[i]``: an upper bound of chord i's height (hf + the larger move of its ends by
    rounding; -inf for chords that do not count, ``n`` chords count). The chords of largest
    bound are measured exactly, a batch at a time (1024, then four times more each round),
    among those whose bound still exceeds the largest exact height found, until none does:
    the maximum is then exact, and only the few chords that can hold it are measured (a
    single batch of every chord above the first chord's height measured most chords of
    the many-path files)."""
    out = bound.copy()
    best = -1.0
    batch = 1024
    while True:
        idx = np.flatnonzero(out > best)
        if not len(idx):
            return best
        if len(idx) > batch:
            idx = idx[np.argpartition(out[idx], len(idx) - batch)[len(idx) - batch:]]
        ex = _int_heights_exact(cs, sa[idx], ta[idx], sb[idx], tb[idx], rf[idx], rf[idx + 1])
        out[idx] = -np.inf  # done
        best = max(best, float(ex.max()))
        batch *= 4


def _int_heights_exact(cs: _CubicSet, sa: np.ndarray, ta: np.ndarray, sb: np.ndarray,
                       tb: np.ndarray, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    npieces = sb - sa + 1
    chord = np.repeat(np.arange(len(sa)), npieces)
    start = np.cumsum(npieces) - npieces
    off = np.arange(len(chord)) - np.repeat(start, npieces)
    seg = np.repeat(sa, npieces) + off
    t_lo = np.where(off == 0, np.repeat(ta, npieces), 0.0)
    t_hi = np.where(seg == np.repeat(sb, npieces), np.repeat(tb, npieces), 1.0)
    h = segment_heights(cs.gather(seg), t_lo, t_hi, ia[chord], ib[chord])
    out = np.zeros(len(sa))
    np.maximum.at(out, chord, h)
    return out


def sample_path(
    fp: FittedPath,
    fm: FieldMap,
    *,
    interpolation: str = "adaptive",
    chord_tol_bits: float = 1.0,
    min_step_bits: float = 2.0,
    max_step_bits: float | None = None,
    fixed_step_bits: float = 16.0,
    fixed_slope_tol: float = 0.05,
    raw_points: np.ndarray | None = None,
) -> np.ndarray:
    """Marks of one stroke, (M, 2) int64 galvo bits (see :func:`sample_paths`)."""
    res = sample_paths([fp], fm, interpolation=interpolation, chord_tol_bits=chord_tol_bits,
                       min_step_bits=min_step_bits, max_step_bits=max_step_bits,
                       fixed_step_bits=fixed_step_bits, fixed_slope_tol=fixed_slope_tol,
                       raw_points=None if raw_points is None else [raw_points])
    return res.marks[0]


def polyline_marks(points: np.ndarray, fm: FieldMap, *, min_step_bits: float,
                   corner_deg: float = 15.0) -> np.ndarray:
    """Marks of a polyline laser path (e.g. a hatch stroke, input units) as int64 bits:
    rounded, consecutive repeats dropped, and marks closer than ``min_step_bits`` to the
    previous one merged, except the ends and corners (turn above ``corner_deg``)."""
    pts = fm.to_bits_float(np.asarray(points, dtype=np.float64).reshape(-1, 2))
    n = len(pts)
    prot = np.zeros(n, dtype=bool)
    if n:
        prot[0] = prot[-1] = True
    if n >= 3:
        a = pts[1:-1] - pts[:-2]
        b = pts[2:] - pts[1:-1]
        prot[1:-1] = turn_deg(a, b) > corner_deg
    keep = _min_step_filter(pts, prot, min_step_bits)
    return _dedup(_round(pts[keep]))
