"""Generate the bundled sample PLT (HP-GL) files in ``resources/samples/``.

Run from anywhere with the project's interpreter::

    .venv/bin/python resources/make_samples.py

Everything here is made by this script (no copies of third-party drawings): glyph
outlines come from the DejaVu Sans font through Qt's ``QPainterPath.addText`` and are
flattened by our own Bezier sampling; the other shapes are computed.  The output is
deterministic for a given font file and Qt version, and the files are committed, so
the script only needs running again when a sample is to change.

Units are HP-GL plotter units, 40 per millimetre.  Every file starts with ``IN;SP1;``
and ends with ``PU;SP0;``.  The files deliberately use different CAD "dialects":

* ``text_outline.plt``  - one point per ``PD`` command, CR/LF line ends (CorelDRAW style)
* ``seal.plt``          - multi-point ``PD`` lists of up to 16 points, LF line ends
* ``arcs_circles.plt``  - HP-GL arc/rectangle/relative/Bezier commands (CI, AA, AR, AT,
  EA, ER, RA, RR, PR, BZ, BR) rather than points
* ``curve_1181.plt``    - one closed contour of exactly 1181 points, 8 points per ``PD``
* ``dense_logo.plt``    - ~40k points in long ``PD`` lists (one per contour), no line
  breaks inside a contour: a performance sample for the GUI
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import numpy as np

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QPointF  # noqa: E402
from PySide6.QtGui import (  # noqa: E402
    QFont,
    QFontDatabase,
    QFontMetricsF,
    QGuiApplication,
    QPainterPath,
    QTransform,
)

HERE = Path(__file__).resolve().parent
OUT_DIR = HERE / "samples"
FONT_FILE = Path("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf")
FONT_FILE_BOLD = Path("/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf")

UNITS_PER_MM = 40

Point = tuple[int, int]
Contour = list[Point]


# --------------------------------------------------------------------------------------
# writing
# --------------------------------------------------------------------------------------


class PltWriter:
    """Accumulates HP-GL commands; counts the coordinate pairs written by PU/PD."""

    def __init__(self, eol: str = "\n", pd_chunk: int = 0) -> None:
        self.eol = eol
        self.pd_chunk = pd_chunk  # points per PD command; 0 = whole contour in one PD
        self.lines: list[str] = ["IN;SP1;"]
        self.n_points = 0

    def raw(self, text: str) -> None:
        self.lines.append(text)

    def contour(self, pts: Contour) -> None:
        """PU to the first point, PD through the rest (a closed contour repeats pt 0)."""
        if len(pts) < 2:
            return
        x0, y0 = pts[0]
        self.lines.append(f"PU{x0},{y0};")
        rest = pts[1:]
        chunk = self.pd_chunk or len(rest)
        for i in range(0, len(rest), chunk):
            part = rest[i : i + chunk]
            self.lines.append("PD" + ",".join(f"{x},{y}" for x, y in part) + ";")
        self.n_points += len(pts)

    def data(self) -> bytes:
        return (self.eol.join([*self.lines, "PU;SP0;"]) + self.eol).encode("ascii")


def save(name: str, data: bytes, n_points: int | None = None) -> None:
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    path = OUT_DIR / name
    path.write_bytes(data)
    extra = f", {n_points} points" if n_points is not None else ""
    print(f"{path.relative_to(HERE.parent)}: {len(data)} bytes{extra}")


# --------------------------------------------------------------------------------------
# geometry helpers
# --------------------------------------------------------------------------------------


#: decimals written for coordinates: 0 = whole plotter units (CorelDRAW/AutoCAD style);
#: the seal and the 1181-point curve use decimals (pstoedit/Inkscape style), so that a fit
#: with the paper's e_per = 0.02 units is possible (rounding stays well below e_per).
DECIMALS = 0


def round_contour(pts: list[tuple[float, float]], close: bool = True) -> Contour:
    """Round to DECIMALS, drop repeated points, close the contour."""
    out: Contour = []
    for x, y in pts:
        p = (round(x, DECIMALS), round(y, DECIMALS)) if DECIMALS else (int(round(x)), int(round(y)))
        if not out or out[-1] != p:
            out.append(p)
    if close and out and out[-1] != out[0]:
        out.append(out[0])
    return out


def circle(
    cx: float, cy: float, r: float, spacing: float, start_deg: float = 0.0, ccw: bool = True
) -> Contour:
    n = max(8, math.ceil(2 * math.pi * r / spacing))
    sgn = 1 if ccw else -1
    a0 = math.radians(start_deg)
    pts = [
        (
            cx + r * math.cos(a0 + sgn * 2 * math.pi * i / n),
            cy + r * math.sin(a0 + sgn * 2 * math.pi * i / n),
        )
        for i in range(n)
    ]
    return round_contour(pts)


def rect(x0: float, y0: float, x1: float, y1: float, ccw: bool = True) -> Contour:
    pts = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    if not ccw:
        pts = pts[::-1]
    return round_contour(pts)


def star(cx: float, cy: float, r_out: float, r_in: float, n: int = 5) -> Contour:
    pts = []
    for i in range(2 * n):
        r = r_out if i % 2 == 0 else r_in
        a = math.pi / 2 + i * math.pi / n
        pts.append((cx + r * math.cos(a), cy + r * math.sin(a)))
    return round_contour(pts)


def cubic(p0, p1, p2, p3, step: float) -> list[tuple[float, float]]:
    """Sample a cubic Bezier at uniform t (excluding p0) with chords about ``step`` long.

    Uniform t gives the uneven point spacing typical of CAD exports."""
    poly_len = math.dist(p0, p1) + math.dist(p1, p2) + math.dist(p2, p3)
    chord = math.dist(p0, p3)
    approx = 0.5 * (poly_len + chord)
    n = max(2, math.ceil(approx / step))
    out = []
    for i in range(1, n + 1):
        t = i / n
        u = 1 - t
        a, b, c, d = u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t
        out.append(
            (
                a * p0[0] + b * p1[0] + c * p2[0] + d * p3[0],
                a * p0[1] + b * p1[1] + c * p2[1] + d * p3[1],
            )
        )
    return out


# --------------------------------------------------------------------------------------
# glyph outlines through Qt
# --------------------------------------------------------------------------------------

_APP = None
_FAMILIES: dict[Path, str] = {}


def font(size_px: float, path: Path = FONT_FILE) -> QFont:
    global _APP
    if _APP is None:
        _APP = QGuiApplication.instance() or QGuiApplication([sys.argv[0]])
    if path not in _FAMILIES:
        fid = QFontDatabase.addApplicationFont(str(path)) if path.exists() else -1
        fams = QFontDatabase.applicationFontFamilies(fid) if fid >= 0 else []
        _FAMILIES[path] = fams[0] if fams else "DejaVu Sans"
    f = QFont(_FAMILIES[path])
    f.setPixelSize(int(size_px))
    if path == FONT_FILE_BOLD:
        f.setBold(True)
    f.setHintingPreference(QFont.HintingPreference.PreferNoHinting)
    f.setKerning(True)
    return f


def text_path(text: str, f: QFont) -> QPainterPath:
    p = QPainterPath()
    p.addText(QPointF(0, 0), f, text)
    return p


def path_contours(path: QPainterPath, tf: QTransform, step: float) -> list[Contour]:
    """Flatten ``path`` (after the affine ``tf``) into closed integer contours.

    Straight segments keep only their end points (as CAD programs write them);
    curves are sampled so consecutive points are about ``step`` units apart."""
    ET = QPainterPath.ElementType
    contours: list[Contour] = []
    cur: list[tuple[float, float]] = []
    n = path.elementCount()
    i = 0

    def mapped(k: int) -> tuple[float, float]:
        e = path.elementAt(k)
        q = tf.map(QPointF(e.x, e.y))
        return (q.x(), q.y())

    while i < n:
        e = path.elementAt(i)
        if e.type == ET.MoveToElement:
            if len(cur) > 2:
                contours.append(round_contour(cur))
            cur = [mapped(i)]
            i += 1
        elif e.type == ET.LineToElement:
            cur.append(mapped(i))
            i += 1
        elif e.type == ET.CurveToElement:
            c1, c2, end = mapped(i), mapped(i + 1), mapped(i + 2)
            cur.extend(cubic(cur[-1], c1, c2, end, step))
            i += 3
        else:  # stray CurveToDataElement
            i += 1
    if len(cur) > 2:
        contours.append(round_contour(cur))
    return [c for c in contours if len(c) >= 4]


def text_contours(
    text: str, x: float, y: float, height: float, step: float, path: Path = FONT_FILE
) -> tuple[list[Contour], float]:
    """Glyph outlines of ``text`` with baseline at (x, y), cap height ``height`` units.

    Returns the contours and the text's advance width in plotter units."""
    f = font(200, path)
    fm = QFontMetricsF(f)
    s = height / fm.capHeight()
    tf = QTransform(s, 0, 0, -s, x, y)  # Qt y grows downwards, HP-GL y upwards
    return path_contours(text_path(text, f), tf, step), fm.horizontalAdvance(text) * s


