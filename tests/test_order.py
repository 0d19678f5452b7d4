"""Scan order: greedy never longer than file order, optimized never longer than greedy,
every stroke once, nesting kept, marks and segments transformed consistently."""

from __future__ import annotations

import itertools
import time

import numpy as np
import pytest

from galvo_core.field import FieldMap
from galvo_core.job import Stroke
from galvo_core.order import (
    KICKS_MIN,
    KICKS_PER_STROKE,
    STALL_WINDOW_MIN,
    Placement,
    _cand_xy,
    _cands_length,
    _greedy,
    _grid_cell,
    _improve,
    _Problem,
    apply_placement,
    apply_to_strokes,
    nesting_constraints,
    order_job_strokes,
    order_strokes,
    orient_strokes,
    travel_length,
)


def square(c: float, r: float, x0: float = 0.0) -> np.ndarray:
    return np.array([(x0 + c - r, c - r), (x0 + c + r, c - r), (x0 + c + r, c + r),
                     (x0 + c - r, c + r), (x0 + c - r, c - r)], dtype=float)


def mixed(seed: int, n: int = 120) -> tuple[list[np.ndarray], list[bool]]:
    rng = np.random.default_rng(seed)
    strokes, closed = [], []
    for _ in range(n):
        p = rng.uniform(0, 1000, 2)
        if rng.random() < 0.3:
            t = np.linspace(0, 2 * np.pi, 17)
            strokes.append(np.c_[p[0] + 10 * np.cos(t), p[1] + 10 * np.sin(t)])
            closed.append(True)
        else:
            k = int(rng.integers(2, 5))
            strokes.append(p + np.cumsum(rng.normal(0, 8, (k, 2)), axis=0))
            closed.append(False)
    return strokes, closed


def valid(pl: list[Placement], n: int) -> None:
    assert sorted(p.index for p in pl) == list(range(n))


@pytest.mark.parametrize("seed", range(6))
def test_greedy_not_longer_than_file_and_optimized_not_longer_than_greedy(seed: int) -> None:
    strokes, closed = mixed(seed)
    f = travel_length(strokes, order_strokes(strokes, method="file"), closed)
    g_pl = order_strokes(strokes, method="greedy", closed=closed)
    o_pl = order_strokes(strokes, method="optimized", closed=closed, time_budget_s=0.3)
    valid(g_pl, len(strokes))
    valid(o_pl, len(strokes))
    g = travel_length(strokes, g_pl, closed)
    o = travel_length(strokes, o_pl, closed)
    assert g <= f + 1e-9
    assert o <= g + 1e-9
    assert g < 0.5 * f  # shuffled input: a real gain
    # a reversal only for open strokes, a rotation only for closed ones
    for p in o_pl:
        assert not (p.reverse and closed[p.index])
        assert not (p.rotate and not closed[p.index])


def test_already_good_order_is_kept() -> None:
    strokes = [np.array([(i * 10.0, 0.0), (i * 10.0 + 5, 0.0)]) for i in range(50)]
    for m in ("greedy", "optimized"):
        pl = order_strokes(strokes, method=m, time_budget_s=0.2)
        assert travel_length(strokes, pl) <= 49 * 5 + 1e-9


def test_apply_placement_rotate_and_reverse() -> None:
    sq = square(0, 1)
    r = apply_placement(sq, True, Placement(0, False, 2))
    assert np.array_equal(r[0], sq[2]) and np.array_equal(r[-1], sq[2]) and len(r) == 5
    line = np.array([(0.0, 0.0), (1.0, 0.0), (2.0, 1.0)])
    assert np.array_equal(apply_placement(line, False, Placement(0, True)), line[::-1])


