"""A cubic's worst point error brought under a bound (rounded input, issue 16).

The fitter's candidates for one cubic over a stretch of input points (the triangle family's
dichotomy, the least-squares cubic, Gauss-Newton with free inner control points) all balance
or minimise the errors *on average*. On rounded input the bound is e_per + q/√2 from every
input point, and the design curve itself is up to q/√2 from the points: a long design cubic
is fitted within the bound only by a curve that follows the design nearly exactly where the
rounding put a point at the corner of its square. A least-squares cubic, pulled a little by
the many points on the other side, misses there by a few hundredths of a unit, and the
piece is split into two or three cubics (cubic typefaces at em 1500-3000: a fifth more
segments than the typeface has).

:func:`minimax_cubics` starts from such a cubic and moves its two inner control points
(the ends stay) to lower the *largest* distance of the piece's input points: per round, the
points' nearest parameters and normals are found again (Newton), the distances are
linearised in the four free coordinates, and Lawson's iteration (a weighted least-squares
fit whose weights grow with each point's residual) approaches the linear minimax step,
kept inside a trust radius (Levenberg-Marquardt damping). It stops as soon as every point
is within the target (the candidate closest to the least-squares cubic that does), or after
a fixed number of rounds, or at once where the start is far off (a piece that spans two
design curves: splitting it is right). The result is only a candidate: the fitter's
acceptance test decides, as for every other.
"""

from __future__ import annotations

import math
from typing import cast

import numpy as np
from numba import njit

from galvo_core import parallel
from galvo_core.geometry import newton_param

__all__ = ["minimax_cubics"]

#: outer rounds (new nearest points and normals each)
MINIMAX_ROUNDS = 10
#: Lawson iterations per round
MINIMAX_LAWSON = 8
#: largest move of a control-point coordinate per round (input units)
MINIMAX_RADIUS = 0.5
#: only starts whose worst point is within this many times the target are refined
MINIMAX_START = 3.0
#: the points whose residual is at least this share of the largest one take part in a
#: round's Lawson iteration
_ACTIVE = 0.5
#: the rounds move the cubic for the points within this share of the worst distance at the
#: last full pass (the others are measured again once these pass)
_WATCH = 0.8
#: ... and at first a strided sample of about this many points
_SAMPLE = 48
#: a refined cubic stays near its start: no inner control-point coordinate moved farther (units)
MINIMAX_MOVE = 0.5
#: stop at this fraction of the bound (the acceptance test measures again, exactly)
MINIMAX_TARGET = 0.995


#: work done (diagnostics): points measured in full passes, watched-point measures, 4 x 4
#: solves, rounds
COUNTS = np.zeros(4, dtype=np.int64)


@njit(cache=True, nogil=True)
def _solve4(N, g, lam, d):  # type: ignore[no-untyped-def]  # pragma: no cover (compiled)
    """d = (N + lam I)^-1 g for a 4 x 4 system (Gaussian elimination, partial pivoting);
    False where singular."""
    a = np.empty((4, 5))
    for i in range(4):
        for j in range(4):
            a[i, j] = N[i, j]
        a[i, i] += lam
        a[i, 4] = g[i]
    for c in range(4):
        p = c
        for i in range(c + 1, 4):
            if abs(a[i, c]) > abs(a[p, c]):
                p = i
        if not abs(a[p, c]) > 0.0:
            return False
        if p != c:
            for j in range(5):
                t = a[c, j]
                a[c, j] = a[p, j]
                a[p, j] = t
        for i in range(c + 1, 4):
            f = a[i, c] / a[c, c]
            for j in range(c, 5):
                a[i, j] -= f * a[c, j]
    for i in range(3, -1, -1):
        s = a[i, 4]
        for j in range(i + 1, 4):
            s -= a[i, j] * d[j]
        d[i] = s / a[i, i]
    return True


@njit(cache=True, nogil=True, inline="always")
def _point(work, k, p0x, p0y, ax, ay, bx, by, dx, dy, uk, steps):  # type: ignore[no-untyped-def]  # pragma: no cover (compiled)
    """Input point ``k``'s nearest parameter (``steps`` Newton steps from ``uk``), its
    distance and its signed normal residual: (u, e, res)."""
    qx = work[k, 0] - p0x
    qy = work[k, 1] - p0y
    for _ in range(steps):
        uk = newton_param(ax, ay, bx, by, dx, dy, qx, qy, uk)
    rx = ((ax * uk + bx) * uk + dx) * uk - qx
    ry = ((ay * uk + by) * uk + dy) * uk - qy
    e = math.sqrt(rx * rx + ry * ry)
    tx = (3.0 * ax * uk + 2.0 * bx) * uk + dx
    ty = (3.0 * ay * uk + 2.0 * by) * uk + dy
    tn = math.sqrt(tx * tx + ty * ty)
    if not tn > 0.0:
        tn = 1.0
    return uk, e, (-ty * rx + tx * ry) / tn


