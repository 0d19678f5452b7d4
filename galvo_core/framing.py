"""Framing: trace the job's outline with the red pointer before marking.

The outline is the bounding box of every mark, or their convex hull, in the galvos'
coordinates (after the export orientation). The framing list turns the pointer on (the
light pin of the port word, laser off), jumps to the outline's first corner, then jumps
around it ``loops`` times (light only, never a mark command) at the light speed, and ends
with one end-of-list. This is what galvoplotter's ``lighting()`` mode writes for the same
``light()`` calls (tests/test_framing.py). For ``send`` the loop repeats until stopped.
"""

from __future__ import annotations

import numpy as np

from galvo_core.errors import InputError
from galvo_core.job import Job
from galvo_core.lmc import (
    AS_IS,
    DEFAULT_BOARD,
    Board,
    ListWriter,
    Orientation,
    bits_per_mm,
    oriented_strokes,
)
from galvo_core.params import LaserParams

SHAPES = ("bbox", "hull")


def convex_hull(pts: np.ndarray) -> np.ndarray:
    """Convex hull (K, 2) counter-clockwise of integer points, no repeated or collinear
    vertices (Andrew's monotone chain)."""
    p = np.unique(np.asarray(pts, dtype=np.int64).reshape(-1, 2), axis=0)
    if len(p) < 3:
        return p

    def half(q: np.ndarray) -> list[np.ndarray]:
        out: list[np.ndarray] = []
        for pt in q:
            while len(out) >= 2:
                a, b = out[-2], out[-1]
                if (b[0] - a[0]) * (pt[1] - a[1]) - (b[1] - a[1]) * (pt[0] - a[0]) > 0:
                    break
                out.pop()
            out.append(pt)
        return out

    # only points that can be on the hull: the extreme of each x column (fast for marks)
    lower = half(p)
    upper = half(p[::-1])
    return np.array(lower[:-1] + upper[:-1], dtype=np.int64)


def outline(job: Job, shape: str = "bbox", orientation: Orientation = AS_IS
            ) -> np.ndarray:
    """The framing outline (K, 2) int bits, closed implicitly (the last vertex joins the
    first), in the galvos' coordinates."""
    if shape not in SHAPES:
        raise ValueError(f"frame shape must be one of {', '.join(SHAPES)}, not {shape!r}")
    ms = [m for m in oriented_strokes(job, orientation) if len(m)]
    if not ms:
        raise InputError(job.source_name, "the job has no marks to frame")
    allm = np.concatenate(ms)
    if shape == "bbox":
        (x0, y0), (x1, y1) = allm.min(axis=0), allm.max(axis=0)
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.int64)
    # the hull of each column's lowest and highest mark is the hull of all marks
    order = np.lexsort((allm[:, 1], allm[:, 0]))
    s = allm[order]
    first = np.concatenate([[True], s[1:, 0] != s[:-1, 0]])
    last = np.concatenate([s[1:, 0] != s[:-1, 0], [True]])
    return convex_hull(s[first | last])


def frame_records(path: np.ndarray, loops: int, job: Job, laser: LaserParams | None = None,
                  light_speed_mm_s: float | None = None,
                  board: Board = DEFAULT_BOARD) -> np.ndarray:
    """The framing list: pointer on, a jump to the first vertex, ``loops`` times around the
    outline, end-of-list. ``light_speed_mm_s`` defaults to the jump speed."""
    if loops < 1:
        raise ValueError("loops must be >= 1")
    las = laser or LaserParams()
    w = ListWriter(bits_per_mm(job), "fiber", board)
    w.begin_lighting()
    w.jump_speed(light_speed_mm_s or las.jump_speed_mm_s)
    p = np.asarray(path, dtype=np.int64)
    w.jump(int(p[0, 0]), int(p[0, 1]), las)
    ring = np.vstack([p[1:], p[:1]])
    for _ in range(loops):
        for x, y in ring:
            if (int(x), int(y)) != (w.x, w.y):
                w.jump(int(x), int(y), las)
    return w.end()
