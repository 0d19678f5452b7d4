"""One truth on screen (issue 18): what the views show, the title, the stats and what Export
writes always belong to the same file and parameters; nothing long runs on the GUI thread.

Driven through the window's scripting surface (``load_file``, ``set_param``, ``wait_idle``,
``export``, ``current_job``), offscreen, on the bundled samples.
"""

from __future__ import annotations

import threading
from pathlib import Path as FsPath

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from _util import SAMPLES, circle_plt  # noqa: E402
from PySide6.QtGui import QImage  # noqa: E402

import app.window as window_mod  # noqa: E402
from app.window import MainWindow, _user_path_message  # noqa: E402
from galvo_core.job import load_job  # noqa: E402

pytestmark = pytest.mark.gui

SIZE = (1200, 760)
SEAL = SAMPLES / "seal.plt"
LOGO = SAMPLES / "dense_logo.plt"


@pytest.fixture
def win(qtbot) -> MainWindow:
    w = MainWindow(restore=False)
    qtbot.addWidget(w)
    w.resize(*SIZE)
    w.show()
    qtbot.waitExposed(w)
    return w


class Gate:
    """Holds ``load_drawing`` of one file until released (a slow file, deterministically)."""

    def __init__(self, monkeypatch, name: str) -> None:
        self.event = threading.Event()
        self.threads: list[str] = []
        real = window_mod.load_drawing

        def gated(path):
            self.threads.append(threading.current_thread().name)
            if FsPath(path).name == name:
                assert self.event.wait(30)
            return real(path)

        monkeypatch.setattr(window_mod, "load_drawing", gated)


def rgb(image: QImage) -> np.ndarray:
    img = image.convertToFormat(QImage.Format.Format_RGB32)
    w, h = img.width(), img.height()
    buf = np.frombuffer(img.constBits(), np.uint8, count=img.sizeInBytes())
    return buf.reshape(h, img.bytesPerLine())[:, : w * 4].reshape(h, w, 4)[:, :, 2::-1].astype(int)


def dark_pixels(w: MainWindow, view) -> int:
    """Pixels of the view that are clearly ink (dark), not background or dimmed ink."""
    a = rgb(w.grab().toImage())
    x, y, ww, hh = view.view_rect_in(w)
    a = a[y + 2 : y + hh - 2, x + 2 : x + ww - 2]
    return int((a.sum(axis=2) < 3 * 140).sum())


def test_export_while_another_file_opens_is_refused_and_esc_returns_to_the_shown_one(
        win, qtbot, monkeypatch, dialogs, tmp_path):
    gate = Gate(monkeypatch, LOGO.name)
    assert win.load_file(SEAL, wait=True)
    seal_job = win.current_job()
    assert seal_job is not None and seal_job.source_name == "seal.plt"
    seal_marks = win.processed.counts["marks"]

    win.load_file(LOGO)  # held on the worker: seal's result stays on screen
    qtbot.waitUntil(lambda: win.stale_bar.isVisible(), timeout=5000)
    assert "seal.plt" in win.windowTitle() and "dense_logo.plt" in win.windowTitle()
    assert "dense_logo.plt" in win.stale_bar.text()
    assert win.current_job() is None  # nothing current to export
    out = tmp_path / "dense_logo.json"
    assert win.export("job", out) is False
    assert not out.exists()
    assert dialogs and "not exported" in dialogs[-1].informativeText()
    assert win.processed.counts["marks"] == seal_marks  # still seal's, and dimmed

    win.cancel_processing()  # Esc
    gate.event.set()
    assert win.wait_idle(60)
    assert win.run_label.text() == "cancelled"
    assert not win.stale_bar.isVisible()
    assert win.windowTitle().startswith("seal.plt")
    assert win.file_path == SEAL and win.current_job() is seal_job
    # Export now writes seal's job under the name it proposes (seal), and the job says so
    out = tmp_path / "after_cancel.json"
    assert win.export("job", out)
    assert load_job(out).source_name == "seal.plt"
    # the file is read on a worker thread, never on the GUI thread
    assert gate.threads and threading.main_thread().name not in gate.threads


