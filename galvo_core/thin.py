"""Line thinning with tolerance ``eps_line`` (paper 000 §2.1, the greedy "sleeve").

The paper walks the points, growing a line P1→P2 while every point between stays within
ε_line of it, and starts a new line at the last good end when the bound breaks. Here:

* Duplicate points are dropped first (consecutive repeats; the first of each repeat is the
  one kept).
* Distances are to the *segment* [P1, P2], not to the infinite line (the paper's formula (2)
  uses the line and also drops the constant C, a typo): a point beyond an end of the segment
  must be within ε_line of that end, so a kept line never hides a point that doubles back.
* "Reach as far as possible": from each kept point the next kept point is the *farthest*
  j for which every point strictly between lies within ε_line of [P_i, P_j]. The search is
  the sleeve (cone intersection) of Zhao & Saalfeld done with numpy on a chunk of points at a
  time: a ray from P_i passes within ε of a point at distance r > ε and direction θ exactly
  when its direction lies in [θ − asin(ε/r), θ + asin(ε/r)]; the running intersection of
  these wedges (cumulative max / min) tells for every candidate end at once whether the ray
  towards it serves all points before it. Candidates are then confirmed with the exact
  point-to-segment distance.

Speed (numpy only; the cost of a numpy call, not of the arithmetic, is what counts): short
reaches (sparse points) come from one sweep over every start of every path at once; long
reaches (dense curves) are searched only from the points the greedy chain stands on, but for
many chains in lockstep (one batched search per round), with seed walkers along long dense
stretches: greedy chains from different points meet after a few lines on most curves, so the
true chain finds most reaches already known. Seeds and batching change only how fast the
chain is found, never which points it keeps. Paths likely to need the DP below (short, few
sampled starts with reaches over 8 points, or mid-sized with most samples closing within
24) are instead swept whole to the DP window: the DP needs that table anyway, and it holds
every reach of at most 24 points. The sweep's last steps, once few starts are left (or not
many, past the first 8 steps, on a dense stretch where starts no longer stop), run as one
2-D block (same arithmetic per cell). (The walk's wedge test is
strict, the sweep's has a 1e-9 rad slack before the exact check; where that slack mattered
for a start, its reach is still found by the walk, so the result is the same either way.)

Near-optimal count: where the greedy leaves fewer than 16 points per kept line (integer
coordinates, sparse points), the greedy is not within 2 % of the optimum (up to 20 % over on
glyph outlines); there the kept points are a shortest path (Imai–Iri) over every exactly
verified shortcut of at most 24 steps plus the greedy shortcuts, so never worse than greedy.
It is solved piecewise (a point no shortcut passes over splits a path) by a breadth-first
search over all pieces at once (levels as Python integer bit sets: one shift/and/or per
shortcut length a level), or edge by edge in Python for pieces with many kept points; a
piece the greedy crosses with one line keeps that line.

Guarantee (tested): every dropped point lies within ``eps_line`` (input units) of the kept
segment that replaces it, and the first and last points are always kept.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence

import numpy as np

from galvo_core.errors import ParamError

__all__ = ["thin", "thin_many", "dedup_indices", "check_positive"]


def check_positive(name: str, value: object) -> float:
    """``value`` as a float if it is a finite number > 0, else :class:`ParamError`."""
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParamError(f"{name} must be a positive number (input units), got {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise ParamError(f"{name} must be a positive finite number (input units), got {value!r}")
    return v


def dedup_indices(points: np.ndarray) -> np.ndarray:
    """Indices of the points that differ from their predecessor (index 0 always kept)."""
    if len(points) == 0:
        return np.zeros(0, dtype=np.intp)
    diff = np.any(points[1:] != points[:-1], axis=1)
    return np.concatenate(([0], np.flatnonzero(diff) + 1)).astype(np.intp)


#: reach of the all-starts sweep before a start counts as "long" (numpy greedy from there)
_SWEEP = 8
#: stride of the sampled starts that find the dense stretches (see :func:`thin_many`)
_SAMPLE = 16
#: a path with at most this fraction of its sampled starts open after _SWEEP points, or
#: at most _WHOLE_LEN points, is swept whole to _DP_WINDOW points (see :func:`_thin_concat`)
_WHOLE_OPEN = 0.9
_WHOLE_LEN = 1024
#: ... or (paths of at most _MID_LEN points) at most this fraction open after _DP_WINDOW
_WHOLE_OPEN24 = 0.5
_MID_LEN = 16384
_SUB24 = 4
#: below this many points per kept line the greedy result is improved by the window DP
_DP_RATIO = 16
_DP_WINDOW = 24
#: at most this many starts left, or (past _SWEEP) at most _FEW_DENSE while at least the
#: fraction _SURVIVE of them survived the last step: the sweep's remaining steps are done as
#: one 2-D block
_FEW = 256
_FEW_DENSE = 512
_SURVIVE = 0.9
#: slack of the wedge prefilter (radians): a candidate this close outside is checked exactly
_LOOSE = 1e-9
#: margin inside the wedge for the "sure" shortcut (no exact check)
_TINY = 1e-12
#: candidates checked at once per start when the farthest one is not accepted outright
_TOP = 4


class _Sleeve:
    """Sweep state of the starts whose wedge is still open after ``d`` steps: rows ``row``
    of the table, starts ``s``, their path ends ``lim``, wedge ``lo``..``hi`` (radians,
    relative to the first point farther than eps, direction ``rx``, ``ry``, once ``has``),
    farthest distance ``rmax`` so far."""

    __slots__ = ("d", "row", "s", "lim", "xs", "ys", "lo", "hi", "rmax", "rx", "ry", "has")
    d: int
    row: np.ndarray
    s: np.ndarray
    lim: np.ndarray
    xs: np.ndarray
    ys: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    rmax: np.ndarray
    rx: np.ndarray
    ry: np.ndarray
    has: np.ndarray

    def take(self, keep: np.ndarray) -> None:
        """Keep only the starts ``keep`` (mask)."""
        for f in ("row", "s", "lim", "xs", "ys", "lo", "hi", "rmax", "rx", "ry", "has"):
            setattr(self, f, getattr(self, f)[keep])

    def split(self, mask: np.ndarray) -> _Sleeve:
        """The starts ``mask`` as a new state (same step); this one keeps the others."""
        other = _Sleeve()
        other.d = self.d
        for f in ("row", "s", "lim", "xs", "ys", "lo", "hi", "rmax", "rx", "ry", "has"):
            v = getattr(self, f)
            setattr(other, f, v[mask])
            setattr(self, f, v[~mask])
        return other


def _sweep(
    x: np.ndarray,
    y: np.ndarray,
    pend: np.ndarray,
    eps: float,
    s0: np.ndarray,
    d_max: int,
    width: int = 0,
    fuzzy: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, _Sleeve]:
    """The sleeve for many starts at once (vectorised over the starts, one step per
    distance d = 1 .. ``d_max``).

    ``x``, ``y``: concatenated points (consecutive points of a path distinct); ``pend[i]``:
    index of the last point of i's path; ``s0``: the starts. Returns ``(ok, opened,
    state)``: ``ok[k, d]`` is True when the shortcut s0[k] -> s0[k] + d is valid (every
    point strictly between within eps of the segment, decided exactly; the table has
    ``max(d_max, width) + 1`` columns), ``opened[k]`` when the wedge is still non-empty
    after ``d_max`` steps and the path goes on (a valid end may lie farther); ``state``
    lets :func:`_sweep_steps` go on farther (``fuzzy``: see there). A start stops as soon
    as its wedge is empty (no farther end can be valid: the wedge is necessary for the
    segment too) or its path ends.
    """
    m = len(s0)
    ok = np.zeros((m, max(d_max, width) + 1), dtype=bool)
    lim = pend[s0]
    live = s0 < lim
    ok[live, 1] = True
    st = _Sleeve()
    st.d = 0
    st.row = np.flatnonzero(live)
    st.s = s0[live]
    st.lim = lim[live]
    k = len(st.s)
    st.lo = np.full(k, -np.inf)
    st.hi = np.full(k, np.inf)
    st.rmax = np.zeros(k)
    st.rx = np.zeros(k)
    st.ry = np.zeros(k)
    st.has = np.zeros(k, dtype=bool)
    st.xs, st.ys = x[st.s], y[st.s]
    _sweep_steps(x, y, eps, st, ok, s0, d_max, fuzzy)
    opened = np.zeros(m, dtype=bool)
    opened[st.row] = True
    return ok, opened, st


def _sweep_steps(
    x: np.ndarray,
    y: np.ndarray,
    eps: float,
    st: _Sleeve,
    ok: np.ndarray,
    s0: np.ndarray,
    d_max: int,
    fuzzy: np.ndarray | None = None,
) -> None:
    """Steps ``st.d + 1`` .. ``d_max`` of :func:`_sweep` (table ``ok``, rows of starts
    ``s0``); afterwards ``st`` holds the starts whose wedge is still open.

    ``fuzzy`` (per table row, if given) is set where the sweep's slack mattered: a
    candidate within ``_LOOSE`` outside the wedge went to the exact check, or the wedge was
    empty but within the slack. Elsewhere the table's farthest valid end is exactly what
    :func:`_reach_rows` (strict wedge, same arithmetic) finds."""
    chk_rows: list[np.ndarray] = []
    chk_d: list[int] = []
    blk: tuple[np.ndarray, np.ndarray] | None = None
    all_has = bool(st.has.all())  # (then no direction of reference is set any more)
    with np.errstate(divide="ignore", invalid="ignore"):
        k_last = 0  # starts of the step before (0: none yet)
        for d in range(st.d + 1, d_max + 1):
            k = len(st.s)
            if k == 0:
                break
            if d < d_max and (
                k <= _FEW or (d > _SWEEP and k <= _FEW_DENSE and 0 < _SURVIVE * k_last <= k)
            ):
                # few starts left, or not many on a dense stretch (open after _SWEEP steps
                # and still not stopping: the block pays for every cell up to d_max): the
                # remaining steps at once (2-D, same decisions)
                blk = _sweep_block(x, y, eps, st, ok, d - 1, d_max, fuzzy)
                break
            k_last = k
            j = st.s + d
            vx = x[j] - st.xs
            vy = y[j] - st.ys
            r = np.hypot(vx, vy)
            far = r > eps
            near = ~far
            if not all_has:
                new = far & ~st.has
                if new.any():
                    st.rx = np.where(new, vx / r, st.rx)
                    st.ry = np.where(new, vy / r, st.ry)
                    st.has |= new
                    all_has = bool(st.has.all())
            rx, ry, lo, hi, rmax = st.rx, st.ry, st.lo, st.hi, st.rmax
            th = np.arctan2(rx * vy - ry * vx, rx * vx + ry * vy)
            if d >= 2:
                # candidate end j: direction inside the wedge of the points before it (or j
                # itself near s), no point before it farther than r_j + eps from s
                maybe = (th >= lo - _LOOSE) & (th <= hi + _LOOSE)
                maybe |= near
                maybe &= rmax <= r + eps
                # no point before farther from s than j: ray distance == segment distance,
                # so the wedge alone decides (kept a hair inside against rounding)
                sure = (th >= lo + _TINY) & (th <= hi - _TINY)
                if not all_has:
                    sure |= ~st.has
                sure &= rmax <= r
                sure &= maybe
                ok[st.row[sure], d] = True
                rest = maybe & ~sure
                if rest.any():
                    chk_rows.append(st.row[rest])
                    chk_d.append(d)
                    if fuzzy is not None:  # (th, lo, hi are never NaN; such a far
                        # candidate has a direction, so it is never sure: it is in rest)
                        fz = (th < lo) | (th > hi)
                        fz &= far
                        fz &= rest
                        if fz.any():
                            fuzzy[st.row[fz]] = True
            w = np.arcsin(eps / np.where(far, r, 0.0))  # NaN for near points: no bound
            np.fmax(lo, th - w, out=lo)
            np.fmin(hi, th + w, out=hi)
            np.maximum(rmax, r, out=rmax)
            alive = (lo <= hi + _LOOSE) & (j < st.lim)  # a wedge closed by rounding only
            if fuzzy is not None:
                fz = alive & (lo > hi)
                if fz.any():
                    fuzzy[st.row[fz]] = True
            if not alive.all():
                st.take(alive)
    st.d = d_max
    for rows, d in zip(chk_rows, chk_d, strict=True):
        # exact point-to-segment distances for the candidates the wedge left open
        ok[rows, d] = _check_rows(x, y, s0[rows], d, eps)
    if blk is not None and len(blk[0]):
        rows, dd = blk
        ok[rows, dd] = _exact_ok(x, y, s0[rows], s0[rows] + dd, eps)


def _sweep_block(
    x: np.ndarray,
    y: np.ndarray,
    eps: float,
    st: _Sleeve,
    ok: np.ndarray,
    d0: int,
    d1: int,
    fuzzy: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray]:
    """Steps d0 + 1 .. d1 of :func:`_sweep_steps` for every live start of ``st`` at once,
    as 2-D arrays (start x distance): marks the sure shortcuts in ``ok`` (and ``fuzzy``),
    returns the (table row, distance) of the candidates that need the exact check, and
    keeps in ``st`` the starts still open after d1. Each cell is decided by the same
    arithmetic as one step at a time (wedge bounds and farthest distance by cumulative
    max / min along the row); cells past the step where a start stopped are ignored."""
    dist = np.arange(d0 + 1, d1 + 1)
    j = st.s[:, None] + dist
    np.minimum(j, st.lim[:, None], out=j)  # (cells past the path end are never used)
    vx = x[j]
    vx -= st.xs[:, None]
    vy = y[j]
    vy -= st.ys[:, None]
    r = np.hypot(vx, vy)
    far = r > eps
    # direction of reference: the first point farther than eps (maybe in this block)
    has0 = st.has
    rx, ry = st.rx, st.ry
    f0 = far.argmax(axis=1)
    rows = np.arange(len(f0))
    new = ~has0 & far[rows, f0]
    if new.any():
        nr = np.flatnonzero(new)
        nf = f0[nr]
        rx = rx.copy()
        ry = ry.copy()
        rx[nr] = vx[nr, nf] / r[nr, nf]
        ry[nr] = vy[nr, nf] / r[nr, nf]
    cols = np.arange(d1 - d0)
    has = has0[:, None] | (new[:, None] & (cols >= f0[:, None]))
    rxc = rx[:, None]
    ryc = ry[:, None]
    th = np.arctan2(rxc * vy - ryc * vx, rxc * vx + ryc * vy)
    w = np.arcsin(eps / np.where(far, r, 0.0))  # NaN for near points: no bound
    k = d1 - d0 + 1
    lo = np.empty((len(f0), k))
    lo[:, 0] = st.lo
    np.subtract(th, w, out=lo[:, 1:])
    np.fmax.accumulate(lo, axis=1, out=lo)
    hi = np.empty((len(f0), k))
    hi[:, 0] = st.hi
    np.add(th, w, out=hi[:, 1:])
    np.fmin.accumulate(hi, axis=1, out=hi)
    rmax = np.empty((len(f0), k))
    rmax[:, 0] = st.rmax
    rmax[:, 1:] = r
    np.maximum.accumulate(rmax, axis=1, out=rmax)
    # a start is evaluated at step d while its wedge was open and its path went on before
    alive = lo[:, 1:] <= hi[:, 1:] + _LOOSE
    alive &= j < st.lim[:, None]
    run = np.empty((len(f0), k), dtype=bool)
    run[:, 0] = True
    run[:, 1:] = alive
    np.logical_and.accumulate(run, axis=1, out=run)
    lb = lo[:, :-1]
    hb = hi[:, :-1]
    rb = rmax[:, :-1]
    # candidate end j: direction inside the wedge of the points before it (or j itself near
    # s), no point before it farther than r_j + eps from s
    maybe = (th >= lb - _LOOSE) & (th <= hb + _LOOSE)
    maybe |= ~far
    maybe &= rb <= r + eps
    maybe &= run[:, :-1]
    if d0 == 0:
        maybe[:, 0] = False  # (d = 1: always valid, set by the caller)
    # no point before farther from s than j: the wedge alone decides (a hair inside)
    sure = (th >= lb + _TINY) & (th <= hb - _TINY)
    sure |= ~has
    sure &= rb <= r
    sure &= maybe
    ri, ci = np.nonzero(sure)
    ok[st.row[ri], ci + (d0 + 1)] = True
    maybe &= ~sure
    ri, ci = np.nonzero(maybe)
    if fuzzy is not None:
        fz = run[:, :-1] & alive & (lo[:, 1:] > hi[:, 1:])
        fuzzy[st.row[fz.any(axis=1)]] = True
        # a far candidate outside the strict wedge (never sure: it has a direction) is
        # among those to check
        t = th[ri, ci]
        out = far[ri, ci] & ~((t >= lb[ri, ci]) & (t <= hb[ri, ci]))
        fuzzy[st.row[ri[out]]] = True
    out_rows = st.row[ri]
    out_d = ci + (d0 + 1)
    last = run[:, -1]
    st.lo = lo[:, -1]
    st.hi = hi[:, -1]
    st.rmax = rmax[:, -1]
    st.rx = rx
    st.ry = ry
    st.has = has[:, -1]
    if not last.all():
        st.take(last)
    return out_rows, out_d


def _check_rows(x: np.ndarray, y: np.ndarray, s: np.ndarray, d: int, eps: float) -> np.ndarray:
    """Exact test of the shortcuts s -> s + d (one per start in ``s``): every point between
    within eps of the segment (true point-to-segment distance)."""
    xs = x[s][:, None]
    ys = y[s][:, None]
    bx = x[s + d][:, None] - xs
    by = y[s + d][:, None] - ys
    k = s[:, None] + np.arange(1, d)
    px = x[k] - xs
    py = y[k] - ys
    den = bx * bx + by * by
    pos = den > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip((px * bx + py * by) / np.where(pos, den, 1.0), 0.0, 1.0)
    if not pos.all():
        t = np.where(pos, t, 0.0)
    ex = px - t * bx
    ey = py - t * by
    return np.max(ex * ex + ey * ey, axis=1) <= eps * eps


def _farthest(ok: np.ndarray) -> np.ndarray:
    """Per row: the largest d with ok[row, d] (0 when none)."""
    m, w = ok.shape
    if w > 32:
        return (w - 1 - np.argmax(ok[:, ::-1], axis=1)) * ok.any(axis=1)
    # each row as a 32-bit integer: its highest set bit is the frexp exponent - 1 (exact)
    pad = np.zeros((m, 32), dtype=bool)
    pad[:, :w] = ok
    v = np.packbits(pad, axis=1, bitorder="little").view("<u4")[:, 0]
    return np.frexp(v.astype(np.float64))[1] - (v > 0)


def _exact_ok(
    x: np.ndarray, y: np.ndarray, ia: np.ndarray, ib: np.ndarray, eps: float
) -> np.ndarray:
    """Per pair (ia[k], ib[k]), ib > ia + 1: True when every point strictly between lies
    within eps of the segment [P_ia, P_ib] (true point-to-segment distance)."""
    cnt = ib - ia - 1
    first = np.cumsum(cnt) - cnt
    own = np.repeat(np.arange(len(ia)), cnt)
    off = np.arange(int(cnt.sum())) - first[own] + 1
    a = ia[own]
    ax = x[a]
    ay = y[a]
    bx = x[ib[own]] - ax
    by = y[ib[own]] - ay
    px = x[a + off] - ax
    py = y[a + off] - ay
    den = bx * bx + by * by
    t = np.clip((px * bx + py * by) / np.where(den > 0.0, den, 1.0), 0.0, 1.0)
    t = np.where(den > 0.0, t, 0.0)
    ex = px - t * bx
    ey = py - t * by
    return np.maximum.reduceat(ex * ex + ey * ey, first) <= eps * eps


def _reach_rows(
    x: np.ndarray, y: np.ndarray, pend: np.ndarray, eps: float, s: np.ndarray, k_win: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sleeve search of many starts at once, each over the next ``k_win`` points.

    For start i the reach is the farthest j > i such that every point strictly between lies
    within eps of [P_i, P_j] (see module doc): the wedge of ray directions serving the
    points before a candidate is the running intersection of [theta - asin(eps/r),
    theta + asin(eps/r)] (angles relative to the first point farther than eps); the search
    stops where that wedge is empty (no farther end can serve them). The farthest candidate
    whose direction lies in the wedge is accepted when no earlier point is farther from P_i
    (ray distance equals segment distance, kept 1e-12 rad inside), else it is checked
    exactly; a failing candidate gives way to the next one down.

    Arrays are (start, window position); ``x``, ``y`` the concatenated points of all paths,
    ``pend[i]`` the last index of i's path (every start below its path end). Returns
    ``(j, mstop, retry)``: the reach (meaningless where ``retry``), the window position where
    the wedge emptied (to size the next window), and the starts whose wedge is still open
    at the end of the window while their path goes on (search again with a larger window).
    """
    m = len(s)
    rows = np.arange(m)
    pe = pend[s]
    lim = pe - s
    d = np.arange(1, k_win + 1)
    idx = s[:, None] + d
    short = bool((lim < k_win).any())  # some window runs past its path end
    if short:
        np.minimum(idx, pe[:, None], out=idx)
    vx = x[idx]
    vx -= x[s][:, None]
    vy = y[idx]
    vy -= y[s][:, None]
    r = np.hypot(vx, vy)
    far = r > eps
    if short:
        valid = d <= lim[:, None]
        far &= valid
    f0 = far.argmax(axis=1)
    hasfar = far[rows, f0]
    rf = r[rows, f0]
    cx = (vx[rows, f0] / rf)[:, None]
    cy = (vy[rows, f0] / rf)[:, None]
    theta = np.arctan2(cx * vy - cy * vx, cx * vx + cy * vy)
    w = np.arcsin(eps / np.where(far, r, 0.0))  # NaN for near points: no bound
    lo = np.fmax.accumulate(theta - w, axis=1)  # NaN until the first far point
    hi = np.fmin.accumulate(theta + w, axis=1)
    empty = lo > hi
    if short:
        empty &= valid
    e0 = empty.argmax(axis=1)
    has_e = empty[rows, e0]
    n_win = np.minimum(lim, k_win)
    mstop = np.where(has_e, e0, n_win)
    retry = ~has_e & (lim > k_win)
    if retry.all():  # (every wedge still open: nothing to pick yet)
        return s + 1, mstop, retry
    mm = np.minimum(mstop + 1, n_win)
    # candidates lie below mm: drop the columns no row needs
    k_use = max(2, int(mm.max()))
    lo = lo[:, : k_use - 1]
    hi = hi[:, : k_use - 1]
    np.fmax(lo, -np.inf, out=lo)  # no far point yet: any direction
    np.fmin(hi, np.inf, out=hi)
    rmax = np.maximum.accumulate(r[:, : k_use - 1], axis=1)
    # candidate end m (window position m, point s + 1 + m), m = 1 .. k_use - 1, is column
    # m - 1: direction inside the wedge of the points before it (or m itself within eps of
    # P_s), no point before it farther than r_m + eps from P_s
    th1 = theta[:, 1:k_use]
    r1 = r[:, 1:k_use]
    c = lo <= th1
    c &= th1 <= hi
    c |= ~far[:, 1:k_use]
    c &= rmax <= r1 + eps
    c &= d[: k_use - 1] < mm[:, None]
    j = s + 1
    nofar = ~hasfar & ~retry  # every point of the rest of the path within eps of P_s
    if not hasfar.all():
        j[nofar] = pe[nofar]
    todo = np.flatnonzero(~nofar & ~retry)
    if not len(todo):
        return j, mstop, retry
    # the farthest candidate of each start, usually accepted by the wedge alone
    cc = c[todo]
    top = (k_use - 2) - cc[:, ::-1].argmax(axis=1)
    has = cc[np.arange(len(todo)), top]
    t = th1[todo, top]
    # no earlier point farther from P_s than the end: the wedge alone is exact
    sure = has & (rmax[todo, top] <= r1[todo, top])
    sure &= lo[todo, top] + _TINY <= t
    sure &= t <= hi[todo, top] - _TINY
    j[todo[sure]] = s[todo[sure]] + 2 + top[sure]
    todo = todo[has & ~sure]
    # the others: the _TOP farthest candidates at a time, checked exactly where needed
    while len(todo):
        cc = c[todo]
        pick = cc & (np.cumsum(cc[:, ::-1], axis=1)[:, ::-1] <= _TOP)
        ri, col = np.nonzero(pick)
        rows = todo[ri]
        t = th1[rows, col]
        good = rmax[rows, col] <= r1[rows, col]
        good &= lo[rows, col] + _TINY <= t
        good &= t <= hi[rows, col] - _TINY
        jj = s[rows] + 2 + col
        if not good.all():
            ns = np.flatnonzero(~good)
            good[ns] = _exact_ok(x, y, s[rows[ns]], jj[ns], eps)
        best = np.full(len(todo), -1)
        np.maximum.at(best, ri[good], col[good])
        found = best >= 0
        j[todo[found]] = s[todo[found]] + 2 + best[found]
        drop = ~found[ri]
        c[rows[drop], col[drop]] = False
        todo = todo[~found & pick.any(axis=1)]
    return j, mstop, retry