def test_nesting_rule_inner_before_outer_hatch_before_contour() -> None:
    # three nested squares at x0 = 0 and 1000 (shuffled), hatch strokes of the outer ones
    strokes, closed, kinds, src = [], [], [], []
    for x0 in (1000.0, 0.0):
        for r in (300.0, 100.0, 200.0):
            strokes.append(square(400, r, x0))
            closed.append(True)
            kinds.append("contour")
            src.append(len(src))
    for k in range(4):
        strokes.append(np.array([(1100.0 + k * 5, 400.0), (1100.0 + k * 5, 700.0)]))
        closed.append(False)
        kinds.append("hatch")
        src.append(0)  # the outer square at x0 = 1000
    before = nesting_constraints(strokes, closed, kinds, src)
    assert (1, 2) in before and (2, 0) in before and (4, 5) in before and (5, 3) in before
    assert all((6 + k, 0) in before for k in range(4))
    for m in ("greedy", "optimized"):
        pl = order_strokes(strokes, method=m, closed=closed, before=before, time_budget_s=0.2)
        pos = {p.index: i for i, p in enumerate(pl)}
        assert all(pos[a] < pos[b] for a, b in before)


def test_job_strokes_segments_follow_marks() -> None:
    fm = FieldMap(1.0, (100.0, 100.0))
    # an open stroke: a line then a cubic
    seg_open = (("line", np.array([[0.0, 0.0], [10.0, 0.0]])),
                ("cubic", np.array([[10.0, 0.0], [15.0, 0.0], [20.0, 5.0], [20.0, 10.0]])))
    m_open = fm.to_bits(np.array([[0, 0], [10, 0], [16, 2], [20, 10]], dtype=float))
    # a closed square of 4 line segments far away
    sq = square(500, 10)
    seg_sq = tuple(("line", sq[i:i + 2].copy()) for i in range(4))
    strokes = [Stroke("contour", 0, True, fm.to_bits(sq), seg_sq),
               Stroke("contour", 1, False, m_open, seg_open)]
    out = order_job_strokes(strokes, fm, method="optimized", time_budget_s=0.2)
    assert len(out) == 2
    for s in out:
        segs = s.segments
        # segments continuous and in the direction of the marks
        assert np.allclose(fm.to_bits(segs[0][1][:1])[0], s.marks[0])
        assert np.allclose(fm.to_bits(segs[-1][1][-1:])[0], s.marks[-1])
        for (_, a), (_, b) in zip(segs[:-1], segs[1:], strict=True):
            assert np.allclose(a[-1], b[0])
    # reversing the open stroke reverses the cubic's control points
    rev = apply_to_strokes(strokes, [Placement(1, True)], fm)[0]
    assert np.array_equal(rev.segments[0][1], seg_open[1][1][::-1])
    assert np.array_equal(rev.marks, m_open[::-1])
    # a rotated square starts at a segment joint and its segments start there too
    rot = apply_to_strokes(strokes, [Placement(0, False, 2)], fm)[0]
    assert np.array_equal(rot.marks[0], fm.to_bits(sq[2:3])[0])
    assert np.array_equal(rot.segments[0][1][0], sq[2])


def test_ten_thousand_strokes_greedy() -> None:
    rng = np.random.default_rng(3)
    a = rng.uniform(0, 10000, (10000, 2))
    strokes = list(np.stack([a, a + rng.normal(0, 20, (10000, 2))], axis=1))
    pl = order_strokes(strokes, method="greedy")
    valid(pl, len(strokes))
    f = travel_length(strokes, [Placement(i) for i in range(len(strokes))])
    assert travel_length(strokes, pl) < 0.05 * f


def test_optimized_improves_on_greedy_and_keeps_precedence() -> None:
    """2-opt / Or-opt with reversal, then double-bridge kicks until they stop improving:
    well below greedy on random segments (LKH is about 0.74x greedy here), never above it,
    and the precedence pairs hold after every kick."""
    rng = np.random.default_rng(11)
    a = rng.uniform(0, 1000, (200, 2))
    strokes = list(np.stack([a, a + rng.normal(0, 10, (200, 2))], axis=1))
    g = travel_length(strokes, order_strokes(strokes, method="greedy"))
    o_pl = order_strokes(strokes, method="optimized", time_budget_s=0.5)
    valid(o_pl, len(strokes))
    assert travel_length(strokes, o_pl) < 0.85 * g
    before = [(i, i + 100) for i in range(0, 100, 7)]
    c_pl = order_strokes(strokes, method="optimized", time_budget_s=0.3, before=before)
    pos = {p.index: i for i, p in enumerate(c_pl)}
    assert all(pos[x] < pos[y] for x, y in before)
    assert travel_length(strokes, c_pl) <= travel_length(
        strokes, order_strokes(strokes, method="greedy", before=before)) + 1e-9


