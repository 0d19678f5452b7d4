"""Typeface outlines as test data for the precision-aware fit (issue 16).

A glyph's outline (TrueType: lines and quadratic Béziers) is scaled to ``em`` input units,
each segment written as a CAD program writes it (a dense run of points, chord height at most
``chord`` units; a line as its two ends), and optionally rounded to whole units (the way most
PLT files store points). The *typeface's own segment count* is the number of line and
quadratic segments of the outlines (each quadratic counts as one; a zero-length closing line
does not count). The true design curve is kept as a dense float polyline (chord height 1e-3
unit) to measure a fit against.

Fonts: DejaVu (Bitstream Vera licence, free to redistribute derived data); the files are
looked up under /usr/share/fonts (Debian's fonts-dejavu-core / fonts-dejavu-extra).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

FONT_DIR = "/usr/share/fonts/truetype/dejavu"
#: name -> file: several styles (serif, sans, bold, italic, condensed bold italic, light)
STYLES = {
    "sans": "DejaVuSans.ttf",
    "sans-bold": "DejaVuSans-Bold.ttf",
    "serif": "DejaVuSerif.ttf",
    "serif-italic": "DejaVuSerif-Italic.ttf",
    "serif-bolditalic": "DejaVuSerifCondensed-BoldItalic.ttf",
    "sans-light": "DejaVuSans-ExtraLight.ttf",
}
TEXT = "aBgQRS&@8eJy%3"


@dataclass
class GlyphSet:
    """Outlines of one text in one style: per contour its dense points (float, or whole
    units), its true curve (dense float polyline) and its own segment count."""

    style: str
    points: list[np.ndarray]
    truth: list[np.ndarray]
    own_segments: int


def _quad(p0, c, p1, t):
    s = 1.0 - t
    return (s * s)[:, None] * p0 + (2.0 * s * t)[:, None] * c + (t * t)[:, None] * p1


def _flatten_quad(p0, c, p1, chord: float) -> np.ndarray:
    """Points of the quadratic at uniform parameter steps, chord height <= ``chord``
    (|B''| = 2|p0 - 2c + p1| constant: height <= |B''| h^2 / 8)."""
    acc = 2.0 * float(np.hypot(*(p0 - 2.0 * c + p1)))
    n = max(1, math.ceil(math.sqrt(acc / (8.0 * chord)))) if acc > 0 else 1
    return _quad(p0, c, p1, np.linspace(0.0, 1.0, n + 1))


def contours(font_file: str, text: str, em: float) -> list[list[tuple]]:
    """Per contour: its segments ("line", p0, p1) / ("quad", p0, c, p1), in units where the
    em is ``em``; glyphs laid out left to right by their advance widths."""
    from fontTools.pens.recordingPen import DecomposingRecordingPen
    from fontTools.ttLib import TTFont

    font = TTFont(font_file)
    gs = font.getGlyphSet()
    cmap = font.getBestCmap()
    scale = em / font["head"].unitsPerEm
    out: list[list[tuple]] = []
    x0 = 0.0
    for ch in text:
        name = cmap[ord(ch)]
        pen = DecomposingRecordingPen(gs)
        gs[name].draw(pen)
        cur = None
        start = None
        segs: list[tuple] = []

        def pt(p, _x0=x0):
            return np.array([p[0] * scale + _x0, p[1] * scale])

        for op, args in pen.value:
            if op == "moveTo":
                cur = start = pt(args[0])
                segs = []
            elif op == "lineTo":
                p = pt(args[0])
                segs.append(("line", cur, p))
                cur = p
            elif op == "qCurveTo":
                pts = [pt(a) for a in args]
                if args[-1] is None:  # (all off-curve: not in DejaVu)
                    raise ValueError("implied-start quadratic contour")
                offs, end = pts[:-1], pts[-1]
                for k, c in enumerate(offs):
                    nxt = end if k == len(offs) - 1 else 0.5 * (c + offs[k + 1])
                    segs.append(("quad", cur, c, nxt))
                    cur = nxt
            elif op == "curveTo":
                raise ValueError("cubic outline: use a TrueType font")
            elif op in ("closePath", "endPath"):
                if cur is not None and not np.array_equal(cur, start):
                    segs.append(("line", cur, start))
                if segs:
                    out.append(segs)
                cur = None
        x0 += gs[name].width * scale
    return out


def dense(segs: list[tuple], chord: float) -> np.ndarray:
    parts = []
    for s in segs:
        if s[0] == "line":
            parts.append(np.array([s[1], s[2]]))
        else:
            parts.append(_flatten_quad(s[1], s[2], s[3], chord))
    pts = np.vstack([parts[0]] + [p[1:] for p in parts[1:]])
    return pts


def glyph_set(style: str, *, em: float = 1000.0, whole: bool, chord: float = 0.002,
              text: str = TEXT) -> GlyphSet:
    cs = contours(os.path.join(FONT_DIR, STYLES[style]), text, em)
    pts, truth = [], []
    for segs in cs:
        p = dense(segs, chord)
        if whole:
            p = np.round(p)
            keep = np.r_[True, (p[1:] != p[:-1]).any(axis=1)]
            p = p[keep]
        pts.append(p)
        truth.append(dense(segs, 1e-3))
    return GlyphSet(style, pts, truth, sum(len(s) for s in cs))


def curve_distance(fitted_dense: np.ndarray, truth: np.ndarray) -> float:
    """Both-ways distance of two polylines (max of the two directed maxima, each vertex of
    one to the other polyline): Hausdorff to within the vertex spacing's sagitta."""
    from galvo_core.geometry import point_polyline_distance

    a = float(point_polyline_distance(fitted_dense, truth).max())
    b = float(point_polyline_distance(truth, fitted_dense).max())
    return max(a, b)
