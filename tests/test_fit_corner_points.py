"""Issue 16 (s10-co): corners the thinning kept on an input point beside the design's corner.
The corner's rounding square then cannot reach the design's corner, and the fit passes far
from it. The design's corner's own input point is kept as a thinned point instead (or too),
with every thinned segment still a line within the thinning's tolerance. Each outline here is
a glyph contour (or a piece of one) as read from the font by bench/fonts.py, in units of an
em, flattened and rounded the way the precision bench does it (0.002 unit chords, whole
units, repeats dropped)."""

from __future__ import annotations

import os
import sys

import numpy as np

from galvo_core.fit import (
    _corners_kept_right,
    _line_errors,
    check_fit,
    fit_paths,
)
from galvo_core.geometry import point_polyline_distance
from galvo_core.thin import thin
from tests.test_fit_design_places import _local_distance

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "bench"))
import fonts  # noqa: E402


def _segs(raw):
    return [(kind, *(np.array(p, dtype=np.float64) for p in pts)) for kind, *pts in raw]


def _dense(segs, chord: float) -> np.ndarray:
    parts = [fonts.flatten_segment(s, chord) for s in segs]
    return np.vstack([parts[0]] + [p[1:] for p in parts[1:]])


def _rounded(segs, closed: bool) -> np.ndarray:
    w = np.round(_dense(segs, 0.002))
    w = w[np.r_[True, (w[1:] != w[:-1]).any(axis=1)]]
    if closed and (w[0] != w[-1]).any():
        w = np.vstack([w, w[:1]])
    return w


def _distances(segs, fp, w, place, r: float = 2.0) -> tuple[float, float]:
    """Both-ways distance of the fit and the design within ``r`` of ``place``, and the design's
    distance there to the rounded input polyline ``w``."""
    truth = _dense(segs, 0.001)
    near = truth[np.hypot(*(truth - place).T) <= r]
    return (_local_distance(segs, fp, place, r, truth),
            float(point_polyline_distance(near, w).max()))


def _check(raw, closed: bool, place) -> tuple[float, float]:
    segs = _segs(raw)
    w = _rounded(segs, closed)
    fp = fit_paths([w], [closed])[0]
    assert not check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    return _distances(segs, fp, w, np.array(place, dtype=np.float64))


#: Cantarell Light "9" at em 2048 (the bowl, closed): a 30-degree corner between two cubics at
#: (958.46, 917.50), whose rounded point is (958, 918); the thinning kept (958, 921), one
#: 3-unit step before it
_CANTARELL_LIGHT_9 = [
    ("cubic", (217.088, 1001.472), (217.088, 1220.608), (356.352, 1368.064), (563.2, 1368.064)),
    ("cubic", (563.2, 1368.064), (782.336, 1368.064), (921.6, 1206.272), (958.464, 917.504)),
    ("cubic", (958.464, 917.504), (882.688, 735.232), (747.52, 638.976), (569.344, 638.976)),
    ("cubic", (569.344, 638.976), (362.496, 638.976), (217.088, 776.192), (217.088, 1001.472)),
]


def test_a_corner_kept_one_step_early_moves_to_the_design_corner_point():
    """The corner's square could not reach the design's corner: 1.124 from the design where
    the rounded input is 0.597. The sides fitted without the points next to the thinned one
    cross in the square of the next input point, which is kept instead."""
    fit, rounded = _check(_CANTARELL_LIGHT_9, True, (958.464, 917.504))
    assert fit <= 0.6
    assert fit <= rounded


#: Cantarell "8" at em 2048 (the upper bowl, closed): a 37-degree corner between two cubics at
#: (11569.15, 798.72); the thinning kept (11571, 799), one step after the corner's point
_CANTARELL_8 = [
    ("cubic", (11282.432, 1085.44), (11282.432, 1214.464), (11380.736, 1298.432),
     (11538.432, 1298.432)),
    ("cubic", (11538.432, 1298.432), (11706.368, 1298.432), (11827.2, 1206.272),
     (11827.2, 1071.104)),
    ("cubic", (11827.2, 1071.104), (11827.2, 946.176), (11722.752, 837.632),
     (11569.152, 798.72)),
    ("cubic", (11569.152, 798.72), (11413.504, 864.256), (11282.432, 935.936),
     (11282.432, 1085.44)),
]


