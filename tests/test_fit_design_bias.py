"""Issue 16 (s10-bias): places of real typeface outlines where the fit on whole-unit input was
farther from the true design curve than the rounded input: a smooth vertex's tangent from a
window of two or three input points, a corner estimate given up whole where part of its move
keeps the lines' bound. The outlines are built as in test_fit_design_places.py (the design
flattened to 0.002 unit chords, rounded to whole units, repeats dropped)."""

from __future__ import annotations

import numpy as np
from test_fit_design_places import _as_cubics, _dense, _local_distance, _rounded

from galvo_core import fit as fitmod
from galvo_core.fit import check_fit, fit_paths
from galvo_core.geometry import point_polyline_distance


def _rounded_distance(segs, w, place, r: float = 2.0) -> float:
    """The rounded polyline's distance to the design within ``r`` of ``place`` (design side)."""
    t = _dense(segs, 0.001)
    return float(point_polyline_distance(t[np.hypot(*(t - place).T) <= r], w).max())


#: DejaVu Sans Mono Oblique "0" at em 1000 (its outer contour, closed): a chain of
#: quadratics flattened into steps of 2-3 units near the lattice slope 2:1, thinned into
#: segments of 13, 4 and 200 input points
_MONO_OBLIQUE_0 = _as_cubics([
    ("quad", (31553.7109375, 65.91796875), (31592.7734375, 65.91796875),
     (31626.220703125, 91.064453125)),
    ("quad", (31626.220703125, 91.064453125), (31659.66796875, 116.2109375),
     (31682.6171875, 163.0859375)),
    ("quad", (31682.6171875, 163.0859375), (31716.30859375, 231.4453125),
     (31739.013671875, 332.275390625)),
    ("quad", (31739.013671875, 332.275390625), (31761.71875, 433.10546875),
     (31761.71875, 519.04296875)),
    ("quad", (31761.71875, 519.04296875), (31761.71875, 594.23828125),
     (31737.79296875, 628.173828125)),
    ("quad", (31737.79296875, 628.173828125), (31713.8671875, 662.109375),
     (31661.62109375, 662.109375)),
    ("quad", (31661.62109375, 662.109375), (31622.55859375, 662.109375),
     (31588.8671875, 637.20703125)),
    ("quad", (31588.8671875, 637.20703125), (31555.17578125, 612.3046875),
     (31531.73828125, 565.91796875)),
    ("quad", (31531.73828125, 565.91796875), (31497.55859375, 498.046875),
     (31475.09765625, 396.240234375)),
    ("quad", (31475.09765625, 396.240234375), (31452.63671875, 294.43359375),
     (31452.63671875, 202.1484375)),
    ("quad", (31452.63671875, 202.1484375), (31452.63671875, 133.30078125),
     (31477.783203125, 99.609375)),
    ("quad", (31477.783203125, 99.609375), (31502.9296875, 65.91796875),
     (31553.7109375, 65.91796875)),
])


def test_a_smooth_vertex_beside_a_short_window_takes_more_points():
    """The smooth vertex between a thinned segment of 13 input points and one of 4 had its
    design estimate from the 9 points between the two segments' middles (2 after it): its
    tangent 5.5 degrees off the design's, and the cubic ending there 0.76 from the design
    where the rounded input is 0.27-0.5. At least _SMOOTH_HALF points on each side."""
    w = _rounded(_MONO_OBLIQUE_0)
    fp = fit_paths([w], [True])[0]
    assert not check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    for place in ([31689.2, 175.2], [31687.1, 170.7], [31690.4, 179.7]):
        p = np.array(place)
        assert _local_distance(_MONO_OBLIQUE_0, fp, p, 2.0) <= max(
            0.6, _rounded_distance(_MONO_OBLIQUE_0, w, p) + 0.02)


#: DejaVu Serif Italic "a" at em 400 (the bowl, closed): a 96-unit design line meets at
#: (175.39, 187.70) the quadratic of the bowl's top at a 90-degree corner; the thinning kept the
#: corner on the input point (175, 190), 2.3 units past the design's
_SERIF_ITALIC_A = _as_cubics([
    ("quad", (51.3671875, 58.59375), (51.3671875, 16.796875), (91.796875, 16.796875)),
    ("quad", (91.796875, 16.796875), (116.40625, 16.796875), (133.10546875, 36.42578125)),
    ("quad", (133.10546875, 36.42578125), (149.8046875, 56.0546875),
     (157.2265625, 93.5546875)),
    ("line", (157.2265625, 93.5546875), (175.390625, 187.6953125)),
    ("line", (175.390625, 187.6953125), (175.390625, 187.6953125)),
    ("quad", (175.390625, 187.6953125), (175.390625, 193.359375),
     (159.765625, 193.359375)),
    ("quad", (159.765625, 193.359375), (122.265625, 193.359375), (93.1640625, 164.0625)),
    ("quad", (93.1640625, 164.0625), (64.2578125, 134.5703125), (53.90625, 81.0546875)),
    ("quad", (53.90625, 81.0546875), (51.3671875, 68.5546875), (51.3671875, 58.59375)),
])


def test_a_corner_keeps_the_part_of_its_move_that_keeps_the_lines(monkeypatch):
    """The corner's estimate, 0.21 across the design line from its input point, made the
    thinned line before it miss its input points by more than the bound, so the whole move
    was given up (0.81 from the design where the rounded input is 0.44). Half of it keeps the
    line within the bound: the corner moves that far (0.70). (With the corner put on the
    input point nearer the design's, ``fit._corners_kept_right``, the fit there is nearer
    still; the partial move is checked with the corner left where the thinning kept it.)"""
    w = _rounded(_SERIF_ITALIC_A)
    fp = fit_paths([w], [True])[0]
    assert not check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    assert _local_distance(_SERIF_ITALIC_A, fp, np.array([175.4, 187.7]), 2.0) <= 0.75
    monkeypatch.setattr(fitmod, "_corners_kept_right",
                        lambda W, K, tlen, *rest: (K, tlen, np.zeros(len(tlen), dtype=bool)))
    fp = fit_paths([w], [True])[0]
    assert not check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    ends = np.array([s.points[-1] for s in fp.segments])
    k = int(np.argmin(np.hypot(*(ends - [175.0, 190.0]).T)))
    assert 0.05 <= float(np.hypot(*(ends[k] - [175.0, 190.0]))) <= 0.5
    assert _local_distance(_SERIF_ITALIC_A, fp, np.array([175.4, 187.7]), 2.0) <= 0.75
