"""Corners the rounding cut in two (``fit._tips_joined``, ``_TIP_SHORT_MANY``), on whole-unit
input.

* A corner between two curves whose own rounded point the thinning dropped, keeping the input
  points one step before and after it: a line of 3-4 units over two input steps is left
  across the corner. It is taken out and the curves beside it meet where their end tangents
  cross (inside the rounding square of the corner's input point), both still within the
  bound; a cubic whose end then moves over a unit keeps its handle, or has its handle
  lengths re-fitted, where moving the handle along would carry its side off its points."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod
from tests.test_fit_design_places import _fit_rounded, _local_distance, _scaled

#: P052 Bold Italic (URW base35) "7" (font units, laid out as in the benches' text), to be set
#: at em 2048: at (35008, -3) the foot's curve turns 107 degrees up into the diagonal stroke
_P052_BOLDITALIC_7 = [
    ("cubic", (34893, -3), (34925, -1), (34944, 0), (34950, 0)),
    ("cubic", (34950, 0), (34961, 0), (34974, -1), (35008, -3)),
    ("cubic", (35008, -3), (35073, 156), (35200, 394), (35303, 548)),
    ("line", (35303, 548), (35361, 629)),
    ("line", (35361, 629), (35361, 668)),
    ("line", (35361, 668), (35101, 668)),
    ("cubic", (35101, 668), (35065, 668), (35031, 669), (34917, 674)),
    ("line", (34917, 674), (34911, 665)),
    ("cubic", (34911, 665), (34904, 619), (34898, 593), (34890, 556)),
    ("line", (34890, 556), (34898, 550)),
    ("cubic", (34898, 550), (34936, 555), (34963, 557), (34987, 557)),
    ("line", (34987, 557), (35256, 557)),
    ("line", (35256, 557), (35177, 448)),
    ("cubic", (35177, 448), (35129, 381), (34991, 173), (34886, 10)),
    ("line", (34886, 10), (34893, -3)),
]

def _joints(fp) -> np.ndarray:
    return np.array([s.points[0] for s in fp.segments], dtype=np.float64)


def test_a_corner_cut_in_two_by_the_thinning_is_one_corner_again(monkeypatch) -> None:
    """Before: corners at (71695, -6) and (71698, -3) with a 3.6-unit line between them over
    two input steps, 0.81 from the design's corner (71696.38, -6.14) where the rounded input
    (its point (71696, -6)) is 0.40. After: one joint within 0.3 of the corner, no line there,
    and fewer segments."""
    segs = _scaled(_P052_BOLDITALIC_7, 2.048)
    corner = np.array([35008 * 2.048, -3 * 2.048])
    w, fp = _fit_rounded(segs)
    near = np.hypot(*(_joints(fp) - corner).T)
    assert (near <= 0.3).sum() == 1 and (near <= 5.0).sum() == 1
    assert _local_distance(segs, fp, corner, 2.0) <= 0.3
    # (one segment fewer than without the rule: 19 against 20 until the twentieth session,
    # whose corner rules give the diagonal stroke two more, 21 against 22)
    monkeypatch.setattr(fitmod, "_TIP_SHORT_MANY", 0.0)
    assert fp.n_segments < _fit_rounded(segs)[1].n_segments