@njit(cache=True, nogil=True, error_model="numpy")
def _minimax_kernel(work, arc, i0, i1, ctrl, target, rounds, lawson, radius, start,
                    out, ok, cnt, active, watch, sample, move):  # type: ignore[no-untyped-def]  # pragma: no cover (compiled)
    """:func:`minimax_cubics`, one piece at a time (compiled). The rounds see only the
    *watched* points (those within ``_WATCH`` of the worst distance at the last full
    pass); all points are measured again only when the watched ones are all within the
    target, and the ones then over ``_WATCH`` of the worst are watched too (an exchange
    method: a long piece's hundreds of points cost two or three full passes, not one per
    round)."""
    nmax = 1
    for r in range(len(i0)):
        nmax = max(nmax, i1[r] - i0[r] + 1)
    u = np.empty(nmax)
    e_all = np.empty(nmax)
    res = np.empty(nmax)
    jac = np.empty((nmax, 4))
    w = np.empty(nmax)
    wl = np.empty(nmax, dtype=np.intp)
    inw = np.zeros(nmax, dtype=np.bool_)
    N = np.empty((4, 4))
    g = np.empty(4)
    d = np.zeros(4)
    dt = np.zeros(4)
    for r in range(len(i0)):
        a = i0[r]
        n = i1[r] - a + 1
        ok[r] = False
        p0x = ctrl[r, 0, 0]
        p0y = ctrl[r, 0, 1]
        p1x = ctrl[r, 1, 0]
        p1y = ctrl[r, 1, 1]
        p2x = ctrl[r, 2, 0]
        p2y = ctrl[r, 2, 1]
        p3x = ctrl[r, 3, 0]
        p3y = ctrl[r, 3, 1]
        out[r, 0, 0] = p0x
        out[r, 0, 1] = p0y
        out[r, 3, 0] = p3x
        out[r, 3, 1] = p3y
        span = arc[i1[r]] - arc[a]
        if not span > 0.0 or n < 3:
            continue
        for j in range(n):
            u[j] = (arc[a + j] - arc[a]) / span
            inw[j] = False
        lim = target[r]
        best = math.inf
        stale = 0
        lrel = 1e-9
        # the first rounds watch a strided sample of the points
        stride = max(1, n // sample)
        nw = 0
        for j in range(stride // 2, n, stride):
            inw[j] = True
            wl[nw] = j
            nw += 1
        full = False  # (this round measures every point)
        steps = 3  # (the first full pass starts from arc-length parameters)
        for it in range(rounds + 1):
            ax = -p0x + 3.0 * (p1x - p2x) + p3x
            ay = -p0y + 3.0 * (p1y - p2y) + p3y
            bx = 3.0 * (p0x + p2x) - 6.0 * p1x
            by = 3.0 * (p0y + p2y) - 6.0 * p1y
            dx = 3.0 * (p1x - p0x)
            dy = 3.0 * (p1y - p0y)
            emax = 0.0
            ws = 3 if it == 0 else 2
            for t in range(nw):
                j = wl[t]
                uk, e, rs = _point(work, a + j, p0x, p0y, ax, ay, bx, by, dx, dy, u[j], ws)
                u[j] = uk
                res[j] = rs
                if not e <= emax:
                    emax = e
            # (the sample's worst is at most the piece's: a far start is given up)
            if it == 0 and not emax <= start * lim:
                break
            if emax <= lim:  # the watched points pass: measure them all
                full = True
            cnt[1] += nw
            cnt[3] += 1
            if full:
                cnt[0] += n
                emax = 0.0
                for j in range(n):
                    uk, e, rs = _point(work, a + j, p0x, p0y, ax, ay, bx, by, dx, dy, u[j],
                                       steps)
                    u[j] = uk
                    res[j] = rs
                    e_all[j] = e
                    if not e <= emax:
                        emax = e
                steps = 2
                if emax <= lim:
                    # ... and it stayed near its start (a near miss needs a small
                    # correction; a cubic moved far to keep its worst points in is bent
                    # off the design elsewhere, the bound on rounded points being loose)
                    ok[r] = (max(abs(p1x - ctrl[r, 1, 0]), abs(p1y - ctrl[r, 1, 1]),
                                 abs(p2x - ctrl[r, 2, 0]), abs(p2y - ctrl[r, 2, 1]))
                             <= move)
                    break
                for j in range(n):  # (the exchange: the new near-worst points watched)
                    if e_all[j] >= watch * emax and not inw[j]:
                        inw[j] = True
                        wl[nw] = j
                        nw += 1
                full = False
                best = math.inf  # (a new set of points: progress is measured afresh)
                stale = 0
            if it == rounds:
                break
            # stalled: no round in the last two brought the worst point 1 % lower
            if emax < 0.99 * best:
                best = emax
                stale = 0
            else:
                stale += 1
                if stale >= 2:
                    break
            # the points that can decide the worst error (the others' weights vanish in
            # Lawson's iteration anyway): residual within a share of the largest
            rmax = 0.0
            for t in range(nw):
                rmax = max(rmax, abs(res[wl[t]]))
            na = 0
            for t in range(nw):
                j = wl[t]
                if abs(res[j]) >= active * rmax:
                    uk = u[j]
                    tx = (3.0 * ax * uk + 2.0 * bx) * uk + dx
                    ty = (3.0 * ay * uk + 2.0 * by) * uk + dy
                    tn = math.sqrt(tx * tx + ty * ty)
                    if not tn > 0.0:
                        tn = 1.0
                    nx = -ty / tn
                    ny = tx / tn
                    sk = 1.0 - uk
                    b1 = 3.0 * sk * sk * uk
                    b2 = 3.0 * sk * uk * uk
                    jac[na, 0] = b1 * nx
                    jac[na, 1] = b1 * ny
                    jac[na, 2] = b2 * nx
                    jac[na, 3] = b2 * ny
                    e_all[na] = res[j]  # (the active residuals, packed; e_all is rebuilt
                    w[na] = 1.0         # at the next full pass)
                    na += 1
            found = False
            for _k in range(lawson):
                for i in range(4):
                    for i2 in range(i, 4):
                        acc = 0.0
                        for j in range(na):
                            acc += w[j] * jac[j, i] * jac[j, i2]
                        N[i, i2] = acc
                        N[i2, i] = acc
                    acc = 0.0
                    for j in range(na):
                        acc += w[j] * jac[j, i] * e_all[j]
                    g[i] = -acc
                tr = N[0, 0] + N[1, 1] + N[2, 2] + N[3, 3]
                if not tr > 0.0:
                    break
                lam = lrel * tr
                good = False
                for _t in range(24):  # damped until the step is inside the radius
                    cnt[2] += 1
                    if _solve4(N, g, lam, dt):
                        big = max(max(abs(dt[0]), abs(dt[1])), max(abs(dt[2]), abs(dt[3])))
                        if big <= radius:
                            good = True
                            break
                    lam = max(4.0 * lam, 1e-6 * tr)
                if not good:
                    break
                # (the next solve starts near this damping: most need the same)
                lrel = max(1e-9, 0.25 * lam / tr)
                for i in range(4):
                    d[i] = dt[i]
                found = True
                ws = 0.0
                for j in range(na):
                    rr = abs(e_all[j] + jac[j, 0] * d[0] + jac[j, 1] * d[1]
                             + jac[j, 2] * d[2] + jac[j, 3] * d[3])
                    w[j] *= rr
                    ws += w[j]
                if not ws > 0.0:
                    break
                for j in range(na):
                    w[j] /= ws
            if not found:
                break
            p1x += d[0]
            p1y += d[1]
            p2x += d[2]
            p2y += d[3]
            if not (max(abs(p1x - ctrl[r, 1, 0]), abs(p1y - ctrl[r, 1, 1]),
                        abs(p2x - ctrl[r, 2, 0]), abs(p2y - ctrl[r, 2, 1])) <= move):
                break  # (moved too far: see below)
        out[r, 1, 0] = p1x
        out[r, 1, 1] = p1y
        out[r, 2, 0] = p2x
        out[r, 2, 1] = p2y


def minimax_cubics(work: np.ndarray, arc: np.ndarray, i0: np.ndarray, i1: np.ndarray,
                   ctrl: np.ndarray, bound: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per piece (input points ``i0[r]`` .. ``i1[r]`` of ``work``, ``arc`` their cumulative
    arc length, ``ctrl[r]`` (4, 2) the start cubic): a cubic with the same ends whose
    every input point is within ``MINIMAX_TARGET`` times ``bound[r]`` (by the Newton
    nearest points), where the refinement finds one. Returns (ctrl (m, 4, 2), ok (m,))."""
    m = len(i0)
    out = np.array(ctrl, dtype=np.float64, copy=True).reshape(m, 4, 2)
    ok = np.zeros(m, dtype=np.bool_)
    if m == 0:
        return out, ok
    a = np.ascontiguousarray(i0, dtype=np.intp)
    b = np.ascontiguousarray(i1, dtype=np.intp)
    start = np.ascontiguousarray(ctrl, dtype=np.float64).reshape(m, 4, 2)
    target = np.ascontiguousarray(MINIMAX_TARGET * np.asarray(bound, dtype=np.float64))

    def chunk(lo: int, hi: int) -> np.ndarray:
        # each piece is refined on its own: chunks of pieces on the pool give the same cubics
        cnt = np.zeros_like(COUNTS)
        _minimax_kernel(work, arc, a[lo:hi], b[lo:hi], start[lo:hi], target[lo:hi],
                        MINIMAX_ROUNDS, MINIMAX_LAWSON, MINIMAX_RADIUS, MINIMAX_START,
                        out[lo:hi], ok[lo:hi], cnt, _ACTIVE, _WATCH, _SAMPLE, MINIMAX_MOVE)
        return cnt

    # (a refinement costs tens of passes over its points: worth the pool from fewer points)
    for cnt in parallel.run_chunks(chunk, (b - a + 1).astype(np.float64),
                                   min_work=parallel.MIN_WORK / 8):
        COUNTS[:] = COUNTS + cast(np.ndarray, cnt)
    return out, ok
