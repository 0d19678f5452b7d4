"""The main window (issue 3 §5): views, layers, loading, errors, drops, --screenshot."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path as FsPath

import numpy as np
import pytest

pytest.importorskip("pytestqt")

import pyqtgraph as pg  # noqa: E402
from PySide6.QtCore import QMimeData, QPointF, Qt, QUrl  # noqa: E402
from PySide6.QtGui import QDropEvent, QImage  # noqa: E402
from PySide6.QtWidgets import QMessageBox  # noqa: E402

import app.views as views  # noqa: E402
import app.window as window_mod  # noqa: E402
from app.main import UsageError, parse_size  # noqa: E402
from app.window import FILE_FILTER, MainWindow  # noqa: E402
from galvo_core.drawing import UNITS_PER_MM, Drawing, Path  # noqa: E402
from galvo_core.errors import InputError  # noqa: E402

pytestmark = pytest.mark.gui

REPO = FsPath(__file__).resolve().parent.parent
SQUARE_PLT = b"IN;SP1;PU0,0;PD4000,0,4000,4000,0,4000,0,0;PU;"
SIZE = (1000, 640)

# "ink": clearly not background (the faint grid stays below this), summed |RGB| difference
INK_THRESHOLD = 150


# --- helpers --------------------------------------------------------------------------------
def square_drawing(name: str = "square.plt", side_mm: float = 100.0) -> Drawing:
    s = side_mm * UNITS_PER_MM
    return Drawing(paths=(Path.from_points([(0, 0), (s, 0), (s, s), (0, s), (0, 0)]),), name=name)


def many_paths_drawing(n: int) -> Drawing:
    rng = np.random.default_rng(1)
    paths = []
    for i in range(n):
        x0, y0 = (i % 25) * 400.0, (i // 25) * 400.0
        pts = np.c_[x0 + rng.uniform(0, 300, 4), y0 + rng.uniform(0, 300, 4)]
        paths.append(Path.from_points(pts))
    return Drawing(paths=tuple(paths), name=f"many_{n}.plt")


def rgb_array(image: QImage) -> np.ndarray:
    img = image.convertToFormat(QImage.Format.Format_RGB32)
    w, h = img.width(), img.height()
    buf = np.frombuffer(img.constBits(), np.uint8, count=img.sizeInBytes())
    arr = buf.reshape(h, img.bytesPerLine())[:, : w * 4].reshape(h, w, 4)
    return arr[:, :, 2::-1].astype(int)  # BGRA in memory -> RGB


def ink_mask(rgb: np.ndarray, background=(255, 255, 255)) -> np.ndarray:
    return np.abs(rgb - np.array(background)).sum(axis=2) > INK_THRESHOLD


def shown(qtbot, win: MainWindow) -> MainWindow:
    qtbot.addWidget(win)
    win.resize(*SIZE)
    win.show()
    qtbot.waitExposed(win)
    assert win.wait_for_result(60)
    qtbot.wait(20)
    win.fit()
    qtbot.wait(20)
    return win


def load(qtbot, win: MainWindow, drawing: Drawing, path=None) -> None:
    win.set_drawing(drawing, path)
    assert win.wait_for_result(60)
    win.fit()
    qtbot.wait(20)


def left_view_ink(win: MainWindow) -> tuple[np.ndarray, tuple[int, int, int, int]]:
    rgb = rgb_array(win.grab().toImage())
    x, y, w, h = win.original.view_rect_in(win)
    m = 2  # stay off the view's edge
    return ink_mask(rgb[y + m : y + h - m, x + m : x + w - m]), (x, y, w, h)


def units_px(win: MainWindow, ux: float, uy: float, view=None) -> tuple[int, int]:
    """Pixel in the window of a drawing point (input units), via the job's field map."""
    x_mm, y_mm = win.result.preview.units_to_mm(np.array([ux, uy]))
    return (view or win.original).data_to_widget(win, x_mm, y_mm)


def ink_near(win: MainWindow, ux: float, uy: float, radius: int = 3) -> bool:
    rgb = rgb_array(win.grab().toImage())
    px, py = units_px(win, ux, uy)
    patch = rgb[max(py - radius, 0) : py + radius + 1, max(px - radius, 0) : px + radius + 1]
    return bool(ink_mask(patch).any())