def arc_text_contours(
    text: str,
    cx: float,
    cy: float,
    r_base: float,
    height: float,
    mid_deg: float,
    step: float,
    letter_gap: float = 0.0,
    path: Path = FONT_FILE,
) -> list[Contour]:
    """Characters of ``text`` on a circle, read clockwise, centred on angle ``mid_deg``,
    upright towards the outside (like the text round a seal)."""
    f = font(200, path)
    fm = QFontMetricsF(f)
    s = height / fm.capHeight()
    adv = [fm.horizontalAdvance(ch) * s + letter_gap for ch in text]
    total = sum(adv) - letter_gap
    theta = math.radians(mid_deg) + total / (2 * r_base)  # start at the left end
    out: list[Contour] = []
    for ch, w in zip(text, adv, strict=True):
        w_ch = w - letter_gap
        a = theta - (w_ch / 2) / r_base  # angle of the character's centre
        theta -= w / r_base
        if ch.isspace():
            continue
        # glyph: centre horizontally, flip y, scale; then rotate so "up" is radial
        rot = a - math.pi / 2
        cr, sr = math.cos(rot), math.sin(rot)
        ox, oy = cx + r_base * math.cos(a), cy + r_base * math.sin(a)
        # local (u, v) -> u*s - w_ch/2 horizontally, -v*s vertically, then rotate
        # QTransform(m11, m12, m21, m22, dx, dy): x' = m11*x + m21*y + dx
        m11, m12 = s * cr, s * sr
        m21, m22 = s * sr, -s * cr
        dx = ox - (w_ch / 2) * cr
        dy = oy - (w_ch / 2) * sr
        tf = QTransform(m11, m12, m21, m22, dx, dy)
        out.extend(path_contours(text_path(ch, f), tf, step))
    return out