def test_new_file_result_replaces_everything_at_once(win, qtbot, monkeypatch, dialogs, tmp_path):
    assert win.load_file(SEAL, wait=True)
    win.select_path(0)
    x, _ = win.original.highlight.getData()
    assert x is not None and len(x) > 0
    assert win.load_file(LOGO)
    assert win.wait_idle(120)
    # the previous file's selection is not drawn over the next file
    assert win.selected is None
    for view in (win.original, win.processed):
        x, _ = view.highlight.getData()
        assert x is None or len(x) == 0
    assert win.windowTitle().startswith("dense_logo.plt")
    job = win.current_job()
    assert job is not None and job.source_name == "dense_logo.plt"
    assert win.stats_panel.shown_number("mark_points") == job.stats["mark_points"]
    out = tmp_path / "logo.json"
    assert win.export("job", out)
    assert load_job(out).source_sha256 == win.drawing.sha256
    assert not dialogs


def test_stale_views_are_visibly_dimmed(win, qtbot, monkeypatch):
    gate = Gate(monkeypatch, LOGO.name)
    assert win.load_file(SEAL, wait=True)
    win.fit()
    qtbot.wait(50)
    before = dark_pixels(win, win.original)
    assert before > 200
    win.load_file(LOGO)
    qtbot.waitUntil(lambda: win.stale_bar.isVisible(), timeout=5000)
    qtbot.wait(50)
    during = dark_pixels(win, win.original)
    gate.event.set()
    assert win.wait_idle(120)
    assert during < 0.2 * before, (before, during)


def test_a_job_with_an_error_or_no_strokes_is_never_exported_silently(
        win, qtbot, dialogs, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    assert win.load_file(src, wait=True)
    assert win.set_param("magnification", 2000.0) and win.wait_idle(60)
    assert win.run_error and "field" in win.run_error
    out = tmp_path / "out.json"
    for kind in ("job", "plt", "svg"):
        n = len(dialogs)
        assert win.export(kind, out.with_suffix("." + kind)) is False
        assert len(dialogs) == n + 1
        assert "field" in dialogs[-1].informativeText()
    assert not list(tmp_path.glob("out.*"))
    # no pen-down at all: the job has no strokes
    empty = tmp_path / "nothing.plt"
    empty.write_bytes(b"IN;SP1;PU100,100;")
    assert win.load_file(empty, wait=True)
    assert win.current_job() is not None and not win.current_job().strokes
    assert win.export("job", out) is False
    assert "no strokes" in dialogs[-1].informativeText()
    assert not out.exists()


def test_export_errors_name_the_users_file_not_the_temporary_one(
        win, qtbot, monkeypatch, dialogs, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    assert win.load_file(src, wait=True)
    target = tmp_path / "job.json"

    def bad_replace(a, b):
        raise RuntimeError(f"cannot move {a} into place")

    monkeypatch.setattr(window_mod.os, "replace", bad_replace)  # the os module is shared
    assert win.export("job", target) is False
    text = dialogs[-1].informativeText()
    assert str(target) in text and ".tmp-" not in text
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".tmp")] == []
    assert _user_path_message("x /a/b/.tmp-12ab.json: no", FsPath("/a/b/job.json")) == \
        "x /a/b/job.json: no"