def test_a_corner_kept_one_step_late_moves_to_the_design_corner_point():
    """0.771 from the design where the rounded input is 0.28 (the bench's CFF row's worst)."""
    fit, _ = _check(_CANTARELL_8, True, (11569.152, 798.72))
    assert fit <= 0.3


#: DejaVu Sans "Q" at em 400 (the outer contour, closed): the tail's 63-unit design line,
#: written as its two rounded ends, ends at (947.46, -4.88) in a 51-degree corner with a
#: quadratic; the thinning kept the line to (946, -5), one step into the curve
_SANS_Q = [
    ("line", (986.328125, 5.2734375), (1038.28125, -51.5625)),
    ("line", (1038.28125, -51.5625), (990.625, -51.5625)),
    ("line", (990.625, -51.5625), (947.4609375, -4.8828125)),
    ("quad", (947.4609375, -4.8828125), (941.015625, -5.2734375), (937.59765625, -5.46875)),
    ("quad", (937.59765625, -5.46875), (934.1796875, -5.6640625), (931.0546875, -5.6640625)),
    ("quad", (931.0546875, -5.6640625), (869.53125, -5.6640625), (832.71484375, 35.44921875)),
    ("quad", (832.71484375, 35.44921875), (795.8984375, 76.5625), (795.8984375, 145.5078125)),
    ("quad", (795.8984375, 145.5078125), (795.8984375, 214.6484375),
     (832.71484375, 255.76171875)),
    ("quad", (832.71484375, 255.76171875), (869.53125, 296.875), (931.0546875, 296.875)),
    ("quad", (931.0546875, 296.875), (992.3828125, 296.875), (1029.1015625, 255.76171875)),
    ("quad", (1029.1015625, 255.76171875), (1065.8203125, 214.6484375),
     (1065.8203125, 145.5078125)),
    ("quad", (1065.8203125, 145.5078125), (1065.8203125, 94.7265625),
     (1045.41015625, 58.59375)),
    ("quad", (1045.41015625, 58.59375), (1025.0, 22.4609375), (986.328125, 5.2734375)),
]


def test_a_corner_kept_past_a_two_point_line_moves_to_the_line_end():
    """0.780 from the design where the rounded input is 0.417: the line's rounded end is the
    corner's point."""
    fit, rounded = _check(_SANS_Q, True, (947.4609375, -4.8828125))
    assert fit <= max(0.6, rounded + 0.02)


#: DejaVu Serif Italic "a" at em 400 (a piece of the bowl's right side, open): a 96-unit
#: design line written as its two rounded ends meets a quadratic at (175.39, 187.70); the
#: thinning kept the line to (175, 190), two steps into the curve
_SERIF_ITALIC_A = [
    ("quad", (91.796875, 16.796875), (116.40625, 16.796875), (133.10546875, 36.42578125)),
    ("quad", (133.10546875, 36.42578125), (149.8046875, 56.0546875), (157.2265625, 93.5546875)),
    ("line", (157.2265625, 93.5546875), (175.390625, 187.6953125)),
    ("quad", (175.390625, 187.6953125), (175.390625, 193.359375), (159.765625, 193.359375)),
]


def test_a_corner_kept_two_steps_past_a_two_point_line_moves_to_the_line_end():
    """0.809 from the design where the rounded input is 0.441."""
    fit, rounded = _check(_SERIF_ITALIC_A, False, (175.390625, 187.6953125))
    assert fit <= max(0.6, rounded + 0.02)



