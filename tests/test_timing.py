"""The time estimate (issue 5): lengths over speeds in whole point periods, delays per stroke,
per corner and per jump; the dwell check."""

from __future__ import annotations

import math

import numpy as np
import pytest

from galvo_core.params import LaserParams
from galvo_core.timing import corners, dwell_count, estimate

MMB = 110.0 / 65536  # mm per bit
L = LaserParams()  # mark 100 mm/s, jump 2000 mm/s, on/off 100/100, polygon 100, end 300 µs
PER_STROKE = (100 + 300 + 100) * 1e-6


def test_one_vector_costs_its_length_over_the_speed_in_whole_periods_plus_stroke_delays():
    m = np.array([[0, 0], [10000, 0]])
    t = estimate([m], L, MMB)
    mm = 10000 * MMB
    periods = math.ceil(mm / (100 * 10e-6))
    assert t["mark_length_mm"] == pytest.approx(mm)
    assert t["estimated_time_s"] == pytest.approx(periods * 10e-6 + PER_STROKE)
    assert t["laser_switches"] == 1 and t["jumps"] == 0 and t["mark_points"] == 2


def test_tiny_steps_cost_at_least_one_point_period_each():
    m = np.column_stack([np.arange(101), np.zeros(101)])  # 100 steps of one bit (1.68 µm)
    fast = LaserParams(mark_speed_mm_s=1000)  # 10 µm per period
    t = estimate([m], fast, MMB)
    assert t["mark_time_s"] == pytest.approx(100 * 10e-6)  # not 100 × 1.7 µs
    assert t["estimated_time_s"] == pytest.approx(100 * 10e-6 + PER_STROKE)
    # at 100 mm/s a 1-bit step takes 1.68 periods: two whole periods
    assert estimate([m], L, MMB)["mark_time_s"] == pytest.approx(100 * 20e-6)


def test_jumps_corners_and_dots():
    square = np.array([[0, 0], [1000, 0], [1000, 1000], [0, 1000], [0, 0]])
    far = square + 20000  # 20000·√2 bits ≈ 47 mm away: a long jump
    near = square + 1000  # 1000·√2 bits ≈ 2.4 mm: a short jump
    dot = np.array([[5, 5]])
    t = estimate([square, far, near, dot], L, MMB)
    assert corners(square) == 3 and t["corners"] == 9
    assert t["laser_switches"] == 4 and t["jumps"] == 3
    j1 = math.hypot(20000, 20000) * MMB
    j2 = math.hypot(19000, 19000) * MMB
    j3 = math.hypot(995, 995) * MMB
    assert t["jump_length_mm"] == pytest.approx(j1 + j2 + j3)
    jump_t = sum(math.ceil(j / (2000 * 10e-6)) * 10e-6 for j in (j1, j2, j3))
    assert t["jump_time_s"] == pytest.approx(jump_t)
    side = math.ceil(1000 * MMB / (100 * 10e-6)) * 10e-6
    assert t["mark_time_s"] == pytest.approx(3 * 4 * side + 10e-6)  # the dot fires 10 µs
    delays = 4 * PER_STROKE + 9 * 100e-6 + (200 + 200 + 8) * 1e-6
    assert t["delay_time_s"] == pytest.approx(delays)
    assert t["estimated_time_s"] == pytest.approx(t["mark_time_s"] + jump_t + delays)


def test_slower_marking_and_longer_delays_take_longer():
    m = [np.array([[0, 0], [30000, 0], [30000, 30000]]), np.array([[0, 5000], [9000, 0]])]
    base = estimate(m, L, MMB)["estimated_time_s"]
    assert estimate(m, LaserParams(mark_speed_mm_s=50), MMB)["estimated_time_s"] > base
    assert estimate(m, LaserParams(polygon_delay_us=500), MMB)["estimated_time_s"] > base
    assert estimate(m, LaserParams(jump_delay_long_us=900), MMB)["estimated_time_s"] > base
    assert estimate([], L, MMB)["estimated_time_s"] == 0.0


def test_dwell_counts_marks_closer_than_speed_times_period():
    # at 500 mm/s one period moves 5 µm ≈ 3 bits: 1-bit steps dwell, 4-bit steps do not
    fast = LaserParams(mark_speed_mm_s=500)
    m = np.array([[0, 0], [1, 0], [2, 0], [6, 0], [10, 0]])
    assert dwell_count([m], fast, MMB) == 2
    assert dwell_count([m], L, MMB) == 0  # 100 mm/s: 1 µm < one bit


def test_all_strokes_at_once_equal_the_per_stroke_definitions():
    """estimate/dwell_count work on one concatenated array; check them against the rules
    applied stroke by stroke."""
    from galvo_core.timing import estimate_with_dwell, stroke_lengths_mm

    rng = np.random.default_rng(5)
    limit = L.mark_speed_mm_s * L.point_period_us * 1e-6
    for _ in range(200):
        strokes = []
        for _ in range(int(rng.integers(0, 7))):
            m = rng.integers(0, 60, (int(rng.integers(0, 7)), 2))
            if len(m) > 2 and rng.random() < 0.4:
                m[1] = m[0]  # a repeated mark: a zero vector, a dwell
            strokes.append(m)
        t, dwell = estimate_with_dwell(strokes, L, MMB)
        assert t == estimate(strokes, L, MMB)
        assert dwell == dwell_count(strokes, L, MMB)
        assert dwell == sum(int((stroke_lengths_mm(m, MMB) < limit).sum())
                            for m in strokes if len(m) >= 2)
        assert t["corners"] == sum(corners(m) for m in strokes if len(m))
        assert t["mark_points"] == sum(len(m) for m in strokes)
        marked = [m for m in strokes if len(m)]
        assert t["mark_length_mm"] == pytest.approx(
            sum(stroke_lengths_mm(m, MMB).sum() for m in marked))
        assert t["laser_switches"] == len(marked)
