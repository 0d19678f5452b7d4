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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Piece", "smooth_vertices", "find_runs", "point_tangents", "split_pieces"]


@dataclass(frozen=True, slots=True)
class Piece:
    """A stretch of thinned points, ``a``..``b`` inclusive: ``kind`` "line" (b == a + 1) or
    "curve" (a candidate for one cubic, b >= a + 2)."""

    kind: str
    a: int
    b: int


def _segments(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    s = np.diff(q, axis=0)
    return s, np.hypot(s[:, 0], s[:, 1])


def smooth_vertices(
    q: np.ndarray, *, cos_join: float = 0.95, length_ratio: float = 3.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per point k: (smooth (M,) bool, turn angle (M,) radians signed, cross sign (M,)).

    End points (k = 0, M-1) are not smooth here (see :func:`point_tangents` for the seam).
    """
    m = len(q)
    smooth = np.zeros(m, dtype=bool)
    turn = np.zeros(m)
    sign = np.zeros(m)
    if m < 3:
        return smooth, turn, sign
    s, ln = _segments(q)
    a, b = s[:-1], s[1:]
    la, lb = ln[:-1], ln[1:]
    dot = (a * b).sum(axis=1)
    cr = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = dot / (la * lb)
    ratio_ok = (lb <= length_ratio * la) & (la <= length_ratio * lb)
    # the greedy thinning leaves a short last segment (the tail of the path): it is not a
    # long thinned line, so the length rule does not cut it off
    ratio_ok[-1] |= lb[-1] < la[-1]
    ok = (cos > cos_join) & ratio_ok
    smooth[1:-1] = ok
    turn[1:-1] = np.arctan2(cr, dot)
    # a turn below ~1e-12 rad is numerically straight: no sign
    sign[1:-1] = np.where(np.abs(cr) > 1e-12 * la * lb, np.sign(cr), 0.0)
    return smooth, turn, sign


def find_runs(
    q: np.ndarray, *, cos_join: float = 0.95, length_ratio: float = 3.0
) -> list[tuple[int, int]]:
    """Curve runs as inclusive point ranges (a, b) with b - a >= 3 (at least 4 points)."""
    m = len(q)
    if m < 4:
        return []
    smooth, _, sign = smooth_vertices(q, cos_join=cos_join, length_ratio=length_ratio)
    runs: list[tuple[int, int]] = []
    start = 0
    run_sign = 0.0
    sm = smooth.tolist()
    sg = sign.tolist()
    for k in range(1, m - 1):
        joins = sm[k] and not (run_sign * sg[k] < 0.0)
        if joins:
            if run_sign == 0.0:
                run_sign = sg[k]
            continue
        if k - start >= 3:
            runs.append((start, k))
        start = k
        # an inflection starts the new run with the new turn's sign already known
        run_sign = sg[k] if sm[k] else 0.0
    if m - 1 - start >= 3:
        runs.append((start, m - 1))
    return runs


def _bessel(q0: np.ndarray, q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Unit tangent at q1 of the parabola through three points (chord-length weights)."""
    d0 = q1 - q0
    d1 = q2 - q1
    h0 = np.hypot(d0[..., 0], d0[..., 1])[..., None]
    h1 = np.hypot(d1[..., 0], d1[..., 1])[..., None]
    t = (h1 / (h0 + h1)) * d0 / h0 + (h0 / (h0 + h1)) * d1 / h1
    return t / np.hypot(t[..., 0], t[..., 1])[..., None]


def _rot_reflect(u: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Direction at angle 2·angle(u) − angle(c): the parabola's end tangent."""
    au = np.arctan2(u[..., 1], u[..., 0])
    ac = np.arctan2(c[..., 1], c[..., 0])
    ang = 2.0 * au - ac
    return np.stack([np.cos(ang), np.sin(ang)], axis=-1)


def point_tangents(
    q: np.ndarray, *, closed: bool = False, cos_join: float = 0.95, length_ratio: float = 3.0
) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangents ``(t_in, t_out)``, each (M, 2), following the path direction."""
    m = len(q)
    s, ln = _segments(q)
    u = s / ln[:, None]
    t_in = np.zeros((m, 2))
    t_out = np.zeros((m, 2))
    t_out[:-1] = u
    t_in[1:] = u
    if m < 3:
        return t_in, t_out
    smooth, _, _ = smooth_vertices(q, cos_join=cos_join, length_ratio=length_ratio)
    central = np.zeros((m, 2))
    central[1:-1] = _bessel(q[:-2], q[1:-1], q[2:])
    # one-sided parabola estimates (need a second point on that side)
    fwd = _rot_reflect(u[:-1], central[1:-1])  # start at k uses q[k], q[k+1], q[k+2]
    bwd = _rot_reflect(u[1:], central[1:-1])  # end at k uses q[k-2], q[k-1], q[k]
    t_out[:-2] = fwd
    t_in[2:] = bwd
    t_out[smooth] = central[smooth]
    t_in[smooth] = central[smooth]
    if closed and m >= 4 and np.array_equal(q[0], q[-1]):
        a, b = s[-1], s[0]
        la, lb = ln[-1], ln[0]
        cos = float(a @ b) / (la * lb)
        if cos > cos_join and lb <= length_ratio * la and la <= length_ratio * lb:
            c = _bessel(q[-2], q[0], q[1])
            t_out[0] = c
            t_in[-1] = c
    return t_in, t_out


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
    m = len(q)
    if m < 2:
        return [], np.zeros((m, 2)), np.zeros((m, 2))
    t_in, t_out = point_tangents(q, closed=closed, cos_join=cos_join, length_ratio=length_ratio)
    runs = find_runs(q, cos_join=cos_join, length_ratio=length_ratio)
    limit = math.radians(max_turn_deg)
    pieces: list[Piece] = []
    pos = 0

    def lines(a: int, b: int) -> None:
        pieces.extend(Piece("line", k, k + 1) for k in range(a, b))

    for a, b in runs:
        lines(pos, a)
        # cumulative tangent angle along the run: out-tangent at a, central inside, in at b
        tang = np.concatenate([t_out[a : a + 1], t_in[a + 1 : b + 1]])
        ang = np.unwrap(np.arctan2(tang[:, 1], tang[:, 0]))
        # interior points have t_in == t_out except at the ends, which is what we want
        total = abs(ang[-1] - ang[0])
        n = max(1, math.ceil(total / limit * (1.0 + 1e-9)))
        cuts = [a]
        if n > 1:
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
        for c0, c1 in zip(cuts[:-1], cuts[1:], strict=True):
            if c1 - c0 >= 2:
                pieces.append(Piece("curve", c0, c1))
            else:
                lines(c0, c1)
        pos = b
    lines(pos, m - 1)
    return pieces, t_in, t_out
