"""Issue 16 (s5, speed): the acceptance test of a fitted cubic is compiled one piece at a
time, with a cheap upper bound of the curve-to-polyline distance tried before the exact one
on every pair of input points. Its verdict must be the one of the plain definition (the
exact bound of every pair, :func:`fit._curve_to_polyline_bound_many`, against the bound),
and its point distances the ones of Newton from arc length (:func:`newton_nearest_many`):
a cheap bound that let a pair through wrongly would let a cubic over the stated bound
through."""

from __future__ import annotations

import numpy as np
import pytest

from galvo_core import fit as fitmod
from galvo_core.geometry import gather_coeffs, newton_nearest_many, power_coeffs_many


def _pieces(seed: int, n_pieces: int = 60, *, rounded: bool):
    """Random cubics with noisy input points along them (some repeated, some far apart),
    concatenated as the fitter holds them: (ctrl, i0, i1, work, arc)."""
    rng = np.random.default_rng(seed)
    ctrl = rng.uniform(-50.0, 50.0, (n_pieces, 4, 2)) + rng.uniform(-1e4, 1e4, (n_pieces, 1, 2))
    work, i0, i1 = [], [], []
    at = 0
    for c in ctrl:
        n = int(rng.integers(2, 80))
        u = np.sort(rng.uniform(0.0, 1.0, n))
        u[0], u[-1] = 0.0, 1.0
        s = 1.0 - u
        b = np.stack([s**3, 3 * s * s * u, 3 * s * u * u, u**3], axis=1)
        p = b @ c + rng.normal(0.0, rng.choice([0.01, 0.2, 2.0]), (n, 2))
        if rounded:
            p = np.round(p)  # (many repeated points)
        p[0], p[-1] = c[0], c[3]
        if n > 4:
            k = int(rng.integers(1, n - 2))
            p[k + 1] = p[k]  # a repeated point
        work.append(p)
        i0.append(at)
        i1.append(at + n - 1)
        at += n
    work_a = np.concatenate(work)
    seg = np.hypot(*np.diff(work_a, axis=0).T)
    arc = np.r_[0.0, np.cumsum(seg)]
    return ctrl, np.array(i0), np.array(i1), work_a, arc


def _reference(ctrl, i0, i1, work, arc, e2, qa, coarse):
    """The plain definition: Newton (6 steps from arc length) per point, the ends at the
    curve's ends, then the exact bound of every pair against e2 (plus the rounding slack
    the curve may not use beside a long segment, unless ``coarse`` marks it a chord)."""
    m = len(ctrl)
    cnt = i1 - i0 + 1
    pid = np.repeat(np.arange(m), cnt)
    starts = np.cumsum(cnt) - cnt
    idx = i0[pid] + np.arange(cnt.sum()) - starts[pid]
    span = arc[i1] - arc[i0]
    u = (arc[idx] - arc[i0][pid]) / np.where(span > 0, span, 1.0)[pid]
    cf = gather_coeffs(power_coeffs_many(ctrl), pid)
    u, d2 = newton_nearest_many(cf, work[idx].T, u, 6)
    u[starts] = 0.0
    u[starts + cnt - 1] = 1.0
    d2[starts] = d2[starts + cnt - 1] = 0.0
    j = np.flatnonzero(np.isin(np.arange(len(idx)), starts + cnt - 1, invert=True))
    bnd = fitmod._curve_to_polyline_bound_many(cf[:, :, j], work[idx[j]], work[idx[j] + 1],
                                                u[j], u[j + 1])
    if len(qa):
        q = qa[pid[j]]
        ln = np.hypot(*(work[idx[j] + 1] - work[idx[j]]).T)
        with np.errstate(divide="ignore", invalid="ignore"):
            f = np.clip(fitmod._LONG_SEGMENT * q / ln, fitmod._LONG_FLOOR, 1.0)
        f = np.where(coarse[idx[j]], 1.0, f)
        bnd = bnd + q * fitmod._HALF_DIAGONAL * (1.0 - np.where(q > 0.0, f, 1.0))
    worst = np.zeros(m)
    np.maximum.at(worst, pid[j], bnd)
    return u, np.sqrt(d2), worst


@pytest.mark.parametrize("rounded", [False, True])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_compiled_accept_matches_the_definition(seed: int, rounded: bool) -> None:
    ctrl, i0, i1, work, arc = _pieces(seed, rounded=rounded)
    m = len(ctrl)
    qa = np.full(m, 1.0) if rounded else fitmod._NO_QUANTA
    # (rounded: some segments marked chords of a coarse curve, full slack beside them)
    coarse = np.random.default_rng(seed).random(len(work)) < (0.3 if rounded else 0.0)
    u_ref, d_ref, worst = _reference(ctrl, i0, i1, work, arc, np.ones(m), qa, coarse)
    cnt = i1 - i0 + 1
    starts = np.cumsum(cnt) - cnt
    cm = power_coeffs_many(ctrl)
    # bounds around each piece's exact worst pair: just under, just over, well over
    for scale in (0.999999, 1.000001, 3.0):
        e2 = worst * scale
        u = np.empty(cnt.sum())
        dist = np.empty(cnt.sum())
        emax0 = np.empty(m)
        far = np.empty(cnt.sum(), dtype=np.intp)
        fitmod._accept_points(cm, i0, i1, starts, work, arc, e2, u, dist, emax0, far)
        # the points: Newton's numbers bit for bit
        assert np.array_equal(u, u_ref)
        assert np.array_equal(dist, d_ref)
        assert np.array_equal(emax0, np.maximum.reduceat(d_ref, starts))
        ok = np.ones(m, dtype=bool)
        fitmod._accept_pairs(cm, i0, i1, starts, work, u, e2, qa, coarse, ok)
        assert np.array_equal(ok, worst <= e2), scale
    # (both verdicts occur)
    ok = np.ones(m, dtype=bool)
    fitmod._accept_pairs(cm, i0, i1, starts, work, u, worst * 0.999999, qa, coarse, ok)
    assert not ok[worst > 0].any()
