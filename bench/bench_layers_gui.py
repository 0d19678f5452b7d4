"""Layer table benchmark (issue 19, GUI side): a pen edit in the window's layer table ->
the shown job re-made with the new pen table (``apply_pens`` on the worker after the cached
pipeline run) and handed to the views; File ▸ Export ▸ LMC list of that job.

Driven through the window's scripting surface, offscreen, 1400x800, each file opened with
Fit field. For each file: the first run (open + process, once), then ``--repeats`` edits of
the mark speed of the last pen (a new value every time), each timed from the edit to the
window being idle with the new result shown; ``apply_pens`` alone on the shown job; the
LMC export through the window. CPU time is ``time.process_time`` (every thread of the
process); wall time is the noisier of the two on a shared machine. Medians of the repeats.

    .venv/bin/python bench/bench_layers_gui.py FILE... [--repeats 5]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
os.environ.setdefault("GALVO_WORKSTATION_SETTINGS",
                      os.path.join(tempfile.mkdtemp(prefix="galvo-bench-"), "s.ini"))

SIZE = (1400, 800)


def timed(fn) -> tuple[float, float]:
    w0, c0 = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - w0, time.process_time() - c0


def one_file(path: Path, repeats: int, out_dir: Path) -> dict:
    from PySide6.QtWidgets import QApplication

    from app.window import MainWindow
    from galvo_core.layers import apply_pens

    app = QApplication.instance() or QApplication([])
    win = MainWindow(restore=False)
    win.resize(*SIZE)
    win.show()
    app.processEvents()
    win.apply_changes({"fit_field": True})
    first = timed(lambda: win.load_file(path, wait=True))
    assert win.wait_idle(600)
    job = win.current_job()
    if job is None:
        win.close()
        return {"file": path.name, "error": win.run_error or win.last_error or "no job"}
    pens = [int(r["pen"]) for r in job.stats["layers"]]
    marks = sum(len(s.marks) for s in job.strokes)
    edits_w, edits_c = [], []
    for i in range(repeats):
        box = win.layers.panel.editor(pens[-1], "mark_speed_mm_s")
        value = 150.0 + 37.0 * (i + 1)

        def edit(box=box, value=value) -> None:
            box.setValue(value)
            assert win.wait_idle(600)

        w, c = timed(edit)
        new = win.current_job()
        assert new is not None and new.layers[-1]["mark_speed_mm_s"] == value
        edits_w.append(w)
        edits_c.append(c)
    job = win.current_job()
    table = win.layers.effective()
    ap = []
    for _ in range(repeats):
        ap.append(timed(lambda: apply_pens(job, table))[1])
    target = out_dir / (path.stem + ".lmc")
    exp = timed(lambda: win.export("lmc", target))
    size = target.stat().st_size
    win.close()
    app.processEvents()
    return {"file": path.name, "pens": len(pens), "strokes": len(job.strokes), "marks": marks,
            "first_s": first[0], "first_cpu_s": first[1],
            "edit_ms": 1000 * statistics.median(edits_w),
            "edit_cpu_ms": 1000 * statistics.median(edits_c),
            "apply_cpu_ms": 1000 * statistics.median(ap),
            "export_ms": 1000 * exp[0], "export_cpu_ms": 1000 * exp[1], "lmc_bytes": size}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+", type=Path)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args(argv)
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {platform.machine()}, "
          f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}, "
          f"Python {platform.python_version()}")
    print("| file | pens | strokes | marks | open+process s (CPU s) | pen edit -> shown ms, "
          "median (CPU ms) | apply_pens CPU ms | LMC export ms (CPU ms) | .lmc bytes |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for f in a.files:
            r = one_file(f, a.repeats, Path(tmp))
            if "error" in r:
                print(f"| {r['file']} | refused: {r['error']} |")
                continue
            print(f"| {r['file'][:48]} | {r['pens']} | {r['strokes']} | {r['marks']} | "
                  f"{r['first_s']:.2f} ({r['first_cpu_s']:.2f}) | {r['edit_ms']:.0f} "
                  f"({r['edit_cpu_ms']:.0f}) | {r['apply_cpu_ms']:.1f} | {r['export_ms']:.0f} "
                  f"({r['export_cpu_ms']:.0f}) | {r['lmc_bytes']} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