def shift(contours: list[Contour], dx: int, dy: int) -> list[Contour]:
    return [[(x + dx, y + dy) for x, y in c] for c in contours]


def bbox(contours: list[Contour]) -> tuple[int, int, int, int]:
    xs = [x for c in contours for x, _ in c]
    ys = [y for c in contours for _, y in c]
    return min(xs), min(ys), max(xs), max(ys)


# --------------------------------------------------------------------------------------
# 1. text_outline.plt
# --------------------------------------------------------------------------------------


def make_text_outline() -> None:
    # "GALVO 2026" about 60 mm wide, "Laser" below it; curves sampled ~2 units apart
    line1, w1 = text_contours("GALVO 2026", 0, 0, 1.0, 1.0)
    cap = 2400 / w1  # cap height giving 2400 units (60 mm) of advance
    line1, w1 = text_contours("GALVO 2026", 0, 0, cap, 2.0)
    line2, w2 = text_contours("Laser", 0, 0, cap, 2.0)
    line2 = shift(line2, int(round((w1 - w2) / 2)), -int(round(cap * 1.6)))
    contours = shift(line1 + line2, 400, 400 + int(round(cap * 1.6)))
    w = PltWriter(eol="\r\n", pd_chunk=1)
    for c in contours:
        w.contour(c)
    save("text_outline.plt", w.data(), w.n_points)


# --------------------------------------------------------------------------------------
# 2. seal.plt
# --------------------------------------------------------------------------------------


def make_seal() -> None:
    global DECIMALS
    DECIMALS = 2
    try:
        _make_seal()
    finally:
        DECIMALS = 0


