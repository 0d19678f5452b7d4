"""The rough edges of issue 18, each as the operator meets it (offscreen)."""

from __future__ import annotations

from pathlib import Path as FsPath

import pytest

pytest.importorskip("pytestqt")

from _util import SAMPLES, circle_plt  # noqa: E402
from PySide6.QtWidgets import QCheckBox, QMessageBox  # noqa: E402

from app.stats import format_stat  # noqa: E402
from app.window import MainWindow  # noqa: E402

pytestmark = pytest.mark.gui


@pytest.fixture
def dialogs(monkeypatch) -> list[QMessageBox]:
    boxes: list[QMessageBox] = []
    monkeypatch.setattr(QMessageBox, "exec", lambda box: boxes.append(box) or 0)
    return boxes


def make(qtbot, size=(1200, 760)) -> MainWindow:
    w = MainWindow(restore=False)
    qtbot.addWidget(w)
    w.resize(*size)
    w.show()
    qtbot.waitExposed(w)
    return w


def test_magnification_box_shows_and_takes_what_fit_field_computes(qtbot, tmp_path):
    big = tmp_path / "big.plt"  # 10 m (a fabric nest): Fit field gives about 0.16 bits/unit
    big.write_bytes(b"IN;SP1;PU0,0;PD400000,0,400000,400000,0,400000,0,0;PU;")
    win = make(qtbot)
    assert win.load_file(big, wait=True) and win.params.fit_field
    mag = win.result.job.field_map.magnification
    box = win.controls.sliders["magnification"].spin
    assert mag < 0.2
    assert box.value() == pytest.approx(mag, abs=1e-4)  # not stuck at the old minimum 0.2
    # untick Fit field and type a smaller magnification: the drawing stays in the field
    win.set_param("fit_field", False)
    box.setValue(round(mag * 0.8, 4))
    assert win.wait_idle(60)
    assert win.params.magnification == pytest.approx(mag * 0.8, abs=1e-4)
    assert win.run_error is None and win.current_job().strokes


def test_gui_errors_name_controls_not_command_line_flags(qtbot, tmp_path, dialogs):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    win = make(qtbot)
    assert win.load_file(src, wait=True)
    assert win.set_param("magnification", 2000.0) and win.wait_idle(60)
    assert win.run_error and "field" in win.run_error
    shown = [win.run_error, *win.warnings_panel.texts()]
    assert not any("--" in t for t in shown), shown
    assert "Fit field" in win.run_error


def test_stats_have_no_float_noise_or_none():
    assert format_stat("max_fit_error_um", 8.88e-14) == "0 µm"
    assert format_stat("max_chord_height_bits", None) == "—"
    assert format_stat("max_fit_error", 3e-15) == "0 u"
    assert format_stat("max_fit_error_um", 0.498) == "0.498 µm"


def test_stats_panel_shows_no_none_and_no_noise(qtbot, tmp_path):
    win = make(qtbot)
    assert win.load_file(SAMPLES / "seal.plt", wait=True)
    assert win.set_param("interpolation", "raw") and win.wait_idle(60)
    texts = list(win.stats_panel.shown.values())
    assert not any(t == "None" or "e-1" in t for t in texts), texts


def test_layout_at_900x560_keeps_every_layer_label_whole(qtbot):
    win = make(qtbot, (900, 560))
    assert win.load_file(SAMPLES / "seal.plt", wait=True)
    qtbot.wait(50)
    for key, cb in win.layer_boxes.items():
        assert isinstance(cb, QCheckBox)
        assert cb.width() >= cb.sizeHint().width(), key  # not squeezed: text not clipped
        r = cb.geometry()
        assert r.right() <= win.layer_bar.width(), key
    ov, pv = win.original, win.processed
    assert ov.width() > 200 and pv.width() > 200 and ov.height() > 150
    assert win.status_label.width() >= win.status_label.sizeHint().width() * 0.9


