"""Running the pipeline off the GUI thread: newest request wins, at most one run in flight.

:class:`LatestRunner` takes requests (a function of a ``cancel`` callable), runs one at a
time on a :class:`QThread`, keeps only the newest waiting request, cancels a run as soon as
a newer request arrives (the pipeline checks the flag and raises
:class:`galvo_core.pipeline.Cancelled`), and delivers only the result of the newest
generation: results of older generations are dropped. :func:`pipeline_task` builds the
request the window sends: pipeline run + display geometry (:mod:`galvo_core.preview`).
"""

from __future__ import annotations

import gc
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path as FsPath
from typing import Any

import numpy as np
from PySide6.QtCore import QCoreApplication, QElapsedTimer, QObject, QThread, Signal

from galvo_core.drawing import Drawing
from galvo_core.errors import GalvoError, ParamError
from galvo_core.fit import FittedPath
from galvo_core.job import Job
from galvo_core.params import Params
from galvo_core.pipeline import Cancelled, Pipeline
from galvo_core.preview import Preview, PreviewCache, build_preview, with_layers

Task = Callable[[Callable[[], bool]], Any]


@dataclass(frozen=True, eq=False)
class RunResult:
    """One finished pipeline run, ready to show."""

    drawing: Drawing | None
    params: Params | None
    job: Job
    fitted: tuple[FittedPath, ...] | None
    preview: Preview
    seconds: float
    stages_run: tuple[str, ...]
    generation: int = 0
    #: a ParamError of the run (e.g. the drawing leaves the field): only the original shows
    error: str | None = None
    #: the file the drawing came from / the job file shown (the title and export name)
    path: FsPath | None = None
    job_path: FsPath | None = None
    #: the layers whose geometry the preview holds (the others are empty until shown)
    layers: frozenset[str] | None = None
    #: per layer: the arrays handed to the view, and the item data made from them on the
    #: worker (QPainterPaths, rectangles: :func:`app.views.prepare_layer`)
    arrays: dict[str, tuple[np.ndarray, ...]] | None = None
    prepared: dict[str, tuple] | None = None
    #: the pen table applied to ``job`` (app.layers_dock: part of what the result was made of)
    pens: Any = None


_NO_POINTS = np.empty((0, 2))


def layer_arrays(pv: Preview) -> dict[str, tuple[np.ndarray, ...]]:
    """The arrays each layer of the views shows (native space: units or bits)."""
    from .views import MAX_MARKER_POINTS

    show_points = len(pv.original_points) < MAX_MARKER_POINTS
    return {
        "original": (pv.original.xy,),
        "original_points": (pv.original_points if show_points else _NO_POINTS,),
        "fitted": (pv.fitted.xy,),
        "control": (pv.control_xy, pv.control_role),
        "marks": (pv.marks,),
        "jumps": (pv.jumps,),
        "hatch": (pv.hatch.xy,),
        "kerf": (pv.kerf.xy,),
        "deviation": (pv.deviation_a, pv.deviation_b, pv.deviation_level),
    }


class PreparedCache:
    """Item data by layer and the identity of its first array (a small LRU that holds the
    arrays, so an id is never reused while cached): a run that did not change a layer's
    arrays does not rebuild its QPainterPath."""

    def __init__(self, size: int = 32) -> None:
        self.size = size
        self._data: OrderedDict[tuple[str, int, float | None], tuple[tuple, tuple]] = \
            OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: str, arrays: tuple[np.ndarray, ...], lod: float | None = None
            ) -> tuple:
        from .views import prepare_layer

        k = (key, id(arrays[0]), lod)
        with self._lock:
            hit = self._data.get(k)
            if hit is not None and hit[0][0] is arrays[0]:
                self._data.move_to_end(k)
                return hit[1]
        value = prepare_layer(key, *arrays, lod=lod)
        with self._lock:
            self._data[k] = (arrays, value)
            while len(self._data) > self.size:
                self._data.popitem(last=False)
        return value


