"""The turn between two directions, in one place (numpy only, no other import).

The time estimate counts corners, the sampler protects them, the hatch marks keep them: all
by the same rule, the unsigned angle between consecutive direction vectors in degrees.
"""

from __future__ import annotations

import numpy as np

#: a turn above this many degrees is a corner: the scanner slows there (polygon delay),
#: and the marks keep the vertex
CORNER_DEG = 15.0


def turn_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Unsigned angle (degrees, 0..180) from direction ``a`` to ``b``, row by row ((K, 2)
    each). ``atan2(|a × b|, a · b)``: exact near 0 and 180 where ``acos`` of the cosine is not;
    0 where either vector is zero."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    cross = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    dot = a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]
    return np.degrees(np.abs(np.arctan2(cross, dot)))


def consecutive_turns_deg(d: np.ndarray) -> np.ndarray:
    """The turn (degrees) between each pair of consecutive vectors of ``d`` (K, 2): K - 1
    values."""
    d = np.asarray(d, dtype=np.float64)
    if len(d) < 2:
        return np.zeros(0)
    return turn_deg(d[:-1], d[1:])
