"""Pen layers in the window (issue 19, GUI side): the layer table beside the processing
panel re-makes the shown job live, the pen table is part of what the shown result was made
of (never a stale export), pen table files, File ▸ Export ▸ LMC list / text.

Driven through the window's scripting surface (``load_file``, ``wait_idle``, ``export``,
``current_job``) and the table's editors, offscreen, on a two-pen file.
"""

from __future__ import annotations

import pytest

pytest.importorskip("pytestqt")

from test_cli_lmc import two_pen_plt  # noqa: E402

from app.window import MainWindow  # noqa: E402
from galvo_core.layers import load_pen_table  # noqa: E402
from galvo_core.lmc import (  # noqa: E402
    bits_per_mm,
    decode,
    encode_job,
    expected_strokes,
    speed_word,
    to_text,
)
from galvo_core.params import LaserParams  # noqa: E402

pytestmark = pytest.mark.gui

SIZE = (1400, 800)


@pytest.fixture
def two(tmp_path):
    p = tmp_path / "two.plt"
    p.write_bytes(two_pen_plt())
    return p


@pytest.fixture
def win(qtbot, two) -> MainWindow:
    w = MainWindow(restore=False)
    qtbot.addWidget(w)
    w.resize(*SIZE)
    w.show()
    qtbot.waitExposed(w)
    assert w.load_file(two, wait=True)
    return w


def by_pen(job) -> dict[int, dict]:
    return {int(r["pen"]): r for r in job.stats["layers"]}


def shown_times(win: MainWindow) -> dict[int, float]:
    """The time column of the layer table as the operator reads it."""
    g = win.layers.panel.grid
    col = g.columnCount() - 1
    return {int(g.item(i, 0).text()): float(g.item(i, col).text()) for i in range(g.rowCount())}


def replay(data: bytes, job) -> list[tuple[int, dict]]:
    """The decoded list, stroke by stroke, checked against the job's strokes (each pass):
    (pen, the settings words in force)."""
    d = decode(data)
    assert d.ended
    want = expected_strokes(job)
    assert len(d.strokes) == len(want)
    out = []
    for got, (layer, marks) in zip(d.strokes, want, strict=True):
        assert got.marks.tolist() == marks.tolist()
        out.append((layer.pen, got.settings))
    return out


def test_rows_are_the_pens_of_the_drawing_with_their_time(win):
    job = win.current_job()
    assert job is not None
    assert [la["pen"] for la in job.layers] == [1, 2]
    assert win.layers.panel.grid.rowCount() == 2
    times = shown_times(win)
    rows = by_pen(job)
    assert set(times) == {1, 2}
    for pen in (1, 2):
        assert times[pen] == pytest.approx(rows[pen]["estimated_time_s"], abs=1e-3)
        assert rows[pen]["estimated_time_s"] > 0
    # the job's time is the sum of its layers'
    assert job.stats["estimated_time_s"] == pytest.approx(sum(times.values()), abs=5e-3)
    assert win.layers.dock.isVisible()


def test_editing_pen_2_remakes_the_job_and_the_lmc_export(win, tmp_path, dialogs):
    before = win.current_job()
    t_before = by_pen(before)
    win.layers.panel.editor(2, "mark_speed_mm_s").setValue(400.0)
    # the shown result was made with the old table: stale, nothing to export until it is new
    assert win.is_stale() and win.current_job() is None
    early = tmp_path / "early.lmc"
    assert win.export("lmc", early) is False
    assert not early.exists() and "not exported" in dialogs[-1].informativeText()
    assert win.wait_idle(60)

    job = win.current_job()
    assert job is not None and job is not before
    layers = {la["pen"]: la for la in job.layers}
    assert layers[2]["mark_speed_mm_s"] == 400.0
    assert layers[1]["mark_speed_mm_s"] == LaserParams().mark_speed_mm_s
    t_after = by_pen(job)
    assert t_after[2]["estimated_time_s"] < 0.5 * t_before[2]["estimated_time_s"]
    assert t_after[1]["estimated_time_s"] == pytest.approx(t_before[1]["estimated_time_s"])
    assert shown_times(win)[2] == pytest.approx(t_after[2]["estimated_time_s"], abs=1e-3)

    out = tmp_path / "two.lmc"
    assert win.export("lmc", out)
    bpm = bits_per_mm(job)
    speeds = {}
    for pen, settings in replay(out.read_bytes(), job):
        speeds.setdefault(pen, set()).add(settings["mark_speed"])
    assert speeds == {1: {speed_word(LaserParams().mark_speed_mm_s, bpm)},
                      2: {speed_word(400.0, bpm)}}
    assert speed_word(400.0, bpm) != speed_word(LaserParams().mark_speed_mm_s, bpm)
    text = tmp_path / "two.txt"
    assert win.export("lmc_text", text)
    assert text.read_text() == to_text(encode_job(job))
    assert not dialogs[1:]


