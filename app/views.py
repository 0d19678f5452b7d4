"""Plot views of a drawing: one pyqtgraph item per layer, never one per path.

Coordinates stay in input units (HP-GL plotter units, 40 per mm) inside the plots, so a
point under the cursor is the point in the file; only the axis tick labels are scaled to
millimetres.

Layers of a :class:`DrawingView`:

``lines``
    Every path as one NaN-separated polyline (``connect="finite"``): one item whatever
    the number of paths.
``markers``
    The points themselves as small dots, drawn only while the drawing has fewer than
    :data:`MAX_MARKER_POINTS` points (an item with no data above that, so the number of
    items never changes).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import pyqtgraph as pg

from galvo_core.drawing import UNITS_PER_MM, Drawing, Path

#: Point markers are drawn only below this many points (scatter rendering gets slow).
MAX_MARKER_POINTS = 200_000
#: Lines are antialiased only below this many points (speed on big drawings).
MAX_ANTIALIAS_POINTS = 300_000

#: Anything :meth:`DrawingView.set_polylines` accepts: a Drawing, or an iterable of
#: :class:`Path` objects and/or (N, 2) arrays of points in input units.
Polylines = Drawing | Iterable[Path | np.ndarray]

# --- palette (light background, dark ink: legible on screen and in print) -------------
BACKGROUND = "#ffffff"
FOREGROUND = "#2b2b2b"
GRID_ALPHA = 0.12
ORIGINAL_LINE = "#1f3f73"  # dark blue
PROCESSED_LINE = "#0f5f4f"  # dark teal
MARKER = "#e0531f"  # orange-red
MARKER_ALPHA = 210
TITLE_SIZE = "11pt"

#: Smallest span a fit zooms to, in input units (1 mm).
MIN_FIT_SPAN = UNITS_PER_MM

#: Range shown when a view is empty: an A4 landscape sheet (297 x 210 mm).
EMPTY_RANGE_MM = (297.0, 210.0)


def _marker_brush():
    colour = pg.mkColor(MARKER)
    colour.setAlpha(MARKER_ALPHA)
    return pg.mkBrush(colour)


def _as_point_arrays(polylines: Polylines) -> list[np.ndarray]:
    if isinstance(polylines, Drawing):
        polylines = polylines.paths
    out: list[np.ndarray] = []
    for item in polylines:
        pts = item.points if isinstance(item, Path) else np.asarray(item, dtype=np.float64)
        pts = pts.reshape(-1, 2)
        if len(pts):
            out.append(pts)
    return out


def nan_separated(polylines: Polylines) -> tuple[np.ndarray, np.ndarray]:
    """x and y arrays of all polylines, one NaN row between consecutive polylines.

    Suitable for one ``PlotDataItem(x, y, connect="finite")``.
    """
    arrays = _as_point_arrays(polylines)
    if not arrays:
        return np.empty(0), np.empty(0)
    total = sum(len(a) for a in arrays) + len(arrays) - 1
    xy = np.full((total, 2), np.nan)
    i = 0
    for a in arrays:
        xy[i : i + len(a)] = a
        i += len(a) + 1
    return xy[:, 0].copy(), xy[:, 1].copy()


def all_points(polylines: Polylines) -> np.ndarray:
    """Every point of every polyline as one (N, 2) array."""
    arrays = _as_point_arrays(polylines)
    if not arrays:
        return np.empty((0, 2))
    return np.concatenate(arrays)


class DrawingView(pg.PlotWidget):
    """One titled, equal-aspect, y-up plot of polylines in input units, mm on the axes."""

    def __init__(self, title: str, line_colour: str, parent=None) -> None:
        super().__init__(parent=parent, background=BACKGROUND)
        self.setAcceptDrops(False)  # let file drops reach the main window
        self.view_title = title
        pi = self.getPlotItem()
        pi.setTitle(title, color=FOREGROUND, size=TITLE_SIZE, bold=True)
        pi.setMenuEnabled(False)
        pi.hideButtons()
        pi.showGrid(x=True, y=True, alpha=GRID_ALPHA)
        pi.layout.setContentsMargins(6, 4, 14, 6)
        for name, label in (("bottom", "x"), ("left", "y")):
            axis = pi.getAxis(name)
            axis.setScale(1.0 / UNITS_PER_MM)  # data in input units, ticks in mm
            axis.enableAutoSIPrefix(False)
            axis.setLabel(f"{label} [mm]", color=FOREGROUND)
            axis.setPen(pg.mkPen(FOREGROUND))
            axis.setTextPen(pg.mkPen(FOREGROUND))
        pi.getAxis("left").setWidth(58)
        vb = pi.getViewBox()
        vb.setAspectLocked(True, ratio=1.0)  # y up is the ViewBox default
        vb.setDefaultPadding(0.04)

        self.lines = pg.PlotDataItem(
            [], [], connect="finite", pen=pg.mkPen(line_colour, width=1.4), name="lines"
        )
        self.markers = pg.PlotDataItem(
            [],
            [],
            pen=None,
            symbol="o",
            symbolSize=3.2,
            symbolPen=None,
            symbolBrush=_marker_brush(),
            name="markers",
        )
        # markers under the lines: on dense curves the line stays readable on top
        self.markers.setZValue(1)
        self.lines.setZValue(2)
        pi.addItem(self.lines)
        pi.addItem(self.markers)
        self.markers_shown = False
        self.n_polylines = 0
        self.n_points = 0
        #: (xmin, ymin, xmax, ymax) of the data in input units, None when empty.
        self.bounds: tuple[float, float, float, float] | None = None
        self._empty_range()

    # --- data --------------------------------------------------------------------------
    def set_polylines(self, polylines: Polylines, *, auto_range: bool = True) -> None:
        """Replace what the view shows; a fixed number of items whatever the input size."""
        arrays = _as_point_arrays(polylines)
        x, y = nan_separated(arrays)
        pts = all_points(arrays)
        self.n_polylines = len(arrays)
        self.n_points = len(pts)
        self.bounds = (*pts.min(axis=0).tolist(), *pts.max(axis=0).tolist()) if len(pts) else None
        self.lines.setData(x, y, connect="finite", antialias=len(pts) < MAX_ANTIALIAS_POINTS)
        self.markers_shown = 0 < len(pts) < MAX_MARKER_POINTS
        if self.markers_shown:
            self.markers.setData(pts[:, 0], pts[:, 1])
        else:
            self.markers.setData([], [])
        if auto_range:
            self.fit()

    def clear_drawing(self) -> None:
        self.set_polylines([])

    def data_items(self) -> list[pg.PlotDataItem]:
        return self.getPlotItem().listDataItems()

    def fit(self, bounds: tuple[float, float, float, float] | None = None) -> None:
        """Zoom to ``bounds`` (default: the data), or to an empty sheet when there is none."""
        bounds = bounds if bounds is not None else self.bounds
        if bounds is None:
            self._empty_range()
            return
        x0, y0, x1, y1 = bounds
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        # at least 1 mm across, so a single dot or a straight line still gets a sane view
        w = max(x1 - x0, MIN_FIT_SPAN)
        h = max(y1 - y0, MIN_FIT_SPAN)
        self.getPlotItem().getViewBox().setRange(
            xRange=(cx - w / 2, cx + w / 2), yRange=(cy - h / 2, cy + h / 2), padding=0.04
        )

    def _empty_range(self) -> None:
        w, h = EMPTY_RANGE_MM
        self.getPlotItem().getViewBox().setRange(
            xRange=(0, w * UNITS_PER_MM), yRange=(0, h * UNITS_PER_MM), padding=0.02
        )

    def view_rect_in(self, widget) -> tuple[int, int, int, int]:
        """The plotting area (ViewBox) as (x, y, w, h) in ``widget`` pixel coordinates."""
        vb = self.getPlotItem().getViewBox()
        rect = self.mapFromScene(vb.sceneBoundingRect()).boundingRect()
        top_left = self.mapTo(widget, rect.topLeft())
        return top_left.x(), top_left.y(), rect.width(), rect.height()

    def data_to_widget(self, widget, x: float, y: float) -> tuple[int, int]:
        """Pixel in ``widget`` of the point (x, y) in input units."""
        vb = self.getPlotItem().getViewBox()
        scene_pt = vb.mapViewToScene(pg.Point(x, y))
        p = self.mapTo(widget, self.mapFromScene(scene_pt))
        return p.x(), p.y()


def cursor_text(x: float, y: float) -> str:
    """Status-bar text for a cursor position in input units."""
    return f"x {x / UNITS_PER_MM:9.3f} mm  y {y / UNITS_PER_MM:9.3f} mm   ({x:.0f}, {y:.0f} units)"


__all__ = [
    "DrawingView",
    "MAX_MARKER_POINTS",
    "Polylines",
    "all_points",
    "cursor_text",
    "nan_separated",
]