def with_prepared(result: RunResult, prepared: PreparedCache | None,
                  cancel: Callable[[], bool]) -> RunResult:
    """``result`` with the layers' arrays and their item data made here (worker)."""
    arrays = layer_arrays(result.preview)
    if prepared is None:
        return replace(result, arrays=arrays)
    pv = result.preview
    lod_units = lod_bits = None
    if pv.bounds is not None:
        # coarse paths for the whole-drawing view: a grid of 1/4000 of the drawing's size
        # (a quarter of a pixel or less on views up to 2000 pixels)
        span_mm = max(pv.bounds[2] - pv.bounds[0], pv.bounds[3] - pv.bounds[1])
        if span_mm > 0:
            # rounded in the layers' own units: a new magnification keeps the grid of the
            # layers in input units (their cached paths stay valid)
            lod_units = float(f"{span_mm / pv.units_scale / 4000.0:.2g}")
            lod_bits = float(f"{span_mm / pv.mm_per_bit / 4000.0:.2g}")
    out = {}
    for key, arr in arrays.items():
        if cancel():
            raise Cancelled()
        lod = lod_bits if key in ("jumps", "hatch", "marks") else lod_units
        if key == "kerf" and len(arr[0]) and arr[0] is arrays["fitted"][0]:
            out[key] = out["fitted"]  # the same outline (preview.build_preview): one path
            continue
        out[key] = prepared.get(key, arr, lod)
    return replace(result, arrays=arrays, prepared=out)


def pipeline_task(pipeline: Pipeline, cache: PreviewCache, drawing: Drawing,
                  params: Params, path: FsPath | None = None,
                  layers: frozenset[str] | None = None,
                  prepared: PreparedCache | None = None) -> Task:
    """The work of one request: run the (cached) pipeline, then the display geometry of
    ``layers`` (all when None)."""

    def task(cancel: Callable[[], bool]) -> RunResult:
        t0 = time.perf_counter()
        res = pipeline.run(drawing, params, cancel=cancel)
        job, stages, fitted = res.job, res.stages_run, res.fitted
        if cancel():
            raise Cancelled()
        preview = build_preview(job, drawing, fitted, cache=cache, cancel=cancel, layers=layers)
        res = RunResult(drawing, params, job, fitted, preview, 0.0, stages, path=path,
                        layers=layers)
        res = with_prepared(res, prepared, cancel)
        return replace(res, seconds=time.perf_counter() - t0)

    return task


def pipeline_task_safe(pipeline: Pipeline, cache: PreviewCache, drawing: Drawing,
                       params: Params, path: FsPath | None = None,
                       layers: frozenset[str] | None = None,
                       prepared: PreparedCache | None = None) -> Task:
    """Like :func:`pipeline_task`, but a ParamError of the run (a drawing that leaves the
    field, …) gives a result with ``error`` set that still shows the original drawing and the
    field (so the operator sees why), instead of failing."""
    inner = pipeline_task(pipeline, cache, drawing, params, path, layers, prepared)

    def task(cancel: Callable[[], bool]) -> RunResult:
        t0 = time.perf_counter()
        try:
            return inner(cancel)
        except ParamError as exc:
            fm = pipeline.field_map(drawing, params)
            job = Job(drawing.name, drawing.sha256, fm, params.processing_dict(),
                      params.laser.as_dict(), (), {}, tuple(drawing.warnings))
            preview = build_preview(job, drawing, None, cache=cache, cancel=cancel,
                                    layers=layers)
            res = RunResult(drawing, params, job, None, preview, time.perf_counter() - t0,
                            (), error=str(exc), path=path, layers=layers)
            return with_prepared(res, prepared, cancel)

    return task


def layer_task(base: RunResult, layers: frozenset[str], cache: PreviewCache,
               prepared: PreparedCache | None = None) -> Task:
    """The work of a layer switched on: the optional layers of ``layers`` that the shown
    result ``base`` lacks, computed from its fit (no pipeline run); every other layer keeps
    ``base``'s very arrays and item data, so the views redraw only the new ones."""

    def task(cancel: Callable[[], bool]) -> RunResult:
        t0 = time.perf_counter()
        pv = with_layers(base.preview, base.drawing, base.fitted, layers, cache=cache,
                         cancel=cancel)
        res = replace(base, preview=pv, layers=frozenset((base.layers or frozenset())
                                                         | layers), stages_run=("layers",))
        res = with_prepared(res, prepared, cancel)
        return replace(res, seconds=time.perf_counter() - t0)

    return task


def job_task(job: Job, drawing: Drawing | None, cache: PreviewCache,
             job_path: FsPath | None = None, prepared: PreparedCache | None = None) -> Task:
    """The work of showing a loaded job file (no pipeline run)."""

    def task(cancel: Callable[[], bool]) -> RunResult:
        t0 = time.perf_counter()
        preview = build_preview(job, drawing, None, cache=cache, cancel=cancel)
        res = RunResult(drawing, None, job, None, preview, 0.0, (), job_path=job_path)
        res = with_prepared(res, prepared, cancel)
        return replace(res, seconds=time.perf_counter() - t0)

    return task


