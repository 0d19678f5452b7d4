"""The window's pen layers (issue 19): the layer table dock, File ▸ Open/Save Pen Table…, and
File ▸ Export ▸ LMC list / LMC text.

:class:`LayersDock` is installed by :class:`app.window.MainWindow` (one call) and owns:

* the pen table the operator edits (:attr:`LayersDock.table`); the table a run uses is
  :meth:`LayersDock.effective`: that table with its profile (the defaults of every pen)
  following the window's laser parameters, so Process ▸ Laser Parameters… and the table
  never disagree;
* :meth:`LayersDock.wrap`: the window's pipeline request with the pen table applied on the
  worker (``galvo_core.layers.apply_pens`` after the run: the job's ``layers`` table and the
  time per layer) and recorded in the result (``RunResult.pens``), so the window can tell a
  result made with another pen table (stale: not exported, ``current_job()`` None);
* the layer table (:class:`app.layers_panel.LayersPanel`) in a dock beside the processing
  panel: one row per pen the job uses, edits re-make the shown job at once, the time per
  layer from ``job.stats["layers"]``. A loaded job file shows its own layers, read only;
* the pen table files (TOML, :func:`galvo_core.layers.load_pen_table` /
  :func:`~galvo_core.layers.dump_pen_table`): a bad file is refused with one message naming
  the file and the place, and nothing changes;
* the export kinds ``lmc`` (BJJCZ list records) and ``lmc_text`` (MeerK40t's readable dump),
  written by :func:`galvo_core.lmc.write_lmc` from the job's own layers table, on the
  export worker like every other kind, with the field orientation (swap x/y, flip x, flip y)
  checked in the dock when the export was asked for;
* a window that restores its settings keeps the pen table and the orientation for the next
  session.
"""

from __future__ import annotations

import dataclasses
import os
import time
import tomllib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path as FsPath
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (
    QCheckBox,
    QDockWidget,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QMenu,
    QVBoxLayout,
    QWidget,
)

from galvo_core.errors import GalvoError
from galvo_core.job import Job, atomic_write_bytes
from galvo_core.layers import (
    PenTable,
    apply_pens,
    dump_pen_table,
    load_pen_table,
    pen_table_from_dict,
)
from galvo_core.lmc import AS_IS, Orientation, job_pen_table, write_lmc
from galvo_core.params import Params
from galvo_core.pipeline import Cancelled

from .layers_panel import LayersPanel

if TYPE_CHECKING:
    from .window import MainWindow

Task = Callable[[Callable[[], bool]], Any]
PEN_FILTER = "Pen tables (*.toml);;All files (*)"
#: settings keys: the pen table (TOML) and the export orientation, kept between sessions
PENS_KEY = "layers/pen_table"
ORIENT_KEY = "layers/orientation"
ORIENT_NAMES = ("swap_xy", "flip_x", "flip_y")


@dataclass(frozen=True)
class LmcWriter:
    """File ▸ Export ▸ LMC list (``text`` False: the job's BJJCZ list records, from its own
    layers table) or LMC text (MeerK40t's readable dump of the same list), with the field
    orientation chosen in the Layers dock when the export was asked for."""

    text: bool = False
    orientation: Orientation = AS_IS

    def __call__(self, job: Job, path: FsPath) -> None:
        write_lmc(job, os.fspath(path), orientation=self.orientation, text=self.text)


def with_profile(table: PenTable, params: Params) -> PenTable:
    """``table`` with its profile's laser settings those of ``params`` (the pens it lists
    keep their own settings)."""
    if table.default.laser == params.laser:
        return table
    return dataclasses.replace(table, default=dataclasses.replace(table.default,
                                                                  laser=params.laser))


def pens_task(inner: Task, pens: PenTable) -> Task:
    """``inner`` (the window's pipeline request, giving a ``RunResult``), then the pen table
    applied to its job on the same worker: layers table, per-layer time; the result records
    ``pens``."""

    def task(cancel: Callable[[], bool]) -> Any:
        res = inner(cancel)
        if cancel():
            raise Cancelled()
        t0 = time.perf_counter()
        job = apply_pens(res.job, pens)
        return dataclasses.replace(res, job=job, pens=pens,
                                   seconds=res.seconds + time.perf_counter() - t0)

    return task


def repens_task(shown: Any, pens: PenTable) -> Task:
    """The shown result (a ``RunResult`` of the current drawing and parameters) with another
    pen table: only ``apply_pens`` runs (it redoes the layers table and the time from the
    strokes, so the job is the one a fresh run with ``pens`` gives); the views keep their
    geometry."""

    def task(cancel: Callable[[], bool]) -> Any:
        t0 = time.perf_counter()
        job = apply_pens(shown.job, pens)
        if cancel():
            raise Cancelled()
        return dataclasses.replace(shown, job=job, pens=pens, stages_run=("layers",),
                                   seconds=time.perf_counter() - t0)

    return task


