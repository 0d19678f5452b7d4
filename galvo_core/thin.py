"""Line thinning with tolerance ``eps_line`` (paper 000 §2.1, the greedy "sleeve").

The paper walks the points, growing a line P1→P2 while every point between stays within
ε_line of it, and starts a new line at the last good end when the bound breaks. Here:

* Duplicate points are dropped first (consecutive repeats; the first of each repeat is the
  one kept).
* Distances are to the *segment* [P1, P2], not to the infinite line (the paper's formula (2)
  uses the line and also drops the constant C, a typo): a point beyond an end of the segment
  must be within ε_line of that end, so a kept line never hides a point that doubles back.
* "Reach as far as possible": from each kept point the next kept point is the *farthest*
  j for which every point strictly between lies within ε_line of [P_i, P_j].

How the reach is found (the sleeve, or cone intersection, of Zhao & Saalfeld): a ray from
P_i passes within ε of a point at distance r > ε exactly when its direction lies in the arc
of half-angle asin(ε/r) around the point's direction. A valid end j must lie in the
intersection of the arcs of every point before it (a point within ε of the segment is within
ε of the ray), and once that intersection is empty no later end can be valid. The first
point farther than ε fixes a reference direction u; every admissible direction is then
within 90° of u, so an arc is an interval of *slopes* (b/a in the frame of u), the running
intersection is two numbers, and no trigonometry is needed (one square root a point). Ends
whose direction lies in the interval (with a 1e-9 relative slack, so float rounding never
loses a valid end) are the candidates; each is confirmed with the exact point-to-segment
distance of every point between, from the farthest candidate back. So the reach is decided
by the exact test alone. (A point whose distance from P_i is eps to within 1e-12 has
ill-conditioned tangents: it never narrows the interval, and ends after it always get the
whole exact test.)

Near-optimal count: where the greedy keeps more than one point in 16 (integer
coordinates, sparse points), the greedy is not within 2 % of the optimum (up to 20 % over on
glyph outlines); there the kept points are a shortest path (Imai–Iri) over every exactly
verified shortcut of at most 24 steps plus the greedy shortcuts, so never worse than greedy.
Of several predecessors at the same distance the one farthest back wins; a greedy shortcut
longer than the window only when it is strictly better.

Speed: the loops are compiled with numba (``cache=True``: compiled once per machine, then
loaded from ``__pycache__``); one call thins every path of a drawing. The work is linear in
the number of points times the reach (at most the 24-point window where the DP runs).

Guarantee (tested): every dropped point lies within ``eps_line`` (input units) of the kept
segment that replaces it, and the first and last points are always kept.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import cast

import numpy as np
from numba import njit

from galvo_core.errors import ParamError
from galvo_core.parallel import run_chunks

__all__ = ["thin", "thin_many", "dedup_indices", "check_positive"]

#: below this many points per kept line the greedy result is improved by the window DP
_DP_RATIO = 16
#: longest shortcut (in steps) of the DP's table
_DP_WINDOW = 24
#: relative slack of the slope test: a candidate this close outside is checked exactly
_SLACK = 1e-9
#: relative band around eps**2 of the "marginal" points (see :func:`_candidates`): outside
#: it sqrt(r**2 - eps**2) >= 1.4e-6 eps, so the tangents' rounding stays far below _SLACK
_MARGIN = 1e-12


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


def thin_many(
    paths: Sequence[object], eps_line: float, *, per_path: object = None
) -> list[np.ndarray]:
    """:func:`thin` for many paths in one go (the same result as one call per path).

    All paths are concatenated, then deduplicated and thinned by one compiled call.
    ``per_path``: optional tolerances (one per path, each finite and > 0) used instead of
    ``eps_line`` (the fitter's precision-aware tolerance, ``eps_line`` + the path's
    rounding).
    """
    eps = check_positive("eps_line", eps_line)
    if per_path is None:
        eps_arr = np.full(len(paths), eps)
    else:
        eps_arr = np.asarray(per_path, dtype=np.float64).reshape(-1)
        if len(eps_arr) != len(paths) or not (np.isfinite(eps_arr) & (eps_arr > 0)).all():
            raise ParamError("thin_many: one positive finite tolerance per path")
    arrs = [np.asarray(p, dtype=np.float64).reshape(-1, 2) for p in paths]
    if not arrs:
        return []
    lens0 = np.array([len(p) for p in arrs], dtype=np.int64)
    o0 = np.zeros(len(arrs) + 1, dtype=np.int64)
    np.cumsum(lens0, out=o0[1:])
    pts = np.concatenate(arrs) if len(arrs) > 1 else arrs[0]
    x0 = np.ascontiguousarray(pts[:, 0])
    y0 = np.ascontiguousarray(pts[:, 1])

    def chunk(lo: int, hi: int) -> tuple[np.ndarray, np.ndarray]:
        a, b = o0[lo], o0[hi]
        return _thin_paths(x0[a:b], y0[a:b], o0[lo:hi + 1] - a, eps_arr[lo:hi],
                           _DP_RATIO, _DP_WINDOW, _SLACK)

    # (each path on its own: chunks of paths thin at once on the kernel threads)
    parts = cast("list[tuple[np.ndarray, np.ndarray]]", run_chunks(chunk, lens0))
    kept = np.concatenate([k for k, _ in parts]) if len(parts) > 1 else parts[0][0]
    cnt = np.concatenate([c for _, c in parts]) if len(parts) > 1 else parts[0][1]
    if len(arrs) == 1:
        return [kept]
    cl = [0, *np.cumsum(cnt).tolist()]
    return [kept[c0:c1] for c0, c1 in zip(cl[:-1], cl[1:], strict=True)]


# --- compiled kernels -------------------------------------------------------------------


@njit(cache=True, nogil=True)
def _serves(x, y, i, j, e2, rr, far):  # type: ignore[no-untyped-def]
    """Every point strictly between i and j within sqrt(e2) of the segment [P_i, P_j]
    (true point-to-segment distance; a zero-length segment is its end point). With ``far``
    only the points farther from P_i than P_j are tested (``rr[k - i]``: squared distance of
    P_k from P_i), for an end inside the sleeve, where the others are served by the ray."""
    xs = x[i]
    ys = y[i]
    bx = x[j] - xs
    by = y[j] - ys
    den = bx * bx + by * by
    for k in range(i + 1, j):
        if far and rr[k - i] <= den:
            continue
        px = x[k] - xs
        py = y[k] - ys
        t = 0.0
        if den > 0.0:
            t = (px * bx + py * by) / den
            if t < 0.0:
                t = 0.0
            elif t > 1.0:
                t = 1.0
        ex = px - t * bx
        ey = py - t * by
        if ex * ex + ey * ey > e2:
            return False
    return True


@njit(cache=True, nogil=True)
def _candidates(x, y, i, end, eps, slack, cand, sure, rr):  # type: ignore[no-untyped-def]
    """The ends j in (i, end] that the sleeve of the points before them admits, in
    increasing order, into ``cand``; returns how many. Every valid end is among them.
    ``sure[c]`` says how much of the exact test is needed: 2 none (every point before the
    end is within eps of P_i, or the end lies inside the sleeve by more than the slack and
    no point before it is farther from P_i, so none projects past the end and the segment
    serves them as the ray does), 1 only the points farther from P_i than the end (inside
    the sleeve by more than the slack), 0 all (inside only within the slack). ``rr[k - i]``
    gets the squared distance of P_k from P_i."""
    xi = x[i]
    yi = y[i]
    e2 = eps * eps
    # a point with r**2 within this band around eps**2 is "marginal": its arc's tangents are
    # ill-conditioned (sqrt(r**2 - eps**2) near 0), so it never sets or narrows the sleeve,
    # and every end after it gets the whole exact test
    e2lo = e2 * (1.0 - _MARGIN)
    e2hi = e2 * (1.0 + _MARGIN)
    nc = 0
    has = False
    marginal = 0  # 1 once a marginal point was passed (then no shortcut: sure = 0)
    ux = 0.0
    uy = 0.0
    slo = 0.0
    shi = 0.0
    rmax2 = 0.0
    # (written to be branch-light: on sparse or noisy points the branches are unpredictable)
    for j in range(i + 1, end + 1):
        dx = x[j] - xi
        dy = y[j] - yi
        r2 = dx * dx + dy * dy
        rr[j - i] = r2
        if not has:
            # every point before j is within eps of P_i: any segment from P_i serves them
            cand[nc] = j
            sure[nc] = 2 * (1 - marginal)
            nc += 1
            rmax2 = max(rmax2, r2)
            if r2 > e2hi:
                # (u need not be a unit vector: every test below is homogeneous in a, b)
                ux = dx
                uy = dy
                t = eps / math.sqrt(r2 - e2)
                slo = -t
                shi = t
                has = True
            elif r2 > e2lo:
                marginal = 1
            continue
        a = ux * dx + uy * dy
        b = ux * dy - uy * dx
        # slo - tol <= b / a <= shi + tol with tol = slack * (1 + |b / a|), times a > 0 (an
        # end with a <= 0 is outside the first far point's arc: never valid)
        tol = slack * (a + abs(b))
        blo = slo * a
        bhi = shi * a
        inside = (a > 0.0) & (blo - tol <= b) & (b <= bhi + tol)
        strict = (blo + tol < b) & (b < bhi - tol)
        cand[nc] = j
        sure[nc] = strict * (1 + (rmax2 <= r2)) * (1 - marginal)
        nc += inside
        rmax2 = max(rmax2, r2)
        if r2 > e2hi:
            s = math.sqrt(r2 - e2)
            ra = a * s + b * eps  # clockwise tangent direction (frame of u, scaled)
            rb = b * s - a * eps
            la = a * s - b * eps  # counter-clockwise tangent direction
            lb = b * s + a * eps
            if ra <= 0.0 and la <= 0.0:
                break  # the arc misses the half-plane of admissible directions
            # (a tangent with a <= 0 leaves that side of the interval open)
            slo = max(slo, rb / ra if ra > 0.0 else slo)
            shi = min(shi, lb / la if la > 0.0 else shi)
            if slo > shi + slack * (1.0 + abs(shi)):
                break
        elif r2 > e2lo:
            marginal = 1
    return nc


@njit(cache=True, nogil=True)
def _reach(x, y, i, end, eps, slack, cand, sure, rr):  # type: ignore[no-untyped-def]
    """The farthest j in (i, end] whose segment from P_i serves every point between."""
    nc = _candidates(x, y, i, end, eps, slack, cand, sure, rr)
    e2 = eps * eps
    for c in range(nc - 1, 0, -1):
        j = cand[c]
        if sure[c] == 2 or _serves(x, y, i, j, e2, rr, sure[c] == 1):
            return j
    return i + 1


@njit(cache=True, nogil=True)
def _thin_paths(x0, y0, o0, eps, dp_ratio, window, slack):  # type: ignore[no-untyped-def]
    """Every path [o0[p], o0[p + 1]) of the points x0, y0: duplicates dropped (a point equal
    to its predecessor in the same path), thinned (path p with tolerance ``eps[p]``).
    Returns the kept indices into each path's own points, concatenated, and how many each
    path keeps."""
    n0 = x0.shape[0]
    n_p = o0.shape[0] - 1
    kidx = np.empty(n0, dtype=np.int64)  # original index of every distinct point
    offs = np.empty(n_p + 1, dtype=np.int64)  # first distinct point of each path
    m = 0
    for p in range(n_p):
        offs[p] = m
        for k in range(o0[p], o0[p + 1]):
            if k == o0[p] or x0[k] != x0[k - 1] or y0[k] != y0[k - 1]:
                kidx[m] = k
                m += 1
    offs[n_p] = m
    x = np.empty(m)
    y = np.empty(m)
    for k in range(m):
        x[k] = x0[kidx[k]]
        y[k] = y0[kidx[k]]
    keep = _thin_all(x, y, offs, eps, dp_ratio, window, slack)
    kept = np.empty(m, dtype=np.int64)
    cnt = np.zeros(n_p, dtype=np.int64)
    nk = 0
    for p in range(n_p):
        for k in range(offs[p], offs[p + 1]):
            if keep[k]:
                kept[nk] = kidx[k] - o0[p]
                nk += 1
                cnt[p] += 1
    return kept[:nk], cnt


@njit(cache=True, nogil=True)
def _thin_all(x, y, offs, eps_p, dp_ratio, window, slack):  # type: ignore[no-untyped-def]
    """Kept-point mask of every path [offs[p], offs[p + 1]) of the distinct points x, y
    (path p thinned with tolerance ``eps_p[p]``)."""
    n = x.shape[0]
    keep = np.zeros(n, dtype=np.bool_)
    cand = np.empty(n + 1, dtype=np.int64)
    sure = np.empty(n + 1, dtype=np.int8)
    rr = np.empty(n + 1, dtype=np.float64)
    chain = np.empty(n + 1, dtype=np.int64)
    for p in range(offs.shape[0] - 1):
        eps = eps_p[p]
        e2 = eps * eps
        a = offs[p]
        e = offs[p + 1] - 1
        m = e - a + 1
        if m <= 0:
            continue
        if m <= 2:
            for k in range(a, e + 1):
                keep[k] = True
            continue
        # the greedy chain
        cnt = 0
        i = a
        chain[cnt] = i
        cnt += 1
        while i < e:
            i = _reach(x, y, i, e, eps, slack, cand, sure, rr)
            chain[cnt] = i
            cnt += 1
        if m >= dp_ratio * cnt:
            for c in range(cnt):
                keep[chain[c]] = True
            continue
        # shortest path over the valid shortcuts of <= window steps and the greedy ones
        ok = np.zeros((m, window + 1), dtype=np.bool_)
        for s in range(a, e):
            nc = _candidates(x, y, s, min(e, s + window), eps, slack, cand, sure, rr)
            for c in range(nc):
                j = cand[c]
                if j == s + 1 or sure[c] == 2 or _serves(x, y, s, j, e2, rr, sure[c] == 1):
                    ok[s - a, j - s] = True
        longsrc = np.full(m, -1, dtype=np.int64)
        for c in range(cnt - 1):
            if chain[c + 1] - chain[c] > window:
                longsrc[chain[c + 1] - a] = chain[c] - a
        best = np.empty(m, dtype=np.int64)
        pred = np.empty(m, dtype=np.int64)
        best[0] = 0
        pred[0] = -1
        for j in range(1, m):
            bj = m + 1
            pj = -1
            for i2 in range(max(0, j - window), j):
                if ok[i2, j - i2] and best[i2] + 1 < bj:
                    bj = best[i2] + 1
                    pj = i2
            ls = longsrc[j]
            if ls >= 0 and best[ls] + 1 < bj:
                bj = best[ls] + 1
                pj = ls
            best[j] = bj
            pred[j] = pj
        if best[m - 1] + 1 <= cnt:
            j = m - 1
            while j >= 0:
                keep[a + j] = True
                j = pred[j]
        else:  # (never: the greedy's own lines are in the graph)
            for c in range(cnt):
                keep[chain[c]] = True
    return keep
