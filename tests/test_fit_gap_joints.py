"""Rounded input, issue 16 (eleventh and twelfth sessions): two design lines, each written as
its two rounded ends, that meet at a vertex turning a few degrees are left in one thinned
line; the fitted line is split at their common input point
(:func:`galvo_core.fit._split_gap_joints`) where one of the two lines continues into a
curve's dense points (a typeface: its design lines end at its curves), and not on a real
polyline, where every step is long and every vertex is such a joint.

Cantarell Thin "g" at em 2048: a 152-unit line and an 8-unit one meet at 4 degrees at
(3221.5, 835.6); one line over both passed 0.77 from that vertex, where the rounded input
is 0.50 from the design. FreeSans "3" at em 2048 (the unseen-font row): a 22.5-unit line
and a 76-unit one at 2 degrees, the thinned line over both and on into the curve passed
0.79 from their vertex (rounded input 0.40). The eleventh session's rule without the dense
run condition split real PLT polylines at their merged vertices: +6,420 segments over the
corpus (lectra_astm_test 5,469 -> 6,473)."""

from __future__ import annotations

import numpy as np
import pytest

from galvo_core import fit as fitmod
from galvo_core.fit import check_fit, fit_paths
from tests.test_fit_design_places import _local_distance, _rounded

#: Cantarell Thin at em 2048 in the precision bench's training text (bench/fonts.py): the
#: "g"'s outer contour (contour 5), coordinates to 0.001 unit
_G = [
    ('cubic', (2893.824, -20.48), (3033.088, -20.48), (3147.776, 43.008), (3221.504, 159.744)),
    ('line', (3221.504, 159.744), (3221.504, -65.536)),
    ('cubic', (3221.504, -65.536), (3221.504, -296.96), (3100.672, -428.032),
     (2885.632, -428.032)),
    ('cubic', (2885.632, -428.032), (2793.472, -428.032), (2703.36, -403.456),
     (2592.768, -348.16)),
    ('line', (2592.768, -348.16), (2580.48, -382.976)),
    ('cubic', (2580.48, -382.976), (2686.976, -438.272), (2781.184, -464.896),
     (2881.536, -464.896)),
    ('cubic', (2881.536, -464.896), (3121.152, -464.896), (3264.512, -315.392),
     (3264.512, -65.536)),
    ('line', (3264.512, -65.536), (3264.512, 987.136)),
    ('line', (3264.512, 987.136), (3231.744, 987.136)),
    ('line', (3231.744, 987.136), (3221.504, 835.584)),
    ('line', (3221.504, 835.584), (3221.504, 827.392)),
    ('cubic', (3221.504, 827.392), (3151.872, 935.936), (3041.28, 995.328), (2897.92, 995.328)),
    ('cubic', (2897.92, 995.328), (2635.776, 995.328), (2461.696, 790.528), (2461.696, 485.376)),
    ('cubic', (2461.696, 485.376), (2461.696, 182.272), (2633.728, -20.48), (2893.824, -20.48)),
]

