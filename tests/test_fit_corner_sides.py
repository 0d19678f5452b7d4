"""Rounded input, issue 16 (eleventh session): corners beside a two-point line whose curve
side is no good estimate, and smooth vertices beside a design line written as its two ends.
Each outline is a glyph contour as read from the font by bench/fonts.py (inline: a fresh
machine has DejaVu fonts only), flattened and rounded as the precision bench does it."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod
from tests.test_fit_design_places import _fit_rounded, _local_distance, _rounded

#: Inconsolata at em 700 in the held-out text: contour 6, the "5"; at (1838.2, 91.8) a short
#: S-shaped cubic ends at a 44-unit design line written as its two rounded ends
_FIVE = [
    ('line', (1824.3046, 436.1602), (1809.202, 214.4557)),
    ('line', (1809.202, 214.4557), (1840.6151, 201.7695)),
    ('cubic', (1840.6151, 201.7695), (1861.665, 228.2786), (1892.5416, 242.9137),
     (1922.3265, 242.9137)),
    ('cubic', (1922.3265, 242.9137), (1968.2462, 242.9137), (2011.5949, 208.3361),
     (2011.5949, 138.8263)),
    ('cubic', (2011.5949, 138.8263), (2011.5949, 71.7452), (1970.1944, 35.0294),
     (1923.371, 35.0294)),
    ('cubic', (1923.371, 35.0294), (1876.2721, 35.0294), (1845.8419, 70.7362),
     (1843.4151, 75.3245)),
    ('cubic', (1843.4151, 75.3245), (1840.5953, 80.6565), (1844.1883, 87.5506),
     (1838.1986, 91.823)),
    ('line', (1838.1986, 91.823), (1794.7036, 59.202)),
    ('cubic', (1794.7036, 59.202), (1823.6278, 16.5067), (1872.1411, -7.8634),
     (1923.9739, -7.8634)),
    ('cubic', (1923.9739, -7.8634), (1999.3716, -7.8634), (2061.7434, 43.3562),
     (2061.7434, 137.8959)),
    ('cubic', (2061.7434, 137.8959), (2061.7434, 231.2673), (2002.8176, 283.3312),
     (1929.7879, 283.3312)),
    ('cubic', (1929.7879, 283.3312), (1905.7008, 283.3312), (1881.3368, 277.6812),
     (1858.7379, 266.4081)),
    ('line', (1858.7379, 266.4081), (1865.3831, 392.0608)),
    ('line', (1865.3831, 392.0608), (2045.4048, 392.0608)),
    ('line', (2045.4048, 392.0608), (2045.4048, 436.1602)),
    ('line', (2045.4048, 436.1602), (1824.3046, 436.1602)),
]
_FIVE_CORNER = np.array([1838.1986, 91.823])


def _input_distance(segs, place) -> float:
    """The rounded input polyline's own both-ways distance to the design near ``place``."""
    pts = _rounded(segs)
    poly = np.vstack([pts, pts[:1]])

    class _Poly:
        segments = [type("S", (), {"kind": "line", "points": poly[i:i + 2]})()
                    for i in range(len(poly) - 1)]

    return _local_distance(segs, _Poly, place, 2.0)


def test_a_curve_side_that_misses_its_quadratic_gives_no_crossing_with_a_two_point_line(
        monkeypatch):
    # the curve side's quadratic spans the S-shaped cubic's inflection (a point 0.84 quanta
    # off it): its tangent slid the crossing along the line 0.67 from the design's corner
    fp = _fit_rounded(_FIVE)[1]
    d = _local_distance(_FIVE, fp, _FIVE_CORNER, 2.0)
    assert d < 0.6 and d <= _input_distance(_FIVE, _FIVE_CORNER) + 0.02, d
    monkeypatch.setattr(fitmod, "_LONE_RES", np.inf)
    fp0 = _fit_rounded(_FIVE)[1]
    assert _local_distance(_FIVE, fp0, _FIVE_CORNER, 2.0) > 0.6


def _dejavu(style: str, index: int, em: float = 400.0):
    """A contour of a DejaVu style (bench/fonts.py) in the training text at ``em``."""
    import os
    import sys

    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "bench"))
    import fonts

    raw = fonts.contours(fonts.font_file(style), fonts.TEXT, em)[index]
    out = []
    for kind, *p in raw:
        p = [np.asarray(v, dtype=np.float64) for v in p]
        if kind == "quad":  # (as the cubic it is)
            out.append(("cubic", p[0], p[0] + 2.0 / 3.0 * (p[1] - p[0]),
                        p[2] + 2.0 / 3.0 * (p[1] - p[2]), p[2]))
        else:
            out.append((kind, *p))
    return out


def test_a_smooth_vertex_beside_a_design_line_moves_only_along_it(monkeypatch):
    # DejaVu Sans "B" at em 400: a 63-unit design line (its two rounded ends) runs into a
    # tangent curve at (387.1, 32.4); the vertex there, moved across the line onto the curve's
    # estimate, tilted the line 0.63 from the design (the rounded input: 0.44)
    segs = _dejavu("sans", 2)
    place = np.array([387.11, 32.42])
    fp = _fit_rounded(segs)[1]
    d = _local_distance(segs, fp, place, 2.0)
    assert d < 0.6 and d <= _input_distance(segs, place) + 0.02, d
    monkeypatch.setattr(fitmod, "_SMOOTH_ALONG", False)
    fp0 = _fit_rounded(segs)[1]
    assert _local_distance(segs, fp0, place, 2.0) > 0.6
    assert fp.n_segments <= fp0.n_segments