def _reach_one(
    x: np.ndarray, y: np.ndarray, i: int, pe: int, eps: float, k_win: int
) -> tuple[int, int, bool]:
    """:func:`_reach_rows` for one start i (path end ``pe``) on plain slices, with the
    candidates tried from the far end in plain Python (the same decisions, fewer calls).
    Returns ``(j, mstop, retry)``."""
    e = min(pe, i + k_win)
    x0 = x[i]
    y0 = y[i]
    vx = x[i + 1 : e + 1] - x0
    vy = y[i + 1 : e + 1] - y0
    r = np.hypot(vx, vy)
    n_win = len(r)
    retry = pe > i + k_win
    far = r > eps
    f0 = int(far.argmax())
    if not far[f0]:
        return pe, n_win, retry
    cx = vx[f0] / r[f0]
    cy = vy[f0] / r[f0]
    theta = np.arctan2(cx * vy - cy * vx, cx * vx + cy * vy)
    w = np.arcsin(eps / np.where(far, r, 0.0))  # NaN for near points: no bound
    lo = np.fmax.accumulate(theta - w)  # NaN until the first far point
    hi = np.fmin.accumulate(theta + w)
    empty = lo > hi
    m_stop = int(empty.argmax())
    if not empty[m_stop]:
        if retry:
            return i + 1, n_win, True
        m_stop = n_win
    mm = min(m_stop + 1, n_win)
    rmax = np.maximum.accumulate(r[:mm])
    top = mm
    while top > 1:  # blocks of 32 candidates from the far end, as Python floats
        b0 = max(1, top - 32)
        th_l = theta[b0:top].tolist()
        r_l = r[b0:top].tolist()
        lo_l = lo[b0 - 1 : top - 1].tolist()
        hi_l = hi[b0 - 1 : top - 1].tolist()
        rb_l = rmax[b0 - 1 : top - 1].tolist()
        for k in range(top - b0 - 1, -1, -1):
            t = th_l[k]
            lw = lo_l[k]
            hw = hi_l[k]
            if lw != lw:  # no far point before this one: any direction
                lw, hw = -math.inf, math.inf
            rm = r_l[k]
            rb = rb_l[k]
            if not ((lw <= t <= hw) or rm <= eps) or rb > rm + eps:
                continue
            j = i + 1 + b0 + k
            if (rb <= rm and lw + _TINY <= t <= hw - _TINY) or bool(
                _exact_ok(x, y, np.array([i]), np.array([j]), eps)[0]
            ):
                return j, m_stop, False
        top = b0
    return i + 1, m_stop, False


