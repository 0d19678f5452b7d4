"""The two plot views: one pyqtgraph item per layer, never one per path.

Both views are in *workpiece millimetres of the galvo field* (bit ``X`` at
``X * mm_per_bit`` mm; the field is the square 0 .. field_size_mm), so the original drawing
(at the current magnification) and the processed result line up point for point.

The arrays come from :mod:`galvo_core.preview` in their native space (input units or galvo
bits); each item gets the affine map to mm as its QTransform. A run that only changed the
magnification therefore changes transforms, not data: no geometry is computed here.

Layers (key: what, view):

``original``          the file's polylines (left)
``original_points``   the file's points, small orange dots (left)
``fitted``            fitted lines and cubics (right)
``control``           control points: anchors (blue squares), inner control points (hollow
                      blue circles) and their handle lines (right)
``marks``             marking points, red dots (right)
``jumps``             laser-off moves, dashed grey (right)
``hatch``             fill lines (right)
``kerf``              the kerf-compensated outline (right)
``deviation``         the fitted curve coloured by its true error to the original points,
                      with a colour bar in µm (right)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pyqtgraph as pg
from numba import njit
from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QImage, QPainterPath, QPen, QPixmapCache, QTransform
from PySide6.QtWidgets import QGraphicsItem

# --- palette (light background, dark ink: legible on screen and in print) -------------
BACKGROUND = "#ffffff"
FOREGROUND = "#2b2b2b"
GRID_ALPHA = 0.10
ORIGINAL_LINE = "#4a5a6e"  # slate
ORIGINAL_POINT = "#e67e00"  # orange
FITTED_LINE = "#0b7a55"  # green-teal
CONTROL = "#1f5fbf"  # blue
MARK = "#d7191c"  # red
JUMP = "#7a7a7a"  # grey, dashed
HATCH = "#8e44ad"  # purple
KERF = "#e6007e"  # magenta
FIELD = "#9aa5b1"
SELECTION = "#ffc400"  # amber underlay
TITLE_SIZE = "11pt"

#: Deviation colours, from "well inside the tolerance" to "at the tolerance": pale yellow to
#: dark brown, a hue none of the other layers uses (the marks are red, the fitted curve
#: green, control points blue, hatch purple, kerf magenta).
DEVIATION_STOPS = ("#f3e08a", "#eab84a", "#c98a1c", "#8c510a", "#3d2300")
DEVIATION_BINS = 16

#: Point markers of the original drawing are drawn only below this many points.
MAX_MARKER_POINTS = 200_000
#: Lines and markers are antialiased only below this many vertices: the software rasteriser
#: spends most of a frame antialiasing big layers (bench/bench_gui.py).
MAX_ANTIALIAS_POINTS = 20_000

#: Layers that a change of the mark points (chord tolerance, magnification, ...) redraws
#: every time; every other layer and the axes (with their grid) are kept as device pixmaps
#: (QGraphicsItem.DeviceCoordinateCache): a repaint that did not change them only copies
#: the pixmap instead of rasterising 100,000 vertices again in software.
UNCACHED_LAYERS = frozenset({"marks", "jumps"})
#: QPixmapCache size (KiB) so that the cached layers of both views fit (the default 10 MiB
#: holds about two full-window layers; an evicted pixmap is simply drawn again).
PIXMAP_CACHE_KB = 256 * 1024

#: Smallest span a fit zooms to, in mm.
MIN_FIT_SPAN_MM = 0.5


@dataclass(frozen=True)
class LayerSpec:
    key: str
    label: str
    view: str  # "original" or "processed"
    default_on: bool
    tip: str


LAYERS: tuple[LayerSpec, ...] = (
    LayerSpec("original", "Original path", "original", True,
              "the file's pen-down paths as written (left view)"),
    LayerSpec("original_points", "Original points", "original", True,
              "every point the file gives: orange dots (left view)"),
    LayerSpec("fitted", "Fitted curve", "processed", True,
              "lines and cubic Béziers of the fit (right view)"),
    LayerSpec("control", "Control points", "processed", True,
              "segment ends (blue squares), Bézier handles (hollow circles) and handle lines"),
    LayerSpec("marks", "Marks", "processed", True,
              "mark points: the galvo positions the laser is sent to (red dots)"),
    LayerSpec("jumps", "Jumps", "processed", True, "laser-off moves between strokes (dashed)"),
    LayerSpec("hatch", "Hatch", "processed", True, "fill lines (when a fill is chosen)"),
    LayerSpec("kerf", "Kerf", "processed", True,
              "the kerf-compensated outline the laser follows (when a kerf width is set)"),
    LayerSpec("deviation", "Deviation", "processed", False,
              "the fitted curve coloured by its true distance to the original points (µm)"),
)
LAYER_KEYS = tuple(spec.key for spec in LAYERS)


def deviation_colormap() -> pg.ColorMap:
    return pg.ColorMap(np.linspace(0.0, 1.0, len(DEVIATION_STOPS)),
                       [pg.mkColor(c) for c in DEVIATION_STOPS])


def _pen(colour: str, width: float = 1.0, alpha: int = 255, style=Qt.PenStyle.SolidLine) -> QPen:
    c = pg.mkColor(colour)
    c.setAlpha(alpha)
    pen = pg.mkPen(c, width=width, style=style)
    pen.setCosmetic(True)
    return pen


def _brush(colour: str, alpha: int = 255):
    c = pg.mkColor(colour)
    c.setAlpha(alpha)
    return pg.mkBrush(c)


def _rect_data_bounds(self, ax, frac=1.0, orthoRange=None):  # noqa: N803 - pyqtgraph API
    """pyqtgraph's ``dataBounds`` for items that keep their data rectangle in ``_rect``."""
    if self._rect.isNull():
        return None, None
    if ax == 0:
        return self._rect.left(), self._rect.right()
    return self._rect.top(), self._rect.bottom()