class LayersDock:
    """The pen layers of one :class:`~app.window.MainWindow` (see the module docstring)."""

    def __init__(self, win: MainWindow) -> None:
        from .window import ExportKind

        self.win = win
        #: the pen table as the operator set it (its profile follows the laser parameters)
        self.table: PenTable = PenTable.from_laser(win.params.laser)
        #: the message of the last refused pen table file (tests, logs)
        self.last_error: str | None = None
        self._job_mode = False

        self.panel = LayersPanel(self.effective())
        self.panel.setObjectName("layers_panel")
        self.panel.changed.connect(self._on_edited)
        # the time per layer right after the pen (the settings scroll in a narrow dock)
        head = self.panel.grid.horizontalHeader()
        head.moveSection(head.visualIndex(self.panel.grid.columnCount() - 1), 2)
        self.note = QLabel("")
        self.note.setObjectName("layers_note")
        self.note.setWordWrap(True)
        self.note.setStyleSheet("color: #5f6b7a;")
        # the field's orientation at LMC export (how the job's X/Y reach the galvos)
        self.orient_boxes: dict[str, QCheckBox] = {}
        orient = QWidget()
        ol = QHBoxLayout(orient)
        ol.setContentsMargins(0, 0, 0, 0)
        ol.addWidget(QLabel("LMC export:"))
        for name, label, tip in (
                ("swap_xy", "swap x/y", "exchange the galvos' X and Y (applied first)"),
                ("flip_x", "flip x", "mirror X across the field"),
                ("flip_y", "flip y", "mirror Y across the field")):
            cb = QCheckBox(label)
            cb.setObjectName(f"lmc_{name}")
            cb.setToolTip(tip)
            cb.toggled.connect(self._on_orientation)
            self.orient_boxes[name] = cb
            ol.addWidget(cb)
        ol.addStretch(1)
        box = QWidget()
        lay = QVBoxLayout(box)
        lay.setContentsMargins(4, 2, 4, 2)
        lay.addWidget(self.panel, 1)
        lay.addWidget(orient)
        lay.addWidget(self.note)
        self.dock = QDockWidget("Layers", win)
        self.dock.setObjectName("dock_layers")
        self.dock.setWidget(box)
        self.dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                              | QDockWidget.DockWidgetFeature.DockWidgetFloatable)
        win.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, self.dock)
        win.splitDockWidget(win.controls_dock, self.dock, Qt.Orientation.Vertical)
        win.resizeDocks([win.controls_dock, self.dock], [500, 240], Qt.Orientation.Vertical)

        # File ▸ Open/Save Pen Table… (before Export), View ▸ Layers
        self.open_action = QAction("Open &Pen Table…", win)
        self.open_action.setStatusTip("the laser settings of each pen (TOML)")
        self.open_action.triggered.connect(self.open_dialog)
        self.save_action = QAction("Save Pen &Table…", win)
        self.save_action.triggered.connect(self.save_dialog)
        menus = {a.text().replace("&", ""): m for a in win.menuBar().actions()
                 if isinstance(m := a.menu(), QMenu)}
        if "File" in menus:
            before = win.export_menu.menuAction()
            menus["File"].insertAction(before, self.open_action)
            menus["File"].insertAction(before, self.save_action)
            menus["File"].insertSeparator(before)
        if "View" in menus:
            menus["View"].addAction(self.dock.toggleViewAction())

        self._export_kind = ExportKind
        self._set_export_kinds()
        win.rebuild_export_menu()
        win.result_shown.connect(self._on_result_shown)
        if win._restore_settings:  # noqa: SLF001 - the window's own choice
            self._restore_settings()

    # ------------------------------------------------------------------ export
    def orientation(self) -> Orientation:
        """The field orientation the LMC export applies (the dock's check boxes)."""
        return Orientation(*(self.orient_boxes[n].isChecked() for n in ORIENT_NAMES))

    def set_orientation(self, orientation: Orientation) -> None:
        for n in ORIENT_NAMES:
            self.orient_boxes[n].setChecked(bool(getattr(orientation, n)))

    def _set_export_kinds(self) -> None:
        # a writer holds the orientation: the one of the moment the export is asked for
        o = self.orientation()
        where = "" if o.is_identity else " (" + ", ".join(
            n.replace("_", " ") for n in ORIENT_NAMES if getattr(o, n)) + ")"
        self.win.export_kinds["lmc"] = self._export_kind(
            "Export &LMC List (.lmc)…", "BJJCZ list (*.lmc)", ".lmc", LmcWriter(False, o),
            "BJJCZ list commands, layers by pen number with their settings" + where)
        self.win.export_kinds["lmc_text"] = self._export_kind(
            "Export LMC &Text…", "Text files (*.txt)", ".lmc.txt", LmcWriter(True, o),
            "the BJJCZ list as readable text, one command per line" + where)

    def _on_orientation(self, _on: bool = False) -> None:
        self._set_export_kinds()
        self._remember()

    # ------------------------------------------------------------------ settings
    def _remember(self) -> None:
        """Keep the pen table and the orientation for the next session (a window that
        restores its settings only)."""
        if not self.win._restore_settings:  # noqa: SLF001
            return
        s = self.win.settings
        s.setValue(PENS_KEY, dump_pen_table(self.table))
        o = self.orientation()
        s.setValue(ORIENT_KEY, ",".join(n for n in ORIENT_NAMES if getattr(o, n)))

    def _restore_settings(self) -> None:
        s = self.win.settings
        text = s.value(PENS_KEY)
        if isinstance(text, str) and text:
            try:
                self.table = pen_table_from_dict(tomllib.loads(text), "settings",
                                                 self.win.params.laser)
            except (GalvoError, tomllib.TOMLDecodeError):
                pass  # a table of an older version: start from the laser parameters
            else:
                self.panel.set_table(self.effective())
        names = s.value(ORIENT_KEY)
        if isinstance(names, str):
            self.set_orientation(Orientation(*(n in names.split(",") for n in ORIENT_NAMES)))

    # ------------------------------------------------------------------ the run
    def effective(self, params: Params | None = None) -> PenTable:
        """The pen table a run with ``params`` (default: the window's) uses."""
        return with_profile(self.table, params if params is not None else self.win.params)

    def wrap(self, task: Task) -> Task:
        """The window's pipeline request with the current pen table applied."""
        return pens_task(task, self.effective())

    def is_current(self, result: Any) -> bool:
        """True when ``result`` (a pipeline RunResult) was made with the current pen table."""
        return getattr(result, "pens", None) == self.effective()

    def set_table(self, table: PenTable) -> None:
        """Use ``table`` (its profile becomes the laser parameters) and process again."""
        self.table = table
        self._remember()
        win = self.win
        if table.default.laser != win.params.laser:
            win.apply_changes({"laser": table.default.laser})  # runs again
        else:
            win.request_run()
        self.panel.set_table(self.effective())

    def restore(self, result: Any) -> None:
        """Processing was cancelled: the pen table goes back to the one ``result`` (the
        shown one) was made with."""
        pens = getattr(result, "pens", None)
        if isinstance(pens, PenTable) and pens != self.table:
            self.table = pens
            self._remember()
            self.panel.set_table(self.effective())

    def _on_edited(self, table: PenTable) -> None:
        self.table = table
        self._remember()
        win = self.win
        res = win.result
        if (res is not None and res.job_path is None and win.job_path is None
                and res.drawing is win.drawing and res.params == win.params
                and res.error is None and isinstance(res.pens, PenTable)
                and not (win.runner.active or win.io.active or win._throttle.isActive())):
            # only the pens changed: re-make the shown job, not the pipeline and the views
            win.runner.request(repens_task(res, self.effective()))
            win._update_stale()  # noqa: SLF001 - the window's own bookkeeping
        else:
            win.request_run()

    def _on_result_shown(self, _gen: int) -> None:
        res = self.win.result
        if res is None:
            return
        job = res.job
        rows = list(job.stats.get("layers", ())) if job is not None else []
        if res.job_path is not None:
            self._job_mode = True
            try:
                table = job_pen_table(job)
            except GalvoError as exc:
                self.note.setText(str(exc))
                table = PenTable()
            self.panel.set_table(table)
            self.panel.setEnabled(False)
            self.note.setText("the layers of the loaded job file (read only)")
        else:
            if self._job_mode or self.panel.table() != self.effective():
                self.panel.set_table(self.effective())
            self._job_mode = False
            self.panel.setEnabled(True)
            self.note.setText("")
        pens = [int(r["pen"]) for r in rows] or sorted({int(s.pen) for s in job.strokes})
        self.panel.set_pens(pens)
        self.panel.set_layer_times(rows)

    # ------------------------------------------------------------------ files
    def open_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self.win, "Open pen table",
                                              self.win._last_dir, PEN_FILTER)  # noqa: SLF001
        if path:
            self.open(path)

    def save_dialog(self) -> None:
        stem = FsPath(self.win.file_name() or "pens").stem
        suggested = str(FsPath(self.win._last_dir) / f"{stem}.pens.toml")  # noqa: SLF001
        path, _ = QFileDialog.getSaveFileName(self.win, "Save pen table", suggested,
                                              PEN_FILTER)
        if path:
            self.save(path)

    def open(self, path: str | os.PathLike[str]) -> bool:
        """Read a pen table file and use it (True); a file that cannot be used is refused
        with a dialog naming it and the place (False) and nothing changes."""
        try:
            table = load_pen_table(path, base=self.win.params.laser)
        except GalvoError as exc:
            self.last_error = str(exc)
            self.win.show_error(str(exc), "Cannot open pen table")
            return False
        self.last_error = None
        self.set_table(table)
        self.win.statusBar().showMessage(f"pen table {path}", 6000)
        return True

    def save(self, path: str | os.PathLike[str]) -> bool:
        """Write the current pen table as TOML (atomic); False (and a dialog) on failure."""
        try:
            atomic_write_bytes(path, dump_pen_table(self.effective()).encode("utf-8"))
        except (OSError, GalvoError) as exc:
            msg = str(exc) if isinstance(exc, GalvoError) else \
                f"{os.fspath(path)}: cannot write ({getattr(exc, 'strerror', None) or exc})"
            self.last_error = msg
            self.win.show_error(msg, "Pen table not saved")
            return False
        self.win.statusBar().showMessage(f"saved pen table {path}", 6000)
        return True
