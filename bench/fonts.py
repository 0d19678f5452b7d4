"""Typeface outlines as test data for the precision-aware fit (issue 16).

A glyph's outline (TrueType: lines and quadratic Béziers; OpenType/CFF: lines and cubic
Béziers) is scaled to ``em`` input units, each segment written as a CAD program writes it (a
dense run of points, chord height at most ``chord`` units; a line as its two ends), and
optionally rounded to whole units (the way most PLT files store points). The *typeface's own
segment count* is the number of line, quadratic and cubic segments of the outlines (each curve
counts as one; a zero-length closing line does not count). The true design curve is kept as a dense
float polyline (chord height 1e-3 unit) to measure a fit against.

Fonts: ``STYLES`` (six DejaVu styles, one text ``TEXT``, em 1000) is the set the fit was
developed on. ``HELDOUT`` are other typefaces, never used to tune the fit: four other DejaVu
styles (TrueType) and Inconsolata and Cantarell (OpenType/CFF: cubic outlines), to be run with
another text (``HELDOUT_TEXT``) and other ems (``HELDOUT_EMS``). Any TTF/OTF file can be given
by its path. DejaVu: Bitstream Vera licence; Inconsolata, Cantarell: SIL Open Font Licence;
the files are looked up under /usr/share/fonts (Debian's fonts-dejavu-core / -extra,
fonts-inconsolata, fonts-cantarell).
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
from dataclasses import dataclass, field

import numpy as np

# Inconsolata has a few (unused) glyphs with a negative advance: fontTools warns on load
logging.getLogger("fontTools.ttLib.tables._h_m_t_x").setLevel(logging.ERROR)

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
#: name -> file: typefaces not in STYLES (held out: the fit was never tuned on them)
HELDOUT = {
    "mono": os.path.join(FONT_DIR, "DejaVuSansMono.ttf"),
    "sans-cond-oblique": os.path.join(FONT_DIR, "DejaVuSansCondensed-Oblique.ttf"),
    "serif-bold": os.path.join(FONT_DIR, "DejaVuSerif-Bold.ttf"),
    "serif-cond-italic": os.path.join(FONT_DIR, "DejaVuSerifCondensed-Italic.ttf"),
    "inconsolata": "/usr/share/fonts/truetype/inconsolata/Inconsolata.otf",
    "cantarell": "/usr/share/fonts/opentype/cantarell/Cantarell-Regular.otf",
    "cantarell-thin": "/usr/share/fonts/opentype/cantarell/Cantarell-Thin.otf",
}
HELDOUT_TEXT = "Wxkz?5Gm2&"
HELDOUT_EMS = (700.0, 1500.0)


def font_file(style: str) -> str:
    """The file of a style: a name of STYLES or HELDOUT, or a TTF/OTF path."""
    if style in STYLES:
        return os.path.join(FONT_DIR, STYLES[style])
    if style in HELDOUT:
        return HELDOUT[style]
    return style


def style_name(style: str) -> str:
    """A short name for a style (a path: its file name without the extension)."""
    if style in STYLES or style in HELDOUT:
        return style
    return os.path.splitext(os.path.basename(style))[0]


@dataclass
class GlyphSet:
    """Outlines of one text in one style: per contour its dense points (float, or whole
    units), its true curve (dense float polyline) and its own segment count."""

    style: str
    points: list[np.ndarray]
    truth: list[np.ndarray]
    own_segments: int
    #: per contour the design vertices between two lines (each line written as its two
    #: rounded ends: no method that sees only the rounded points can promise to come nearer
    #: than 0.65-0.71 unit there in the worst case, bench_precision_worst.py's oracle)
    line_corners: list[np.ndarray] = field(default_factory=list)


def _quad(p0, c, p1, t):
    s = 1.0 - t
    return (s * s)[:, None] * p0 + (2.0 * s * t)[:, None] * c + (t * t)[:, None] * p1


def _flatten_quad(p0, c, p1, chord: float) -> np.ndarray:
    """Points of the quadratic at uniform parameter steps, chord height <= ``chord``
    (|B''| = 2|p0 - 2c + p1| constant: height <= |B''| h^2 / 8)."""
    acc = 2.0 * float(np.hypot(*(p0 - 2.0 * c + p1)))
    n = max(1, math.ceil(math.sqrt(acc / (8.0 * chord)))) if acc > 0 else 1
    return _quad(p0, c, p1, np.linspace(0.0, 1.0, n + 1))


def _cubic(p0, c1, c2, p1, t):
    s = 1.0 - t
    return ((s * s * s)[:, None] * p0 + (3.0 * s * s * t)[:, None] * c1
            + (3.0 * s * t * t)[:, None] * c2 + (t * t * t)[:, None] * p1)


def _flatten_cubic(p0, c1, c2, p1, chord: float) -> np.ndarray:
    """Points of the cubic at uniform parameter steps, chord height <= ``chord``
    (B''(t) = 6((1-t)(p0 - 2c1 + c2) + t(c1 - 2c2 + p1)): |B''| <= 6 max of the two ends'
    norms, height over a parameter step h <= max|B''| h^2 / 8)."""
    acc = 6.0 * max(float(np.hypot(*(p0 - 2.0 * c1 + c2))),
                    float(np.hypot(*(c1 - 2.0 * c2 + p1))))
    n = max(1, math.ceil(math.sqrt(acc / (8.0 * chord)))) if acc > 0 else 1
    return _cubic(p0, c1, c2, p1, np.linspace(0.0, 1.0, n + 1))


def flatten_segment(s: tuple, chord: float) -> np.ndarray:
    """The points of one segment ("line", p0, p1) / ("quad", p0, c, p1) /
    ("cubic", p0, c1, c2, p1), chord height <= ``chord``."""
    if s[0] == "line":
        return np.array([s[1], s[2]])
    if s[0] == "quad":
        return _flatten_quad(s[1], s[2], s[3], chord)
    return _flatten_cubic(s[1], s[2], s[3], s[4], chord)


def segments_of(recording: list[tuple], pt) -> list[list[tuple]]:
    """Per contour its segments, from a fontTools RecordingPen's value (``pt`` maps a design
    point to output units). As fontTools' BasePen reads the pen calls: qCurveTo with n
    off-curve points is n quadratics through the implied on-curve midpoints, ending on its
    last point, or, with None last (a TrueType contour of off-curve points only, no moveTo),
    a closed ring of quadratics between all the midpoints; curveTo(c1, c2, p) is a cubic
    (more than two off-curve points: fontTools' super-Bézier decomposition); a qCurveTo /
    curveTo without off-curve points is a line. A contour is closed by a line back to its
    start if it does not end there (a zero-length lineTo of the design is kept: it is one of
    the typeface's segments, as the default bench has always counted it)."""
    from fontTools.pens.basePen import decomposeSuperBezierSegment

    out: list[list[tuple]] = []
    cur = start = None
    segs: list[tuple] = []

    def line(p):
        nonlocal cur
        segs.append(("line", cur, p))
        cur = p

    for op, args in recording:
        if op == "moveTo":
            cur = start = pt(args[0])
            segs = []
        elif op == "lineTo":
            line(pt(args[0]))
        elif op == "qCurveTo":
            if args[-1] is None:
                offs = [pt(a) for a in args[:-1]]
                n = len(offs)
                mids = [0.5 * (offs[k - 1] + offs[k]) for k in range(n)]
                cur = start = mids[0]
                segs = [("quad", mids[k], offs[k], mids[(k + 1) % n]) for k in range(n)]
                continue
            pts = [pt(a) for a in args]
            offs, end = pts[:-1], pts[-1]
            if not offs:
                line(end)
            for k, c in enumerate(offs):
                nxt = end if k == len(offs) - 1 else 0.5 * (c + offs[k + 1])
                segs.append(("quad", cur, c, nxt))
                cur = nxt
        elif op == "curveTo":
            if len(args) == 1:
                line(pt(args[0]))
            elif len(args) == 2:  # BasePen: one off-curve point = a quadratic
                segs.append(("quad", cur, pt(args[0]), pt(args[1])))
                cur = pt(args[1])
            else:
                parts = ([args] if len(args) == 3
                         else decomposeSuperBezierSegment(list(args)))
                for c1, c2, p in parts:
                    segs.append(("cubic", cur, pt(c1), pt(c2), pt(p)))
                    cur = pt(p)
        elif op in ("closePath", "endPath"):
            if cur is not None and not np.array_equal(cur, start):
                line(start)
            if segs:
                out.append(segs)
            cur = None
    return out


def contours(font_file: str, text: str, em: float) -> list[list[tuple]]:
    """Per contour: its segments ("line", p0, p1) / ("quad", p0, c, p1) /
    ("cubic", p0, c1, c2, p1), in units where the em is ``em``; glyphs laid out left to
    right by their advance widths."""
    from fontTools.pens.recordingPen import DecomposingRecordingPen
    from fontTools.ttLib import TTFont

    font = TTFont(font_file)
    gs = font.getGlyphSet()
    cmap = font.getBestCmap()
    scale = em / font["head"].unitsPerEm
    out: list[list[tuple]] = []
    x0 = 0.0
    for ch in text:
        if ord(ch) not in cmap:
            raise ValueError(f"{font_file}: no glyph for {ch!r}")
        name = cmap[ord(ch)]
        pen = DecomposingRecordingPen(gs)
        gs[name].draw(pen)

        def pt(p, _x0=x0):
            return np.array([p[0] * scale + _x0, p[1] * scale])

        out += segments_of(pen.value, pt)
        x0 += gs[name].width * scale
    return out


def dense(segs: list[tuple], chord: float) -> np.ndarray:
    parts = [flatten_segment(s, chord) for s in segs]
    pts = np.vstack([parts[0]] + [p[1:] for p in parts[1:]])
    return pts


def glyph_set(style: str, *, em: float = 1000.0, whole: bool, chord: float = 0.002,
              text: str = TEXT) -> GlyphSet:
    """``style``: a name of STYLES or HELDOUT, or a TTF/OTF path."""
    cs = contours(font_file(style), text, em)
    pts, truth, lc = [], [], []
    for segs in cs:
        p = dense(segs, chord)
        if whole:
            p = np.round(p)
            keep = np.r_[True, (p[1:] != p[:-1]).any(axis=1)]
            p = p[keep]
        pts.append(p)
        truth.append(dense(segs, 1e-3))
        lc.append(np.array([s[1] for i, s in enumerate(segs)
                            if s[0] == "line" and segs[i - 1][0] == "line"]).reshape(-1, 2))
    return GlyphSet(style_name(style), pts, truth, sum(len(s) for s in cs), lc)


#: radius (units) around a line-line design corner left out of the "away" distance
LINE_CORNER_R = 2.0


def curve_distance(fitted_dense: np.ndarray, truth: np.ndarray,
                   skip: np.ndarray | None = None, r: float = LINE_CORNER_R) -> float:
    """Both-ways distance of two polylines (max of the two directed maxima, each vertex of
    one to the other polyline): Hausdorff to within the vertex spacing's sagitta. ``skip``:
    points (K, 2) whose r-neighbourhoods are left out (of both polylines' vertices)."""
    from galvo_core.geometry import point_polyline_distance

    def kept(p):
        if skip is None or len(skip) == 0:
            return p
        d2 = ((p[:, None, :] - skip[None, :, :]) ** 2).sum(axis=2).min(axis=1)
        return p[d2 > r * r]

    fa, ta = kept(fitted_dense), kept(truth)
    a = float(point_polyline_distance(fa, truth).max()) if len(fa) else 0.0
    b = float(point_polyline_distance(ta, fitted_dense).max()) if len(ta) else 0.0
    return max(a, b)


def add_font_options(ap, *, styles_default: str | None = None) -> None:
    """The bench's font options: which typefaces, text and ems (argparse)."""
    ap.add_argument("--set", choices=("train", "heldout"), default="train",
                    help="train: the six DejaVu STYLES, TEXT, em 1000 (the default run); "
                         "heldout: HELDOUT typefaces, HELDOUT_TEXT, ems 700 and 1500")
    ap.add_argument("--styles", default=styles_default,
                    help="comma-separated names of STYLES / HELDOUT (default: the set's)")
    ap.add_argument("--font", action="append", default=[], metavar="FILE",
                    help="a TTF/OTF file (several: repeat); with no --styles, only these")
    ap.add_argument("--text", help="the text to set (default: the set's)")
    ap.add_argument("--em", help="em size(s) in input units, comma-separated "
                                 "(default: the set's)")


def font_options(a) -> tuple[list[str], str, list[float]]:
    """(styles, text, ems) from the options of ``add_font_options``."""
    train = a.set == "train"
    if a.styles:
        styles = a.styles.split(",")
    elif a.font:
        styles = []
    else:
        styles = list(STYLES if train else HELDOUT)
    styles += a.font
    for st in styles:
        if st not in STYLES and st not in HELDOUT and not os.path.isfile(st):
            raise SystemExit(f"error: {st}: not a style name ({', '.join([*STYLES, *HELDOUT])})"
                             " nor a font file")
    text = a.text if a.text is not None else (TEXT if train else HELDOUT_TEXT)
    if a.em:
        try:
            ems = [float(e) for e in str(a.em).split(",")]
        except ValueError:
            raise SystemExit(f"error: --em {a.em}: not a number list") from None
    else:
        ems = [1000.0] if train else list(HELDOUT_EMS)
    return styles, text, ems


def run_label(text: str, ems: list[float]) -> str | None:
    """A line naming the text and ems of a run, or None for the default's (TEXT, em 1000),
    whose output stays as it always was."""
    if text == TEXT and ems == [1000.0]:
        return None
    return f"text {text!r}, em {', '.join(f'{e:g}' for e in ems)}"


@contextlib.contextmanager
def font_errors(style: str):
    """A font that cannot be read, or lacks a glyph of the text: one line
    ``error: <file>: <reason>`` and exit status 1, no traceback."""
    from fontTools.ttLib import TTLibError

    f = font_file(style)
    try:
        yield
    except (OSError, ValueError, TTLibError) as e:
        msg = str(e)
        raise SystemExit(f"error: {msg}" if msg.startswith(f) else f"error: {f}: {msg}") from None