#: first window of a start without history; later windows are sized from the last one
_WIN0 = 48
#: seeds inside a long dense stretch are this many kept lines apart (see :func:`_walk`)
_SEED_LINES = 32
#: ... and at least this many points apart
_SEED_GAP = 256
#: a seed that has not met another walker this many steps past the next seed gives up
_SEED_SLACK = 48
#: no seeds inside a stretch where one kept line covers more points than this
_SEED_MAX_REACH = 400
#: stretches of unknown reaches shorter than this get no seed of their own
_RUN_MIN = 48


class _Walker:
    """One greedy walk: ``cur`` its point, ``end`` its path's last point; a seed (not
    ``true``) also has its stretch end ``stop``, the next seed ``cap`` and a count ``past``
    of steps beyond it; ``win`` the next window size."""

    __slots__ = ("cur", "end", "true", "stop", "cap", "past", "win")

    def __init__(self, cur: int, end: int, true: bool, stop: int, cap: int, win: int) -> None:
        self.cur = cur
        self.end = end
        self.true = true
        self.stop = stop
        self.cap = cap
        self.past = 0
        self.win = win


def _walk(
    x: np.ndarray,
    y: np.ndarray,
    pend: np.ndarray,
    eps: float,
    starts: list[int],
    nxt: list[int],
    opened: np.ndarray,
) -> list[int]:
    """Fill ``nxt[i]`` (the greedy reach of i; -1 = not known yet, only where ``opened``)
    for every point the greedy chains from ``starts`` (the path starts) stand on.

    Walkers advance in lockstep: each round every walker follows known reaches in plain
    Python up to a point whose reach is unknown, and the reaches of all those points are
    found in one :func:`_reach_rows` call (a few per round, grouped by window size). A plain
    walk through dense stretches (unknown reaches) would take one round per kept line, so
    seed walkers start at every stretch of at least ``_RUN_MIN`` points and, once the reach
    there is known, every ``_SEED_LINES`` kept lines along a long one: greedy chains from
    different points meet after a few lines on most curves (from then on they are the same
    chain), so a true walk finds the seeds' reaches already known. Walkers standing on the
    same point are merged; a seed that leaves its stretch, or goes ``_SEED_SLACK`` steps
    past the next seed without meeting anyone, stops. A seed is only ever a head start: the
    chains are those of plain walks, found in fewer rounds. Returns the points whose reach
    it found.
    """
    n = len(opened)
    # stretches of unknown reaches, split at path ends
    first = opened.copy()
    first[1:] &= ~opened[:-1] | (pend[:-1] != pend[1:])
    rs = np.flatnonzero(first)
    last = opened.copy()
    last[:-1] &= ~opened[1:] | (pend[:-1] != pend[1:])
    ren = np.flatnonzero(last) + 1
    long_runs = np.flatnonzero(ren - rs >= _RUN_MIN)
    sd = rs[long_runs]
    is_start = np.zeros(n, dtype=bool)
    is_start[starts] = True
    sd = sd[~is_start[sd]]
    # a seed's cap is the next seed of its path (or the path end)
    cap = np.append(sd[1:], n)
    cap = np.where(pend[cap.clip(max=n - 1)] == pend[sd], cap, pend[sd] + 1)
    walkers = [_Walker(a, int(pend[a]), True, n, n, _WIN0) for a in starts]
    walkers += [
        _Walker(a, e, False, e + 1, b, _WIN0)
        for a, e, b in zip(sd.tolist(), pend[sd].tolist(), cap.tolist(), strict=True)
    ]
    rs_l = rs.tolist()
    ren_l = ren.tolist()
    found: list[int] = []
    split: set[int] = set()
    while walkers:
        at: dict[int, _Walker] = {}
        for w in walkers:
            c = w.cur
            e = w.end
            while c < e:
                j = nxt[c]
                if j < 0:
                    break
                c = j
            if c >= e:
                continue
            if not w.true:
                if c >= w.stop:
                    continue
                if c > w.cap:
                    w.past += 1
                    if w.past > _SEED_SLACK:
                        continue
            w.cur = c
            o = at.get(c)
            if o is None:
                at[c] = w
            else:  # two walks met: from here on they are one
                o.true = o.true or w.true
                o.cap = max(o.cap, w.cap)
                o.stop = max(o.stop, w.stop)
        if not at:
            break
        walkers = list(at.values())
        _reach_batch(x, y, pend, eps, walkers, nxt, found)
        for w in walkers[:]:
            c = w.cur
            rid = bisect.bisect_right(rs_l, c) - 1  # c's stretch
            reach = nxt[c] - c
            if rid in split or reach < 0:  # (reach < 0: still searching, larger window)
                continue
            split.add(rid)
            stop = ren_l[rid]
            gap = max(_SEED_GAP, _SEED_LINES * reach)
            if reach > _SEED_MAX_REACH or stop - c < 2 * gap:
                continue
            pos = list(range(c + gap, stop - gap // 2, gap))
            caps = pos[1:] + [stop if w.true else w.cap]
            walkers += [
                _Walker(p, w.end, False, w.end + 1, q, w.win)
                for p, q in zip(pos, caps, strict=True)
            ]
            if not w.true:
                w.cap = min(w.cap, pos[0])
    return found


#: cost of one :func:`_reach_rows` call in window cells (decides when to split a round)
_CALL_CELLS = 1200
#: most window cells (starts x window points) in one :func:`_reach_rows` call
_MAX_CELLS = 1 << 19
#: windows this long are searched one start at a time (calls cost little against them)
_ONE_BY_ONE = 2048


def _reach_batch(
    x: np.ndarray,
    y: np.ndarray,
    pend: np.ndarray,
    eps: float,
    walkers: list,
    nxt: list[int],
    found: list[int],
) -> None:
    """Set ``nxt[w.cur]`` for the walkers of one round and size each one's next window from
    where its wedge emptied (a quarter more, + 8). One :func:`_reach_rows` call, or two
    when the short windows would waste more than a call costs; a walker whose wedge is still
    open at the end of its window keeps its point and gets twice the window next round."""
    m = len(walkers)
    wins = [w.win for w in walkers]
    order = sorted(range(m), key=wins.__getitem__)
    ws = [wins[k] for k in order]
    top = ws[-1]
    best, cut = m * top, m
    for k in range(1, m):
        cost = _CALL_CELLS + k * ws[k - 1] + (m - k) * top
        if cost < best:
            best, cut = cost, k
    groups = [(order[:cut], ws[cut - 1]), (order[cut:], top)] if cut < m else [(order, top)]
    # bounded memory: at most _MAX_CELLS window cells per call
    groups = [
        (rows[c : c + max(1, _MAX_CELLS // k_win)], k_win)
        for rows, k_win in groups
        for c in range(0, len(rows), max(1, _MAX_CELLS // k_win))
    ]
    for rows, k_win in groups:
        grp = [walkers[k] for k in rows]
        if len(grp) == 1 or k_win >= _ONE_BY_ONE:
            one = [_reach_one(x, y, w.cur, int(pend[w.cur]), eps, k_win) for w in grp]
            jl = [o[0] for o in one]
            ml = [o[1] for o in one]
            rl = [o[2] for o in one]
        else:
            s = np.array([w.cur for w in grp], dtype=np.intp)
            j, ms, retry = _reach_rows(x, y, pend, eps, s, k_win)
            jl = j.tolist()
            ml = ms.tolist()
            rl = retry.tolist()
        for k, w in enumerate(grp):
            if rl[k]:
                w.win = 2 * k_win
            else:
                nxt[w.cur] = jl[k]
                found.append(w.cur)
                w.win = max(16, ml[k] + ml[k] // 4 + 8)


def thin(points: object, eps_line: float, *, closed: bool = False) -> np.ndarray:
    """Kept points of the greedy sleeve thinning.

    Parameters
    ----------
    points:
        (N, 2) float, input units.
    eps_line:
        Tolerance in input units, finite and > 0 (else :class:`ParamError`).
    closed:
        The path is a ring (first point equal to last). The seam point is kept like any
        end point, so the thinned ring closes exactly; otherwise no difference.

    Returns
    -------
    np.ndarray of int
        Increasing indices into the ORIGINAL ``points`` (duplicates never kept twice in a
        row; of a run of equal points the first is the one kept). Always contains 0 and the
        index of the last distinct point (N − 1 unless the path ends on repeats). Every
        point between two consecutive kept indices lies within ``eps_line`` of the segment
        joining them. Empty input gives an empty array.
    """
    return thin_many([points], eps_line)[0]


def thin_many(paths: Sequence[object], eps_line: float) -> list[np.ndarray]:
    """:func:`thin` for many paths in one go (same result as one call per path).

    All paths are deduplicated and concatenated; the short reaches of every start are found
    by one vectorised sweep over all paths together (:func:`_sweep`); where the sleeve
    reaches farther than ``_SWEEP`` points the reach is found only for the points the greedy
    chains stand on, many at once (:func:`_walk`). Paths with fewer than ``_DP_RATIO``
    points per kept line then get the shortest path over the exactly verified shortcuts of
    at most ``_DP_WINDOW`` steps plus the greedy ones (all such paths again in one sweep).
    """
    eps = check_positive("eps_line", eps_line)
    arrs = [np.asarray(p, dtype=np.float64).reshape(-1, 2) for p in paths]
    if not arrs:
        return []
    lens0 = np.array([len(p) for p in arrs], dtype=np.intp)
    o0 = np.concatenate(([0], np.cumsum(lens0)))
    pts = np.concatenate(arrs) if len(arrs) > 1 else arrs[0]
    # duplicates: a point equal to its predecessor in the same path is dropped
    keep = np.ones(len(pts), dtype=bool)
    if len(pts) > 1:
        # (two column compares: np.any along a length-2 axis is far slower)
        keep[1:] = (pts[1:, 0] != pts[:-1, 0]) | (pts[1:, 1] != pts[:-1, 1])
    keep[o0[:-1][lens0 > 0]] = True
    kidx = np.flatnonzero(keep)  # original (concatenated) index of every distinct point
    ck = np.searchsorted(kidx, o0)  # first distinct point of each path
    dl = np.diff(ck)  # distinct points per path
    big = dl > 2
    if big.any():
        sel = np.ones(len(kidx), dtype=bool)  # distinct points kept by the thinning
        qpos = np.flatnonzero(np.repeat(big, dl))  # the thinned paths' points, concatenated
        sel[qpos] = False
        flat = _thin_concat(pts[kidx[qpos]], dl[big], eps)
        sel[qpos[flat]] = True
        kept = kidx[sel]
    else:
        kept = kidx
    cut = np.searchsorted(kept, o0)
    got = kept - np.repeat(o0[:-1], np.diff(cut))
    cl = cut.tolist()
    return [got[c0:c1] for c0, c1 in zip(cl[:-1], cl[1:], strict=True)]


def _thin_concat(q: np.ndarray, lens: np.ndarray, eps: float) -> np.ndarray:
    """Kept points of every path of ``q`` (the distinct points of all paths with more than
    two, concatenated; ``lens`` points each) as increasing indices into ``q``: the greedy
    chain, or the DP's where a path has few points per kept line."""
    offs = np.concatenate(([0], np.cumsum(lens)))
    x = np.ascontiguousarray(q[:, 0])
    y = np.ascontiguousarray(q[:, 1])
    pend = np.repeat(offs[1:] - 1, lens)
    n = len(q)
    with np.errstate(divide="ignore", invalid="ignore"):
        # a sample of every _SAMPLE-th start tells where sleeves are long (dense curves):
        # those stretches skip the sweep; their reaches are found only where a chain stands
        samp = np.arange(0, n, _SAMPLE)
        # paths likely to get the DP (few samples still open, or short) are swept whole to
        # the DP window: the DP needs that table anyway, and it holds most greedy reaches.
        # Samples are swept here only where a long path needs them (the others' come from
        # the sweep of every start below, the same decisions)
        short = lens <= _WHOLE_LEN
        need = np.logical_or.reduceat(np.repeat(~short, lens), samp) if n else samp > 0
        need[1:] |= need[:-1]  # (a stretch is dense when its sample and the next are open)
        sopen = np.zeros(len(samp), dtype=bool)
        pid = np.searchsorted(offs, samp, side="right") - 1
        n_samp = np.bincount(pid, minlength=len(lens))
        far24 = np.zeros(len(lens), dtype=bool)
        if need.any():
            ok_s, sopen[need], st_s = _sweep(x, y, pend, eps, samp[need], _SWEEP, _DP_WINDOW)
            # mid-sized paths whose samples are open after _SWEEP: is a sleeve of _DP_WINDOW
            # points still open at most of them? (else the DP is likely: sweep them whole)
            # (every _SUB24-th sample is enough for that estimate)
            n_open = np.bincount(pid, weights=sopen, minlength=len(lens))
            mid = (lens > _WHOLE_LEN) & (lens <= _MID_LEN) & (n_open > _WHOLE_OPEN * n_samp)
            p_need = pid[need]
            sub = np.arange(len(p_need)) % _SUB24 == 0
            pick = mid[p_need[st_s.row]] & sub[st_s.row]
            if pick.any():
                st_s.take(pick)
                _sweep_steps(x, y, eps, st_s, ok_s, samp[need], _DP_WINDOW)
                n24 = np.bincount(p_need[st_s.row], minlength=len(lens))
                n_sub = np.bincount(p_need[sub], minlength=len(lens))
                far24 = mid & (n24 <= _WHOLE_OPEN24 * n_sub)
        dense = np.repeat(sopen & np.append(sopen[1:], True), _SAMPLE)[:n]
        n_open = np.bincount(pid, weights=sopen, minlength=len(lens))
        whole = np.repeat((n_open <= _WHOLE_OPEN * n_samp) | short | far24, lens)
        dense &= ~whole
        opened = dense.copy()
        starts = np.flatnonzero(~dense)
        nxt_a = np.full(n, -1, dtype=np.intp)
        table = None
        if len(starts):
            # (the table is as wide as the DP window: the DP goes on from here)
            w_row = whole[starts]
            fuzzy = np.zeros(len(starts), dtype=bool) if w_row.any() else None
            ok, op, st = _sweep(x, y, pend, eps, starts, _SWEEP, _DP_WINDOW, fuzzy)
            if fuzzy is not None:
                # reaches a plain greedy walk finds where the sweep stopped at _SWEEP (or
                # skipped the point as dense): from the whole table unless its slack mattered
                rest = np.flatnonzero(~need)  # samples of short paths, all in starts
                sopen[rest] = op[np.searchsorted(starts, samp[rest])]
                dense0 = np.repeat(sopen & np.append(sopen[1:], True), _SAMPLE)[:n]
                walked = w_row & (op | dense0[starts])
                st_w = st.split(whole[st.s])
                _sweep_steps(x, y, eps, st_w, ok, starts, _DP_WINDOW, fuzzy)
                op[w_row] = False
                op[st_w.row] = True
                op |= walked & fuzzy
            # (the farthest valid end: beyond it no wedge stayed open)
            nxt_a[starts] = starts + _farthest(ok)
            opened[starts] = op
            table = (starts, ok, st)
        nxt_a[opened] = -1
        nxt = nxt_a.tolist()
        if opened.any():
            found = _walk(x, y, pend, eps, offs[:-1].tolist(), nxt, opened)
            nxt_a[found] = [nxt[i] for i in found]
        keep = _chain_marks(nxt, nxt_a, offs)
        cnt = np.add.reduceat(keep, offs[:-1])
        dp = lens < _DP_RATIO * cnt
        if dp.any():
            _shortest_many(x, y, pend, eps, offs, dp, keep, cnt, table)
    return np.flatnonzero(keep)


#: from this many paths on, chains are marked by pointer doubling instead of walked
_MANY_PATHS = 32


def _chain_marks(nxt: list[int], nxt_a: np.ndarray, offs: np.ndarray) -> np.ndarray:
    """The points the greedy chains stand on (``nxt``, the same as array ``nxt_a``: reach of
    each point, known on every chain), from every path start (``offs[:-1]``) to its end, as
    a mask."""
    n = len(nxt)
    keep = np.zeros(n, dtype=bool)
    if len(offs) - 1 < _MANY_PATHS:
        nodes: list[int] = []
        for a, e in zip(offs[:-1].tolist(), (offs[1:] - 1).tolist(), strict=True):
            i = a
            nodes.append(i)
            while i < e:
                i = nxt[i]
                nodes.append(i)
        keep[nodes] = True
        return keep
    jump = nxt_a.copy()
    free = jump < 0
    jump[free] = np.flatnonzero(free)
    ends = offs[1:] - 1
    jump[ends] = ends
    return _reachable(jump, offs[:-1])


def _reachable(jump: np.ndarray, roots: np.ndarray) -> np.ndarray:
    """Mask of every point reached from ``roots`` by repeating ``jump`` (fixed points end a
    chain): pointer doubling, log2(longest chain) whole-array steps."""
    mark = np.zeros(len(jump), dtype=bool)
    mark[roots] = True
    s = np.asarray(roots, dtype=np.intp)
    while True:
        t = jump[s]
        t = t[~mark[t]]  # (repeats only of a chain end: harmless)
        if not len(t):
            return mark
        mark[t] = True
        s = np.concatenate((s, t))
        jump = jump[jump]


def _shortest_many(
    x: np.ndarray,
    y: np.ndarray,
    pend: np.ndarray,
    eps: float,
    offs: np.ndarray,
    dp: np.ndarray,
    keep: np.ndarray,
    cnt: np.ndarray,
    table: tuple[np.ndarray, np.ndarray, _Sleeve] | None,
) -> None:
    """In ``keep`` (the greedy chains, ``cnt`` points per path), replace the chain of every
    path with ``dp`` by the fewest kept points over the valid shortcuts of at most
    ``_DP_WINDOW`` steps plus the greedy ones (so never more than the greedy result): a
    shortest path (Imai–Iri) in that graph; of several predecessors at the same distance the
    one farthest back wins, a greedy shortcut longer than the window only when strictly
    better. Every shortcut used is verified exactly.

    A point no shortcut passes over (a corner) is on every path, so the paths split there
    into independent pieces. Two equivalent solvers share the pieces: a breadth-first search
    over all of them at once (:func:`_dp_levels`, one round of numpy calls per kept point of
    the longest piece) and a plain Python relaxation over the edges (:func:`_dp_edges`, for
    pieces with many kept points and few edges each).
    """
    n = len(x)
    lens = np.diff(offs)
    in_dp = np.repeat(dp, lens)
    starts = np.flatnonzero(in_dp)
    ok = _dp_table(x, y, pend, eps, starts, table)
    w = ok.shape[1]
    ri, dd = np.divmod(np.flatnonzero(ok), w)  # (faster than a 2-D nonzero)
    ii = starts[ri]
    jj = ii + dd
    chain_nodes = np.flatnonzero(keep & in_dp)
    # greedy shortcuts longer than the window (not in the table)
    ep = chain_nodes[:-1]
    eb = chain_nodes[1:]
    long = (eb - ep > _DP_WINDOW) & (pend[ep] == pend[eb])
    ep = ep[long]
    eb = eb[long]
    # points passed over by some shortcut; the others cut the paths into pieces
    span = np.bincount(ii + 1, minlength=n + 1)[: n + 1] - np.bincount(jj, minlength=n + 1)
    span[ep + 1] += 1
    span[eb] -= 1
    inside = np.zeros(n, dtype=bool)
    inside[starts] = True
    cuts = np.flatnonzero((np.cumsum(span[:n]) == 0) & inside)
    last = np.zeros(n, dtype=bool)
    last[offs[1:] - 1] = True
    seg_a = cuts[~last[cuts]]  # piece [seg_a[k], seg_e[k]]
    seg_e = cuts[1:][~last[cuts[:-1]]] if len(cuts) > 1 else cuts[:0]
    # cost of each piece by edge relaxation (its edges) and its greedy kept points
    deg = np.bincount(ri, minlength=len(starts))
    cdeg = np.concatenate(([0], np.cumsum(np.bincount(starts, weights=deg, minlength=n))))
    edges = (cdeg[seg_e] - cdeg[seg_a]).astype(np.intp)
    ck = np.searchsorted(chain_nodes, seg_e, side="right") - np.searchsorted(
        chain_nodes, seg_a, side="right"
    )
    # breadth-first for the pieces with at most l_cut greedy lines: a round costs about
    # _LEVEL_EDGES Python edges plus _WORD_EDGES per 64 points of the pieces still going
    order = np.argsort(ck, kind="stable")
    rest = int(edges.sum()) - np.cumsum(edges[order])
    size = seg_e - seg_a + 1
    bits = np.cumsum(size[order] * ck[order]) / 64.0
    cost = ck[order] * _LEVEL_EDGES + bits * _WORD_EDGES + rest
    k_best = int(np.argmin(cost))
    l_cut = int(ck[order[k_best]]) if cost[k_best] < edges.sum() else -1
    pred = np.full(n, -1, dtype=np.intp)
    one = ck == 1  # one greedy line: the DP cannot do better, and takes that line
    pred[seg_e[one]] = seg_a[one]
    lv = (ck <= l_cut) & ~one
    if lv.any():
        _dp_levels(seg_a[lv], seg_e[lv], ck[lv], w, ii, jj, ep, eb, pred)
    ed = (ck > l_cut) & ~one
    if ed.any():
        a_l = seg_a[ed]
        e_l = seg_e[ed]
        on = np.zeros(n + 1, dtype=np.int8)
        np.add.at(on, a_l, 1)
        np.add.at(on, e_l, -1)
        sel = np.cumsum(on[:n]).astype(bool)[ii]
        _dp_edges(
            a_l.tolist(),
            e_l.tolist(),
            ii[sel],
            jj[sel],
            dict(zip(eb.tolist(), ep.tolist(), strict=True)),
            pred,
        )
    # the shortest paths: back from every path end along the predecessors
    jump = np.where(pred >= 0, pred, np.arange(n))
    mark = _reachable(jump, offs[1:][dp] - 1)
    use = np.zeros(len(dp), dtype=bool)
    use[dp] = np.add.reduceat(mark, offs[:-1])[dp] <= cnt[dp]
    sel = np.repeat(use, lens)
    keep[sel] = mark[sel]


def _dp_table(
    x: np.ndarray,
    y: np.ndarray,
    pend: np.ndarray,
    eps: float,
    starts: np.ndarray,
    table: tuple[np.ndarray, np.ndarray, _Sleeve] | None,
) -> np.ndarray:
    """Valid shortcuts of at most ``_DP_WINDOW`` steps from every point of ``starts``
    (sorted): the greedy's sweep ``table`` (its starts, table, open wedges) goes on to the
    window for the starts it has, a new sweep does the others (same decisions either way:
    every start is swept on its own)."""
    n = len(x)
    ok = np.zeros((len(starts), _DP_WINDOW + 1), dtype=bool)
    done = np.zeros(n, dtype=bool)
    if table is not None:
        s8, ok8, st = table
        in_dp = np.zeros(n, dtype=bool)
        in_dp[starts] = True
        st.take(in_dp[st.s])
        _sweep_steps(x, y, eps, st, ok8, s8, _DP_WINDOW)
        mine = in_dp[s8]
        if np.count_nonzero(mine) == len(starts):  # (every start in the table)
            return ok8[mine]
        ok[np.searchsorted(starts, s8[mine])] = ok8[mine]
        done[s8] = True
    rest = starts[~done[starts]]
    if len(rest):
        ok[np.searchsorted(starts, rest)] = _sweep(x, y, pend, eps, rest, _DP_WINDOW)[0]
    return ok


#: one breadth-first round costs about as much as this many Python edges (one per
#: shortcut in :func:`_dp_edges`), plus _WORD_EDGES per 64 points of the pieces it works on
_LEVEL_EDGES = 6
_WORD_EDGES = 0.33
#: shortcut lengths per group in a breadth-first round (see :func:`_dp_levels`)
_SHIFT_GROUP = 4
#: most (round x point) cells unpacked at once when the rounds' bit sets become distances
_UNPACK_CELLS = 1 << 22


def _dp_levels(
    seg_a: np.ndarray,
    seg_e: np.ndarray,
    rounds_est: np.ndarray,
    width: int,
    ii: np.ndarray,
    jj: np.ndarray,
    ep: np.ndarray,
    eb: np.ndarray,
    pred: np.ndarray,
) -> None:
    """:func:`_shortest_many`'s predecessors in the pieces [seg_a[k], seg_e[k]] (sorted)
    by a breadth-first search from their starts, all pieces at once.

    ``ii -> jj``: every valid table shortcut (point indices, sorted by start, at most
    ``width - 1`` points long); ``ep -> eb`` the greedy long shortcuts. The search finds
    each point's distance (lines from its piece start), one round per level, on Python
    integers as bit sets: a round is a shift, an and and an or per shortcut length,
    whatever the number of pieces (the lengths in groups of ``_SHIFT_GROUP``: a round stops
    at the first group whose lengths and all longer ones start nowhere in its front). Each
    piece gets its own bit range (its end a copy that is never expanded), the pieces with
    most greedy lines (``rounds_est``) in the lowest bits, so the sets shrink as the short
    pieces finish.
    Then, vectorised over the shortcuts, a point's predecessor is the smallest start among
    the table shortcuts into it from one level below, else the greedy long shortcut (when
    only that one reaches it from there): the order of the edge-by-edge relaxation
    (:func:`_dp_edges`)."""
    size = seg_e - seg_a + 1
    order = np.argsort(-rounds_est, kind="stable")
    base = np.zeros(len(seg_a), dtype=np.intp)
    base[order] = np.cumsum(size[order]) - size[order]  # first bit of each piece
    total = int(size.sum())
    gpos = np.arange(total) + np.repeat((seg_a - base)[order], size[order])  # point of a bit
    is_end = np.zeros(total, dtype=bool)
    is_end[base + size - 1] = True
    n = len(pred)
    # the table shortcuts from inside the pieces, one bit set per length
    src = np.zeros(n, dtype=bool)
    inner = np.flatnonzero(~is_end)
    src[gpos[inner]] = True
    bit_of = np.zeros(n, dtype=np.intp)
    bit_of[gpos[inner]] = inner
    sel = src[ii]
    ia, ja = (ii, jj) if sel.all() else (ii[sel], jj[sel])
    tab = np.zeros((width, total), dtype=bool)
    tab.reshape(-1)[(ja - ia) * total + bit_of[ia]] = True
    packed = np.packbits(tab, axis=1, bitorder="little")
    nb = packed.shape[1]
    raw = packed.tobytes()
    shifts = [
        (d, b)
        for d in range(1, width)
        if (b := int.from_bytes(raw[d * nb : (d + 1) * nb], "little"))
    ]
    # the lengths in groups of _SHIFT_GROUP, each with the union of its and all longer
    # lengths' sets: a round skips the rest once the front has none of those starts
    groups: list[tuple[int, list[tuple[int, int]]]] = []
    later = 0
    for g in range((len(shifts) - 1) // _SHIFT_GROUP * _SHIFT_GROUP, -1, -_SHIFT_GROUP):
        grp = shifts[g : g + _SHIFT_GROUP]
        for _, b in grp:
            later |= b
        groups.append((later, grp))
    groups.reverse()
    # greedy long shortcuts inside the pieces, as bits
    pk = np.searchsorted(seg_a, ep, side="right") - 1
    inside = (pk >= 0) & (ep < seg_e[pk.clip(min=0)])
    lp = ep[inside]
    lb = eb[inside]
    lbit = lp - seg_a[pk[inside]] + base[pk[inside]]
    lpairs = list(zip(lbit.tolist(), (lbit + (lb - lp)).tolist(), strict=True))
    long_bits = _to_int(_mask(total, lbit))
    seen = _to_int(_mask(total, np.concatenate((base, base + size - 1))))
    front = _to_int(_mask(total, base))
    rounds: list[int] = []
    while front:
        nxt = 0
        for later, grp in groups:
            if not front & later:
                break
            for d, b in grp:
                t = front & b
                if t:
                    nxt |= t << d
        if long_bits and front & long_bits:
            for p, e in lpairs:
                if front >> p & 1:
                    nxt |= 1 << e
        nxt &= ~seen
        seen |= nxt
        rounds.append(nxt)
        front = nxt
    dist = np.zeros(n, dtype=np.intp)
    dist[gpos] = _levels_of(rounds, total)  # (piece ends and starts: 0 either way)
    # predecessors: from one level below, smallest table start first, else the long one
    da = dist[ia]
    big = np.iinfo(np.intp).max
    low = np.full(n, big, dtype=np.intp)
    np.minimum.at(low, ja, da)
    if len(lp):
        np.minimum.at(low, lb, dist[lp])
    good = da == low[ja]
    pm = np.full(n, big, dtype=np.intp)
    np.minimum.at(pm, ja[good], ia[good])
    tgt = np.flatnonzero(low < big)
    p = pm[tgt]
    if len(lp):
        lsrc = np.full(n, -1, dtype=np.intp)
        lsrc[lb] = lp
        p = np.where(p < big, p, lsrc[tgt])
    pred[tgt] = p


def _mask(n: int, idx: np.ndarray) -> np.ndarray:
    """Boolean mask of length n, True at ``idx``."""
    m = np.zeros(n, dtype=bool)
    m[idx] = True
    return m


def _to_int(mask: np.ndarray) -> int:
    """A boolean mask as a Python integer bit set (bit i = mask[i])."""
    return int.from_bytes(np.packbits(mask, bitorder="little").tobytes(), "little")


def _levels_of(rounds: list[int], n: int) -> np.ndarray:
    """Per point (bit) 0 .. n - 1, the (1-based) round whose bit set holds it, 0 for none
    (the sets are disjoint). Only the nonzero bytes are unpacked."""
    dist = np.zeros(n, dtype=np.intp)
    if not rounds:
        return dist
    nb = (n + 7) // 8
    packed = np.frombuffer(b"".join(r.to_bytes(nb, "little") for r in rounds), dtype=np.uint8)
    nz = np.flatnonzero(packed)  # (round, byte) of every nonzero byte
    q = np.flatnonzero(np.unpackbits(packed[nz], bitorder="little"))
    at = nz[q >> 3]
    lv, by = np.divmod(at, nb)
    dist[by * 8 + (q & 7)] = lv + 1
    return dist


def _dp_edges(
    seg_a: list[int],
    seg_e: list[int],
    ii: np.ndarray,
    jj: np.ndarray,
    extra: dict[int, int],
    pred: np.ndarray,
) -> None:
    """:func:`_shortest_many`'s predecessors in the pieces [seg_a[k], seg_e[k]] by relaxing
    their shortcuts (ii -> jj) in plain Python, grouped by end point, within a group by
    start; ``extra[b] = p`` the greedy long shortcuts."""
    order = np.lexsort((ii, jj))
    ii_l = ii[order].tolist()
    jj_l = jj[order].tolist()
    pos = 0
    ne = len(jj_l)
    for a, e in zip(seg_a, seg_e, strict=True):
        m = e + 1 - a
        inf = m + 1
        best = [inf] * m
        prd = [0] * m
        best[0] = 0
        while pos < ne and jj_l[pos] <= e:
            i = ii_l[pos] - a
            j = jj_l[pos] - a
            v = best[i] + 1
            if v < best[j]:
                best[j] = v
                prd[j] = i
            pos += 1
            if extra and (pos == ne or jj_l[pos] != jj_l[pos - 1]):
                p = extra.get(j + a)
                if p is not None and best[p - a] + 1 < best[j]:
                    best[j] = best[p - a] + 1
                    prd[j] = p - a
        pred[a + 1 : e + 1] = np.asarray(prd[1:], dtype=np.intp) + a
