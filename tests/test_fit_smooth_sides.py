"""A smooth vertex of rounded input moves onto a least-squares estimate of the design only
where that estimate has input points on both sides of it (``fit._SMOOTH_SIDES``): with one
point on a side the quadratic extrapolates, and at a notch of a few units (a serif's
zigzag the rounding makes look smooth) it pulled the vertex off the design by the whole
rounding."""

from __future__ import annotations

import numpy as np

from tests.test_fit_design_places import _fit_rounded, _local_distance, _scaled

#: NimbusRoman-Italic (URW base35) "i"'s stem (its design in font units, laid out as in the
#: benches' text), to be set at em 2048: a 37-unit line, then a 2-unit and a 2-unit line (a
#: notch turning 11, 27 and 15 degrees), then the 334-unit line up the stem
_NIMBUS_ITALIC_I = [
    ("cubic", (20276, 114), (20251, 81), (20245, 73), (20235, 63)),
    ("cubic", (20235, 63), (20218, 46), (20203, 36), (20194, 36)),
    ("cubic", (20194, 36), (20186, 36), (20178, 43), (20178, 51)),
    ("cubic", (20178, 51), (20178, 61), (20181, 77), (20188, 95)),
    ("line", (20188, 95), (20193, 113)),
    ("line", (20193, 113), (20194, 115)),
    ("line", (20194, 115), (20194, 117)),
    ("line", (20194, 117), (20282, 439)),
    ("line", (20282, 439), (20279, 441)),
    ("cubic", (20279, 441), (20177, 422), (20158, 419), (20119, 416)),
    ("line", (20119, 416), (20119, 400)),
    ("cubic", (20119, 400), (20173, 399), (20182, 396), (20182, 376)),
    ("cubic", (20182, 376), (20182, 368), (20179, 351), (20173, 332)),
    ("line", (20173, 332), (20125, 155)),
    ("cubic", (20125, 155), (20109, 95), (20103, 66), (20103, 46)),
    ("cubic", (20103, 46), (20103, 9), (20119, -11), (20149, -11)),
    ("cubic", (20149, -11), (20196, -11), (20232, 19), (20289, 103)),
    ("line", (20289, 103), (20276, 114)),
]


def test_a_vertex_with_one_input_point_beyond_it_is_not_pulled_off_the_notch() -> None:
    """The thinned vertex at the notch's middle corner (input point (41357, 236)) was judged
    smooth and moved half a unit across the stem onto a quadratic through the curve's points
    before it and the one point after it: 0.94 from the design there, where the rounded
    input is 0.47. Left on its input point, the fit is within 0.6 of the design there."""
    segs = _scaled(_NIMBUS_ITALIC_I, 2.048)
    _, fp = _fit_rounded(segs)
    notch = np.array([20194.0, 115.0]) * 2.048
    assert _local_distance(segs, fp, notch, 4.0) <= 0.6
    assert len(fp.segments) <= 1.2 * len(segs)
