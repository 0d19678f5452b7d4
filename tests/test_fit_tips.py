"""An acute tip the thinning cut (``fit._tips_joined``): the tip's own rounded point lies
within the bound of the chord between its neighbours, so the thinning drops it and keeps a
corner one input step before the tip and one after, with a short line between them across
the tip. That line is taken out and the two segments beside it meet where their end tangents
cross (inside the tip point's rounding square), where both still keep the bound."""

from __future__ import annotations

import numpy as np

from tests.test_fit_design_places import _fit_rounded, _local_distance, _scaled

#: NimbusRoman-Italic (URW base35) "%"'s upper ring (its design in font units, laid out as in
#: the benches' text), to be set at em 2048: at (34315, 593) the ring's outer curve comes up
#: almost vertically and turns back 129 degrees into the bar's curve
_NIMBUS_ITALIC_PERCENT = [
    ("line", (34571, 676), (34531, 676)),
    ("cubic", (34531, 676), (34481, 626), (34438, 608), (34370, 608)),
    ("cubic", (34370, 608), (34337, 608), (34314, 614), (34301, 625)),
    ("line", (34301, 625), (34283, 641)),
    ("cubic", (34283, 641), (34269, 654), (34242, 662), (34215, 662)),
    ("cubic", (34215, 662), (34105, 662), (33997, 542), (33997, 419)),
    ("cubic", (33997, 419), (33997, 346), (34049, 289), (34116, 289)),
    ("cubic", (34116, 289), (34168, 289), (34215, 315), (34253, 363)),
    ("cubic", (34253, 363), (34292, 413), (34321, 488), (34321, 540)),
    ("cubic", (34321, 540), (34321, 552), (34319, 568), (34315, 587)),
    ("cubic", (34315, 587), (34315, 590), (34315, 590), (34314, 593)),
    ("cubic", (34314, 593), (34335, 585), (34348, 583), (34375, 583)),
    ("cubic", (34375, 583), (34422, 583), (34445, 589), (34488, 613)),
    ("line", (34488, 613), (34138, -13)),
    ("line", (34138, -13), (34185, -13)),
    ("line", (34185, -13), (34571, 676)),
]


def test_a_tip_cut_by_a_short_line_is_joined_at_its_sides_crossing() -> None:
    """Before: corners at (70275, 1213) and (70276, 1214) and a 0.8-unit line between them,
    0.84 from the design's tip (70275.07, 1214.46), whose own rounded point (70275, 1214) the
    thinning dropped. After: one joint 0.1 from the tip, one segment fewer."""
    segs = _scaled(_NIMBUS_ITALIC_PERCENT, 2.048)
    _, fp = _fit_rounded(segs)
    tip = np.array([34314.0, 593.0]) * 2.048
    ends = np.array([s.points[-1] for s in fp.segments])
    assert np.hypot(*(ends - tip).T).min() <= 0.3
    assert _local_distance(segs, fp, tip, 3.0) <= 0.6
    assert len(fp.segments) <= len(segs)
