"""The smooth-stretch repair does not move a corner joint of the fit onto its design estimate
(``fit._no_estimates_at_corners``): the estimate of a point is a least-squares quadratic over
a window of its neighbours, and where that window spans a corner the quadratic rounds the
corner off; the repair then moved the corner's joint onto it, off the design's corner."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod
from tests.test_fit_design_places import _fit_rounded, _local_distance, _scaled

#: FreeMono Bold "$" (font units, laid out as in the benches' text), to be set at em 2048: at
#: (38818, 574) the upper curve of the S meets the curve into its middle stroke at 32 degrees
_FREEMONO_BOLD_DOLLAR = [
    ("cubic", (38702, 684), (38661, 684), (38652, 656), (38652, 618)),
    ("line", (38652, 618), (38652, 592)),
    ("cubic", (38652, 592), (38566, 577), (38507, 513), (38507, 435)),
    ("cubic", (38507, 435), (38507, 354), (38560, 300), (38659, 280)),
    ("line", (38659, 280), (38733, 265)),
    ("cubic", (38733, 265), (38789, 254), (38813, 235), (38813, 200)),
    ("cubic", (38813, 200), (38813, 157), (38765, 124), (38700, 124)),
    ("cubic", (38700, 124), (38645, 124), (38592, 149), (38584, 180)),
    ("cubic", (38584, 180), (38581, 191), (38576, 229), (38533, 229)),
    ("cubic", (38533, 229), (38491, 229), (38483, 198), (38483, 162)),
    ("line", (38483, 162), (38483, 101)),
    ("cubic", (38483, 101), (38483, 66), (38491, 34), (38534, 34)),
    ("cubic", (38534, 34), (38548, 34), (38557, 38), (38573, 52)),
    ("cubic", (38573, 52), (38605, 38), (38610, 36), (38652, 27)),
    ("line", (38652, 27), (38652, -56)),
    ("cubic", (38652, -56), (38652, -93), (38659, -123), (38702, -123)),
    ("cubic", (38702, -123), (38743, -123), (38751, -94), (38751, -56)),
    ("line", (38751, -56), (38751, 27)),
    ("cubic", (38751, 27), (38855, 47), (38917, 112), (38917, 199)),
    ("cubic", (38917, 199), (38917, 330), (38797, 353), (38751, 363)),
    ("line", (38751, 363), (38686, 377)),
    ("cubic", (38686, 377), (38635, 387), (38611, 406), (38611, 433)),
    ("cubic", (38611, 433), (38611, 470), (38650, 495), (38710, 495)),
    ("cubic", (38710, 495), (38751, 495), (38791, 478), (38794, 459)),
    ("cubic", (38794, 459), (38800, 432), (38819, 417), (38846, 417)),
    ("cubic", (38846, 417), (38887, 417), (38896, 445), (38896, 483)),
    ("line", (38896, 483), (38896, 515)),
    ("cubic", (38896, 515), (38896, 552), (38886, 581), (38846, 581)),
    ("cubic", (38846, 581), (38837, 581), (38829, 579), (38818, 574)),
    ("cubic", (38818, 574), (38814, 575), (38810, 576), (38809, 577)),
    ("line", (38809, 577), (38795, 582)),
    ("cubic", (38795, 582), (38776, 588), (38771, 588), (38751, 592)),
    ("line", (38751, 592), (38751, 618)),
    ("cubic", (38751, 618), (38751, 656), (38742, 684), (38702, 684)),
]


def test_a_corner_is_not_moved_onto_a_smooth_estimate() -> None:
    """Before: the corner's estimate (the crossing of its sides, kept inside the rounding
    square) put its joint 0.06 from the design's outline near the corner (79499.26, 1175.55);
    the repair then moved it onto the smooth estimate, inside the corner: the fit 0.76 from
    the design where the rounded input is 0.45. After: 0.50."""
    segs = _scaled(_FREEMONO_BOLD_DOLLAR, 2.048)
    corner = np.array([38818 * 2.048, 574 * 2.048])
    w, fp = _fit_rounded(segs)
    assert _local_distance(segs, fp, corner, 2.0) <= 0.55


def test_only_a_corner_joints_own_estimate_is_dropped() -> None:
    """Two paths of two segments each: the joint of the first turns 90 degrees (a corner),
    that of the second 5 (smooth). The corner joint's estimate is dropped, no other (the
    estimates of the points beside a corner still repair the segments there: a false corner
    of the rounding leaves a twisted cubic that only they correct)."""
    points = np.array([[0, 0], [10, 0], [10, 10],  # path 0: lines (0,0)-(10,0)-(10,10)
                       [20, 0], [30, 0], [40, 0.875]], dtype=np.float64)
    tail = np.array([1, 2, 4, 5])
    step = np.ones(4, dtype=np.intp)
    gfirst = np.array([0, 10, 21, 31])
    seg_owner = np.array([0, 0, 1, 1])
    valid = np.ones(42, dtype=bool)
    fitmod._no_estimates_at_corners(points, tail, step, gfirst, seg_owner, valid)
    assert np.flatnonzero(~valid).tolist() == [10]


#: Cantarell "a" (font units, em 1000), to be set at em 1500: the stem's right side, a
#: vertical line at x = 655.5, runs tangentially into the bowl's top curve at (655.5, 469.5);
#: its rounded points are on x = 656 and the curve's first ones on x = 655 (a false corner)
_CANTARELL_A = [
    ("cubic", (210, -10), (271, -10), (323, 10), (362, 45)),
    ("line", (362, 45), (381, 0)),
    ("line", (381, 0), (437, 0)),
    ("line", (437, 0), (437, 313)),
    ("cubic", (437, 313), (437, 428), (369, 492), (243, 492)),
    ("cubic", (243, 492), (180, 492), (112, 475), (60, 446)),
    ("line", (60, 446), (80, 387)),
    ("cubic", (80, 387), (130, 409), (180, 420), (227, 420)),
    ("cubic", (227, 420), (313, 420), (357, 384), (357, 313)),
    ("line", (357, 313), (357, 281)),
    ("cubic", (357, 281), (141, 279), (47, 234), (47, 131)),
    ("cubic", (47, 131), (47, 45), (111, -10), (210, -10)),
]


def test_a_false_corner_keeps_the_estimates_that_untwist_its_cubic() -> None:
    """The joint of the stem's line and the curve is a corner of the fit (the rounding's
    one-unit jog), and the short cubic after it starts twisted; the estimates of its points
    pull it back onto the design (0.52 from it, rounded input 0.45). Dropping the estimates
    of the whole window around the corner left it 1.08 off."""
    segs = _scaled(_CANTARELL_A, 1.5)
    w, fp = _fit_rounded(segs)
    assert _local_distance(segs, fp, np.array([655.4, 477.7]), 6.0) <= 0.6
