"""Rounded input, issue 16 (fifteenth session): a unit jog of the rounding after a diagonal
straight run (a 45-degree staircase shifting its phase where the design's slope drifts) is a
rounding wiggle, not two corners (``runs._JOG``, ``runs._JOG_DIAG``). The outlines are paths of
the sparse bench (``bench_precision_speed.py --sparse``: waved ellipses rounded to whole units,
their true curves known), generated here the same way."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod
from galvo_core import runs
from galvo_core.fit import check_fit, fit_paths
from galvo_core.geometry import point_polyline_distance
from tests._util import flattened_cubic, resampled


def _sparse_path(i: int) -> tuple[np.ndarray, np.ndarray]:
    """Path i of the sparse bench's generator: (rounded points, true curve)."""
    import os
    import sys

    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "bench"))
    from bench_precision_speed import sparse_outline

    return sparse_outline(i)


def _dense(fp) -> np.ndarray:
    return np.vstack([flattened_cubic(*s.points, chord=0.002) if s.kind == "cubic"
                      else np.asarray(s.points) for s in fp.segments])


def _fit(w):
    fp = fit_paths([w], [True])[0]
    assert not check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    return fp


def _distance(fd, tr, place=None, r=3.0) -> float:
    """Both-ways distance of the fit and the true curve (within r of ``place`` if given)."""
    a, b = fd, tr
    if place is not None:
        a = fd[np.hypot(*(fd - place).T) < r]
        b = tr[np.hypot(*(tr - place).T) < r]
    return max(float(point_polyline_distance(a, tr).max()),
               float(point_polyline_distance(b, fd).max()))


def test_a_unit_jog_after_a_diagonal_run_is_no_corner(monkeypatch):
    # path 21 near (1144, 953): 55 units of 45-degree staircase, then a one-unit horizontal
    # jog where the design's slope turns to 41 degrees; as two corners the joint stayed on
    # the rounded point, 0.67 from the design
    w, tr = _sparse_path(21)
    place = np.array([1144.0, 953.0])
    fp = _fit(w)
    d = _distance(_dense(fp), tr, place)
    monkeypatch.setattr(runs, "_JOG", 0.0)
    # (and without the twentieth session's free curve sides, where the two corners' estimates
    # then stay: fit._CORNER_LINES_ONLY)
    monkeypatch.setattr(fitmod, "_CORNER_LINES_ONLY", False)
    fp0 = _fit(w)
    d0 = _distance(_dense(fp0), tr, place)
    assert d < 0.3 and d0 > 0.6, (d, d0)
    assert fp.n_segments < fp0.n_segments


def test_a_jog_after_an_axis_parallel_run_stays_out_of_the_rule(monkeypatch):
    # path 507: a 147-unit flat top (all points at y = 1763, the design 0.4 above them in
    # places): taken into one curve run it became one cubic that sags 0.5 below the points,
    # within the bound and 0.87 from the design
    w, tr = _sparse_path(507)
    d = _distance(_dense(_fit(w)), tr)
    monkeypatch.setattr(runs, "_JOG_DIAG", 0.0)
    monkeypatch.setattr(fitmod, "_CORNER_LINES_ONLY", False)  # (as above)
    d_all = _distance(_dense(_fit(w)), tr)
    assert d < 0.65 and d_all > 0.8, (d, d_all)


def test_a_step_of_the_design_between_parallel_runs_stays_sharp(monkeypatch):
    # a designed step 2 units across (more than _CLUSTER_SHIFT quanta) between two long
    # diagonal lines written as 1-unit steps is no jog of the rounding: its corners stay
    d = np.array([np.cos(0.8), np.sin(0.8)])
    n = np.array([-d[1], d[0]])
    p1 = 300.0 * d
    p3 = p1 + 2.0 * n + 300.0 * d
    design = np.array([(0.0, 0.0), p1, p1 + 2.0 * n, p3, p3 + 200.0 * n, 200.0 * n,
                       (0.0, 0.0)]) + [0.3, 0.2]
    w = np.round(resampled(design, 1.0))
    w = w[np.r_[True, (np.diff(w, axis=0) != 0).any(axis=1)]]
    fine = resampled(design, 0.05)
    dist = _distance(_dense(_fit(w)), fine)
    # (the shift's guard alone: taken for a jog, the step's corners are rounded off, 0.92
    # from the design; the turn guard, runs._CLUSTER_TURNS, holds them too)
    monkeypatch.setattr(runs, "_CLUSTER_SHIFT", 100.0)
    d_turns = _distance(_dense(_fit(w)), fine)
    monkeypatch.setattr(runs, "_CLUSTER_TURNS", False)
    d_any = _distance(_dense(_fit(w)), fine)
    assert dist < 0.6 and d_turns < 0.6 and d_any > 0.75, (dist, d_turns, d_any)
