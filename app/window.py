"""The workstation window: original and processed views side by side, live tuning, export.

Data flow: a control moves -> :attr:`MainWindow.params` (validated by Params) -> a throttled
request to the :class:`~app.worker.LatestRunner` (the pipeline and the display geometry run
on a worker thread; newest request wins; stale results dropped) -> :meth:`apply_result`
hands arrays to the views' layers and the numbers to the job panel. The GUI computes no
geometry: :mod:`galvo_core.preview` does.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path as FsPath
from typing import Any

import numpy as np
from PySide6.QtCore import (
    QBuffer,
    QByteArray,
    QFileSystemWatcher,
    QIODevice,
    QSettings,
    Qt,
    QTimer,
    Signal,
)
from PySide6.QtGui import (
    QAction,
    QActionGroup,
    QColor,
    QDragEnterEvent,
    QDropEvent,
    QIcon,
    QKeySequence,
    QPainter,
    QPen,
    QPixmap,
)
from PySide6.QtWidgets import (
    QCheckBox,
    QDockWidget,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QMainWindow,
    QMessageBox,
    QProgressBar,
    QScrollArea,
    QSplitter,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from galvo_core.drawing import Drawing
from galvo_core.errors import GalvoError, ParamError
from galvo_core.job import Job, atomic_write_bytes, load_job, write_job
from galvo_core.params import Params
from galvo_core.pipeline import Pipeline
from galvo_core.preview import PreviewCache

from . import views as views_mod
from .controls import ControlsPanel, LaserDialog
from .stats import StatsPanel, WarningsPanel
from .views import LAYERS, WorkView, scale_transform, units_transform
from .worker import LatestRunner, RunResult, job_task

APP_NAME = "Galvo Workstation"
ORGANISATION = "galvo-workstation"
#: Environment variable naming an INI file to keep the settings in (tests point it to a
#: temporary file so they never touch the user's settings).
SETTINGS_ENV = "GALVO_WORKSTATION_SETTINGS"
#: The repository's resources folder (icons, sample files).
RESOURCES_DIR = FsPath(__file__).resolve().parent.parent / "resources"
ICON_PATH = RESOURCES_DIR / "icons" / "app.svg"
SAMPLES_DIR = RESOURCES_DIR / "samples"

#: Slider updates while dragging are sent at most this often (ms); release sends at once.
THROTTLE_MS = 60
#: Show the progress bar only for runs longer than this (ms).
BUSY_DELAY_MS = 200
MAX_RECENT = 8

_EXTS = ("plt", "hpgl", "hpg", "hp", "pgl", "pcl", "spl")
FILE_FILTER = (
    "HP-GL files ("
    + " ".join(f"*.{e}" for e in _EXTS)
    + " "
    + " ".join(f"*.{e.upper()}" for e in _EXTS)
    + ");;Job files (*.json *.JSON);;All files (*)"
)
JOB_FILTER = "Job files (*.json);;All files (*)"


def load_drawing(path: str | os.PathLike) -> Drawing:
    """Read an HP-GL file (the importer is imported lazily, on first use)."""
    from galvo_core.hpgl import read_file

    return read_file(path)


def describe_load_error(path: str | os.PathLike, exc: BaseException) -> str:
    """One line for the user, never a traceback."""
    name = FsPath(path).name or str(path)
    if isinstance(exc, GalvoError):  # InputError: "<file>: <reason>" from the importer
        return str(exc)
    if isinstance(exc, OSError):
        reason = exc.strerror or str(exc) or type(exc).__name__
        return f"{name}: cannot read the file: {reason}"
    detail = str(exc) or type(exc).__name__
    return f"{name}: unexpected error while loading ({type(exc).__name__}: {detail})"


def bundled_sample() -> FsPath | None:
    """The first ``*.plt`` in ``resources/samples`` (sorted by name), or None."""
    if not SAMPLES_DIR.is_dir():
        return None
    found = sorted(p for p in SAMPLES_DIR.iterdir() if p.suffix.lower() == ".plt" and p.is_file())
    return found[0] if found else None


def exporters() -> dict[str, Any]:
    """The optional PLT/SVG writers of ``galvo_core.export`` (imported lazily): name ->
    function; missing ones are absent."""
    try:
        from galvo_core import export  # type: ignore[attr-defined]
    except Exception:  # noqa: BLE001 - not there yet, or broken: grey the actions out
        return {}
    return {n: getattr(export, n) for n in ("write_plt", "write_svg")
            if callable(getattr(export, n, None))}


def app_settings() -> QSettings:
    """The settings store: the INI file named by $GALVO_WORKSTATION_SETTINGS, else the
    platform's default place for this organisation/application."""
    path = os.environ.get(SETTINGS_ENV)
    if path:
        return QSettings(path, QSettings.Format.IniFormat)
    return QSettings(ORGANISATION, APP_NAME)


def _fmt_int(n: int) -> str:
    return f"{n:,}".replace(",", "\u2009")


def params_to_json(p: Params) -> str:
    return json.dumps(p.as_dict())


def params_from_json(text: str, base: Params | None = None) -> Params:
    """Params from :func:`params_to_json` text (or the older layout with a ``laser``
    table); unknown keys are ignored, an invalid value gives ``base``."""
    base = base or Params()
    try:
        d = json.loads(text)
        if isinstance(d.get("laser"), dict):
            d = {**d.pop("laser"), **d}
        return Params.from_mapping(d, base=base, ignore_unknown=True)
    except (ValueError, TypeError, AttributeError):
        return base


