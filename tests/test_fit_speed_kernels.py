"""Issue 16 (s6, sparse whole-unit speed): compiled replacements of numpy steps of the fit
must give the same numbers as the steps they replace (the fitted arrays stay the same bit
for bit). Each test compares a compiled kernel with the plain computation it replaced:
libm's hypot, the acceptance test's verdicts, the windowed polyline distance over every
segment of its window, Newton's refinement of the nearest points, and the least-squares
handles."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit
from test_fit_accept_kernels import _pieces  # (tests/ is on the path under pytest)

from galvo_core import fit as fitmod
from galvo_core import geometry as geo
from galvo_core.geometry import (
    gather_coeffs,
    hypot_into,
    nearest_on_cubic_each,
    newton_nearest_many,
    power_coeffs_many,
)


@njit(cache=False)
def _hypot_fast(x, y, out):  # (hypot_into over arrays)
    flag = np.empty(len(x), dtype=np.bool_)
    hypot_into(x, y, len(x), out, flag)


@njit(cache=False)
def _hypot_libm(x, y, out):
    for i in range(len(x)):
        out[i] = math.hypot(x[i], y[i])


def test_hypot_into_is_libms_hypot() -> None:
    rng = np.random.default_rng(11)
    n = 400_000
    xs = [rng.normal(size=n) * 100.0,  # the fit's range
          rng.normal(size=n) * 10.0 ** rng.integers(-300, 300, n),  # every magnitude
          np.round(rng.normal(size=n) * 50.0)]  # whole units, zeros among them
    ys = [rng.normal(size=n) * 100.0,
          rng.normal(size=n) * 10.0 ** rng.integers(-300, 300, n),
          np.round(rng.normal(size=n) * 50.0) * rng.integers(0, 2, n)]
    near = rng.normal(size=n)  # nearly equal, and widely varying
    xs.append(near)
    ys.append(near * (1.0 + rng.normal(size=n) * 10.0 ** rng.integers(-17, 0, n)))
    sp = np.array([0.0, -0.0, 5e-324, 1e-310, 2.0**-459, 2.0**-511, 1e-300, 1.0, 3.0, -4.0,
                   2.0**511, 1e308, 1.7e308, np.inf, -np.inf, np.nan])
    gx, gy = np.meshgrid(sp, sp)
    xs.append(gx.ravel())
    ys.append(gy.ravel())
    for x, y in zip(xs, ys, strict=True):
        a = np.empty(len(x))
        b = np.empty(len(x))
        _hypot_fast(x, y, a)
        _hypot_libm(x, y, b)
        same = (a == b) | (np.isnan(a) & np.isnan(b))
        assert same.all(), (x[~same][:3], y[~same][:3], a[~same][:3], b[~same][:3])
    # (sqrt(x² + y²) alone differs: the correction matters)
    x, y = xs[0], ys[0]
    assert (np.sqrt(x * x + y * y) != np.hypot(x, y)).any()


@pytest.mark.parametrize("rounded", [False, True])
@pytest.mark.parametrize("seed", [4, 5])
def test_quick_acceptance_gives_the_full_verdicts(seed: int, rounded: bool) -> None:
    """_accept without ``full`` (the piece stops at its first point left over the bound)
    gives the verdicts of the full test, and the passing pieces' bounds, parameters and
    distances, at bounds where both verdicts occur and the seeded search decides some."""
    ctrl, i0, i1, work, arc = _pieces(seed, rounded=rounded)
    m = len(ctrl)
    bf = fitmod._BatchFitter.__new__(fitmod._BatchFitter)
    bf.work, bf.arc, bf.quant = work, arc, None
    full0 = bf._accept(ctrl, i0, i1, np.full(m, np.inf), full=True)
    worst = full0[1]
    both = 0
    for scale in (0.5, 0.9, 0.999999, 1.000001, 1.5, 3.0, 5.0):
        e2 = worst * scale + 1e-12
        ok_f, em_f, d_f, st = bf._accept(ctrl, i0, i1, e2, full=True)
        ok_q, em_q, d_q, _ = bf._accept(ctrl, i0, i1, e2)
        assert np.array_equal(ok_f, ok_q), scale
        assert np.array_equal(em_f[ok_f], em_q[ok_q])
        cnt = i1 - i0 + 1
        pid = np.repeat(np.arange(m), cnt)
        sel = ok_f[pid]
        assert np.array_equal(d_f[sel], d_q[sel])
        both += bool(ok_f.any() and (~ok_f).any())
    assert both >= 3


def _window_min(px, py, poly, at, k):
    """The windowed distance as before: every segment of the window, its arithmetic."""
    ns = len(poly) - 1
    lo = max(0, min(at - k, ns - 1))
    hi = min(ns - 1, max(at + k, 0))
    best = np.inf
    for j in range(lo, hi + 1):
        a = poly[j]
        v = poly[j + 1] - a
        dx, dy = px - a[0], py - a[1]
        den = v[0] * v[0] + v[1] * v[1]
        u = 0.0
        if den > 0.0:
            u = min(1.0, max(0.0, (dx * v[0] + dy * v[1]) / den))
        ex, ey = dx - u * v[0], dy - u * v[1]
        best = min(best, ex * ex + ey * ey)
    return math.sqrt(best)


@njit(cache=False)
def _win(px, py, poly, at, k, cum, ub):
    return fitmod._win_d(px, py, poly, 0, len(poly) - 1, at, k, cum, ub)


@njit(cache=False)
def _full(px, py, poly, at, cum, ub):
    return fitmod._full_d(px, py, poly, 0, len(poly), at, cum, ub)


@njit(cache=False)
def _brute(px, py, poly):
    return fitmod._brute_d(px, py, poly, 0, len(poly))


def test_pruned_polyline_distances_are_the_plain_ones() -> None:
    """Skipping the segments that cannot be nearer gives the same smallest distance as
    every segment of the window (and of the whole polyline), on wiggly rounded polylines
    with repeated points, for samples near and far."""
    rng = np.random.default_rng(3)
    for trial in range(30):
        n = int(rng.integers(5, 400))
        t = np.cumsum(rng.uniform(0.0, 0.2, n))
        poly = np.stack([40.0 * np.cos(t) + rng.normal(0, 0.5, n),
                         25.0 * np.sin(2.0 * t) + rng.normal(0, 0.5, n)], axis=1)
        if trial % 2:
            poly = np.round(poly)
        cum = np.r_[0.0, np.cumsum(np.hypot(*np.diff(poly, axis=0).T))]
        for _ in range(40):
            j = int(rng.integers(0, n))
            p = poly[j] + rng.normal(0.0, rng.choice([0.3, 3.0, 30.0]), 2)
            at = int(np.clip(j + rng.integers(-20, 20), -1, n - 1))
            near = _win(p[0], p[1], poly, at, 2, cum, np.inf)
            for k in (2, 8, 64):
                want = _window_min(p[0], p[1], poly, at, k)
                assert _win(p[0], p[1], poly, at, k, cum, np.inf) == want
                # (a wider window, bounded by a narrower one's distance)
                assert _win(p[0], p[1], poly, at, k, cum, near) == want
            want = _brute(p[0], p[1], poly)
            assert want == geo.point_polyline_distance(p[None], poly)[0]
            assert _full(p[0], p[1], poly, at, cum, np.inf) == want
            # (bounded by a windowed distance: the other arithmetic)
            assert _full(p[0], p[1], poly, at, cum, near) == want


def test_short_polylines_measured_as_point_polyline_distance() -> None:
    rng = np.random.default_rng(12)
    for n in (2, 3, 17, 130):
        poly = np.round(np.cumsum(rng.normal(0.0, 2.0, (n, 2)), axis=0))
        poly[n // 2] = poly[n // 2 - 1]  # (a repeated point)
        samp = poly[0] + rng.normal(0.0, 5.0, (200, 2)) + rng.uniform(0, 1, (200, 1)) * (
            poly[-1] - poly[0])
        got = fitmod._polyline_distance_over(samp, poly, 0.5, 64)
        assert np.array_equal(got, geo.point_polyline_distance(samp, poly))


def test_compiled_refinement_gives_the_numpy_nearest_points() -> None:
    """nearest_on_cubic_each's compiled Newton refinement of its candidates gives the
    numbers of the former numpy version (Newton per candidate with newton_nearest_many,
    the curve point by _bernstein_each, the better kept)."""
    rng = np.random.default_rng(8)
    ctrl = rng.uniform(-30.0, 30.0, (40, 4, 2))
    ctrl[::5] = np.round(ctrl[::5])  # (loops, cusps and plain arcs among them)
    pid = np.sort(rng.integers(0, len(ctrl), 3000))
    pts = geo._bernstein_each(ctrl[pid], rng.uniform(0, 1, len(pid))) + rng.normal(
        0.0, 3.0, (len(pid), 2))
    u_new, d_new = nearest_on_cubic_each(ctrl, pid, pts, seeds=24, iters=5)

    def numpy_refine(c, pid, p, u0, lo, hi, ok, iters, best_u, best_d2):
        p0, p1, p2, p3 = c[:, 0], c[:, 1], c[:, 2], c[:, 3]
        coef = (-p0 + 3.0 * p1 - 3.0 * p2 + p3, 3.0 * p0 - 6.0 * p1 + 3.0 * p2,
                -3.0 * p0 + 3.0 * p1, p0)
        cf = gather_coeffs(np.stack(coef, axis=1), pid)
        for m in range(len(u0)):
            u = newton_nearest_many(cf, p.T, u0[m], iters, lo=lo[m], hi=hi[m],
                                    downhill=True)[0]
            r = geo._bernstein_each(c[pid], u) - p
            dn = r[:, 0] * r[:, 0] + r[:, 1] * r[:, 1]
            better = ok[m] & (dn < best_d2)
            best_u[better] = u[better]
            best_d2[better] = dn[better]

    orig = geo._refine_kernel
    try:
        geo._refine_kernel = numpy_refine
        u_old, d_old = nearest_on_cubic_each(ctrl, pid, pts, seeds=24, iters=5)
    finally:
        geo._refine_kernel = orig
    assert np.array_equal(u_new, u_old)
    assert np.array_equal(d_new, d_old)


def test_compiled_least_squares_are_the_numpy_ones() -> None:
    """_least_squares (compiled, one piece at a time, its sample read from the input)
    gives the handles of the former numpy version: the strided sample, Schneider's sums
    in the order of the points (np.bincount), twice 2 Newton steps."""
    ctrl, i0, i1, work, arc = _pieces(9, rounded=True)
    m = len(ctrl)
    rng = np.random.default_rng(9)
    bf = fitmod._BatchFitter.__new__(fitmod._BatchFitter)
    bf.work, bf.arc = work, arc
    bf.q = np.concatenate([work[i0], work[i1]])
    A, B = np.arange(m), np.arange(m) + m
    ang = rng.uniform(0, 2 * np.pi, (2 * m, 1))
    tan = np.hstack([np.cos(ang), np.sin(ang)])
    bf.t_out, bf.t_in = tan, tan[::-1].copy()
    got, gok = bf._least_squares(A, B, i0, i1)
    # the former numpy version
    L = i1 - i0 - 1
    stride = np.maximum(1, -(-L // fitmod._BISECT_SAMPLE))
    cnt = -(-L // stride)
    pid = np.repeat(np.arange(m), cnt)
    off = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    ix = i0[pid] + 1 + stride[pid] * off
    span = arc[i1] - arc[i0]
    u = (arc[ix] - arc[i0][pid]) / np.where(span > 0, span, 1.0)[pid]
    pts = work[ix]
    p0, p3, t0, t3 = bf.q[A], bf.q[B], bf.t_out[A], bf.t_in[B]
    chord = np.hypot(*(p3 - p0).T)
    for it in range(3):
        s = 1.0 - u
        b0, b1, b2, b3 = s * s * s, 3 * s * s * u, 3 * s * u * u, u * u * u
        a1 = b1[:, None] * t0[pid]
        a2 = -b2[:, None] * t3[pid]
        r = pts - (b0 + b1)[:, None] * p0[pid] - (b2 + b3)[:, None] * p3[pid]
        c11, c12, c22, x1, x2 = (np.bincount(pid, w, m) for w in (
            (a1 * a1).sum(1), (a1 * a2).sum(1), (a2 * a2).sum(1), (r * a1).sum(1),
            (r * a2).sum(1)))
        with np.errstate(divide="ignore", invalid="ignore"):
            det = c11 * c22 - c12 * c12
            al = (x1 * c22 - x2 * c12) / det
            be = (c11 * x2 - c12 * x1) / det
        ok = (np.abs(det) > 1e-12 * (c11 * c22 + 1e-300)) & (al > 0) & (be > 0)
        ok &= (al < 2.0 * chord) & (be < 2.0 * chord)
        al = np.where(ok, al, chord / 3.0)
        be = np.where(ok, be, chord / 3.0)
        ref = np.stack([p0, p0 + al[:, None] * t0, p3 - be[:, None] * t3, p3], axis=1)
        if it == 2:
            break
        cf = gather_coeffs(power_coeffs_many(ref), pid)
        u, _ = newton_nearest_many(cf, pts.T, u, 2)
    assert np.array_equal(got, ref)
    assert np.array_equal(gok, ok)
    assert ok.any() and (~ok).any()


def test_compiled_power_coeffs_are_numpys_bit_for_bit() -> None:
    """power_coeffs_many (compiled, s11) gives power_coeffs_into's numbers bit for bit, also
    where they overflow, and takes numpy's own path for non-finite control points."""
    rng = np.random.default_rng(11)
    for m in (0, 1, 9, 500):
        scale = rng.choice([1e-300, 1e-5, 1.0, 1e3, 1e300, 1e308], size=(m, 4, 2))
        with np.errstate(over="ignore"):
            c = rng.normal(size=(m, 4, 2)) * scale
        if m > 1:
            c[m // 2, 1, 0] = np.nan if m % 2 else -np.inf
        want = np.empty(c.shape)
        with np.errstate(all="ignore"):
            geo.power_coeffs_into(want.swapaxes(0, 1), c[:, 0], c[:, 1], c[:, 2], c[:, 3])
            got = power_coeffs_many(c)
        assert got.tobytes() == want.tobytes()


def test_unique_and_groups_without_sorting_are_numpys() -> None:
    """geometry's grouping of points by sample count and np.unique(..., return_inverse)
    shortcuts (s11) give numpy's arrays, sorted or not, dense or sparse values."""
    rng = np.random.default_rng(5)
    for n in (1, 2, 7, 3000):
        for hi in (1, 4, 60, 10 ** 7):
            x = rng.integers(0, hi, n).astype(np.intp)
            for y in (x, np.sort(x)):
                u, inv = np.unique(y, return_inverse=True)
                u2, inv2 = geo._unique_inverse(y)
                assert u2.dtype == u.dtype and np.array_equal(u2, u)
                assert np.array_equal(inv2, inv)
                groups = geo._groups(y)
                assert [v for v, _ in groups] == np.unique(y).tolist()
                for v, sel in groups:
                    assert np.array_equal(sel, np.flatnonzero(y == v))


def test_distances_up_to_a_stop_are_the_full_ones() -> None:
    """_distance_over_upto (s11: the smooth-stretch pass stops at the first target over its
    limit) measures the same numbers as _distance_over, in order, up to the first over
    ``stop`` (all of them with stop inf), on short (brute force), one-point and long
    polylines."""
    rng = np.random.default_rng(21)
    for n in (1, 2, 40, 600):
        poly = np.round(np.cumsum(rng.normal(0.0, 2.0, (n, 2)), axis=0))
        samp = poly[rng.integers(0, n, 300)] + rng.normal(0.0, 1.5, (300, 2))
        full = fitmod._distance_over(samp, poly, 0.5, 64)
        d, cnt = fitmod._distance_over_upto(samp, poly, 0.5, 64, np.inf)
        assert cnt == len(samp) and np.array_equal(d, full)
        for stop in (0.2, 1.0, 3.0, 100.0):
            d, cnt = fitmod._distance_over_upto(samp, poly, 0.5, 64, stop)
            assert np.array_equal(d[:cnt], full[:cnt])
            assert (full[:cnt - 1] <= stop).all()
            if cnt < len(samp):
                assert full[cnt - 1] > stop
            else:
                assert (full[:-1] <= stop).all()


def test_design_off_with_a_limit_is_none_exactly_when_over_it() -> None:
    """_design_off with a limit (s11: it stops at the first target over it) answers None
    exactly where the unlimited measure's first distance is over the limit, else that
    measure's numbers."""
    rng = np.random.default_rng(4)
    t = np.linspace(0.0, 3.0, 400)
    W = np.round(np.stack([200.0 * np.cos(t), 150.0 * np.sin(t)], axis=1))
    est = W + rng.normal(0.0, 0.3, W.shape)
    valid = rng.uniform(size=len(W)) > 0.2
    for _ in range(60):
        f = int(rng.integers(0, 300))
        e = f + int(rng.integers(5, 99))
        p0, p3 = W[f], W[e]
        if rng.uniform() < 0.5:
            ctrl = np.stack([p0, p3]).astype(np.float64)
        else:
            mid = W[(f + e) // 2] + rng.normal(0.0, 2.0, 2)
            ctrl = np.stack([p0, p0 + 0.6 * (mid - p0), p3 + 0.6 * (mid - p3), p3])
        free = fitmod._design_off(W, est, valid, ctrl, f, e, 0.25)
        assert free is not None
        for limit in (0.1, 0.5, 1.0, 2.0, 10.0):
            got = fitmod._design_off(W, est, valid, ctrl, f, e, 0.25, limit)
            if free[0] > limit:
                assert got is None
            else:
                assert got == free


def test_chunked_nearest_points_are_the_one_call_ones(monkeypatch: pytest.MonkeyPatch) -> None:
    """nearest_on_cubic_each over chunks of its points on the kernel threads (s11) gives
    the one-thread numbers."""
    from galvo_core import parallel

    rng = np.random.default_rng(9)
    ctrl = rng.uniform(-30.0, 30.0, (50, 4, 2))
    pid = rng.integers(0, len(ctrl), 5000)
    pts = geo._bernstein_each(ctrl[pid], rng.uniform(0, 1, len(pid))) + rng.normal(
        0.0, 3.0, (len(pid), 2))
    monkeypatch.setattr(parallel, "THREADS", 1)
    one = nearest_on_cubic_each(ctrl, pid, pts, seeds=16, iters=4)
    monkeypatch.setattr(parallel, "THREADS", 3)
    monkeypatch.setattr(parallel, "MIN_WORK", 0)
    three = nearest_on_cubic_each(ctrl, pid, pts, seeds=16, iters=4)
    assert np.array_equal(one[0], three[0]) and np.array_equal(one[1], three[1])


def test_compiled_handle_order_is_numpys() -> None:
    """_handles_in_order compiled (s11) answers as numpy's sum of the products did, also
    on overflowing and non-finite control points."""
    rng = np.random.default_rng(2)
    for m in (0, 1, 100, 3000):
        scale = rng.choice([1e-300, 1.0, 1e200, 1e308], size=(m, 4, 2))
        with np.errstate(all="ignore"):
            c = rng.normal(size=(m, 4, 2)) * scale
            if m > 3:
                c[1, 2, 0] = np.nan
                c[2, 3, 1] = np.inf
            want = ((c[:, 2] - c[:, 1]) * (c[:, 3] - c[:, 0])).sum(axis=1) > 0.0
            got = fitmod._handles_in_order(c)
        assert np.array_equal(got, want)