def test_ten_thousand_strokes_optimized_not_longer_than_greedy() -> None:
    rng = np.random.default_rng(5)
    a = rng.uniform(0, 10000, (10000, 2))
    strokes = list(np.stack([a, a + rng.normal(0, 20, (10000, 2))], axis=1))
    pl = order_strokes(strokes, method="optimized", time_budget_s=1.0)
    valid(pl, len(strokes))
    g = travel_length(strokes, order_strokes(strokes, method="greedy"))
    assert travel_length(strokes, pl) <= g + 1e-9


def segments(n: int, seed: int, side: float = 1000.0) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    a = rng.uniform(0, side, (n, 2))
    return list(np.stack([a, a + rng.normal(0, 10, (n, 2))], axis=1))


def improve_stats(strokes: list[np.ndarray]) -> tuple[dict, float, float]:
    """Work of the optimized search run to its own end (no deadline), its travel and
    greedy's."""
    prob = _Problem(strokes, [False] * len(strokes), None)
    start = _greedy(prob, [])
    stats: dict = {}
    out = _improve(prob, start, [], time.perf_counter() + 1e6, stats=stats)
    return stats, _cands_length(prob, out), _cands_length(prob, start)


def test_optimized_stops_when_it_stops_improving() -> None:
    """A small job does not spend a budget: with no deadline the search ends after one
    window of kicks that gains nothing (here the order is already the best)."""
    strokes = [np.array([(i * 10.0, 0.0), (i * 10.0 + 5, 0.0)]) for i in range(40)]
    stats, length, _ = improve_stats(strokes)
    assert length == pytest.approx(39 * 5)
    assert stats["kicks"] <= STALL_WINDOW_MIN


def test_optimized_work_grows_linearly() -> None:
    """Kicks, local-search steps and rewritten tour positions at 10x the strokes (same
    density): at most ~20x (linear with a wide margin; moves are bounded by MOVE_SPAN, kicks
    by KICKS_PER_STROKE per stroke), and the travel well below greedy at both sizes."""
    small = improve_stats(segments(300, 1))
    big = improve_stats(segments(3000, 2, side=1000.0 * 10 ** 0.5))
    for key in ("kicks", "ls_steps", "written"):
        assert big[0][key] <= 20 * max(small[0][key], 300), key
    assert big[0]["kicks"] <= max(KICKS_MIN, KICKS_PER_STROKE * 3000)
    for _, length, greedy in (small, big):
        assert length < 0.85 * greedy


def test_orient_strokes_is_optimal_for_a_fixed_order() -> None:
    """The direction of every open stroke and the start of every closed one (among its allowed
    starts) give the shortest travel for the given order: checked against all combinations."""
    for seed in range(4):
        rng = np.random.default_rng(seed)
        strokes, closed, starts = [], [], []
        for k in range(9):
            p = rng.uniform(0, 100, 2)
            if k % 4 == 1:
                t = np.linspace(0, 2 * np.pi, 9)
                strokes.append(np.c_[p[0] + 8 * np.cos(t), p[1] + 8 * np.sin(t)])
                closed.append(True)
                starts.append(np.array([0, 3, 5]))
            else:
                strokes.append(p + np.cumsum(rng.normal(0, 10, (3, 2)), axis=0))
                closed.append(False)
                starts.append(None)
        order = [int(i) for i in rng.permutation(len(strokes))]
        got = orient_strokes(strokes, order, closed=closed, starts=starts)
        assert [p.index for p in got] == order
        choices = [[Placement(i, False, r) for r in starts[i]] if closed[i]
                   else [Placement(i), Placement(i, True)] for i in order]
        best = min(travel_length(strokes, list(c), closed) for c in itertools.product(*choices))
        assert travel_length(strokes, got, closed) == pytest.approx(best, abs=1e-9)
        assert all(p.rotate in starts[p.index] for p in got if closed[p.index])


