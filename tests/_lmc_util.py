"""Small jobs for the LMC, framing and CLI export tests."""

from __future__ import annotations

import numpy as np

from galvo_core.field import FieldMap
from galvo_core.job import Job, Stroke
from galvo_core.params import LaserParams


def make_job(strokes: list[tuple[int, list[tuple[int, int]]]], *, size_mm: float = 110.0,
             bits: int = 65536, laser: LaserParams | None = None) -> Job:
    fm = FieldMap(1.0, (0.0, 0.0), bits, size_mm)
    ss = tuple(Stroke("contour", i, False, np.array(m, dtype=np.int64), (), pen)
               for i, (pen, m) in enumerate(strokes))
    return Job("t.plt", "0" * 64, fm, {}, (laser or LaserParams()).as_dict(), ss)


def rng_strokes(seed: int, n: int, pens: tuple[int, ...]) -> list[tuple[int, list]]:
    """Random open strokes whose first mark never sits where the last one ended (so that
    galvoplotter's goto(), which skips a jump to the current position, jumps every time)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        k = int(rng.integers(2, 40))
        start = rng.integers(1000, 64000, size=2)
        steps = rng.integers(-900, 900, size=(k - 1, 2))
        m = np.clip(np.vstack([start, start + np.cumsum(steps, axis=0)]), 0, 65535)
        out.append((pens[i % len(pens)], [tuple(int(v) for v in p) for p in m]))
    return out