@pytest.fixture
def square_plt(tmp_path) -> FsPath:
    p = tmp_path / "square.plt"
    p.write_bytes(SQUARE_PLT)
    return p


@pytest.fixture
def garbage_plt(tmp_path) -> FsPath:
    p = tmp_path / "garbage.plt"
    p.write_bytes(bytes(range(256)) * 8 + b"\x00\xff\xfe" * 100)
    return p


@pytest.fixture
def importer():
    """The real HP-GL importer (tests needing it are skipped until it exists)."""
    mod = pytest.importorskip("galvo_core.hpgl")
    if not hasattr(mod, "read_file"):
        pytest.skip("galvo_core.hpgl.read_file not there yet")
    return mod.read_file


@pytest.fixture
def dialogs(monkeypatch) -> list[QMessageBox]:
    """Error dialogs are recorded instead of blocking in exec()."""
    shown_boxes: list[QMessageBox] = []

    def fake_exec(box):
        shown_boxes.append(box)
        return int(QMessageBox.StandardButton.Ok)

    monkeypatch.setattr(QMessageBox, "exec", fake_exec)
    return shown_boxes


# --- window with drawings built in code --------------------------------------------------------
def test_empty_window_has_empty_left_view(qtbot):
    win = shown(qtbot, MainWindow())
    assert win.drawing is None
    assert win.windowTitle() == "Galvo Workstation"
    ink, _ = left_view_ink(win)
    assert ink.mean() < 0.001, "an empty view should show no ink, only the faint grid"
    assert "No file" in win.status_summary()


def test_view_has_ink_where_the_paths_are(qtbot):
    win = shown(qtbot, MainWindow(square_drawing()))
    ink, (x, y, w, h) = left_view_ink(win)
    assert w > 100 and h > 100
    assert ink.sum() > 200, "the square's outline must be drawn in the left view"
    s = 100 * UNITS_PER_MM
    for ux, uy in [(s / 2, 0), (s, s / 2), (s / 2, s), (0, s / 2), (0, 0), (s, s)]:
        assert ink_near(win, ux, uy), f"no ink at ({ux}, {uy})"
    # the middle of the square is empty
    assert not ink_near(win, s / 2, s / 2, radius=20)


def test_both_views_are_in_workpiece_mm_of_the_field(qtbot):
    win = shown(qtbot, MainWindow(square_drawing(side_mm=50.0)))
    pv = win.result.preview
    fm = win.result.job.field_map
    # true size by default: 50 mm on the drawing is 50 mm on the workpiece, centred in the field
    b = pv.bounds
    assert b[2] - b[0] == pytest.approx(50.0, rel=0.01)
    assert (b[0] + b[2]) / 2 == pytest.approx(fm.field_size_mm / 2, abs=0.1)
    # field outline: bits 0 .. field_bits in mm
    x, y = win.original.field.getData()
    assert x.max() == pytest.approx(fm.field_size_mm)
    # the mark of the first corner is drawn where the original corner is
    first_mark_mm = win.result.job.strokes[0].marks[0] * fm.mm_per_bit
    corner_mm = pv.units_to_mm(np.array([0.0, 0.0]))
    assert first_mark_mm == pytest.approx(corner_mm, abs=2 * fm.mm_per_bit)


def test_views_are_linked_equal_aspect_and_y_up(qtbot):
    win = shown(qtbot, MainWindow(square_drawing()))
    vb_l = win.original.getPlotItem().getViewBox()
    vb_r = win.processed.getPlotItem().getViewBox()
    assert vb_l.state["aspectLocked"] == 1.0 and vb_r.state["aspectLocked"] == 1.0
    assert not vb_l.state["yInverted"] and not vb_r.state["yInverted"]
    vb_l.setRange(xRange=(20, 40), yRange=(20, 40), padding=0)
    qtbot.wait(10)
    (lx, ly), (rx, ry) = vb_l.viewRange(), vb_r.viewRange()
    assert lx == pytest.approx(rx, rel=0.01) and ly == pytest.approx(ry, rel=0.01)
    # y up: a point with a larger y is drawn higher (smaller pixel row)
    _, py_low = win.original.data_to_widget(win, 30, 22)
    _, py_high = win.original.data_to_widget(win, 30, 38)
    assert py_high < py_low


