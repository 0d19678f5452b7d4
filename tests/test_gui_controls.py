"""The workstation's live controls (issue 8): each control moves the result the right way,
as the window shows it; the worker keeps the window responsive; files, export, settings;
screenshots by pixel statistics and a few golden images.

Golden images live in tests/golden/; regenerate them with GALVO_REGEN_GOLDEN=1.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path as FsPath

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from _util import SAMPLES, circle_plt  # noqa: E402
from PySide6.QtCore import QTimer  # noqa: E402
from PySide6.QtGui import QImage  # noqa: E402

from app import views  # noqa: E402
from app.controls import GROUPS, SLIDER_STEPS, SliderSpec  # noqa: E402
from app.main import UsageError, params_from_sets  # noqa: E402
from app.window import MainWindow  # noqa: E402
from app.worker import LatestRunner  # noqa: E402
from galvo_core import pipeline as pipeline_mod  # noqa: E402
from galvo_core.drawing import Drawing, Path  # noqa: E402
from galvo_core.hpgl import read_bytes, read_file  # noqa: E402
from galvo_core.job import load_job  # noqa: E402
from galvo_core.params import Params  # noqa: E402
from galvo_core.pipeline import Cancelled  # noqa: E402

pytestmark = pytest.mark.gui

REPO = FsPath(__file__).resolve().parent.parent
GOLDEN = FsPath(__file__).resolve().parent / "golden"
REGEN = os.environ.get("GALVO_REGEN_GOLDEN") == "1"
SIZE = (1200, 760)
WARN_PLT = b"IN;SP1;PU0,0;PD400,0,400,300;XX1;PU;PA1200,1200;PD1500,1500;\nPU2000,0;ZZ;PD2400,0;"


# --- helpers -----------------------------------------------------------------------------
def rgb_array(image: QImage) -> np.ndarray:
    img = image.convertToFormat(QImage.Format.Format_RGB32)
    w, h = img.width(), img.height()
    buf = np.frombuffer(img.constBits(), np.uint8, count=img.sizeInBytes())
    return buf.reshape(h, img.bytesPerLine())[:, : w * 4].reshape(h, w, 4)[:, :, 2::-1].astype(int)


def colour_fraction(rgb: np.ndarray, colour: str, tol: int = 40) -> float:
    c = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
    return float((np.abs(rgb - c).sum(axis=2) < tol).mean())


def ink(rgb: np.ndarray) -> float:
    return float((np.abs(rgb - 255).sum(axis=2) > 150).mean())


def view_rgb(win: MainWindow, view) -> np.ndarray:
    rgb = rgb_array(win.grab().toImage())
    x, y, w, h = view.view_rect_in(win)
    return rgb[y + 2 : y + h - 2, x + 2 : x + w - 2]


def make_window(qtbot, drawing: Drawing | None = None, path=None, **kw) -> MainWindow:
    win = MainWindow(restore=False, **kw)
    qtbot.addWidget(win)
    win.resize(*SIZE)
    win.show()
    qtbot.waitExposed(win)
    if drawing is not None:
        win.set_drawing(drawing, path)
        assert win.wait_for_result(60)
    win.fit()
    qtbot.wait(10)
    return win


def move(win: MainWindow, name: str, value: float) -> None:
    """Move a slider to ``value`` and release it, as an operator would; wait for the result."""
    s = win.controls.sliders[name]
    s.set_position(s.to_position(value), final=True)
    assert win.wait_for_result(60)


def shown(win: MainWindow, key: str) -> float:
    return win.stats_panel.shown_number(key)


def uses(stage: str) -> bool:
    """True when galvo_core.pipeline calls the module of ``stage`` (kerf, fill, order)."""
    src = FsPath(pipeline_mod.__file__).read_text(encoding="utf-8")
    return bool(re.search(rf"galvo_core\.{stage}\b|from galvo_core import [^\n]*\b{stage}\b",
                          src))


@pytest.fixture(scope="module")
def circle() -> Drawing:
    return read_bytes(circle_plt(), "circle.plt")


@pytest.fixture(scope="module")
def seal() -> Drawing:
    return read_file(SAMPLES / "seal.plt")


def square(side_units: float = 2000.0) -> Drawing:
    s = side_units
    return Drawing(paths=(Path.from_points([(0, 0), (s, 0), (s, s), (0, s), (0, 0)]),),
                   name="square.plt")


# --- each control moves the result the right way (as the window shows it) ------------------
def test_defaults_come_from_galvo_core(qtbot):
    win = make_window(qtbot)
    d = Params()
    for name, s in win.controls.sliders.items():
        if getattr(d, name) is not None:
            assert s.value() == pytest.approx(getattr(d, name)), name
    for name, combo in win.controls.combos.items():
        assert combo.currentText() == getattr(d, name)
    assert win.params == d or win.params.processing_dict() == d.processing_dict()


def test_larger_e_per_gives_fewer_control_points(qtbot, circle):
    win = make_window(qtbot, circle)
    move(win, "e_per", 0.005)
    few_tol = shown(win, "control_points")
    fitted_before = win.result.fitted
    move(win, "e_per", 0.5)
    assert win.result.params.e_per == pytest.approx(0.5, rel=0.01)
    assert shown(win, "control_points") < few_tol
    # refitted (by this run, or by a run the release cancelled after its fit stage)
    assert win.result.fitted is not fitted_before


def test_larger_magnification_gives_more_marks_without_refitting(qtbot, circle):
    win = make_window(qtbot, circle)
    move(win, "magnification", 5.0)
    low = shown(win, "mark_points")
    move(win, "magnification", 40.0)
    assert shown(win, "mark_points") > low
    assert win.result.stages_run == ("sample",), "moving the magnification must not refit"
    assert "1 u = " in win.controls.sliders["magnification"].info.text()
    # conversions follow the magnification: e_per in µm doubles with it
    before = win.controls.sliders["e_per"].info.text()
    move(win, "magnification", 80.0)
    assert win.controls.sliders["e_per"].info.text() != before


def test_larger_chord_tolerance_gives_fewer_marks(qtbot, circle):
    win = make_window(qtbot, circle)
    move(win, "chord_tol_bits", 0.2)
    many = shown(win, "mark_points")
    move(win, "chord_tol_bits", 20.0)
    assert shown(win, "mark_points") < many


def test_fit_field_checkbox(qtbot, circle):
    win = make_window(qtbot, circle)
    win.controls.fit_field.setChecked(True)
    assert win.wait_for_result(60)
    mag = win.result.job.field_map.magnification
    assert mag > 50  # a 20 mm circle fills the 110 mm field
    assert win.controls.sliders["magnification"].value() == pytest.approx(mag, rel=1e-3)
    assert not win.controls.sliders["magnification"].slider.isEnabled()


@pytest.mark.skipif(not uses("kerf"), reason="kerf compensation is not wired into "
                    "galvo_core.pipeline yet (runs as soon as pipeline.py uses galvo_core.kerf)")
def test_kerf_moves_the_outline(qtbot):
    win = make_window(qtbot, square())
    length0 = shown(win, "mark_length_mm")
    assert win.processed.counts["kerf"] == 0
    win.controls.combos["kerf_side"].setCurrentText("outside")
    move(win, "kerf_mm", 1.0)
    assert win.processed.counts["kerf"] > 0
    assert shown(win, "mark_length_mm") > length0  # outside: a longer outline
    x, y = (a for a in win.processed.layers["kerf"].getData())
    outline = win.result.preview.units_to_mm(np.c_[x, y])
    orig = win.result.preview.bounds
    assert np.nanmax(outline[:, 0]) - np.nanmin(outline[:, 0]) > 0
    assert orig is not None


@pytest.mark.skipif(not uses("fill"), reason="fill is not wired into galvo_core.pipeline yet "
                    "(runs as soon as pipeline.py uses galvo_core.fill)")
def test_zigzag_fill_gives_fewer_switches_than_scanline(qtbot):
    win = make_window(qtbot, square(4000.0))
    move(win, "hatch_spacing_mm", 2.0)
    win.controls.combos["fill"].setCurrentText("scanline")
    assert win.wait_for_result(60)
    scan = shown(win, "laser_switches")
    assert win.processed.counts["hatch"] > 0
    win.controls.combos["fill"].setCurrentText("zigzag")
    assert win.wait_for_result(60)
    assert shown(win, "laser_switches") < scan


def _slider_specs() -> list[SliderSpec]:
    return [i for _, items in GROUPS for i in items if isinstance(i, SliderSpec)]


def test_every_slider_at_both_extremes(qtbot, circle, dialogs):
    win = make_window(qtbot, circle)
    for spec in _slider_specs():
        if spec.name not in win.controls.sliders:
            continue
        s = win.controls.sliders[spec.name]
        for pos in (0, SLIDER_STEPS):
            s.set_position(pos, final=True)
            assert win.wait_for_result(60), spec.name
            assert win.result is not None
            # either a result for these params or an error in the warnings panel
            assert win.run_error or win.result.params == win.params, spec.name
        win.set_params(Params())  # back to defaults before the next slider
        assert win.wait_for_result(60)
    assert not dialogs
    assert win.isVisible()


def test_drawing_leaving_the_field_is_an_error_in_the_panel_not_a_crash(qtbot, circle, dialogs):
    win = make_window(qtbot, circle)
    move(win, "magnification", 2000.0)
    assert win.run_error and "field" in win.run_error
    assert any("field" in t for t in win.warnings_panel.texts())
    assert win.original.counts["original"] > 0  # the drawing is still shown
    assert win.processed.counts["marks"] == 0
    assert not dialogs
    move(win, "magnification", 20.0)
    assert win.run_error is None and win.processed.counts["marks"] > 0


def test_laser_dialog_defaults_and_time(qtbot, circle, monkeypatch):
    from app.controls import LaserDialog
    from galvo_core.params import LaserParams

    dlg = LaserDialog(LaserParams())
    qtbot.addWidget(dlg)
    assert dlg.values() == LaserParams().as_dict()
    dlg.spins["mark_speed_mm_s"].setValue(1000.0)
    dlg._accept()
    assert dlg.result_laser.mark_speed_mm_s == 1000.0
    win = make_window(qtbot, circle)
    slow = shown(win, "estimated_time_s")
    win.apply_changes({"laser": dlg.result_laser})
    assert win.wait_for_result(60)
    assert shown(win, "estimated_time_s") < slow


# --- live, never frozen ------------------------------------------------------------------
def test_dragging_is_throttled_and_the_release_wins(qtbot, circle):
    win = make_window(qtbot, circle)
    s = win.controls.sliders["magnification"]
    started = win.runner.n_started
    for v in np.linspace(10.0, 30.0, 25):
        s.set_position(s.to_position(float(v)), final=False)
    s.set_position(s.to_position(33.0), final=True)
    assert win.wait_for_result(60)
    assert win.runner.n_started - started <= 4, "drag updates must be throttled"
    assert win.result.params.magnification == pytest.approx(s.value())
    assert win.runner.max_in_flight == 1


def test_runner_newest_wins_and_stays_responsive(qtbot):
    runner = LatestRunner()
    delivered: list[int] = []
    runner.finished.connect(lambda gen, res: delivered.append(res))
    ticks: list[float] = []
    timer = QTimer()
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start(10)

    def slow(value):
        def task(cancel):
            for _ in range(40):
                if cancel():
                    raise Cancelled()
                time.sleep(0.005)
            return value

        return task

    for v in range(6):
        runner.request(slow(v))
    assert runner.wait_idle(30)
    timer.stop()
    assert delivered == [5], "only the newest request is delivered"
    assert runner.max_in_flight == 1
    assert runner.n_started <= 3  # the first, maybe one cancelled, and the newest
    assert len(ticks) >= 5, "the event loop must keep running while the worker works"


def test_cancel_keeps_the_last_result(qtbot, circle, monkeypatch):
    win = make_window(qtbot, circle)
    shown_before = win.result
    gate = threading.Event()
    real_run = win.pipeline.run

    def slow_run(drawing, params, cancel=None):
        while not gate.wait(0.01):
            if cancel is not None and cancel():
                raise Cancelled()
        return real_run(drawing, params, cancel)

    monkeypatch.setattr(win.pipeline, "run", slow_run)
    s = win.controls.sliders["e_per"]
    s.set_position(s.to_position(0.3), final=True)
    qtbot.waitUntil(lambda: win.progress.isVisible(), timeout=5000)
    assert win.cancel_button.isVisible()
    ticks = []
    QTimer.singleShot(5, lambda: ticks.append(1))
    qtbot.waitUntil(lambda: bool(ticks), timeout=2000)  # responsive while a run is in flight
    win.cancel_processing()
    assert win.wait_for_result(10)
    assert win.result is shown_before
    assert not win.progress.isVisible()


def test_internal_error_in_a_run_is_reported_not_raised(qtbot, circle, monkeypatch):
    win = make_window(qtbot, circle)

    def boom(*a, **k):
        raise ZeroDivisionError("boom")

    monkeypatch.setattr(win.pipeline, "run", boom)
    move(win, "e_per", 0.1)
    assert win.run_error and "ZeroDivisionError" in win.run_error
    assert any("ZeroDivisionError" in t for t in win.warnings_panel.texts())


# --- views: hover, selection, warnings, layers --------------------------------------------
def test_hover_text_has_mm_units_and_bits(qtbot, circle):
    win = make_window(qtbot, circle)
    pv = win.result.preview
    x, y = pv.units_to_mm(np.array([1000.0, 600.0]))
    text = win.cursor_text(x, y)
    assert "mm" in text and "1000.0, 600.0 u" in text and "bits" in text
    bits = pv.mm_to_bits(np.array([x, y]))
    assert f"X {bits[0]:.0f}" in text


def test_click_selects_a_path_in_both_views(qtbot):
    d = read_bytes(WARN_PLT, "warn.plt")
    win = make_window(qtbot, d)
    pv = win.result.preview
    x, y = pv.units_to_mm(d.paths[1].points[0])
    assert win.select_at(x, y) == 1
    for v in (win.original, win.processed):
        hx, _ = v.highlight.getData()
        assert hx is not None and len(hx) >= 2
    text = win.stats_panel.selection.text()
    assert "Path 2" in text and "input points" in text and "marks" in text
    win.select_at(x + 500, y + 500)
    assert win.selected is None
    hx, _ = win.original.highlight.getData()
    assert hx is None or len(hx) == 0


def test_clicking_a_warning_zooms_to_its_path(qtbot):
    d = read_bytes(WARN_PLT, "warn.plt")
    win = make_window(qtbot, d)
    texts = win.warnings_panel.texts()
    assert any("line 2" in t and "ZZ" in t for t in texts)
    idx = next(i for i, w in enumerate(win.warnings_panel.warnings) if "ZZ" in w.message)
    item = win.warnings_panel.list.item(idx)
    win.warnings_panel.list.itemClicked.emit(item)
    qtbot.wait(10)
    (x0, x1), _ = win.original.getPlotItem().getViewBox().viewRange()
    px, _ = win.result.preview.units_to_mm(d.paths[2].points[0])
    assert x0 <= px <= x1
    assert x1 - x0 < 40  # zoomed in (the whole drawing is 60 mm wide)
    assert win.selected == 2
    (rx0, rx1), _ = win.processed.getPlotItem().getViewBox().viewRange()
    assert (rx0, rx1) == pytest.approx((x0, x1), abs=0.01 * (x1 - x0))  # linked, to a pixel


def test_layers_toggle_and_show_empty_when_off(qtbot, circle):
    win = make_window(qtbot, circle)
    for key in views.LAYER_KEYS:
        view = win.original if key in win.original.layers else win.processed
        for on in (not win.layer_boxes[key].isChecked(), True):
            win.layer_boxes[key].setChecked(on)
            assert view.layers[key].isVisible() == on
            assert win.layer_actions[key].isChecked() == on
    assert win.processed.colorbar is not None  # deviation on: its colour bar in µm
    assert "µm" in win.processed.colorbar.label
    top = win.result.preview.tolerance_um
    assert win.processed.colorbar.tick_labels()[0] == f"{top:.3g}"
    win.layer_boxes["deviation"].setChecked(False)
    assert win.processed.colorbar is None


# --- files -------------------------------------------------------------------------------
def test_refused_and_empty_files(qtbot, tmp_path, dialogs, circle):
    win = make_window(qtbot, circle, "circle.plt")
    kept = win.drawing
    bad = tmp_path / "garbage.plt"
    bad.write_bytes(bytes(range(256)) * 4)
    empty = tmp_path / "empty.plt"
    empty.write_bytes(b"")
    for f in (bad, empty):
        assert win.load_file(f, wait=True) is False
        assert win.drawing is kept
    assert len(dialogs) == 2 and "empty" in dialogs[1].informativeText()
    no_geometry = tmp_path / "nothing.plt"
    no_geometry.write_bytes(b"IN;SP1;PU;")
    assert win.load_file(no_geometry, wait=True) is True
    assert win.wait_for_result(30)
    assert win.processed.counts["marks"] == 0
    assert any("no pen-down" in t for t in win.warnings_panel.texts())


def test_export_job_png_and_load_the_job_back(qtbot, tmp_path, dialogs):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    win = make_window(qtbot)
    assert win.load_file(src, wait=True) and win.wait_for_result(60)
    job_path = tmp_path / "circle.json"
    assert win.export("job", job_path)
    job = load_job(job_path)
    assert job.stats["mark_points"] == win.result.job.stats["mark_points"]
    png = tmp_path / "views.png"
    assert win.export("png", png)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # a failing export leaves nothing behind and says why
    bad = tmp_path / "no_such_dir" / "x.json"
    assert win.export("job", bad) is False
    assert not bad.parent.exists() and dialogs
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".tmp")] == []
    # the job file back: its marks, and the source found beside it
    n_marks = win.processed.counts["marks"]
    assert win.load_file(job_path, wait=True) and win.wait_for_result(30)
    assert win.job_path == job_path and win.banner.isVisible()
    assert win.processed.counts["marks"] == n_marks
    assert win.original.counts["original"] > 0
    assert not win.controls.isEnabled()
    src.unlink()  # without the source: the original view is empty
    assert win.load_job_file(job_path, wait=True) and win.wait_for_result(30)
    assert win.original.counts["original"] == 0 and win.processed.counts["marks"] == n_marks
    assert "job" in win.windowTitle() or "circle.json" in win.windowTitle()


def test_plt_and_svg_export_write_what_galvo_core_export_writes(qtbot, tmp_path, circle):
    """File > Export PLT/SVG write the shown job through galvo_core.export: the same bytes
    as the headless writers."""
    from galvo_core.export import write_plt, write_svg

    win = make_window(qtbot, circle)
    assert win.export_plt_action.isEnabled() and win.export_svg_action.isEnabled()
    job = win.current_job()
    assert job is not None
    for kind, write in (("plt", write_plt), ("svg", write_svg)):
        out, ref = tmp_path / f"gui.{kind}", tmp_path / f"ref.{kind}"
        assert win.export(kind, out)
        write(job, ref)
        assert out.read_bytes() == ref.read_bytes()


def test_reload_when_the_file_changes_on_disk(qtbot, tmp_path):
    f = tmp_path / "live.plt"
    f.write_bytes(b"IN;SP1;PU0,0;PD1000,0,1000,1000;PU;")
    win = make_window(qtbot)
    assert win.load_file(f, wait=True) and win.wait_for_result(30)
    assert win.original.counts["original"] == 3
    f.write_bytes(b"IN;SP1;PU0,0;PD1000,0,1000,1000,0,1000,0,0;PU;")
    qtbot.waitUntil(lambda: win.drawing is not None and win.drawing.n_points == 5,
                    timeout=5000)
    assert win.wait_for_result(30)
    assert win.original.counts["original"] == 5


def test_settings_and_recent_files_persist(qtbot, tmp_path):
    from PySide6.QtCore import QSettings

    ini = tmp_path / "s.ini"
    f = tmp_path / "a.plt"
    f.write_bytes(circle_plt(n=90))
    win = MainWindow(settings=QSettings(str(ini), QSettings.Format.IniFormat))
    qtbot.addWidget(win)
    win.show()
    assert win.load_file(f, wait=True) and win.wait_for_result(30)
    win.apply_changes({"e_per": 0.123})
    win.layer_boxes["jumps"].setChecked(False)
    win.close()
    again = MainWindow(settings=QSettings(str(ini), QSettings.Format.IniFormat))
    qtbot.addWidget(again)
    assert again.params.e_per == pytest.approx(0.123)
    assert again.controls.sliders["e_per"].value() == pytest.approx(0.123)
    assert not again.layer_boxes["jumps"].isChecked()
    assert again.recent_files()[0].endswith("a.plt")
    actions = again.recent_menu.actions()
    assert actions and actions[0].text() == "a.plt"


# --- screenshots ---------------------------------------------------------------------------
def test_screenshot_pixels_of_the_seal(qtbot, seal):
    win = make_window(qtbot, seal)
    win.layer_boxes["deviation"].setChecked(True)
    qtbot.wait(20)
    left, right = view_rgb(win, win.original), view_rgb(win, win.processed)
    assert ink(left) > 0.02 and ink(right) > 0.02
    assert colour_fraction(left, views.ORIGINAL_POINT) > 0.002
    assert colour_fraction(right, views.MARK) > 0.001
    assert colour_fraction(right, views.CONTROL) > 0.001
    assert colour_fraction(left, views.MARK) == 0  # marks only on the right
    # the deviation overlay is coloured (green for well within tolerance)
    win.layer_boxes["fitted"].setChecked(False)
    win.layer_boxes["marks"].setChecked(False)
    win.layer_boxes["control"].setChecked(False)
    qtbot.wait(20)
    right = view_rgb(win, win.processed)
    cols = (views.DEVIATION_STOPS[0], views.DEVIATION_STOPS[1], views.DEVIATION_STOPS[2])
    assert sum(colour_fraction(right, c, 60) for c in cols) > 0.002


def _golden(name: str, image: QImage, tol: float = 6.0) -> None:
    GOLDEN.mkdir(exist_ok=True)
    path = GOLDEN / f"{name}.png"
    if REGEN or not path.exists():
        if not REGEN and os.environ.get("CI"):
            pytest.fail(f"golden image {path.name} missing (GALVO_REGEN_GOLDEN=1 makes it)")
        image.save(str(path))
        if not REGEN:
            pytest.skip(f"golden image {path.name} created; rerun to compare")
        return
    want = QImage(str(path))
    got = rgb_array(image)
    ref = rgb_array(want)
    assert got.shape == ref.shape, f"{name}: size {got.shape} != golden {ref.shape}"
    diff = np.abs(got - ref).sum(axis=2)
    changed = float((diff > 90).mean())
    mean = float(diff.mean())
    if changed > 0.01 or mean > tol:
        image.save(f"/tmp/golden-{name}-actual.png")
    assert changed <= 0.01 and mean <= tol, (
        f"{name}: {changed:.2%} pixels differ (mean |Δ| {mean:.2f}); actual saved to "
        f"/tmp/golden-{name}-actual.png; GALVO_REGEN_GOLDEN=1 to accept")


@pytest.mark.parametrize("layers", ["default", "deviation"])
def test_golden_views_of_curve_1181(qtbot, layers):
    win = make_window(qtbot, read_file(SAMPLES / "curve_1181.plt"))
    win.resize(1000, 600)
    if layers == "deviation":
        for k in ("original_points", "marks", "control", "jumps"):
            win.layer_boxes[k].setChecked(False)
        win.layer_boxes["deviation"].setChecked(True)
    qtbot.wait(30)
    win.fit()
    qtbot.wait(30)
    _golden(f"curve_1181_{layers}", win.splitter.grab().toImage())


# --- command line ----------------------------------------------------------------------------
def test_params_from_sets():
    p = params_from_sets(["e_per=0.05", "magnification=36", "fit_field=false", "fill=zigzag",
                          "mark_speed_mm_s=500", "offset_bits=100,200", "max_step_bits=none"])
    assert (p.e_per, p.magnification, p.fill) == (0.05, 36.0, "zigzag")
    assert p.laser.mark_speed_mm_s == 500 and p.offset_bits == (100.0, 200.0)
    for bad in (["nope=1"], ["e_per=-1"], ["e_per=abc"], ["fill=spiral"], ["e_per"],
                ["field_bits=1.5"], ["fit_field=maybe"]):
        with pytest.raises(UsageError):
            params_from_sets(bad)


def run_cli(*args: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.pop("QT_QPA_PLATFORM", None)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-m", "app.main", *args], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_screenshot_cli_with_settings(tmp_path):
    out = tmp_path / "o.png"
    r = run_cli(str(SAMPLES / "curve_1181.plt"), "--screenshot", str(out), "--size", "900x560",
                "--set", "e_per=0.05", "--set", "magnification=36")
    assert r.returncode == 0, r.stderr
    img = rgb_array(QImage(str(out)))
    assert img.shape[:2] == (560, 900)
    assert colour_fraction(img, views.MARK) > 0.0005  # the processed view was drawn
    for bad in (["--set", "bogus=1"], ["--set", "e_per=-3"], ["--set", "magnification=x"]):
        r = run_cli(str(SAMPLES / "curve_1181.plt"), "--screenshot", str(out), *bad)
        assert r.returncode == 2
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    assert json.dumps  # (json imported for job checks above)


def test_a_long_warnings_list_is_filled_over_several_passes(qtbot):
    """A kerf that swallows thousands of rings warns once per ring: the panel lists the
    first ones at once and the rest over the next event-loop passes (the GUI thread is
    never held for all of them); a new list stops the old one's filling; all are there
    to read and click."""
    from PySide6.QtCore import Qt

    from app.stats import WarningsPanel
    from galvo_core.drawing import Warning

    panel = WarningsPanel()
    qtbot.addWidget(panel)
    many = tuple(Warning(i + 1, 1, f"ring {i} was swallowed") for i in range(1000))
    seen: list[int] = []
    panel.activated.connect(seen.append)
    panel.set_warnings(many)
    assert panel.list.count() == panel.WARNINGS_PER_PASS
    qtbot.waitUntil(lambda: panel.list.count() == len(many), timeout=5000)
    assert panel.list.item(999).text().endswith("ring 999 was swallowed")
    panel.list.itemClicked.emit(panel.list.item(999))
    assert seen == [999]
    panel.set_warnings(many)  # the same warnings again: nothing to redo
    assert panel.list.count() == len(many)
    few = many[:3]
    panel.set_warnings(many[::-1])
    panel.set_warnings(few, error="out of the field")  # before the long one is filled
    qtbot.wait(50)
    assert panel.texts() == ["✖ out of the field"] + [f"⚠ line {w.line}, col 1: {w.message}"
                                                      for w in few]
    assert panel.list.item(0).data(Qt.ItemDataRole.UserRole) == -1
