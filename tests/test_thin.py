"""Line thinning (paper 000 §2.1): guarantee, near-optimality, degenerate input, and that the
compiled sleeve search and DP give the plain definitions' result (brute force: the farthest
valid end, the fewest lines over the window's and the greedy's shortcuts with the documented
tie rule). Speed is measured in bench/bench_thin.py, not here."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import galvo_core.thin as thin_mod
from galvo_core.errors import ParamError
from galvo_core.geometry import point_segment_distance
from galvo_core.thin import thin, thin_many


def assert_thin_guarantee(p, kept, eps):
    p = np.asarray(p, float)
    assert kept[0] == 0
    assert np.all(np.diff(kept) > 0)
    # no duplicate kept twice in a row
    assert np.all(np.any(p[kept[1:]] != p[kept[:-1]], axis=1))
    # last distinct point kept
    last_distinct = len(p) - 1
    while last_distinct > 0 and np.array_equal(p[last_distinct], p[last_distinct - 1]):
        last_distinct -= 1
    assert kept[-1] == last_distinct
    for a, b in zip(kept[:-1], kept[1:], strict=True):
        if b - a > 1:
            d = point_segment_distance(p[a + 1 : b], p[a], p[b])
            assert d.max() <= eps * (1 + 1e-9), (a, b, d.max())


def imai_iri(q, eps, window=120):
    """Fewest kept points (exact shortest path over all valid shortcuts within a window)."""
    n = len(q)
    best = [math.inf] * n
    best[0] = 0
    for j in range(1, n):
        for i in range(j - 1, max(-1, j - window), -1):
            if best[i] + 1 < best[j]:
                if j - i < 2 or point_segment_distance(q[i + 1 : j], q[i], q[j]).max() <= eps:
                    best[j] = best[i] + 1
    return best[-1] + 1


@pytest.mark.parametrize("bad", [0, 0.0, -0.02, float("nan"), float("inf"), "x", None])
def test_bad_tolerance_refused_naming_parameter(bad):
    with pytest.raises(ParamError, match="eps_line"):
        thin(np.zeros((3, 2)), bad)


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 10_000),
    st.integers(2, 400),
    st.sampled_from([0.02, 0.1, 1.0]),
    st.sampled_from(["walk", "smooth", "grid"]),
)
def test_every_dropped_point_within_eps_of_its_line(seed, n, eps, kind):
    rng = np.random.default_rng(seed)
    if kind == "walk":
        p = np.cumsum(rng.normal(0, 0.3, (n, 2)), axis=0)
    elif kind == "smooth":
        x = np.sort(rng.uniform(0, 50, n))
        p = np.c_[x, 10 * np.sin(x / rng.uniform(1, 8))] + rng.normal(0, 0.005, (n, 2))
    else:  # integer plotter coordinates with many repeats and backtracking
        p = np.cumsum(rng.integers(-1, 2, (n, 2)), axis=0).astype(float)
    assert_thin_guarantee(p, thin(p, eps), eps)


def test_collinear_run_keeps_two_points_and_corners_are_kept():
    x = np.linspace(0, 100, 1001)
    line = np.c_[x, 0.5 * x]
    assert list(thin(line, 0.02)) == [0, 1000]
    # a square sampled densely keeps exactly its 4 corners + closing point
    side = np.linspace(0, 1, 50, endpoint=False)[:, None]
    c = np.array([[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]], float)
    sq = np.vstack([c[i] + side * (c[i + 1] - c[i]) for i in range(4)] + [c[:1]])
    kept = thin(sq, 0.02, closed=True)
    np.testing.assert_array_equal(sq[kept], c)


def test_duplicates_dropped_and_indices_are_original():
    p = np.array([[0, 0], [0, 0], [1, 0], [1, 0], [1, 0], [2, 1], [2, 1]], float)
    kept = thin(p, 0.01)
    assert list(kept) == [0, 2, 5]
    assert list(thin(np.array([[3.0, 3.0]] * 5), 0.02)) == [0]
    assert list(thin(np.zeros((0, 2)), 0.02)) == []
    assert list(thin([[1.0, 2.0], [4.0, 6.0]], 0.02)) == [0, 1]


def test_closed_ring_keeps_its_seam():
    t = np.linspace(0, 2 * np.pi, 400)
    p = np.c_[50 * np.cos(t), 50 * np.sin(t)]
    p[-1] = p[0]
    kept = thin(p, 0.02, closed=True)
    assert kept[0] == 0 and kept[-1] == len(p) - 1
    assert_thin_guarantee(p, kept, 0.02)


def test_back_and_forth_is_not_hidden():
    """A path that doubles back on itself must keep the turning point (segment distance)."""
    p = np.array([[0, 0], [10, 0], [5, 0]], float)
    assert list(thin(p, 0.02)) == [0, 1, 2]


@pytest.mark.parametrize(
    "offset,scale,eps", [(1e7, 1.0, 0.02), (0.0, 1e-6, 1e-8), (-1e7, 1e-3, 1e-5)]
)
def test_huge_and_tiny_coordinates(offset, scale, eps):
    t = np.linspace(0, 3, 2000)
    p = offset + scale * np.c_[1000 * t, 200 * np.sin(3 * t)]
    kept = thin(p, eps)
    assert 2 < len(kept) < len(p)
    assert_thin_guarantee(p, kept, eps)


def test_near_optimal_against_imai_iri():
    """Dense noisy smooth curves: within 2 % of the optimum vertex count."""
    rng = np.random.default_rng(7)
    total_greedy = total_opt = 0
    for _ in range(3):
        n = 700
        x = np.sort(rng.uniform(0, 100, n))
        y = np.sin(x * rng.uniform(0.05, 0.3)) * rng.uniform(5, 30) + rng.normal(0, 0.003, n)
        q = np.c_[x, y]
        g = len(thin(q, 0.02))
        o = imai_iri(q, 0.02)
        assert g <= math.floor(1.02 * o) + 1, (g, o)
        total_greedy += g
        total_opt += o
    assert total_greedy <= 1.02 * total_opt


def test_dense_ellipse_keeps_few_points():
    """200k points of a smooth ellipse: a few hundred kept lines, each within eps."""
    t = np.linspace(0, 2 * np.pi, 200_000)
    p = np.c_[400 * np.cos(t), 300 * np.sin(t)]
    kept = thin(p, 0.02)
    assert len(kept) < 1000
    assert_thin_guarantee(p, kept, 0.02)


def greedy_reference(p, eps, window=400):
    """The greedy sleeve by its definition: from each kept point the farthest j whose
    segment serves every point between (brute force over the next ``window`` points)."""
    chain = [0]
    i = 0
    n = len(p)
    while i < n - 1:
        js = np.arange(i + 1, min(n, i + window + 1))
        if len(js) == 1:
            chain.append(i + 1)
            i += 1
            continue
        a = p[i]
        ab = p[js] - a  # (J, 2) candidate segments
        ap = p[i + 1 : js[-1]] - a  # (K, 2) points that may lie between
        den = np.maximum((ab * ab).sum(1), 1e-300)
        s = np.clip((ap @ ab.T) / den, 0.0, 1.0)  # (K, J)
        ex = ap[:, :1] - s * ab[:, 0]
        ey = ap[:, 1:] - s * ab[:, 1]
        d2 = ex * ex + ey * ey
        between = np.arange(i + 1, js[-1])[:, None] < js[None, :]
        worst = np.where(between, d2, 0.0).max(axis=0)
        j = int(js[np.flatnonzero(worst <= eps * eps)[-1]])
        assert j < i + window or j == n - 1, "reference window too small"
        chain.append(j)
        i = j
    return np.array(chain)


def _dense_wavy(seed, n):
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(0, n / 40, n))
    y = 12 * np.sin(x / 7) + 5 * np.sin(x / 2.3 + 1) + rng.normal(0, 0.002, n)
    return np.c_[x, y]


@pytest.mark.parametrize("seed", [0, 1])
def test_batched_greedy_is_the_plain_greedy(seed):
    """A long dense curve (the walkers start seeds along it, windows are resized and
    retried): the kept points are exactly the plain greedy's, farthest valid end each time."""
    p = _dense_wavy(seed, 9000)
    kept = thin(p, 0.02)
    assert len(p) >= 16 * len(kept)  # dense: the DP stage is not involved
    np.testing.assert_array_equal(kept, greedy_reference(p, 0.02))