def test_titles_axes_and_icon(qtbot):
    win = shown(qtbot, MainWindow(square_drawing("logo.plt")))
    assert "logo.plt" in win.windowTitle()
    assert win.original.getPlotItem().titleLabel.text == "Original"
    assert win.processed.getPlotItem().titleLabel.text == "Processed"
    for view in (win.original, win.processed):
        assert "mm" in view.getPlotItem().getAxis("bottom").labelText
        assert "mm" in view.getPlotItem().getAxis("left").labelText
    if window_mod.ICON_PATH.is_file():
        assert not win.windowIcon().isNull()


def _plot_items(view) -> list:
    return [i for i in view.getPlotItem().items
            if isinstance(i, (pg.PlotDataItem, views.DeviationItem, views.PointsItem,
                              views.ControlItem, views.LinesItem))]


@pytest.mark.parametrize("n_paths", [1, 500, 3000])
def test_number_of_plot_items_is_fixed(qtbot, n_paths):
    win = shown(qtbot, MainWindow(many_paths_drawing(n_paths)))
    n_left = len([s for s in views.LAYERS if s.view == "original"])
    n_right = len([s for s in views.LAYERS if s.view == "processed"])
    # one item per layer, plus the field outline and the selection highlight
    assert len(_plot_items(win.original)) == n_left + 2
    assert len(_plot_items(win.processed)) == n_right + 2
    kinds = (pg.PlotDataItem, views.PointsItem, views.LinesItem)
    scene_items = [i for i in win.original.scene().items() if isinstance(i, kinds)]
    assert len(scene_items) == n_left + 2
    assert win.original.counts["original"] == 4 * n_paths
    assert win.original.counts["original_points"] == 4 * n_paths


def test_markers_drawn_only_below_the_limit(qtbot, monkeypatch):
    win = shown(qtbot, MainWindow(many_paths_drawing(50)))
    assert win.markers_shown
    assert len(win.original.layers["original_points"].getData()[0]) == 200
    monkeypatch.setattr(views, "MAX_MARKER_POINTS", 100)
    load(qtbot, win, many_paths_drawing(50))
    assert not win.markers_shown
    x, _ = win.original.layers["original_points"].getData()
    assert x is None or len(x) == 0
    assert win.original.counts["original"] == 200


def test_processed_view_shows_fit_controls_and_marks(qtbot):
    win = shown(qtbot, MainWindow(square_drawing()))
    c = win.processed.counts
    assert c["fitted"] >= 5 and c["marks"] >= 5 and c["control"] >= 5
    assert c["hatch"] == 0 and c["kerf"] == 0  # features off: the layers are simply empty
    stats = win.result.job.stats
    assert win.stats_panel.shown_number("mark_points") == stats["mark_points"]


def test_status_bar_counts(qtbot):
    d = Drawing(
        paths=(
            Path.from_points([(0, 0), (4000, 0), (4000, 2000), (0, 2000), (0, 0)]),
            Path.from_points([(100, 100), (200, 200)]),
        ),
        name="two.plt",
    )
    win = shown(qtbot, MainWindow())
    win.set_drawing(d, "/some/where/two.plt")
    assert win.wait_idle(60)
    summary = win.status_summary()
    assert win.status_label.text() == summary
    assert "2 paths" in summary
    assert "7 points" in summary
    assert "1 closed" in summary
    assert "100.00 × 50.00 mm" in summary
    assert "two.plt" in summary
    assert "two.plt" in win.windowTitle()
    # one warning count in the status bar (the job's, which includes the file's)
    assert "warning" not in summary
    n = len(win.result.job.warnings)
    assert win.warnings_label.text().split()[-2:] == [str(n), "warning" + ("s" if n != 1 else "")]


