"""Coordinate quantum detection and the precision-aware fit (issue 16)."""

from __future__ import annotations

import numpy as np
import pytest

from galvo_core.fit import check_fit, fit_paths, fit_report, rounding_slack
from galvo_core.geometry import flatten_cubic, point_polyline_distance
from galvo_core.precision import axis_quantum, coordinate_quantum, drawing_quantum, path_quanta


def ellipse(n=2000, a=300.0, b=170.0, x0=17.3, y0=-4.1):
    t = np.linspace(0.0, 2.0 * np.pi, n)
    return np.c_[x0 + a * np.cos(t), y0 + b * np.sin(t)]


@pytest.mark.parametrize("q", [1.0, 0.1, 0.01, 0.001, 0.25, 0.37])
def test_grid_steps_are_found(q):
    p = np.round(ellipse() / q) * q
    assert coordinate_quantum(p) == pytest.approx(q, rel=1e-6)


def test_scaled_grid_with_an_offset_is_found():
    """SC/IP scaling: user unit k lands on q k + offset plotter units."""
    q, off = 0.4 * 1.0000001, 0.123
    p = np.round(ellipse() / q) * q + off
    gq, (ox, oy) = drawing_quantum([p])
    assert gq == pytest.approx(q, rel=1e-6)
    assert ox == pytest.approx(off, abs=1e-6) and oy == pytest.approx(off, abs=1e-6)


def test_exact_input_and_too_little_evidence_give_zero():
    assert coordinate_quantum(ellipse()) == 0.0
    assert coordinate_quantum([[0, 0], [100, 0], [100, 50], [0, 50], [0, 0]]) == 0.0
    assert coordinate_quantum(np.zeros((0, 2))) == 0.0
    assert axis_quantum([1.0, 2.0]) == (0.0, 0.0)


def test_per_path_quantum_where_a_path_is_off_the_drawing_grid():
    whole = np.round(ellipse())
    exact = ellipse(a=90.0, b=40.0)
    q = path_quanta([whole, exact, np.round(ellipse(b=30.0))])
    assert q.tolist() == [1.0, 0.0, 1.0]


def _dense(fp):
    parts = [flatten_cubic(s.points, 0.002) if s.kind == "cubic" else s.points
             for s in fp.segments]
    return np.vstack([parts[0]] + [p[1:] for p in parts[1:]])


def test_whole_unit_curve_fits_like_the_design_within_the_rounding():
    """An ellipse written in whole units at the default tolerances: a tenth of the
    segments of a fit that ignores the rounding (which keeps the rounded points as lines),
    every point within e_per + 1/sqrt2 of the fit and the fit within that of the polyline,
    and the fit within that distance of the unrounded ellipse too."""
    true = ellipse(20000)
    p = np.round(true)
    p = p[np.r_[True, (p[1:] != p[:-1]).any(axis=1)]]
    (fp,) = fit_paths([p], [True])
    (blind,) = fit_paths([p], [True], quantum_units=0.0)
    assert len(fp.segments) <= 0.1 * len(blind.segments)
    rep = check_fit(p, fp, 0.02, 0.02, report=True)
    assert rep["quantum_units"] == 1.0
    assert rep["bound"] == pytest.approx(0.02 + 0.5**0.5)
    assert not rep["violation"]
    d = _dense(fp)
    both = max(point_polyline_distance(d, true).max(), point_polyline_distance(true, d).max())
    assert both < 0.02 + 0.5**0.5


def test_exact_input_keeps_the_users_bound():
    (fp,) = fit_paths([ellipse()], [True])
    rep = check_fit(ellipse(), fp, 0.02, 0.02, report=True)
    assert rep["quantum_units"] == 0.0 and rep["bound"] == 0.02 and not rep["violation"]
    assert rounding_slack([ellipse()]).tolist() == [0.0]


def test_fit_report_per_path_numbers():
    from galvo_core.drawing import Drawing, Path

    d = Drawing(name="x", paths=(Path(np.round(ellipse()), 1, True),
                                 Path(ellipse(a=50.0, b=20.0), 1, True)))
    rep = fit_report(d, per_path=True)
    assert rep["quantum_units"] == 1.0
    paths = rep["paths"]
    assert [p["quantum_units"] for p in paths] == [1.0, 0.0]
    assert all(p["max_error"] <= p["bound"] for p in paths)
    assert sum(p["segments"] for p in paths) == rep["lines"] + rep["cubics"]


def test_grid_verify_in_chunks_gives_the_unchunked_answer():
    """The drawing-level verify runs in chunks of points (short numpy calls, so a GUI thread
    is not held up): the per-point answer is the one of a single call, including the
    tolerance's scale set by a far coordinate in a later chunk, and a million-point drawing
    gets the same quanta as its paths tested alone."""
    from galvo_core.precision import _on_grid_each

    rng = np.random.default_rng(3)
    p = np.round(rng.uniform(-500.0, 500.0, size=(5000, 2)) * 10.0) / 10.0
    p[10] += 2e-5  # on the grid only within the tolerance the far point below gives
    p[20] += 0.03  # off the grid
    p[4990] = (1e7, 0.0)  # the largest coordinate, in the last chunk
    whole = _on_grid_each(p, 0.1, (0.0, 0.0), chunk=len(p))
    for chunk in (1, 7, 1000, 4096):
        assert np.array_equal(_on_grid_each(p, 0.1, (0.0, 0.0), chunk=chunk), whole)
    assert whole[10] and not whole[20] and whole.sum() == len(p) - 1
    # a drawing of 1.2 M points (several chunks): whole-unit paths and one exact path
    paths = [np.round(ellipse(120_000, x0=float(k) * 700.0)) for k in range(10)] + [ellipse()]
    assert np.array_equal(path_quanta(paths), [1.0] * 10 + [0.0])