def _swatch(key: str) -> QIcon:
    """A small legend swatch for a layer checkbox."""
    pm = QPixmap(22, 14)
    pm.fill(QColor(0, 0, 0, 0))
    p = QPainter(pm)
    p.setRenderHint(QPainter.RenderHint.Antialiasing)
    v = views_mod
    if key in ("original_points", "marks"):
        c = QColor(v.ORIGINAL_POINT if key == "original_points" else v.MARK)
        p.setPen(Qt.PenStyle.NoPen)
        p.setBrush(c)
        for x in (4, 11, 18):
            p.drawEllipse(x - 2, 5, 4, 4)
    elif key == "control":
        c = QColor(v.CONTROL)
        p.setPen(QPen(c, 1.2))
        p.drawLine(4, 10, 17, 4)
        p.setBrush(c)
        p.drawRect(1, 7, 5, 5)
        p.setBrush(QColor("white"))
        p.drawEllipse(14, 1, 6, 6)
    elif key == "deviation":
        for i, col in enumerate(v.DEVIATION_STOPS):
            p.setPen(QPen(QColor(col), 4))
            p.drawLine(1 + i * 4, 7, 5 + i * 4, 7)
    else:
        colour = {"original": v.ORIGINAL_LINE, "fitted": v.FITTED_LINE, "jumps": v.JUMP,
                  "hatch": v.HATCH, "kerf": v.KERF}[key]
        pen = QPen(QColor(colour), 2)
        if key == "jumps":
            pen.setStyle(Qt.PenStyle.DashLine)
            pen.setWidthF(1.4)
        p.setPen(pen)
        p.drawLine(1, 7, 21, 7)
    p.end()
    return QIcon(pm)


