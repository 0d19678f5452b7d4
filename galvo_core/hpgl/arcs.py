"""Arcs, circles and Béziers flattened the way an HP-GL plotter draws them.

Chord rule (HP-GL reference, AA/AR/CI/AT/RT): an arc of sweep ``s`` degrees with chord
angle ``c`` is drawn as ``ceil(|s| / c)`` equal chords; the chord angle defaults to 5
degrees and is clamped to [0.5, 180]. In chord-tolerance mode (``CT1``) the argument is the
largest distance between chord and arc instead, and the chord angle is ``2·acos(1 − d/r)``.
All angles are degrees, counter-clockwise from +x; all lengths in the caller's units.
"""

from __future__ import annotations

import math

import numpy as np

DEFAULT_CHORD_DEG = 5.0
MIN_CHORD_DEG = 0.5
MAX_CHORD_DEG = 180.0


def chord_angle(arg: float | None, radius: float, *, tolerance_mode: bool) -> float:
    """The chord angle in degrees for an arc argument ``arg`` (None = default)."""
    if arg is None or not math.isfinite(arg):
        return DEFAULT_CHORD_DEG
    if tolerance_mode:
        r = abs(radius)
        d = abs(arg)
        if r <= 0 or d <= 0:
            return DEFAULT_CHORD_DEG
        if d >= r:
            return MAX_CHORD_DEG
        ang = math.degrees(2.0 * math.acos(1.0 - d / r))
    else:
        ang = abs(arg)
        if ang == 0:
            return DEFAULT_CHORD_DEG
    return min(max(ang, MIN_CHORD_DEG), MAX_CHORD_DEG)


def arc_points(
    cx: float, cy: float, radius: float, start_deg: float, sweep_deg: float, chord_deg: float
) -> np.ndarray:
    """Points of an arc, first point at ``start_deg``, (n+1, 2) with n = ceil(|sweep|/chord)."""
    n = max(1, math.ceil(abs(sweep_deg) / chord_deg - 1e-9))
    ang = np.radians(start_deg + sweep_deg * np.arange(n + 1) / n)
    pts = np.empty((n + 1, 2))
    pts[:, 0] = cx + radius * np.cos(ang)
    pts[:, 1] = cy + radius * np.sin(ang)
    return pts


def circle_through(
    p0: tuple[float, float], p1: tuple[float, float], p2: tuple[float, float]
) -> tuple[float, float, float, float, float] | None:
    """Centre, radius, start angle and sweep of the arc from p0 through p1 to p2.

    Returns (cx, cy, r, start_deg, sweep_deg), or None when the points are collinear
    (or coincide), in which case a plotter draws straight lines.
    """
    (ax, ay), (bx, by), (ex, ey) = p0, p1, p2
    d = 2.0 * (ax * (by - ey) + bx * (ey - ay) + ex * (ay - by))
    scale = max(abs(ax - ex), abs(ay - ey), abs(bx - ax), abs(by - ay), 1e-300)
    if abs(d) <= 1e-12 * scale * scale:
        return None
    a2, b2, e2 = ax * ax + ay * ay, bx * bx + by * by, ex * ex + ey * ey
    cx = (a2 * (by - ey) + b2 * (ey - ay) + e2 * (ay - by)) / d
    cy = (a2 * (ex - bx) + b2 * (ax - ex) + e2 * (bx - ax)) / d
    r = math.hypot(ax - cx, ay - cy)
    t0 = math.degrees(math.atan2(ay - cy, ax - cx))
    t1 = math.degrees(math.atan2(by - cy, bx - cx))
    t2 = math.degrees(math.atan2(ey - cy, ex - cx))
    ccw = d > 0  # orientation of p0 -> p1 -> p2
    if ccw:
        sweep = (t2 - t0) % 360.0
        # p1 lies on the ccw way from p0 to p2 by construction of the orientation
    else:
        sweep = -((t0 - t2) % 360.0)
    if sweep == 0.0 and (ax, ay) == (ex, ey):
        sweep = 360.0 if ccw else -360.0
    del t1
    return cx, cy, r, t0, sweep


def bezier_points(ctrl: np.ndarray, tol: float) -> np.ndarray:
    """A cubic Bézier flattened to a polyline within ``tol`` of the curve; includes both ends.

    Uses the standard bound on the second differences of the control polygon
    (n = ceil(sqrt(3/4 · max‖Δ²P‖ / tol))) with n >= 1.
    """
    p = np.asarray(ctrl, dtype=np.float64)
    d2 = max(
        float(np.hypot(*(p[0] - 2 * p[1] + p[2]))), float(np.hypot(*(p[1] - 2 * p[2] + p[3])))
    )
    n = max(1, min(4096, math.ceil(math.sqrt(0.75 * d2 / max(tol, 1e-12)))))
    t = np.linspace(0.0, 1.0, n + 1)[:, None]
    mt = 1.0 - t
    return (
        mt**3 * p[0] + 3 * mt * mt * t * p[1] + 3 * mt * t * t * p[2] + t**3 * p[3]
    )
