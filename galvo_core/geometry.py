"""Vectorised plane geometry for lines and cubic Béziers (numpy only, no Qt).

Conventions
-----------
* Coordinates are float64 in *input units* (HP-GL plotter units) unless stated otherwise;
  every function is unit-agnostic (distances come back in the units of the coordinates).
* A cubic Bézier is given by its control polygon ``ctrl``: array-like of shape (4, 2),
  ``ctrl[0]`` and ``ctrl[3]`` are the curve's end points.
* Curve parameters ``t`` / ``u`` are in [0, 1].
* Point sets are arrays of shape (K, 2).

Nothing here loops over points in Python: the work is done on whole arrays (the Newton
refinement of nearest points in a compiled loop, numba), chunked where a
pairwise table could otherwise grow large.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from galvo_core.parallel import run_chunks

__all__ = [
    "cubic_eval",
    "cubic_derivative",
    "cubic_second_derivative",
    "cubic_length",
    "nearest_on_cubic",
    "nearest_on_cubic_each",
    "point_segment_distance",
    "point_polyline_distance",
    "flatten_cubic",
]

#: Largest pairwise table (rows x columns) built in one go by the chunked routines.
_CHUNK_CELLS = 1 << 21


def _ctrl(ctrl: object) -> np.ndarray:
    c = np.asarray(ctrl, dtype=np.float64)
    if c.shape != (4, 2):
        raise ValueError(f"a cubic needs 4 control points of shape (4, 2), got {c.shape}")
    return c


def _power_coeffs(c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Power-basis coefficients: B(t) = a t^3 + b t^2 + d t + e."""
    p0, p1, p2, p3 = c
    a = -p0 + 3.0 * p1 - 3.0 * p2 + p3
    b = 3.0 * p0 - 6.0 * p1 + 3.0 * p2
    d = -3.0 * p0 + 3.0 * p1
    return a, b, d, p0


def cubic_eval(ctrl: object, t: object) -> np.ndarray:
    """Points of the cubic at parameters ``t``.

    ``ctrl`` (4, 2), ``t`` (M,) in [0, 1] (values outside extrapolate) -> (M, 2), same units
    as ``ctrl``. Uses the Bernstein form, so ``t == 0`` and ``t == 1`` give ``ctrl[0]`` and
    ``ctrl[3]`` exactly.
    """
    c = _ctrl(ctrl)
    t = np.asarray(t, dtype=np.float64).reshape(-1, 1)
    s = 1.0 - t
    return (
        (s * s * s) * c[0]
        + (3.0 * s * s * t) * c[1]
        + (3.0 * s * t * t) * c[2]
        + (t * t * t) * c[3]
    )


def cubic_derivative(ctrl: object, t: object) -> np.ndarray:
    """First derivative dB/dt at ``t``: (M,) -> (M, 2), units per unit parameter."""
    c = _ctrl(ctrl)
    t = np.asarray(t, dtype=np.float64).reshape(-1, 1)
    s = 1.0 - t
    d0 = c[1] - c[0]
    d1 = c[2] - c[1]
    d2 = c[3] - c[2]
    return 3.0 * ((s * s) * d0 + (2.0 * s * t) * d1 + (t * t) * d2)


def cubic_second_derivative(ctrl: object, t: object) -> np.ndarray:
    """Second derivative d²B/dt² at ``t``: (M,) -> (M, 2)."""
    c = _ctrl(ctrl)
    t = np.asarray(t, dtype=np.float64).reshape(-1, 1)
    e0 = c[2] - 2.0 * c[1] + c[0]
    e1 = c[3] - 2.0 * c[2] + c[1]
    return 6.0 * ((1.0 - t) * e0 + t * e1)


def cubic_length(ctrl: object, n: int = 64) -> float:
    """Arc length of the cubic (Gauss-Legendre over ``n`` equal parameter pieces)."""
    c = _ctrl(ctrl)
    xg, wg = np.polynomial.legendre.leggauss(5)
    edges = np.linspace(0.0, 1.0, n + 1)
    half = 0.5 * (edges[1:] - edges[:-1])
    mid = 0.5 * (edges[1:] + edges[:-1])
    t = (mid[:, None] + half[:, None] * xg[None, :]).ravel()
    speed = np.hypot(*cubic_derivative(c, t).T).reshape(n, 5)
    return float((speed * wg[None, :]).sum(axis=1).dot(half))


def flatten_cubic(ctrl: object, tol: float) -> np.ndarray:
    """A polyline within ``tol`` of the cubic: (M, 2), M >= 2, first/last = the end points.

    Uniform parameter steps, as many as the bound |B''| <= 6 max|P_i - 2P_(i+1) + P_(i+2)|
    requires for a chord-height error <= ``tol`` (chord error <= |B''|max h² / 8).
    ``tol`` in the units of ``ctrl``, > 0. Every point of the curve is within ``tol`` of the
    polyline and every vertex lies on the curve.
    """
    c = _ctrl(ctrl)
    if not (tol > 0.0 and np.isfinite(tol)):
        raise ValueError("flatten_cubic: tol must be a positive finite number")
    m = 6.0 * max(
        float(np.hypot(*(c[2] - 2.0 * c[1] + c[0]))), float(np.hypot(*(c[3] - 2.0 * c[2] + c[1])))
    )
    n = int(np.ceil(np.sqrt(m / (8.0 * tol)))) if m > 0.0 else 1
    n = max(1, min(n, 1_000_000))
    return cubic_eval(c, np.linspace(0.0, 1.0, n + 1))


def _newton_nearest(
    c: np.ndarray,
    p: np.ndarray,
    u: np.ndarray,
    lo: np.ndarray | float,
    hi: np.ndarray | float,
    iters: int,
) -> np.ndarray:
    """Newton on f(u) = B'(u)·(B(u) - p), each u kept inside its bracket [lo, hi]."""
    cf = np.array(_power_coeffs(c))[:, :, None]
    return newton_nearest_many(cf, p.T, u, iters, lo=lo, hi=hi)[0]


_NEAREST_CANDIDATES = 3  # local minima of the sampled distance refined by Newton


