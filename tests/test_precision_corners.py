"""Rounded input, fourth round of issue 16 (s4-a): a curve run ends at its corner (the short
thinned segment the thinning leaves there is the run's end, and so is a rounding wiggle
inside a curve), a corner between a line written as its two ends and a curve is placed from
the line and the curve's tangent, and the merge rounds never lose a range of the path."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod
from galvo_core.fit import check_fit, fit_paths
from galvo_core.runs import split_pieces_many

ROUNDED = [[0.02 + 0.5**0.5, 1.0]]  # (eps, quantum) of a whole-unit path at the defaults


def _pieces(q):
    a, b, curve, *_ = split_pieces_many(q, [len(q)], [False], rounding=ROUNDED)
    return list(zip(a.tolist(), b.tolist(), curve.tolist(), strict=True))


def _arc(n, step, radius=100.0):
    t = np.arange(n) * step / radius
    return np.c_[radius * np.sin(t), radius * (1.0 - np.cos(t))]


def test_short_segment_before_a_corner_ends_the_curve_run():
    arc = _arc(6, 20.0)  # five 20-unit chords of a circle
    d = arc[-1] - arc[-2]
    corner = arc[-1] + 5.0 * d / np.hypot(*d)  # a 5-unit tail: a quarter of the chords
    q = np.vstack([arc, corner, corner + [0.0, 60.0]])  # then a line turning 70 degrees
    pieces = _pieces(q)
    assert (0, 6, True) in pieces  # one run up to the corner (index 6), then the line
    assert (6, 7, False) in pieces
    # exact input keeps the length rule: the short tail is a line of its own there
    a, b, curve, *_ = split_pieces_many(q, [len(q)], [False])
    assert (5, 6) in list(zip(a.tolist(), b.tolist(), strict=True))


def test_short_wiggle_inside_a_curve_does_not_break_the_run():
    arc = _arc(9, 20.0)
    # the rounding leaves a 2-unit segment inside the curve, along the chord 4 -> 5
    d = arc[5] - arc[4]
    u = d / np.hypot(*d)
    wig = np.vstack([arc[:5], arc[4] + 9.0 * u + [0.0, 1.0], arc[4] + 11.0 * u, arc[5:]])
    pieces = _pieces(wig)
    assert [p for p in pieces if not p[2]] == []  # no line inside the curve


def test_merge_round_phases_never_pick_overlapping_groups():
    idx = np.array([0, 2, 3, 4, 7, 8, 12])
    for k in (2, 3):
        pos = fitmod._chain_phase(idx, k)
        for ph in range(k):
            pick = idx[pos == ph]
            assert (np.diff(pick) >= k).all(), (k, ph, pick)
    # consecutive candidates: every k-th one per phase, as before
    assert fitmod._chain_phase(np.arange(7), 3).tolist() == [0, 1, 2, 0, 1, 2, 0]


def _corner_shape(dx, dy, radius=60.0, end=1.4):
    t = np.linspace(end - 1.2, end, 4000)
    arc = np.c_[radius * np.cos(t), radius * np.sin(t)]
    exact = np.vstack([arc, arc[-1] + [80.0, 0.0]]) + [dx, dy]
    pts = np.round(exact)
    return exact, exact[-2], pts[np.r_[True, (pts[1:] != pts[:-1]).any(axis=1)]]


def test_corner_between_a_two_point_line_and_an_arc_is_near_the_true_corner():
    # the line is written as its two rounded ends (no least-squares line): the corner is
    # placed from that line and the arc's tangent, within 0.5 of the true corner (it stayed
    # on its rounded input point before, up to 0.6 off), and the bound holds
    for dx, dy in ((0.3, 0.2), (0.41, -0.37), (-0.2, 0.45)):
        exact, corner, pts = _corner_shape(dx, dy)
        (fp,) = fit_paths([pts], [False])
        ends = np.array([s.points[-1] for s in fp.segments[:-1]])
        assert np.hypot(*(ends - corner).T).min() <= 0.5
        assert not check_fit(pts, fp, 0.02, 0.02, report=True)["violation"]
