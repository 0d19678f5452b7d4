"""Issue 16 (s5, speed on sparse whole-unit outlines): the joints of rounded input are moved
onto their design estimates only where both segments still keep the bound
(:func:`fit._seg_fits`); that check now runs for many segments at once
(:func:`fit._seg_fits_many`), and the nearest-point search's sampled candidates are compiled.
Their answers must be the plain versions' ones exactly: a batch check that let a segment
through wrongly would move a joint off the stated bound, and any other difference changes
the fit."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod
from galvo_core import geometry as geo


def _rounded_outline(seed: int):
    """A rounded smooth closed outline (points 1-2 units apart) and, along it, segments
    (lines and cubics through nearby points, their ends pushed by up to half a unit) with
    their input ranges: (W, ctrls, first, last)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2.0 * np.pi, 3000, endpoint=False)
    r = 1.0 + 0.15 * np.cos(3 * t)
    W = np.round(np.c_[300.0 * r * np.cos(t), 200.0 * r * np.sin(t)])
    W = W[np.r_[True, (W[1:] != W[:-1]).any(axis=1)]]
    ctrls, first, last = [], [], []
    for _ in range(300):
        f = int(rng.integers(0, len(W) - 60))
        e = f + int(rng.integers(1, 50))
        p0 = W[f] + rng.uniform(-0.5, 0.5, 2)
        p3 = W[e] + rng.uniform(-0.5, 0.5, 2)
        if e - f < 4 or rng.random() < 0.3:
            c = np.stack([p0, p3])
        else:
            a, b = W[f + (e - f) // 3], W[f + 2 * (e - f) // 3]
            c = np.stack([p0, p0 + 1.5 * (a - W[f]), p3 + 1.5 * (b - W[e]), p3])
            c[1:3] += rng.uniform(-0.7, 0.7, (2, 2))
        ctrls.append(c)
        first.append(f)
        last.append(e)
    return W, ctrls, np.array(first), np.array(last)


def test_batch_segment_check_is_the_single_one():
    seen = set()
    for seed in range(3):
        W, ctrls, first, last = _rounded_outline(seed)
        wstep = np.hypot(*np.diff(W, axis=0).T)
        for bound in (0.6, 0.9, 1.4):
            h = np.full(len(ctrls), 0.05)
            got = fitmod._seg_fits_many(W, wstep, ctrls, first, last,
                                        np.full(len(ctrls), bound), h)
            want = [fitmod._seg_fits(W, c, int(f), int(e), bound, 0.05)
                    for c, f, e in zip(ctrls, first, last, strict=True)]
            assert got.tolist() == want
            seen.update(want)
    assert seen == {True, False}  # (both answers were exercised)


def _numpy_candidates(c, pid, p, ns, out, best_u, best_d2, cands):
    """The former numpy selection of the sampled candidates, for every row."""
    cubs, ci = np.unique(pid, return_inverse=True)
    cc = c[cubs]
    su = np.linspace(0.0, 1.0, ns + 1)
    t = su.reshape(1, -1, 1)
    s = 1.0 - t
    sp = ((s * s * s) * cc[:, None, 0] + (3.0 * s * s * t) * cc[:, None, 1]
          + (3.0 * s * t * t) * cc[:, None, 2] + (t * t * t) * cc[:, None, 3])
    geo._sampled_candidates_np(np.ascontiguousarray(sp[:, :, 0]),
                               np.ascontiguousarray(sp[:, :, 1]), ci, p, su, ns, out,
                               best_u, best_d2, cands)


def test_compiled_candidates_give_the_numpy_nearest_points(monkeypatch):
    rng = np.random.default_rng(7)
    for trial in range(6):
        c = rng.normal(size=(40, 4, 2)) * (1.0, 30.0, 500.0)[trial % 3]
        if trial % 2:  # integer curves and points: equal sampled minima occur
            c = np.round(c)
            c[::4, 1], c[::4, 2] = c[::4, 0], c[::4, 3]  # (lines as cubics)
        pid = rng.integers(0, len(c), 4000)
        p = rng.normal(size=(4000, 2)) * 60.0
        if trial % 2:
            p = np.round(p)
        t1, d1 = geo.nearest_on_cubic_each(c, pid, p, seeds=64, iters=8)
        with monkeypatch.context() as mp:
            mp.setattr(geo, "_sampled_candidates", _numpy_candidates)
            t2, d2 = geo.nearest_on_cubic_each(c, pid, p, seeds=64, iters=8)
        assert np.array_equal(t1, t2) and np.array_equal(d1, d2)


def test_seeded_samples_are_the_einsum_ones():
    rng = np.random.default_rng(3)
    su = np.linspace(0.0, 1.0, 49)
    s = 1.0 - su
    basis = np.stack([s**3, 3.0 * s * s * su, 3.0 * s * su * su, su**3], axis=1)
    c = rng.normal(size=(500, 4, 2)) * 1000.0
    out = np.empty((len(c), len(su), 2))
    geo._samples_kernel(basis, c, out)
    assert np.array_equal(out, np.einsum("sk,mkd->msd", basis, c))


def test_windowed_polyline_distance_keeps_its_contract():
    """Over ``lim`` the exact distance (point_polyline_distance's), within ``lim`` a distance
    between the exact one (up to rounding) and ``lim``: checks built on it are never too
    lenient."""
    rng = np.random.default_rng(11)
    over = within = 0
    for trial in range(40):
        t = np.sort(rng.uniform(0.0, 6.0, int(rng.integers(20, 2000))))
        poly = np.c_[100.0 * np.cos(t), 80.0 * np.sin(t)]
        if trial % 2:
            poly = np.round(poly)
        ts = np.sort(rng.uniform(0.0, 6.0, int(rng.integers(1, 500))))
        samp = np.c_[100.0 * np.cos(ts), 80.0 * np.sin(ts)]
        samp += rng.normal(size=samp.shape) * (0.1, 1.0, 4.0)[trial % 3]
        for k, lim in ((8, 0.5), (64, 0.3), (8, 2.0)):
            d = fitmod._polyline_distance_over(samp, poly, lim, k)
            exact = geo.point_polyline_distance(samp, poly)
            big = d > lim
            assert np.array_equal(d[big], exact[big])
            # (the windowed arithmetic divides by the squared length: ulps apart)
            assert (exact[~big] <= d[~big] * (1.0 + 1e-12) + 1e-12).all()
            assert (d[~big] <= lim).all()
            over += int(big.sum())
            within += int((~big).sum())
    assert over and within


def test_sampled_upper_bound_is_never_below_the_nearest_distance():
    """The batch check skips Newton where a point is within the bound at its cubic's
    nearest sample: that must never be less than the distance the full search gives."""
    rng = np.random.default_rng(5)
    c = rng.normal(size=(60, 4, 2)) * 40.0
    c[::5, 2] = c[::5, 0] + (c[::5, 3] - c[::5, 1])  # (loops and cusps: more samples)
    pid = np.sort(rng.integers(0, len(c), 6000))
    p = rng.normal(size=(6000, 2)) * 40.0
    _, d = geo.nearest_on_cubic_each(c, pid, p, seeds=64, iters=8)
    up = np.sqrt(geo.sampled_upper_d2(c, pid, p, seeds=64))
    assert (d <= up).all()
    assert (d < up).mean() > 0.5  # (Newton does improve on the samples)