def nearest_on_cubic(
    ctrl: object, pts: object, *, seeds: int = 48, iters: int = 6
) -> tuple[np.ndarray, np.ndarray]:
    """True nearest point on the cubic for every point.

    ``ctrl`` (4, 2), ``pts`` (K, 2) -> ``(t, dist)``: ``t`` (K,) the parameter in [0, 1] of
    the nearest curve point, ``dist`` (K,) its Euclidean distance (same units as the input).

    Robust against local minima: the curve is sampled at ``seeds + 1`` parameters (more for
    curves whose control polygon turns a lot), each point starts at its nearest sample,
    ``iters`` Newton steps refine it inside the bracket of the neighbouring samples, and the
    result is never worse than the best sample or either end point.
    """
    c = _ctrl(ctrl)
    p = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
    if len(p):  # (one cubic: nearest_on_cubic_each's steps without its grouping)
        cc = np.ascontiguousarray(c[None])
        ns = int(_seed_counts(cc, seeds)[0])
        best_u = np.empty(len(p))
        best_d2 = np.empty(len(p))
        if _nearest_one_kernel(cc, np.linspace(0.0, 1.0, ns + 1), np.ascontiguousarray(p),
                               iters, min(_NEAREST_CANDIDATES, ns + 1), best_u, best_d2):
            return best_u, np.sqrt(best_d2)
    return nearest_on_cubic_each(
        c[None], np.zeros(len(p), dtype=np.intp), p, seeds=seeds, iters=iters
    )


@njit(cache=True, nogil=True)
def _nearest_one_kernel(cc, su, p, iters, nc, best_u, best_d2):  # type: ignore[no-untyped-def]
    """:func:`nearest_on_cubic_each` for the one cubic cc[0] (its numbers: the samples at
    ``su`` and candidates of :func:`_candidates_kernel`, the refinement of
    :func:`_refine_kernel`); False (nothing decided) where two sampled minima tie (the
    caller then takes nearest_on_cubic_each, which selects those by numpy)."""
    k = p.shape[0]
    ns = su.shape[0] - 1
    spx = np.empty((1, ns + 1))
    spy = np.empty((1, ns + 1))
    u0 = np.zeros((_NEAREST_CANDIDATES, k))
    lo = np.zeros((_NEAREST_CANDIDATES, k))
    hi = np.ones((_NEAREST_CANDIDATES, k))
    ok = np.zeros((_NEAREST_CANDIDATES, k), dtype=np.bool_)
    tie = np.zeros(k, dtype=np.bool_)
    pid = np.zeros(k, dtype=np.int64)
    out = np.arange(k)
    _candidates_kernel(cc, su, pid, p, out, spx, spy, best_u, best_d2, u0, lo, hi, ok, nc,
                       tie)
    if tie.any():
        return False
    _refine_kernel(cc, pid, p, u0, lo, hi, ok, iters, best_u, best_d2)
    return True


def _seed_counts(c: np.ndarray, seeds: int) -> np.ndarray:
    """Samples - 1 per cubic (M, 4, 2): ``seeds``, more for a control polygon turning more
    than 90 degrees (loops, cusps)."""
    legs = np.diff(c, axis=1)
    ang = np.arctan2(legs[..., 1], legs[..., 0])
    turn = np.abs(np.angle(np.exp(1j * np.diff(ang, axis=1)))).sum(axis=1)
    ratio = turn / (np.pi / 2)
    return (seeds * np.where(ratio > 1.0, ratio, 1.0)).astype(np.intp)


