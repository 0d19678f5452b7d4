"""Rounded input, issue 16 (fifth round): cubic outlines whose tangent points lie on half
units. Rounding (half to even) puts the point where the design touches a grid line one unit
off its neighbours: the thinning leaves a zigzag of short segments there, which used to end
the curve runs (corners by the length rule, false inflections) and cost lines."""

from __future__ import annotations

import math

import numpy as np
from _util import flattened_cubic as _cubic

from galvo_core.fit import check_fit, fit_paths
from galvo_core.runs import split_pieces_many


def _whole_units(segs) -> np.ndarray:
    """A closed outline of cubics written densely and rounded to whole units (as a PLT
    file stores it), consecutive repeats dropped."""
    parts = [_cubic(*s) for s in segs]
    p = np.round(np.vstack([parts[0]] + [q[1:] for q in parts[1:]]))
    keep = np.r_[True, (p[1:] != p[:-1]).any(axis=1)]
    return p[keep]


def _oval(cx: float, cy: float, rx: float, ry: float, k: float = 0.56) -> list[tuple]:
    """Four cubics (a typeface's "o"): on-curve points at the extrema, G1 joins."""
    ends = [(cx + rx, cy), (cx, cy + ry), (cx - rx, cy), (cx, cy - ry)]
    tans = [(0, 1), (-1, 0), (0, -1), (1, 0)]
    out = []
    for i in range(4):
        a, b = np.array(ends[i]), np.array(ends[(i + 1) % 4])
        ta, tb = np.array(tans[i]), np.array(tans[(i + 1) % 4])
        h = k * float(np.hypot(*(b - a))) / math.sqrt(2.0)
        out.append((a, a + h * ta, b - h * tb, b))
    return out


def test_tangent_points_on_half_units_cost_no_lines():
    # five ovals whose extrema lie on half units (em 1500 of a 1000-unit typeface)
    ovals = [_oval(1000.5 + 1000 * i, 800.5, rx + 0.5 * (i % 2), ry)
             for i, (rx, ry) in enumerate([(300, 420), (220, 160), (451, 333), (180, 260),
                                           (377, 377)])]
    paths = [_whole_units(s) for s in ovals]
    fps = fit_paths(paths, [True] * len(paths))
    own = sum(len(s) for s in ovals)
    n = sum(f.n_segments for f in fps)
    # before: 33 segments for 20 design cubics (1.65x), lines at every extremum
    assert n <= 1.2 * own
    for p, f in zip(paths, fps, strict=True):
        assert not check_fit(p, f, 0.02, 0.02, report=True)["violation"]


def _pieces(q: np.ndarray, eps: float = 0.727):
    a, b, curve, _, _ = split_pieces_many(q, [len(q)], [False], rounding=[[eps, 1.0]])
    return list(zip(a.tolist(), b.tolist(), curve.tolist(), strict=True))


def _arc_points(radius: float, a0: float, a1: float, n: int, c=(0.0, 0.0)) -> np.ndarray:
    t = np.linspace(a0, a1, n)
    return np.c_[c[0] + radius * np.cos(t), c[1] + radius * np.sin(t)]


def test_rounding_zigzag_inside_a_curve_is_one_run():
    # thinned points of an arc (radius 600, chords ~38) with a zigzag of two short
    # segments (2 and 6 units) where the rounding flipped a tangent point
    arc = np.round(_arc_points(600.0, 0.0, 0.9, 16))
    i = 8
    d = arc[i + 1] - arc[i]
    u = d / np.hypot(*d)
    nrm = np.array([-u[1], u[0]])
    zig = np.array([arc[i] + 12 * u, arc[i] + 14 * u + nrm, arc[i] + 20 * u])
    q = np.vstack([arc[: i + 1], np.round(zig), arc[i + 1:]])
    pieces = _pieces(q)
    # one curve run over the zigzag (the 80-degree limit cuts nothing at 52 degrees)
    assert pieces == [(0, len(q) - 1, True)]


def test_corner_beside_a_short_segment_stays_a_corner():
    # two arcs meeting at a corner of about 80 degrees; the thinning left a 4-unit
    # segment of the first arc's end before the corner
    first = _arc_points(500.0, -0.6, 0.0, 12, c=(-500.0, 0.0))
    end = first[-1] + np.array([0.3, 4.0])
    second = _arc_points(500.0, math.pi * 0.55, math.pi * 0.55 + 0.6, 12,
                         c=end - 500.0 * np.array([math.cos(math.pi * 0.55),
                                                   math.sin(math.pi * 0.55)]))
    q = np.round(np.vstack([first, end, second[1:]]))
    pieces = _pieces(q)
    corner = len(first)  # the point after the short segment
    assert any(b == corner for _, b, c in pieces if c)  # a curve piece ends at the corner
    assert all(not (a < corner < b) for a, b, _ in pieces)  # and none runs through it


def test_short_design_line_between_two_corners_stays():
    # a 10-unit flat between two right-angle corners, curves on both sides
    left = _arc_points(400.0, -0.5, 0.0, 10, c=(-400.0, 0.0))
    top = left[-1]
    flat_end = top + np.array([-10.0, 0.0])  # turned 90 degrees left, then left again
    right = np.c_[flat_end[0] + 0 * np.arange(1), flat_end[1]]
    down = _arc_points(400.0, math.pi, math.pi + 0.5, 10, c=(flat_end[0] + 400.0,
                                                             flat_end[1]))
    q = np.round(np.vstack([left, right, down[1:]]))
    q = q[np.r_[True, (q[1:] != q[:-1]).any(axis=1)]]
    pieces = _pieces(q)
    k = len(left) - 1  # the first corner; the second is k + 1
    assert (k, k + 1, False) in pieces