class DeviationItem(pg.GraphicsObject):
    """Chords coloured by a level in 0..1: ONE item, one QPainterPath per colour bin."""

    def __init__(self, width: float = 3.2) -> None:
        super().__init__()
        self._paths: list[tuple[QPen, QPainterPath]] = []
        self._rect = QRectF()
        self._width = width
        cmap = deviation_colormap()
        self._pens = []
        for i in range(DEVIATION_BINS):
            colour = cmap.map((i + 0.5) / DEVIATION_BINS, mode="qcolor")
            pen = QPen(colour, width)
            pen.setCosmetic(True)
            pen.setCapStyle(Qt.PenCapStyle.FlatCap)
            self._pens.append(pen)
        self.n_chords = 0
        self._coarse: list | None = None
        #: what the last paint drew: "full" or "coarse" (tests, benchmark)
        self.last_drawn = ""

    @staticmethod
    def prepare(a: np.ndarray, b: np.ndarray, level: np.ndarray,
                lod: float | None = None) -> tuple:
        """The paths per colour bin and the rectangle (any thread: no item touched). The
        chords of a bin that follow one another along the curve (each starting where the
        one before ended) are joined into polylines, one path per bin; with ``lod`` a big
        overlay also gets coarse levels (the polylines decimated on grids of ``lod`` times
        :data:`LOD_FACTORS`, see :func:`decimate`), drawn while a grid cell is at most
        half a device pixel."""
        if not len(level):
            return [], QRectF(), 0, None
        a = np.asarray(a, dtype=np.float64)
        b = np.asarray(b, dtype=np.float64)
        bins = np.minimum((np.asarray(level) * DEVIATION_BINS).astype(np.int64),
                          DEVIATION_BINS - 1)
        order = np.argsort(bins, kind="stable")
        sb = bins[order]
        cuts = np.flatnonzero(np.diff(sb)) + 1
        pieces = [(int(bins[idx[0]]), _chain_chords(a[idx], b[idx], idx))
                  for idx in np.split(order, cuts)]
        paths = [(k, _qpath(xy[:, 0], xy[:, 1]))
                 for k, xy in pieces]
        levels: list[tuple[float, list]] = []
        if lod is not None and lod > 0 and len(level) >= MAX_ANTIALIAS_POINTS:
            # like LinesItem: finest first, a level only where it saves 30 % of the rows
            prev = sum(len(xy) for _, xy in pieces)
            for f in LOD_FACTORS[::-1]:
                dec = [(k, decimate(xy, lod * f)) for k, xy in pieces]
                n = sum(len(c) for _, c in dec)
                if n < 0.7 * prev:
                    levels.append((float(lod * f), [
                        (k, _qpath(c[:, 0], c[:, 1]))
                        for k, c in dec]))
                    prev = n
        # compiled passes (numpy's axis-0 min/max over 380 k chords took 20-40 ms)
        ra, rb = _finite_rect(a), _finite_rect(b)
        return (paths, ra.united(rb) if not ra.isNull() else rb, len(level),
                levels[::-1] or None)

    def setPrepared(self, prepared: tuple) -> None:  # noqa: N802
        paths, rect, n, coarse = prepared
        self.prepareGeometryChange()
        self._paths = [(self._pens[k], path) for k, path in paths]
        self._coarse = [(g, [(self._pens[k], path) for k, path in lv]) for g, lv in coarse] \
            if coarse else None
        self._rect = rect
        self.n_chords = n
        self.update()

    def setData(self, a: np.ndarray, b: np.ndarray, level: np.ndarray) -> None:  # noqa: N802
        self.setPrepared(self.prepare(a, b, level))

    def boundingRect(self) -> QRectF:  # noqa: N802 - Qt API
        return self._rect

    dataBounds = _rect_data_bounds  # noqa: N815 - pyqtgraph API

    def paint(self, p, *args) -> None:
        small = self.n_chords < MAX_ANTIALIAS_POINTS
        p.setRenderHint(p.RenderHint.Antialiasing, small)
        paths = self._paths
        self.last_drawn = "full"
        level = _pick_level(getattr(self, "_coarse", None), p)
        if level is not None:
            paths = level[1]
            self.last_drawn = "coarse"
        if small:
            for pen, path in paths:
                p.setPen(pen)
                p.drawPath(path)
            return
        # a big overlay: the raster engine strokes a wide pen as polygons (10x the time of
        # a 1-pixel line): a 2-pixel look from two 1-pixel passes one device pixel apart
        t = p.transform()
        thin = [(QPen(pen), path) for pen, path in paths]
        for pen, _ in thin:
            pen.setWidthF(1.0)
        for d in (0.0, 1.0):
            p.setTransform(t * QTransform.fromTranslate(d, d))
            for pen, path in thin:
                p.setPen(pen)
                p.drawPath(path)
        p.setTransform(t)


