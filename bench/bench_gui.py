"""GUI benchmark (issue 18): control change -> redrawn views at real file sizes, and the
GUI thread's longest stall while files open, process, export and load back.

Driven through the window's scripting surface, offscreen (software rasteriser), 1400x800:

* **latency**: for each file, each control is changed the way the operator does (a slider
  released at a new value, a checkbox toggled) and the time is taken from the change to the
  moment the new result has been handed to the views and both views have painted since (a
  view that has not painted by then is repainted synchronously). Fresh values every time
  (no cache hit), median of ``--repeats``. Wall time and process CPU time (both threads)
  are recorded; the machine is shared, so wall time is the noisier of the two.
* **stalls**: a 5 ms QTimer on the GUI thread records the largest gap between its ticks
  while a file is opened and processed, exported as a job, and the job loaded back; peak
  memory (ru_maxrss) after each phase.
* **memory**: big files opened one after the other (a session): resident and peak memory
  and the garbage collector's frozen objects after each, and what a full collection finds
  at the end (memory must stay about one file's, not grow with each file opened).

    .venv/bin/python bench/bench_gui.py latency [FILES...] [--points 150000] [--repeats 5]
    .venv/bin/python bench/bench_gui.py stalls [--points 1000000 | --file F] [--opens 5]
    .venv/bin/python bench/bench_gui.py memory [FILES...] [--opens 10]
    .venv/bin/python bench/bench_gui.py holders [FILES...] [--points 1000000] [--min-ms 30]

``holders`` opens each file (twice) and changes e_per, kerf and magnification, listing each
stretch over ``--min-ms`` in which one thread held the GIL alone (its CPU time advanced
while a 1 ms sampler could not run), with that thread's Python stack before and after: the
long C calls that stall the GUI thread, told apart from a busy machine.

Without FILES, ``latency`` uses a generated ``--points`` file (bench/gen_plt.py); give the
corpus files (``../shared/corpus/plt/...``) to measure them. ``stalls --opens N`` opens the
file N times in the same window (each open replaces the last one's result) and gives the
max and median of the opens' longest stalls.

``GALVO_BENCH_WHERE=<ms>``: a thread samples every thread's Python stack each 5 ms, and for
each gap of the GUI timer longer than <ms> the samples taken inside it are printed (what
the GUI thread ran, what the worker ran; no sample for a while: one thread held the GIL in
a single C call, or the process was not scheduled). ``GALVO_BENCH_SWITCH_S``: set the
interpreter's switch interval after the window set its own (to compare).
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
os.environ.setdefault("GALVO_WORKSTATION_SETTINGS",
                      os.path.join(tempfile.mkdtemp(prefix="galvo-bench-"), "s.ini"))

SIZE = (1400, 800)
#: GALVO_BENCH_WHERE=<ms>: sample the GUI thread and print what it ran in gaps over <ms>
_WHERE = os.environ.get("GALVO_BENCH_WHERE", "")
WHERE_MS = float(_WHERE) if _WHERE.replace(".", "", 1).isdigit() else 100.0


class StallProbe:
    """The largest gap between ticks of a 5 ms timer on the GUI thread (ms)."""

    def __init__(self) -> None:
        from PySide6.QtCore import Qt, QTimer

        self.timer = QTimer()
        self.timer.setTimerType(Qt.TimerType.PreciseTimer)
        self.timer.setInterval(5)
        self.timer.timeout.connect(self._tick)
        self.last = time.perf_counter()
        self.max_gap = 0.0
        self.long: list[float] = []

    def _tick(self) -> None:
        now = time.perf_counter()
        gap = (now - self.last) * 1000.0
        self.last = now
        self.max_gap = max(self.max_gap, gap)
        if gap > 100.0:
            self.long.append(gap)
        if gap > WHERE_MS:
            if hasattr(self, "sampler"):
                self.sampler.report(now - gap / 1000.0, now, gap)

    def start(self) -> None:
        if os.environ.get("GALVO_BENCH_WHERE") and not hasattr(self, "sampler"):
            self.sampler = MainSampler()
        self.last = time.perf_counter()
        self.max_gap = 0.0
        self.long = []
        self.timer.start()

    def stop(self) -> float:
        self.timer.stop()
        return self.max_gap


class MainSampler:
    """With GALVO_BENCH_WHERE set: a thread that samples the GUI thread's Python stack
    every 5 ms, so a stall can be attributed (the samples taken inside a gap name what the
    GUI thread ran; none at all means a thread held the GIL in one C call, or the process
    was not scheduled)."""

    def __init__(self) -> None:
        import collections
        import threading

        self.samples: collections.deque = collections.deque(maxlen=400)
        self.main = threading.main_thread().ident
        threading.Thread(target=self._run, daemon=True).start()

    def _run(self) -> None:
        import traceback

        while True:
            time.sleep(0.005)
            frames = sys._current_frames()  # noqa: SLF001
            now = time.perf_counter()
            st = []
            for ident, frame in frames.items():
                tag = "gui" if ident == self.main else "bg"
                if ident == threading_ident():
                    continue
                fr = traceback.extract_stack(frame)[-5:]
                st.append(tag + ": " + " <- ".join(
                    f"{x.filename.split('/')[-1]}:{x.lineno} {x.name}" for x in reversed(fr)))
            self.samples.append((now, st))

    def report(self, t0: float, t1: float, gap: float) -> None:
        inside = [(t, st) for t, st in self.samples if t0 - 0.006 <= t <= t1 + 0.006]
        print(f"    gap {gap:.0f} ms, {len(inside)} samples of the GUI thread in it:",
              file=sys.stderr)
        for t, st in inside:
            for line in st:
                print(f"      {(t - t0) * 1000:6.0f} ms {line}", file=sys.stderr)


def threading_ident() -> int:
    import threading

    return threading.get_ident()


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def machine() -> str:
    date = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    return (f"machine: {platform.machine()} {os.cpu_count()} cores, Python "
            f"{platform.python_version()}, {platform.system()} {platform.release()}; load "
            f"average {os.getloadavg()[0]:.1f}; date {date}")


class GuiWork:
    """The longest single apply_result and view paint on the GUI thread (ms)."""

    def __init__(self, win) -> None:
        self.apply = 0.0
        self.paint = 0.0
        self.paint_cpu = 0.0  # the GUI thread's CPU time in the longest paint
        real_apply = win.apply_result

        def apply(result) -> None:
            t = time.perf_counter()
            real_apply(result)
            self.apply = max(self.apply, (time.perf_counter() - t) * 1000)

        win.apply_result = apply
        for v in (win.original, win.processed):
            real_paint = v.paintEvent

            def paint(ev, real=real_paint) -> None:
                t, c = time.perf_counter(), time.thread_time()
                real(ev)
                ms = (time.perf_counter() - t) * 1000
                if ms > self.paint:
                    self.paint, self.paint_cpu = ms, (time.thread_time() - c) * 1000

            v.paintEvent = paint

    def take(self) -> tuple[float, float]:
        out = (self.apply, self.paint)
        self.apply = self.paint = 0.0
        return out


def make_window():
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication([])
    from app.window import MainWindow

    win = MainWindow(restore=False)
    if os.environ.get("GALVO_BENCH_SWITCH_S"):  # compare the window's switch interval
        sys.setswitchinterval(float(os.environ["GALVO_BENCH_SWITCH_S"]))
    win.gui_work = GuiWork(win)
    win.resize(*SIZE)
    win.show()
    for _ in range(3):
        app.processEvents()
    return app, win


def timed(app, win, action: Callable[[], object], timeout_s: float = 600.0
          ) -> tuple[float, float]:
    """(wall s, cpu s) from ``action()`` to the views painted with its result."""
    views = (win.original, win.processed)
    shown: list[tuple[int, ...]] = []

    def on_shown(gen: int) -> None:
        shown.append(tuple(v.paint_count for v in views))

    win.result_shown.connect(on_shown)
    before = tuple(v.paint_count for v in views)
    t0, c0 = time.perf_counter(), time.process_time()
    action()
    assert win.wait_idle(timeout_s)
    app.processEvents()
    ref = shown[-1] if shown else before
    for v, n in zip(views, ref, strict=True):
        if v.paint_count == n:
            v.repaint_now()
    t1, c1 = time.perf_counter(), time.process_time()
    win.result_shown.disconnect(on_shown)
    return t1 - t0, c1 - c0


def release(win, name: str, value: float) -> Callable[[], None]:
    def act() -> None:
        s = win.controls.sliders[name]
        s.set_position(s.to_position(value), final=True)

    return act


def toggle(win, key: str, on: bool) -> Callable[[], None]:
    return lambda: win.layer_boxes[key].setChecked(on)


def latency(files: list[Path], repeats: int, only: list[str] | None = None) -> None:
    app, win = make_window()
    probe = StallProbe()
    print(machine())
    print(f"window {SIZE[0]}x{SIZE[1]}, offscreen; median of {repeats} (fresh values); "
          "wall ms / CPU ms (both threads)")
    for f in files:
        win.layer_boxes["deviation"].setChecked(False)
        from galvo_core.params import Params

        win.set_params(Params(), run=False)
        probe.start()
        wall, cpu = timed(app, win, lambda f=f: win.load_file(f))
        stall = probe.stop()
        d = win.drawing
        st = win.result.job.stats
        print(f"\n{f.name}: {d.n_points} points, {len(d.paths)} paths, "
              f"{st['control_points']} control points, {st['mark_points']} marks; "
              f"fit field {win.params.fit_field}")
        print(f"  open (read + fit + sample + display): {wall * 1000:.0f} ms wall, "
              f"{cpu * 1000:.0f} ms CPU; GUI thread's longest stall {stall:.0f} ms")
        mag = win.result.job.field_map.magnification
        win.set_param("fit_field", False)
        win.set_param("magnification", round(mag * 0.9, 4))
        assert win.wait_idle(600) and win.run_error is None, win.run_error
        rows: list[tuple[str, Callable[[int], Callable[[], None]]]] = [
            ("e_per (fit)", lambda i: release(win, "e_per", 0.05 + 0.01 * i)),
            ("eps_line (fit)", lambda i: release(win, "eps_line", 0.06 + 0.01 * i)),
            ("magnification", lambda i, m=mag: release(win, "magnification",
                                                       round(m * (0.85 - 0.01 * i), 4))),
            ("chord_tol_bits", lambda i: release(win, "chord_tol_bits", 0.6 + 0.1 * i)),
            ("kerf_mm (kerf + fit)", lambda i: release(win, "kerf_mm", 0.02 + 0.005 * i)),
            # with a kerf the offset in input units follows the magnification: kerf + refit
            ("magnification, kerf on", lambda i, m=mag: release(
                win, "magnification", round(m * (0.80 - 0.01 * i), 4))),
            ("layer: deviation on", lambda i: toggle(win, "deviation", True)),
            ("layer: deviation off", lambda i: toggle(win, "deviation", False)),
            ("layer: control off", lambda i: toggle(win, "control", False)),
            ("layer: control on", lambda i: toggle(win, "control", True)),
            ("layer: marks off", lambda i: toggle(win, "marks", False)),
            ("layer: marks on", lambda i: toggle(win, "marks", True)),
        ]
        if only:
            rows = [r for r in rows if any(o in r[0] for o in only)]
        print(f"  {'change':26s} {'wall ms':>9s} {'CPU ms':>8s} {'stall ms':>9s}"
              f" {'apply/paint ms':>15s} {'max wall/CPU ms':>16s}")
        for name, make in rows:
            walls, cpus, stalls, gui = [], [], [], []
            if name.startswith("layer:") and win.params.kerf_mm:
                win.set_param("kerf_mm", 0.0)  # the layer rows without kerf, as the first
                assert win.wait_idle(600)
            for i in range(repeats):
                if name.startswith("layer: deviation on"):
                    # a new fit each time, so the overlay is computed, not taken from the cache
                    win.layer_boxes["deviation"].setChecked(False)
                    win.set_param("e_per", 0.2 + 0.01 * i)
                    assert win.wait_idle(600)
                if name.startswith("layer: deviation off"):
                    win.layer_boxes["deviation"].setChecked(True)
                    assert win.wait_idle(600)
                if name.startswith("layer: control on") or name.startswith("layer: marks on"):
                    win.layer_boxes[name.split()[1]].setChecked(False)
                    assert win.wait_idle(600)
                if name.startswith("layer: control off") or name.startswith("layer: marks off"):
                    win.layer_boxes[name.split()[1]].setChecked(True)
                    assert win.wait_idle(600)
                probe.start()
                win.gui_work.take()
                w, c = timed(app, win, make(i))
                stalls.append(probe.stop())
                gui.append(win.gui_work.take())
                walls.append(w * 1000)
                cpus.append(c * 1000)
            ap = statistics.median(g[0] for g in gui)
            pa = statistics.median(g[1] for g in gui)
            print(f"  {name:26s} {statistics.median(walls):9.0f} {statistics.median(cpus):8.0f}"
                  f" {max(stalls):9.0f} {ap:7.0f}/{pa:<7.0f} {max(walls):8.0f}/{max(cpus):<7.0f}")
        win.set_param("kerf_mm", 0.0)
        win.wait_idle(600)
    win.close()


def stalls(points: int, big: Path | None, opens: int = 1) -> None:
    from gen_plt import generate_plt

    app, win = make_window()
    probe = StallProbe()
    tmp = Path(tempfile.mkdtemp(prefix="galvo-bench-"))
    if big is None:
        big = tmp / f"bench_{points}.plt"
        big.write_bytes(generate_plt(points, seed=0))
    print(machine())
    print(f"file {big.name} ({big.stat().st_size / 1e6:.1f} MB); window {SIZE[0]}x{SIZE[1]}")
    print(f"{'phase':34s} {'wall s':>7s} {'longest GUI stall ms':>21s} {'peak MB':>8s}"
          "   (GUI thread's own longest apply_result / paint, ms)")

    def phase(name: str, action: Callable[[], object]) -> None:
        probe.start()
        # to the views painted with the result (a view that has not painted since is
        # repainted here; one that has is not painted twice)
        dt, _ = timed(app, win, action, 1200)
        gap = probe.stop()
        probe.max_gap = gap
        pc = win.gui_work.paint_cpu
        ap, pt = win.gui_work.take()
        print(f"{name:34s} {dt:7.1f} {gap:21.0f} {peak_mb():8.0f}   "
              f"(gaps > 100 ms: {len(probe.long)}; apply {ap:.0f}, paint {pt:.0f}"
              f" of which CPU {pc:.0f})")

    win.gui_work.take()
    gaps = []
    for k in range(opens):
        # the same file again: the window frees the last one's result as for a new file
        phase("open + process" if k == 0 else f"open again ({k + 1}/{opens})",
              lambda: win.load_file(big))
        gaps.append(probe.max_gap)
    if opens > 1:
        print(f"  open + process over {opens} opens: longest stall max {max(gaps):.0f} ms, "
              f"median {statistics.median(gaps):.0f} ms")
    d = win.drawing
    print(f"  {d.n_points} points, {len(d.paths)} paths, "
          f"{win.result.job.stats['mark_points']} marks, error: {win.run_error}")
    job = tmp / "big.json"
    phase("export job (JSON)", lambda: win.export("job", job, wait=False))
    print(f"  job file {job.stat().st_size / 1e6:.0f} MB")
    phase("e_per change (refit)", release(win, "e_per", 0.3))
    phase("load the job back", lambda: win.load_file(job))
    win.close()


class GilHolders:
    """A thread that wakes every 1 ms and reads every other thread's CPU clock: when it
    could not run for more than ``min_ms`` while another thread's CPU time advanced by as
    much, that thread held the GIL (one long C call that does not release it); its Python
    stack before and after the gap names the call. Independent of the machine's load (a
    thread that merely was not scheduled has no CPU time to show)."""

    def __init__(self, min_ms: float = 30.0) -> None:
        import threading

        self.min_s = min_ms / 1000.0
        self.main = threading.main_thread().ident
        self.found: list[tuple[str, float, float, str, str]] = []
        self.on = False
        threading.Thread(target=self._run, daemon=True).start()

    @staticmethod
    def _stack(frame) -> str:
        import traceback

        fr = traceback.extract_stack(frame)[-4:]
        return " <- ".join(f"{x.filename.split('/')[-1]}:{x.lineno} {x.name}"
                           for x in reversed(fr))

    def _run(self) -> None:
        me = threading_ident()
        last_cpu: dict[int, float] = {}
        last_stack: dict[int, str] = {}
        last = time.perf_counter()
        while True:
            time.sleep(0.001)
            now = time.perf_counter()
            for ident, frame in sys._current_frames().items():  # noqa: SLF001
                if ident == me:
                    continue
                try:
                    cpu = time.clock_gettime(time.pthread_getcpuclockid(ident))
                except (OSError, OverflowError):
                    continue
                d = cpu - last_cpu.get(ident, cpu)
                st = self._stack(frame)
                if self.on and d > self.min_s and now - last > self.min_s:
                    tag = "gui" if ident == self.main else "worker"
                    self.found.append((tag, d * 1000, (now - last) * 1000,
                                       last_stack.get(ident, "?"), st))
                last_cpu[ident] = cpu
                last_stack[ident] = st
            last = now

    def take(self) -> list[tuple[str, float, float, str, str]]:
        out, self.found = self.found, []
        return out


def holders(files: list[Path], min_ms: float) -> None:
    """Each file opened, then e_per, kerf and magnification changed: every stretch over
    ``min_ms`` in which one thread held the GIL alone (:class:`GilHolders`)."""
    app, win = make_window()
    probe = GilHolders(min_ms)
    print(machine())
    from galvo_core.params import Params

    for f in files:
        win.set_params(Params(), run=False)
        steps: list[tuple[str, Callable[[], object]]] = [
            ("open", lambda f=f: win.load_file(f)),
            ("open again", lambda f=f: win.load_file(f)),
            ("e_per", release(win, "e_per", 0.07)),
            ("kerf", release(win, "kerf_mm", 0.03)),
            ("kerf 2", release(win, "kerf_mm", 0.035)),
            ("magnification", lambda: win.set_param(
                "magnification", round(win.result.job.field_map.magnification * 0.95, 4))),
            ("kerf off", release(win, "kerf_mm", 0.0)),
            ("magnification 2", lambda: win.set_param(
                "magnification", round(win.result.job.field_map.magnification * 0.95, 4))),
        ]
        print(f"\n{f.name}")
        for name, act in steps:
            if name.startswith("magnification"):
                win.set_param("fit_field", False)
                assert win.wait_idle(600)
            probe.take()
            probe.on = True
            _, cpu = timed(app, win, act, 1200)
            probe.on = False
            found = probe.take()
            reaper = getattr(win, "_reaper", None)
            freeing = ""
            if reaper is not None:
                freeing = f"; longest freeing pass {reaper.longest_s * 1000:.1f} ms CPU"
                reaper.longest_s = 0.0
            print(f"  {name:16s} CPU {cpu * 1000:6.0f} ms; GIL held > {min_ms:.0f} ms: "
                  f"{len(found)}{freeing}", flush=True)
            for tag, d, gap, before, after in found:
                print(f"    {tag} {d:5.0f} ms CPU in a {gap:4.0f} ms gap\n"
                      f"      before: {before}\n      after:  {after}", flush=True)
    win.close()


def rss_mb() -> float:
    """The resident set size now (MB), from /proc (Linux)."""
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 1e6


def memory(files: list[Path], opens: int) -> None:
    """Open ``files`` in turn ``opens`` times (a session): resident and peak memory, the
    objects in the garbage collector's frozen generation and the GUI thread's longest
    stall after each; at the end what a full collection still finds."""
    import gc

    app, win = make_window()
    probe = StallProbe()
    print(machine())
    print(f"{'#':>2s} {'file':30s} {'wall s':>6s} {'RSS MB':>7s} {'peak MB':>8s} "
          f"{'frozen objs':>11s} {'stall ms':>8s}")
    print(f"   (start){'':22s} {'':6s} {rss_mb():7.0f} {peak_mb():8.0f} "
          f"{gc.get_freeze_count():11d}")
    for i in range(opens):
        f = files[i % len(files)]
        probe.start()
        t0 = time.perf_counter()
        win.load_file(f)
        assert win.wait_idle(1200), f
        for _ in range(3):
            app.processEvents()
        gap = probe.stop()
        print(f"{i + 1:2d} {f.name[:30]:30s} {time.perf_counter() - t0:6.1f} {rss_mb():7.0f} "
              f"{peak_mb():8.0f} {gc.get_freeze_count():11d} {gap:8.0f}", flush=True)
    gc.unfreeze()
    t0 = time.perf_counter()
    found = gc.collect()
    print(f"then gc.unfreeze() + gc.collect(): {found} unreachable objects, "
          f"{(time.perf_counter() - t0) * 1000:.0f} ms; RSS {rss_mb():.0f} MB")
    win.close()



def _generated(points: int) -> Path:
    """A gen_plt file of ``points`` points (seed 0) in a fresh temporary folder."""
    from gen_plt import generate_plt

    f = Path(tempfile.mkdtemp(prefix="galvo-bench-")) / f"gen_{points}.plt"
    f.write_bytes(generate_plt(points, seed=0))
    return f

def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    a1 = sub.add_parser("latency")
    a1.add_argument("files", nargs="*", type=Path)
    a1.add_argument("--points", type=int, default=150_000)
    a1.add_argument("--repeats", type=int, default=5)
    a1.add_argument("--rows", default="", help="only the rows whose name contains one of "
                    "these comma-separated words (e.g. 'magnification,chord,deviation on')")
    a2 = sub.add_parser("stalls")
    a2.add_argument("--points", type=int, default=1_000_000)
    a2.add_argument("--file", type=Path, default=None)
    a2.add_argument("--opens", type=int, default=1, help="open the file this many times "
                    "(the longest stall of each open; max and median)")
    a3 = sub.add_parser("memory")
    a3.add_argument("files", nargs="*", type=Path)
    a3.add_argument("--opens", type=int, default=10)
    a4 = sub.add_parser("holders")
    a4.add_argument("files", nargs="*", type=Path)
    a4.add_argument("--points", type=int, default=1_000_000)
    a4.add_argument("--min-ms", type=float, default=30.0)
    a = ap.parse_args(argv)
    if a.cmd == "holders":
        holders(list(a.files) or [_generated(a.points)], a.min_ms)
        return 0
    if a.cmd == "memory":
        files = list(a.files)
        if not files:
            from gen_plt import generate_plt

            tmp = Path(tempfile.mkdtemp(prefix="galvo-bench-"))
            for seed, n in ((1, 400_000), (2, 400_000), (3, 1_000_000)):
                f = tmp / f"gen_{n}_{seed}.plt"
                f.write_bytes(generate_plt(n, seed=seed))
                files.append(f)
        memory(files, a.opens)
    elif a.cmd == "latency":
        latency(list(a.files) or [_generated(a.points)], a.repeats,
                [w for w in a.rows.split(",") if w] or None)
    else:
        stalls(a.points, a.file, a.opens)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