class MainWindow(QMainWindow):
    """The workstation: two linked views, layer toggles, processing controls, job panel."""

    #: emitted after a result has been handed to the views (generation)
    result_shown = Signal(int)

    def __init__(self, drawing: Drawing | None = None, parent: QWidget | None = None, *,
                 settings: QSettings | None = None, restore: bool = True) -> None:
        super().__init__(parent)
        self.settings = settings if settings is not None else app_settings()
        self._restore_settings = restore
        self.drawing: Drawing | None = None
        self.file_path: FsPath | None = None
        self.job_path: FsPath | None = None
        self.params = Params()
        self.pipeline = Pipeline()
        self.preview_cache = PreviewCache()
        self.result: RunResult | None = None
        self.run_error: str | None = None
        self.selected: int | None = None
        self._last_dir = str(self.settings.value("last_dir", str(FsPath.cwd())))
        self._fit_pending = False
        self._drawing_bbox: tuple[float, float, float, float] | None = None
        #: The message of the last error dialog (kept for tests and logs).
        self.last_error: str | None = None
        self.last_result_time = 0.0

        self.setObjectName("MainWindow")
        if ICON_PATH.is_file():
            self.setWindowIcon(QIcon(str(ICON_PATH)))
        self.setAcceptDrops(True)
        self.setMinimumSize(480, 320)
        self.setDockOptions(QMainWindow.DockOption.AnimatedDocks
                            | QMainWindow.DockOption.AllowTabbedDocks)

        # --- views ---------------------------------------------------------------------
        self.original = WorkView("Original", tuple(s.key for s in LAYERS
                                                   if s.view == "original"))
        self.processed = WorkView("Processed", tuple(s.key for s in LAYERS
                                                     if s.view == "processed"))
        self.processed.setXLink(self.original)
        self.processed.setYLink(self.original)
        splitter = QSplitter(Qt.Orientation.Horizontal)
        splitter.addWidget(self.original)
        splitter.addWidget(self.processed)
        splitter.setChildrenCollapsible(False)
        splitter.setHandleWidth(5)
        splitter.setSizes([1, 1])
        splitter.setStretchFactor(0, 1)
        splitter.setStretchFactor(1, 1)
        self.splitter = splitter

        self.layer_boxes: dict[str, QCheckBox] = {}
        layer_bar = QWidget()
        layer_bar.setObjectName("layer_bar")
        bar = QHBoxLayout(layer_bar)
        bar.setContentsMargins(6, 2, 6, 2)
        bar.setSpacing(10)
        title = QLabel("Layers:")
        title.setStyleSheet("font-weight: bold; color: #3d4853;")
        bar.addWidget(title)
        for spec in LAYERS:
            cb = QCheckBox(spec.label)
            cb.setObjectName(f"layer_{spec.key}")
            cb.setIcon(_swatch(spec.key))
            cb.setToolTip(spec.tip)
            cb.setChecked(spec.default_on)
            cb.toggled.connect(lambda on, k=spec.key: self.set_layer_visible(k, on))
            self.layer_boxes[spec.key] = cb
            bar.addWidget(cb)
        bar.addStretch(1)
        self.layer_bar = layer_bar

        self.banner = QLabel("")
        self.banner.setObjectName("banner")
        self.banner.setWordWrap(True)
        self.banner.setStyleSheet(
            "background: #fff4e5; color: #663c00; padding: 3px 8px; border-bottom: 1px solid "
            "#f0c080;")
        self.banner.hide()

        central = QWidget()
        cl = QVBoxLayout(central)
        cl.setContentsMargins(0, 0, 0, 0)
        cl.setSpacing(0)
        cl.addWidget(layer_bar)
        cl.addWidget(self.banner)
        cl.addWidget(splitter, 1)
        self.setCentralWidget(central)

        # --- docks ---------------------------------------------------------------------
        self.controls = ControlsPanel(self.params)
        self.controls.changed.connect(self._on_controls_changed)
        self.controls.laser_requested.connect(self.open_laser_dialog)
        self.controls.defaults_button.clicked.connect(self.restore_defaults)
        scroll = QScrollArea()
        scroll.setWidget(self.controls)
        scroll.setWidgetResizable(True)
        scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        scroll.setMinimumWidth(max(self.controls.minimumSizeHint().width(), 300)
                               + scroll.verticalScrollBar().sizeHint().width() + 8)
        self.controls_dock = QDockWidget("Processing", self)
        self.controls_dock.setObjectName("dock_processing")
        self.controls_dock.setWidget(scroll)
        self.controls_dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                                       | QDockWidget.DockWidgetFeature.DockWidgetFloatable)
        self.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, self.controls_dock)

        self.stats_panel = StatsPanel()
        self.warnings_panel = WarningsPanel()
        self.warnings_panel.activated.connect(self.zoom_to_warning)
        job_split = QSplitter(Qt.Orientation.Horizontal)
        job_split.addWidget(self.stats_panel)
        job_split.addWidget(self.warnings_panel)
        job_split.setStretchFactor(0, 3)
        job_split.setStretchFactor(1, 2)
        job_split.setSizes([520, 280])
        self.job_dock = QDockWidget("Job", self)
        self.job_dock.setObjectName("dock_job")
        self.job_dock.setWidget(job_split)
        self.job_dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                                  | QDockWidget.DockWidgetFeature.DockWidgetFloatable)
        self.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, self.job_dock)
        self.setCorner(Qt.Corner.BottomRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        self.resizeDocks([self.job_dock], [200], Qt.Orientation.Vertical)
        self.resizeDocks([self.controls_dock], [self.controls_dock.minimumSizeHint().width()],
                         Qt.Orientation.Horizontal)

        # --- worker, timers, watcher ---------------------------------------------------
        self.runner = LatestRunner(self)
        self.runner.finished.connect(self._on_result)
        self.runner.failed.connect(self._on_failed)
        self.runner.cancelled.connect(self._on_cancelled)
        self.runner.busy_changed.connect(self._on_busy_changed)
        self._throttle = QTimer(self)
        self._throttle.setSingleShot(True)
        self._throttle.setInterval(THROTTLE_MS)
        self._throttle.timeout.connect(self.request_run)
        self._busy_timer = QTimer(self)
        self._busy_timer.setInterval(100)
        self._busy_timer.timeout.connect(self._update_busy)
        self.watcher = QFileSystemWatcher(self)
        self.watcher.fileChanged.connect(self._on_file_changed)
        self._reload_timer = QTimer(self)
        self._reload_timer.setSingleShot(True)
        self._reload_timer.setInterval(300)
        self._reload_timer.timeout.connect(self._reload_changed)

        self._build_menus()
        self._build_status_bar()
        for view in (self.original, self.processed):
            view.scene().sigMouseMoved.connect(lambda pos, v=view: self._on_mouse_moved(v, pos))
            view.scene().sigMouseClicked.connect(lambda ev, v=view: self._on_mouse_clicked(v, ev))
            view.update_legend()
            view.on_legend_toggle = lambda k: self.layer_boxes[k].toggle()
        self.warnings_panel.set_warnings(())
        self.stats_panel.set_stats({})

        if restore:
            self._restore_state()
        for spec in LAYERS:  # items follow the boxes (also those left at their default)
            for v in (self.original, self.processed):
                v.set_layer_visible(spec.key, self.layer_boxes[spec.key].isChecked())
        self.controls.set_params(self.params, self._field_map_for(self.params))
        if drawing is not None:
            self.set_drawing(drawing)
        else:
            self._update_title()
            self._update_status()

    # --- UI construction ------------------------------------------------------------------
    def _build_menus(self) -> None:
        file_menu = self.menuBar().addMenu("&File")
        self.open_action = QAction("&Open…", self)
        self.open_action.setShortcut(QKeySequence.StandardKey.Open)
        self.open_action.triggered.connect(self.open_dialog)
        file_menu.addAction(self.open_action)
        self.recent_menu = file_menu.addMenu("Open &Recent")
        self.reload_action = QAction("&Reload", self)
        self.reload_action.setShortcut(QKeySequence("Ctrl+R"))
        self.reload_action.triggered.connect(self.reload)
        file_menu.addAction(self.reload_action)
        self.open_job_action = QAction("Open &Job File…", self)
        self.open_job_action.triggered.connect(self.open_job_dialog)
        file_menu.addAction(self.open_job_action)
        file_menu.addSeparator()
        self.export_job_action = QAction("Export &Job (JSON)…", self)
        self.export_job_action.setShortcut(QKeySequence("Ctrl+E"))
        self.export_job_action.triggered.connect(lambda: self.export_dialog("job"))
        self.export_plt_action = QAction("Export &PLT…", self)
        self.export_plt_action.triggered.connect(lambda: self.export_dialog("plt"))
        self.export_svg_action = QAction("Export &SVG…", self)
        self.export_svg_action.triggered.connect(lambda: self.export_dialog("svg"))
        self.export_png_action = QAction("Export P&NG of the Views…", self)
        self.export_png_action.triggered.connect(lambda: self.export_dialog("png"))
        for a in (self.export_job_action, self.export_plt_action, self.export_svg_action,
                  self.export_png_action):
            file_menu.addAction(a)
        file_menu.addSeparator()
        self.quit_action = QAction("&Quit", self)
        self.quit_action.setShortcut(QKeySequence.StandardKey.Quit)
        self.quit_action.setMenuRole(QAction.MenuRole.QuitRole)
        self.quit_action.triggered.connect(self.close)
        file_menu.addAction(self.quit_action)

        view_menu = self.menuBar().addMenu("&View")
        self.fit_action = QAction("Zoom to &Fit", self)
        self.fit_action.setShortcuts([QKeySequence("F"), QKeySequence("Home")])
        self.fit_action.triggered.connect(self.fit)
        view_menu.addAction(self.fit_action)
        self.field_action = QAction("Zoom to the &Field", self)
        self.field_action.triggered.connect(self.fit_field_view)
        view_menu.addAction(self.field_action)
        view_menu.addSeparator()
        self.layer_actions: dict[str, QAction] = {}
        for i, spec in enumerate(LAYERS):
            a = QAction(spec.label, self, checkable=True, checked=spec.default_on)
            if i < 9:
                a.setShortcut(QKeySequence(f"Alt+{i + 1}"))
            a.toggled.connect(lambda on, k=spec.key: self.layer_boxes[k].setChecked(on))
            self.layer_actions[spec.key] = a
            view_menu.addAction(a)
        self.points_action = self.layer_actions["original_points"]
        view_menu.addSeparator()
        view_menu.addAction(self.controls_dock.toggleViewAction())
        view_menu.addAction(self.job_dock.toggleViewAction())

        proc = self.menuBar().addMenu("&Process")
        self.laser_action = QAction("&Laser Parameters…", self)
        self.laser_action.triggered.connect(self.open_laser_dialog)
        proc.addAction(self.laser_action)
        self.cancel_action = QAction("&Cancel Processing", self)
        self.cancel_action.setShortcut(QKeySequence("Esc"))
        self.cancel_action.triggered.connect(self.cancel_processing)
        proc.addAction(self.cancel_action)
        self.defaults_action = QAction("&Restore Default Parameters", self)
        self.defaults_action.triggered.connect(self.restore_defaults)
        proc.addAction(self.defaults_action)
        group = QActionGroup(self)
        del group  # (no exclusive groups needed)
        self._refresh_export_actions()
        self._rebuild_recent_menu()

    def _build_status_bar(self) -> None:
        sb = self.statusBar()
        self.status_label = QLabel()
        self.warnings_label = QLabel()
        self.cursor_label = QLabel()
        self.cursor_label.setMinimumWidth(420)
        self.cursor_label.setTextFormat(Qt.TextFormat.PlainText)
        self.cursor_label.setStyleSheet("font-family: monospace;")
        self.run_label = QLabel()
        self.run_label.setStyleSheet("color: #5f6b7a;")
        self.progress = QProgressBar()
        self.progress.setRange(0, 0)
        self.progress.setMaximumWidth(110)
        self.progress.setMaximumHeight(14)
        self.progress.setTextVisible(False)
        self.progress.hide()
        self.cancel_button = QToolButton()
        self.cancel_button.setText("Cancel")
        self.cancel_button.setToolTip("stop processing (Esc); the last result stays shown")
        self.cancel_button.clicked.connect(self.cancel_processing)
        self.cancel_button.hide()
        sb.addWidget(self.status_label, 1)
        sb.addPermanentWidget(self.progress)
        sb.addPermanentWidget(self.cancel_button)
        sb.addPermanentWidget(self.run_label)
        sb.addPermanentWidget(self.warnings_label)
        sb.addPermanentWidget(self.cursor_label)

    # --- params ---------------------------------------------------------------------------
    def _field_map_for(self, params: Params):
        try:
            return self.pipeline.field_map(self.drawing or Drawing(paths=()), params)
        except (GalvoError, ValueError):
            return None

    def set_params(self, params: Params, *, run: bool = True) -> None:
        """Use ``params`` (controls follow) and process again."""
        self.params = params
        self.controls.set_params(params, self._field_map_for(params))
        if run:
            self.request_run()

    def apply_changes(self, changes: dict[str, Any], final: bool = True) -> bool:
        """Change some Params fields (validated); returns False (and says why) when refused."""
        try:
            params = self.params.replace(**changes)
        except (ParamError, TypeError, ValueError) as exc:
            self.statusBar().showMessage(f"refused: {exc}", 8000)
            self.controls.set_params(self.params, self._field_map_for(self.params))
            return False
        self.params = params
        if final:
            self._throttle.stop()
            self.request_run()
        elif not self._throttle.isActive():
            self._throttle.start()
        return True

    def _on_controls_changed(self, changes: dict, final: bool) -> None:
        self.apply_changes(dict(changes), final)

    def restore_defaults(self) -> None:
        self.set_params(Params(laser=self.params.laser))

    def open_laser_dialog(self) -> None:
        dlg = LaserDialog(self.params.laser, self)
        if dlg.exec() and dlg.result_laser is not None:
            self.apply_changes({"laser": dlg.result_laser})

    # --- running --------------------------------------------------------------------------
    def request_run(self) -> int | None:
        """Process the current drawing with the current params on the worker thread."""
        if self.drawing is None or self.job_path is not None:
            return None
        from .worker import pipeline_task_safe

        return self.runner.request(pipeline_task_safe(self.pipeline, self.preview_cache,
                                                      self.drawing, self.params))

    def wait_for_result(self, timeout_s: float = 60.0) -> bool:
        """Block (processing events) until the worker is idle (tests, --screenshot)."""
        return self.runner.wait_idle(timeout_s)

    def cancel_processing(self) -> None:
        if self.runner.busy:
            self.runner.cancel()
            self.statusBar().showMessage("Processing cancelled — the last result stays shown",
                                         6000)

    def _on_busy_changed(self, busy: bool) -> None:
        if busy:
            self._busy_timer.start()
        else:
            self._busy_timer.stop()
            self.progress.hide()
            self.cancel_button.hide()

    def _update_busy(self) -> None:
        ms = self.runner.elapsed_ms()
        long_run = self.runner.busy and ms >= BUSY_DELAY_MS
        self.progress.setVisible(long_run)
        self.cancel_button.setVisible(long_run)
        if long_run:
            self.run_label.setText(f"processing… {ms / 1000:.1f} s")

    def _on_result(self, gen: int, result: RunResult) -> None:
        self.apply_result(result)
        self.result_shown.emit(gen)

    def _on_failed(self, gen: int, message: str, user_facing: bool) -> None:
        self.run_error = message
        self.warnings_panel.set_warnings(self.result.job.warnings if self.result else (),
                                         error=message)
        self.statusBar().showMessage(message, 10_000)
        self.run_label.setText("processing failed")

    def _on_cancelled(self, gen: int) -> None:
        if not self.runner.busy:
            self.run_label.setText("cancelled")

    def apply_result(self, result: RunResult) -> None:
        """Show a finished run: layers, field, stats, warnings, conversions."""
        self.result = result
        self.run_error = getattr(result, "error", None)
        pv = result.preview
        ut = units_transform(pv.units_scale, pv.units_offset)
        bt = scale_transform(pv.mm_per_bit)
        o, p = self.original, self.processed
        show_points = len(pv.original_points) < views_mod.MAX_MARKER_POINTS
        o.set_layer("original", pv.original.xy, transform=ut, count=pv.original.n_vertices)
        o.set_layer("original_points", pv.original_points if show_points else
                    np.empty((0, 2)), transform=ut)
        self.markers_shown = show_points and len(pv.original_points) > 0
        p.set_layer("fitted", pv.fitted.xy, transform=ut, count=pv.fitted.n_vertices)
        p.set_layer("control", pv.control_xy, pv.control_role, transform=ut,
                    count=pv.n_control_points)
        p.set_layer("marks", pv.marks, transform=bt)
        p.set_layer("jumps", pv.jumps, transform=bt, count=len(pv.jumps) // 3 + (
            1 if len(pv.jumps) else 0))
        p.set_layer("hatch", pv.hatch.xy, transform=bt, count=pv.hatch.n_vertices)
        p.set_layer("kerf", pv.kerf.xy, transform=ut, count=pv.kerf.n_vertices)
        p.set_layer("deviation", pv.deviation_a, pv.deviation_b, pv.deviation_level,
                    transform=ut)
        fm = pv.field_map
        label = f"field {fm.field_size_mm:g} mm ({_fmt_int(fm.field_bits)} bits)"
        for v in (o, p):
            v.set_field(pv.field_outline, label)
            v.bounds = pv.bounds
        if self.layer_boxes["deviation"].isChecked():
            p.set_colorbar(True, pv.tolerance_um)
        if self.selected is not None:
            self._show_selection(self.selected)
        size_units = None
        bb = self._drawing_bbox
        if result.drawing is self.drawing and bb is not None:
            size_units = (bb[2] - bb[0], bb[3] - bb[1])
        self.controls.set_field_map(fm, size_units)
        if self.params.fit_field:
            self.controls.sliders["magnification"].set_value(fm.magnification)
        stats = dict(result.job.stats) if result.job is not None else {}
        extra = {}
        if len(pv.deviation_err):
            extra["max_deviation_um"] = pv.max_deviation_um
        self.stats_panel.set_stats(stats, extra)
        self.warnings_panel.set_warnings(result.job.warnings, error=self.run_error)
        stages = ", ".join(result.stages_run) or "cached"
        self.run_label.setText(f"{result.seconds * 1000:.0f} ms ({stages})")
        o.update_legend()
        p.update_legend()
        if self._fit_pending:
            self._fit_pending = False
            self.fit()
        self.last_result_time = time.perf_counter()
        self._update_status()

    # --- layers ---------------------------------------------------------------------------
    def set_layer_visible(self, key: str, visible: bool) -> None:
        for v in (self.original, self.processed):
            v.set_layer_visible(key, visible)
        if key in self.layer_actions and self.layer_actions[key].isChecked() != visible:
            self.layer_actions[key].setChecked(visible)
        if key == "deviation":
            top = self.result.preview.tolerance_um if self.result is not None else 1.0
            self.processed.set_colorbar(visible, top)
        self.settings.setValue(f"layers/{key}", visible)

    def layer_visible(self, key: str) -> bool:
        return self.layer_boxes[key].isChecked()

    # --- data -----------------------------------------------------------------------------
    def set_drawing(self, drawing: Drawing, path: str | os.PathLike | None = None) -> None:
        """Show ``drawing`` and process it (on the worker)."""
        self._leave_job_mode()
        self.drawing = drawing
        self._drawing_bbox = drawing.bbox()
        self.file_path = FsPath(path) if path is not None else None
        self.selected = None
        self._fit_pending = True
        self._watch(self.file_path)
        self._update_title()
        self._update_status()
        self.controls.set_params(self.params, self._field_map_for(self.params))
        self.request_run()

    def fit(self) -> None:
        """Zoom both (linked) views to what they show."""
        boxes = [b for b in (self.original.bounds, self.processed.bounds) if b is not None]
        if not boxes:
            self.original.fit()
            return
        self.original.fit((min(b[0] for b in boxes), min(b[1] for b in boxes),
                           max(b[2] for b in boxes), max(b[3] for b in boxes)),
                          top_px=self._legend_px())

    def _legend_px(self) -> float:
        return max(self.original.legend_height(), self.processed.legend_height())

    def fit_field_view(self) -> None:
        if self.result is not None:
            out = self.result.preview.field_outline
            self.original.fit((0.0, 0.0, float(out[:, 0].max()), float(out[:, 1].max())))
        else:
            self.original.set_empty_range()

    # --- loading --------------------------------------------------------------------------
    def open_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open HP-GL file", self._last_dir, FILE_FILTER)
        if path:
            self.load_file(path)

    def open_job_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open job file", self._last_dir, JOB_FILTER)
        if path:
            self.load_job_file(path)

    def load_file(self, path: str | os.PathLike) -> bool:
        """Read and show ``path`` (a job file when it ends in .json); on any failure show an
        error dialog and keep the current drawing. Returns True when the file was loaded."""
        path = FsPath(path)
        self._last_dir = str(path.parent)
        self.settings.setValue("last_dir", self._last_dir)
        if path.suffix.lower() == ".json":
            return self.load_job_file(path)
        try:
            drawing = load_drawing(path)
        except Exception as exc:  # noqa: BLE001 - InputError, OSError or a bug: a dialog
            self.show_error(describe_load_error(path, exc))
            return False
        previous, previous_path = self.drawing, self.file_path
        try:
            self.set_drawing(drawing, path)
        except Exception as exc:  # noqa: BLE001
            self._restore(previous, previous_path)
            self.show_error(describe_load_error(path, exc))
            return False
        self._add_recent(path)
        return True

    def load_job_file(self, path: str | os.PathLike) -> bool:
        """Show a job file's strokes and marks (no processing); the original view shows the
        source drawing when a file of that name and checksum sits beside the job."""
        path = FsPath(path)
        try:
            job = load_job(path)
        except Exception as exc:  # noqa: BLE001
            self.show_error(describe_load_error(path, exc), "Cannot open job file")
            return False
        source = self._find_source(path, job)
        self.runner.cancel()
        self.drawing = source
        self._drawing_bbox = source.bbox() if source is not None else None
        self.file_path = None
        self.job_path = path
        self.selected = None
        self._fit_pending = True
        self._watch(None)
        self.controls.setEnabled(False)
        where = f"; original from {source.name}" if source is not None else (
            "; its source file was not found beside it, so the original view is empty")
        self.banner.setText(f"Showing the job file {path.name} as written (processing controls "
                            f"are inactive{where}). Open a PLT file to process again.")
        self.banner.show()
        self._add_recent(path)
        self._update_title()
        self._update_status()
        self.runner.request(job_task(job, source, self.preview_cache))
        return True

    def _find_source(self, job_path: FsPath, job: Job) -> Drawing | None:
        if not job.source_name:
            return None
        cand = job_path.parent / FsPath(job.source_name).name
        if not cand.is_file():
            return None
        try:
            d = load_drawing(cand)
        except Exception:  # noqa: BLE001 - the original is optional
            return None
        if job.source_sha256 and d.sha256 and d.sha256 != job.source_sha256:
            return None
        return d

    def _leave_job_mode(self) -> None:
        if self.job_path is not None:
            self.job_path = None
            self.controls.setEnabled(True)
            self.banner.hide()

    def reload(self) -> bool:
        if self.job_path is not None:
            return self.load_job_file(self.job_path)
        if self.file_path is None:
            return False
        return self.load_file(self.file_path)

    def _restore(self, drawing: Drawing | None, path: FsPath | None) -> None:
        try:
            if drawing is not None:
                self.set_drawing(drawing, path)
            else:
                self.drawing = None
                self.file_path = None
                self._update_title()
                self._update_status()
        except Exception:  # noqa: BLE001 - nothing more can be done; the dialog follows
            pass

    # --- file watching --------------------------------------------------------------------
    def _watch(self, path: FsPath | None) -> None:
        old = self.watcher.files()
        if old:
            self.watcher.removePaths(old)
        if path is not None and path.is_file():
            self.watcher.addPath(str(path))

    def _on_file_changed(self, path: str) -> None:
        self._reload_timer.start()

    def _reload_changed(self) -> None:
        """The watched file changed on disk: reload it; a refused version keeps the current
        drawing and says so in the status bar (no dialog for a file still being written)."""
        path = self.file_path
        if path is None:
            return
        if not path.is_file():  # replaced by rename: try again shortly
            self._reload_timer.start(500)
            return
        try:
            drawing = load_drawing(path)
        except Exception as exc:  # noqa: BLE001
            self.statusBar().showMessage(f"not reloaded: {describe_load_error(path, exc)}",
                                         10_000)
            self._watch(path)
            return
        keep = self.selected
        self.set_drawing(drawing, path)
        self._fit_pending = False
        self.selected = keep
        self.statusBar().showMessage(f"{path.name} changed on disk: reloaded", 5000)

    # --- recent files ---------------------------------------------------------------------
    def recent_files(self) -> list[str]:
        v = self.settings.value("recent_files", [])
        if isinstance(v, str):
            v = [v]
        return [str(x) for x in (v or [])]

    def _add_recent(self, path: FsPath) -> None:
        p = str(FsPath(path).resolve())
        items = [p] + [x for x in self.recent_files() if x != p]
        self.settings.setValue("recent_files", items[:MAX_RECENT])
        self._rebuild_recent_menu()

    def _rebuild_recent_menu(self) -> None:
        self.recent_menu.clear()
        items = self.recent_files()
        for p in items:
            a = self.recent_menu.addAction(FsPath(p).name)
            a.setToolTip(p)
            a.setStatusTip(p)
            a.triggered.connect(lambda _=False, p=p: self.load_file(p))
        self.recent_menu.setEnabled(bool(items))

    # --- export ---------------------------------------------------------------------------
    def _refresh_export_actions(self) -> None:
        ex = exporters()
        self.export_plt_action.setEnabled("write_plt" in ex)
        self.export_svg_action.setEnabled("write_svg" in ex)
        for a, name in ((self.export_plt_action, "write_plt"),
                        (self.export_svg_action, "write_svg")):
            a.setToolTip("" if name in ex else "galvo_core.export is not available")

    def export_dialog(self, kind: str) -> None:
        filters = {"job": "Job files (*.json)", "plt": "HP-GL files (*.plt)",
                   "svg": "SVG files (*.svg)", "png": "PNG images (*.png)"}
        stem = FsPath(self.file_name() or "untitled").stem
        suggested = str(FsPath(self._last_dir) / f"{stem}.{'json' if kind == 'job' else kind}")
        path, _ = QFileDialog.getSaveFileName(self, f"Export {kind.upper()}", suggested,
                                              filters[kind])
        if path:
            self.export(kind, path)

    def export(self, kind: str, path: str | os.PathLike) -> bool:
        """Write the current job (json/plt/svg) or a PNG of the views. Atomic: a failure
        leaves no half-written file, and says why in a dialog."""
        path = FsPath(path)
        try:
            if kind == "png":
                atomic_write_bytes(path, self.views_png())
            else:
                job = self.result.job if self.result is not None else None
                if job is None:
                    raise GalvoError("nothing to export: open a file first")
                if kind == "job":
                    write_job(job, path)
                else:
                    fn = exporters().get(f"write_{kind}")
                    if fn is None:
                        raise GalvoError(f"{kind.upper()} export is not available")
                    fn(job, path)
        except Exception as exc:  # noqa: BLE001 - GalvoError, OSError or a bug: a dialog
            msg = str(exc) if isinstance(exc, GalvoError) else (
                f"{path.name}: {type(exc).__name__}: {exc}")
            self.show_error(msg, "Export failed")
            return False
        self.statusBar().showMessage(f"exported {path}", 6000)
        return True

    def views_png(self) -> bytes:
        """Both views (as shown) as PNG bytes."""
        image = self.splitter.grab().toImage()
        data = QByteArray()
        buf = QBuffer(data)
        buf.open(QIODevice.OpenModeFlag.WriteOnly)
        if not image.save(buf, "PNG"):
            raise GalvoError("cannot encode the PNG image")
        buf.close()
        return bytes(data.data())

    # --- errors ---------------------------------------------------------------------------
    def build_error_dialog(self, message: str, title: str = "Cannot open file") -> QMessageBox:
        """The error dialog for ``message`` (separate from showing it, for tests)."""
        box = QMessageBox(self)
        box.setIcon(QMessageBox.Icon.Critical)
        box.setWindowTitle(f"{title} — {APP_NAME}")
        box.setText(title)
        box.setInformativeText(message)
        box.setStandardButtons(QMessageBox.StandardButton.Ok)
        box.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        box.setStyleSheet("QLabel#qt_msgbox_informativelabel { min-width: 380px; }")
        return box

    def show_error(self, message: str, title: str = "Cannot open file") -> None:
        """Show ``message`` in a modal error dialog."""
        self.last_error = message
        self.statusBar().showMessage(message, 10_000)
        self.build_error_dialog(message, title).exec()

    # --- drag and drop --------------------------------------------------------------------
    @staticmethod
    def _local_files(event) -> list[str]:
        mime = event.mimeData()
        if not mime.hasUrls():
            return []
        return [u.toLocalFile() for u in mime.urls() if u.isLocalFile() and u.toLocalFile()]

    def dragEnterEvent(self, event: QDragEnterEvent) -> None:  # noqa: N802 - Qt API
        if self._local_files(event):
            event.acceptProposedAction()
        else:
            event.ignore()

    def dragMoveEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._local_files(event):
            event.acceptProposedAction()
        else:
            event.ignore()

    def dropEvent(self, event: QDropEvent) -> None:  # noqa: N802 - Qt API
        files = self._local_files(event)
        if not files:
            event.ignore()
            return
        event.acceptProposedAction()
        self.load_file(files[0])
        if len(files) > 1:
            self.statusBar().showMessage(
                f"{len(files)} files dropped: opened only {FsPath(files[0]).name}", 8_000
            )

    # --- selection, hover, warnings -------------------------------------------------------
    def _on_mouse_moved(self, view: WorkView, scene_pos) -> None:
        vb = view.getPlotItem().getViewBox()
        if not vb.sceneBoundingRect().contains(scene_pos):
            self.cursor_label.setText("")
            return
        p = vb.mapSceneToView(scene_pos)
        self.cursor_label.setText(self.cursor_text(p.x(), p.y()))

    def cursor_text(self, x_mm: float, y_mm: float) -> str:
        """Status-bar text for a cursor position in mm: mm, input units, galvo bits."""
        text = f"x {x_mm:8.3f}  y {y_mm:8.3f} mm"
        if self.result is not None:
            pv = self.result.preview
            u = pv.mm_to_units(np.array([x_mm, y_mm]))
            b = pv.mm_to_bits(np.array([x_mm, y_mm]))
            text += f" │ {u[0]:.1f}, {u[1]:.1f} u │ X {b[0]:.0f}  Y {b[1]:.0f} bits"
        return text

    def _on_mouse_clicked(self, view: WorkView, ev) -> None:
        if ev.button() != Qt.MouseButton.LeftButton or self.result is None:
            return
        vb = view.getPlotItem().getViewBox()
        if not vb.sceneBoundingRect().contains(ev.scenePos()):
            return
        p = vb.mapSceneToView(ev.scenePos())
        self.select_at(p.x(), p.y(), view)

    def select_at(self, x_mm: float, y_mm: float, view: WorkView | None = None) -> int | None:
        """Select the path nearest to (x, y) mm (within ~8 pixels); None clears."""
        if self.result is None:
            return None
        radius = 8.0 * (view or self.original).mm_per_pixel()
        idx = self.result.preview.pick(x_mm, y_mm, radius)
        self.select_path(idx)
        return idx

    def select_path(self, index: int | None) -> None:
        """Highlight a source path in both views and show its counts (None clears)."""
        self.selected = index
        self._show_selection(index)

    def _show_selection(self, index: int | None) -> None:
        from galvo_core.preview import path_summary

        empty = np.empty((0, 2))
        res = self.result
        if index is None or res is None:
            ut = units_transform(1.0, (0.0, 0.0))
            self.original.set_highlight(empty, ut)
            self.processed.set_highlight(empty, ut)
            self.stats_panel.set_selection("Click a path to see its counts.")
            return
        pv = res.preview
        ut = units_transform(pv.units_scale, pv.units_offset)
        left, right = pv.path_geometry(index)
        self.original.set_highlight(left, ut)
        self.processed.set_highlight(right, ut)
        info = path_summary(index, res.job, res.drawing, res.fitted)
        self.selection_info = info
        parts = [f"<b>Path {index + 1}</b>"]
        names = (("input_points", "input points"), ("control_points", "control points"),
                 ("lines", "lines"), ("cubics", "cubics"), ("mark_points", "marks"),
                 ("hatch_marks", "hatch marks"))
        for key, label in names:
            if key in info:
                parts.append(f"{_fmt_int(int(info[key]))} {label}")
        if "mark_length_mm" in info:
            parts.append(f"{info['mark_length_mm']:.2f} mm marked")
        if "max_fit_error_um" in info:
            parts.append(f"fit error ≤ {info['max_fit_error_um']:.3g} µm")
        if info.get("closed"):
            parts.append("closed")
        self.stats_panel.set_selection(" · ".join(parts))

    def zoom_to_warning(self, index: int) -> None:
        """Zoom both views to a warning's place: the path starting nearest its file position,
        or everything when it has none."""
        from galvo_core.preview import warning_path

        if index < 0 or self.result is None or index >= len(self.warnings_panel.warnings):
            self.fit()
            return
        w = self.warnings_panel.warnings[index]
        path = warning_path(self.result.drawing, w)
        box = self.result.preview.path_bounds(path) if path is not None else None
        if box is None:
            self.fit()
            return
        self.select_path(path)
        pad = max(box[2] - box[0], box[3] - box[1], 1.0) * 0.5
        self.original.fit((box[0] - pad, box[1] - pad, box[2] + pad, box[3] + pad),
                          top_px=self._legend_px())

    # --- title and status -----------------------------------------------------------------
    def file_name(self) -> str:
        if self.job_path is not None:
            return self.job_path.name
        if self.file_path is not None:
            return self.file_path.name
        if self.drawing is not None and self.drawing.name:
            return self.drawing.name
        return ""

    def _update_title(self) -> None:
        name = self.file_name()
        if self.drawing is None and self.job_path is None:
            self.setWindowTitle(APP_NAME)
        else:
            self.setWindowTitle(f"{name or 'untitled'} — {APP_NAME}")

    def _size_mm(self, d: Drawing) -> tuple[float, float]:
        """``d.size_mm()``, kept per drawing (a bbox over every point: too slow per run)."""
        cached = getattr(self, "_size_mm_of", None)
        if cached is None or cached[0] is not d:
            cached = (d, d.size_mm())
            self._size_mm_of = cached
        return cached[1]

    def status_summary(self) -> str:
        """The counts shown in the status bar, as plain text."""
        d = self.drawing
        if d is None:
            if self.job_path is not None:
                return f"job file {self.job_path.name}"
            return "No file — File ▸ Open… or drop an HP-GL file onto the window"
        w, h = self._size_mm(d)
        return "   ·   ".join(
            [
                f"{_fmt_int(len(d.paths))} paths",
                f"{_fmt_int(d.n_points)} points",
                f"{_fmt_int(d.n_closed)} closed",
                f"{w:.2f} × {h:.2f} mm",
                f"{_fmt_int(len(d.warnings))} warning{'s' if len(d.warnings) != 1 else ''}",
                self.file_name() or "untitled",
            ]
        )

    def _update_status(self) -> None:
        self.status_label.setText(self.status_summary())
        n_warn = len(self.result.job.warnings) if self.result is not None else 0
        if self.run_error:
            self.warnings_label.setText("✖ error")
            self.warnings_label.setStyleSheet("color: #b00020; font-weight: bold;")
        elif n_warn:
            self.warnings_label.setText(f"⚠ {n_warn}")
            self.warnings_label.setStyleSheet("color: #b35c00; font-weight: bold;")
        else:
            self.warnings_label.setText("")

    # --- settings -------------------------------------------------------------------------
    def _restore_state(self) -> None:
        s = self.settings
        text = s.value("params")
        if isinstance(text, str) and text:
            self.params = params_from_json(text)
        for spec in LAYERS:
            v = s.value(f"layers/{spec.key}")
            if v is not None:
                on = v in (True, "true", "1", 1)
                self.layer_boxes[spec.key].setChecked(on)
        geo = s.value("window/geometry")
        if geo is not None:
            self.restoreGeometry(geo)
        state = s.value("window/state")
        if state is not None:
            self.restoreState(state)

    def save_state(self) -> None:
        s = self.settings
        s.setValue("params", params_to_json(self.params))
        s.setValue("window/geometry", self.saveGeometry())
        s.setValue("window/state", self.saveState())
        s.setValue("last_dir", self._last_dir)
        s.sync()

    def closeEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._restore_settings:
            self.save_state()
        self.runner.shutdown()
        super().closeEvent(event)