@dataclass(frozen=True, eq=False)
class Loaded:
    """A file read on the worker: the drawing and the facts the GUI needs at once (so the
    GUI thread never walks its points)."""

    path: FsPath
    drawing: Drawing
    bbox: tuple[float, float, float, float] | None
    size_mm: tuple[float, float]
    #: the status bar's counts (each walks every path: 10-30 ms on 40 k paths)
    n_points: int = -1
    n_closed: int = -1
    #: a fresh pipeline for the new file that already knows its bbox (the GUI thread's
    #: field map of the new drawing then walks no points)
    pipeline: Pipeline | None = None


def load_task(path: FsPath, read: Callable[[FsPath], Drawing],
              fresh: Callable[[], Pipeline] | None = Pipeline) -> Task:
    """Read an HP-GL file on the worker (cancel drops the result: the reader itself runs to
    its end); ``fresh`` makes the pipeline it will be processed with."""

    def task(cancel: Callable[[], bool]) -> Loaded:
        drawing = read(path)
        if cancel():
            raise Cancelled()
        pipeline = fresh() if fresh is not None else None
        bb = pipeline.bbox(drawing) if pipeline is not None else drawing.bbox()
        return Loaded(path, drawing, bb, drawing.size_mm(), drawing.n_points,
                      drawing.n_closed, pipeline)

    return task


@dataclass(frozen=True, eq=False)
class LoadedJob:
    path: FsPath
    job: Job
    source: Drawing | None
    bbox: tuple[float, float, float, float] | None


def job_load_task(path: FsPath, read_job: Callable[[FsPath], Job],
                  find_source: Callable[[FsPath, Job], Drawing | None]) -> Task:
    """Read a job file (and its source drawing when it sits beside it) on the worker."""

    def task(cancel: Callable[[], bool]) -> LoadedJob:
        job = read_job(path)
        if cancel():
            raise Cancelled()
        source = find_source(path, job)
        return LoadedJob(path, job, source, source.bbox() if source is not None else None)

    return task


def export_task(write: Callable[[Job, FsPath], None], job: Job, path: FsPath) -> Task:
    """Write ``job`` to ``path`` on the worker (atomic writers: a failure leaves nothing);
    a big job in a helper process (:mod:`app.offload`: JSON holds the GIL)."""
    from .offload import write_job_file

    def task(cancel: Callable[[], bool]) -> FsPath:
        write_job_file(write, job, path)
        return path

    return task


