"""The gap-end rule of the fit (``fit._gap_ends_kept``) is for a curve's dense end beside a
design line; on a real polyline file (a Tektronix screen plot: strokes and text, whole units)
it must not split the thinned lines that serve a few short strokes beside a long one."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from galvo_core import fit as fitmod
from galvo_core import hpgl
from tests.test_fit_design_places import _local_distance, _rounded

CORPUS = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "plt"
TEK = CORPUS / "vk2bea__hpgl-plotter__tektronix.hpgl"


@pytest.mark.skipif(not TEK.exists(), reason="corpus not present")
def test_polyline_strokes_are_not_split_at_their_long_steps(monkeypatch) -> None:
    d = hpgl.read_file(TEK)
    with_rule = fitmod.fit_drawing(d)
    monkeypatch.setattr(fitmod, "_gap_ends_kept", lambda W, K, tlen, *a: (K, tlen))
    without = fitmod.fit_drawing(d)
    n_with = sum(f.n_segments for f in with_rule)
    n_without = sum(f.n_segments for f in without)
    # (the rule unguarded made 957 segments of this file's 761: a quarter more marks)
    assert n_with <= 1.05 * n_without
    # and the bound still holds on every path (true distances both ways)
    for f, p in zip(with_rule, d.paths, strict=True):
        rep = fitmod.check_fit(p.points, f, fitmod.DEFAULT_E_PER, fitmod.DEFAULT_EPS_LINE,
                               report=True)
        assert rep["violation"] == 0.0


#: NimbusRoman-Italic (URW base35) "l" at em 1000 (its design in whole units): a curve's end
#: (three cubics, a 2-unit line) nearly collinear with the 598-unit design line after it
_NIMBUS_ITALIC_L = [
    ("cubic", (228, 123), (163, 40), (155, 32), (133, 32)),
    ("cubic", (133, 32), (123, 32), (118, 38), (118, 50)),
    ("cubic", (118, 50), (118, 58), (121, 71), (126, 89)),
    ("cubic", (126, 89), (127, 93), (128, 96), (128, 97)),
    ("line", (128, 97), (128, 99)),
    ("line", (128, 99), (279, 678)),
    ("line", (279, 678), (274, 683)),
    ("cubic", (274, 683), (214, 669), (176, 663), (118, 656)),
    ("line", (118, 656), (118, 640)),
    ("cubic", (118, 640), (166, 640), (186, 634), (186, 617)),
    ("cubic", (186, 617), (186, 613), (185, 607), (183, 599)),
    ("line", (183, 599), (45, 71)),
    ("cubic", (45, 71), (42, 61), (41, 52), (41, 45)),
    ("cubic", (41, 45), (41, 8), (58, -11), (90, -11)),
    ("cubic", (90, -11), (142, -11), (176, 17), (241, 114)),
    ("line", (241, 114), (228, 123)),
]


def test_a_gap_end_beside_a_curve_that_is_no_line_is_kept() -> None:
    """The thinning kept the curve's last 37 points and the long line in one segment (the
    line's start 0.67 off it, on the design); the rest of that segment is no line within the
    bound, and splitting it at its farthest points (each next to the line's start) never
    makes it one, so the line's start was dropped and the fit passed 0.67 from the design's
    corner. Thinned on its own, the rest is a few lines, each within the bound: the line's
    start is kept and the fit passes within 0.6 of the design there."""
    w = _rounded(_NIMBUS_ITALIC_L)
    fp = fitmod.fit_paths([w], [True])[0]
    assert not fitmod.check_fit(w, fp, 0.02, 0.02, report=True)["violation"]
    ends = np.array([s.points[-1] for s in fp.segments])
    assert np.hypot(*(ends - [128.0, 99.0]).T).min() <= 0.71  # (a joint at the line's start)
    assert _local_distance(_NIMBUS_ITALIC_L, fp, np.array([128.0, 99.0]), 2.0) <= 0.6
    # (the design's own count here is 16)
    assert len(fp.segments) <= 16