#: FreeSerif Italic "n" at em 2048, placed as in the precision bench's unseen-font text (the
#: outer contour, closed): a 7.4-unit design line, written as its two rounded ends, 7.2 units
#: apart, meets a cubic at (45025.28, 903.17), whose rounded point is (45025, 903); the
#: thinning kept the line to (45024, 903), one step into the curve
_FREESERIF_ITALIC_N = [
    ('cubic', (45537.28, 239.616), (45488.128, 180.224), (45406.208, 77.824), (45369.344, 77.824)),
    ('cubic', (45369.344, 77.824), (45352.96, 77.824), (45336.576, 94.208), (45336.576, 110.592)),
    ('cubic', (45336.576, 110.592), (45336.576, 124.928), (45336.576, 124.928),
     (45365.248, 239.616)),
    ('line', (45365.248, 239.616), (45481.984, 661.504)),
    ('cubic', (45481.984, 661.504), (45494.272, 704.512), (45500.416, 749.568),
     (45500.416, 778.24)),
    ('cubic', (45500.416, 778.24), (45500.416, 851.968), (45445.12, 903.168), (45365.248, 903.168)),
    ('cubic', (45365.248, 903.168), (45234.176, 903.168), (45105.152, 780.288),
     (44894.208, 452.608)),
    ('line', (44894.208, 452.608), (45031.424, 899.072)),
    ('line', (45031.424, 899.072), (45025.28, 903.168)),
    ('cubic', (45025.28, 903.168), (44914.688, 880.64), (44871.68, 872.448), (44693.504, 839.68)),
    ('line', (44693.504, 839.68), (44693.504, 806.912)),
    ('cubic', (44693.504, 806.912), (44797.952, 804.864), (44824.576, 792.576),
     (44824.576, 751.616)),
    ('cubic', (44824.576, 751.616), (44824.576, 739.328), (44822.528, 727.04), (44820.48, 716.8)),
    ('line', (44820.48, 716.8), (44623.872, 0.0)),
    ('line', (44623.872, 0.0), (44777.472, 0.0)),
    ('cubic', (44777.472, 0.0), (44873.728, 323.584), (44892.16, 368.64), (44982.272, 507.904)),
    ('cubic', (44982.272, 507.904), (45105.152, 696.32), (45209.6, 798.72), (45285.376, 798.72)),
    ('cubic', (45285.376, 798.72), (45316.096, 798.72), (45334.528, 776.192), (45334.528, 739.328)),
    ('cubic', (45334.528, 739.328), (45334.528, 714.752), (45322.24, 647.168), (45305.856, 583.68)),
    ('line', (45305.856, 583.68), (45215.744, 245.76)),
    ('cubic', (45215.744, 245.76), (45187.072, 141.312), (45182.976, 112.64), (45182.976, 92.16)),
    ('cubic', (45182.976, 92.16), (45182.976, 14.336), (45211.648, -18.432), (45279.232, -18.432)),
    ('cubic', (45279.232, -18.432), (45371.392, -18.432), (45424.64, 24.576), (45565.952, 212.992)),
    ('line', (45565.952, 212.992), (45537.28, 239.616)),
]


def test_a_corner_kept_past_a_short_two_point_line_moves_to_the_line_end():
    """0.738 from the design where the rounded input is 0.295: the line is under 8 quanta long
    (``fit._LONE_LENGTH``), but at 7 times the curve's steps beside it it is a design line
    all the same (``fit._BESIDE_LENGTH``), and its rounded end is the corner's point."""
    fit, rounded = _check(_FREESERIF_ITALIC_N, True, (45025.28, 903.168))
    assert fit <= max(0.6, rounded + 0.02)

def test_kept_corner_points_keep_every_thinned_segment_a_line_within_the_tolerance():
    """The corner's point replaces the thinned point where the segment across it stays a line
    within the tolerance; else that segment is split near its middle; else the old point is
    kept too; else nothing changes. Every thinned segment after is a line within the
    tolerance (the thinning's promise, which the fitter's fallbacks rely on): tried at every
    thinned point of the "9" with every input point up to three steps around it."""
    w = _rounded(_segs(_CANTARELL_LIGHT_9), True)
    e = 0.5 + 0.5 * np.sqrt(2.0)
    K = thin(w, e, closed=True).astype(np.intp)
    branches = set()
    for v in range(1, len(K) - 1):
        for j in range(int(K[v]) - 3, int(K[v]) + 4):
            if j == K[v] or not K[v - 1] < j < K[v + 1]:
                continue
            K2, tlen, changed = _corners_kept_right(w, K, np.array([len(K)]), np.array([v]),
                                                    np.array([j]), np.array([True]),
                                                    np.full(len(K), e))
            assert tlen[0] == len(K2)
            if not changed:
                assert np.array_equal(K2, K)
                branches.add("none")
                continue
            assert j in K2 and (np.diff(K2) > 0).all()
            assert K2[0] == 0 and K2[-1] == len(w) - 1
            branches.add(("replaced" if K[v] not in K2 else "kept", len(K2) - len(K)))
            err = _line_errors(w, np.stack([w[K2[:-1]], w[K2[1:]]], axis=1), K2[:-1], K2[1:])
            assert (err <= e).all()
    assert {("replaced", 0), ("replaced", 1), ("kept", 1), "none"} <= branches
