"""Curve runs (paper 000 §2.2): joining, corners, inflections, < 90° pieces, tangents."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from galvo_core.runs import (
    find_runs,
    point_tangents,
    segmented_cumsum,
    split_pieces,
    split_pieces_many,
)
from galvo_core.thin import thin


def arc(r, a0, a1, n, c=(0.0, 0.0)):
    t = np.linspace(a0, a1, n)
    return np.c_[c[0] + r * np.cos(t), c[1] + r * np.sin(t)]


def covers_path(pieces, m):
    assert pieces[0].a == 0 and pieces[-1].b == m - 1
    for p0, p1 in zip(pieces[:-1], pieces[1:], strict=True):
        assert p0.b == p1.a
    for p in pieces:
        assert p.b > p.a
        if p.kind == "line":
            assert p.b == p.a + 1


def test_circle_is_one_run_split_under_the_turn_limit():
    q = arc(100, 0, 2 * math.pi, 121)
    q[-1] = q[0]
    assert find_runs(q) == [(0, 120)]
    pieces, t_in, t_out = split_pieces(q, closed=True, max_turn_deg=80)
    covers_path(pieces, len(q))
    assert all(p.kind == "curve" for p in pieces)
    assert len(pieces) == 5  # 360 / 80 -> 5 balanced pieces of 72 degrees
    for p in pieces:
        cosang = float(t_out[p.a] @ t_in[p.b])
        assert cosang > math.cos(math.radians(80))


def test_polygon_has_no_curve_runs():
    q = np.array([[0, 0], [10, 0], [10, 10], [5, 14], [0, 10], [0, 0]], float)
    assert find_runs(q) == []
    pieces, _, _ = split_pieces(q, closed=True)
    assert [p.kind for p in pieces] == ["line"] * 5


def test_runs_shorter_than_four_points_stay_lines():
    q = np.array([[0, 0], [10, 0], [20, 0.5], [30, 1.5], [30, 20]], float)
    assert find_runs(q) == [(0, 3)]  # 4 points, smooth vertices 1 and 2: a curve run
    q1 = np.array([[0, 0], [10, 0], [20, 0.5], [25, 10], [25, 20]], float)
    assert find_runs(q1) == []  # vertex 2 is a corner: only 3 points before it
    q2 = np.array([[0, 0], [10, 0], [20, 0.5], [30, 20]], float)
    assert find_runs(q2) == []


def test_inflection_splits_an_s_curve_at_the_shared_point():
    a = arc(50, math.pi, 0, 40, c=(50, 0))  # clockwise upper half
    b = arc(50, math.pi, 2 * math.pi, 40, c=(150, 0))[1:]  # counter-clockwise lower half
    q = np.vstack([a, b])
    runs = find_runs(q)
    assert len(runs) == 2
    assert runs[0][1] == runs[1][0]
    assert abs(runs[0][1] - 39) <= 1


def test_corners_end_runs():
    # two arcs meeting at a sharp corner (a pointed arch)
    left = arc(100, math.pi, math.pi / 3, 60, c=(100, 0))
    right = arc(100, 2 * math.pi / 3, 0, 60, c=(200, 0))[1:]
    q = np.vstack([left, right])
    runs = find_runs(q)
    assert runs == [(0, 59), (59, 118)]


def test_long_line_into_a_curve_stays_a_line():
    line = np.array([[-200.0, 0.0]])
    q = np.vstack([line, arc(10, -math.pi / 2, 0, 20, c=(0, 10))])
    pieces, _, _ = split_pieces(q)
    assert pieces[0].kind == "line" and (pieces[0].a, pieces[0].b) == (0, 1)
    assert any(p.kind == "curve" for p in pieces)


def test_tangents_from_neighbours_match_the_circle():
    rng = np.random.default_rng(1)
    t = np.sort(rng.uniform(0, math.pi, 60))  # uneven spacing
    q = np.c_[100 * np.cos(t), 100 * np.sin(t)]
    t_in, t_out = point_tangents(q)
    true = np.c_[-np.sin(t), np.cos(t)]
    # interior: two-sided estimate; ends: one-sided parabola (not one segment)
    ang_err = np.arccos(np.clip((t_out[:-1] * true[:-1]).sum(1), -1, 1))
    assert ang_err.max() < 0.01
    seg_dir = (q[1] - q[0]) / np.hypot(*(q[1] - q[0]))
    assert np.arccos(t_out[0] @ true[0]) < 0.5 * np.arccos(seg_dir @ true[0])
    end_err = np.arccos(np.clip(t_in[-1] @ true[-1], -1, 1))
    assert end_err < 0.01


def test_thinned_ellipse_pieces_respect_turn_limit():
    t = np.linspace(0, 2 * math.pi, 3000)
    p = np.c_[300 * np.cos(t), 80 * np.sin(t)]
    p[-1] = p[0]
    q = p[thin(p, 0.02, closed=True)]
    pieces, t_in, t_out = split_pieces(q, closed=True)
    covers_path(pieces, len(q))
    for pc in pieces:
        if pc.kind == "curve":
            assert float(t_out[pc.a] @ t_in[pc.b]) > math.cos(math.radians(80)) - 1e-9


# --- many paths at once ------------------------------------------------------------------


def _mixed_thinned_paths(seed):
    """Thinned-path-like polylines of every kind the rules distinguish, with their flags."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(40):
        kind = i % 8
        if kind == 0:  # closed circle, smooth seam, 5 pieces of 72 degrees
            q = arc(rng.uniform(5, 500), 0, 2 * math.pi, int(rng.integers(20, 140)))
            q[-1] = q[0]
            out.append((q, True))
        elif kind == 1:  # a spiral turning several times (many balanced cuts)
            t = np.linspace(0, rng.uniform(7, 20), int(rng.integers(60, 200)))
            out.append((np.c_[t * np.cos(t), t * np.sin(t)] * 10, False))
        elif kind == 2:  # S-curve: an inflection
            a = arc(50, math.pi, 0, 30, c=(50, 0))
            b = arc(50, math.pi, 2 * math.pi, 30, c=(150, 0))[1:]
            out.append((np.vstack([a, b]), False))
        elif kind == 3:  # polygon: corners only
            out.append(
                (np.array([[0, 0], [10, 0], [10, 10], [5, 14], [0, 10], [0, 0]], float), True)
            )
        elif kind == 4:  # tiny paths: one, two, three points
            out.append((rng.normal(size=(int(rng.integers(1, 4)), 2)) * 10, bool(i % 3)))
        elif kind == 5:  # long line running into a curve, short tail at the end
            q = np.vstack([[[-200.0, 0.0]], arc(10, -math.pi / 2, 0, 20, c=(0, 10))])
            out.append((np.vstack([q, q[-1:] + [0.0, 0.3]]), False))
        elif kind == 6:  # noisy arc on integer coordinates
            t = np.sort(rng.uniform(0, 3, 50))
            out.append(
                (np.round(np.c_[np.cos(t), np.sin(t)] * 80 + rng.normal(0, 0.5, (50, 2))), False)
            )
        else:  # closed path whose seam is a corner
            q = arc(100, 0, 1.5 * math.pi, 40)
            out.append((np.vstack([q, [[0.0, 0.0]], q[:1]]), True))
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_many_paths_at_once_give_exactly_the_pieces_of_each_path(seed):
    """split_pieces_many on the concatenation = split_pieces per path, offset by the path's
    first index, bit for bit (tangents too); no piece crosses a path boundary."""
    items = _mixed_thinned_paths(seed)
    qs = [q for q, _ in items]
    lens = [len(q) for q in qs]
    a, b, curve, t_in, t_out = split_pieces_many(np.concatenate(qs), lens, [c for _, c in items])
    off = np.concatenate(([0], np.cumsum(lens)))
    expected = []
    for k, (q, c) in enumerate(items):
        pieces, ti, to = split_pieces(q, closed=c)
        expected += [(p.a + off[k], p.b + off[k], p.kind == "curve") for p in pieces]
        np.testing.assert_array_equal(t_in[off[k] : off[k + 1]], ti)
        np.testing.assert_array_equal(t_out[off[k] : off[k + 1]], to)
    assert list(zip(a.tolist(), b.tolist(), curve.tolist(), strict=True)) == expected
    owner = np.searchsorted(off, a, side="right")
    assert (np.searchsorted(off, b, side="left") == owner).all()  # b <= the path's last


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 150), max_size=30), st.integers(0, 2**31))
def test_segmented_cumsum_is_cumsum_of_each_segment_bit_for_bit(lens, seed):
    x = np.random.default_rng(seed).normal(size=sum(lens)) * 1e3
    got = segmented_cumsum(x, lens)
    s = 0
    for n in lens:
        np.testing.assert_array_equal(got[s : s + n], np.cumsum(x[s : s + n]))
        s += n