def test_field_label_is_not_under_the_legend(qtbot, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    win = make(qtbot)
    assert win.load_file(src, wait=True)
    win.fit_field_view()
    qtbot.wait(50)
    for view in (win.original, win.processed):
        label = view.field_label.sceneBoundingRect()
        legend = view.legend.sceneBoundingRect()
        assert view.field_label.toPlainText().startswith("field")
        assert not label.intersects(legend)


def test_hatch_passes_control(qtbot, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    win = make(qtbot)
    assert win.load_file(src, wait=True)
    assert win.set_param("fill", "scanline") and win.wait_idle(60)
    one = sum(len(s.marks) for s in win.current_job().strokes if s.kind == "hatch")
    passes = win.controls.sliders["hatch_passes"]
    passes.spin.setValue(2)
    assert win.wait_idle(60)
    assert win.params.hatch_passes == 2
    two = sum(len(s.marks) for s in win.current_job().strokes if s.kind == "hatch")
    assert two > 1.5 * one
    win.restore_defaults()
    assert passes.value() == 1


def test_plt_export_says_it_is_in_galvo_bits(qtbot, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    win = make(qtbot)
    assert win.load_file(src, wait=True)
    assert "galvo bits" in win.export_plt_action.text()
    out = tmp_path / "x.plt"
    assert win.export("plt", out) and out.exists()
    assert "galvo bits" in win.statusBar().currentMessage()
    assert FsPath(out).stat().st_size > 0


def test_undo_and_redo_of_parameter_changes(qtbot, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    win = make(qtbot)
    assert win.load_file(src, wait=True)
    assert not win.undo_action.isEnabled()
    e0 = win.params.e_per
    s = win.controls.sliders["e_per"]
    s.set_position(s.to_position(0.3), final=False)  # a drag is not a change of its own
    s.set_position(s.to_position(0.5), final=False)
    s.set_position(s.to_position(0.5), final=True)  # the release
    assert win.wait_idle(60) and win.params.e_per == pytest.approx(0.5, rel=0.01)
    assert win.set_param("chord_tol_bits", 2.0) and win.wait_idle(60)
    assert win.undo() and win.wait_idle(60)
    assert win.params.chord_tol_bits != 2.0 and win.params.e_per == pytest.approx(0.5, rel=0.01)
    assert win.current_job().params["chord_tol_bits"] == win.params.chord_tol_bits
    assert win.undo() and win.wait_idle(60)
    assert win.params.e_per == e0 and s.value() == pytest.approx(e0)
    assert win.undo() is False
    assert win.redo() and win.redo() and win.wait_idle(60)
    assert win.params.chord_tol_bits == 2.0 and win.redo() is False
    win.undo()
    assert win.set_param("e_per", 0.7)  # a new change forgets what was undone
    assert win.redo() is False


def test_ruler_measures_in_mm_and_bits(qtbot, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    win = make(qtbot)
    assert win.load_file(src, wait=True)
    win.ruler_action.setChecked(True)
    assert win.ruler_click(10.0, 20.0) is None
    text = win.ruler_click(13.0, 24.0)  # a 3-4-5 triangle: 5 mm
    mpb = win.result.preview.mm_per_bit
    assert text is not None and "5.000 mm" in text
    bits = float(text.split("=")[1].split("bits")[0].replace("\u2009", ""))
    assert bits == pytest.approx(5.0 / mpb, abs=0.1)
    x, _ = win.processed._ruler_item.getData()
    assert list(x) == [10.0, 13.0]
    win.ruler_action.setChecked(False)
    x, _ = win.processed._ruler_item.getData()
    assert x is None or len(x) == 0


def test_marking_simulation_plays_the_job_in_order(qtbot, tmp_path):
    from galvo_core.preview import beam_timeline

    win = make(qtbot)
    assert win.load_file(SAMPLES / "seal.plt", wait=True)
    job = win.current_job()
    xy, t, on = beam_timeline(job)
    assert len(xy) == sum(len(s.marks) for s in job.strokes)
    assert t[-1] == pytest.approx(job.stats["estimated_time_s"])
    assert (t[1:] >= t[:-1]).all()
    assert on.sum() == len(xy) - len(job.strokes)  # each stroke starts with a jump
    win.sim_action.setChecked(True)
    assert win.sim_bar.isVisible()
    start = win.simulate_at(0.0)
    assert start["time_s"] == 0 and start["index"] == 0
    np_first = job.strokes[0].marks[0]
    assert tuple(start["bits"]) == pytest.approx(tuple(np_first))
    end = win.simulate_at(1.0)
    assert end["time_s"] == pytest.approx(job.stats["estimated_time_s"])
    assert tuple(end["bits"]) == pytest.approx(tuple(job.strokes[-1].marks[-1]))
    mid = win.simulate_at(0.5)
    assert 0 < mid["index"] < len(xy) - 1
    assert "s /" in win.sim_label.text()
    # scrubbing with the slider moves the beam
    win.sim_slider.setValue(250)
    x, _ = win.processed._sim_items[0].getData()
    assert x is not None and 1 < len(x) <= mid["index"] + 2
    win.sim_action.setChecked(False)
    assert not win.sim_bar.isVisible()


def test_screenshot_of_a_drawing_bigger_than_the_field_uses_fit_field(qtbot, dialogs):
    """--screenshot opens its drawing with open_drawing: the same Fit field rule."""
    from galvo_core.hpgl import read_bytes

    big = read_bytes(b"IN;SP1;PU0,0;PD16000,0,16000,16000,0,16000,0,0;PU;", "big.plt")
    win = make(qtbot)
    win.open_drawing(big, "big.plt")
    assert win.wait_idle(60)
    assert win.params.fit_field and win.run_error is None and win.banner.isVisible()
    assert win.current_job().strokes and not dialogs


def test_stats_table_cells_follow_each_new_result(qtbot):
    # a re-run updates the cells in place (same rows): every cell must show the new job's
    win = make(qtbot)
    assert win.load_file(SAMPLES / "seal.plt", wait=True)
    table = win.stats_panel.table

    def cells() -> dict[str, str]:
        out = {}
        for r in range(table.rowCount()):
            for c in range(0, table.columnCount(), 2):
                a, b = table.item(r, c), table.item(r, c + 1)
                if a is not None and b is not None:
                    out[a.toolTip()] = b.text()
        return out

    first = cells()
    for value in (0.5, 3.0):
        assert win.set_param("chord_tol_bits", value) and win.wait_idle(60)
        stats = win.result.job.stats
        shown = cells()
        for key in ("mark_points", "chord_tol_bits", "estimated_time_s", "mark_length_mm"):
            assert shown[key] == format_stat(key, stats[key]), key
    assert shown["mark_points"] != first["mark_points"]
