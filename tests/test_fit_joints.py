"""Issue 16 (s3b): on rounded input, a joint left on its input point inside a smooth stretch
moves onto the design estimate, within the stated bound."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod


def _rounded_arc(radius: float, n: int, centre: tuple[float, float]):
    ang = 0.7 + np.arange(n) / radius  # spacing 1 unit along the arc, near 45 degrees
    design = np.c_[centre[0] + radius * np.sin(ang), centre[1] + radius * np.cos(ang)]
    w = np.round(design)
    keep = np.r_[True, (w[1:] != w[:-1]).any(axis=1)]
    return w[keep], np.asarray(centre), radius


def _to_circle(p, centre, radius):
    return abs(float(np.hypot(*(np.asarray(p) - centre))) - radius)


def test_joint_inside_a_rounded_curve_moves_nearer_the_design():
    w, c, r = _rounded_arc(2000.0, 60, (0.3, 0.37))
    n = len(w)
    # the joint: the input point of the middle third farthest from the design
    mid = np.arange(n // 3, 2 * n // 3)
    g = int(mid[np.argmax([_to_circle(w[k], c, r) for k in mid])])
    before = _to_circle(w[g], c, r)
    assert before > 0.3  # a point well off the design
    lo, hi = g - 6, g + 6  # two short lines, as thinning leaves them inside a curve
    points = np.array([w[lo], w[g], w[hi]], dtype=np.float64)
    is_cubic = np.array([False, False])
    tail = np.array([1, 2])
    step = np.array([1, 1])
    gfirst = np.array([lo, g])
    glast = np.array([g, hi])
    owner = np.array([0, 0])
    bound = 0.02 + np.sqrt(0.5)
    arc = fitmod._arc_per_path(w, np.array([n]))
    changed = fitmod._joints_on_the_design(w, arc, points, is_cubic, tail, step, gfirst,
                                           glast, owner, np.array([1.0]), np.array([bound]))
    assert changed.all()
    after = _to_circle(points[1], c, r)
    assert after < before - 0.15
    assert np.abs(points[1] - w[g]).max() <= 0.5 + 1e-12  # inside the rounding square
    # the moved lines keep the stated bound (checked by the independent referee)
    fp = fitmod.FittedPath.from_arrays(0, 1, False, is_cubic, points, gfirst - lo,
                                       glast - lo, 0.0, hi - lo + 1, 3)
    rep = fitmod.check_fit(w[lo:hi + 1], fp, 0.02, 0.02, quantum_units=1.0, report=True)
    assert rep["violation"] == 0.0


def test_joint_at_a_corner_stays_on_its_input_point():
    # two straight rounded lines meeting at 90 degrees: not a smooth stretch, no move
    a = np.round(np.c_[np.arange(0, 30) + 0.3, np.full(30, 0.4)])
    b = np.round(np.c_[np.full(30, 29.3), 0.4 + np.arange(1, 31)])
    w = np.vstack([a, b])
    g = 29
    points = np.array([w[0], w[g], w[-1]], dtype=np.float64)
    arc = fitmod._arc_per_path(w, np.array([len(w)]))
    changed = fitmod._joints_on_the_design(
        w, arc, points, np.array([False, False]), np.array([1, 2]), np.array([1, 1]),
        np.array([0, g]), np.array([g, len(w) - 1]), np.array([0, 0]), np.array([1.0]),
        np.array([0.727]))
    assert not changed.any()
    assert (points[1] == w[g]).all()
