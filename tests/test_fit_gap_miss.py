"""A corner the thinning kept one short step into the curve past a design line's rounded end
(``fit._corners_beside_gaps``, ``_GAP_MISS``): where the line from the design line's far end to
that corner misses the line's end by 0.3 quanta or more, the line's end is the corner. The miss
adds to the rounding of the line's end, which may lie up to q/sqrt(2) the other way."""

from __future__ import annotations

import numpy as np

from tests.test_fit_design_places import _fit_rounded, _local_distance, _scaled

#: Z003 Medium Italic (URW base35) "G" (font units, laid out as in the benches' text), to be
#: set at em 2048: the 150-unit line from (4149, 240) down to (4113, 96) meets the curve of the
#: lower bowl at a 33-degree corner
_Z003_G = [
    ("line", (4222, 240), (4243, 240)),
    ("line", (4243, 240), (4289, 268)),
    ("cubic", (4289, 268), (4250, 271), (4166, 273), (4064, 273)),
    ("line", (4064, 273), (4003, 242)),
    ("line", (4003, 242), (4003, 234)),
    ("cubic", (4003, 234), (4054, 237), (4103, 239), (4149, 240)),
    ("line", (4149, 240), (4113, 96)),
    ("cubic", (4113, 96), (4070, 56), (4011, 29), (3965, 29)),
    ("cubic", (3965, 29), (3891, 29), (3845, 87), (3845, 178)),
    ("cubic", (3845, 178), (3845, 373), (3976, 555), (4117, 555)),
    ("cubic", (4117, 555), (4158, 555), (4193, 538), (4212, 508)),
    ("cubic", (4212, 508), (4225, 488), (4230, 471), (4236, 429)),
    ("line", (4236, 429), (4310, 512)),
    ("cubic", (4310, 512), (4291, 569), (4255, 591), (4178, 591)),
    ("cubic", (4178, 591), (4068, 591), (3970, 546), (3890, 460)),
    ("cubic", (3890, 460), (3809, 373), (3758, 251), (3758, 145)),
    ("cubic", (3758, 145), (3758, 48), (3811, -12), (3897, -12)),
    ("cubic", (3897, -12), (3959, -12), (4011, 3), (4101, 49)),
    ("cubic", (4101, 49), (4086, -11), (4068, -76), (4059, -98)),
    ("cubic", (4059, -98), (4039, -152), (4010, -174), (3957, -174)),
    ("cubic", (3957, -174), (3928, -174), (3880, -170), (3849, -165)),
    ("line", (3849, -165), (3807, -231)),
    ("cubic", (3807, -231), (3843, -235), (3858, -236), (3879, -236)),
    ("cubic", (3879, -236), (3959, -236), (4027, -200), (4093, -124)),
    ("cubic", (4093, -124), (4136, -74), (4154, -32), (4183, 84)),
    ("line", (4183, 84), (4222, 240)),
]


def test_a_corner_kept_a_step_into_the_curve_goes_to_the_lines_end() -> None:
    """Before: the line's rounded end (8423, 197) dropped, the corner kept at (8422, 195) one
    step into the curve; the line to it missed (8423, 197) by 0.46 on the far side from the
    design's corner (8423.42, 196.61): 0.99 from the design where the rounded input is 0.56.
    After: the corner at the line's end, the fit within 0.05 of the rounded input there, and
    the segment count unchanged."""
    segs = _scaled(_Z003_G, 2.048)
    corner = np.array([4113 * 2.048, 96 * 2.048])
    w, fp = _fit_rounded(segs)
    k = int(np.argmin(np.hypot(*(w - corner).T)))
    rounded = float(np.hypot(*(w[k] - corner)))
    assert _local_distance(segs, fp, corner, 2.0) <= rounded + 0.05
    assert fp.n_segments <= 27