def test_dp_is_a_shortest_path_over_window_and_greedy_shortcuts(monkeypatch):
    """The DP's vertex count is the fewest over every valid shortcut of at most 24 steps
    plus the greedy ones (brute force), and never more than the greedy's."""
    rng = np.random.default_rng(3)
    p = np.cumsum(rng.normal(0, 0.5, (400, 2)), axis=0)
    eps = 1.0
    kept = thin(p, eps)
    monkeypatch.setattr(thin_mod, "_DP_RATIO", 0)  # the greedy alone
    greedy = thin(p, eps)
    assert len(kept) <= len(greedy)
    n = len(p)
    best = [math.inf] * n
    best[0] = 1
    greedy_in = {int(b): int(a) for a, b in zip(greedy[:-1], greedy[1:], strict=True)}
    for j in range(1, n):
        for i in range(max(0, j - 24), j):
            if j - i < 2 or point_segment_distance(p[i + 1 : j], p[i], p[j]).max() <= eps:
                best[j] = min(best[j], best[i] + 1)
        if j in greedy_in:
            best[j] = min(best[j], best[greedy_in[j]] + 1)
    assert len(kept) == best[-1]


def test_near_optimal_on_integer_staircase():
    """Integer plotter coordinates at a tolerance of half a unit (few points per kept line,
    where the plain greedy sleeve was up to 20 % over): within 2 % of the optimum."""
    total_g = total_o = 0
    for r in (40, 90, 150):
        t = np.linspace(0, 2 * np.pi, int(6 * r))
        p = np.round(np.c_[r * np.cos(t), 0.6 * r * np.sin(t)])
        keep = np.concatenate(([True], np.any(p[1:] != p[:-1], axis=1)))
        q = p[keep]
        kept = thin(q, 0.5)
        assert_thin_guarantee(q, kept, 0.5)
        total_g += len(kept)
        total_o += imai_iri(q, 0.5)
    assert total_g <= 1.02 * total_o, (total_g, total_o)