def test_passes_and_disabled_layers_reach_the_list(win, tmp_path):
    win.layers.panel.editor(1, "passes").setValue(3)
    assert win.wait_idle(60)
    win.layers.panel.editor(2, "enabled").setChecked(False)
    assert win.wait_idle(60)
    job = win.current_job()
    assert job is not None
    n1 = sum(1 for s in job.strokes if s.pen == 1)
    out = tmp_path / "p.lmc"
    assert win.export("lmc", out)
    pens = [pen for pen, _ in replay(out.read_bytes(), job)]
    assert pens == [1] * (3 * n1)
    assert by_pen(job)[2]["estimated_time_s"] == 0.0


def test_pen_table_files(win, tmp_path, dialogs):
    good = tmp_path / "pens.toml"
    good.write_text("[laser]\nmark_speed_mm_s = 250\n[pen.2]\npower_percent = 85\n"
                    "passes = 2\n")
    assert win.layers.open(good)
    assert win.wait_idle(60)
    job = win.current_job()
    layers = {la["pen"]: la for la in job.layers}
    assert layers[2]["power_percent"] == 85 and layers[2]["passes"] == 2
    assert layers[1]["mark_speed_mm_s"] == 250  # the profile
    assert win.params.laser.mark_speed_mm_s == 250  # one truth: the laser parameters follow
    assert win.layers.panel.editor(2, "passes").value() == 2

    # a bad file: one message naming the file and the place; nothing changes, no new run
    bad = tmp_path / "bad.toml"
    bad.write_text("[pen.2]\npower_percent = 150\n")
    n_runs = win.runner.n_started
    assert win.layers.open(bad) is False
    msg = dialogs[-1].informativeText() or dialogs[-1].text()
    assert str(bad) in msg and "pen.2" in msg
    assert win.runner.n_started == n_runs and not win.is_stale()
    assert win.current_job() is job
    broken = tmp_path / "broken.toml"
    broken.write_text("[pen.1\n")
    assert win.layers.open(broken) is False
    assert str(broken) in win.layers.last_error and win.current_job() is job

    # save: reads back to the table in use
    win.layers.panel.editor(1, "frequency_khz").setValue(60.0)
    assert win.wait_idle(60)
    saved = tmp_path / "saved.toml"
    assert win.layers.save(saved)
    assert load_pen_table(saved) == win.layers.effective()
    assert load_pen_table(saved).settings(1).laser.frequency_khz == 60.0
    assert win.layers.save(tmp_path / "no such dir" / "x.toml") is False
    assert "no such dir" in win.layers.last_error


def test_laser_parameters_are_the_profile_of_unedited_pens(win):
    win.layers.panel.editor(2, "mark_speed_mm_s").setValue(400.0)
    assert win.wait_idle(60)
    win.apply_changes({"laser": LaserParams(mark_speed_mm_s=1000.0)})
    assert win.wait_idle(60)
    layers = {la["pen"]: la for la in win.current_job().layers}
    assert layers[1]["mark_speed_mm_s"] == 1000.0  # follows the laser parameters
    assert layers[2]["mark_speed_mm_s"] == 400.0  # set in the table: kept
    assert win.layers.panel.editor(1, "mark_speed_mm_s").value() == 1000.0


def test_loaded_job_file_shows_its_layers_read_only_and_exports_them(win, tmp_path, qtbot):
    win.layers.panel.editor(2, "power_percent").setValue(90.0)
    assert win.wait_idle(60)
    job_path = tmp_path / "two.json"
    assert win.export("job", job_path)
    lmc_a = tmp_path / "a.lmc"
    assert win.export("lmc", lmc_a)
    assert win.load_file(job_path, wait=True)
    assert not win.layers.panel.isEnabled()
    assert win.layers.panel.editor(2, "power_percent").value() == 90.0
    lmc_b = tmp_path / "b.lmc"
    assert win.export("lmc", lmc_b)
    assert lmc_b.read_bytes() == lmc_a.read_bytes()


def test_export_failure_names_the_users_file(win, tmp_path, dialogs):
    target = tmp_path / "missing" / "two.lmc"
    assert win.export("lmc", target) is False
    assert str(target) in (dialogs[-1].informativeText() or dialogs[-1].text())
    assert ".tmp-" not in dialogs[-1].informativeText()


