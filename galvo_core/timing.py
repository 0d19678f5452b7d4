"""A delay-aware estimate of marking time, and the dwell check.

Model (the usual galvo controller timing, as in SCANLAB RTC / EZCAD-style boards, which
output one position every point period — 10 µs at the XY2-100 rate):

* every mark vector (consecutive marks of a stroke) takes its length over the mark speed,
  rounded **up** to whole point periods, and at least one period: the controller steps a
  vector in whole periods, so a stroke of many tiny steps costs what it really costs (a
  1-bit step at 100 mm/s would take 17 ns; it takes 10 µs);
* a dot (a stroke of one mark) fires for one point period;
* every jump (laser off, from the last mark of a stroke to the first of the next) takes its
  length over the jump speed, likewise in whole periods, plus a jump delay (short, or long
  past ``long_jump_mm``);
* every stroke costs the laser-on delay at its start, and the mark-end delay plus the
  laser-off delay at its end (one laser switch per stroke);
* every corner inside a stroke (direction change above :data:`CORNER_DEG` between
  consecutive mark vectors) costs the polygon delay.

No jump is counted before the first stroke (the scanner is assumed to wait at the first mark)
nor after the last. Lengths are on the workpiece (mm), times in seconds. The estimate does
not model acceleration (sky-writing, the galvo's own lag); the delays stand in for it.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass
from operator import attrgetter
from typing import Any

import numpy as np

from galvo_core.params import LaserParams
from galvo_core.turns import CORNER_DEG, consecutive_turns_deg


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
    return int((consecutive_turns_deg(d) > corner_deg).sum())


def _periods(length_mm: np.ndarray, speed_mm_s: float, period_s: float) -> np.ndarray:
    """Whole point periods a vector takes (at least one)."""
    n = np.ceil(length_mm / (speed_mm_s * period_s) - 1e-9)
    return np.maximum(n, 1.0)


def estimate(
    strokes: Sequence[np.ndarray], laser: LaserParams, mm_per_bit: float
) -> dict[str, float | int]:
    """Time and lengths for strokes of marks (each (M, 2) int bits) in marking order.

    Returns mark_length_mm, jump_length_mm, estimated_time_s, corners, laser_switches
    (= strokes with marks), jumps, mark_points, and the parts of the time (mark_time_s,
    jump_time_s, delay_time_s).
    """
    return estimate_with_dwell(strokes, laser, mm_per_bit)[0]


@dataclass(frozen=True, eq=False)
class JoinedMarks:
    """Every mark of a job's strokes in marking order as one array, with the stroke table
    beside it: made once per job (:func:`joined_marks`) and shared by the time estimate,
    the stats and the display geometry, so none of them loops over 10^4-10^5 strokes."""

    #: (M, 2) int64 galvo bits, every stroke's marks in order
    marks: np.ndarray
    #: (S,) int64 each stroke's mark count (0 for an empty stroke)
    lens: np.ndarray
    #: (S,) int64 each stroke's ``source_index``
    source: np.ndarray
    #: (S,) bool: the stroke is a hatch stroke
    hatch: np.ndarray


_EMPTY_MARKS = np.empty((0, 2), dtype=np.int64)
_JOINED: OrderedDict[int, tuple[object, JoinedMarks]] = OrderedDict()
_JOINED_LOCK = threading.Lock()


def joined_marks(strokes: Sequence[Any]) -> JoinedMarks:
    """The :class:`JoinedMarks` of ``strokes`` (job strokes: ``marks``, ``source_index``,
    ``kind``). The last few tuples are remembered by identity (the entry holds the tuple,
    so its id cannot be reused meanwhile; other sequences are joined each time): a job's
    strokes are joined once, whoever asks first (the stats, the preview, the simulation)."""
    key = id(strokes)
    keep = isinstance(strokes, tuple)  # only an immutable sequence is remembered
    with _JOINED_LOCK:
        hit = _JOINED.get(key) if keep else None
        if hit is not None and hit[0] is strokes:
            _JOINED.move_to_end(key)
            return hit[1]
    n = len(strokes)
    lens = np.fromiter(map(len, map(attrgetter("marks"), strokes)), dtype=np.int64, count=n)
    if lens.sum():
        try:  # (M, 2) arrays, as the pipeline makes them
            allm = np.concatenate([s.marks for s in strokes])
        except ValueError:
            allm = np.concatenate([np.asarray(s.marks).reshape(-1, 2) for s in strokes])
        allm = np.asarray(allm, dtype=np.int64).reshape(-1, 2)
    else:
        allm = _EMPTY_MARKS
    src = np.fromiter(map(attrgetter("source_index"), strokes), dtype=np.int64, count=n)
    kinds = set(map(attrgetter("kind"), strokes))
    if "hatch" in kinds:
        hatch = np.fromiter((s.kind == "hatch" for s in strokes), dtype=bool, count=n)
    else:
        hatch = np.zeros(n, dtype=bool)
    out = JoinedMarks(allm, lens, src, hatch)
    if not keep:
        return out
    with _JOINED_LOCK:
        _JOINED[key] = (strokes, out)
        while len(_JOINED) > 4:
            _JOINED.popitem(last=False)
    return out


def estimate_with_dwell(
    strokes: Sequence[np.ndarray] | JoinedMarks, laser: LaserParams, mm_per_bit: float
) -> tuple[dict[str, float | int], int]:
    """:func:`estimate` and :func:`dwell_count` in one pass over all strokes at once (one
    concatenated array; stroke boundaries by offsets, no loop per stroke). ``strokes``: the
    strokes' marks, or a job's :class:`JoinedMarks` (already concatenated)."""
    us = 1e-6
    period = laser.point_period_us * us
    if isinstance(strokes, JoinedMarks):
        sizes = strokes.lens[strokes.lens > 0]
        n_strokes = len(sizes)
        allm = strokes.marks.astype(np.float64) if n_strokes else None
    else:
        ms = [m for m in strokes if len(m)]
        n_strokes = len(ms)
        if n_strokes:
            try:  # (M, 2) arrays: no Python work per stroke
                allm = np.concatenate(ms).astype(np.float64).reshape(-1, 2)
            except ValueError:
                allm = np.concatenate([np.asarray(m).reshape(-1, 2)
                                       for m in ms]).astype(np.float64)
            sizes = np.fromiter(map(len, ms), dtype=np.int64, count=n_strokes)
    if not n_strokes or allm is None:
        return {"mark_length_mm": 0.0, "jump_length_mm": 0.0, "estimated_time_s": 0.0,
                "corners": 0, "laser_switches": 0, "jumps": 0, "mark_points": 0,
                "mark_time_s": 0.0, "jump_time_s": 0.0, "delay_time_s": 0.0}, 0
    starts = np.cumsum(sizes) - sizes
    ends = starts + sizes - 1
    dx = allm[1:, 0] - allm[:-1, 0]
    dy = allm[1:, 1] - allm[:-1, 1]
    # vectors inside a stroke: all but those from a stroke's last mark to the next's first
    inside = np.ones(len(dx), dtype=bool)
    inside[ends[:-1]] = False
    vx, vy = dx[inside], dy[inside]
    seg_mm = np.hypot(vx, vy) * mm_per_bit
    mark_len = float(seg_mm.sum())
    mark_t = float(_periods(seg_mm, laser.mark_speed_mm_s, period).sum()) * period
    mark_t += int((sizes == 1).sum()) * period  # dots
    dwell = int(np.count_nonzero(
        seg_mm < laser.mark_speed_mm_s * laser.point_period_us * 1e-6))
    # corners: turns between consecutive non-zero vectors of the same stroke
    vsid = np.repeat(np.arange(n_strokes), np.maximum(sizes - 1, 0))
    nz = (vx != 0) | (vy != 0)
    vx, vy, vsid = vx[nz], vy[nz], vsid[nz]
    n_corners = 0
    if len(vx) >= 2:
        v = np.stack([vx, vy], axis=1)
        turn = consecutive_turns_deg(v)
        n_corners = int(np.count_nonzero((turn > CORNER_DEG) & (vsid[1:] == vsid[:-1])))
    # jumps
    jv = allm[starts[1:]] - allm[ends[:-1]]
    jump_mm = np.hypot(jv[:, 0], jv[:, 1]) * mm_per_bit
    jump_len = float(jump_mm.sum())
    jump_t = float(_periods(jump_mm, laser.jump_speed_mm_s, period).sum()) * period
    jdel = np.where(jump_mm > laser.long_jump_mm, laser.jump_delay_long_us,
                    laser.jump_delay_us).sum() * us
    delays = (n_strokes * (laser.laser_on_delay_us + laser.mark_delay_us
                           + laser.laser_off_delay_us) * us
              + n_corners * laser.polygon_delay_us * us + float(jdel))
    return {
        "mark_length_mm": mark_len,
        "jump_length_mm": jump_len,
        "estimated_time_s": mark_t + jump_t + delays,
        "corners": n_corners,
        "laser_switches": n_strokes,
        "jumps": n_strokes - 1,
        "mark_points": int(sizes.sum()),
        "mark_time_s": mark_t,
        "jump_time_s": jump_t,
        "delay_time_s": delays,
    }, dwell


def dwell_count(strokes: Sequence[np.ndarray], laser: LaserParams, mm_per_bit: float) -> int:
    """Consecutive marks closer than mark speed × point period: the beam stands still there
    (the controller cannot move less than one step per period, so it dwells)."""
    return estimate_with_dwell(strokes, laser, mm_per_bit)[1]


def estimate_layers(
    layers: Sequence[tuple[Sequence[np.ndarray], LaserParams, int]], mm_per_bit: float
) -> tuple[dict[str, float | int], list[dict[str, float | int]]]:
    """The time of a job marked layer by layer (issue 19): ``layers`` in marking order, each
    (its strokes' marks in job order, its laser settings, its passes). A layer's strokes are
    marked ``passes`` times in a row with that layer's speeds and delays (:func:`estimate`
    of the repeated sequence, so the jumps between passes count); the jump from the end of
    one layer to the start of the next counts in the next layer, at its jump speed and delay.

    Returns the totals (the keys of :func:`estimate`) and one dict per layer with the same
    keys plus ``passes``.
    """
    per: list[dict[str, float | int]] = []
    last: np.ndarray | None = None
    for strokes, laser, passes in layers:
        ms = [np.asarray(m).reshape(-1, 2) for m in strokes if len(m)]
        t = estimate(ms * passes, laser, mm_per_bit)
        if ms and last is not None:
            # the jump into this layer: its own speed and delay
            d = float(np.hypot(*(ms[0][0] - last).astype(np.float64))) * mm_per_bit
            period = laser.point_period_us * 1e-6
            jt = float(_periods(np.array([d]), laser.jump_speed_mm_s, period)[0]) * period
            jd = (laser.jump_delay_long_us if d > laser.long_jump_mm
                  else laser.jump_delay_us) * 1e-6
            t["jump_length_mm"] = float(t["jump_length_mm"]) + d
            t["jump_time_s"] = float(t["jump_time_s"]) + jt
            t["delay_time_s"] = float(t["delay_time_s"]) + jd
            t["estimated_time_s"] = float(t["estimated_time_s"]) + jt + jd
            t["jumps"] = int(t["jumps"]) + 1
        if ms:
            last = ms[-1][-1]
        t["passes"] = int(passes)
        per.append(t)
    keys = ("mark_length_mm", "jump_length_mm", "estimated_time_s", "corners",
            "laser_switches", "jumps", "mark_points", "mark_time_s", "jump_time_s",
            "delay_time_s")
    total: dict[str, float | int] = {k: sum(p[k] for p in per) for k in keys}
    return total, per