def _mixed_paths(seed):
    rng = np.random.default_rng(seed)
    out = [np.zeros((0, 2)), np.array([[1.0, 1.0]]), np.array([[2.0, 2.0]] * 4)]
    for _ in range(30):
        n = int(rng.integers(2, 300))
        kind = rng.integers(0, 4)
        if kind == 0:
            p = np.cumsum(rng.normal(0, 0.3, (n, 2)), axis=0)
        elif kind == 1:
            x = np.sort(rng.uniform(0, 50, n))
            p = np.c_[x, 10 * np.sin(x / rng.uniform(1, 8))]
        elif kind == 2:
            p = np.cumsum(rng.integers(-1, 2, (n, 2)), axis=0).astype(float)
        else:  # dense smooth curve (long sleeves) with a repeated tail
            t = np.linspace(0, rng.uniform(1, 6), 20 * n)
            p = np.vstack(
                [
                    np.c_[300 * np.cos(t), 200 * np.sin(t)],
                    [[300 * np.cos(t[-1]), 200 * np.sin(t[-1])]] * 3,
                ]
            )
        out.append(p)
    rng.shuffle(out)
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("eps", [0.02, 0.5, 1.0])
def test_thin_many_is_thin_per_path(seed, eps):
    paths = _mixed_paths(seed)
    many = thin_many(paths, eps)
    assert len(many) == len(paths)
    for p, k in zip(paths, many, strict=True):
        np.testing.assert_array_equal(k, thin(p, eps))
        if len(p):
            assert_thin_guarantee(p, k, eps)
    assert thin_many([], eps) == []
    with pytest.raises(ParamError, match="eps_line"):
        thin_many(paths, 0.0)


