"""A delay-aware estimate of marking time, and the dwell check.

Model (the usual galvo controller timing, as in SCANLAB RTC / EZCAD-style boards):

* every jump (laser off) costs its length over the jump speed plus a jump delay (short, or
  long past ``long_jump_mm``);
* every stroke costs the laser-on delay at its start, and the mark-end delay plus the
  laser-off delay at its end;
* every mark vector costs its length over the mark speed, but never less than one point
  period (10 µs at the XY2-100 rate): a stroke of many tiny steps costs what it really costs;
* every corner inside a stroke (direction change above :data:`CORNER_DEG`) costs the
  polygon delay.

Lengths are on the workpiece (mm), times in seconds.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from galvo_core.params import LaserParams

CORNER_DEG = 15.0


def stroke_lengths_mm(marks: np.ndarray, mm_per_bit: float) -> np.ndarray:
    if len(marks) < 2:
        return np.zeros(0)
    d = np.diff(marks.astype(np.float64), axis=0)
    return np.hypot(d[:, 0], d[:, 1]) * mm_per_bit


def corners(marks: np.ndarray, corner_deg: float = CORNER_DEG) -> int:
    """Interior vertices where the direction turns by more than ``corner_deg``."""
    if len(marks) < 3:
        return 0
    d = np.diff(marks.astype(np.float64), axis=0)
    d = d[(d != 0).any(axis=1)]
    if len(d) < 2:
        return 0
    a, b = d[:-1], d[1:]
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    dot = (a * b).sum(axis=1)
    ang = np.degrees(np.abs(np.arctan2(cross, dot)))
    return int((ang > corner_deg).sum())


def estimate(
    strokes: Sequence[np.ndarray], laser: LaserParams, mm_per_bit: float
) -> dict[str, float | int]:
    """Time and lengths for strokes of marks (each (M, 2) int bits) in marking order.

    The first jump starts at the field centre's position of the previous job's end: here the
    first stroke's first mark (no jump is counted before it).
    """
    us = 1e-6
    mark_len = 0.0
    jump_len = 0.0
    t = 0.0
    n_corners = 0
    n_marks = 0
    n_strokes = 0
    prev_end: np.ndarray | None = None
    for m in strokes:
        if len(m) == 0:
            continue
        n_strokes += 1
        n_marks += len(m)
        if prev_end is not None:
            j = float(np.hypot(*(m[0] - prev_end).astype(np.float64))) * mm_per_bit
            jump_len += j
            t += j / laser.jump_speed_mm_s
            t += (laser.jump_delay_long_us if j > laser.long_jump_mm else laser.jump_delay_us) * us
        seg = stroke_lengths_mm(m, mm_per_bit)
        mark_len += float(seg.sum())
        t += float(np.maximum(seg / laser.mark_speed_mm_s, laser.point_period_us * us).sum())
        if len(m) == 1:  # a dot: the laser fires for one point period
            t += laser.point_period_us * us
        c = corners(m)
        n_corners += c
        t += c * laser.polygon_delay_us * us
        t += (laser.laser_on_delay_us + laser.mark_delay_us + laser.laser_off_delay_us) * us
        prev_end = m[-1]
    return {
        "mark_length_mm": mark_len,
        "jump_length_mm": jump_len,
        "estimated_time_s": t,
        "corners": n_corners,
        "laser_switches": n_strokes,
        "mark_points": n_marks,
    }


def dwell_count(strokes: Sequence[np.ndarray], laser: LaserParams, mm_per_bit: float) -> int:
    """Consecutive marks closer than mark speed × point period: the beam stands still there."""
    limit_mm = laser.mark_speed_mm_s * laser.point_period_us * 1e-6
    n = 0
    for m in strokes:
        if len(m) >= 2:
            n += int((stroke_lengths_mm(m, mm_per_bit) < limit_mm).sum())
    return n
