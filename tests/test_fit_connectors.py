"""Issue 16: a line between a vertex moved onto the design and a thinned line that misses its
input points from there is split into the thinned line and a connector, a segment over no
input step from the moved vertex to its input point (``fit._valid_lines``). Where the joint
can sit at one point for both segments beside it within the bound, the connector is taken out
(``fit._connectors_out``): one segment fewer, the bound held, the design as near."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod
from galvo_core.fit import check_fit, fit_paths
from tests._util import design_distance
from tests.test_fit_design_places import _dense, _rounded


def _cubic_of_quad(p0, c, p1):
    p0, c, p1 = (np.asarray(v, dtype=np.float64) for v in (p0, c, p1))
    return ("cubic", tuple(p0), tuple(p0 + 2.0 / 3.0 * (c - p0)), tuple(p1 + 2.0 / 3.0 * (c - p1)),
            tuple(p1))


#: DejaVu Serif "B" (the inner contour of its lower bowl) in the precision bench's training
#: text at em 1000: two design lines and four quadratics
_SERIF_B = [
    ("line", (843.26171875, 51.7578125), (989.2578125, 51.7578125)),
    _cubic_of_quad((989.2578125, 51.7578125), (1077.1484375, 51.7578125),
                   (1117.67578125, 89.84375)),
    _cubic_of_quad((1117.67578125, 89.84375), (1158.203125, 127.9296875),
                   (1158.203125, 210.9375)),
    _cubic_of_quad((1158.203125, 210.9375), (1158.203125, 293.45703125),
                   (1117.919921875, 331.298828125)),
    _cubic_of_quad((1117.919921875, 331.298828125), (1077.63671875, 369.140625),
                   (989.2578125, 369.140625)),
    ("line", (989.2578125, 369.140625), (843.26171875, 369.140625)),
    ("line", (843.26171875, 369.140625), (843.26171875, 51.7578125)),
]


def _connectors(fp) -> int:
    return int(((fp.first == fp.last) & ~fp.is_cubic).sum())


def test_connector_taken_out_where_the_joint_can_move(monkeypatch):
    w = _rounded(_SERIF_B)
    fp = fit_paths([w], [True])[0]
    monkeypatch.setattr(fitmod, "_CONNECTOR_SHARES", ())
    without = fit_paths([w], [True])[0]
    # without the pass the fit holds a connector; with it, none, and one segment fewer
    assert _connectors(without) >= 1
    assert _connectors(fp) == 0
    assert len(fp.first) < len(without.first)
    assert not check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    truth = _dense(_SERIF_B, 0.001)
    assert design_distance(fp, truth) <= design_distance(without, truth) + 0.02


#: DejaVu Sans "B" (the inner contour of its lower bowl) in the training text at em 1000:
#: three design lines and four quadratics
_SANS_B = [
    ("line", (809.5703125, 348.14453125), (809.5703125, 81.0546875)),
    ("line", (809.5703125, 81.0546875), (967.7734375, 81.0546875)),
    _cubic_of_quad((967.7734375, 81.0546875), (1047.36328125, 81.0546875),
                   (1085.693359375, 114.013671875)),
    _cubic_of_quad((1085.693359375, 114.013671875), (1124.0234375, 146.97265625),
                   (1124.0234375, 214.84375)),
    _cubic_of_quad((1124.0234375, 214.84375), (1124.0234375, 283.203125),
                   (1085.693359375, 315.673828125)),
    _cubic_of_quad((1085.693359375, 315.673828125), (1047.36328125, 348.14453125),
                   (967.7734375, 348.14453125)),
    ("line", (967.7734375, 348.14453125), (809.5703125, 348.14453125)),
]


def test_refinement_merges_a_line_that_is_no_design_line(monkeypatch):
    """A thinned line inside a smooth stretch (not a design line: it has input points between
    its ends) is merged with its neighbour by the refinement (``fit._MINIMAX_LINES``), as two
    cubics are: fewer segments, the bound held, no farther from the design."""
    w = _rounded(_SANS_B)
    fp = fit_paths([w], [True])[0]
    monkeypatch.setattr(fitmod, "_MINIMAX_LINES", False)
    without = fit_paths([w], [True])[0]
    assert len(fp.first) < len(without.first)
    assert not check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    truth = _dense(_SANS_B, 0.001)
    assert design_distance(fp, truth) <= design_distance(without, truth) + 0.02
    # the design's long lines stay lines
    lines = [s for s in fp.segments if s.kind == "line"]
    assert sum(np.hypot(*(s.points[1] - s.points[0])) > 100.0 for s in lines) == 3
