"""Issue 16 (s7, sparse whole-unit speed): the smooth-stretch pass's compiled steps
(:func:`fit._design_off`, :func:`fit._seg_fits`) must give the numbers of the numpy code
they replaced, also where (s14) they measure only the samples that can matter
(:func:`fit._max_over`: the same numbers over the exactness limit, upper bounds at or under
it that may differ from the former windows' in rare cases). Each test compares them
with that former code, copied here, on arcs rounded to whole units like the fitter's
rounded input. :func:`fit._ls_cubic`, compiled whole in s14, sums its normal equations in
order (numpy's dot products sum in blocks): the same cubic up to that rounding."""

from __future__ import annotations

import math

import numpy as np
import pytest

from galvo_core import fit as fitmod
from galvo_core.geometry import cubic_eval, nearest_on_cubic, point_segment_distance


def _design_off_numpy(W, est, valid, ctrl, f, e, h, limit=math.inf):
    """The former :func:`fit._design_off`."""
    if len(ctrl) == 2:
        length = float(np.hypot(*(ctrl[1] - ctrl[0])))
        m = max(2, math.ceil(length / h) + 1)
        samp = ctrl[0] + np.linspace(0.0, 1.0, m)[:, None] * (ctrl[1] - ctrl[0])
    else:
        length = float(np.hypot(*np.diff(ctrl, axis=0).T).sum())
        m = max(16, math.ceil(length / h) + 1)
        samp = cubic_eval(ctrl, np.linspace(0.0, 1.0, m))
    v = np.flatnonzero(valid[f:e + 1]) + f
    d1 = 0.0
    lim = fitmod._STRETCH_EXACT * h
    if len(v):
        v2 = v[:-1][np.diff(v) == 1]
        key = np.concatenate([2 * v, 2 * v2 + 1])
        tp = np.concatenate([est[v], 0.5 * (est[v2] + est[v2 + 1])])[np.argsort(key)]
        d1 = float(fitmod._polyline_distance_over(tp, samp, lim, 64).max())
    if d1 > limit:
        return None
    poly = np.where(valid[f:e + 1, None], est[f:e + 1], W[f:e + 1])
    return d1, float(fitmod._polyline_distance_over(samp, poly, lim).max())


def _seg_fits_numpy(W, ctrl, first, last, bound, h) -> bool:
    """The former :func:`fit._seg_fits`."""
    loc = W[first:last + 1]
    if len(ctrl) == 2:
        d = point_segment_distance(loc, ctrl[0], ctrl[1])
        length = float(np.hypot(*(ctrl[1] - ctrl[0])))
        m = max(2, math.ceil(length / h) + 1)
        samp = ctrl[0] + np.linspace(0.0, 1.0, m)[:, None] * (ctrl[1] - ctrl[0])
    else:
        _, d = nearest_on_cubic(ctrl, loc, seeds=64, iters=8)
        length = float(np.hypot(*np.diff(ctrl, axis=0).T).sum())
        m = max(16, math.ceil(length / h) + 1)
        samp = cubic_eval(ctrl, np.linspace(0.0, 1.0, m))
    if d.max() > bound:
        return False
    return bool(fitmod._polyline_distance_over(samp, loc, bound - 0.5 * h).max()
                <= bound - 0.5 * h)


def _ls_cubic_numpy(p0, p3, tg):
    """The former :func:`fit._ls_cubic`."""
    c = np.hypot(*np.diff(tg, axis=0).T)
    tot = c.sum()
    if len(tg) < 4 or tot <= 0.0:
        return None
    t = np.r_[0.0, np.cumsum(c)] / tot
    ctrl = None
    for it in range(fitmod._STRETCH_ITERS + 1):
        s = 1.0 - t
        if ctrl is not None:
            d1 = 3.0 * ((s * s)[:, None] * (ctrl[1] - ctrl[0])
                        + (2.0 * s * t)[:, None] * (ctrl[2] - ctrl[1])
                        + (t * t)[:, None] * (ctrl[3] - ctrl[2]))
            d2 = 6.0 * (s[:, None] * (ctrl[2] - 2.0 * ctrl[1] + ctrl[0])
                        + t[:, None] * (ctrl[3] - 2.0 * ctrl[2] + ctrl[1]))
            r = cubic_eval(ctrl, t) - tg
            den = (d1 * d1).sum(axis=1) + (r * d2).sum(axis=1)
            dt = np.where(den > 0.0, (r * d1).sum(axis=1) / np.where(den > 0.0, den, 1.0),
                          0.0)
            t = np.clip(t - dt, 0.0, 1.0)
            s = 1.0 - t
            if it == fitmod._STRETCH_ITERS:
                return ctrl
        b1 = 3.0 * s * s * t
        b2 = 3.0 * s * t * t
        r = tg - (s ** 3)[:, None] * p0 - (t ** 3)[:, None] * p3
        a11, a12, a22 = b1 @ b1, b1 @ b2, b2 @ b2
        det = a11 * a22 - a12 * a12
        if not det > 1e-12 * max(a11 * a22, 1e-300):
            return ctrl
        r1, r2 = b1 @ r, b2 @ r
        ctrl = np.stack([p0, (a22 * r1 - a12 * r2) / det, (a11 * r2 - a12 * r1) / det, p3])
    return ctrl