# --- loading: refused files and crashes become dialogs, the drawing stays -----------------------
def test_refused_file_shows_dialog_and_keeps_drawing(qtbot, monkeypatch, dialogs, tmp_path):
    win = shown(qtbot, MainWindow())
    load(qtbot, win, square_drawing("keep.plt"), "keep.plt")
    kept = win.drawing

    def refuse(path):
        raise InputError(FsPath(path).name, "not an HP-GL file")

    monkeypatch.setattr(window_mod, "load_drawing", refuse)
    assert win.load_file(tmp_path / "bad.plt", wait=True) is False
    assert len(dialogs) == 1
    box = dialogs[0]
    assert box.icon() == QMessageBox.Icon.Critical
    assert "bad.plt: not an HP-GL file" in box.informativeText() + box.text()
    assert "Traceback" not in box.informativeText()
    assert win.drawing is kept
    assert "keep.plt" in win.windowTitle()
    assert win.original.counts["original"] == 5


def test_unexpected_exception_becomes_dialog(qtbot, monkeypatch, dialogs, tmp_path):
    win = shown(qtbot, MainWindow(square_drawing("keep.plt")))
    kept = win.drawing

    def boom(path):
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(window_mod, "load_drawing", boom)
    assert win.load_file(tmp_path / "x.plt", wait=True) is False
    assert len(dialogs) == 1
    msg = dialogs[0].informativeText()
    assert "x.plt" in msg and "ZeroDivisionError" in msg
    assert win.drawing is kept


def test_unreadable_file_shows_dialog(qtbot, dialogs, tmp_path):
    win = shown(qtbot, MainWindow(square_drawing("keep.plt")))
    kept = win.drawing
    win.load_file(tmp_path / "does_not_exist.plt", wait=True)  # InputError or OSError
    assert len(dialogs) == 1
    assert "does_not_exist.plt" in dialogs[0].informativeText()
    assert win.drawing is kept


def test_error_dialog_is_buildable(qtbot):
    win = shown(qtbot, MainWindow())
    box = win.build_error_dialog("f.plt: empty file")
    assert box.icon() == QMessageBox.Icon.Critical
    assert box.informativeText() == "f.plt: empty file"
    assert "Galvo Workstation" in box.windowTitle()


# --- with the real importer ----------------------------------------------------------------------
def test_window_opens_on_a_file(qtbot, importer, square_plt):
    win = shown(qtbot, MainWindow())
    assert win.load_file(square_plt, wait=True) is True
    assert win.wait_for_result(60)
    assert "square.plt" in win.windowTitle()
    assert "100.00 × 100.00 mm" in win.status_summary()
    win.fit()
    qtbot.wait(20)
    ink, _ = left_view_ink(win)
    assert ink.sum() > 200
    assert ink_near(win, 2000, 0) and ink_near(win, 4000, 2000)


def test_garbage_file_is_refused_with_importer_message(qtbot, importer, dialogs, garbage_plt):
    with pytest.raises(InputError) as info:
        importer(garbage_plt)
    win = shown(qtbot, MainWindow(square_drawing("keep.plt")))
    kept = win.drawing
    assert win.load_file(garbage_plt, wait=True) is False
    assert len(dialogs) == 1
    assert str(info.value) in dialogs[0].informativeText()
    assert win.drawing is kept


# --- menus and drops -----------------------------------------------------------------------------
def test_file_menu(qtbot, monkeypatch):
    win = shown(qtbot, MainWindow())
    texts = [a.text().replace("&", "") for a in win.menuBar().actions()]
    assert texts[0] == "File"
    file_actions = [a.text().replace("&", "") for a in win.menuBar().actions()[0].menu().actions()]
    assert "Open…" in file_actions and "Quit" in file_actions
    for ext in ("*.plt", "*.hpgl", "*.hpg", "*.hp ", "*.pgl", "*.pcl", "*.spl", "All files"):
        assert ext in FILE_FILTER

    opened = []
    monkeypatch.setattr(
        window_mod.QFileDialog, "getOpenFileName", lambda *a, **k: ("/tmp/x.plt", FILE_FILTER)
    )
    monkeypatch.setattr(win, "load_file", lambda p: opened.append(p))
    win.open_action.trigger()
    assert opened == ["/tmp/x.plt"]


def test_quit_closes_window(qtbot):
    win = shown(qtbot, MainWindow())
    win.quit_action.trigger()
    assert not win.isVisible()