#: FreeSans (GNU FreeFont, OTF) at em 2048, the "3" of the unseen-font text (A-Z a-z 0-9 @%$&;
#: contour 74 there), moved 65000 units left (whole units: the same rounded input, moved)
_THREE = [
    ('cubic', (650.688, 1294.336), (810.432, 1294.336), (906.688, 1200.128), (906.688, 1046.528)),
    ('cubic', (906.688, 1046.528), (906.688, 858.112), (789.952, 823.296), (550.336, 819.2)),
    ('line', (550.336, 819.2), (550.336, 665.6)),
    ('line', (550.336, 665.6), (572.864, 665.6)),
    ('line', (572.864, 665.6), (648.64, 667.648)),
    ('cubic', (648.64, 667.648), (847.296, 667.648), (949.696, 577.536), (949.696, 403.456)),
    ('cubic', (949.696, 403.456), (949.696, 221.184), (837.056, 112.64), (648.64, 112.64)),
    ('cubic', (648.64, 112.64), (452.032, 112.64), (355.776, 210.944), (343.488, 421.888)),
    ('line', (343.488, 421.888), (163.264, 421.888)),
    ('cubic', (163.264, 421.888), (185.792, 106.496), (339.392, -47.104), (642.496, -47.104)),
    ('cubic', (642.496, -47.104), (941.504, -47.104), (1134.016, 131.072), (1134.016, 405.504)),
    ('cubic', (1134.016, 405.504), (1134.016, 589.824), (1062.336, 692.224), (888.256, 751.616)),
    ('cubic', (888.256, 751.616), (1023.424, 804.864), (1091.008, 907.264),
     (1091.008, 1052.672)),
    ('cubic', (1091.008, 1052.672), (1091.008, 1302.528), (925.12, 1452.032),
     (648.64, 1452.032)),
    ('cubic', (648.64, 1452.032), (355.776, 1452.032), (200.128, 1292.288), (193.984, 983.04)),
    ('line', (193.984, 983.04), (374.208, 983.04)),
    ('cubic', (374.208, 983.04), (378.304, 1140.736), (421.312, 1294.336), (650.688, 1294.336)),
]


def _fit(pts, closed=True):
    fp = fit_paths([pts], [closed])[0]
    assert not check_fit(pts, fp, 0.02, 0.02, report=True)["violation"]
    return fp


def _polyline_distance(segs, pts, vertex):
    """The rounded input's own local distance to the design at ``vertex``."""
    poly = np.vstack([pts, pts[:1]])

    class _P:  # (the rounded polyline as one fitted line per step)
        segments = [type("S", (), {"kind": "line", "points": poly[i:i + 2]})()
                    for i in range(len(poly) - 1)]

    return _local_distance(segs, _P, vertex, 2.0)


@pytest.mark.parametrize("segs, vertex", [
    (_G, (3221.504, 835.584)),  # the dense run beyond the shorter line (outside the line)
    (_THREE, (572.864, 665.6)),  # beyond the longer one (inside the thinned line)
])
def test_two_nearly_collinear_design_lines_keep_their_vertex(monkeypatch, segs, vertex):
    vertex = np.array(vertex)
    pts = _rounded(segs)
    fp = _fit(pts)
    d = _local_distance(segs, fp, vertex, 2.0)
    d_in = _polyline_distance(segs, pts, vertex)
    assert d < 0.6 and d <= d_in + 0.02, (d, d_in)
    # one segment more than without the split, no more
    monkeypatch.setattr(fitmod, "_GAP_JOINTS", False)
    fp0 = _fit(pts)
    d0 = _local_distance(segs, fp0, vertex, 2.0)
    assert d0 > 0.7, d0  # (what it was: the vertex missed)
    assert fp.n_segments == fp0.n_segments + 1, (fp.n_segments, fp0.n_segments)


#: a real PLT polyline (the corpus's ertantoygar/textilecadinterpreter lectra_astm_test.hpgl,
#: path 546: a rounded rectangle whose long sides step by one unit): every step is long, no
#: curve's dense points anywhere
_LECTRA = [
    (18756, 32209), (27520, 32209), (35113, 32209), (38713, 32209), (38713, 31689),
    (38713, 30048), (38713, 29528), (35113, 29528), (27520, 29528), (18756, 29529),
    (2400, 29529), (920, 29529), (400, 30049), (400, 31689), (920, 32209), (2400, 32209),
    (18756, 32209),
]


def test_a_polyline_of_long_steps_is_not_split(monkeypatch):
    pts = np.array(_LECTRA, dtype=np.float64)
    n = _fit(pts).n_segments
    monkeypatch.setattr(fitmod, "_GAP_JOINTS", False)
    assert _fit(pts).n_segments == n
    # (the eleventh session's rule, without the dense run, split it at its one-unit steps)
    monkeypatch.setattr(fitmod, "_GAP_JOINTS", True)
    monkeypatch.setattr(fitmod, "_GAP_JOINT_RUN", 0)
    assert _fit(pts).n_segments > n
