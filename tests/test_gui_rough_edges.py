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