class _RunThread(QThread):
    succeeded = Signal(int, object)
    failed = Signal(int, str, bool)  # generation, message, is a GalvoError (user-facing)
    was_cancelled = Signal(int)

    def __init__(self, generation: int, task: Task, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.generation = generation
        self.task = task
        self.cancel_event = threading.Event()

    def run(self) -> None:  # worker thread
        # A run creates 10^5-10^6 long-lived objects (paths, fits, strokes); a full garbage
        # collection walking them holds the GIL for 0.2-0.5 s and freezes the GUI thread.
        # So the collector is paused during the task, and what the task built is then
        # frozen (gc.freeze: left out of later collections). Frozen objects are still freed
        # by reference counting when dropped (they build no cycles: a full collection after
        # ten big files found none of theirs), and the window empties its caches per file
        # (MainWindow._fresh_caches), so the frozen set stays the live set: bounded by the
        # file shown (bench/RESULTS.md, "GUI (issue 18)": memory over ten files).
        # The result is frozen before it is handed over, so the GUI thread never meets
        # a collection over it.
        gc_on = gc.isenabled()
        gc.disable()
        try:
            report = self._run_task()
        finally:
            if gc_on:
                gc.freeze()
                gc.enable()
        report()

    def _run_task(self) -> Callable[[], None]:
        """Run the task; returns the signal emission that reports how it ended."""
        gen = self.generation
        try:
            result = self.task(self.cancel_event.is_set)
        except Cancelled:
            return lambda: self.was_cancelled.emit(gen)
        except GalvoError as exc:
            msg = str(exc)
            return lambda: self.failed.emit(gen, msg, True)
        except Exception as exc:  # noqa: BLE001 - reported in the window, never a crash
            msg = f"internal error: {type(exc).__name__}: {exc}"
            return lambda: self.failed.emit(gen, msg, False)
        return lambda: self.succeeded.emit(gen, result)


class LatestRunner(QObject):
    """Single-flight, latest-wins executor of tasks on a worker thread.

    Signals (all on the GUI thread): ``started(gen)``, ``finished(gen, result)`` only for the
    newest generation, ``failed(gen, message, user_facing)`` likewise, ``cancelled(gen)``,
    ``busy_changed(bool)``.
    """

    started = Signal(int)
    finished = Signal(int, object)
    failed = Signal(int, str, bool)
    cancelled = Signal(int)
    busy_changed = Signal(bool)

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.generation = 0
        self._cancelled_upto = 0
        self._pending: tuple[int, Task] | None = None
        self._thread: _RunThread | None = None
        self._clock = QElapsedTimer()
        #: generations started / delivered / dropped as stale (for tests and the benchmark)
        self.n_started = 0
        self.n_delivered = 0
        self.n_dropped = 0
        self.max_in_flight = 0
        self._in_flight = 0

    # ------------------------------------------------------------------ requests
    def request(self, task: Task) -> int:
        """Queue ``task`` as the newest request; returns its generation."""
        self.generation += 1
        self._pending = (self.generation, task)
        if self._thread is not None:
            self._thread.cancel_event.set()  # stale now: stop it at its next check
        else:
            self._start_next()
        return self.generation

    def cancel(self) -> None:
        """Drop the waiting request and stop the running one."""
        self._pending = None
        self._cancelled_upto = self.generation  # never deliver these, even if they finish
        if self._thread is not None:
            self._thread.cancel_event.set()

    @property
    def busy(self) -> bool:
        return self._thread is not None or self._pending is not None

    @property
    def active(self) -> bool:
        """A request waits or runs that was not cancelled (a cancelled run may still be
        finishing on its thread: busy, but not active)."""
        t = self._thread
        return self._pending is not None or (t is not None and not t.cancel_event.is_set())

    def elapsed_ms(self) -> int:
        return int(self._clock.elapsed()) if self._thread is not None else 0

    def running_generation(self) -> int | None:
        return self._thread.generation if self._thread is not None else None

    def wait_idle(self, timeout_s: float = 60.0) -> bool:
        """Process events until nothing runs or waits (for --screenshot and tests)."""
        deadline = time.monotonic() + timeout_s
        app = QCoreApplication.instance()
        while self.busy and time.monotonic() < deadline:
            if self._thread is not None:
                self._thread.wait(10)
            if app is not None:
                app.processEvents()
        return not self.busy

    def shutdown(self, timeout_ms: int = 10_000) -> None:
        """Cancel everything and wait for the worker (window close)."""
        self.cancel()
        t = self._thread
        if t is not None:
            t.wait(timeout_ms)
            QCoreApplication.processEvents()

    # ------------------------------------------------------------------ internals
    def _start_next(self) -> None:
        if self._pending is None:
            self.busy_changed.emit(False)
            return
        gen, task = self._pending
        self._pending = None
        t = _RunThread(gen, task)
        t.succeeded.connect(self._on_succeeded)
        t.failed.connect(self._on_failed)
        t.was_cancelled.connect(self._on_cancelled)
        t.finished.connect(self._on_thread_finished)
        self._thread = t
        self._in_flight += 1
        self.max_in_flight = max(self.max_in_flight, self._in_flight)
        self.n_started += 1
        self._clock.start()
        if self.n_started == 1 or gen == self.generation:
            self.busy_changed.emit(True)
        self.started.emit(gen)
        t.start()

    def _on_succeeded(self, gen: int, result: object) -> None:
        if gen != self.generation or gen <= self._cancelled_upto:
            self.n_dropped += 1
            return
        self.n_delivered += 1
        if isinstance(result, RunResult):
            object.__setattr__(result, "generation", gen)
        self.finished.emit(gen, result)

    def _on_failed(self, gen: int, message: str, user_facing: bool) -> None:
        if gen != self.generation or gen <= self._cancelled_upto:
            self.n_dropped += 1
            return
        self.failed.emit(gen, message, user_facing)

    def _on_cancelled(self, gen: int) -> None:
        self.cancelled.emit(gen)

    def _on_thread_finished(self) -> None:
        t = self._thread
        self._thread = None
        self._in_flight -= 1
        if t is not None:
            t.deleteLater()
        self._start_next()