def test_optimized_finds_the_optimum_of_small_instances() -> None:
    """Six reversible strokes: every order and direction tried (720 orders, each with its
    best directions)."""
    for seed in range(8):
        rng = np.random.default_rng(100 + seed)
        a = rng.uniform(0, 100, (6, 2))
        strokes = list(np.stack([a, a + rng.normal(0, 15, (6, 2))], axis=1))
        best = min(travel_length(strokes, orient_strokes(strokes, list(p)))
                   for p in itertools.permutations(range(6)))
        got = order_strokes(strokes, method="optimized", time_budget_s=0.1)
        assert travel_length(strokes, got) == pytest.approx(best, abs=1e-9)


def test_optimized_search_is_deterministic_for_a_seed() -> None:
    """The same kicks, hence the same order, when the time budget does not cut the search."""
    rng = np.random.default_rng(4)
    a = rng.uniform(0, 1000, (300, 2))
    strokes = list(np.stack([a, a + rng.normal(0, 10, (300, 2))], axis=1))
    closed = [False] * 300
    prob = _Problem(strokes, closed, None)
    start = _greedy(prob, [])
    runs = [_improve(prob, start, [], time.perf_counter() + 60.0, seed=s, max_kicks=300)
            for s in (0, 0, 1)]
    assert runs[0] == runs[1]
    assert sorted(prob.cstroke[runs[2]].tolist()) == list(range(300))


def test_precedence_cycle_and_empty_strokes() -> None:
    """A cycle of precedence pairs cannot be kept: every stroke is still placed once, empty
    strokes at the end, and optimized is not longer than greedy."""
    strokes, closed = mixed(9, 60)
    strokes[5] = np.zeros((0, 2))
    before = [(1, 2), (2, 3), (3, 1), (10, 5), (5, 11), (20, 40)]
    g_pl = order_strokes(strokes, method="greedy", closed=closed, before=before)
    o_pl = order_strokes(strokes, method="optimized", closed=closed, before=before,
                         time_budget_s=0.2)
    valid(g_pl, len(strokes))
    valid(o_pl, len(strokes))
    assert o_pl[-1].index == 5
    pos = {p.index: i for i, p in enumerate(o_pl)}
    assert pos[20] < pos[40]
    assert travel_length(strokes, o_pl, closed) <= travel_length(strokes, g_pl, closed) + 1e-9


