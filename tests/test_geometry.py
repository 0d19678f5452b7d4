"""Vectorised geometry: evaluation, derivatives, true nearest point, distances, flattening."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from galvo_core.geometry import (
    cubic_derivative,
    cubic_eval,
    cubic_length,
    cubic_second_derivative,
    flatten_cubic,
    nearest_on_cubic,
    point_polyline_distance,
    point_segment_distance,
)

coord = st.floats(-100, 100, allow_nan=False)
ctrl_st = st.lists(st.tuples(coord, coord), min_size=4, max_size=4).map(np.array)


def de_casteljau(c, t):
    pts = [np.asarray(c, float)]
    while len(pts[-1]) > 1:
        p = pts[-1]
        pts.append((1 - t) * p[:-1] + t * p[1:])
    return pts[-1][0]


def test_cubic_eval_ends_exact_and_matches_de_casteljau():
    c = np.array([[0.1, 0.2], [3.0, 7.0], [9.0, -2.0], [10.3, 4.4]])
    pts = cubic_eval(c, [0.0, 0.3, 0.77, 1.0])
    assert pts.shape == (4, 2)
    assert np.array_equal(pts[0], c[0]) and np.array_equal(pts[-1], c[3])
    for t, p in zip([0.3, 0.77], pts[1:3], strict=True):
        np.testing.assert_allclose(p, de_casteljau(c, t), rtol=1e-13)


def test_derivatives_match_finite_differences():
    c = np.array([[0.0, 0.0], [1.0, 5.0], [6.0, -3.0], [8.0, 2.0]])
    t = np.linspace(0.05, 0.95, 7)
    h = 1e-6
    fd1 = (cubic_eval(c, t + h) - cubic_eval(c, t - h)) / (2 * h)
    np.testing.assert_allclose(cubic_derivative(c, t), fd1, atol=1e-6)
    fd2 = (cubic_derivative(c, t + h) - cubic_derivative(c, t - h)) / (2 * h)
    np.testing.assert_allclose(cubic_second_derivative(c, t), fd2, atol=1e-5)


def test_cubic_length_of_straight_cubic():
    c = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]])
    assert cubic_length(c) == pytest.approx(3.0, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(ctrl_st, st.lists(st.tuples(coord, coord), min_size=1, max_size=20).map(np.array))
# a cusp: the nearest point lies in the bracket of a sample farther than the best one
@example(c=np.array([(0.0, 2.0), (0.0, 0.0), (0.5, -5.0), (0.0, 1.0)]), pts=np.array([[0.0, 0.0]]))
# a straight cubic whose distance is concave at the best sample (Newton would climb)
@example(c=np.array([(0.0, 6.103515625e-05), (0.0, 0.0), (0.0, -1.0), (0.0, -1.0)]),
         pts=np.array([[0.0, 0.0]]))
def test_nearest_on_cubic_is_the_true_nearest(c, pts):
    """Agrees with brute force over 200k samples (loops and cusps included)."""
    t, d = nearest_on_cubic(c, pts)
    assert t.shape == d.shape == (len(pts),)
    assert np.all((t >= 0) & (t <= 1))
    np.testing.assert_allclose(np.hypot(*(cubic_eval(c, t) - pts).T), d, atol=1e-9)
    dense = cubic_eval(c, np.linspace(0, 1, 200_001))
    for p, dd in zip(pts, d, strict=True):
        brute = np.hypot(*(dense - p).T).min()
        # never worse than brute force (up to its sampling step), never below the truth
        assert dd <= brute + 1e-9
        step = np.hypot(*np.diff(dense, axis=0).T).max()
        assert dd >= brute - step


def test_nearest_handles_points_beyond_the_ends_and_on_the_curve():
    c = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 1.0], [3.0, 0.0]])
    t, d = nearest_on_cubic(c, [[-5.0, 0.0], [8.0, -1.0], cubic_eval(c, [0.42])[0]])
    assert t[0] == 0.0 and d[0] == pytest.approx(5.0)
    assert t[1] == 1.0
    assert t[2] == pytest.approx(0.42, abs=1e-9) and d[2] < 1e-9


def test_point_segment_distance():
    d = point_segment_distance([[0, 1], [-3, 4], [12, 0], [5, -2]], [0, 0], [10, 0])
    np.testing.assert_allclose(d, [1, 5, 2, 2])
    # zero-length segment is a point
    np.testing.assert_allclose(point_segment_distance([[3, 4]], [0, 0], [0, 0]), [5])
    # broadcast per-point segments
    a = np.array([[0, 0], [0, 0]])
    b = np.array([[1, 0], [0, 1]])
    np.testing.assert_allclose(point_segment_distance([[0.5, 1], [1, 0.5]], a, b), [1, 1])


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.tuples(coord, coord), min_size=1, max_size=30).map(np.array),
    st.lists(st.tuples(coord, coord), min_size=1, max_size=30).map(np.array),
)
def test_point_polyline_distance_matches_per_segment_minimum(pts, poly):
    d = point_polyline_distance(pts, poly)
    if len(poly) == 1:
        ref = np.hypot(*(pts - poly[0]).T)
    else:
        ref = np.min(
            [point_segment_distance(pts, poly[i], poly[i + 1]) for i in range(len(poly) - 1)],
            axis=0,
        )
    np.testing.assert_allclose(d, ref, atol=1e-9)


def test_point_polyline_distance_large_input_uses_same_answer():
    rng = np.random.default_rng(3)
    poly = np.cumsum(rng.normal(0, 1, (3000, 2)), axis=0)
    pts = rng.uniform(-40, 40, (6000, 2))
    d = point_polyline_distance(pts, poly)
    sub = rng.choice(len(pts), 50, replace=False)
    ref = np.min([point_segment_distance(pts[sub], poly[i], poly[i + 1]) for i in range(2999)], 0)
    np.testing.assert_allclose(d[sub], ref, atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(ctrl_st, st.sampled_from([1.0, 0.1, 0.01]))
def test_flatten_cubic_within_tolerance(c, tol):
    poly = flatten_cubic(c, tol)
    assert np.array_equal(poly[0], c[0]) and np.array_equal(poly[-1], c[3])
    dense = cubic_eval(c, np.linspace(0, 1, 5001))
    assert point_polyline_distance(dense, poly).max() <= tol * (1 + 1e-9)


def test_flatten_rejects_bad_tolerance():
    with pytest.raises(ValueError):
        flatten_cubic(np.zeros((4, 2)), 0.0)


@pytest.mark.parametrize("downhill", [False, True])
@pytest.mark.parametrize("bounds", ["scalar", "per point"])
def test_chunked_newton_kernel_equals_the_point_by_point_loop(downhill, bounds):
    """The Newton kernel steps a chunk of points at a time (so that it vectorises): its u
    and distances are bit for bit those of the loop that finishes one point before the
    next, over several chunks, with non-convex stretches, degenerate cubics and NaN."""
    from galvo_core.geometry import _newton_kernel, _newton_one_cubic

    rng = np.random.default_rng(7)
    k = 1300  # 2 full chunks of 512 and a partial one
    cf = rng.normal(size=(4, 2, k)) * 10.0
    cf[:, :, ::9] = 0.0
    cf[0, 0, 5] = np.nan
    p = rng.normal(size=(2, k)) * 10.0
    u0 = rng.random(k)
    if bounds == "scalar":
        lo, hi = np.zeros(1), np.ones(1)
    else:
        lo = rng.random(k) * 0.5
        hi = lo + rng.random(k) * 0.5
    ua, da = u0.copy(), np.empty(k)
    ub, db = u0.copy(), np.empty(k)
    _newton_kernel(cf, p, ua, da, 6, lo, hi, downhill)
    _newton_one_cubic(cf, p, ub, db, 6, lo, hi, downhill)
    assert np.array_equal(ua, ub, equal_nan=True)
    assert np.array_equal(da, db, equal_nan=True)
    assert not np.array_equal(ua, u0)  # (the steps moved u)
