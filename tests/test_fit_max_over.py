"""Issue 16 (s14, the sparse speed bench): the smooth-stretch pass measures the largest
distance of a segment's samples (or of its design estimates) to a polyline only where it
can matter (:func:`fit._max_over`: an upper bound of each distance by a walk along the
polyline, then the points whose bound can reach the largest). The answer must be the
answer of measuring every point (:func:`fit._distance_over_upto`): the same number where
over the exactness limit, never below the true largest distance, the same verdict
against a stop; and :func:`fit._points_near_cubic` must never contradict the exact
nearest points on the cubic."""

from __future__ import annotations

import numpy as np
import pytest

from galvo_core import fit as fitmod
from galvo_core.geometry import nearest_on_cubic, point_polyline_distance


def _cases(rng):
    """Ordered point runs beside polylines: a rounded wavy arc and points near it, a
    polyline that doubles back on itself (the walk's local nearest is not the nearest),
    points far off, one-point and two-point polylines."""
    out = []
    for _ in range(12):
        n = int(rng.integers(20, 300))
        t = np.linspace(0.0, rng.uniform(2.0, 6.0), n)
        amp = rng.uniform(0.0, 30.0)
        poly = np.stack([t * rng.uniform(20.0, 60.0), amp * np.sin(t)], axis=1)
        poly = np.round(poly)
        poly = poly[np.r_[True, (np.diff(poly, axis=0) != 0).any(axis=1)]]
        m = int(rng.integers(10, 800))
        u = np.linspace(0.0, t[-1], m)
        off = rng.uniform(0.0, 1.5)
        samp = np.stack([u * (poly[-1, 0] / t[-1]), amp * np.sin(u) + off
                         + rng.normal(0.0, 0.2, m)], axis=1)
        out.append((samp, poly))
    # a zigzag folding back: the points' nearest segments are not in order
    z = np.array([[0, 0], [10, 0], [0, 1], [10, 2], [0, 3], [10, 4]], dtype=float)
    s = np.stack([np.linspace(0, 10, 50), np.full(50, 2.2)], axis=1)
    out.append((s, z))
    out.append((s, z[:1].copy()))
    out.append((s, z[:2].copy()))
    out.append((s + [0.0, 40.0], z))
    return out


@pytest.mark.parametrize("seed", range(4))
def test_max_over_is_the_largest_of_all_points(seed: int) -> None:
    rng = np.random.default_rng(700 + seed)
    checked = over_lim = 0
    for samp, poly in _cases(rng):
        samp = np.ascontiguousarray(samp)
        poly = np.ascontiguousarray(poly)
        true = point_polyline_distance(samp, poly)
        for lim in (0.05, 0.3, 1.0):
            for k in (8, 64):
                every, cnt = fitmod._distance_over_upto(samp, poly, lim, k, np.inf)
                want = every[:cnt].max()
                for stride in (1, 4, 8):
                    got, over = fitmod._max_over(samp, poly, lim, k, -np.inf, np.inf, stride)
                    assert not over
                    assert got >= true.max() - 1e-12
                    if want > lim:
                        assert got == want  # the exact largest
                        over_lim += 1
                    else:
                        assert got <= lim
                    # a stop at or above lim: over exactly when some point is
                    for stop in (lim, 0.5 * (lim + true.max()), true.max() + 0.1):
                        stop = max(stop, lim)
                        _, hit = fitmod._max_over(samp, poly, lim, k, -np.inf, stop, stride)
                        assert hit == bool((every[:cnt] > stop).any())
                    # a floor at lim: the verdict "all within lim" is the same
                    d, hit = fitmod._max_over(samp, poly, lim, k, lim, lim, stride)
                    assert (not hit and d <= lim) == bool((true <= lim).all())
                    checked += 1
    assert checked >= 100 and over_lim >= 20


def test_max_over_nan_fails_as_before() -> None:
    samp = np.array([[0.0, 1.0], [1.0, np.nan], [2.0, 3.0]])
    poly = np.array([[0.0, 0.0], [2.0, 0.0]])
    d, over = fitmod._max_over(samp, poly, 0.3, 8, -np.inf, np.inf, 4)
    every, cnt = fitmod._distance_over_upto(samp, poly, 0.3, 8, np.inf)
    # (the NaN point is not within any distance: the measure of every point, in order)
    assert not over and not d <= 0.3 and np.array_equal(d, every[:cnt].max(), equal_nan=True)
    assert not fitmod._samples_within(np.array([[0.0, 0.0], [np.nan, 1.0]]), 0.1,
                                      poly, 0, 1, 0.5)


@pytest.mark.parametrize("seed", range(3))
def test_points_near_cubic_agrees_with_the_nearest_points(seed: int) -> None:
    rng = np.random.default_rng(900 + seed)
    seen = set()
    for _ in range(60):
        ctrl = np.cumsum(rng.normal(0.0, 20.0, (4, 2)), axis=0)
        u = np.sort(rng.uniform(0.0, 1.0, int(rng.integers(5, 120))))
        s = 1.0 - u[:, None]
        pts = (s ** 3 * ctrl[0] + 3 * s * s * u[:, None] * ctrl[1]
               + 3 * s * u[:, None] ** 2 * ctrl[2] + u[:, None] ** 3 * ctrl[3])
        W = np.round(pts + rng.normal(0.0, 0.3, pts.shape))
        d = nearest_on_cubic(ctrl, W, seeds=64, iters=8)[1].max()
        for bound in (0.5 * d, d - 0.01, d + 0.01, d + 0.5, 2.0 * d + 0.1):
            v = fitmod._points_near_cubic(np.ascontiguousarray(ctrl), 0.05, W, 0, len(W) - 1,
                                          bound)
            if v == 1:
                assert d <= bound
            elif v == 0:
                assert d > bound
            seen.add(int(v))
    # both verdicts are reached (and the undecided band exists only near the bound)
    assert {0, 1} <= seen