def _ring_scan_greedy(prob: _Problem, before: list[tuple[int, int]]) -> list[int]:
    """The greedy walk as a plain search by rings of square buckets (the rule the compiled
    k-d tree walk keeps, ties included): buckets of side _grid_cell, visited ring by ring
    (bottom row, top row, left column, right column), a bucket's points in the order they
    became alive, the first strictly nearest kept, stop after ring r once the best is within
    r cells; beyond ring 8 every alive point, the lowest index among the nearest."""
    pts = prob.cpt
    cell = _grid_cell(pts)
    lo = pts.min(axis=0)
    ij = np.floor((pts - lo) / cell).astype(np.int64)
    nx, ny = int(ij[:, 0].max()) + 1, int(ij[:, 1].max()) + 1
    buckets: dict[tuple[int, int], list[int]] = {}
    alive = np.zeros(len(pts), dtype=bool)
    _, ext = _cand_xy(prob)

    def insert(ids: np.ndarray) -> None:
        for k in ids.tolist():
            alive[k] = True
            buckets.setdefault((int(ij[k, 0]), int(ij[k, 1])), []).append(k)

    def ring(ci: int, cj: int, r: int) -> list[tuple[int, int]]:
        if r == 0:
            return [(ci, cj)]
        return ([(ci + d, cj - r) for d in range(-r, r + 1)]
                + [(ci + d, cj + r) for d in range(-r, r + 1)]
                + [(ci - r, cj + d) for d in range(-r + 1, r)]
                + [(ci + r, cj + d) for d in range(-r + 1, r)])

    def nearest(p: np.ndarray) -> int:
        ci, cj = (int(v) for v in np.floor((p - lo) / cell))
        best, bd = -1, np.inf
        for r in range(max(nx, ny) + abs(ci) + abs(cj) + 2):
            if r > 8:
                ids = np.flatnonzero(alive)
                d2 = ((pts[ids] - p) ** 2).sum(axis=1)
                return int(ids[np.flatnonzero(d2 == d2.min())[0]])
            for key in ring(ci, cj, r):
                for k in buckets.get(key, []):
                    d2 = float(((pts[k] - p) ** 2).sum())
                    if alive[k] and d2 < bd:
                        best, bd = k, d2
            if best >= 0 and np.sqrt(bd) <= r * cell:
                return best
        return best

    n = prob.n
    succ: list[list[int]] = [[] for _ in range(n)]
    npred = [0] * n
    for a, b in before:
        succ[a].append(b)
        npred[b] += 1
    for i in range(n):
        if npred[i] == 0:
            insert(prob.cand_of[i])
    cand = int(prob.cand_of[next(i for i in range(n) if npred[i] == 0)][0])
    out = []
    while True:
        i = int(prob.cstroke[cand])
        out.append(cand)
        alive[prob.cand_of[i]] = False
        for j in succ[i]:
            npred[j] -= 1
            if npred[j] == 0:
                insert(prob.cand_of[j])
        if len(out) == n:
            return out
        cand = nearest(ext[cand])


@pytest.mark.parametrize("seed", range(4))
def test_greedy_walk_is_the_bucket_ring_search_ties_included(seed: int) -> None:
    """The compiled k-d tree walk picks what a ring-by-ring search of square buckets picks,
    ties too (integer points on a small lattice: many ends at the same distance; crowded
    clusters; far outliers beyond ring 8; closed strokes with several starts; precedence)."""
    rng = np.random.default_rng(seed)
    strokes, closed = [], []
    for k in range(700):
        if k % 50 == 0:  # a far outlier
            p = rng.integers(-4000, 4000, 2).astype(float)
        elif k % 3 == 0:  # a crowded cluster
            p = rng.integers(0, 12, 2).astype(float)
        else:
            p = rng.integers(0, 300, 2).astype(float)
        if k % 7 == 0:
            sq = np.array([(0, 0), (3, 0), (3, 4), (0, 4), (0, 0)], dtype=float) + p
            strokes.append(sq)
            closed.append(True)
        else:
            strokes.append(np.stack([p, p + rng.integers(-5, 6, 2)]))
            closed.append(False)
    before = [(i, i + 1) for i in range(0, 200, 9)] + [(i, i + 300) for i in range(0, 90, 4)]
    prob = _Problem(strokes, closed, None)
    want = _ring_scan_greedy(prob, before)
    got = _greedy(prob, before)
    assert got == want
    assert sorted(int(prob.cstroke[c]) for c in got) == list(range(len(strokes)))


def test_greedy_walk_tie_beyond_ring_8_takes_the_lowest_index() -> None:
    """Four ends 1000 units from the start, in four directions, more than 8 buckets away:
    the bucket search looks at every alive point there and keeps the lowest index (stroke
    1), not the first of its ring (stroke 4, in the ring's bottom row)."""
    far = [(1000.0, 0.0), (0.0, 1000.0), (-1000.0, 0.0), (0.0, -1000.0)]
    strokes = [np.array([(0.0, 0.0), (0.0, 0.0)])] + [np.array([p, p]) for p in far]
    strokes += [np.array([(800.0 + k % 20, 800.0 + k // 20)] * 2) for k in range(400)]
    prob = _Problem(strokes, [False] * len(strokes), None)
    assert 1000.0 > 8 * _grid_cell(prob.cpt)
    got = _greedy(prob, [])
    assert got == _ring_scan_greedy(prob, [])
    assert [int(prob.cstroke[c]) for c in got[:2]] == [0, 1]
