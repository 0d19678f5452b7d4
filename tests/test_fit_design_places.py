"""Issue 16 (s6-d): places of real typeface outlines where the fit on whole-unit input was
farther from the true design curve than the rounded input itself. Each outline here is the
design (a glyph contour as read from the font by bench/fonts.py, in units of an em) rounded
the way the precision bench rounds it: flattened to 0.002 unit chords, rounded to whole
units, repeats dropped."""

from __future__ import annotations

import math

import numpy as np

from galvo_core.fit import check_fit, fit_paths
from galvo_core.geometry import flatten_cubic, point_polyline_distance


def _dense(segs, chord: float) -> np.ndarray:
    """The design's points: lines as their ends, cubics at uniform parameter steps with
    chord height <= ``chord`` (as bench/fonts.py flattens them)."""
    parts = []
    for kind, *p in segs:
        p = np.array(p, dtype=np.float64)
        if kind == "line":
            parts.append(p)
            continue
        acc = 6.0 * max(float(np.hypot(*(p[0] - 2.0 * p[1] + p[2]))),
                        float(np.hypot(*(p[1] - 2.0 * p[2] + p[3]))))
        n = max(1, math.ceil(math.sqrt(acc / (8.0 * chord)))) if acc > 0 else 1
        t = np.linspace(0.0, 1.0, n + 1)[:, None]
        s = 1.0 - t
        parts.append(s ** 3 * p[0] + 3 * s * s * t * p[1] + 3 * s * t * t * p[2] + t ** 3 * p[3])
    return np.vstack([parts[0]] + [q[1:] for q in parts[1:]])


def _rounded(segs) -> np.ndarray:
    w = np.round(_dense(segs, 0.002))
    return w[np.r_[True, (w[1:] != w[:-1]).any(axis=1)]]


def _local_distance(segs, fp, place, r: float) -> float:
    """Both-ways distance of the fit and the design within ``r`` of ``place``."""
    truth = _dense(segs, 0.001)
    fit = np.vstack([flatten_cubic(s.points, 0.002) if s.kind == "cubic"
                     else np.asarray(s.points) for s in fp.segments])
    out = 0.0
    for a, b in ((truth, fit), (fit, truth)):
        near = a[np.hypot(*(a - place).T) <= r]
        if len(near):
            out = max(out, float(point_polyline_distance(near, b).max()))
    return out


#: Inconsolata "?" at em 1500 (the hook and its stem): the stem's right side, a design line at
#: x = 3437.54 from y = 277 to 339, continues tangentially into a cubic that bends right only
#: slowly, so its rounded points stay on x = 3438 up to y = 371 and the thinning keeps one line
#: from y = 277 to there
_INCONSOLATA_Q = [
    ("line", (3095.79345703125, 841.42529296875), (3172.1689453125, 770.22802734375)),
    ("cubic", (3172.1689453125, 770.22802734375), (3219.4716796875, 849.3369140625),
     (3299.0888671875, 899.87548828125), (3374.93115234375, 899.87548828125)),
    ("cubic", (3374.93115234375, 899.87548828125), (3464.65869140625, 899.87548828125),
     (3532.78564453125, 830.009765625), (3532.78564453125, 741.3720703125)),
    ("cubic", (3532.78564453125, 741.3720703125), (3532.78564453125, 643.1015625),
     (3454.97900390625, 581.8359375), (3409.6435546875, 532.05615234375)),
    ("cubic", (3409.6435546875, 532.05615234375), (3343.37841796875, 459.2958984375),
     (3339.15966796875, 406.4912109375), (3339.15966796875, 339.15966796875)),
    ("line", (3339.15966796875, 339.15966796875), (3339.15966796875, 277.0224609375)),
    ("line", (3339.15966796875, 277.0224609375), (3437.54150390625, 277.0224609375)),
    ("line", (3437.54150390625, 277.0224609375), (3437.54150390625, 339.15966796875)),
    ("cubic", (3437.54150390625, 339.15966796875), (3437.54150390625, 392.02001953125),
     (3441.0263671875, 436.59375), (3502.7900390625, 491.490234375)),
    ("cubic", (3502.7900390625, 491.490234375), (3552.29443359375, 535.4912109375),
     (3651.44384765625, 592.564453125), (3651.44384765625, 733.51318359375)),
    ("cubic", (3651.44384765625, 733.51318359375), (3651.44384765625, 873.31201171875),
     (3554.95166015625, 998.13720703125), (3384.9873046875, 998.13720703125)),
    ("cubic", (3384.9873046875, 998.13720703125), (3272.6689453125, 998.13720703125),
     (3161.068359375, 941.9970703125), (3095.79345703125, 841.42529296875)),
]


def test_shallow_corner_at_the_end_of_a_line_stays_on_the_line():
    """Where a thinned line (its points' least-squares line) meets a curve at a shallow turn,
    the corner moves along that line only: the mean of the line's and the curve's estimates
    tilted the whole 94-unit line by the curve's 0.3 unit at its end, 0.66 from the design
    at the design's tangent joint (the rounded input is 0.46 away there)."""
    w = _rounded(_INCONSOLATA_Q)
    fp = fit_paths([w], [True])[0]
    assert not check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    assert _local_distance(_INCONSOLATA_Q, fp, np.array([3437.54, 342.0]), 6.0) < 0.5


