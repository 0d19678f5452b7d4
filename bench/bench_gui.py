"""GUI latency: slider release -> redrawn views, for changes that only re-sample the marks.

A 100,000-point PLT (bench/gen_plt.py, 400 mm wide) is opened in the workstation (offscreen);
after the first run (parse + fit) the chord tolerance and the magnification sliders are moved
and released alternately between two values. Each sample times, on the GUI thread, from the
release (``ParamSlider.set_position(..., final=True)``) to the moment both views have been
repainted with the new result: the result is handed to the views (``result_shown``) and each
view has painted once after that — in the event loop, as the running application does, or,
for a view that has not painted by the time the result is shown, by a synchronous
``repaint()``. ``--force-repaint`` repaints both views synchronously after the result even
when the event loop already painted them (a second full paint per view: the method of the
first version of this benchmark). The pipeline's own time (re-sample + display geometry on
the worker) is reported apart.

    .venv/bin/python bench/bench_gui.py [--points 100000] [--repeats 15] [--force-repaint]
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
sys.path.insert(0, str(HERE))
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
os.environ.setdefault("GALVO_WORKSTATION_SETTINGS",
                      os.path.join(tempfile.mkdtemp(prefix="galvo-bench-"), "s.ini"))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=100_000)
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--size", default="1400x800")
    ap.add_argument("--force-repaint", action="store_true",
                    help="always repaint both views after the result (paints them twice)")
    a = ap.parse_args(argv)

    from gen_plt import generate_plt
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication([])
    from app.window import MainWindow
    from galvo_core.params import Params

    tmp = Path(tempfile.mkdtemp(prefix="galvo-bench-"))
    f = tmp / f"bench_{a.points}.plt"
    f.write_bytes(generate_plt(a.points, seed=0))

    win = MainWindow(restore=False)
    w, h = (int(v) for v in a.size.split("x"))
    win.resize(w, h)
    win.show()
    # 400 mm drawing: magnification 4 bits/unit keeps it inside the 110 mm field
    win.set_params(Params(magnification=4.0), run=False)
    t0 = time.perf_counter()
    assert win.load_file(f)
    assert win.wait_for_result(600)
    first = time.perf_counter() - t0
    for _ in range(3):
        app.processEvents()
    win.fit()
    stats = win.result.job.stats

    shown: list[int] = []
    views = (win.original, win.processed)
    painted_at_shown: list[tuple[int, int]] = []

    def on_shown(gen: int) -> None:
        painted_at_shown.append(tuple(v.paint_count for v in views))  # type: ignore[arg-type]
        shown.append(gen)

    win.result_shown.connect(on_shown)

    def release(name: str, value: float) -> tuple[float, float, tuple[str, ...]]:
        s = win.controls.sliders[name]
        n = len(shown)
        t = time.perf_counter()
        s.set_position(s.to_position(value), final=True)
        while len(shown) == n:
            if win.runner._thread is not None:  # noqa: SLF001 - benchmark
                win.runner._thread.wait(1)
            app.processEvents()
        for v, before in zip(views, painted_at_shown[-1], strict=True):
            if a.force_repaint or v.paint_count == before:
                v.repaint_now()  # not painted since the result arrived: paint it now
        dt = time.perf_counter() - t
        return dt, win.result.seconds, win.result.stages_run

    results: dict[str, list[tuple[float, float]]] = {}
    plans = {"chord_tol_bits": (0.5, 2.0), "magnification": (3.0, 4.0)}
    for name, (v0, v1) in plans.items():
        release(name, v0)  # warm the caches of both values
        release(name, v1)
        rows = []
        for i in range(a.repeats):
            dt, worker, stages = release(name, v0 if i % 2 == 0 else v1)
            assert stages in (("sample",), ()), stages
            rows.append((dt, worker))
        results[name] = rows
        # the cached value (same params twice) is not a re-sample: measure fresh values too
    fresh = []
    s = win.controls.sliders["chord_tol_bits"]
    for i in range(a.repeats):
        value = s.from_position(300 + 20 * i)
        dt, worker, stages = release("chord_tol_bits", value)
        fresh.append((dt, worker))
    results["chord_tol_bits (new values)"] = fresh
    fresh = []
    for i in range(a.repeats):
        dt, worker, stages = release("magnification", 2.5 + 0.1 * i)
        fresh.append((dt, worker))
    results["magnification (new values)"] = fresh

    print(f"machine: {platform.machine()} {platform.processor() or ''} "
          f"{os.cpu_count()} cores, Python {platform.python_version()}, "
          f"{platform.system()} {platform.release()}")
    print(f"file: {a.points} points, {stats['input_points']} input points, "
          f"{stats['control_points']} control points, {stats['mark_points']} marks, "
          f"{stats['strokes']} strokes; window {a.size}")
    print(f"first load (parse + fit + sample + geometry + draw): {first:.2f} s")
    print(f"load average at the end: {os.getloadavg()[0]:.2f}; views repainted "
          f"{'always (twice)' if a.force_repaint else 'once after the result'}")
    print(f"{'change':32s} {'median ms':>10s} {'p90 ms':>8s} {'worker ms':>10s}")
    for name, rows in results.items():
        dts = sorted(r[0] * 1000 for r in rows)
        wk = statistics.median(r[1] * 1000 for r in rows)
        p90 = dts[int(0.9 * (len(dts) - 1))]
        print(f"{name:32s} {statistics.median(dts):10.1f} {p90:8.1f} {wk:10.1f}")
    win.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
