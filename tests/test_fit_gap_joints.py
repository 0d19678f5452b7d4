"""Rounded input, issue 16 (eleventh session): two design lines, each written as its two
rounded ends, that meet at a vertex turning a few degrees are left in one thinned line;
the fitted line is split at their common input point (:func:`galvo_core.fit._split_gap_joints`).

Cantarell Thin "g" at em 2048: a 152-unit line and an 8-unit one meet at 4 degrees at
(3221.5, 835.6); one line over both passed 0.77 from that vertex, where the rounded input
is 0.50 from the design."""

from __future__ import annotations

import numpy as np

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
_VERTEX = np.array([3221.504, 835.584])


def _fit():
    pts = _rounded(_G)
    fp = fit_paths([pts], [True])[0]
    assert not check_fit(pts, fp, 0.02, 0.02, report=True)["violation"]
    return pts, fp


def test_two_nearly_collinear_design_lines_keep_their_vertex(monkeypatch):
    pts, fp = _fit()
    d = _local_distance(_G, fp, _VERTEX, 2.0)
    # the rounded input's own distance there
    poly = np.vstack([pts, pts[:1]])

    class _P:  # (the rounded polyline as one fitted line per step)
        segments = [type("S", (), {"kind": "line", "points": poly[i:i + 2]})()
                    for i in range(len(poly) - 1)]

    d_in = _local_distance(_G, _P, _VERTEX, 2.0)
    assert d < 0.6 and d <= d_in + 0.02, (d, d_in)
    # one segment more than without the split, no more
    monkeypatch.setattr(fitmod, "_GAP_JOINTS", False)
    _, fp0 = _fit()
    d0 = _local_distance(_G, fp0, _VERTEX, 2.0)
    assert d0 > 0.7, d0  # (what it was: the vertex missed)
    assert fp.n_segments == fp0.n_segments + 1, (fp.n_segments, fp0.n_segments)