def test_drop_a_file_loads_it(qtbot, monkeypatch, tmp_path):
    win = shown(qtbot, MainWindow())
    monkeypatch.setattr(window_mod, "load_drawing", lambda p: square_drawing(FsPath(p).name))
    win.settings.remove("recent_files")
    target = tmp_path / "dropped.plt"
    target.write_bytes(SQUARE_PLT)
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(target))])
    ev = QDropEvent(
        QPointF(50, 50),
        Qt.DropAction.CopyAction,
        mime,
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
    )
    win.dropEvent(ev)
    assert win.wait_idle(30)
    assert win.drawing is not None
    assert "dropped.plt" in win.windowTitle()
    assert win.recent_files()[0].endswith("dropped.plt")
    # drops of non-files are ignored
    text_mime = QMimeData()
    text_mime.setText("hello")
    ev2 = QDropEvent(
        QPointF(50, 50),
        Qt.DropAction.CopyAction,
        text_mime,
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
    )
    win.dropEvent(ev2)
    assert "dropped.plt" in win.windowTitle()
    assert win.acceptDrops()
    assert not win.original.acceptDrops() and not win.processed.acceptDrops()


# --- command line ---------------------------------------------------------------------------
def run_cli(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.pop("QT_QPA_PLATFORM", None)  # the program must pick offscreen itself
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run(
        [sys.executable, "-m", "app.main", *args],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def png_left_ink(path: FsPath) -> float:
    img = QImage(str(path))
    assert not img.isNull(), "not a valid image"
    rgb = rgb_array(img)
    h, w = rgb.shape[:2]
    left = rgb[int(h * 0.12) : int(h * 0.85), int(w * 0.08) : int(w * 0.48)]
    return float(ink_mask(left).mean())


def test_parse_size():
    assert parse_size("1400x800") == (1400, 800)
    assert parse_size("640X480") == (640, 480)
    for bad in ("", "1400", "x800", "10x10", "1400x800x3", "-5x100", "abc", "99999x800"):
        with pytest.raises(UsageError):
            parse_size(bad)


@pytest.mark.slow
def test_screenshot_cli_writes_png_of_requested_size(importer, square_plt, tmp_path):
    out = tmp_path / "shot.png"
    r = run_cli(str(square_plt), "--screenshot", str(out), "--size", "900x600")
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    img = QImage(str(out))
    assert (img.width(), img.height()) == (900, 600)
    assert png_left_ink(out) > 0.002, "the left view should show the square"


@pytest.mark.slow
def test_screenshot_cli_default_size_and_bundled_sample(importer, tmp_path):
    if window_mod.bundled_sample() is None:
        pytest.skip("no bundled sample in resources/samples yet")
    out = tmp_path / "sample.png"
    r = run_cli("--screenshot", str(out))
    assert r.returncode == 0, r.stderr
    img = QImage(str(out))
    assert (img.width(), img.height()) == (1400, 800)
    assert png_left_ink(out) > 0.002


@pytest.mark.slow
@pytest.mark.parametrize(
    "args",
    [
        ["--screenshot", "{out}", "--size", "12x"],
        ["--screenshot", "{out}", "--size", "0x0"],
        ["--screenshot", "{out}", "--size", "1400x800x2"],
        ["--size", "1400x800"],  # --size without --screenshot
        ["--screenshot", "{out}", "--bogus"],
        ["a.plt", "b.plt", "--screenshot", "{out}"],
    ],
)
def test_screenshot_cli_bad_args_exit_2(tmp_path, args):
    r = run_cli(*(a.replace("{out}", str(tmp_path / "o.png")) for a in args))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    assert not (tmp_path / "o.png").exists()


@pytest.mark.slow
def test_screenshot_cli_refused_file_exit_2(importer, garbage_plt, tmp_path):
    out = tmp_path / "o.png"
    r = run_cli(str(garbage_plt), "--screenshot", str(out))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    assert "garbage.plt" in lines[0]
    assert not out.exists()


@pytest.mark.slow
def test_screenshot_cli_missing_file_and_bad_output_folder(importer, tmp_path):
    r = run_cli(str(tmp_path / "nope.plt"), "--screenshot", str(tmp_path / "o.png"))
    assert r.returncode == 2 and r.stderr.startswith("error: "), r.stderr
    assert "nope.plt" in r.stderr
    r = run_cli("--screenshot", str(tmp_path / "no_such_dir" / "o.png"))
    assert r.returncode == 2 and r.stderr.startswith("error: "), r.stderr