def _stretch_targets_numpy(W, est, valid, f, e, q):
    """The former :func:`fit._stretch_targets`."""
    d = np.where(valid[f:e + 1, None], est[f:e + 1], W[f:e + 1])
    if len(d) < 2:
        return d
    gap = np.hypot(*np.diff(d, axis=0).T)
    n = np.maximum(np.ceil(gap / (fitmod._STRETCH_STEP * q)).astype(np.intp), 1)
    seg = np.repeat(np.arange(len(gap)), n)
    frac = (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    pts = np.vstack([d[seg] + frac[:, None] * (d[seg + 1] - d[seg]), d[-1:]])
    if len(pts) > fitmod._STRETCH_TARGETS:
        pts = pts[np.linspace(0, len(pts) - 1, fitmod._STRETCH_TARGETS).round().astype(np.intp)]
    return pts


def _arc(rng, n):
    """A smooth arc of n points 1-2 units apart rounded to whole units (W), its unrounded
    points a little disturbed (the estimates), most of them valid."""
    r = rng.uniform(30.0, 400.0)
    a0 = rng.uniform(0.0, 2.0 * np.pi)
    ang = a0 + np.cumsum(rng.uniform(1.0, 2.0, n)) / r * rng.choice([-1.0, 1.0])
    P = np.stack([r * np.cos(ang), r * np.sin(ang)], axis=1) + rng.uniform(0, 1000, 2)
    W = np.round(P)
    est = P + rng.normal(size=P.shape) * 0.05
    valid = rng.random(n) < 0.85
    return W, est, valid


def _segments(rng, W, est):
    """Lines and cubics over stretches of W (short and long, over the windows of the
    polyline distance), near and less near the points."""
    n = len(W)
    for _ in range(12):
        f = int(rng.integers(0, n - 3))
        e = int(min(n - 1, f + rng.choice([1, 3, 12, 40, 150, 400])))
        if e <= f:
            continue
        p0 = est[f] + rng.normal(size=2) * 0.2
        p3 = est[e] + rng.normal(size=2) * 0.2
        yield f, e, np.stack([p0, p3])
        idx = np.linspace(f, e, 4)
        c = np.stack([np.interp(idx, np.arange(n), est[:, k]) for k in range(2)], axis=1)
        c[1:3] += (c[1:3] - 0.5 * (c[0] + c[3])) * 0.35 + rng.normal(size=(2, 2)) * 0.3
        c[0], c[3] = p0, p3
        yield f, e, c


@pytest.mark.parametrize("seed", range(6))
def test_design_off_compiled_is_the_numpy_one(seed: int) -> None:
    rng = np.random.default_rng(seed)
    W, est, valid = _arc(rng, 900)
    seen = 0
    for f, e, ctrl in _segments(rng, W, est):
        for h in (0.25, 0.1):
            want = _design_off_numpy(W, est, valid, ctrl, f, e, h)
            got = fitmod._design_off(W, est, valid, ctrl, f, e, h)
            assert got == want
            # with a limit at the distance (both sides): None exactly when over it
            for lim in (want[0], np.nextafter(want[0], -np.inf)):
                assert fitmod._design_off(W, est, valid, ctrl, f, e, h, lim) \
                    == _design_off_numpy(W, est, valid, ctrl, f, e, h, lim)
            seen += 1
    assert seen >= 20


@pytest.mark.parametrize("seed", range(6))
def test_seg_fits_compiled_is_the_numpy_one(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    W, est, _ = _arc(rng, 900)
    verdicts = set()
    for f, e, ctrl in _segments(rng, W, est):
        for h in (0.25, 0.1):
            loc = W[f:e + 1]
            if len(ctrl) == 2:
                d = point_segment_distance(loc, ctrl[0], ctrl[1])
            else:
                d = nearest_on_cubic(ctrl, loc, seeds=64, iters=8)[1]
            # bounds around the points' worst, so the polyline side decides both ways
            for bound in (d.max(), d.max() + 0.5 * h, d.max() + 0.3, d.max() + 1.0):
                want = _seg_fits_numpy(W, ctrl, f, e, bound, h)
                assert fitmod._seg_fits(W, ctrl, f, e, bound, h) == want
                verdicts.add(want)
    assert verdicts == {True, False}


@pytest.mark.parametrize("seed", range(6))
def test_ls_cubic_compiled_is_the_numpy_one(seed: int) -> None:
    rng = np.random.default_rng(200 + seed)
    W, est, valid = _arc(rng, 900)
    cases = 0
    for f, e, ctrl in _segments(rng, W, est):
        if len(ctrl) != 4:
            continue
        tg = fitmod._stretch_targets(W, est, valid, f, e, 1.0)
        # (the targets themselves: the former numpy ones, thinned or not, gaps filled)
        for q in (1.0, 0.3):
            assert np.array_equal(fitmod._stretch_targets(W, est, valid, f, e, q),
                                  _stretch_targets_numpy(W, est, valid, f, e, q))
        want = _ls_cubic_numpy(ctrl[0], ctrl[-1], tg)
        got = fitmod._ls_cubic(ctrl[0], ctrl[-1], tg)
        if want is None:
            assert got is None
        else:
            # (the summation order's rounding, magnified a little by the Newton steps)
            assert np.allclose(got, want, rtol=0.0, atol=1e-9 * (1.0 + np.abs(want).max()))
            cases += 1
    # targets at the ends of their range (parameters clipped to 0 and 1) and degenerate
    tg = np.array([[0.0, 0.0], [-1.0, 0.5], [3.0, 2.0], [6.0, 1.0], [7.0, -0.5], [5.0, 0.0]])
    assert np.allclose(fitmod._ls_cubic(tg[0], tg[-1], tg), _ls_cubic_numpy(tg[0], tg[-1], tg),
                       rtol=0.0, atol=1e-12)
    assert fitmod._ls_cubic(tg[0], tg[0], np.zeros((6, 2))) is None
    assert cases >= 8


def test_nearest_on_one_cubic_is_nearest_on_cubic_each() -> None:
    """The one-cubic path of nearest_on_cubic gives nearest_on_cubic_each's numbers, on
    plain arcs, loops and cusps (more samples), and where two sampled minima tie (the
    centre of a symmetric arc: handed over to nearest_on_cubic_each)."""
    from galvo_core.geometry import nearest_on_cubic_each

    rng = np.random.default_rng(7)
    cubics = [rng.normal(size=(4, 2)) * 50.0 for _ in range(40)]
    cubics.append(np.array([[0.0, 0.0], [100.0, 100.0], [0.0, 100.0], [100.0, 0.0]]))  # loop
    cubics.append(np.array([[0.0, 0.0], [10.0, 10.0], [-10.0, 10.0], [0.0, 0.0]]))
    sym = np.array([[-50.0, 0.0], [-50.0, 40.0], [50.0, 40.0], [50.0, 0.0]])
    cubics.append(sym)
    for c in cubics:
        pts = np.concatenate([rng.normal(size=(60, 2)) * 60.0, c + 0.25, [[0.0, -5.0]]])
        for seeds, iters in ((64, 8), (48, 6)):
            t, d = nearest_on_cubic(c, pts, seeds=seeds, iters=iters)
            te, de = nearest_on_cubic_each(c[None], np.zeros(len(pts), dtype=np.intp), pts,
                                           seeds=seeds, iters=iters)
            assert np.array_equal(t, te) and np.array_equal(d, de)
    assert nearest_on_cubic(sym, np.zeros((0, 2)))[0].shape == (0,)


def test_one_input_point_measured_as_before() -> None:
    """A segment over one input point (f == e): the distances to that point, as the former
    code had them (point_polyline_distance of a one-point polyline)."""
    rng = np.random.default_rng(9)
    W, est, valid = _arc(rng, 50)
    for f in (3, 10, 20):
        for ctrl in (np.stack([W[f] + 0.3, W[f] + [2.0, 1.0]]),
                     np.array([W[f], W[f] + [1.0, 2.0], W[f] + [3.0, 2.0], W[f] + [4.0, 0.0]])):
            for h in (0.25, 0.1):
                assert fitmod._design_off(W, est, valid, ctrl, f, f, h) \
                    == _design_off_numpy(W, est, valid, ctrl, f, f, h)
                for bound in (1.0, 3.0, 5.0):
                    assert fitmod._seg_fits(W, ctrl, f, f, bound, h) \
                        == _seg_fits_numpy(W, ctrl, f, f, bound, h)
        assert np.array_equal(fitmod._stretch_targets(W, est, valid, f, f, 1.0),
                              _stretch_targets_numpy(W, est, valid, f, f, 1.0))
