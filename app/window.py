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
import re
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path as FsPath
from typing import Any

import numpy as np
from PySide6.QtCore import (
    QBuffer,
    QByteArray,
    QFileSystemWatcher,
    QIODevice,
    QObject,
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
    QApplication,
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

from galvo_core import params as params_mod
from galvo_core.drawing import Drawing
from galvo_core.errors import GalvoError, ParamError
from galvo_core.export import write_plt, write_svg
from galvo_core.job import Job, atomic_write_bytes, load_job, write_job
from galvo_core.params import Params
from galvo_core.pipeline import Pipeline
from galvo_core.preview import PreviewCache

from . import views as views_mod
from .controls import ControlsPanel, LaserDialog
from .flow import flow_container
from .stats import StatsPanel, WarningsPanel
from .views import LAYERS, WorkView, scale_transform, units_transform
from .worker import (
    LatestRunner,
    Loaded,
    LoadedJob,
    PreparedCache,
    RunResult,
    export_task,
    job_load_task,
    job_task,
    layer_arrays,
    load_task,
)

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
#: Dim the views as out of date when a run of new parameters takes longer than this (ms);
#: a result of another file is marked at once.
STALE_DELAY_MS = 400
MAX_RECENT = 8
#: The interpreter's thread switch interval while a window is open (s; Python's default is
#: 5 ms). The GUI thread shares the GIL with the workers, and every Qt call that releases
#: it (each painter call of a paint) must win it back: with a worker busy in Python code
#: each takes up to a whole interval, so a 10 ms paint took 40-60 ms while a file
#: processed. 1 ms keeps such waits short at a small cost in switches for the worker.
SWITCH_INTERVAL_S = 0.001
#: What a new file or result replaces (the last file's drawing, result and caches) is let go
#: this long after (ms): freeing 40 k paths with their fits, strokes and display data takes
#: the GUI thread 10-20 ms, which then no longer adds to the new result's apply and paint.
RELEASE_DELAY_MS = 150
#: ...and in event-loop passes of at most about this long each (s): dropping the last
#: reference to a file's result frees it in one C-level cascade that holds the GIL (23-45 ms
#: of the GUI thread on 40 k-path files, a stall of its own); see :class:`_Reaper`.
RELEASE_STEP_S = 0.004
#: The processed view paints after the original (see MainWindow._stagger_paints), at the
#: latest this long after a result (ms).
STAGGER_MAX_MS = 80

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


def _read_for_gui(path: FsPath) -> Drawing:
    """:func:`load_drawing` with any failure turned into one line for the user."""
    try:
        return load_drawing(path)
    except Exception as exc:  # noqa: BLE001 - InputError, OSError or a bug: one line
        raise GalvoError(describe_load_error(path, exc)) from None


def _read_job_for_gui(path: FsPath) -> Job:
    from .offload import load_job_file

    try:
        return load_job_file(path, load_job)
    except Exception as exc:  # noqa: BLE001
        raise GalvoError(describe_load_error(path, exc)) from None


def bundled_sample() -> FsPath | None:
    """The first ``*.plt`` in ``resources/samples`` (sorted by name), or None."""
    if not SAMPLES_DIR.is_dir():
        return None
    found = sorted(p for p in SAMPLES_DIR.iterdir() if p.suffix.lower() == ".plt" and p.is_file())
    return found[0] if found else None


@dataclass(frozen=True)
class ExportKind:
    """One kind of File ▸ Export: the menu text, the save dialog's filter and suffix, the
    writer ``write(job, path)`` (atomic), and what the status bar says about the file after
    writing it. Other modules add kinds to :attr:`MainWindow.export_kinds` (then call
    :meth:`MainWindow.rebuild_export_menu`)."""

    label: str
    file_filter: str
    suffix: str
    write: Callable[[Job, FsPath], None]
    note: str = ""


def default_export_kinds() -> dict[str, ExportKind]:
    return {
        "job": ExportKind("Export &Job (JSON)…", "Job files (*.json)", ".json", write_job,
                          "job file"),
        "plt": ExportKind("Export &PLT (galvo bits)…", "HP-GL files (*.plt)", ".plt",
                          write_plt, "HP-GL of the marks in galvo bits (1 plotter unit = "
                          "1 bit, not 40 units per mm)"),
        "svg": ExportKind("Export &SVG (mm)…", "SVG files (*.svg)", ".svg", write_svg,
                          "SVG of the fitted geometry in mm on the workpiece"),
    }


def _user_path_message(text: str, path: FsPath) -> str:
    """An error text that names the user's file, never the temporary file of an atomic
    write (``.tmp-…`` beside it)."""
    return re.sub(r"\S*\.tmp-[^\s:;,)]*", str(path), text)


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


class _Reaper:
    """Frees objects in short event-loop passes (:data:`RELEASE_STEP_S` each) instead of in
    one cascade: an object that only the reaper holds is opened up first (its referents,
    ``gc.get_referents``, are taken over, so dropping it frees nothing else), the items of
    a big container (more than 64 referents: the tuples of 40 k paths, strokes, fits) are
    dropped a few at a time, each freeing its own small subtree. Objects that something
    else still references are merely let go (never changed: a result may share its drawing
    with the one on screen)."""

    def __init__(self, parent: QObject) -> None:
        import collections

        self.queue: collections.deque[tuple[object, bool]] = collections.deque()
        self.timer = QTimer(parent)
        self.timer.setSingleShot(True)
        self.timer.setInterval(0)
        self.timer.timeout.connect(self.step)
        self.longest_s = 0.0  # the longest pass, GUI-thread CPU time (benchmarks)

    def add(self, objs: list[object]) -> None:
        self.queue.extend((o, True) for o in objs)
        del objs[:]
        if self.queue and not self.timer.isActive():
            self.timer.start()

    def step(self) -> None:
        import gc

        c0 = time.thread_time()
        end = time.perf_counter() + RELEASE_STEP_S
        q = self.queue
        n = 0
        while q:
            o, expand = q.popleft()
            # 3 references: this frame's, getrefcount's argument and the caller's tuple's
            # (already gone: unpacked) -> 2 when nothing else holds it
            if expand and sys.getrefcount(o) <= 2:
                kids = gc.get_referents(o)
                q.extendleft((k, len(kids) <= 64) for k in reversed(kids))
                del kids
            del o
            n += 1
            if not n & 15 and time.perf_counter() > end:
                break
        self.longest_s = max(self.longest_s, time.thread_time() - c0)
        if q:
            self.timer.start()

    def busy(self) -> bool:
        return bool(self.queue)


class MainWindow(QMainWindow):
    """The workstation: two linked views, layer toggles, processing controls, job panel."""

    #: emitted after a result has been handed to the views (generation)
    result_shown = Signal(int)

    def __init__(self, drawing: Drawing | None = None, parent: QWidget | None = None, *,
                 settings: QSettings | None = None, restore: bool = True) -> None:
        super().__init__(parent)
        if sys.getswitchinterval() > SWITCH_INTERVAL_S:
            sys.setswitchinterval(SWITCH_INTERVAL_S)
        self.settings = settings if settings is not None else app_settings()
        self._restore_settings = restore
        self.drawing: Drawing | None = None
        self.file_path: FsPath | None = None
        self.job_path: FsPath | None = None
        self.params = Params()
        self.pipeline = Pipeline()
        self.preview_cache = PreviewCache()
        self.prepared_cache = PreparedCache()
        self.result: RunResult | None = None
        self.run_error: str | None = None
        self.selected: int | None = None
        self._last_dir = str(self.settings.value("last_dir", str(FsPath.cwd())))
        self._fit_pending = False
        self._drawing_bbox: tuple[float, float, float, float] | None = None
        #: The message of the last error dialog (kept for tests and logs).
        self.last_error: str | None = None
        self.last_result_time = 0.0
        #: the file being read on the worker (None when none)
        self.loading_path: FsPath | None = None
        #: True/False: how the last load_file/load_job_file ended; None while it runs
        self.last_load_ok: bool | None = None
        #: True/False: how the last export ended; None while it runs
        self.last_export_ok: bool | None = None
        self._keep_selection: int | None = None
        self._undo: list[Params] = []
        self._redo: list[Params] = []
        self._committed: Params | None = None
        self._reloading = False
        self._fit_banner = False
        #: the banner's text once the next result is shown ("" hides it; None: no change):
        #: the banner speaks of the result shown, and changing it resizes the views (a
        #: full repaint of both), which the new result's paint then includes
        self._banner_next: str | None = None
        self._stale_shown = False
        #: File ▸ Export kinds (other modules may add to it, then rebuild_export_menu())
        self.export_kinds: dict[str, ExportKind] = default_export_kinds()

        self.setObjectName("MainWindow")
        if ICON_PATH.is_file():
            self.setWindowIcon(QIcon(str(ICON_PATH)))
        self.setAcceptDrops(True)
        self.setMinimumSize(480, 320)
        self.setDockOptions(QMainWindow.DockOption.AnimatedDocks
                            | QMainWindow.DockOption.AllowTabbedDocks)

        self._build_views()
        self._build_layer_bar()
        self._build_central()
        self._build_controls_dock()
        self._build_job_dock()
        self._build_workers()
        self._build_menus()
        self._build_status_bar()
        from .layers_dock import LayersDock
        self.layers = LayersDock(self)  # the layer table, pen table files, LMC export
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
        self._committed = self.params
        if drawing is not None:
            self.set_drawing(drawing)
        else:
            self._update_title()
            self._update_status()

    # --- UI construction ------------------------------------------------------------------
    def _build_views(self) -> None:
        """The two views (original, processed), linked, side by side in a splitter."""
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

    def _build_layer_bar(self) -> None:
        """The layer check boxes above the views (they wrap in a narrow window)."""
        self.layer_boxes: dict[str, QCheckBox] = {}
        layer_bar, bar = flow_container()  # wraps to a second row in a narrow window
        layer_bar.setObjectName("layer_bar")
        bar.setContentsMargins(6, 2, 6, 2)
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
        self.layer_bar = layer_bar

    def _build_central(self) -> None:
        """The banner, the views, the stale bar over them and the simulation bar."""
        self.banner = QLabel("")
        self.banner.setObjectName("banner")
        self.banner.setWordWrap(True)
        self.banner.setStyleSheet(
            "background: #fff4e5; color: #663c00; padding: 3px 8px; border-bottom: 1px solid "
            "#f0c080;")
        self.banner.hide()

        #: says that the views show an older result than the file/parameters asked for
        self.stale_bar = QLabel("")
        self.stale_bar.setObjectName("stale_bar")
        self.stale_bar.setWordWrap(True)
        self.stale_bar.setStyleSheet(
            "background: #e8eef7; color: #1d3557; padding: 3px 8px; border-top: 1px solid "
            "#a8bcd8;")
        self.stale_bar.hide()

        central = QWidget()
        cl = QVBoxLayout(central)
        cl.setContentsMargins(0, 0, 0, 0)
        cl.setSpacing(0)
        cl.addWidget(self.layer_bar)
        cl.addWidget(self.banner)
        cl.addWidget(self.splitter, 1)
        self._build_simulation_bar()
        cl.addWidget(self.sim_bar)
        self.setCentralWidget(central)
        # the stale bar floats over the top of the views: showing it must not resize them
        # (a resize re-rasterises every cached layer)
        self.stale_bar.setParent(central)
        self.stale_bar.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents)
        self._central = central

    def _build_controls_dock(self) -> None:
        """The Processing dock: the controls generated from the parameter model."""
        self.controls = ControlsPanel(self.params)
        self.controls.changed.connect(self._on_controls_changed)
        self.controls.laser_requested.connect(self.open_laser_dialog)
        self.controls.defaults_button.clicked.connect(self.restore_defaults)
        mag = self.controls.sliders.get("magnification")
        if mag is not None:
            # the box shows and takes any magnification down to its last decimal, e.g. the
            # 0.09 Fit field computes for a big drawing (the slider keeps its range)
            mag.spin.setMinimum(10.0 ** -mag.spin.decimals())
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

    def _build_job_dock(self) -> None:
        """The Job dock: stats and warnings."""
        self.stats_panel = StatsPanel()
        self.warnings_panel = WarningsPanel()
        self.warnings_panel.activated.connect(self.zoom_to_warning)
        self.warnings_panel.translate = self.gui_message
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

    def _build_workers(self) -> None:
        """The workers (runs, file reads, exports), the throttle and the file watcher."""
        self.runner = LatestRunner(self)
        self.runner.finished.connect(self._on_result)
        self.runner.failed.connect(self._on_failed)
        self.runner.cancelled.connect(self._on_cancelled)
        self.runner.busy_changed.connect(self._on_busy_changed)
        # reading files (HP-GL, job files) and writing exports: each on its own worker
        self.io = LatestRunner(self)
        self.io.finished.connect(self._on_loaded)
        self.io.failed.connect(self._on_load_failed)
        self.io.cancelled.connect(lambda gen: self._on_cancelled(gen))
        self.io.busy_changed.connect(self._on_busy_changed)
        self.exporter = LatestRunner(self)
        self.exporter.finished.connect(self._on_exported)
        self.exporter.failed.connect(self._on_export_failed)
        self.exporter.busy_changed.connect(self._on_busy_changed)
        self._export_target: tuple[str, FsPath] | None = None
        self._released: list[object] = []
        self._reaper = _Reaper(self)
        self._release_timer = QTimer(self)
        self._release_timer.setSingleShot(True)
        self._release_timer.setInterval(RELEASE_DELAY_MS)
        self._release_timer.timeout.connect(self._hand_to_reaper)
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
        self.export_menu = file_menu.addMenu("&Export")
        self.export_actions: dict[str, QAction] = {}
        self.export_png_action = QAction("Export P&NG of the Views…", self)
        self.export_png_action.triggered.connect(lambda: self.export_dialog("png"))
        self.rebuild_export_menu()
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
        self.sim_action = QAction("Marking &Simulation", self, checkable=True)
        self.sim_action.setShortcut(QKeySequence("Ctrl+M"))
        self.sim_action.toggled.connect(self.set_simulation)
        view_menu.addAction(self.sim_action)
        self.ruler_action = QAction("&Ruler (click two points)", self, checkable=True)
        self.ruler_action.setShortcut(QKeySequence("R"))
        self.ruler_action.toggled.connect(self.set_ruler)
        view_menu.addAction(self.ruler_action)
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

        edit = self.menuBar().addMenu("&Edit")
        self.undo_action = QAction("&Undo Parameter Change", self)
        self.undo_action.setShortcut(QKeySequence.StandardKey.Undo)
        self.undo_action.triggered.connect(self.undo)
        self.redo_action = QAction("&Redo Parameter Change", self)
        self.redo_action.setShortcuts([QKeySequence.StandardKey.Redo,
                                       QKeySequence("Ctrl+Shift+Z")])
        self.redo_action.triggered.connect(self.redo)
        edit.addAction(self.undo_action)
        edit.addAction(self.redo_action)
        self._update_undo_actions()

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
        self.cursor_label.setMinimumWidth(0)
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

    def set_params(self, params: Params, *, run: bool = True, record: bool = False) -> None:
        """Use ``params`` (controls follow) and process again; ``record``: as an operator's
        change that Undo takes back."""
        if record:
            self._record(params)
        else:
            self._committed = params
        self.params = params
        self.controls.set_params(params, self._field_map_for(params))
        if run:
            self.request_run()

    # --- undo / redo of parameter changes -------------------------------------------------
    #: how many parameter changes Undo remembers
    UNDO_DEPTH = 200

    def _record(self, params: Params) -> None:
        """A committed change to ``params``: the previous committed set goes on the undo
        stack (drags are not recorded, only their release)."""
        prev = getattr(self, "_committed", None)
        if prev is not None and prev != params:
            self._undo.append(prev)
            del self._undo[:-self.UNDO_DEPTH]
            self._redo.clear()
        self._committed = params
        self._update_undo_actions()

    def undo(self) -> bool:
        """Back to the parameters before the last change (False when there is none)."""
        if not self._undo:
            return False
        self._redo.append(self._committed)
        self.set_params(self._undo.pop())
        self._update_undo_actions()
        self.statusBar().showMessage("undone: parameters as before the last change", 4000)
        return True

    def redo(self) -> bool:
        """Again the change that Undo took back (False when there is none)."""
        if not self._redo:
            return False
        self._undo.append(self._committed)
        self.set_params(self._redo.pop())
        self._update_undo_actions()
        return True

    def _update_undo_actions(self) -> None:
        if hasattr(self, "undo_action"):
            self.undo_action.setEnabled(bool(self._undo))
            self.redo_action.setEnabled(bool(self._redo))

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
            self._record(params)
            self._throttle.stop()
            self.request_run()
        elif not self._throttle.isActive():
            self._throttle.start()
        return True

    def _on_controls_changed(self, changes: dict, final: bool) -> None:
        self.apply_changes(dict(changes), final)

    def restore_defaults(self) -> None:
        self.set_params(Params(laser=self.params.laser), record=True)

    def open_laser_dialog(self) -> None:
        dlg = LaserDialog(self.params.laser, self)
        if dlg.exec() and dlg.result_laser is not None:
            self.apply_changes({"laser": dlg.result_laser})

    # --- running ------------------------------------------------------------------------
    def wanted_layers(self) -> frozenset[str]:
        """The layers shown (their geometry is computed; the optional ones only then)."""
        return frozenset(k for k, cb in self.layer_boxes.items() if cb.isChecked())

    def request_run(self) -> int | None:
        """Process the current drawing with the current params on the worker thread."""
        if self.drawing is None or self.job_path is not None:
            return None
        from .worker import pipeline_task_safe

        gen = self.runner.request(self.layers.wrap(pipeline_task_safe(
            self.pipeline, self.preview_cache, self.drawing, self.params, self.file_path,
            self.wanted_layers(), self.prepared_cache)))
        self._update_stale()
        return gen

    def request_layers(self) -> int | None:
        """Compute the shown layers that the shown result lacks (a layer switched on) from
        its fit, on the worker, without running the pipeline again; a full run when the
        result is not the current drawing's with the current parameters and pens."""
        res = self.result
        if (res is None or res.fitted is None or res.drawing is not self.drawing
                or res.params != self.params or not self.layers.is_current(res)
                or self.runner.active):
            return self.request_run()
        from .worker import layer_task

        gen = self.runner.request(layer_task(res, self.wanted_layers(), self.preview_cache,
                                             self.prepared_cache))
        self._update_stale()
        return gen

    def gui_message(self, text: str) -> str:
        """A core message in the window's words: command-line flags (``--fit-field``)
        become the names of the controls that do the same."""
        if not text or "--" not in text:
            return text
        labels: dict[str, str] = {"fit_field": "Fit field"}
        for name, w in self.controls.sliders.items():
            labels[name] = w.spec.label.split("  ")[0]
        for name in self.controls.combos:
            labels[name] = name.replace("_", " ")

        def sub(m: re.Match[str]) -> str:
            name = m.group(1).replace("-", "_")
            return f"“{labels[name]}”" if name in labels else name.replace("_", " ")

        return re.sub(r"--([a-z][a-z0-9-]*)", sub, text)

    # --- scripting surface (tests, benchmarks, scripts) -----------------------------------
    def busy(self) -> bool:
        """True while a file is read, a run is pending or running, or an export writes."""
        return (self.io.busy or self.runner.busy or self.exporter.busy
                or self._throttle.isActive())

    def wait_idle(self, timeout_s: float = 60.0) -> bool:
        """Process events until nothing is read, processed or written (True), or until
        ``timeout_s`` passes (False)."""
        deadline = time.monotonic() + timeout_s
        app = QApplication.instance()
        while self.busy() and time.monotonic() < deadline:
            for r in (self.io, self.runner, self.exporter):
                t = r._thread  # noqa: SLF001 - wait on the worker briefly, then pump events
                if t is not None:
                    t.wait(5)
            if app is not None:
                app.processEvents()
        # the processed view's staggered paint: let it through in its own pass
        for _ in range(20):
            if app is None or self.processed.updatesEnabled():
                break
            app.processEvents()
        self._paint_processed()
        return not self.busy()

    def wait_for_result(self, timeout_s: float = 60.0) -> bool:
        """Block (processing events) until everything is idle (tests, --screenshot)."""
        return self.wait_idle(timeout_s)

    def set_param(self, name: str, value: Any) -> bool:
        """Change one parameter (a Params field, or a LaserParams field, ``laser.`` prefix
        optional) as the controls would, and process again; False (and the status bar says
        why) when refused."""
        name = name.removeprefix("laser.")
        if name not in params_mod.WHERE:
            self.statusBar().showMessage(f"refused: no parameter named {name!r}", 8000)
            return False
        ok = self.apply_changes({name: value})
        if ok:
            self.controls.set_params(self.params, self._field_map_for(self.params))
        return ok

    def current_job(self) -> Job | None:
        """The job the views show when it is current (what Export writes), else None."""
        if self.result is None or self.is_stale():
            return None
        return self.result.job

    # --- one truth on screen --------------------------------------------------------------
    def is_stale(self) -> bool:
        """True while the views do not show the result of the current file and parameters
        (a file is being read, a run is pending or running)."""
        if self.io.active or self.runner.active or self._throttle.isActive():
            return True
        res = self.result
        if res is None:
            return self.drawing is not None
        if res.job_path is not None or self.job_path is not None:
            return res.job_path != self.job_path
        return (res.drawing is not self.drawing or res.params != self.params
                or not self.layers.is_current(res))

    def shown_name(self) -> str:
        """The name of the file whose result the views show ('' when none)."""
        res = self.result
        if res is None:
            return ""
        for p in (res.job_path, res.path):
            if p is not None:
                return FsPath(p).name
        return res.drawing.name if res.drawing is not None and res.drawing.name else ""

    def pending_name(self) -> str:
        """The file being read or processed ('' when it is the shown one or none)."""
        if self.loading_path is not None:
            return self.loading_path.name
        return self.file_name()

    def _update_stale(self) -> None:
        """Mark the views stale (dimmed, with a bar saying what is pending) while they show
        an older result than asked for; a short run of the same file (< BUSY_DELAY_MS) only
        dims them when it lasts."""
        stale = self.is_stale() and self.result is not None
        other_file = stale and (self.loading_path is not None
                                or self.pending_name() != self.shown_name())
        long_run = self.runner.elapsed_ms() >= STALE_DELAY_MS or self.io.active
        show = stale and (other_file or long_run or not self.runner.active)
        if show:
            shown = self.shown_name() or "the previous drawing"
            if self.loading_path is not None:
                what = f"opening {self.loading_path.name}…"
            elif other_file:
                what = f"processing {self.pending_name()}…"
            else:
                what = "processing the new parameters…"
            self.stale_bar.setText(
                f"⟳ Showing the last result of {shown} (out of date) — {what} "
                "Esc cancels and keeps the shown result; export waits for the new one.")
        if show != self._stale_shown:
            self._stale_shown = show
            if show:
                self._place_stale_bar()
                self.stale_bar.raise_()
            self.stale_bar.setVisible(show)
            for v in (self.original, self.processed):
                v.set_stale(show)
        self._update_title()

    def _place_stale_bar(self) -> None:
        g = self.splitter.geometry()
        w = g.width()
        self.stale_bar.setFixedWidth(w)
        self.stale_bar.adjustSize()
        # along the bottom of the views (their titles stay readable)
        self.stale_bar.move(g.x(), g.y() + g.height() - self.stale_bar.height())

    def resizeEvent(self, ev) -> None:  # noqa: N802 - Qt API
        super().resizeEvent(ev)
        if self._stale_shown:
            self._place_stale_bar()

    def cancel_processing(self) -> None:
        """Stop reading/processing; the shown result stays and becomes the truth again: the
        file, the parameters and the controls go back to those of the shown result."""
        if not (self.runner.active or self.io.active or self._throttle.isActive()):
            return
        self._throttle.stop()
        self.runner.cancel()
        self.io.cancel()
        self.loading_path = None
        self._keep_selection = None
        if self.last_load_ok is None:
            self.last_load_ok = False
        res = self.result
        self._banner_next = None  # the banner stays the shown result's
        if res is not None:
            if res.job_path is None:
                self._leave_job_mode(now=True)
            self.drawing = res.drawing
            self.file_path = FsPath(res.path) if res.path is not None else None
            self.job_path = res.job_path
            self._drawing_bbox = self.pipeline.bbox(res.drawing) if res.drawing else None
            if res.params is not None:
                self.params = res.params
                self._committed = res.params
                self.controls.set_params(res.params, res.preview.field_map)
            self.layers.restore(res)  # and the pen table
            self._watch(self.file_path)
        self.run_label.setText("cancelled")
        self.statusBar().showMessage(
            f"Processing cancelled — {self.shown_name() or 'nothing'} stays shown, with its "
            "parameters", 6000)
        self._update_title()
        self._update_status()
        self._update_stale()

    def _on_busy_changed(self, busy: bool) -> None:
        any_busy = self.runner.busy or self.io.busy or self.exporter.busy
        if any_busy:
            self._busy_timer.start()
        else:
            self._busy_timer.stop()
            self.progress.hide()
            self.cancel_button.hide()
            if self.run_label.text().startswith(("processing…", "opening", "exporting")):
                self.run_label.setText("")  # ended without a result (a dialog said why)
        self._update_stale()

    def _update_busy(self) -> None:
        ms = max(self.runner.elapsed_ms(), self.io.elapsed_ms(), self.exporter.elapsed_ms())
        busy = self.runner.active or self.io.active or self.exporter.active
        long_run = busy and ms >= BUSY_DELAY_MS
        self.progress.setVisible(long_run)
        self.cancel_button.setVisible(long_run and (self.runner.active or self.io.active))
        if long_run:
            if self.exporter.active and self._export_target is not None:
                what = f"exporting {self._export_target[1].name}…"
            elif self.io.active and self.loading_path is not None:
                what = f"opening {self.loading_path.name}…"
            else:
                what = "processing…"
            self.run_label.setText(f"{what} {ms / 1000:.1f} s")
        self._update_stale()

    def _on_result(self, gen: int, result: RunResult) -> None:
        if result.drawing is not self.drawing or result.job_path != self.job_path:
            return  # of a file no longer asked for (never shown under another's name)
        self.apply_result(result)
        self.result_shown.emit(gen)

    def _on_failed(self, gen: int, message: str, user_facing: bool) -> None:
        message = self.gui_message(message)
        self.run_error = message
        self.warnings_panel.set_warnings(self.result.job.warnings if self.result else (),
                                         error=message)
        self.statusBar().showMessage(message, 10_000)
        self.run_label.setText("processing failed")

    def _on_cancelled(self, gen: int) -> None:
        if not (self.runner.active or self.io.active):
            self.run_label.setText("cancelled")
        self._update_stale()

    def apply_result(self, result: RunResult) -> None:
        """Show a finished run: layers, field, stats, warnings, conversions."""
        self._stagger_paints()
        self._release_later(self.result)
        self.result = result
        self._apply_banner()
        err = getattr(result, "error", None)
        self.run_error = self.gui_message(err) if err else None
        pv = result.preview
        ut = units_transform(pv.units_scale, pv.units_offset)
        bt = scale_transform(pv.mm_per_bit)
        o, p = self.original, self.processed
        arrays = result.arrays if result.arrays is not None else layer_arrays(pv)
        prep = result.prepared or {}
        show_points = len(pv.original_points) < views_mod.MAX_MARKER_POINTS
        counts = {
            "original": pv.original.n_vertices,
            "fitted": pv.fitted.n_vertices,
            "control": pv.n_control_points,
            "jumps": len(pv.jumps) // 3 + (1 if len(pv.jumps) else 0),
            "hatch": pv.hatch.n_vertices,
            "kerf": pv.kerf.n_vertices,
        }
        for key, arr in arrays.items():
            view = o if key in o.layers else p
            tr = bt if key in ("marks", "jumps", "hatch") else ut
            view.set_layer(key, *arr, transform=tr, count=counts.get(key),
                           prepared=prep.get(key))
        self.markers_shown = show_points and len(pv.original_points) > 0
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
        mag = self.controls.sliders.get("magnification")
        if mag is not None and self.params.fit_field:
            mag.set_value(fm.magnification)
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
        self._update_stale()
        if self.sim_bar.isVisible():
            self._sim = None
            self.simulate_at(self.sim_slider.value() / self.SIM_STEPS)
        missing = [k for k in self.wanted_layers() if not pv.has_layer(k)]
        if missing and result.job_path is None and result.fitted is not None:
            self.request_layers()  # a layer turned on while this result was computed

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
        res = self.result
        if (visible and res is not None and not res.preview.has_layer(key)
                and self.job_path is None and not self.runner.busy):
            self.request_layers()  # its geometry was not computed while hidden

    def layer_visible(self, key: str) -> bool:
        return self.layer_boxes[key].isChecked()

    # --- data -----------------------------------------------------------------------------
    def set_drawing(self, drawing: Drawing, path: str | os.PathLike | None = None, *,
                    bbox: tuple[float, float, float, float] | None = None,
                    size_mm: tuple[float, float] | None = None,
                    pipeline: Pipeline | None = None) -> None:
        """Process ``drawing`` (on the worker) and show it when its result is ready; the
        selection of the previous drawing is cleared at once. ``bbox``/``size_mm``: its
        facts when already known (computed on the worker by :meth:`load_file`, as is
        ``pipeline``, a fresh one that knows the bbox)."""
        self._leave_job_mode()
        self._fit_banner = False
        if drawing is not self.drawing:
            self._fresh_caches(pipeline)
        self.drawing = drawing
        self._drawing_bbox = bbox if bbox is not None else self.pipeline.bbox(drawing)
        if size_mm is not None:
            self._remember_facts(drawing, size=size_mm)
        self.file_path = FsPath(path) if path is not None else None
        self.selected = None
        self._show_selection(None)
        self._fit_pending = True
        self._reloading = False
        self._watch(self.file_path)
        self.controls.set_params(self.params, self._field_map_for(self.params))
        self.request_run()
        self._update_title()
        self._update_status()
        self._update_stale()

    def _stagger_paints(self) -> None:
        """A new result's apply, the original view's paint and the processed view's paint
        run in three event-loop passes: after a new result both views repaint in full
        (20-35 ms of the GUI thread each on 100 k+ points, two to four times that when a
        worker holds the interpreter lock) and Qt paints all the window's dirty widgets in
        one go, right after the apply; in separate passes input and timers get a turn in
        between."""
        if self.processed.updatesEnabled():
            self.original.setUpdatesEnabled(False)
            self.processed.setUpdatesEnabled(False)
            QTimer.singleShot(0, self._paint_original)
            # at the latest after STAGGER_MAX_MS
            QTimer.singleShot(STAGGER_MAX_MS, self._paint_processed)

    def _paint_original(self) -> None:
        if not self.original.updatesEnabled():
            # the processed view once the original has painted (then timers get a turn)
            self.original.on_painted = self._after_original_paint
            self.original.setUpdatesEnabled(True)  # (schedules its repaint)

    def _after_original_paint(self) -> None:
        self.original.on_painted = None
        QTimer.singleShot(0, self._paint_processed)

    def _paint_processed(self) -> None:
        self.original.on_painted = None
        for v in (self.original, self.processed):
            if not v.updatesEnabled():
                v.setUpdatesEnabled(True)  # (schedules its repaint)

    def grab(self, *args: Any) -> QPixmap:
        """``QWidget.grab``, with the processed view's staggered paint let through."""
        self._paint_processed()
        return super().grab(*args)

    def _release_later(self, *objs: object) -> None:
        """Drop ``objs`` (the window's last references to replaced results, drawings,
        caches) after ``RELEASE_DELAY_MS``, in an event-loop pass of their own."""
        self._released.extend(o for o in objs if o is not None)
        if self._released and not self._release_timer.isActive():
            self._release_timer.start()

    def _hand_to_reaper(self) -> None:
        objs, self._released[:] = list(self._released), []
        self._reaper.add(objs)

    def _fresh_caches(self, pipeline: Pipeline | None = None) -> None:
        """Empty caches for a new file: they hold the stages, display geometry and item
        data of the drawings they were made from, so what the last file left there is
        freed with its result (memory stays about one file's, not the session's).
        ``pipeline``: a fresh one made on the worker (see :func:`load_task`)."""
        self._release_later(self.pipeline, self.preview_cache, self.prepared_cache)
        self.pipeline = pipeline if pipeline is not None else Pipeline()
        self.preview_cache = PreviewCache()
        self.prepared_cache = PreparedCache()

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

    def load_file(self, path: str | os.PathLike, *, wait: bool = False,
                  timeout_s: float = 600.0) -> bool:
        """Open ``path`` (a job file when it ends in .json): it is read on a worker thread
        and processed; the views keep showing the current result (marked stale) until the
        new one is ready. On any failure an error dialog says why and the current drawing
        stays. Returns True when the read started; with ``wait``, once it is done, True
        when the file was opened (its result shown)."""
        path = FsPath(path)
        self._last_dir = str(path.parent)
        self.settings.setValue("last_dir", self._last_dir)
        if path.suffix.lower() == ".json":
            return self.load_job_file(path, wait=wait, timeout_s=timeout_s)
        self.loading_path = path
        self.last_load_ok = None
        self.io.request(load_task(path, _read_for_gui))
        self._update_stale()
        if not wait:
            return True
        return self.wait_idle(timeout_s) and bool(self.last_load_ok)

    def load_job_file(self, path: str | os.PathLike, *, wait: bool = False,
                      timeout_s: float = 600.0) -> bool:
        """Show a job file's strokes and marks (no processing); the original view shows the
        source drawing when a file of that name and checksum sits beside the job. Read on a
        worker thread, like :meth:`load_file` (same return value)."""
        path = FsPath(path)
        self.loading_path = path
        self.last_load_ok = None
        self.io.request(job_load_task(path, _read_job_for_gui, self._find_source))
        self._update_stale()
        if not wait:
            return True
        return self.wait_idle(timeout_s) and bool(self.last_load_ok)

    def _on_loaded(self, gen: int, loaded: object) -> None:
        self.loading_path = None
        if isinstance(loaded, Loaded):
            keep = self._keep_selection
            self._keep_selection = None
            self._open_fitting_field(loaded)
            if loaded.n_points >= 0:
                self._remember_facts(loaded.drawing,
                                     counts=(loaded.n_points, loaded.n_closed))
            self.set_drawing(loaded.drawing, loaded.path, bbox=loaded.bbox,
                             size_mm=loaded.size_mm, pipeline=loaded.pipeline)
            if keep is not None:
                self._fit_pending = False
                self.selected = keep
            self._add_recent(loaded.path)
        elif isinstance(loaded, LoadedJob):
            self._show_job(loaded)
        self.last_load_ok = True

    def open_drawing(self, drawing: Drawing, path: str | os.PathLike | None = None) -> None:
        """Open a drawing read elsewhere (the --screenshot command) as :meth:`load_file`
        opens a file: a drawing bigger than the field at true size gets Fit field."""
        p = FsPath(path) if path is not None else FsPath(drawing.name or "untitled")
        loaded = Loaded(p, drawing, self.pipeline.bbox(drawing), drawing.size_mm())
        self._open_fitting_field(loaded)
        self.set_drawing(drawing, path, bbox=loaded.bbox, size_mm=loaded.size_mm)

    def _on_load_failed(self, gen: int, message: str, user_facing: bool) -> None:
        path = self.loading_path
        self.loading_path = None
        self._keep_selection = None
        self.last_load_ok = False
        self._update_stale()
        if self._reloading:
            self._reloading = False
            self.statusBar().showMessage(f"not reloaded: {message}", 10_000)
            self._watch(self.file_path)
            return
        title = "Cannot open job file" if path is not None and \
            path.suffix.lower() == ".json" else "Cannot open file"
        self.show_error(message, title)

    def _open_fitting_field(self, loaded: Loaded) -> None:
        """A drawing bigger than the field at the current (true-size) magnification opens
        with Fit field on, and the banner says so (instead of an error state)."""
        p = self.params
        if p.fit_field or p.clamp or p.magnification is not None or loaded.bbox is None:
            return
        from galvo_core.field import check_in_field

        try:
            fm = (loaded.pipeline or self.pipeline).field_map(loaded.drawing, p)
            check_in_field(fm, loaded.bbox, clamp=False)
            return
        except (GalvoError, ValueError):
            pass
        try:
            params = p.replace(fit_field=True)
        except (GalvoError, ValueError):
            return
        self.set_params(params, run=False)
        w, h = loaded.size_mm
        self._banner_next = (
            f"{loaded.path.name} is {w:.1f} × {h:.1f} mm, bigger than the "
            f"{p.field_size_mm:g} mm field at true size: opened with Fit field on (scaled "
            "to the field). Untick Fit field for a fixed magnification.")
        self._fit_banner = True

    def _show_job(self, loaded: LoadedJob) -> None:
        source, path = loaded.source, loaded.path
        self.runner.cancel()
        self._fresh_caches()
        self.drawing = source
        self._drawing_bbox = loaded.bbox
        self.file_path = None
        self.job_path = path
        self.selected = None
        self._show_selection(None)
        self._fit_pending = True
        self._watch(None)
        self.controls.setEnabled(False)
        where = f"; original from {source.name}" if source is not None else (
            "; its source file was not found beside it, so the original view is empty")
        self._banner_next = (f"Showing the job file {path.name} as written (processing "
                             f"controls are inactive{where}). Open a PLT file to process "
                             "again.")
        self._add_recent(path)
        self.runner.request(job_task(loaded.job, source, self.preview_cache, path,
                                     self.prepared_cache))
        self._update_title()
        self._update_status()
        self._update_stale()

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

    def _leave_job_mode(self, now: bool = False) -> None:
        """Back to processing files: the banner (of a job file, or of the last file's Fit
        field) goes with the next result, or ``now``."""
        if self.job_path is not None:
            self.job_path = None
            self.controls.setEnabled(True)
        if not self._fit_banner:  # (set when the file opening got Fit field: its banner)
            self._banner_next = ""
        if now:
            self._apply_banner()

    def _apply_banner(self) -> None:
        """The banner change asked for (see ``_banner_next``), the views resized at once."""
        text, self._banner_next = self._banner_next, None
        if text is None or (not text and self.banner.isHidden()):
            return
        if text:
            self.banner.setText(text)
            self.banner.show()
        else:
            self.banner.hide()
        layout = self.centralWidget().layout()
        if layout is not None:
            layout.activate()  # the views take their size now (before a fit to them)

    def reload(self) -> bool:
        if self.job_path is not None:
            return self.load_job_file(self.job_path)
        if self.file_path is None:
            return False
        return self.load_file(self.file_path)

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
        self._reloading = True
        self._keep_selection = self.selected
        self.load_file(path)
        self.statusBar().showMessage(f"{path.name} changed on disk: reloading", 5000)

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
    @property
    def export_job_action(self) -> QAction:
        return self.export_actions["job"]

    @property
    def export_plt_action(self) -> QAction:
        return self.export_actions["plt"]

    @property
    def export_svg_action(self) -> QAction:
        return self.export_actions["svg"]

    def rebuild_export_menu(self) -> None:
        """File ▸ Export from :attr:`export_kinds` (call after adding a kind)."""
        self.export_menu.clear()
        self.export_actions = {}
        for kind, spec in self.export_kinds.items():
            a = QAction(spec.label, self)
            if kind == "job":
                a.setShortcut(QKeySequence("Ctrl+E"))
            a.setStatusTip(spec.note)
            a.triggered.connect(lambda _=False, k=kind: self.export_dialog(k))
            self.export_actions[kind] = a
            self.export_menu.addAction(a)
        self.export_menu.addSeparator()
        self.export_menu.addAction(self.export_png_action)
        self._refresh_export_actions()

    def _writer(self, kind: str) -> Callable[[Job, FsPath], None] | None:
        spec = self.export_kinds.get(kind)
        return None if spec is None else spec.write

    def _refresh_export_actions(self) -> None:
        for kind, a in self.export_actions.items():
            a.setEnabled(self._writer(kind) is not None)

    def export_dialog(self, kind: str) -> None:
        """Ask where, then export (on the worker). Refused at once, with a dialog, while the
        views do not show the current result or when the job has an error."""
        refusal = self.export_refusal(kind)
        if refusal is not None:
            self.show_error(refusal, "Not exported")
            return
        if kind == "png":
            flt, suffix = "PNG images (*.png)", ".png"
        else:
            flt, suffix = self.export_kinds[kind].file_filter, self.export_kinds[kind].suffix
        stem = FsPath(self.file_name() or "untitled").stem
        suggested = str(FsPath(self._last_dir) / f"{stem}{suffix}")
        path, _ = QFileDialog.getSaveFileName(self, f"Export {kind.upper()}", suggested, flt)
        if path:
            self.export(kind, path, wait=False)

    def export_refusal(self, kind: str) -> str | None:
        """Why the current result cannot be exported now (None: it can). The views, the
        title and the file written must belong to the same file and parameters: nothing is
        exported while another result is pending, nor a job with an error or no strokes."""
        if kind == "png":
            return None
        if kind not in self.export_kinds:
            return f"unknown export kind {kind!r}"
        if self._writer(kind) is None:
            return f"{kind.upper()} export is not available"
        res = self.result
        if res is None:
            return "nothing to export: open a file first"
        shown = self.shown_name() or "the shown drawing"
        if self.is_stale():
            pending = self.pending_name()
            what = f"{pending} is still being read or processed" if pending and \
                pending != shown else "the parameters changed and the new result is not ready"
            return (f"{shown}: not exported: {what}; the views show an older result. Export "
                    "when the new result is shown (or press Esc to go back to the shown one).")
        if res.error:
            return f"{shown}: not exported: {res.error}"
        if not res.job.strokes:
            return (f"{shown}: not exported: the job has no strokes (nothing would be marked); "
                    "see the warnings")
        return None

    def export(self, kind: str, path: str | os.PathLike, *, wait: bool = True,
               timeout_s: float = 600.0) -> bool:
        """Write the shown job (``kind`` one of :attr:`export_kinds`: job/plt/svg, …) or a
        PNG of the views (``"png"``) to ``path``. The writing runs on a worker thread; with
        ``wait`` this returns once it is done (True: written), else at once (True: started).
        Refused with a dialog (False) while the shown result is stale, or when it has an
        error or no strokes. Atomic: a failure leaves no half-written file, and says why in a
        dialog naming ``path``."""
        path = FsPath(path)
        refusal = self.export_refusal(kind)
        if refusal is not None:
            self.show_error(refusal, "Not exported")
            return False
        if kind == "png":
            try:
                atomic_write_bytes(path, self.views_png())
            except Exception as exc:  # noqa: BLE001 - a dialog
                self._export_error(path, exc)
                return False
            self.statusBar().showMessage(f"exported {path}", 6000)
            return True
        assert self.result is not None
        writer = self._writer(kind)
        assert writer is not None
        self._export_target = (kind, path)
        self.last_export_ok = None
        self.exporter.request(export_task(writer, self.result.job, path))
        self.run_label.setText(f"exporting {path.name}…")
        if not wait:
            return True
        if not self.exporter.wait_idle(timeout_s):
            return False
        return bool(self.last_export_ok)

    def _export_error(self, path: FsPath, exc: BaseException | str) -> None:
        if isinstance(exc, str):
            msg = exc
        elif isinstance(exc, GalvoError):
            msg = str(exc)
        elif isinstance(exc, OSError):
            msg = f"{path}: cannot write ({exc.strerror or exc})"
        else:
            msg = f"{path}: {type(exc).__name__}: {exc}"
        self.last_export_ok = False
        self.show_error(_user_path_message(msg, path), "Export failed")

    def _on_exported(self, gen: int, path: object) -> None:
        self.last_export_ok = True
        kind = self._export_target[0] if self._export_target else ""
        note = self.export_kinds[kind].note if kind in self.export_kinds else ""
        self.run_label.setText("")
        self.statusBar().showMessage(f"exported {path}" + (f" ({note})" if note else ""),
                                     8000)

    def _on_export_failed(self, gen: int, message: str, user_facing: bool) -> None:
        path = self._export_target[1] if self._export_target else FsPath("?")
        self.run_label.setText("")
        if not user_facing:
            message = f"{path}: {message}"
        self._export_error(path, message)

    def views_png(self) -> bytes:
        """Both views (as shown) as PNG bytes."""
        self._paint_processed()
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
        if self.ruler_action.isChecked():
            self.ruler_click(p.x(), p.y())
            return
        self.select_at(p.x(), p.y(), view)

    # --- marking simulation ---------------------------------------------------------------
    SIM_STEPS = 1000

    def _build_simulation_bar(self) -> None:
        from PySide6.QtWidgets import QSlider

        bar = QWidget()
        bar.setObjectName("simulation_bar")
        lay = QHBoxLayout(bar)
        lay.setContentsMargins(6, 2, 6, 2)
        self.sim_play = QToolButton()
        self.sim_play.setText("▶")
        self.sim_play.setCheckable(True)
        self.sim_play.setToolTip("play the job in its marking order")
        self.sim_play.toggled.connect(self._sim_toggle_play)
        self.sim_slider = QSlider(Qt.Orientation.Horizontal)
        self.sim_slider.setRange(0, self.SIM_STEPS)
        self.sim_slider.valueChanged.connect(lambda v: self.simulate_at(v / self.SIM_STEPS))
        self.sim_label = QLabel("")
        self.sim_label.setMinimumWidth(260)
        lay.addWidget(QLabel("Simulation:"))
        lay.addWidget(self.sim_play)
        lay.addWidget(self.sim_slider, 1)
        lay.addWidget(self.sim_label)
        bar.hide()
        self.sim_bar = bar
        self._sim_timer = QTimer(self)
        self._sim_timer.setInterval(40)
        self._sim_timer.timeout.connect(self._sim_tick)
        self._sim: tuple[Any, ...] | None = None

    def set_simulation(self, on: bool) -> None:
        """Show the marking simulation bar (the beam and what it has marked so far)."""
        if self.sim_action.isChecked() != on:
            self.sim_action.setChecked(on)
            return
        self.sim_bar.setVisible(on)
        if not on:
            self.sim_play.setChecked(False)
        self._sim = None
        self.simulate_at(self.sim_slider.value() / self.SIM_STEPS if on else None)

    def _sim_data(self) -> tuple[Any, ...] | None:
        from galvo_core.preview import beam_timeline

        res = self.result
        if res is None:
            return None
        if self._sim is None or self._sim[0] is not res.job:
            xy, t, on = beam_timeline(res.job)
            self._sim = (res.job, xy, t, on)
        return self._sim

    def simulate_at(self, fraction: float | None) -> dict[str, Any] | None:
        """Put the simulated beam at ``fraction`` (0..1) of the job's estimated time: the
        beam marker, the marked trail so far, and the time read-out. None hides them.
        Returns the state shown (time, total, index, position in bits, laser on)."""
        import pyqtgraph as pg

        view = self.processed
        if not hasattr(view, "_sim_items"):
            trail = pg.PlotDataItem([], [], pen=pg.mkPen("#111111", width=2))
            beam = pg.ScatterPlotItem([], [], size=14, pen=pg.mkPen("#111111", width=2),
                                      brush=pg.mkBrush(255, 255, 255, 0))
            for it in (trail, beam):
                it.setZValue(2e5)
                view.getPlotItem().addItem(it, ignoreBounds=True)
            view._sim_items = (trail, beam)
        trail, beam = view._sim_items
        data = self._sim_data() if fraction is not None else None
        if data is None or not len(data[2]):
            trail.setData([], [])
            beam.setData([], [])
            self.sim_label.setText("")
            return None
        _, xy, t, on = data
        total = float(t[-1])
        now = min(max(fraction, 0.0), 1.0) * total
        k = int(np.searchsorted(t, now, side="right")) - 1
        k = max(0, min(k, len(t) - 1))
        pos = xy[k].copy()
        lit = False
        if k + 1 < len(t) and t[k + 1] > t[k]:
            f = (now - t[k]) / (t[k + 1] - t[k])
            pos = xy[k] + f * (xy[k + 1] - xy[k])
            lit = bool(on[k + 1])
        mpb = self.result.preview.mm_per_bit if self.result else 1.0
        seg = np.vstack((xy[: k + 1], pos[None, :])) * mpb
        conn = np.zeros(len(seg), dtype=bool)
        conn[:-1] = np.append(on[1 : k + 1], lit)  # draw a step only where the laser was on
        trail.setData(seg[:, 0], seg[:, 1], connect=conn)
        beam.setData([pos[0] * mpb], [pos[1] * mpb],
                     pen=pg.mkPen("#d7191c" if lit else "#111111", width=2))
        self.sim_label.setText(f"t = {now:.3f} s / {total:.3f} s · laser "
                               f"{'on' if lit else 'off'}")
        return {"time_s": now, "total_s": total, "index": k, "bits": pos, "laser_on": lit}

    def _sim_toggle_play(self, on: bool) -> None:
        self.sim_play.setText("⏸" if on else "▶")
        if on:
            if self.sim_slider.value() >= self.SIM_STEPS:
                self.sim_slider.setValue(0)
            self._sim_timer.start()
        else:
            self._sim_timer.stop()

    def _sim_tick(self) -> None:
        v = self.sim_slider.value() + 2
        if v >= self.SIM_STEPS:
            v = self.SIM_STEPS
            self.sim_play.setChecked(False)
        self.sim_slider.setValue(v)

    # --- ruler ----------------------------------------------------------------------------
    def set_ruler(self, on: bool) -> None:
        """Ruler mode: clicks in either view measure instead of selecting."""
        if self.ruler_action.isChecked() != on:
            self.ruler_action.setChecked(on)
            return
        self._ruler_pts: list[tuple[float, float]] = []
        self._draw_ruler()
        self.statusBar().showMessage(
            "Ruler: click two points (R again to leave)" if on else "", 6000 if on else 1)

    def ruler_click(self, x_mm: float, y_mm: float) -> str | None:
        """One ruler click (mm in the field); the second one measures and says so."""
        pts = getattr(self, "_ruler_pts", [])
        if len(pts) >= 2:
            pts = []
        pts.append((x_mm, y_mm))
        self._ruler_pts = pts
        self._draw_ruler()
        if len(pts) < 2:
            self.statusBar().showMessage("Ruler: click the second point", 6000)
            return None
        text = self.measure(pts[0], pts[1])
        self.statusBar().showMessage(text, 30_000)
        return text

    def measure(self, a_mm: tuple[float, float], b_mm: tuple[float, float]) -> str:
        """The distance between two points of the field in mm and galvo bits (and its
        components), at the shown result's field."""
        dx, dy = b_mm[0] - a_mm[0], b_mm[1] - a_mm[1]
        d = float(np.hypot(dx, dy))
        text = f"Ruler: {d:.3f} mm  (Δx {dx:.3f}, Δy {dy:.3f} mm)"
        if self.result is not None:
            mpb = self.result.preview.mm_per_bit
            text += f" = {d / mpb:,.1f} bits (Δx {dx / mpb:,.0f}, Δy {dy / mpb:,.0f})".replace(
                ",", "\u2009")
        return text

    def _draw_ruler(self) -> None:
        pts = getattr(self, "_ruler_pts", [])
        for view in (self.original, self.processed):
            item = getattr(view, "_ruler_item", None)
            if item is None:
                import pyqtgraph as pg

                item = pg.PlotDataItem([], [], pen=pg.mkPen("#222222", width=1.5),
                                       symbol="+", symbolSize=12, symbolPen="#222222")
                item.setZValue(1e5)
                view.getPlotItem().addItem(item, ignoreBounds=True)
                view._ruler_item = item
            if pts:
                item.setData([p[0] for p in pts], [p[1] for p in pts])
            else:
                item.setData([], [])

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
        """The name of the file asked for (the shown one once its result is ready)."""
        if self.job_path is not None:
            return self.job_path.name
        if self.file_path is not None:
            return self.file_path.name
        if self.drawing is not None and self.drawing.name:
            return self.drawing.name
        return ""

    def _update_title(self) -> None:
        """The title names the file whose result the views show; a file being opened or
        processed instead is named as pending."""
        shown = self.shown_name() if self.result is not None else ""
        pending = self.loading_path.name if self.loading_path is not None else (
            self.file_name() if self.is_stale() else "")
        if self.result is None and self.drawing is None and self.job_path is None:
            title = APP_NAME if not pending else f"(opening {pending}…) — {APP_NAME}"
        elif not shown:
            title = f"{pending or self.file_name() or 'untitled'} — {APP_NAME}"
        elif pending and pending != shown:
            title = f"{shown} (opening {pending}…) — {APP_NAME}"
        else:
            title = f"{shown} — {APP_NAME}"
        if self.windowTitle() != title:
            self.setWindowTitle(title)

    def _remember_facts(self, d: Drawing, **facts: object) -> dict[str, object]:
        """The status bar's facts of ``d`` (size, point and closed-path counts: each walks
        every path, 10-30 ms on 40 k paths), kept for the drawing shown and the one
        opening, whose status lines alternate while it processes (others are dropped:
        the memo must not keep a closed file alive)."""
        memo: dict[int, tuple[Drawing, dict[str, object]]] = self.__dict__.setdefault(
            "_facts_of", {})
        hit = memo.get(id(d))
        if hit is None or hit[0] is not d:
            hit = (d, {})
            memo[id(d)] = hit
        live = {id(d), id(self.drawing)}
        if self.result is not None:
            live.add(id(self.result.drawing))
        for k in [k for k in memo if k not in live]:
            self._release_later(memo.pop(k))
        hit[1].update(facts)
        return hit[1]

    def _size_mm(self, d: Drawing) -> tuple[float, float]:
        """``d.size_mm()``, kept per drawing (a bbox over every point: too slow per run)."""
        facts = self._remember_facts(d)
        if "size" not in facts:
            facts["size"] = d.size_mm()
        return facts["size"]  # type: ignore[return-value]

    def status_summary(self) -> str:
        """The counts shown in the status bar, as plain text."""
        res = self.result
        d = res.drawing if res is not None else self.drawing
        job_path = res.job_path if res is not None else self.job_path
        if d is None:
            if job_path is not None:
                return f"job file {job_path.name}"
            return "No file — File ▸ Open… or drop an HP-GL file onto the window"
        w, h = self._size_mm(d)
        facts = self._remember_facts(d)
        if "counts" not in facts:  # walks every path: once per drawing
            facts["counts"] = (d.n_points, d.n_closed)
        n_points, n_closed = facts["counts"]  # type: ignore[misc]
        return "   ·   ".join(
            [
                f"{_fmt_int(len(d.paths))} paths",
                f"{_fmt_int(n_points)} points",
                f"{_fmt_int(n_closed)} closed",
                f"{w:.2f} × {h:.2f} mm",
                (self.shown_name() if res is not None else self.file_name()) or "untitled",
            ]
        )

    def _update_status(self) -> None:
        self.status_label.setText(self.status_summary())
        # one warning count: the job's (the file's own warnings are among them)
        n_warn = len(self.result.job.warnings) if self.result is not None else 0
        if self.run_error:
            self.warnings_label.setText("✖ error")
            self.warnings_label.setStyleSheet("color: #b00020; font-weight: bold;")
        elif self.result is not None:
            self.warnings_label.setText(f"⚠ {_fmt_int(n_warn)} warning"
                                        f"{'s' if n_warn != 1 else ''}" if n_warn else
                                        "0 warnings")
            self.warnings_label.setStyleSheet("color: #b35c00; font-weight: bold;" if n_warn
                                              else "color: #5f6b7a;")
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
        for r in (self.runner, self.io, self.exporter):
            r.shutdown()
        super().closeEvent(event)
