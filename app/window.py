"""The main window: the original drawing and the processed result side by side."""

from __future__ import annotations

import os
from pathlib import Path as FsPath

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QDragEnterEvent, QDropEvent, QIcon, QKeySequence
from PySide6.QtWidgets import (
    QFileDialog,
    QLabel,
    QMainWindow,
    QMessageBox,
    QSplitter,
    QWidget,
)

from galvo_core.drawing import Drawing
from galvo_core.errors import GalvoError, InputError

from .views import ORIGINAL_LINE, PROCESSED_LINE, DrawingView, Polylines, cursor_text

APP_NAME = "Galvo Workstation"
#: The repository's resources folder (icons, sample files).
RESOURCES_DIR = FsPath(__file__).resolve().parent.parent / "resources"
ICON_PATH = RESOURCES_DIR / "icons" / "app.svg"
SAMPLES_DIR = RESOURCES_DIR / "samples"

_EXTS = ("plt", "hpgl", "hpg", "hp", "pgl", "pcl", "spl")
FILE_FILTER = (
    "HP-GL files ("
    + " ".join(f"*.{e}" for e in _EXTS)
    + " "
    + " ".join(f"*.{e.upper()}" for e in _EXTS)
    + ");;All files (*)"
)


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


def _fmt_int(n: int) -> str:
    return f"{n:,}".replace(",", "\u2009")  # thin-space thousands separator