def test_export_and_job_load_run_on_a_worker(win, qtbot, monkeypatch, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    assert win.load_file(src, wait=True)
    threads: list[str] = []
    real = window_mod.write_job

    def recording(job, path):
        threads.append(threading.current_thread().name)
        real(job, path)

    win.export_kinds["job"] = window_mod.ExportKind("Job", "*.json", ".json", recording)
    out = tmp_path / "circle.json"
    assert win.export("job", out)
    real_load = window_mod.load_job

    def load(path):
        threads.append(threading.current_thread().name)
        return real_load(path)

    monkeypatch.setattr(window_mod, "load_job", load)
    n = win.processed.counts["marks"]
    assert win.load_file(out, wait=True)
    assert win.job_path == out and win.processed.counts["marks"] == n
    assert len(threads) == 2 and threading.main_thread().name not in threads


def test_set_param_and_current_job(win, qtbot, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    assert win.load_file(src, wait=True)
    assert win.set_param("e_per", 0.3)
    assert win.current_job() is None  # pending: the shown job is not the current one
    assert win.wait_idle(60)
    assert win.current_job().params["e_per"] == 0.3
    assert win.controls.sliders["e_per"].value() == pytest.approx(0.3, rel=1e-3)
    assert win.set_param("mark_speed_mm_s", 500.0) and win.wait_idle(60)
    assert win.current_job().laser["mark_speed_mm_s"] == 500.0
    assert win.set_param("no_such_thing", 1) is False
    assert win.set_param("e_per", -1.0) is False
    assert win.current_job().params["e_per"] == 0.3


def test_drawing_bigger_than_the_field_opens_with_fit_field(win, qtbot, dialogs, tmp_path):
    # 400 x 400 mm at 40 units per mm: bigger than the 110 mm field at true size
    big = tmp_path / "big.plt"
    big.write_bytes(b"IN;SP1;PU0,0;PD16000,0,16000,16000,0,16000,0,0;PU;")
    assert win.params.magnification is None and not win.params.fit_field
    assert win.load_file(big, wait=True)
    assert win.params.fit_field and win.run_error is None
    assert win.banner.isVisible() and "Fit field" in win.banner.text()
    assert win.current_job() is not None and win.current_job().strokes
    assert not dialogs


def test_deviation_is_computed_only_when_shown(win, qtbot, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    win.layer_boxes["deviation"].setChecked(False)
    assert win.load_file(src, wait=True)
    assert not win.result.preview.has_layer("deviation")
    assert len(win.result.preview.deviation_err) == 0
    win.layer_boxes["deviation"].setChecked(True)
    assert win.wait_idle(60)
    assert win.result.preview.has_layer("deviation")
    assert len(win.result.preview.deviation_err) > 0
    assert win.processed.layers["deviation"].n_chords == len(win.result.preview.deviation_err)


def test_a_layer_switched_on_is_added_to_the_shown_result_without_a_new_run(win, qtbot,
                                                                            tmp_path):
    """Switching the deviation on computes that layer from the shown fit: the job, the
    other layers' arrays (so their drawn items) and the stats stay the shown result's; a
    parameter change after it runs the pipeline as usual."""
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    win.layer_boxes["deviation"].setChecked(False)
    assert win.load_file(src, wait=True)
    before = win.result
    win.layer_boxes["deviation"].setChecked(True)
    assert win.wait_idle(60)
    after = win.result
    assert after is not before and after.stages_run == ("layers",)
    assert after.job is before.job and after.fitted is before.fitted
    assert after.preview.marks is before.preview.marks
    assert after.preview.fitted.xy is before.preview.fitted.xy
    assert after.prepared["marks"] is before.prepared["marks"]
    assert after.preview.has_layer("deviation") and len(after.preview.deviation_err)
    assert win.processed.layers["deviation"].n_chords == len(after.preview.deviation_err)
    assert win.set_param("e_per", 0.07) and win.wait_idle(60)
    assert "fit" in win.result.stages_run and win.result.preview.has_layer("deviation")


def test_the_previous_file_is_freed_when_the_next_one_is_shown(win, qtbot, tmp_path):
    """Opening another file releases the last one's drawing, job and display geometry
    (no cache, frozen garbage-collector generation or view keeps them): memory stays about
    one file's over a session, without a collection. Not before the next file's result is
    shown, and then a moment later (freeing 40 k paths is 10-20 ms of the GUI thread)."""
    import gc
    import weakref

    a, b = tmp_path / "a.plt", tmp_path / "b.plt"
    a.write_bytes(circle_plt())
    b.write_bytes(b"IN;SP1;PU0,0;PD400,0,400,400,0,400,0,0;PU;")
    assert win.load_file(a, wait=True)
    refs = [weakref.ref(x) for x in (win.drawing, win.result, win.result.job,
                                     win.result.preview)]
    assert win.load_file(b, wait=True) and win.drawing.name == "b.plt"
    # (let go a moment after the new result, in an event-loop pass of their own)
    qtbot.wait(window_mod.RELEASE_DELAY_MS + 50)
    qtbot.waitUntil(lambda: not win._reaper.busy(), timeout=5000)  # its short passes
    assert gc.isenabled()  # no collection asked for: reference counting frees them
    assert [r() is None for r in refs] == [True] * len(refs)


def test_the_reaper_frees_a_big_result_in_short_passes_and_spares_what_is_shared(
        qtbot, monkeypatch):
    """A replaced result is freed a few objects per event-loop pass (one cascade held the
    GIL 23-45 ms on 40 k-path files): everything only it held is freed, in many passes
    when each may do little; an object the next result shares is left as it was."""
    import weakref

    from PySide6.QtCore import QObject

    class Item:
        def __init__(self, i: int) -> None:
            self.points = np.full((4, 2), float(i))
            self.tags = [i, str(i)]

    class Result:
        def __init__(self, shared: list[int]) -> None:
            self.items = tuple(Item(i) for i in range(3000))
            self.by_name = {f"p{i}": it for i, it in enumerate(self.items[:500])}
            self.shared = shared

    shared = [1, 2, 3]
    res = Result(shared)
    refs = [weakref.ref(res), weakref.ref(res.items[0]), weakref.ref(res.items[-1])]
    monkeypatch.setattr(window_mod, "RELEASE_STEP_S", 0.0)  # the least per pass
    owner = QObject()
    reaper = window_mod._Reaper(owner)
    reaper.add([res])
    del res
    assert refs[0]() is not None  # not freed at once
    passes = 0
    while reaper.busy():
        reaper.step()
        passes += 1
    assert passes > 10
    assert [r() is None for r in refs] == [True, True, True]
    assert shared == [1, 2, 3]


def test_stroke_by_stroke_json_of_many_strokes_is_write_jobs(tmp_path):
    """The big-job writer encodes strokes in groups: over several groups (700 strokes) the
    bytes are still exactly write_job's."""
    from app import offload
    from galvo_core.hpgl import read_bytes
    from galvo_core.job import write_job
    from galvo_core.params import Params
    from galvo_core.pipeline import Pipeline

    body = b"".join(b"PU%d,%d;PD%d,%d,%d,%d;" % (40 * (i % 30), 40 * (i // 30),
                                                   40 * (i % 30) + 20, 40 * (i // 30),
                                                   40 * (i % 30) + 20, 40 * (i // 30) + 25)
                    for i in range(700))
    job = Pipeline().run(read_bytes(b"IN;SP1;" + body, "many.plt"), Params(fit_field=True)).job
    assert len(job.strokes) == 700
    ref = tmp_path / "ref.json"
    write_job(job, ref)
    assert offload.job_json_bytes(job) == ref.read_bytes()


def test_export_kinds_can_be_extended(win, qtbot, tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    assert win.load_file(src, wait=True)
    written: list[str] = []
    win.export_kinds["txt"] = window_mod.ExportKind(
        "Export &Text…", "Text (*.txt)", ".txt",
        lambda job, path: (written.append(job.source_name), path.write_text("x")))
    win.rebuild_export_menu()
    assert "txt" in win.export_actions and win.export_actions["txt"].isEnabled()
    assert win.export("txt", tmp_path / "a.txt") and written == ["circle.plt"]


def test_big_job_files_are_written_and_read_the_same_way(tmp_path, monkeypatch):
    """The stroke-by-stroke JSON of app.offload is byte for byte write_job's, and a job
    read in the helper process equals the one read directly."""
    from app import offload
    from galvo_core.hpgl import read_file
    from galvo_core.job import write_job
    from galvo_core.params import Params
    from galvo_core.pipeline import Pipeline

    job = Pipeline().run(read_file(SEAL), Params(fit_field=True)).job
    a = tmp_path / "a.json"
    write_job(job, a)
    assert offload.job_json_bytes(job) == a.read_bytes()
    monkeypatch.setattr(offload, "BIG_JOB_ITEMS", 0)
    b = tmp_path / "b.json"
    offload.write_job_file(write_job, job, b)
    assert b.read_bytes() == a.read_bytes()
    monkeypatch.setattr(offload, "BIG_JOB_BYTES", 0)
    monkeypatch.setattr(offload, "CHUNK_SEGMENTS", 50)
    back = offload.load_job_file(a, lambda p: pytest.fail("read in the helper process"))
    direct = load_job(a)
    assert len(back.strokes) == len(direct.strokes) > 1
    for s, t in zip(back.strokes, direct.strokes, strict=True):
        assert np.array_equal(s.marks, t.marks) and len(s.segments) == len(t.segments)
    assert back.stats == direct.stats and back.source_sha256 == direct.source_sha256
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(Exception, match="bad.json"):
        offload.load_job_file(bad, load_job)


def test_opening_a_file_walks_its_points_on_the_worker_only(win, qtbot, monkeypatch):
    """The facts the GUI needs at once of a file being opened (bbox, size, point and
    closed-path counts: each walks every path, tens of ms on 40 k paths) come from the
    worker: opening one file after another, the GUI thread walks the points of neither
    (the status bar still gives the new file's counts)."""
    from galvo_core.drawing import Drawing

    assert win.load_file(SEAL, wait=True)
    main = threading.main_thread()
    walks: list[str] = []

    def on_gui(name: str) -> None:
        if threading.current_thread() is main:
            walks.append(name)

    for name in ("bbox", "size_mm"):
        real = getattr(Drawing, name)
        monkeypatch.setattr(Drawing, name,
                            lambda self, real=real, name=name: on_gui(name) or real(self))
    for name in ("n_points", "n_closed"):
        real = getattr(Drawing, name).fget
        monkeypatch.setattr(Drawing, name, property(
            lambda self, real=real, name=name: on_gui(name) or real(self)))
    assert win.load_file(LOGO, wait=True) and win.drawing.name == "dense_logo.plt"
    assert win.load_file(SEAL, wait=True) and win.drawing.name == "seal.plt"
    assert walks == []
    d = win.drawing
    monkeypatch.undo()
    assert f"{window_mod._fmt_int(d.n_points)} points" in win.status_summary()
    assert f"{window_mod._fmt_int(d.n_closed)} closed" in win.status_summary()


def test_the_fit_field_banner_goes_with_the_result_it_speaks_of(win, qtbot, monkeypatch,
                                                                 tmp_path):
    """The banner of a file opened with Fit field stays while that file's result is shown,
    the next file processing (changing it resizes both views: one repaint with the new
    result, not one more during the run), and goes with the next file's result."""
    from galvo_core.pipeline import Pipeline

    big = tmp_path / "big.plt"
    big.write_bytes(b"IN;SP1;PU0,0;PD16000,0,16000,16000,0,16000,0,0;PU;")
    assert win.load_file(big, wait=True) and win.banner.isVisible()
    release = threading.Event()
    real_run = Pipeline.run

    def held(self, drawing, *args, **kw):
        if drawing.name == "seal.plt":
            assert release.wait(30)
        return real_run(self, drawing, *args, **kw)

    monkeypatch.setattr(Pipeline, "run", held)
    win.load_file(SEAL)
    qtbot.waitUntil(lambda: win.drawing is not None and win.drawing.name == "seal.plt",
                    timeout=10_000)
    qtbot.wait(50)
    assert win.result.drawing.name == "big.plt"  # big's result still shown ...
    assert win.banner.isVisible() and "big.plt" in win.banner.text()  # ... with its banner
    release.set()
    assert win.wait_idle(60) and win.result.drawing.name == "seal.plt"
    assert not win.banner.isVisible()