def _chain_chords(a: np.ndarray, b: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Chords ``a[j] -> b[j]`` (in their order; ``idx`` their rows in the whole overlay) as
    NaN-separated polylines: a chord that starts where the one before it ended (the next
    row of the overlay) continues its polyline, any other starts a new one."""
    n = len(idx)
    start = np.ones(n, dtype=bool)
    if n > 1:
        start[1:] = (np.diff(idx) != 1) | (a[1:] != b[:-1]).any(axis=1)
    piece = np.cumsum(start)  # 1-based piece of each chord
    brow = np.arange(n) + 2 * piece - 1  # rows: NaN (not before the first), a, b, b, ...
    xy = np.full((n + 2 * int(piece[-1]) - 1, 2), np.nan)
    xy[brow] = b
    xy[brow[start] - 1] = a[start]
    return xy


#: Rows per call when a big QPainterPath is built (see :func:`_qpath`).
QPATH_CHUNK = 50_000


def _qpath(x: np.ndarray, y: np.ndarray) -> QPainterPath:
    """NaN-separated polylines as a QPainterPath (pyqtgraph's arrayToQPath, connect
    "finite"), built in pieces of :data:`QPATH_CHUNK` rows: one call holds the interpreter
    lock for its whole run (0.2-0.3 s for a million rows, the GUI thread frozen meanwhile
    when a worker builds it); pieces of 50,000 rows hold it about 10 ms each. Each piece
    starts with the last row of the one before, so no edge is lost."""
    n = len(x)
    if n <= QPATH_CHUNK:
        return pg.arrayToQPath(x, y, connect="finite")
    out = QPainterPath()
    for i in range(0, n, QPATH_CHUNK):
        lo = max(i - 1, 0)
        out.addPath(pg.arrayToQPath(x[lo:i + QPATH_CHUNK], y[lo:i + QPATH_CHUNK],
                                    connect="finite"))
    return out


def _polygon(xy: np.ndarray):
    """(N, 2) finite points -> QPolygonF (filled through a numpy view, no Python loop)."""
    import pyqtgraph.functions as fn

    poly = fn.create_qpolygonf(len(xy))
    if len(xy):
        fn.ndarray_from_qpolygonf(poly)[:] = xy
    return poly


def _small_polygon(xy: np.ndarray):
    """The QPolygonF of a marker set that :func:`draw_points` draws as points (a small
    one); None for a large one (rasterised from the array, no polygon needed)."""
    return _polygon(xy) if len(xy) < MAX_ANTIALIAS_POINTS else None


def _finite_rect(xy: np.ndarray) -> QRectF:
    """The bounding rectangle of the finite rows of ``xy`` (one compiled pass without the
    interpreter lock: numpy's axis-0 min/max took 7 ms on 170 k rows)."""
    from galvo_core.preview import bbox

    box = bbox(xy) if len(xy) else None
    if box is None:
        return QRectF()
    return QRectF(QPointF(box[0], box[1]), QPointF(box[2], box[3]))


def _footprint(width: float, square: bool, frac: float) -> tuple[np.ndarray, np.ndarray]:
    """Pixel offsets (dx, dy) covered by a marker of ``width`` pixels centred at
    ``k + frac`` (k an integer; pixel i covers [i, i + 1], its centre at i + 0.5): a disk
    (round cap) or a square (square cap), as the raster engine draws a wide point without
    antialiasing. At least the centre pixel."""
    r = width / 2.0
    n = int(math.ceil(r)) + 1
    o = np.arange(-n, n + 1)
    dx, dy = np.meshgrid(o, o)
    cx = dx + 0.5 - frac
    cy = dy + 0.5 - frac
    if square:
        inside = (np.abs(cx) <= r) & (np.abs(cy) <= r)
    else:
        inside = cx * cx + cy * cy <= r * r
    if not inside.any():
        inside = (np.abs(cx) <= 0.5) & (np.abs(cy) <= 0.5)
    return dx[inside].ravel(), dy[inside].ravel()


def _premultiplied(colour: QColor) -> np.uint32:
    a = colour.alpha()
    r, g, b = (c * a // 255 for c in (colour.red(), colour.green(), colour.blue()))
    return np.uint32((a << 24) | (r << 16) | (g << 8) | b)


def draw_points(p, xy: np.ndarray, poly, pen: QPen, grid: float = 2.0,
                cache: dict | None = None, small: bool | None = None) -> None:
    """Draw markers at ``xy`` (item coordinates) with ``pen``. Small sets: antialiased, as
    they are. Large sets: culled to the device and thinned to one marker per ``grid``
    device pixels (what the eye can tell apart anyway), then rasterised here: each marker's
    footprint (the pen's disk or square, no antialiasing) is written into one ARGB image
    with numpy and the image is drawn once. The raster engine would stroke every wide point
    as a path; this keeps a 100,000-point layer at a few milliseconds."""
    if small is None:  # the caller may decide by its whole layer (a coarse level is small)
        small = len(xy) < MAX_ANTIALIAS_POINTS
    if small:
        p.setRenderHint(p.RenderHint.Antialiasing, True)
        p.setPen(pen)
        p.drawPoints(poly if poly is not None else _polygon(xy))
        return
    dev = p.device()
    if dev is None:  # pragma: no cover - painting always has a device
        return
    dpr = float(dev.devicePixelRatioF()) if hasattr(dev, "devicePixelRatioF") else 1.0
    w, h = int(math.ceil(dev.width() * dpr)), int(math.ceil(dev.height() * dpr))
    if w <= 0 or h <= 0:
        return
    t = p.transform()
    key = (id(xy), len(xy), t.m11(), t.m12(), t.m21(), t.m22(), t.dx(), t.dy(), w, h, dpr,
           pen.widthF(), pen.color().rgba(), grid)
    if cache is not None and cache.get("key") == key:  # the same picture again (a repaint)
        p.save()
        p.resetTransform()
        p.drawImage(QPointF(0.0, 0.0), cache["image"])
        p.restore()
        return
    dx = (xy[:, 0] * t.m11() + xy[:, 1] * t.m21() + t.dx()) * dpr
    dy = (xy[:, 0] * t.m12() + xy[:, 1] * t.m22() + t.dy()) * dpr
    g = max(1, int(round(grid * dpr)))
    width = max(pen.widthF(), 1.0) * dpr
    pad = int(math.ceil(width / 2.0 / g)) + 1  # cells off the device whose marker shows
    gw, gh = w // g + 1 + 2 * pad, h // g + 1 + 2 * pad
    with np.errstate(invalid="ignore"):
        ix = np.floor(dx / g)
        iy = np.floor(dy / g)
        keep = (ix >= -pad) & (ix < gw - pad) & (iy >= -pad) & (iy < gh - pad)
    occ = np.zeros((gh, gw), dtype=bool)  # one marker per grid cell
    occ[iy[keep].astype(np.int64) + pad, ix[keep].astype(np.int64) + pad] = True
    cy, cx = np.nonzero(occ)
    # cell centres (cell + 0.5) * g: all share one fractional part
    centre = 0.5 * g
    frac = centre - math.floor(centre)
    ox, oy = _footprint(width, pen.capStyle() == Qt.PenCapStyle.SquareCap, frac)
    bx = (cx - pad) * g + int(math.floor(centre))
    by = (cy - pad) * g + int(math.floor(centre))
    img = np.zeros((h, w), dtype=np.uint32)
    value = _premultiplied(pen.color())
    for ddx, ddy in zip(ox.tolist(), oy.tolist(), strict=True):
        px = bx + ddx
        py = by + ddy
        ok = (px >= 0) & (px < w) & (py >= 0) & (py < h)
        img[py[ok], px[ok]] = value
    qimg = QImage(img.data, w, h, 4 * w, QImage.Format.Format_ARGB32_Premultiplied)
    qimg.setDevicePixelRatio(dpr)
    if cache is not None:
        cache.update(key=key, image=qimg, buffer=img, data=xy)  # the buffer backs the image
    p.save()
    p.resetTransform()
    p.drawImage(QPointF(0.0, 0.0), qimg)
    p.restore()


class _FastItem(pg.GraphicsObject):
    """Base of the point layers: drawn with QPainter.drawPoints and cosmetic pens, so tens
    of thousands of markers cost milliseconds (pyqtgraph's scatter builds one object per
    spot)."""

    def __init__(self) -> None:
        super().__init__()
        self._rect = QRectF()
        self._pad = 0.0

    def boundingRect(self) -> QRectF:  # noqa: N802 - Qt API
        if self._rect.isNull():
            return QRectF()
        # markers have a size in pixels: pad by a few pixels in item coordinates
        px = self.pixelLength(pg.Point(1, 0)) or 0.0
        pad = 6.0 * px
        return self._rect.adjusted(-pad, -pad, pad, pad)

    dataBounds = _rect_data_bounds  # noqa: N815 - pyqtgraph API

    def setData(self, xy: np.ndarray) -> None:  # noqa: N802 - like pyqtgraph
        """Prepare (here, on the calling thread) and show; the worker calls ``prepare`` and
        the GUI thread only ``setPrepared``."""
        self.setPrepared(self.prepare(xy))  # type: ignore[attr-defined]

    def getData(self) -> tuple[np.ndarray, np.ndarray]:  # noqa: N802 - like pyqtgraph
        return self._xy[:, 0], self._xy[:, 1]  # type: ignore[attr-defined]


class PointsItem(_FastItem):
    """Round (or square) dots of a fixed pixel size at (N, 2) points: ONE item."""

    def __init__(self, colour: str, size: float, alpha: int = 235, square: bool = False) -> None:
        super().__init__()
        self.pen = _pen(colour, size, alpha)
        self.pen.setCapStyle(Qt.PenCapStyle.SquareCap if square else Qt.PenCapStyle.RoundCap)
        self._xy = np.empty((0, 2))
        self._poly = _polygon(self._xy)
        self._raster: dict = {}

    @staticmethod
    def prepare(xy: np.ndarray, lod: float | None = None) -> tuple:
        """Finite points, their polygon (small sets) and rectangle (any thread); with
        ``lod`` a big set also gets one point per grid cell at the coarse levels (drawn
        while a cell is at most half a pixel: the same markers on screen)."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        if not np.isfinite(xy).all():
            xy = xy[np.isfinite(xy).all(axis=1)]
        levels = None
        if lod is not None and lod > 0 and len(xy) >= MAX_ANTIALIAS_POINTS:
            levels = _levels_per_cell(xy, lod)
        return xy, _small_polygon(xy), _finite_rect(xy), levels

    def setPrepared(self, prepared: tuple) -> None:  # noqa: N802
        self.prepareGeometryChange()
        self._xy, self._poly, self._rect, self._levels = prepared
        self.update()

    def paint(self, p, *args) -> None:
        if len(self._xy):
            level = _pick_level(getattr(self, "_levels", None), p)
            xy = level[1] if level is not None else self._xy
            draw_points(p, xy, self._poly if level is None else None, self.pen,
                        cache=self._raster, small=len(self._xy) < MAX_ANTIALIAS_POINTS)


class ControlItem(_FastItem):
    """Control points: handle lines, anchors (filled squares), inner control points (hollow
    circles) — ONE item. Data: (xy, role) from galvo_core.preview.control_layer."""

    def __init__(self) -> None:
        super().__init__()
        self.line_pen = _pen(CONTROL, 1.0, alpha=170)
        self.anchor_pen = _pen(CONTROL, 5.5)
        self.anchor_pen.setCapStyle(Qt.PenCapStyle.SquareCap)
        self.knot_pen = _pen(CONTROL, 6.5)
        self.knot_pen.setCapStyle(Qt.PenCapStyle.RoundCap)
        self.hole_pen = _pen("#ffffff", 3.6)
        self.hole_pen.setCapStyle(Qt.PenCapStyle.RoundCap)
        self._lines = QPainterPath()
        self._xy_anchors = self._xy_knots = np.empty((0, 2))
        self._anchors = _polygon(self._xy_anchors)
        self._knots = _polygon(self._xy_knots)
        self._xy = np.empty((0, 2))
        self._role = np.empty(0, dtype=np.int8)
        self._coarse: tuple | None = None
        self.last_drawn = ""

    @staticmethod
    def prepare(xy: np.ndarray, role: np.ndarray, lod: float | None = None) -> tuple:
        """Handle lines as a path, anchors, knots and the rectangle (any thread). With
        ``lod`` a big layer also gets a coarse version for the whole-drawing view: handle
        lines shorter than ``lod`` left out (under half a pixel: the markers cover them)
        and one anchor and one knot per ``lod`` grid cell."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        role = np.asarray(role)
        handles = role[: len(xy)] != 1
        hx = xy.copy()
        hx[~handles] = np.nan
        lines = _qpath(hx[:, 0], hx[:, 1]) if len(xy) \
            else QPainterPath()
        anchors, knots = xy[role == 1], xy[role == 2]
        coarse = None
        if lod is not None and lod > 0 and len(xy) >= MAX_ANTIALIAS_POINTS:
            # rows are P0, P1, NaN, P2, P3, NaN, ... then the anchors: pairs start where a
            # handle row follows a NaN (or the start) and is followed by a handle row
            h = handles & np.isfinite(xy[:, 0])
            start = np.flatnonzero(h[:-1] & h[1:])
            d = np.hypot(*(xy[start + 1] - xy[start]).T)
            coarse = []
            for f in LOD_FACTORS:
                g = lod * f
                long_ = start[d >= g]
                if len(long_):
                    px = np.full((3 * len(long_), 2), np.nan)
                    px[0::3], px[1::3] = xy[long_], xy[long_ + 1]
                    c_lines = _qpath(px[:-1, 0], px[:-1, 1])
                else:
                    c_lines = QPainterPath()
                coarse.append((float(g), c_lines, _one_per_cell(anchors, g),
                               _one_per_cell(knots, g)))
        return (xy, role, lines, anchors, knots, _small_polygon(anchors), _small_polygon(knots),
                _finite_rect(xy[role >= 0]), coarse)

    def setPrepared(self, prepared: tuple) -> None:  # noqa: N802
        self.prepareGeometryChange()
        (self._xy, self._role, self._lines, self._xy_anchors, self._xy_knots, self._anchors,
         self._knots, self._rect, self._coarse) = prepared
        self.update()

    def setData(self, xy: np.ndarray, role: np.ndarray) -> None:  # noqa: N802
        self.setPrepared(self.prepare(xy, role))

    def getData(self) -> tuple[np.ndarray, np.ndarray]:  # noqa: N802
        pts = self._xy[self._role > 0]
        return pts[:, 0], pts[:, 1]

    def paint(self, p, *args) -> None:
        if not len(self._xy):
            return
        small = len(self._xy) < MAX_ANTIALIAS_POINTS
        p.setRenderHint(p.RenderHint.Antialiasing, small)
        p.setPen(self.line_pen)
        lines, knots, anchors = self._lines, self._xy_knots, self._xy_anchors
        kpoly, apoly = self._knots, self._anchors
        self.last_drawn = "full"
        level = _pick_level(getattr(self, "_coarse", None), p)
        if level is not None:
            lines, anchors, knots = level[1], level[2], level[3]
            kpoly = apoly = None
            self.last_drawn = "coarse"
        p.drawPath(lines)
        draw_points(p, knots, kpoly, self.knot_pen, grid=3.0, small=small)
        draw_points(p, knots, kpoly, self.hole_pen, grid=3.0, small=small)
        draw_points(p, anchors, apoly, self.anchor_pen, grid=3.0, small=small)


class LinesItem(_FastItem):
    """NaN-separated polylines as ONE QPainterPath, built by :meth:`prepare` (on the worker
    thread: building the path of a million vertices takes a quarter of a second, which the
    GUI thread must not spend). Big layers are drawn with 1-pixel lines, no antialiasing."""

    def __init__(self, pen: QPen) -> None:
        super().__init__()
        self.pen = QPen(pen)
        self.thin_pen = QPen(pen)
        self.thin_pen.setWidthF(1.0)
        self._path = QPainterPath()
        self._coarse: list[tuple[float, QPainterPath]] | None = None
        self._xy = np.empty((0, 2))
        self._n = 0
        #: what the last paint drew: "full" or "coarse" (tests, benchmark)
        self.last_drawn = ""

    @staticmethod
    def prepare(xy: np.ndarray, lod: float | None = None) -> tuple:
        """(xy, path, rectangle, finite vertices, coarse) of NaN-separated polylines (any
        thread). With ``lod`` (item units) a big layer also gets a coarse path: vertices
        merged on a grid of ``lod`` (:func:`decimate`), drawn while a device pixel is at
        least twice ``lod`` (so it differs from the full path by under a pixel)."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        if not len(xy):
            return xy, QPainterPath(), QRectF(), 0, None
        finite = np.isfinite(xy).all(axis=1)
        n = int(finite.sum())
        if not n:
            return xy, QPainterPath(), QRectF(), 0, None
        path = _qpath(xy[:, 0], xy[:, 1])
        levels: list[tuple[float, QPainterPath]] = []
        # pieces of two vertices (the jumps) keep both ends at every grid: no coarse level
        two_point = (len(xy) % 3 == 2 and n == 2 * (len(xy) // 3 + 1)
                     and bool(np.isnan(xy[2::3, 0]).all()))
        if lod is not None and lod > 0 and n >= MAX_ANTIALIAS_POINTS and not two_point:
            prev = len(xy)
            for f in LOD_FACTORS[::-1]:  # finest first: each level from the full data
                c = decimate(xy, lod * f)
                if len(c) < 0.7 * prev:
                    levels.append((float(lod * f), _qpath(c[:, 0], c[:, 1])))
                    prev = len(c)
        return xy, path, _finite_rect(xy), n, levels[::-1] or None  # finite rows only

    def setPrepared(self, prepared: tuple) -> None:  # noqa: N802
        self.prepareGeometryChange()
        self._xy, self._path, self._rect, self._n, self._coarse = prepared
        self.update()

    def paint(self, p, *args) -> None:
        if not self._n:
            return
        small = self._n < MAX_ANTIALIAS_POINTS
        p.setRenderHint(p.RenderHint.Antialiasing, small)
        p.setPen(self.pen if small else self.thin_pen)
        path = self._path
        self.last_drawn = "full"
        level = _pick_level(self._coarse, p)
        if level is not None:
            path = level[1]
            self.last_drawn = "coarse"
        p.drawPath(path)


#: coarse levels of big layers, as multiples of the finest grid (coarsest first)
LOD_FACTORS = (4.0, 2.0, 1.0)


def _pick_level(levels, p):
    """The coarsest level whose grid is at most half a device pixel under the painter's
    transform (None: draw the full data)."""
    if not levels:
        return None
    t = p.transform()
    px = 1.0 / max(math.hypot(t.m11(), t.m12()), 1e-300)  # item units per device pixel
    for level in levels:  # coarsest first
        if level[0] <= 0.5 * px:
            return level
    return None


def _one_per_cell(pts: np.ndarray, cell: float) -> np.ndarray:
    """One point per grid cell of side ``cell`` (the first of each), order kept."""
    if len(pts) < 2:
        return pts
    return _first_per_cell(pts, np.floor((pts - pts.min(axis=0)) / cell).astype(np.int64))


def _levels_per_cell(pts: np.ndarray, cell: float) -> list[tuple[float, np.ndarray]]:
    """``(cell * f, _one_per_cell(pts, cell * f))`` for f in :data:`LOD_FACTORS` (whole
    numbers): the finest grid's cells computed once, a coarser one's by integer division
    (the same cells: floor(x / (f g)) = floor(floor(x / g) / f) for x >= 0)."""
    from galvo_core.preview import bbox

    box = bbox(pts) if len(pts) >= 2 else None
    pts = np.ascontiguousarray(pts, dtype=np.float64)
    if box is None or not np.isfinite(pts).all():
        c = np.floor((pts - pts.min(axis=0)) / cell).astype(np.int64)
        return [(float(cell * f), _first_per_cell(pts, c // int(f))) for f in LOD_FACTORS]
    # one compiled pass per level, the cells computed as above (floor of the finest grid,
    # then integer division), no (N, 2) temporaries
    x0, y0 = box[0], box[1]
    cx_max = int(math.floor((box[2] - x0) / cell))
    cy_max = int(math.floor((box[3] - y0) / cell))
    out = []
    for f in LOD_FACTORS:
        k = int(f)
        nx, ny = cx_max // k + 1, cy_max // k + 1
        if nx * ny <= max(64 * len(pts), 20_000_000):
            keep = _first_in_grid(pts, x0, y0, float(cell), k, ny, nx * ny)
            out.append((float(cell * f), pts[keep]))
        else:
            c = np.floor((pts - np.array([x0, y0])) / cell).astype(np.int64)
            out.append((float(cell * f), _first_per_cell(pts, c // k)))
    return out


@njit(cache=True, nogil=True)
def _first_in_grid(pts: np.ndarray, x0: float, y0: float, cell: float, k: int, ny: int,
                   cells: int) -> np.ndarray:  # pragma: no cover - jit
    """The first point in each cell ``floor((p - (x0, y0)) / cell) // k`` (one pass, a
    bitmap of ``cells`` cells, ``ny`` rows)."""
    seen = np.zeros(cells, dtype=np.bool_)
    keep = np.zeros(len(pts), dtype=np.bool_)
    for i in range(len(pts)):
        cx = np.int64(np.floor((pts[i, 0] - x0) / cell)) // k
        cy = np.int64(np.floor((pts[i, 1] - y0) / cell)) // k
        key = cx * ny + cy
        if not seen[key]:
            seen[key] = True
            keep[i] = True
    return keep


def _first_per_cell(pts: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The first point of ``pts`` in each integer cell ``c`` (N, 2), order kept."""
    ny = int(c[:, 1].max()) + 1
    key = c[:, 0] * ny + c[:, 1]
    cells = (int(c[:, 0].max()) + 1) * ny
    if cells <= max(64 * len(pts), 20_000_000):
        # a bitmap of the cells (20 MB at most): one pass, no sort
        return pts[_first_in_cell(key, cells)]
    _, first = np.unique(key, return_index=True)
    return pts[np.sort(first)]


@njit(cache=True, nogil=True)
def _first_in_cell(key: np.ndarray, cells: int) -> np.ndarray:  # pragma: no cover - jit
    seen = np.zeros(cells, dtype=np.bool_)
    keep = np.zeros(len(key), dtype=np.bool_)
    for i in range(len(key)):
        k = key[i]
        if not seen[k]:
            seen[k] = True
            keep[i] = True
    return keep


def decimate(xy: np.ndarray, cell: float) -> np.ndarray:
    """NaN-separated polylines with the vertices that stay in the grid cell (side
    ``cell``) of the vertex before them dropped; the first and last vertex of every piece
    and the NaN rows are kept. Every dropped vertex lies within ``cell * √2`` of the kept
    polyline, so at a pixel of two cells or more the drawing is the same to a pixel."""
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    if len(xy) < 3:
        return xy
    return xy[_decimate_keep(xy, float(cell))]


@njit(cache=True, nogil=True)
def _decimate_keep(xy: np.ndarray, cell: float) -> np.ndarray:  # pragma: no cover - jit
    """The rows :func:`decimate` keeps (one compiled pass)."""
    n = len(xy)
    keep = np.ones(n, dtype=np.bool_)
    px = np.floor(xy[0, 0] / cell)
    py = np.floor(xy[0, 1] / cell)
    for i in range(1, n):
        cx = np.floor(xy[i, 0] / cell)
        cy = np.floor(xy[i, 1] / cell)
        if cx == px and cy == py:  # NaN rows never equal: always kept
            keep[i] = False
        px = cx
        py = cy
    for i in range(n - 1):
        if not np.isfinite(xy[i + 1, 0]):  # the last vertex of each piece
            keep[i] = True
    keep[n - 1] = True
    return keep


def prepare_layer(key: str, *arrays: np.ndarray, lod: float | None = None) -> tuple:
    """What the item of layer ``key`` needs from ``arrays`` (QPainterPaths, rectangles):
    safe to call on a worker thread, then handed to :meth:`WorkView.set_layer`. ``lod``:
    the coarse grid of line layers, in the layer's units (see :meth:`LinesItem.prepare`)."""
    cls = _LAYER_CLASS[key]
    if cls in (LinesItem, ControlItem, PointsItem, DeviationItem):
        return cls.prepare(*arrays, lod=lod)
    return cls.prepare(*arrays)


class ColourBar(pg.GraphicsWidgetAnchor, pg.GraphicsWidget):
    """A vertical colour bar of the deviation colours with labels in µm (one overlay item)."""

    W, H = 92, 150

    def __init__(self) -> None:
        pg.GraphicsWidget.__init__(self)
        pg.GraphicsWidgetAnchor.__init__(self)
        self.setFlag(self.GraphicsItemFlag.ItemIgnoresTransformations)
        self.setZValue(50)
        self.top_um = 1.0
        self.setMinimumSize(self.W, self.H)
        self.setMaximumSize(self.W, self.H)
        self.label = "deviation [µm]"

    def set_range(self, top_um: float) -> None:
        self.top_um = float(top_um)
        self.update()

    def boundingRect(self) -> QRectF:  # noqa: N802 - Qt API
        return QRectF(0, 0, self.W, self.H)

    def tick_labels(self) -> list[str]:
        return [f"{self.top_um * f:.3g}" for f in (1.0, 0.5, 0.0)]

    def paint(self, p, *args) -> None:
        from PySide6.QtGui import QBrush, QFont, QLinearGradient

        p.setRenderHint(p.RenderHint.Antialiasing, True)
        p.setPen(pg.mkPen("#c8ccd0"))
        p.setBrush(pg.mkBrush(255, 255, 255, 215))
        p.drawRect(QRectF(0, 0, self.W - 1, self.H - 1))
        font = QFont()
        font.setPointSizeF(7.5)
        p.setFont(font)
        p.setPen(pg.mkPen(FOREGROUND))
        p.drawText(QRectF(4, 2, self.W - 8, 14), Qt.AlignmentFlag.AlignCenter, self.label)
        x0, y0, w, h = 10, 20, 14, self.H - 30
        grad = QLinearGradient(0, y0 + h, 0, y0)
        for i, c in enumerate(DEVIATION_STOPS):
            grad.setColorAt(i / (len(DEVIATION_STOPS) - 1), pg.mkColor(c))
        p.setBrush(QBrush(grad))
        p.setPen(pg.mkPen("#6b7580"))
        p.drawRect(QRectF(x0, y0, w, h))
        for f, text in zip((0.0, 0.5, 1.0), self.tick_labels(), strict=True):
            y = y0 + f * h
            p.drawLine(QPointF(x0 + w, y), QPointF(x0 + w + 3, y))
            p.drawText(QRectF(x0 + w + 5, y - 7, self.W - x0 - w - 8, 14),
                       Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter,
                       text + (" = tol." if f == 0.0 else ""))


class WorkView(pg.PlotWidget):
    """One titled, equal-aspect, y-up plot in workpiece mm with a field outline, layers,
    a selection highlight and a legend."""

    def __init__(self, title: str, layer_keys: tuple[str, ...], parent=None) -> None:
        super().__init__(parent=parent, background=BACKGROUND)
        self.setAcceptDrops(False)  # let file drops reach the main window
        self.view_title = title
        pi = self.getPlotItem()
        pi.setTitle(title, color=FOREGROUND, size=TITLE_SIZE, bold=True)
        pi.setMenuEnabled(False)
        pi.hideButtons()
        pi.showGrid(x=True, y=True, alpha=GRID_ALPHA)
        pi.layout.setContentsMargins(4, 2, 10, 4)
        for name, label in (("bottom", "x"), ("left", "y")):
            axis = pi.getAxis(name)
            axis.enableAutoSIPrefix(False)
            axis.setLabel(f"{label} [mm]", color=FOREGROUND)
            axis.setPen(pg.mkPen(FOREGROUND))
            axis.setTextPen(pg.mkPen(FOREGROUND))
        pi.getAxis("left").setWidth(52)
        if QPixmapCache.cacheLimit() < PIXMAP_CACHE_KB:
            QPixmapCache.setCacheLimit(PIXMAP_CACHE_KB)
        cache = QGraphicsItem.CacheMode.DeviceCoordinateCache
        for name in ("left", "bottom"):  # ticks, labels and the grid: redrawn on zoom only
            pi.getAxis(name).setCacheMode(cache)
        vb = pi.getViewBox()
        vb.setAspectLocked(True, ratio=1.0)  # y up is the ViewBox default
        vb.setDefaultPadding(0.04)

        self.field = pg.PlotDataItem([], [], pen=_pen(FIELD, 1.2, style=Qt.PenStyle.DashLine),
                                     name="field")
        self.field.setZValue(-10)
        pi.addItem(self.field)
        self.field_label = pg.TextItem("", color=FIELD, anchor=(1, 0))
        self.field_label.setZValue(-10)
        pi.addItem(self.field_label, ignoreBounds=True)

        self.highlight = pg.PlotDataItem([], [], connect="finite",
                                         pen=_pen(SELECTION, 7.0, alpha=200), name="selection")
        self.highlight.setZValue(-5)
        pi.addItem(self.highlight)

        self.layers: dict[str, pg.GraphicsObject] = {}
        self.legend_samples: dict[str, pg.PlotDataItem] = {}
        for key in layer_keys:
            item, sample = _make_layer(key)
            item.setZValue(_Z[key])
            pi.addItem(item)
            self.layers[key] = item
            if key not in UNCACHED_LAYERS:
                for it in _painting_items(item):
                    it.setCacheMode(cache)
            self.legend_samples[key] = sample

        self.legend = pg.LegendItem(offset=(0, 0), labelTextColor=FOREGROUND,
                                    brush=pg.mkBrush(255, 255, 255, 215),
                                    pen=pg.mkPen("#c8ccd0"), labelTextSize="8pt",
                                    verSpacing=-6, horSpacing=8)
        self.legend.setParentItem(vb)
        self.legend.sigSampleClicked.connect(self._on_sample_clicked)
        self.legend.anchor((0, 0), (0, 0), offset=(4, 4))
        self.colorbar: ColourBar | None = None

        #: (xmin, ymin, xmax, ymax) in mm of what the view shows, None when empty.
        self.bounds: tuple[float, float, float, float] | None = None
        self.counts: dict[str, int] = dict.fromkeys(layer_keys, 0)
        self._data_ids: dict[str, int] = {}
        self.set_empty_range()

    # --- data ----------------------------------------------------------------------------
    def set_layer(self, key: str, *arrays: np.ndarray, transform: QTransform,
                  count: int | None = None, prepared: tuple | None = None, **extra) -> bool:
        """Give a layer its data (native space) and the transform to mm. The data are only
        re-sent when the first array is another object than last time. ``prepared``: the
        item's data made by :func:`prepare_layer` on a worker (else made here). Returns True
        when the data changed."""
        item = self.layers[key]
        if item.transform() != transform:  # an equal transform would still repaint
            item.setTransform(transform)
        ident = id(arrays[0]) if arrays else 0
        if self._data_ids.get(key) == ident and ident:
            return False
        self._data_ids[key] = ident
        # keep the arrays alive so the id stays theirs
        item._galvo_data = arrays
        item.setPrepared(prepared if prepared is not None else item.prepare(*arrays))
        if isinstance(item, DeviationItem):
            self.counts[key] = item.n_chords
            return True
        self.counts[key] = count if count is not None else len(arrays[0])
        return True

    def set_highlight(self, xy: np.ndarray, transform: QTransform) -> None:
        if not len(xy) and getattr(self, "_highlight_empty", False):
            return  # already empty: no change, no repaint of the whole view
        self._highlight_empty = not len(xy)
        self.highlight.setTransform(transform)
        if len(xy):
            self.highlight.setData(xy[:, 0], xy[:, 1], connect="finite")
        else:
            self.highlight.setData([], [])

    def set_field(self, outline_mm: np.ndarray | None, label: str = "") -> None:
        if outline_mm is None or not len(outline_mm):
            self.field.setData([], [])
            self.field_label.setText("")
            return
        self.field.setData(outline_mm[:, 0], outline_mm[:, 1])
        self.field_label.setText(label)
        # under the field's lower right corner: the legend covers the top left
        self.field_label.setPos(float(outline_mm[:, 0].max()), float(outline_mm[:, 1].min()))

    def set_layer_visible(self, key: str, visible: bool) -> None:
        if key in self.layers:
            self.layers[key].setVisible(visible)
            self.update_legend()

    def update_legend(self) -> None:
        """Legend entries for the visible layers that have something to show."""
        want = [k for k, item in self.layers.items()
                if item.isVisible() and k != "deviation" and self.counts.get(k, 0) > 0]
        if want == getattr(self, "_legend_keys", None):
            return
        self._legend_keys = want
        # pyqtgraph re-lays the legend out (setGeometry, its anchors) after every entry
        # removed or added: 40-50 ms of the GUI thread for a new set of layers. Once here.
        self.legend.updateSize = lambda: None
        try:
            self.legend.clear()
            for key in want:
                label = next(s.label for s in LAYERS if s.key == key)
                self.legend.addItem(self.legend_samples[key], label)
            self._legend_columns()
        finally:
            del self.legend.updateSize
        self.legend.updateSize()
        self.legend.setVisible(bool(want))

    def _legend_columns(self) -> None:
        n = len(getattr(self, "_legend_keys", ()) or ())
        fits = max(1, int(self.getPlotItem().getViewBox().width() // 125))
        cols = max(1, min(n, fits))
        if self.legend.columnCount != cols:
            self.legend.setColumnCount(cols)

    def resizeEvent(self, ev) -> None:  # noqa: N802 - Qt API
        super().resizeEvent(ev)
        if hasattr(self, "legend"):
            self._legend_columns()

    #: called with a layer key when its legend sample is clicked (the window toggles it)
    on_legend_toggle = None

    def _on_sample_clicked(self, sample_item) -> None:
        sample_item.setVisible(True)  # the legend toggled its stand-in: undo, toggle the layer
        for key, s in self.legend_samples.items():
            if s is sample_item and self.on_legend_toggle is not None:
                self.on_legend_toggle(key)

    def set_colorbar(self, visible: bool, top_um: float = 1.0) -> None:
        """The deviation colour bar (0 .. ``top_um`` µm), inside the plot at the right."""
        if visible and self.colorbar is None:
            self.colorbar = ColourBar()
            self.colorbar.setParentItem(self.getPlotItem().getViewBox())
            self.colorbar.anchor((1, 0), (1, 0), offset=(-6, 4))
        if self.colorbar is not None:
            if visible:
                self.colorbar.set_range(top_um)
            else:
                self.colorbar.setParentItem(None)
                if self.colorbar.scene() is not None:
                    self.colorbar.scene().removeItem(self.colorbar)
                self.colorbar = None

    def repaint_now(self) -> None:
        """Render the view synchronously (benchmark: 'redrawn')."""
        self.viewport().repaint()

    #: viewport paints so far (the benchmark tells whether a result was drawn already)
    paint_count = 0

    #: called (once set) after each paint of the view (the window staggers the views' paints)
    on_painted: Callable[[], None] | None = None

    def paintEvent(self, ev) -> None:  # noqa: N802 - Qt API
        super().paintEvent(ev)
        self.paint_count += 1
        if self.on_painted is not None:
            self.on_painted()

    def data_items(self) -> list[pg.GraphicsObject]:
        return [self.layers[k] for k in self.layers]

    #: how much of the background covers the layers while the result is out of date
    STALE_VEIL_ALPHA = 180

    def set_stale(self, stale: bool) -> None:
        """Dim the plot (the result shown is out of date) or show it normally: a veil of
        the background colour over the plot area, so the layers' cached pixmaps stay valid
        (changing their opacity would rasterise them all again, twice per change)."""
        self.stale = stale
        veil = getattr(self, "_veil", None)
        if veil is None:
            from PySide6.QtWidgets import QGraphicsRectItem

            veil = QGraphicsRectItem()
            c = pg.mkColor(BACKGROUND)
            c.setAlpha(self.STALE_VEIL_ALPHA)
            veil.setBrush(pg.mkBrush(c))
            veil.setPen(pg.mkPen(None))
            veil.setZValue(1e6)
            self.scene().addItem(veil)
            self._veil = veil
        if stale:
            veil.setRect(self.getPlotItem().getViewBox().sceneBoundingRect())
        veil.setVisible(stale)

    # --- range ---------------------------------------------------------------------------
    def legend_height(self) -> float:
        """Pixels the legend strip covers at the top of the plot (0 when hidden)."""
        if not self.legend.isVisible():
            return 0.0
        return float(self.legend.boundingRect().height()) + 6.0

    def fit(self, bounds: tuple[float, float, float, float] | None = None,
            top_px: float | None = None) -> None:
        """Zoom to ``bounds`` (mm; default: the data), or to the empty sheet; ``top_px``
        pixels at the top are kept free for legends (default: this view's legend)."""
        bounds = bounds if bounds is not None else self.bounds
        if bounds is None:
            self.set_empty_range()
            return
        x0, y0, x1, y1 = bounds
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        w = max(x1 - x0, MIN_FIT_SPAN_MM) * 1.08
        h = max(y1 - y0, MIN_FIT_SPAN_MM) * 1.08
        vb = self.getPlotItem().getViewBox()
        W, H = max(vb.width(), 1.0), max(vb.height(), 1.0)  # noqa: N806
        # leave room at the top for the legend strip (it sits inside the plot)
        top_px = self.legend_height() if top_px is None else top_px
        top = min(0.3, top_px / H) if H > 50 else 0.0
        h_free = H * (1.0 - top)
        s = max(w / W, h / h_free)  # mm per pixel so that the box fits below the legend
        bottom = cy - h_free * s / 2
        vb.setRange(xRange=(cx - W * s / 2, cx + W * s / 2), yRange=(bottom, bottom + H * s),
                    padding=0.0)

    def set_empty_range(self) -> None:
        self.getPlotItem().getViewBox().setRange(xRange=(0, 110), yRange=(0, 110), padding=0.03)

    # --- pixel helpers (tests, picking) --------------------------------------------------
    def view_rect_in(self, widget) -> tuple[int, int, int, int]:
        """The plotting area (ViewBox) as (x, y, w, h) in ``widget`` pixel coordinates."""
        vb = self.getPlotItem().getViewBox()
        rect = self.mapFromScene(vb.sceneBoundingRect()).boundingRect()
        top_left = self.mapTo(widget, rect.topLeft())
        return top_left.x(), top_left.y(), rect.width(), rect.height()

    def data_to_widget(self, widget, x_mm: float, y_mm: float) -> tuple[int, int]:
        """Pixel in ``widget`` of the point (x, y) in mm."""
        vb = self.getPlotItem().getViewBox()
        scene_pt = vb.mapViewToScene(pg.Point(x_mm, y_mm))
        p = self.mapTo(widget, self.mapFromScene(scene_pt))
        return p.x(), p.y()

    def mm_per_pixel(self) -> float:
        vb = self.getPlotItem().getViewBox()
        (x0, x1), _ = vb.viewRange()
        w = max(vb.width(), 1.0)
        return (x1 - x0) / w


_Z = {
    "deviation": 4.5,
    "hatch": 2,
    "kerf": 3,
    "original": 3,
    "fitted": 4,
    "jumps": 5,
    "control": 6,
    "original_points": 6,
    "marks": 7,
}


def _make_layer(key: str) -> tuple[pg.GraphicsObject, pg.PlotDataItem]:
    """The layer's item and a legend sample (a styled stand-in, never added to a plot)."""
    if key == "original":
        kw = dict(pen=_pen(ORIGINAL_LINE, 1.3))
    elif key == "original_points":
        kw = dict(pen=None, symbol="o", symbolSize=4.0, symbolPen=None,
                  symbolBrush=_brush(ORIGINAL_POINT, 230))
    elif key == "fitted":
        kw = dict(pen=_pen(FITTED_LINE, 1.6))
    elif key == "control":
        kw = dict(pen=_pen(CONTROL, 1.0, alpha=170))
    elif key == "marks":
        kw = dict(pen=None, symbol="o", symbolSize=4.0, symbolPen=None,
                  symbolBrush=_brush(MARK, 235))
    elif key == "jumps":
        kw = dict(pen=_pen(JUMP, 1.0, style=Qt.PenStyle.DashLine))
    elif key == "hatch":
        kw = dict(pen=_pen(HATCH, 1.0, alpha=200))
    elif key == "kerf":
        kw = dict(pen=_pen(KERF, 1.5))
    elif key == "deviation":
        item = DeviationItem()
        return item, pg.PlotDataItem([], [], pen=_pen(DEVIATION_STOPS[0], 3))
    else:  # pragma: no cover - a programming error
        raise KeyError(key)
    if key == "original_points":
        item = PointsItem(ORIGINAL_POINT, 4.0, 230)
    elif key == "marks":
        item = PointsItem(MARK, 4.0, 235)
    elif key == "control":
        item = ControlItem()
    else:
        item = LinesItem(kw["pen"])
    # samples get one point so that pyqtgraph hands their symbol style to the legend
    if key == "control":
        sample = pg.PlotDataItem([0.0], [0.0], pen=_pen(CONTROL, 1.0, alpha=170), symbol="s",
                                 symbolSize=5.5, symbolBrush=_brush(CONTROL),
                                 symbolPen=_pen(CONTROL, 1.3))
    else:
        sample = pg.PlotDataItem([0.0], [0.0], **kw)
    return item, sample


_LAYER_CLASS: dict[str, type] = {
    "original": LinesItem, "fitted": LinesItem, "jumps": LinesItem, "hatch": LinesItem,
    "kerf": LinesItem, "original_points": PointsItem, "marks": PointsItem,
    "control": ControlItem, "deviation": DeviationItem,
}


def _painting_items(item: pg.GraphicsObject) -> list[pg.GraphicsObject]:
    """The items that paint a layer: a PlotDataItem draws through its curve and scatter
    children, the other layer items themselves."""
    if isinstance(item, pg.PlotDataItem):
        return [item.curve, item.scatter]
    return [item]


def units_transform(scale: float, offset: tuple[float, float]) -> QTransform:
    """QTransform of ``mm = units * scale + offset``."""
    return QTransform(scale, 0.0, 0.0, scale, float(offset[0]), float(offset[1]))


def scale_transform(scale: float) -> QTransform:
    return QTransform(scale, 0.0, 0.0, scale, 0.0, 0.0)


__all__ = [
    "LAYERS",
    "LAYER_KEYS",
    "DeviationItem",
    "LayerSpec",
    "WorkView",
    "scale_transform",
    "units_transform",
]