def _bernstein_each(c: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Point k of cubic ``c[k]`` (K, 4, 2) at ``t[k]`` (the arithmetic of
    :func:`cubic_eval`, so the same bits)."""
    t = t.reshape(-1, 1)
    s = 1.0 - t
    return (
        (s * s * s) * c[:, 0]
        + (3.0 * s * s * t) * c[:, 1]
        + (3.0 * s * t * t) * c[:, 2]
        + (t * t * t) * c[:, 3]
    )


def nearest_on_cubic_each(
    ctrl: object, pid: object, pts: object, *, seeds: int = 48, iters: int = 6
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`nearest_on_cubic` for many points, each against its own cubic ``ctrl[pid[k]]``.

    ``ctrl`` (M, 4, 2), ``pid`` (K,) ints, ``pts`` (K, 2) -> ``(t, dist)`` (K,) each: bit for
    bit what :func:`nearest_on_cubic` gives for each cubic and its points (the same samples,
    candidates and Newton steps; the sampled search runs once per distinct sample count, the
    Newton refinement once for all points).
    """
    c = np.asarray(ctrl, dtype=np.float64).reshape(-1, 4, 2)
    pid = np.asarray(pid, dtype=np.intp).reshape(-1)
    p = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
    k = len(p)
    if k == 0:
        return np.zeros(0), np.zeros(0)
    nsp = _seed_counts(c, seeds)[pid]
    best_u = np.empty(k)
    best_d2 = np.empty(k)
    cc = np.ascontiguousarray(c)

    def chunk(a: int, b: int) -> None:  # (each point on its own: the same numbers)
        _nearest_each_part(cc, pid[a:b], p[a:b], nsp[a:b], iters, best_u[a:b], best_d2[a:b])

    run_chunks(chunk, nsp)
    return best_u, np.sqrt(best_d2)


def _nearest_each_part(c, pid, p, nsp, iters, best_u, best_d2) -> None:
    """:func:`nearest_on_cubic_each` for the points ``p`` (their cubics c[pid], sample
    counts ``nsp``) into ``best_u``, ``best_d2`` (squared)."""
    k = len(p)
    # per point: best sample, and the bracketed start of each candidate's Newton run
    u0 = np.zeros((_NEAREST_CANDIDATES, k))
    lo = np.zeros((_NEAREST_CANDIDATES, k))
    hi = np.ones((_NEAREST_CANDIDATES, k))
    ok = np.zeros((_NEAREST_CANDIDATES, k), dtype=bool)
    for ns, sel in _groups(nsp):
        _sampled_candidates(c, pid[sel], p[sel], ns, sel, best_u, best_d2, (u0, lo, hi, ok))
    # Newton from every candidate (the arithmetic of _power_coeffs and cubic_eval), compiled
    _refine_kernel(c, pid, p, u0, lo, hi, ok, iters, best_u, best_d2)


#: points per chunk of :func:`_refine_kernel` (its Newton steps run over a chunk at a time)
_REFINE_CHUNK = 256


@njit(cache=True, nogil=True)
def _refine_kernel(c, pid, p, u0, lo, hi, ok, iters, best_u,
                   best_d2):  # type: ignore[no-untyped-def]
    """:func:`nearest_on_cubic_each`'s refinement (compiled): per candidate m and point k
    (its cubic c[pid[k]]), ``iters`` Newton steps from u0[m, k] inside lo[m, k] .. hi[m, k]
    (:func:`_newton_kernel`'s downhill steps, the power coefficients of the former numpy
    version: a = ((-p0 + 3 p1) - 3 p2) + p3, b = (3 p0 - 6 p1) + 3 p2, d = -3 p0 + 3 p1),
    the point of the cubic there (:func:`_bernstein_each`'s arithmetic) and, where ok[m, k]
    and nearer than best_d2[k], it replaces best_u[k], best_d2[k] (in place). Candidate by
    candidate, as before; the same numbers."""
    k_n = pid.shape[0]
    nc = _REFINE_CHUNK
    cb = np.empty((8, nc))
    ub = np.empty(nc)
    for m in range(u0.shape[0]):
        for c0 in range(0, k_n, nc):
            n = min(nc, k_n - c0)
            for j in range(n):
                k = c0 + j
                g = pid[k]
                p0x = c[g, 0, 0]
                p0y = c[g, 0, 1]
                p1x = c[g, 1, 0]
                p1y = c[g, 1, 1]
                p2x = c[g, 2, 0]
                p2y = c[g, 2, 1]
                p3x = c[g, 3, 0]
                p3y = c[g, 3, 1]
                cb[0, j] = ((-p0x + 3.0 * p1x) - 3.0 * p2x) + p3x
                cb[1, j] = ((-p0y + 3.0 * p1y) - 3.0 * p2y) + p3y
                cb[2, j] = (3.0 * p0x - 6.0 * p1x) + 3.0 * p2x
                cb[3, j] = (3.0 * p0y - 6.0 * p1y) + 3.0 * p2y
                cb[4, j] = -3.0 * p0x + 3.0 * p1x
                cb[5, j] = -3.0 * p0y + 3.0 * p1y
                cb[6, j] = p[k, 0] - p0x
                cb[7, j] = p[k, 1] - p0y
                ub[j] = u0[m, k]
            for _ in range(iters):
                for j in range(n):
                    k = c0 + j
                    ax = cb[0, j]
                    ay = cb[1, j]
                    bx = cb[2, j]
                    by = cb[3, j]
                    dx = cb[4, j]
                    dy = cb[5, j]
                    lo_k = lo[m, k]
                    hi_k = hi[m, k]
                    ub[j] = newton_param_in(ax, ay, bx, by, dx, dy, cb[6, j], cb[7, j], ub[j],
                                            lo_k, hi_k, True)
            for j in range(n):
                k = c0 + j
                if not ok[m, k]:
                    continue
                g = pid[k]
                t = ub[j]
                s = 1.0 - t
                rx = ((((s * s * s) * c[g, 0, 0] + (3.0 * s * s * t) * c[g, 1, 0])
                       + (3.0 * s * t * t) * c[g, 2, 0]) + (t * t * t) * c[g, 3, 0]) - p[k, 0]
                ry = ((((s * s * s) * c[g, 0, 1] + (3.0 * s * s * t) * c[g, 1, 1])
                       + (3.0 * s * t * t) * c[g, 2, 1]) + (t * t * t) * c[g, 3, 1]) - p[k, 1]
                dn = rx * rx + ry * ry
                if dn < best_d2[k]:
                    best_u[k] = t
                    best_d2[k] = dn


def _groups(keys: np.ndarray) -> list[tuple[int, np.ndarray]]:
    """Per distinct value of ``keys`` (ascending): (value, the ascending indices holding it)
    (``np.flatnonzero(keys == value)`` for each of ``np.unique(keys)``, by one stable
    sort)."""
    if len(keys) == 0:
        return []
    if (keys[1:] == keys[0]).all():  # (mostly one sample count)
        return [(int(keys[0]), np.arange(len(keys)))]
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    cut = np.flatnonzero(sk[1:] != sk[:-1]) + 1
    lo = np.r_[0, cut]
    hi = np.r_[cut, len(sk)]
    return [(int(sk[a]), order[a:b]) for a, b in zip(lo.tolist(), hi.tolist(), strict=True)]


def _unique_inverse(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(x, return_inverse=True)`` for 1-d integers, without its sort where ``x``
    is sorted already (the points of a cubic together, the cubics in order)."""
    if len(x) and (x[1:] >= x[:-1]).all():
        new = np.r_[True, x[1:] != x[:-1]]
        return x[new], np.cumsum(new) - 1
    if len(x) and x.min() >= 0 and x.max() <= 4 * len(x):  # (a table of the values)
        seen = np.zeros(int(x.max()) + 1, dtype=bool)
        seen[x] = True
        rank = np.cumsum(seen) - 1
        return np.flatnonzero(seen).astype(x.dtype, copy=False), rank[x]
    return np.unique(x, return_inverse=True)


def sampled_upper_d2(ctrl: object, pid: object, pts: object, *, seeds: int = 48) -> np.ndarray:
    """Per point the smallest squared distance to the samples of its cubic ``ctrl[pid[k]]``
    that :func:`nearest_on_cubic_each` (same ``seeds``) starts from, with their arithmetic:
    its distance is never larger than the square root of this (a cheap upper bound, exact
    in floating point). ``pid`` sorted (the points of a cubic together) is fastest."""
    c = np.asarray(ctrl, dtype=np.float64).reshape(-1, 4, 2)
    pid = np.asarray(pid, dtype=np.int64).reshape(-1)
    p = np.ascontiguousarray(pts, dtype=np.float64).reshape(-1, 2)
    out = np.empty(len(p))
    if len(p) == 0:
        return out
    nsp = _seed_counts(c, seeds)
    per = nsp[pid]
    cc = np.ascontiguousarray(c)
    for ns, sel in _groups(per):
        o = np.empty(len(sel))
        _upper_kernel(cc, pid[sel], p[sel], np.linspace(0.0, 1.0, ns + 1), o)
        out[sel] = o
    return out


@njit(cache=True, nogil=True)
def _upper_kernel(c, pid, p, su, out):  # type: ignore[no-untyped-def]
    """out[i]: the smallest squared distance of p[i] to cubic c[pid[i]] sampled at ``su``
    (cubic_eval's arithmetic; the samples recomputed when pid changes)."""
    n = su.shape[0]
    sx = np.empty(n)
    sy = np.empty(n)
    last = -1
    for i in range(pid.shape[0]):
        g = pid[i]
        if g != last:
            for j in range(n):
                b0, b1, b2, b3 = bernstein_weights(su[j])
                sx[j] = bernstein_point(b0, b1, b2, b3, c, g, 0)
                sy[j] = bernstein_point(b0, b1, b2, b3, c, g, 1)
            last = g
        px = p[i, 0]
        py = p[i, 1]
        best = np.inf
        for j in range(n):
            dx = px - sx[j]
            dy = py - sy[j]
            v = dx * dx + dy * dy
            if v < best:
                best = v
        out[i] = best


def _sampled_candidates(
    c: np.ndarray,
    pid: np.ndarray,
    p: np.ndarray,
    ns: int,
    out: np.ndarray,
    best_u: np.ndarray,
    best_d2: np.ndarray,
    cands: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> None:
    """The sampled part of :func:`nearest_on_cubic_each` for cubics sampled at ``ns + 1``
    parameters, written at positions ``out``: the best sample (``best_u``, ``best_d2``) of
    each point ``p`` and, per candidate (the best few local minima of the sampled distance,
    not only the smallest: near a cusp or loop the true nearest point can lie in the bracket
    of a sample slightly farther than the best one), its start, bracket and validity
    (``cands`` = u0, lo, hi, ok, each (candidates, K))."""
    u0, lo, hi, ok = cands
    cubs, ci = _unique_inverse(pid)
    cc = np.ascontiguousarray(c[cubs])
    su = np.linspace(0.0, 1.0, ns + 1)
    spx = np.empty((len(cc), ns + 1))  # the samples, the arithmetic of cubic_eval
    spy = np.empty((len(cc), ns + 1))
    tie = np.zeros(len(p), dtype=np.bool_)
    _candidates_kernel(cc, su, ci.astype(np.int64), np.ascontiguousarray(p, dtype=np.float64),
                       np.asarray(out, dtype=np.int64), spx, spy, best_u, best_d2, u0, lo, hi,
                       ok, min(_NEAREST_CANDIDATES, ns + 1), tie)
    if tie.any():  # equal sampled minima: numpy's order of the candidates, as before
        r = np.flatnonzero(tie)
        _sampled_candidates_np(spx, spy, ci[r], p[r], su, ns, out[r], best_u, best_d2, cands)


@njit(cache=True, nogil=True)
def _candidates_kernel(cc, su, ci, p, out, spx, spy, best_u, best_d2, u0, lo, hi, ok, nc,
                       tie):  # type: ignore[no-untyped-def]
    """The samples spx/spy of the cubics ``cc`` at ``su`` (cubic_eval's arithmetic), then
    per point i (against the samples of cubic ci[i], written at out[i]): the first nearest
    sample and its squared distance (best_u, best_d2), and the (up to) ``nc`` local minima
    of the sampled squared distance, smallest first, as candidates (u0 the sample, lo/hi
    its neighbours, ok: one was found); tie[i]: two of the smallest local minima are equal
    (the caller then uses numpy's selection). The numbers of the numpy version."""
    n = su.shape[0]
    ns = n - 1
    for g in range(cc.shape[0]):
        for j in range(n):
            b0, b1, b2, b3 = bernstein_weights(su[j])
            spx[g, j] = bernstein_point(b0, b1, b2, b3, cc, g, 0)
            spy[g, j] = bernstein_point(b0, b1, b2, b3, cc, g, 1)
    d2 = np.empty(n)
    tv = np.empty(nc + 1)
    tj = np.empty(nc + 1, dtype=np.int64)
    for i in range(p.shape[0]):
        g = ci[i]
        o = out[i]
        px = p[i, 0]
        py = p[i, 1]
        best = np.inf
        bi = 0
        for j in range(n):
            dx = px - spx[g, j]
            dy = py - spy[g, j]
            v = dx * dx + dy * dy
            d2[j] = v
            if v < best:
                best = v
                bi = j
        best_u[o] = su[bi]
        best_d2[o] = best
        nt = 0
        eq = False
        for j in range(n):
            v = d2[j]
            if j > 0 and not v <= d2[j - 1]:
                continue
            if j < n - 1 and not v <= d2[j + 1]:
                continue
            # insert (v, j) into the nc + 1 smallest so far
            if nt == nc + 1 and not v < tv[nt - 1]:
                if v == tv[nt - 1]:
                    eq = True
                continue
            pos = nt if nt < nc + 1 else nc
            while pos > 0 and v < tv[pos - 1]:
                tv[pos] = tv[pos - 1]
                tj[pos] = tj[pos - 1]
                pos -= 1
            if pos > 0 and v == tv[pos - 1]:
                eq = True
            tv[pos] = v
            tj[pos] = j
            if nt < nc + 1:
                nt += 1
        for m in range(nc):
            j = tj[m] if m < nt else 0
            ok[m, o] = m < nt
            u0[m, o] = su[j]
            lo[m, o] = su[max(j - 1, 0)]
            hi[m, o] = su[min(j + 1, ns)]
        tie[i] = eq


def _sampled_candidates_np(
    spx: np.ndarray,
    spy: np.ndarray,
    ci: np.ndarray,
    p: np.ndarray,
    su: np.ndarray,
    ns: int,
    out: np.ndarray,
    best_u: np.ndarray,
    best_d2: np.ndarray,
    cands: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> None:
    """The numpy selection of :func:`_sampled_candidates` (rows with equal minima)."""
    u0, lo, hi, ok = cands
    rows = max(1, (_CHUNK_CELLS // 2) // (ns + 1))
    ncand = min(_NEAREST_CANDIDATES, ns + 1)
    for s0 in range(0, len(p), rows):
        q = p[s0 : s0 + rows]
        g = ci[s0 : s0 + rows]
        o = out[s0 : s0 + rows]
        d2 = (q[:, 0:1] - spx[g]) ** 2 + (q[:, 1:2] - spy[g]) ** 2
        local = np.ones_like(d2, dtype=bool)
        local[:, 1:] &= d2[:, 1:] <= d2[:, :-1]
        local[:, :-1] &= d2[:, :-1] <= d2[:, 1:]
        masked = np.where(local, d2, np.inf)
        cand = np.argpartition(masked, ncand - 1, axis=1)[:, :ncand]
        best_u[o] = su[np.argmin(d2, axis=1)]
        best_d2[o] = d2.min(axis=1)
        rowi = np.arange(len(q))
        for m in range(ncand):
            j = cand[:, m]
            ok[m, o] = np.isfinite(masked[rowi, j])
            u0[m, o] = su[j]
            lo[m, o] = su[np.maximum(j - 1, 0)]
            hi[m, o] = su[np.minimum(j + 1, ns)]


def point_segment_distance(pts: object, a: object, b: object) -> np.ndarray:
    """Euclidean distance of each point to the closed segment [a, b].

    ``pts`` (K, 2); ``a``, ``b`` (2,) or (K, 2) (broadcast) -> (K,). A zero-length segment
    is its point.
    """
    p = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    ab = b - a
    ap = p - a
    den = (ab * ab).sum(axis=-1)
    num = (ap * ab).sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), 0.0)
    s = np.clip(s, 0.0, 1.0)
    s = np.asarray(s)[..., None]
    return np.hypot(*(ap - s * ab).reshape(-1, 2).T)


#: squared lengths below this are treated as zero (their reciprocal would overflow)
_TINY_SQUARED = 1e-300


def point_polyline_distance(pts: object, poly: object) -> np.ndarray:
    """Distance of each point to the polyline ``poly`` (true Euclidean distance).

    ``pts`` (K, 2), ``poly`` (N, 2) with N >= 1 -> (K,). Brute force over all segments,
    chunked so that no table exceeds about two million cells.
    """
    p = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
    q = np.asarray(poly, dtype=np.float64).reshape(-1, 2)
    if len(q) == 0:
        raise ValueError("point_polyline_distance: empty polyline")
    if len(q) == 1:
        return np.hypot(*(p - q[0]).T)
    if len(p) * len(q) > 8 * _CHUNK_CELLS:
        return _polyline_distance_rtree(p, q)
    a = q[:-1]
    ab = q[1:] - a
    den = (ab * ab).sum(axis=1)
    # (a segment so short that 1 / its squared length overflows is its start point)
    big = den > _TINY_SQUARED
    inv = np.where(big, 1.0 / np.where(big, den, 1.0), 0.0)
    out = np.full(len(p), np.inf)
    srows = max(1, min(len(a), _CHUNK_CELLS // max(1, min(len(p), 4096))))
    prow = max(1, _CHUNK_CELLS // srows)
    for s0 in range(0, len(a), srows):
        aa = a[s0 : s0 + srows]
        vv = ab[s0 : s0 + srows]
        ii = inv[s0 : s0 + srows]
        for p0 in range(0, len(p), prow):
            pp = p[p0 : p0 + prow]
            dx = pp[:, 0:1] - aa[None, :, 0]
            dy = pp[:, 1:2] - aa[None, :, 1]
            s = np.clip((dx * vv[None, :, 0] + dy * vv[None, :, 1]) * ii[None, :], 0.0, 1.0)
            ex = dx - s * vv[None, :, 0]
            ey = dy - s * vv[None, :, 1]
            d2 = (ex * ex + ey * ey).min(axis=1)
            np.minimum(out[p0 : p0 + prow], d2, out=out[p0 : p0 + prow])
    return np.sqrt(out)


def _polyline_distance_rtree(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Large inputs: GEOS R-tree of the segments (shapely), exact nearest distances."""
    import shapely

    segs = shapely.linestrings(np.stack([q[:-1], q[1:]], axis=1))
    tree = shapely.STRtree(segs)
    pts = shapely.points(p)
    (ip, _), dist = tree.query_nearest(pts, return_distance=True, all_matches=False)
    out = np.full(len(p), np.inf)
    np.minimum.at(out, ip, dist)
    return out


# --- many cubics at once --------------------------------------------------------------
#
# The fitter works on many pieces at a time: every point k belongs to a cubic ``pid[k]``.
# The cubics are held in power form per point, one (4, 2, K) block ``cf`` (rows a, b, d, e;
# x and y) with B(u) = ((a·u + b)·u + d)·u + e, so that each Newton step is a handful of
# element-wise operations over both coordinates of all points of all pieces together.


def power_coeffs_many(ctrl: np.ndarray) -> np.ndarray:
    """Power-basis coefficients of M cubics: ``ctrl`` (M, 4, 2) -> (M, 4, 2) = [a, b, d, e]
    (:func:`power_coeffs_into`'s arithmetic, compiled: :func:`_power_kernel`)."""
    c = np.ascontiguousarray(ctrl, dtype=np.float64)
    out = np.empty(c.shape)
    if not (c.ndim == 3 and c.shape[1:] == (4, 2) and _power_kernel(c, out)):
        power_coeffs_into(out.swapaxes(0, 1), c[:, 0], c[:, 1], c[:, 2], c[:, 3])
    return out


@njit(cache=True, nogil=True)
def _power_kernel(c, out):  # type: ignore[no-untyped-def]
    """:func:`power_coeffs_many` per cubic: a = (-p0 + 3 (p1 - p2)) + p3, b = 3 (p0 + p2)
    - 6 p1, d = 3 (p1 - p0), e = p0 (:func:`power_coeffs_into`'s operations, in its
    order: the same numbers); False (the caller then takes numpy's) where a control point
    is not finite (a NaN's sign bit may come out otherwise)."""
    for m in range(c.shape[0]):
        for j in range(2):
            p0 = c[m, 0, j]
            p1 = c[m, 1, j]
            p2 = c[m, 2, j]
            p3 = c[m, 3, j]
            if not (abs(p0) < np.inf and abs(p1) < np.inf and abs(p2) < np.inf
                    and abs(p3) < np.inf):
                return False
            out[m, 0, j] = (-p0 + 3.0 * (p1 - p2)) + p3
            out[m, 1, j] = 3.0 * (p0 + p2) - 6.0 * p1
            out[m, 2, j] = 3.0 * (p1 - p0)
            out[m, 3, j] = p0
    return True


def power_coeffs_into(
    out: np.ndarray, p0: np.ndarray, p1: np.ndarray, p2: np.ndarray, p3: np.ndarray
) -> np.ndarray:
    """``out[0 .. 3]`` = a, b, d, e of B(u) = ((a u + b) u + d) u + e for the control points
    p0 .. p3 (arrays of one shape, e.g. (M, 2) or (2, M)); returns ``out``."""
    np.add(-p0, 3.0 * (p1 - p2), out=out[0])
    out[0] += p3
    np.subtract(3.0 * (p0 + p2), 6.0 * p1, out=out[1])
    np.multiply(3.0, p1 - p0, out=out[2])
    out[3] = p0
    return out


def gather_coeffs(coef: np.ndarray, pid: np.ndarray) -> np.ndarray:
    """The (4, 2, K) coefficient block (see above) of cubic ``pid[k]`` per point, from the
    (M, 4, 2) coefficients ``coef`` of :func:`power_coeffs_many`."""
    return np.take(coef.transpose(1, 2, 0), pid, axis=2)


#: points per block of :func:`newton_nearest_many` (its (2, K) work arrays stay in cache)
_NEWTON_BLOCK = 1 << 14


def newton_nearest_many(
    cf: np.ndarray,
    p: np.ndarray,
    u: np.ndarray,
    iters: int,
    *,
    lo: np.ndarray | float = 0.0,
    hi: np.ndarray | float = 1.0,
    downhill: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Newton on f(u) = B'(u)·(B(u) − p) for every point with its own cubic (``cf`` the
    (4, 2, K) block, see above, or (4, 2, 1) for one cubic), points ``p`` (2, K), u kept in
    [lo, hi] (default [0, 1]). Where f' <= 0 (the distance is not convex there, Newton
    would climb) no step is taken, or, with ``downhill`` (for narrow brackets around a
    sample), u goes halfway to the end of its bracket that the distance falls towards.
    Returns ``(u, squared distance)``.

    Any returned u gives an upper bound of the true distance (it is the distance to a point
    of the curve), so a test ``dist <= tol`` made with it is never too lenient.
    """
    k = len(u)
    if k <= _NEWTON_BLOCK:
        return _newton_block(cf, p, u, iters, lo, hi, downhill)
    u_out = np.empty(k)
    d2_out = np.empty(k)
    for c in range(0, k, _NEWTON_BLOCK):
        s = slice(c, c + _NEWTON_BLOCK)
        u_out[s], d2_out[s] = _newton_block(
            cf[:, :, s] if cf.shape[2] > 1 else cf,
            p[:, s],
            u[s],
            iters,
            lo[s] if isinstance(lo, np.ndarray) else lo,
            hi[s] if isinstance(hi, np.ndarray) else hi,
            downhill,
        )
    return u_out, d2_out


def _newton_block(
    cf: np.ndarray,
    p: np.ndarray,
    u: np.ndarray,
    iters: int,
    lo: np.ndarray | float,
    hi: np.ndarray | float,
    downhill: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`newton_nearest_many` on one block (compiled, :func:`_newton_kernel`)."""
    k = len(u)
    u_out = np.array(u, dtype=np.float64)  # (a copy: the caller's u is not changed)
    d2 = np.empty(k)
    lo_a = np.ascontiguousarray(lo, dtype=np.float64).reshape(-1)
    hi_a = np.ascontiguousarray(hi, dtype=np.float64).reshape(-1)
    _newton_kernel(
        np.ascontiguousarray(cf, dtype=np.float64),
        np.ascontiguousarray(p, dtype=np.float64),
        u_out,
        d2,
        iters,
        lo_a,
        hi_a,
        downhill,
    )
    return u_out, d2


#: points per chunk of :func:`_newton_kernel`: every Newton step runs over a chunk (the
#: loop over points is then vectorised by the compiler; the chunk stays in L1)
_NEWTON_CHUNK = 512


@njit(cache=True, nogil=True)
def _newton_kernel(cf, p, u, d2, iters, lo, hi, downhill):  # type: ignore[no-untyped-def]
    """Newton on f(u) = B'(u)·(B(u) − p) per point, in place on ``u``; ``d2`` gets the
    squared distances at the final u. ``cf`` (4, 2, K) or (4, 2, 1); ``lo``, ``hi`` of
    length K or 1. (Scalar IEEE arithmetic in the order of the former numpy version, so the
    results are the same bit for bit; per chunk of points step by step, so that the loop
    over the points of a chunk vectorises: the same operations, 3-4x faster.)"""
    k_n = u.shape[0]
    if cf.shape[2] == 1:
        _newton_one_cubic(cf, p, u, d2, iters, lo, hi, downhill)
        return
    one_lo = lo.shape[0] == 1
    one_hi = hi.shape[0] == 1
    for c0 in range(0, k_n, _NEWTON_CHUNK):
        c1 = min(k_n, c0 + _NEWTON_CHUNK)
        for _ in range(iters):
            _newton_step(cf, p, u, c0, c1, lo, hi, one_lo, one_hi, downhill)
    for k in range(k_n):
        uk = u[k]
        rx = ((cf[0, 0, k] * uk + cf[1, 0, k]) * uk + cf[2, 0, k]) * uk - (p[0, k] - cf[3, 0, k])
        ry = ((cf[0, 1, k] * uk + cf[1, 1, k]) * uk + cf[2, 1, k]) * uk - (p[1, k] - cf[3, 1, k])
        d2[k] = rx * rx + ry * ry


@njit(cache=True, nogil=True, inline="always")
def _cubic_point(cf, c, p, k):  # type: ignore[no-untyped-def]
    """:func:`_newton_kernel`'s cubic ``c`` (power coefficients a, b, d) and point ``k``
    relative to its start: (ax, ay, bx, by, dx, dy, qx, qy)."""
    return (cf[0, 0, c], cf[0, 1, c], cf[1, 0, c], cf[1, 1, c], cf[2, 0, c], cf[2, 1, c],
            p[0, k] - cf[3, 0, c], p[1, k] - cf[3, 1, c])


@njit(cache=True, nogil=True, inline="always")
def _newton_step(cf, p, u, c0, c1, lo, hi, one_lo, one_hi, downhill):  # type: ignore[no-untyped-def]
    """One Newton step of :func:`_newton_kernel` for the points c0 .. c1 - 1."""
    for k in range(c0, c1):
        ax, ay, bx, by, dx, dy, qx, qy = _cubic_point(cf, k, p, k)
        lo_k = lo[0] if one_lo else lo[k]
        hi_k = hi[0] if one_hi else hi[k]
        u[k] = newton_param_in(ax, ay, bx, by, dx, dy, qx, qy, u[k], lo_k, hi_k, downhill)


#: :func:`hypot_into`'s common range (both in it: libm's hypot is this arithmetic)
_HYPOT_LARGE = 2.0 ** 511
_HYPOT_TINY = 2.0 ** -459
_HYPOT_RATIO = 2.0 ** -26


@njit(cache=True, nogil=True, inline="always")
def _hypot_common(x, y):  # type: ignore[no-untyped-def]
    """(h, ok): ok where |x| and |y| are in the common range (the larger at most 2^511, the
    smaller at least 2^-459 and over 2^-26 of the larger: finite, no scaling, not widely
    varying), h then libm's hypot(x, y) (glibc's correction of sqrt(x² + y²) after Borges,
    without FMA: the same operations, so the same number); branch-free, so a loop of it
    vectorises."""
    x = abs(x)
    y = abs(y)
    ax = y if x < y else x
    ay = x if x < y else y
    ok = (ax <= _HYPOT_LARGE) & (ay >= _HYPOT_TINY) & (ay > ax * _HYPOT_RATIO)
    h = math.sqrt(ax * ax + ay * ay)
    d1 = h - ay
    t1a = ax * (2.0 * d1 - ax)
    t2a = (d1 - 2.0 * (ax - ay)) * d1
    d2 = h - ax
    t1b = 2.0 * d2 * (ax - 2.0 * ay)
    t2b = (4.0 * d2 - ay) * ay + d2 * d2
    near = h <= 2.0 * ay
    t1 = t1a if near else t1b
    t2 = t2a if near else t2b
    hh = h if ok else 1.0  # (no division by 0 outside the range: libm's value there)
    return h - (t1 + t2) / (2.0 * hh), ok


@njit(cache=True, nogil=True, inline="always")
def hypot_into(xs, ys, n, out, flag):  # type: ignore[no-untyped-def]
    """out[j] = math.hypot(xs[j], ys[j]) for j < n, the same numbers, faster: the common
    range (:func:`_hypot_common`) in a loop that vectorises, the rest (zeros, huge, tiny,
    widely varying, NaN) by libm's hypot in a second pass (``flag`` a bool work array)."""
    for j in range(n):
        h, ok = _hypot_common(xs[j], ys[j])
        out[j] = h
        flag[j] = ok
    for j in range(n):
        if not flag[j]:
            out[j] = math.hypot(xs[j], ys[j])


@njit(cache=True, nogil=True, inline="always")
def newton_param(ax, ay, bx, by, dx, dy, qx, qy, uk):  # type: ignore[no-untyped-def]
    """One Newton step of the parameter ``uk`` of the cubic a u^3 + b u^2 + d u (power form,
    its start at the origin) towards the point of it nearest (qx, qy) (relative to the start
    too), clamped to [0, 1]; no step where the squared distance is not convex (the compiled
    fitting kernels' reparametrisation; inlined, so their arithmetic is unchanged)."""
    return newton_param_in(ax, ay, bx, by, dx, dy, qx, qy, uk, 0.0, 1.0, False)


@njit(cache=True, nogil=True, inline="always")
def newton_param_in(ax, ay, bx, by, dx, dy, qx, qy, uk, lo, hi,
                    downhill):  # type: ignore[no-untyped-def]
    """:func:`newton_param` clamped to [lo, hi] instead, and with ``downhill`` halving the
    way towards the end downhill where the squared distance is not convex (instead of no
    step): :func:`_newton_kernel`'s step. Inlined: the callers' arithmetic is unchanged."""
    rx = ((ax * uk + bx) * uk + dx) * uk - qx  # B(u) - p
    ry = ((ay * uk + by) * uk + dy) * uk - qy
    d1x = (3.0 * ax * uk + 2.0 * bx) * uk + dx  # B'(u)
    d1y = (3.0 * ay * uk + 2.0 * by) * uk + dy
    f = d1x * rx + d1y * ry  # f = B'·(B - p)
    fp = (6.0 * ax * uk + 2.0 * bx) * rx + (6.0 * ay * uk + 2.0 * by) * ry
    fp += d1x * d1x  # f' = B''·(B - p) + |B'|^2
    fp += d1y * d1y
    if fp <= 0.0:  # not convex here: no step, or halve the way downhill
        if downhill:
            uk = 0.5 * (uk + (hi if f < 0.0 else lo))
    else:
        uk -= f / fp
    return min(max(uk, lo), hi)


@njit(cache=True, nogil=True)
def _newton_one_cubic(cf, p, u, d2, iters, lo, hi, downhill):  # type: ignore[no-untyped-def]
    """The scalar :func:`_newton_kernel` (one point after the other), for ``cf`` (4, 2, 1)
    or (4, 2, K)."""
    k_n = u.shape[0]
    one_c = cf.shape[2] == 1
    one_lo = lo.shape[0] == 1
    one_hi = hi.shape[0] == 1
    for k in range(k_n):
        c = 0 if one_c else k
        ax, ay, bx, by, dx, dy, qx, qy = _cubic_point(cf, c, p, k)
        lo_k = lo[0] if one_lo else lo[k]
        hi_k = hi[0] if one_hi else hi[k]
        uk = u[k]
        for _ in range(iters):
            uk = newton_param_in(ax, ay, bx, by, dx, dy, qx, qy, uk, lo_k, hi_k, downhill)
        rx = ((ax * uk + bx) * uk + dx) * uk - qx
        ry = ((ay * uk + by) * uk + dy) * uk - qy
        u[k] = uk
        d2[k] = rx * rx + ry * ry


def nearest_on_cubics(
    ctrl: np.ndarray, pid: np.ndarray, pts: np.ndarray, *, seeds: int = 48, iters: int = 6
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`nearest_on_cubic` for many points, each against its own cubic ``ctrl[pid[k]]``.

    ``ctrl`` (M, 4, 2), ``pid`` (K,) ints, ``pts`` (K, 2) -> ``(t, dist)`` (K,) each. Seeded
    like :func:`nearest_on_cubic` (``seeds + 1`` samples per cubic, best sample kept when
    Newton does worse), so it is robust against local minima.
    """
    c = np.asarray(ctrl, dtype=np.float64).reshape(-1, 4, 2)
    p = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
    k = len(p)
    if k == 0:
        return np.zeros(0), np.zeros(0)
    su, basis = seed_basis(seeds)
    samp = np.empty((len(c), len(su), 2))  # (M, S, 2): np.einsum("sk,mkd->msd", basis, c)
    _samples_kernel(basis, np.ascontiguousarray(c), samp)
    t_out = np.empty(k)
    d_out = np.empty(k)
    _seeded_kernel(power_coeffs_many(c), np.ascontiguousarray(pid, dtype=np.intp),
                   np.ascontiguousarray(p), samp, su, iters, t_out, d_out)
    return t_out, d_out


def seed_basis(seeds: int = 48) -> tuple[np.ndarray, np.ndarray]:
    """The sample parameters of :func:`nearest_on_cubics` (``seeds + 1`` of them, evenly
    spread over [0, 1]) and their Bernstein basis (S, 4)."""
    su = np.linspace(0.0, 1.0, seeds + 1)
    s = 1.0 - su
    return su, np.stack([s**3, 3.0 * s * s * su, 3.0 * s * su * su, su**3], axis=1)


@njit(cache=True, nogil=True)
def _samples_kernel(basis, c, out):  # type: ignore[no-untyped-def]
    """out[m, s] = sum over k of basis[s, k] * c[m, k], summed in order (the numbers of
    the former ``np.einsum("sk,mkd->msd", basis, c)``)."""
    for m in range(c.shape[0]):
        bernstein_samples(basis, c, m, out[m])


@njit(cache=True, nogil=True, inline="always")
def bernstein_weights(t):  # type: ignore[no-untyped-def]
    """The cubic Bernstein weights at t, cubic_eval's arithmetic: (1 - t)³, 3 (1 - t)² t,
    3 (1 - t) t², t³ (each multiplied left to right)."""
    s = 1.0 - t
    return s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t


@njit(cache=True, nogil=True, inline="always")
def bernstein_point(b0, b1, b2, b3, c, m, d):  # type: ignore[no-untyped-def]
    """Coordinate d of the cubic c[m] (control points, (M, 4, 2)) at the weights b0..b3,
    summed in order ((b0 c0 + b1 c1) + b2 c2) + b3 c3 (cubic_eval's and np.einsum's
    numbers): the one sampling loop of the compiled kernels."""
    return ((b0 * c[m, 0, d] + b1 * c[m, 1, d]) + b2 * c[m, 2, d]) + b3 * c[m, 3, d]


@njit(cache=True, nogil=True, inline="always")
def bernstein_samples(basis, c, m, out):  # type: ignore[no-untyped-def]
    """out[i] = the cubic c[m] at the sample i of ``basis`` (S, 4) (:func:`bernstein_point`)."""
    for i in range(basis.shape[0]):
        b0 = basis[i, 0]
        b1 = basis[i, 1]
        b2 = basis[i, 2]
        b3 = basis[i, 3]
        for d in range(2):
            out[i, d] = bernstein_point(b0, b1, b2, b3, c, m, d)


@njit(cache=True, nogil=True, inline="always")
def seeded_nearest(cm, m, samp, su, iters, px, py):  # type: ignore[no-untyped-def]
    """One point's :func:`_seeded_kernel` (its numbers): the nearest of the samples
    ``samp`` (S, 2) of cubic m (power coefficients ``cm``), Newton from there, the better of
    both: (t, distance)."""
    j = 0
    best = np.inf
    for i in range(samp.shape[0]):
        ex = px - samp[i, 0]
        ey = py - samp[i, 1]
        v = ex * ex + ey * ey
        if v != v:
            j = i
            best = v
            break
        if i == 0 or v < best:
            j = i
            best = v
    ax = cm[m, 0, 0]
    ay = cm[m, 0, 1]
    bx = cm[m, 1, 0]
    by = cm[m, 1, 1]
    dx = cm[m, 2, 0]
    dy = cm[m, 2, 1]
    qx = px - cm[m, 3, 0]
    qy = py - cm[m, 3, 1]
    uk = su[j]
    for _ in range(iters):
        uk = newton_param(ax, ay, bx, by, dx, dy, qx, qy, uk)
    rx = ((ax * uk + bx) * uk + dx) * uk - qx
    ry = ((ay * uk + by) * uk + dy) * uk - qy
    dn = rx * rx + ry * ry
    if dn < best:
        return uk, math.sqrt(dn)
    return su[j], math.sqrt(best)


#: points per chunk of :func:`_seeded_kernel` (its Newton steps run over a chunk at a time)
_SEEDED_CHUNK = 256


@njit(cache=True, nogil=True)
def _seeded_kernel(cm, pid, p, samp, su, iters, t_out, d_out):  # type: ignore[no-untyped-def]
    """:func:`nearest_on_cubics` per point (compiled): the nearest of the cubic's samples
    ``samp[pid[k]]`` (at parameters ``su``; the first on ties, or the first NaN), Newton
    from there (as :func:`_newton_kernel`, bit for bit), the better of both. The Newton
    steps run step by step over chunks of points (the same numbers per point)."""
    nc = _SEEDED_CHUNK
    cb = np.empty((8, nc))
    ub = np.empty(nc)
    u0b = np.empty(nc)
    bestb = np.empty(nc)
    for k0 in range(0, len(pid), nc):
        n = min(nc, len(pid) - k0)
        for jj in range(n):
            k = k0 + jj
            m = pid[k]
            px = p[k, 0]
            py = p[k, 1]
            j = 0
            best = np.inf
            for i in range(samp.shape[1]):
                ex = px - samp[m, i, 0]
                ey = py - samp[m, i, 1]
                v = ex * ex + ey * ey
                if v != v:
                    j = i
                    best = v
                    break
                if i == 0 or v < best:
                    j = i
                    best = v
            bestb[jj] = best
            u0b[jj] = su[j]
            ub[jj] = su[j]
            cb[0, jj] = cm[m, 0, 0]
            cb[1, jj] = cm[m, 0, 1]
            cb[2, jj] = cm[m, 1, 0]
            cb[3, jj] = cm[m, 1, 1]
            cb[4, jj] = cm[m, 2, 0]
            cb[5, jj] = cm[m, 2, 1]
            cb[6, jj] = px - cm[m, 3, 0]
            cb[7, jj] = py - cm[m, 3, 1]
        for _ in range(iters):
            for jj in range(n):
                ax = cb[0, jj]
                ay = cb[1, jj]
                bx = cb[2, jj]
                by = cb[3, jj]
                dx = cb[4, jj]
                dy = cb[5, jj]
                uk = ub[jj]
                ub[jj] = newton_param(ax, ay, bx, by, dx, dy, cb[6, jj], cb[7, jj], uk)
        for jj in range(n):
            k = k0 + jj
            uk = ub[jj]
            rx = ((cb[0, jj] * uk + cb[2, jj]) * uk + cb[4, jj]) * uk - cb[6, jj]
            ry = ((cb[1, jj] * uk + cb[3, jj]) * uk + cb[5, jj]) * uk - cb[7, jj]
            dn = rx * rx + ry * ry
            best = bestb[jj]
            if dn < best:
                t_out[k] = uk
                d_out[k] = math.sqrt(dn)
            else:
                t_out[k] = u0b[jj]
                d_out[k] = math.sqrt(best)
