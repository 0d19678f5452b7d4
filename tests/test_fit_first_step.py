"""A corner's side that the thinning made one line over a design line written as its two
rounded ends and the points of the stretch after it (``fit._FIRST_STEP``): the corner's
estimate takes that side's direction from the design line's step alone. The least-squares
line through all of the side's points leans to the stretch after the design line (20
points against its 2) and moved an acute tip 0.26 into the letter."""

from __future__ import annotations

import numpy as np

from tests.test_fit_design_places import _fit_rounded, _local_distance, _scaled

#: NimbusRoman-Italic (URW base35) "x" (its design in font units, laid out as in the benches'
#: text), to be set at em 2048: at (26927, 176) the right stroke's curve meets a 124-unit
#: design line at a 129-degree tip; after the line, a curve's dense points in the same
#: thinned segment
_NIMBUS_ITALIC_X = [
    ("cubic", (27123, 111), (27115, 102), (27110, 96), (27101, 84)),
    ("cubic", (27101, 84), (27078, 54), (27066, 44), (27054, 44)),
    ("cubic", (27054, 44), (27040, 44), (27031, 57), (27024, 85)),
    ("cubic", (27024, 85), (27021, 96), (27021, 98), (27020, 101)),
    ("cubic", (27020, 101), (26995, 203), (26984, 249), (26984, 264)),
    ("cubic", (26984, 264), (27029, 342), (27064, 385), (27082, 385)),
    ("cubic", (27082, 385), (27088, 385), (27097, 382), (27106, 377)),
    ("cubic", (27106, 377), (27118, 370), (27125, 368), (27134, 368)),
    ("cubic", (27134, 368), (27154, 368), (27168, 383), (27168, 404)),
    ("cubic", (27168, 404), (27168, 426), (27151, 441), (27127, 441)),
    ("cubic", (27127, 441), (27083, 441), (27046, 405), (26976, 298)),
    ("line", (26976, 298), (26965, 353)),
    ("cubic", (26965, 353), (26951, 421), (26940, 441), (26913, 441)),
    ("cubic", (26913, 441), (26890, 441), (26858, 433), (26796, 412)),
    ("cubic", (26796, 412), (26790, 410), (26790, 410), (26785, 408)),
    ("line", (26785, 408), (26789, 393)),
    ("cubic", (26789, 393), (26828, 403), (26835, 404), (26845, 404)),
    ("cubic", (26845, 404), (26870, 404), (26876, 395), (26890, 335)),
    ("line", (26890, 335), (26919, 212)),
    ("line", (26919, 212), (26837, 95)),
    ("cubic", (26837, 95), (26816, 65), (26797, 47), (26786, 47)),
    ("cubic", (26786, 47), (26780, 47), (26770, 50), (26760, 56)),
    ("cubic", (26760, 56), (26747, 63), (26737, 66), (26728, 66)),
    ("cubic", (26728, 66), (26708, 66), (26694, 51), (26694, 31)),
    ("cubic", (26694, 31), (26694, 5), (26713, -11), (26744, -11)),
    ("cubic", (26744, -11), (26775, -11), (26787, -2), (26837, 58)),
    ("cubic", (26837, 58), (26864, 91), (26886, 121), (26927, 176)),
    ("line", (26927, 176), (26957, 56)),
    ("cubic", (26957, 56), (26970, 4), (26983, -11), (27015, -11)),
    ("cubic", (27015, -11), (27053, -11), (27079, 13), (27137, 103)),
    ("line", (27137, 103), (27123, 111)),
]


def test_a_corner_side_takes_its_direction_from_the_design_line_step() -> None:
    """Before: the tip's joint at (55145.88, 359.76), 0.92 from the design's tip (55146.5,
    360.45), where the rounded input point (55146, 360) is 0.67 from it. After: the joint
    stays within 0.75 of the tip (no farther than the rounding's own 0.71 and a little)."""
    segs = _scaled(_NIMBUS_ITALIC_X, 2.048)
    _, fp = _fit_rounded(segs)
    tip = np.array([26927.0, 176.0]) * 2.048
    assert _local_distance(segs, fp, tip, 3.0) <= 0.75
    assert len(fp.segments) <= 1.2 * len(segs)