class MainWindow(QMainWindow):
    """Two linked views ("Original", "Processed"), File menu, drops, a status bar."""

    def __init__(self, drawing: Drawing | None = None, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.drawing: Drawing | None = None
        self.file_path: FsPath | None = None
        self._last_dir = str(FsPath.cwd())
        #: The message of the last error dialog (kept for tests and logs).
        self.last_error: str | None = None

        if ICON_PATH.is_file():
            self.setWindowIcon(QIcon(str(ICON_PATH)))
        self.setAcceptDrops(True)
        self.setMinimumSize(480, 320)

        self.original = DrawingView("Original", ORIGINAL_LINE)
        self.processed = DrawingView("Processed", PROCESSED_LINE)
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
        self.setCentralWidget(splitter)

        self._build_menus()
        self._build_status_bar()
        for view in (self.original, self.processed):
            view.scene().sigMouseMoved.connect(lambda pos, v=view: self._on_mouse_moved(v, pos))

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
        self.points_action = QAction("Show &Points", self, checkable=True, checked=True)
        self.points_action.setShortcut(QKeySequence("P"))
        self.points_action.toggled.connect(self._set_points_visible)
        view_menu.addAction(self.points_action)

    def _build_status_bar(self) -> None:
        sb = self.statusBar()
        self.status_label = QLabel()
        self.warnings_label = QLabel()
        self.cursor_label = QLabel()
        self.cursor_label.setMinimumWidth(330)
        self.cursor_label.setTextFormat(Qt.TextFormat.PlainText)
        sb.addWidget(self.status_label, 1)
        sb.addPermanentWidget(self.warnings_label)
        sb.addPermanentWidget(self.cursor_label)

    # --- data -----------------------------------------------------------------------------
    def set_drawing(self, drawing: Drawing, path: str | os.PathLike | None = None) -> None:
        """Show ``drawing`` as the original and its processed result."""
        self.original.set_polylines(drawing, auto_range=False)
        self.set_processed(self.process(drawing))
        self.drawing = drawing
        self.file_path = FsPath(path) if path is not None else None
        self.fit()
        self._update_title()
        self._update_status()

    def process(self, drawing: Drawing) -> Polylines:
        """The processing pipeline's result for the right-hand view.

        For now the paths unchanged; later issues put thinning, fitting, kerf compensation
        etc. here (or call :meth:`set_processed` directly with their result).
        """
        return drawing.paths

    def set_processed(self, polylines: Polylines) -> None:
        """Show a processed result: a Drawing, Paths or (N, 2) point arrays in input units.

        The view stays linked to the original (same pan/zoom); the range is not changed.
        """
        self.processed.set_polylines(polylines, auto_range=False)

    def fit(self) -> None:
        """Zoom both (linked) views to the union of what they show."""
        boxes = [b for b in (self.original.bounds, self.processed.bounds) if b is not None]
        if not boxes:
            self.original.fit()
            return
        self.original.fit(
            (
                min(b[0] for b in boxes),
                min(b[1] for b in boxes),
                max(b[2] for b in boxes),
                max(b[3] for b in boxes),
            )
        )

    def _set_points_visible(self, visible: bool) -> None:
        for view in (self.original, self.processed):
            view.markers.setVisible(visible)

    # --- loading --------------------------------------------------------------------------
    def open_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open HP-GL file", self._last_dir, FILE_FILTER)
        if path:
            self.load_file(path)

    def load_file(self, path: str | os.PathLike) -> bool:
        """Read and show ``path``; on any failure show an error dialog and keep the current
        drawing. Returns True when the file was loaded."""
        path = FsPath(path)
        self._last_dir = str(path.parent)
        try:
            drawing = load_drawing(path)
        except (InputError, GalvoError, OSError) as exc:
            self.show_error(describe_load_error(path, exc))
            return False
        except Exception as exc:  # noqa: BLE001 - a bug must not crash the window
            self.show_error(describe_load_error(path, exc))
            return False
        previous, previous_path = self.drawing, self.file_path
        try:
            self.set_drawing(drawing, path)
        except Exception as exc:  # noqa: BLE001
            self._restore(previous, previous_path)
            self.show_error(describe_load_error(path, exc))
            return False
        return True

    def _restore(self, drawing: Drawing | None, path: FsPath | None) -> None:
        try:
            if drawing is not None:
                self.set_drawing(drawing, path)
            else:
                self.original.clear_drawing()
                self.processed.clear_drawing()
                self.drawing = None
                self.file_path = None
                self._update_title()
                self._update_status()
        except Exception:  # noqa: BLE001 - nothing more can be done; the dialog follows
            pass

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

    # --- title and status -----------------------------------------------------------------
    def file_name(self) -> str:
        if self.file_path is not None:
            return self.file_path.name
        if self.drawing is not None and self.drawing.name:
            return self.drawing.name
        return ""

    def _update_title(self) -> None:
        name = self.file_name()
        if self.drawing is None:
            self.setWindowTitle(APP_NAME)
        else:
            self.setWindowTitle(f"{name or 'untitled'} — {APP_NAME}")

    def status_summary(self) -> str:
        """The counts shown in the status bar, as plain text."""
        d = self.drawing
        if d is None:
            return "No file — File ▸ Open… or drop an HP-GL file onto the window"
        w, h = d.size_mm()
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
        d = self.drawing
        n_warn = len(d.warnings) if d is not None else 0
        if d is not None and n_warn:
            self.warnings_label.setText(f"⚠ {n_warn}")
            self.warnings_label.setStyleSheet("color: #b35c00; font-weight: bold;")
            shown = [str(w) for w in d.warnings[:25]]
            if n_warn > len(shown):
                shown.append(f"… and {n_warn - len(shown)} more")
            self.warnings_label.setToolTip("\n".join(shown))
        else:
            self.warnings_label.setText("")
            self.warnings_label.setToolTip("")
        if d is not None and not self.original.markers_shown and d.n_points:
            self.status_label.setToolTip(
                "Point markers hidden: too many points to draw them quickly"
            )
        else:
            self.status_label.setToolTip("")

    def _on_mouse_moved(self, view: DrawingView, scene_pos) -> None:
        vb = view.getPlotItem().getViewBox()
        if vb.sceneBoundingRect().contains(scene_pos):
            p = vb.mapSceneToView(scene_pos)
            self.cursor_label.setText(cursor_text(p.x(), p.y()))
        else:
            self.cursor_label.setText("")