def test_screenshot_with_the_layer_table(win, tmp_path):
    win.layers.panel.editor(2, "mark_speed_mm_s").setValue(400.0)
    assert win.wait_idle(60)
    png = tmp_path / "layers_window.png"
    assert win.grab().save(str(png))
    assert png.stat().st_size > 10_000
    dock = win.layers.dock
    assert dock.isVisible() and not dock.isFloating()
    # beside the processing panel, both whole inside the window
    g, c = dock.geometry(), win.controls_dock.geometry()
    assert win.rect().contains(g) and g.height() >= 100
    assert abs(g.left() - c.left()) < 5 and g.top() >= c.bottom()


def test_a_result_of_another_pen_table_is_never_exported(win, tmp_path, dialogs):
    shown = win.current_job()
    win.layers.panel.editor(2, "power_percent").setValue(90.0)
    win.runner.cancel()  # the run of the new table never delivers (dropped, failed)
    assert win.wait_idle(60)
    assert win.result.job is shown
    assert win.is_stale() and win.current_job() is None
    out = tmp_path / "old.lmc"
    assert win.export("lmc", out) is False and not out.exists()
    assert "not exported" in dialogs[-1].informativeText()


def test_esc_goes_back_to_the_pen_table_of_the_shown_result(win, tmp_path):
    shown = win.current_job()
    win.layers.panel.editor(2, "power_percent").setValue(90.0)
    win.cancel_processing()
    assert win.wait_idle(60)
    assert win.current_job() is shown
    assert win.layers.panel.editor(2, "power_percent").value() == LaserParams().power_percent
    out = tmp_path / "shown.lmc"
    assert win.export("lmc", out)
    assert {la["power_percent"] for la in win.current_job().layers} == \
        {LaserParams().power_percent}
    replay(out.read_bytes(), shown)


def test_a_pen_edit_gives_the_job_of_a_fresh_run(win):
    from galvo_core.layers import apply_pens
    from galvo_core.pipeline import Pipeline

    preview = win.result.preview
    win.layers.panel.editor(2, "mark_speed_mm_s").setValue(333.0)
    assert win.wait_idle(60)
    win.layers.panel.editor(1, "passes").setValue(2)
    assert win.wait_idle(60)
    # only the pens changed: the shown geometry is kept, only the job is re-made
    assert win.result.stages_run == ("layers",) and win.result.preview is preview
    job = win.current_job()
    fresh = apply_pens(Pipeline().run(win.drawing, win.params).job, win.layers.effective())
    assert job.layers == fresh.layers
    rest = {k: v for k, v in job.stats.items() if k != "layers"}
    assert rest == pytest.approx({k: v for k, v in fresh.stats.items() if k != "layers"})
    assert len(job.stats["layers"]) == len(fresh.stats["layers"]) == 2
    for a, b in zip(job.stats["layers"], fresh.stats["layers"], strict=True):
        assert a == pytest.approx(b)
    assert job.stats["layers"][0]["passes"] == 2
    assert [s.marks.tolist() for s in job.strokes] == [s.marks.tolist() for s in fresh.strokes]


def test_lmc_export_applies_the_orientation_checked_in_the_dock(win, tmp_path):
    from galvo_core.lmc import Orientation

    job = win.current_job()
    win.layers.orient_boxes["flip_y"].setChecked(True)
    win.layers.orient_boxes["swap_xy"].setChecked(True)
    out = tmp_path / "flipped.lmc"
    assert win.export("lmc", out)
    o = Orientation(swap_xy=True, flip_y=True)
    d = decode(out.read_bytes())
    want = expected_strokes(job, orientation=o)
    assert [s.marks.tolist() for s in d.strokes] == [m.tolist() for _, m in want]
    plain = expected_strokes(job)
    assert [s.marks.tolist() for s in d.strokes] != [m.tolist() for _, m in plain]
    text = tmp_path / "flipped.txt"
    assert win.export("lmc_text", text)
    assert text.read_text() == to_text(encode_job(job, orientation=o))


def test_pen_table_and_orientation_kept_between_sessions(qtbot, two, tmp_path):
    from PySide6.QtCore import QSettings

    ini = str(tmp_path / "s.ini")
    a = MainWindow(settings=QSettings(ini, QSettings.Format.IniFormat))
    qtbot.addWidget(a)
    assert a.load_file(two, wait=True)
    a.layers.panel.editor(2, "power_percent").setValue(77.0)
    a.layers.orient_boxes["flip_x"].setChecked(True)
    assert a.wait_idle(60)
    a.close()
    b = MainWindow(settings=QSettings(ini, QSettings.Format.IniFormat))
    qtbot.addWidget(b)
    assert b.layers.table.settings(2).laser.power_percent == 77.0
    assert b.layers.orientation().flip_x and not b.layers.orientation().flip_y
    assert b.load_file(two, wait=True)
    assert {la["pen"]: la for la in b.current_job().layers}[2]["power_percent"] == 77.0
    b.close()
