"""The fitting guarantee where a merge round once broke it: at 434aac2 the resplit round
could pick two triples of one phase that shared a segment, and a range of the path ended up
in no segment (its points at distance inf: not marked at all). A smooth whole-unit outline
that hit it, and a sample of random whole-unit paths (arcs, smoothed random walks, sines;
open and closed): every input point within the stated bound of the segments that cover it
and every segment within it of the input polyline (check_fit, true distances, as referee)."""

from __future__ import annotations

import numpy as np
import pytest
from _util import waved_ellipse, whole_units

from galvo_core.fit import check_fit, fit_paths


def _random_paths(seed: int, count: int):
    rng = np.random.default_rng(seed)
    paths, closed = [], []
    for i in range(count):
        n = int(rng.integers(50, 1500))
        if i % 3 == 0:  # an arc
            r = rng.uniform(20, 2000)
            t = rng.uniform(0, 6.28) + np.linspace(0, rng.uniform(0.2, 6.2), n)
            p = np.c_[r * np.cos(t), r * np.sin(t)] + rng.uniform(-500, 500, 2)
        elif i % 3 == 1:  # a smoothed random walk
            steps = rng.normal(0, 1, (n, 2)).cumsum(0)
            ker = np.ones(int(rng.integers(1, 30)))
            ker /= len(ker)
            p = np.c_[np.convolve(steps[:, 0], ker, "same"),
                      np.convolve(steps[:, 1], ker, "same")] * rng.uniform(1, 20)
        else:  # a sine
            x = np.linspace(0, rng.uniform(100, 3000), n)
            p = np.c_[x, rng.uniform(5, 300) * np.sin(x / rng.uniform(20, 400))]
        w = np.round(p)
        w = w[np.r_[True, (w[1:] != w[:-1]).any(axis=1)]]
        if len(w) < 3:
            continue
        c = bool(rng.integers(0, 2))
        if c and not (w[0] == w[-1]).all():
            w = np.vstack([w, w[:1]])
        paths.append(w)
        closed.append(c)
    return paths, closed


def _assert_bound(paths, closed):
    fps = fit_paths(paths, closed)
    for i, (w, fp) in enumerate(zip(paths, fps, strict=True)):
        rep = check_fit(w, fp, 0.02, 0.02, report=True)
        assert np.isfinite(rep["max_in_to_curve"]), i  # every input point covered
        assert rep["violation"] == 0.0, (i, rep)


def test_outline_that_lost_a_range_is_covered_within_the_bound():
    _assert_bound([whole_units(waved_ellipse(1, 2))], [True])


@pytest.mark.parametrize("seed", [7])
def test_random_whole_unit_paths_keep_the_bound(seed):
    _assert_bound(*_random_paths(seed, 30))