#: DejaVu Sans "3" at em 400 (its outer contour, quadratics written as cubics): the lower
#: bowl ends tangentially in a horizontal design line at y = 139.648 from x = 3682.2 to
#: 3648.2, written as its two rounded ends (y = 140) after a few rounded points of the curve
_SANS_3_QUADS = [
    ('quad', (3729.6875, 157.2265625), (3758.0078125, 151.171875), (3773.92578125, 132.03125)),
    ('quad', (3773.92578125, 132.03125), (3789.84375, 112.890625), (3789.84375, 84.765625)),
    ('quad', (3789.84375, 84.765625), (3789.84375, 41.6015625), (3760.15625, 17.96875)),
    ('quad', (3760.15625, 17.96875), (3730.46875, -5.6640625), (3675.78125, -5.6640625)),
    ('quad', (3675.78125, -5.6640625), (3657.421875, -5.6640625), (3637.98828125, -2.05078125)),
    ('quad', (3637.98828125, -2.05078125), (3618.5546875, 1.5625), (3597.8515625, 8.7890625)),
    ('line', (3597.8515625, 8.7890625), (3597.8515625, 46.875)),
    ('quad', (3597.8515625, 46.875), (3614.2578125, 37.3046875), (3633.7890625, 32.421875)),
    ('quad', (3633.7890625, 32.421875), (3653.3203125, 27.5390625), (3674.609375, 27.5390625)),
    ('quad', (3674.609375, 27.5390625), (3711.71875, 27.5390625), (3731.15234375, 42.1875)),
    ('quad', (3731.15234375, 42.1875), (3750.5859375, 56.8359375), (3750.5859375, 84.765625)),
    ('quad', (3750.5859375, 84.765625), (3750.5859375, 110.546875), (3732.51953125, 125.09765625)),
    ('quad', (3732.51953125, 125.09765625), (3714.453125, 139.6484375),
     (3682.2265625, 139.6484375)),
    ('line', (3682.2265625, 139.6484375), (3648.2421875, 139.6484375)),
    ('line', (3648.2421875, 139.6484375), (3648.2421875, 172.0703125)),
    ('line', (3648.2421875, 172.0703125), (3683.7890625, 172.0703125)),
    ('quad', (3683.7890625, 172.0703125), (3712.890625, 172.0703125), (3728.3203125, 183.69140625)),
    ('quad', (3728.3203125, 183.69140625), (3743.75, 195.3125), (3743.75, 217.1875)),
    ('quad', (3743.75, 217.1875), (3743.75, 239.6484375), (3727.83203125, 251.66015625)),
    ('quad', (3727.83203125, 251.66015625), (3711.9140625, 263.671875), (3682.2265625, 263.671875)),
    ('quad', (3682.2265625, 263.671875), (3666.015625, 263.671875), (3647.4609375, 260.15625)),
    ('quad', (3647.4609375, 260.15625), (3628.90625, 256.640625), (3606.640625, 249.21875)),
    ('line', (3606.640625, 249.21875), (3606.640625, 284.375)),
    ('quad', (3606.640625, 284.375), (3629.1015625, 290.625), (3648.73046875, 293.75)),
    ('quad', (3648.73046875, 293.75), (3668.359375, 296.875), (3685.7421875, 296.875)),
    ('quad', (3685.7421875, 296.875), (3730.6640625, 296.875), (3756.8359375, 276.46484375)),
    ('quad', (3756.8359375, 276.46484375), (3783.0078125, 256.0546875),
     (3783.0078125, 221.2890625)),
    ('quad', (3783.0078125, 221.2890625), (3783.0078125, 197.0703125), (3769.140625, 180.37109375)),
    ('quad', (3769.140625, 180.37109375), (3755.2734375, 163.671875), (3729.6875, 157.2265625)),
]


def _as_cubics(segs):
    """TrueType quadratics written as the cubics they are."""
    out = []
    for kind, *p in segs:
        if kind == "quad":
            p0, c, p1 = (np.array(x) for x in p)
            out.append(("cubic", p0, p0 + 2.0 / 3.0 * (c - p0), p1 + 2.0 / 3.0 * (c - p1), p1))
        else:
            out.append((kind, *p))
    return out


_SANS_3 = _as_cubics(_SANS_3_QUADS)


def test_a_cubic_does_not_swallow_a_design_line_written_as_two_points():
    """The curve run through the bowl took the line's two rounded ends along: one cubic, within
    its bound of the chord between them, bulged 0.36 above it, 0.71 from the design line where
    the rounded input is 0.35 from it. The cubic bulging over such a gap at its end is fitted
    without that segment, which becomes a line: no farther from the design than the input."""
    w = _rounded(_SANS_3)
    fp = fit_paths([w], [True])[0]
    assert not check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    fit = np.vstack([flatten_cubic(s.points, 0.002) if s.kind == "cubic"
                     else np.linspace(*np.asarray(s.points), 200) for s in fp.segments])
    a, b = np.array([3682.2265625, 139.6484375]), np.array([3648.2421875, 139.6484375])
    line = a + np.linspace(0.0, 1.0, 101)[:, None] * (b - a)
    rounded = point_polyline_distance(line, np.vstack([w, w[:1]])).max()
    assert point_polyline_distance(line, fit).max() <= rounded + 0.05
    over = fit[(fit[:, 0] > b[0]) & (fit[:, 0] < a[0]) & (np.abs(fit[:, 1] - a[1]) < 3)]
    assert np.abs(over[:, 1] - a[1]).max() <= rounded + 0.05