def test_many_small_paths_in_one_call_equal_one_call_each():
    """2000 small integer paths in one call (chains marked by pointer doubling) give what
    one call per path gives (chains walked one by one), sparse input too."""
    rng = np.random.default_rng(2)
    small = [np.cumsum(rng.integers(-3, 4, (15, 2)), axis=0).astype(float) for _ in range(2000)]
    walk = np.cumsum(rng.normal(0, 0.5, (5000, 2)), axis=0)
    paths = small + [walk]
    for eps in (0.02, 1.0):
        many = thin_many(paths, eps)
        for p, k in zip(paths[::50] + [walk], many[::50] + [many[-1]], strict=True):
            np.testing.assert_array_equal(k, thin(p, eps))
            assert_thin_guarantee(p, k, eps)


def _integer_outlines():
    """Integer-coordinate outlines with long collinear runs (where the sweep's rounding
    slack and the greedy's strict wedge can disagree) and rounded curves."""
    rng = np.random.default_rng(5)
    out = []
    for r in (30, 60, 120, 400):
        t = np.linspace(0, 2 * np.pi, int(5 * r))
        out.append(np.round(np.c_[r * np.cos(t), 0.7 * r * np.sin(t)]))
    for _ in range(6):  # polylines through integer points, one point per unit step
        corners = np.cumsum(rng.integers(-40, 41, (8, 2)), axis=0)
        runs = [
            np.round(a + np.linspace(0, 1, int(np.abs(b - a).max()) + 1)[:-1, None] * (b - a))
            for a, b in zip(corners[:-1], corners[1:], strict=True)
        ]
        out.append(np.concatenate(runs + [corners[-1:]]))
    return out


def _valid_ends(p, i, end, eps):
    """Every j in (i, end] whose segment from p[i] serves every point between (brute force,
    the same arithmetic as the thinning's exact test)."""
    out = []
    for j in range(i + 1, end + 1):
        if j == i + 1:
            out.append(j)
            continue
        a = p[i]
        b = p[j] - a
        q = p[i + 1 : j] - a
        den = b @ b
        t = np.zeros(len(q))
        if den > 0:
            t = np.clip((q[:, 0] * b[0] + q[:, 1] * b[1]) / den, 0.0, 1.0)
        ex = q[:, 0] - t * b[0]
        ey = q[:, 1] - t * b[1]
        if (ex * ex + ey * ey).max() <= eps * eps:
            out.append(j)
    return out


@pytest.mark.parametrize("eps", [0.02, 0.5, 1.0, 2.0])
def test_sleeve_never_loses_a_valid_end(eps):
    """The slope-interval sleeve admits every valid end (also on integer collinear runs,
    where a point lies exactly eps from a line and the interval closes to a single
    direction), and the reach is the farthest valid end."""
    rng = np.random.default_rng(8)
    paths = _integer_outlines() + [
        np.cumsum(rng.normal(0, 0.4, (700, 2)), axis=0),
        _dense_wavy(2, 900),
    ]
    checked = 0
    for p in paths:
        q = p[thin_mod.dedup_indices(p)]
        x = np.ascontiguousarray(q[:, 0])
        y = np.ascontiguousarray(q[:, 1])
        n = len(q)
        cand = np.empty(n + 1, dtype=np.int64)
        sure = np.empty(n + 1, dtype=np.int8)
        rr = np.empty(n + 1)
        for i in range(0, n - 1, 7):
            end = min(n - 1, i + 60)
            valid = _valid_ends(q, i, end, eps)
            nc = thin_mod._candidates(x, y, i, end, eps, thin_mod._SLACK, cand, sure, rr)
            got = cand[:nc].tolist()
            assert set(valid) <= set(got), (i, sorted(set(valid) - set(got)))
            if valid[-1] < end:  # (the window did not cut the reach short)
                r = thin_mod._reach(x, y, i, end, eps, thin_mod._SLACK, cand, sure, rr)
                assert r == valid[-1]
            checked += 1
    assert checked > 500