def _make_seal() -> None:
    cx, cy = 1000, 1000
    contours: list[Contour] = []
    # outer ring: two concentric circles -> the ring region has a hole (~1.2 unit chords)
    contours.append(circle(cx, cy, 800, 1.2, start_deg=-90))
    contours.append(circle(cx, cy, 740, 1.2, start_deg=-90, ccw=False))
    # text round the top of the ring, read clockwise, upright outwards
    contours += arc_text_contours(
        "GALVO LASER WORKSTATION",
        cx,
        cy,
        590,
        95,
        mid_deg=90,
        step=1.0,
        letter_gap=4,
        path=FONT_FILE_BOLD,
    )
    # five-pointed star in the centre (straight edges: 11 points)
    contours.append(star(cx, cy, 270, 270 * 0.382))
    # rectangular frame with a rectangular hole at the bottom, a label in the hole
    contours.append(rect(cx - 260, cy - 570, cx + 260, cy - 390))
    contours.append(rect(cx - 235, cy - 545, cx + 235, cy - 415, ccw=False))
    label, lw = text_contours("No. 2026", 0, 0, 60, 1.0)
    contours += shift(label, int(round(cx - lw / 2)), cy - 510)
    w = PltWriter(eol="\n", pd_chunk=16)
    for c in contours:
        w.contour(c)
    save("seal.plt", w.data(), w.n_points)


# --------------------------------------------------------------------------------------
# 3. arcs_circles.plt
# --------------------------------------------------------------------------------------


def make_arcs_circles() -> None:
    L: list[str] = ["IN;SP1;", "PA;"]
    # --- row 1: CI circles (CI draws round the current pen position; pen comes back)
    L += [
        "PU500,3300;CI300;",  # circle r=300, default chord angle (5 degrees)
        "PU1300,3300;CI300,2;",  # same circle, fine chord angle 2 degrees
        "PU2100,3300;CI300,30;",  # chord angle 30 degrees -> a visible 12-gon
        "CI150;",  # concentric smaller circle, same centre (pen did not move)
        "PU2900,3300;CI300,45;CI200,1;",  # octagon (45 deg chords) round a fine circle
    ]
    # --- row 2: AA absolute arcs (centre x,y, sweep degrees, optional chord angle)
    L += [
        "PU800,2500;PD;AA500,2500,270;PU;",  # 3/4 arc CCW from angle 0, default chord
        "PU1600,2500;PD;AA1300,2500,-270,1;PU;",  # negative sweep: clockwise, 1 deg
        "PU2100,2800;PD;AA2100,2500,180,10;PD2100,2800;PU;",  # half disc, 10 deg chords
        # an S-curve: two half arcs in opposite senses joined, pen stays down
        "PU2750,2200;PD;AA2750,2350,180,2;AA2750,2650,-180,2;PU;",
    ]
    # --- row 3: AR relative arcs and AT three-point arcs
    L += [
        # rounded slot: line, relative-centre half arc, line, half arc back
        "PU300,1500;PD700,1500;AR0,150,180,2;PD300,1800;AR0,-150,180,2;PU;",
        # AT: arc through an intermediate point to an end point (3-point arc)
        "PU1000,1500;PD;AT1250,1850,1500,1500;PU;",  # default chord
        "PU1600,1500;PD;AT1800,1700,2000,1500,1;PD1600,1500;PU;",  # closed segment
        # AT with collinear points degenerates to a straight line
        "PU2200,1500;PD;AT2400,1600,2600,1700;PU;",
        # a "pill": two relative arcs with a PD between them
        "PU2900,1450;PD3200,1450;AR0,150,180,3;PD2900,1750;AR0,-150,180,3;PU;",
    ]
    # --- row 4: rectangles; EA/ER draw the edge, RA/RR are filled (HP-GL/2 fill)
    L += [
        "PU200,800;EA700,1200;",  # edge rectangle absolute, corner to corner
        "PU900,800;ER500,400;",  # edge rectangle relative
        "PU1550,800;RA1950,1200;",  # fill rectangle absolute
        "PU2100,800;RR400,400;",  # fill rectangle relative
        "PU2650,800;ER500,400;PU2750,900;ER300,200;",  # rectangle with rectangular hole
    ]
    # --- row 5: PR relative moves and Bezier curves
    L += [
        # a square and a zigzag in relative coordinates, then back to absolute
        "PU200,150;PR;PD400,0,0,400,-400,0,0,-400;PU500,0;PD40,80,40,-80,40,80,40,-80,"
        "40,80,40,-80,40,80,40,-80;PA;PU;",
        # BZ: absolute cubic Beziers (3 points each) continuing from the pen position
        "PU1500,150;PD;BZ1500,550,1900,550,1900,150,1900,-50,2300,-50,2300,150;PU;",
        # BR: relative cubic Beziers, a closed leaf shape
        "PU2500,150;PD;BR100,400,500,400,600,0,-100,-400,-500,-400,-600,0;PU;",
        # plain absolute polyline with float coordinates for good measure
        "PU3300,150.5;PD3500.25,150.5,3400.125,450.75,3300,150.5;PU;",
    ]
    L.append("PU;SP0;")
    data = ("\n".join(L) + "\n").encode("ascii")
    save("arcs_circles.plt", data)


