"""Marking points: from fitted lines and cubics to integer galvo bits (paper 000 §4).

:func:`sample_path` turns one :class:`~galvo_core.fit.FittedPath` into the marks of one
stroke. ``adaptive`` cuts each cubic into chords whose chord height stays within
``chord_tol_bits`` (measured on the unrounded marks; rounding to integers adds at most
√2/2 bit); lines are sent as their end points (split at ``max_step_bits`` when given).
``raw`` sends the original input points. Consecutive marks closer than ``min_step_bits`` are
merged, except the last mark of a stroke and marks at corners (segment joints).
"""

from __future__ import annotations

import numpy as np

from galvo_core.field import FieldMap
from galvo_core.fit import FittedPath
from galvo_core.geometry import flatten_cubic


def _split_line(a: np.ndarray, b: np.ndarray, max_step: float | None) -> np.ndarray:
    if max_step is None:
        return b[None, :]
    length = float(np.hypot(*(b - a)))
    n = max(1, int(np.ceil(length / max_step)))
    t = (np.arange(1, n + 1) / n)[:, None]
    return a + t * (b - a)


def sample_path(
    fp: FittedPath,
    fm: FieldMap,
    *,
    interpolation: str = "adaptive",
    chord_tol_bits: float = 1.0,
    min_step_bits: float = 2.0,
    max_step_bits: float | None = None,
    raw_points: np.ndarray | None = None,
) -> np.ndarray:
    """Marks of one stroke, (M, 2) int64 galvo bits, in the direction of the segments."""
    if interpolation == "raw":
        pts = raw_points if raw_points is not None else np.empty((0, 2))
        return _dedup(fm.to_bits(pts))
    if not fp.segments:
        return np.empty((0, 2), dtype=np.int64)
    chunks: list[np.ndarray] = []
    joints: list[int] = []
    first = fm.to_bits_float(fp.segments[0].points[:1])
    chunks.append(first)
    count = 1
    for seg in fp.segments:
        ctrl = fm.to_bits_float(seg.points)
        if seg.kind == "cubic":
            pts = flatten_cubic(ctrl, chord_tol_bits)[1:]
            if max_step_bits is not None and len(pts):
                prev = np.vstack((ctrl[:1], pts[:-1]))
                steps = np.hypot(*(pts - prev).T)
                if steps.max() > max_step_bits:
                    n = int(np.ceil(len(pts) * steps.max() / max_step_bits))
                    pts = flatten_cubic(ctrl, chord_tol_bits / max(1.0, (n / len(pts)) ** 2))[1:]
        else:
            pts = _split_line(ctrl[0], ctrl[1], max_step_bits)
        chunks.append(pts)
        count += len(pts)
        joints.append(count - 1)
    allpts = np.concatenate(chunks)
    keep = np.ones(len(allpts), dtype=bool)
    if min_step_bits > 0 and len(allpts) > 2:
        is_joint = np.zeros(len(allpts), dtype=bool)
        is_joint[joints] = True
        is_joint[0] = True
        last = allpts[0]
        for i in range(1, len(allpts) - 1):
            if not is_joint[i] and np.hypot(*(allpts[i] - last)) < min_step_bits:
                keep[i] = False
            else:
                last = allpts[i]
    marks = allpts[keep]
    r = np.where(marks >= 0, np.floor(marks + 0.5), np.ceil(marks - 0.5)).astype(np.int64)
    return _dedup(r)


def _dedup(marks: np.ndarray) -> np.ndarray:
    """Drop consecutive repeats of the same integer mark (a dot keeps one mark)."""
    if len(marks) < 2:
        return marks
    keep = np.ones(len(marks), dtype=bool)
    keep[1:] = (marks[1:] != marks[:-1]).any(axis=1)
    return marks[keep]
