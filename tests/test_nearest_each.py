"""nearest_on_cubic_each: many cubics at once, the same bits as one nearest_on_cubic each."""

from __future__ import annotations

import numpy as np
import pytest

from galvo_core.geometry import nearest_on_cubic, nearest_on_cubic_each


def _cubics(rng, m):
    c = rng.normal(size=(m, 4, 2)) * rng.uniform(0.01, 500, (m, 1, 1))
    c[::5, 2] = c[::5, 1]  # repeated control points
    c[1::7, 3] = c[1::7, 0]  # closed loops (their control polygon turns a lot: more seeds)
    c[2::9] = c[2::9, :1]  # all four equal: a point
    return c


@pytest.mark.parametrize("seeds, iters", [(48, 6), (128, 10)])
def test_each_cubic_gets_exactly_what_nearest_on_cubic_gives(seeds, iters):
    rng = np.random.default_rng(3)
    c = _cubics(rng, 60)
    counts = rng.integers(0, 40, len(c))
    pid = np.repeat(np.arange(len(c)), counts)
    rng.shuffle(pid)  # points of one cubic need not be together
    pts = c[pid].mean(axis=1) + rng.normal(size=(len(pid), 2)) * 50
    t, d = nearest_on_cubic_each(c, pid, pts, seeds=seeds, iters=iters)
    for k in range(len(c)):
        sel = pid == k
        t1, d1 = nearest_on_cubic(c[k], pts[sel], seeds=seeds, iters=iters)
        np.testing.assert_array_equal(t[sel], t1)
        np.testing.assert_array_equal(d[sel], d1)


def test_no_points():
    t, d = nearest_on_cubic_each(np.zeros((2, 4, 2)), np.zeros(0, int), np.zeros((0, 2)))
    assert t.shape == d.shape == (0,)