# --------------------------------------------------------------------------------------
# 4. curve_1181.plt
# --------------------------------------------------------------------------------------


def make_curve_1181() -> None:
    """A heart made of two circular lobes and two straight flanks meeting at a sharp
    tip, with a sharp notch between the lobes: smooth curves, straight runs and real
    corners in one closed contour of exactly 1181 points (the paper's Table 1 count),
    sampled unevenly 1-3 units apart like a CAD/traced export."""
    N = 1181
    R = 225.0  # lobe radius (perimeter ~2360 units -> mean spacing 2 units)
    cx1, cx2, cyl = -R * 0.72, R * 0.72, 0.0  # lobe centres
    tip = (0.0, -2.25 * R)

    # angle (seen from a lobe centre) of the tangent point of a line from the tip
    def tangent_angle(cxl: float, side: int) -> float:
        dx, dy = cxl - tip[0], cyl - tip[1]
        d = math.hypot(dx, dy)
        base = math.atan2(-dy, -dx)  # direction centre -> tip
        off = math.acos(R / d)
        return base + side * off

    # right lobe: from the notch, clockwise over the top down to the tangent point
    notch_a2 = math.pi - math.acos(cx2 / R)  # angle of the notch seen from centre 2
    t2 = tangent_angle(cx2, +1)
    notch_a1 = math.acos(cx2 / R)  # symmetric on the left lobe
    t1 = tangent_angle(cx1, -1)

    fine: list[tuple[float, float]] = []
    corners: list[int] = []

    def arc(cxa, a0, a1):
        n = 4000
        for i in range(n):
            a = a0 + (a1 - a0) * i / n
            fine.append((cxa + R * math.cos(a), cyl + R * math.sin(a)))

    def line(p, q):
        n = 2000
        for i in range(n):
            fine.append((p[0] + (q[0] - p[0]) * i / n, p[1] + (q[1] - p[1]) * i / n))

    # clockwise: notch -> right lobe -> right flank -> tip -> left flank -> left lobe
    corners.append(len(fine))
    a_end2 = t2 if t2 < notch_a2 else t2 - 2 * math.pi
    arc(cx2, notch_a2, a_end2)
    p_t2 = (cx2 + R * math.cos(t2), cyl + R * math.sin(t2))
    p_t1 = (cx1 + R * math.cos(t1), cyl + R * math.sin(t1))
    line(p_t2, tip)
    corners.append(len(fine))
    line(tip, p_t1)
    a_start1 = t1
    a_end1 = notch_a1
    if a_end1 > a_start1:
        a_end1 -= 2 * math.pi
    arc(cx1, a_start1, a_end1)
    fine.append(fine[0])
    F = np.asarray(fine)
    seg = np.hypot(*np.diff(F, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    total = s[-1]

    # uneven spacing: random increments of 1.2-2.8 units -> N-1 intervals; try seeds
    # in order until no two consecutive points round onto the same integer point
    for seed in range(1181, 1181 + 100):
        rng = np.random.default_rng(seed)
        inc = rng.uniform(0.6, 1.4, N - 1)
        inc *= total / inc.sum()
        targets = np.concatenate([[0.0], np.cumsum(inc)])[:-1]
        # snap the nearest sample to each corner so corners are real points
        for k in corners:
            j = int(np.argmin(np.abs(targets - s[k])))
            targets[j] = s[k]
        targets.sort()
        xs = np.interp(targets, s, F[:, 0])
        ys = np.interp(targets, s, F[:, 1])
        pts = [(round(x + 1000, 3), round(y + 1000, 3)) for x, y in zip(xs, ys, strict=True)]
        if all(a != b for a, b in zip(pts, pts[1:] + pts[:1], strict=True)):
            break
    else:
        raise RuntimeError("no seed gave distinct consecutive points")
    contour = pts + [pts[0]]
    assert len(contour) == N, len(contour)
    w = PltWriter(eol="\n", pd_chunk=8)
    w.contour(contour)
    save("curve_1181.plt", w.data(), w.n_points)


# --------------------------------------------------------------------------------------
# 5. dense_logo.plt
# --------------------------------------------------------------------------------------


def make_dense_logo() -> None:
    """~40k points in a 100 x 72 mm field: bold title, two lines of text, a rounded
    frame with a rounded hole, three rose curves (with cusps) round circles, ribbons."""
    K = 0.78  # overall scale (the design numbers below are for a 128 mm wide logo)

    def k(v: float) -> float:
        return K * v

    contours: list[Contour] = []
    # big title and text lines, dense curve sampling (0.6-0.8 units)
    title, tw = text_contours("GALVO", 0, 0, k(900), 0.8, path=FONT_FILE_BOLD)
    contours += shift(title, 0, int(k(2300)))
    sub, sw = text_contours("Workstation 2026", 0, 0, k(330), 0.7)
    contours += shift(sub, int(round((tw - sw) / 2)), int(k(1700)))
    small, smw = text_contours(
        "PLT / HP-GL sample - dense outlines for speed tests", 0, 0, k(90), 0.5
    )
    contours += shift(small, int(round((tw - smw) / 2)), int(k(1450)))
    x0, y0, x1, y1 = bbox(contours)
    # frame with rounded corners around the text, and an inner one -> a hole
    for inset, ccw in ((0.0, True), (k(60), False)):
        r = k(200) - inset
        ax0, ay0 = x0 - k(300) + inset, y0 - k(1500) + inset
        ax1, ay1 = x1 + k(300) - inset, y1 + k(300) - inset
        pts: list[tuple[float, float]] = []
        for ccx, ccy, a0 in (
            (ax1 - r, ay0 + r, -90),
            (ax1 - r, ay1 - r, 0),
            (ax0 + r, ay1 - r, 90),
            (ax0 + r, ay0 + r, 180),
        ):
            n = max(8, math.ceil(0.5 * math.pi * r / 0.8))
            for i in range(n + 1):
                a = math.radians(a0 + 90 * i / n)
                pts.append((ccx + r * math.cos(a), ccy + r * math.sin(a)))
        c = round_contour(pts)
        contours.append(c if ccw else c[::-1])
    # decorative curves along the bottom band: rose curves round circles
    band_y = y0 - k(800)
    for i_r, (petals, cxr) in enumerate(((5, x0 + k(400)), (7, (x0 + x1) / 2), (4, x1 - k(400)))):
        rr = k(430)
        n = 9000
        pts = []
        for i in range(n):
            t = 2 * math.pi * i / n
            rad = rr * (0.35 + 0.65 * abs(math.cos(petals * t / 2)))
            pts.append((cxr + rad * math.cos(t), band_y + rad * math.sin(t)))
        contours.append(round_contour(pts))
        contours.append(circle(cxr, band_y, k(90 + 20 * i_r), 0.6))
    # sine ribbons between the roses (two offset sines joined at the ends)
    for xa, xb in ((x0 + k(900), (x0 + x1) / 2 - k(500)), ((x0 + x1) / 2 + k(500), x1 - k(900))):
        n = int((xb - xa) / 0.8)
        top = [
            (xa + (xb - xa) * i / n, band_y + k(60) + k(90) * math.sin(6 * math.pi * i / n))
            for i in range(n + 1)
        ]
        bot = [(x, y - k(120)) for x, y in top[::-1]]
        contours.append(round_contour(top + bot))
    # shift everything into positive coordinates
    bx0, by0, _, _ = bbox(contours)
    contours = shift(contours, 200 - bx0, 200 - by0)
    w = PltWriter(eol="\n", pd_chunk=0)
    for c in contours:
        w.contour(c)
    save("dense_logo.plt", w.data(), w.n_points)


def main() -> None:
    make_text_outline()
    make_seal()
    make_arcs_circles()
    make_curve_1181()
    make_dense_logo()


if __name__ == "__main__":
    main()
