"""The typeface outlines the precision bench measures against (bench/fonts.py, issue 16): the
segments read from fontTools' pen are the glyph's true outline (quadratic and cubic, incl.
implied on-curve points), and their flattening keeps its chord-height promise. A wrong
reading here would make every "distance to the true curve" of the bench meaningless."""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "bench"))
pytest.importorskip("fontTools")

import fonts  # noqa: E402


def _chain_ok(contour):
    """Each segment starts where the previous one ends, and the last ends at the first's
    start (closed)."""
    ends = [s[-1] for s in contour]
    starts = [s[1] for s in contour]
    return all(np.array_equal(e, s) for e, s in zip(ends, starts[1:] + starts[:1], strict=True))


def test_implied_oncurve_points_of_an_all_offcurve_quadratic_contour():
    # a TrueType contour of four off-curve points (a rounded square): fontTools draws it as
    # qCurveTo(*offs, None) with no moveTo; the on-curve points are the midpoints
    offs = [(0, 0), (10, 0), (10, 10), (0, 10)]
    rec = [("qCurveTo", (*offs, None)), ("closePath", ())]
    (c,) = fonts.segments_of(rec, lambda p: np.array(p, dtype=float))
    assert [s[0] for s in c] == ["quad"] * 4
    assert _chain_ok(c)
    assert [tuple(s[2]) for s in c] == [(0, 0), (10, 0), (10, 10), (0, 10)]
    assert tuple(c[0][1]) == (0, 5) and tuple(c[1][1]) == (5, 0)


def test_multi_offcurve_qcurve_and_cubic_and_closing_line():
    rec = [("moveTo", ((0, 0),)), ("qCurveTo", ((10, 0), (20, 10), (20, 20))),
           ("curveTo", ((20, 30), (10, 40), (0, 40))), ("closePath", ())]
    (c,) = fonts.segments_of(rec, lambda p: np.array(p, dtype=float))
    assert [s[0] for s in c] == ["quad", "quad", "cubic", "line"]
    assert tuple(c[0][3]) == (15, 5)  # the implied on-curve point between the two controls
    assert _chain_ok(c)


def _area(poly):
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


@pytest.mark.parametrize("style", ["serif-italic", "mono", "cantarell", "inconsolata"])
def test_outline_area_matches_fonttools(style):
    """The signed area inside each glyph's contours, from our segments (flattened, chord
    1e-3), equals fontTools' AreaPen's closed-form area of the same glyph (an independent
    reading of the pen's quadratic / cubic calls)."""
    from fontTools.pens.areaPen import AreaPen
    from fontTools.ttLib import TTFont

    path = fonts.font_file(style)
    if not os.path.isfile(path):
        pytest.skip(f"{path} not installed")
    font = TTFont(path)
    gs, cmap = font.getGlyphSet(), font.getBestCmap()
    em = 1500.0
    scale = em / font["head"].unitsPerEm
    kinds = set()
    for ch in "aBgQRS&@8eJy%3Wxkz?5Gm2":
        pen = AreaPen(gs)
        gs[cmap[ord(ch)]].draw(pen)
        cs = fonts.contours(path, ch, em)
        assert all(_chain_ok(c) for c in cs)
        kinds |= {s[0] for c in cs for s in c}
        ours = sum(_area(fonts.dense(c, 1e-3)[:-1]) for c in cs)
        want = pen.value * scale * scale
        # chord 1e-3 over an outline of a few thousand units: well under 1 unit^2 apart
        assert ours == pytest.approx(want, abs=2.0, rel=1e-5), ch
    cff = style in ("cantarell", "inconsolata")
    assert ("cubic" in kinds) == cff and ("quad" in kinds) != cff


def test_cubic_flattening_keeps_the_chord_height():
    p0, c1, c2, p1 = (np.array(v, dtype=float) for v in ((0, 0), (300, 400), (-100, 400),
                                                         (200, 0)))
    for chord in (0.5, 0.05, 0.002):
        pts = fonts._flatten_cubic(p0, c1, c2, p1, chord)
        n = len(pts) - 1
        t = np.linspace(0, 1, 200 * n + 1)
        fine = fonts._cubic(p0, c1, c2, p1, t)
        k = np.minimum((t * n).astype(int), n - 1)
        a, b = pts[k], pts[k + 1]
        ab = b - a
        u = np.clip(((fine - a) * ab).sum(1) / (ab * ab).sum(1), 0, 1)
        h = np.hypot(*(a + u[:, None] * ab - fine).T).max()
        assert h <= chord
        assert h > chord / 8  # not wastefully dense either