def dp_reference(p, eps, window=24):
    """The DP's result by its definition: fewest lines over every valid shortcut of at
    most ``window`` steps plus the greedy chain's longer ones; of several predecessors at the
    same distance the smallest start, a long greedy shortcut only when strictly better."""
    n = len(p)
    chain = [0]
    while chain[-1] < n - 1:
        chain.append(_valid_ends(p, chain[-1], n - 1, eps)[-1])
    longs = {b: a for a, b in zip(chain[:-1], chain[1:], strict=True) if b - a > window}
    ok = [set(_valid_ends(p, i, min(n - 1, i + window), eps)) for i in range(n)]
    best = [0] + [n + 1] * (n - 1)
    pred = [-1] * n
    for j in range(1, n):
        for i in range(max(0, j - window), j):
            if j in ok[i] and best[i] + 1 < best[j]:
                best[j] = best[i] + 1
                pred[j] = i
        if j in longs and best[longs[j]] + 1 < best[j]:
            best[j] = best[longs[j]] + 1
            pred[j] = longs[j]
    out = []
    j = n - 1
    while j >= 0:
        out.append(j)
        j = pred[j]
    return out[::-1], chain


@pytest.mark.parametrize("eps", [0.5, 1.0])
def test_dp_is_the_definition_with_its_tie_rule(eps):
    """On paths with few points per kept line (where the DP decides) the kept points are
    exactly the reference DP's, ties included; on the others exactly the greedy chain."""
    rng = np.random.default_rng(4)
    paths = [np.cumsum(rng.normal(0, 0.5, (300, 2)), axis=0)]
    for r in (20, 45):
        t = np.linspace(0, 2 * np.pi, int(6 * r))
        paths.append(np.round(np.c_[r * np.cos(t), 0.6 * r * np.sin(t)]))
    paths.append(_dense_wavy(3, 800))
    kinds = set()
    for p in paths:
        q = p[thin_mod.dedup_indices(p)]
        ref, chain = dp_reference(q, eps)
        got = thin(q, eps).tolist()
        if len(q) < thin_mod._DP_RATIO * len(chain):
            assert got == ref
            kinds.add("dp")
        else:
            assert got == chain
            kinds.add("greedy")
    assert kinds == {"dp", "greedy"}


@pytest.mark.parametrize(
    "p",
    [
        # P1 is 1 ulp farther than eps from P0 (its tangents are ill-conditioned); the float
        # test finds P1 exactly eps from [P0, P2], so the farthest valid end is P2
        [[0.0, 0.0], [-0.4825834180282613, 0.13081760066657866],
         [1.7796976777253253, 6.565267853846727]],
        # P1's computed distance from P0 is eps exactly, and P1 lies behind P0
        [[1.2910892834597443, -0.15166979352694648], [1.0462417882921353, -0.587616698677273],
         [2.3373310717518794, -0.7392864922042195]],
    ],
)
def test_points_eps_from_the_start_to_the_last_bit(p):
    """Found by a review fuzzer: a point whose distance from P_i is eps to rounding must
    neither lose a valid end nor let an invalid one through; the exact test decides."""
    q = np.array(p)
    x = np.ascontiguousarray(q[:, 0])
    y = np.ascontiguousarray(q[:, 1])
    cand = np.empty(4, dtype=np.int64)
    sure = np.empty(4, dtype=np.int8)
    rr = np.empty(4)
    r = thin_mod._reach(x, y, 0, 2, 0.5, thin_mod._SLACK, cand, sure, rr)
    assert r == _valid_ends(q, 0, 2, 0.5)[-1]
    assert thin(q, 0.5).tolist() == ([0, 2] if r == 2 else [0, 1, 2])
