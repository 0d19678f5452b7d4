"""Running the pipeline off the GUI thread: newest request wins, at most one run in flight.

:class:`LatestRunner` takes requests (a function of a ``cancel`` callable), runs one at a
time on a :class:`QThread`, keeps only the newest waiting request, cancels a run as soon as
a newer request arrives (the pipeline checks the flag and raises
:class:`galvo_core.pipeline.Cancelled`), and delivers only the result of the newest
generation: results of older generations are dropped. :func:`pipeline_task` builds the
request the window sends: pipeline run + display geometry (:mod:`galvo_core.preview`).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QCoreApplication, QElapsedTimer, QObject, QThread, Signal

from galvo_core.drawing import Drawing
from galvo_core.errors import GalvoError, ParamError
from galvo_core.fit import FittedPath
from galvo_core.job import Job
from galvo_core.params import Params
from galvo_core.pipeline import Cancelled, Pipeline
from galvo_core.preview import Preview, PreviewCache, build_preview

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


def pipeline_task(pipeline: Pipeline, cache: PreviewCache, drawing: Drawing,
                  params: Params) -> Task:
    """The work of one request: run the (cached) pipeline, then the display geometry."""

    def task(cancel: Callable[[], bool]) -> RunResult:
        t0 = time.perf_counter()
        res = pipeline.run(drawing, params, cancel=cancel)
        job, stages, fitted = res.job, res.stages_run, res.fitted
        if cancel():
            raise Cancelled()
        preview = build_preview(job, drawing, fitted, cache=cache, cancel=cancel)
        return RunResult(drawing, params, job, fitted, preview, time.perf_counter() - t0, stages)

    return task


def pipeline_task_safe(pipeline: Pipeline, cache: PreviewCache, drawing: Drawing,
                       params: Params) -> Task:
    """Like :func:`pipeline_task`, but a ParamError of the run (a drawing that leaves the
    field, …) gives a result with ``error`` set that still shows the original drawing and the
    field (so the operator sees why), instead of failing."""
    inner = pipeline_task(pipeline, cache, drawing, params)

    def task(cancel: Callable[[], bool]) -> RunResult:
        t0 = time.perf_counter()
        try:
            return inner(cancel)
        except ParamError as exc:
            fm = pipeline.field_map(drawing, params)
            job = Job(drawing.name, drawing.sha256, fm, params.processing_dict(),
                      params.laser.as_dict(), (), {}, tuple(drawing.warnings))
            preview = build_preview(job, drawing, None, cache=cache, cancel=cancel)
            return RunResult(drawing, params, job, None, preview, time.perf_counter() - t0,
                             (), error=str(exc))

    return task


def job_task(job: Job, drawing: Drawing | None, cache: PreviewCache) -> Task:
    """The work of showing a loaded job file (no pipeline run)."""

    def task(cancel: Callable[[], bool]) -> RunResult:
        t0 = time.perf_counter()
        preview = build_preview(job, drawing, None, cache=cache, cancel=cancel)
        return RunResult(drawing, None, job, None, preview, time.perf_counter() - t0, ())

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
        try:
            result = self.task(self.cancel_event.is_set)
        except Cancelled:
            self.was_cancelled.emit(self.generation)
        except GalvoError as exc:
            self.failed.emit(self.generation, str(exc), True)
        except Exception as exc:  # noqa: BLE001 - reported in the window, never a crash
            self.failed.emit(self.generation, f"internal error: {type(exc).__name__}: {exc}",
                             False)
        else:
            self.succeeded.emit(self.generation, result)


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
        if self._thread is not None:
            self._thread.cancel_event.set()

    @property
    def busy(self) -> bool:
        return self._thread is not None or self._pending is not None

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
        if gen != self.generation:
            self.n_dropped += 1
            return
        self.n_delivered += 1
        if isinstance(result, RunResult):
            object.__setattr__(result, "generation", gen)
        self.finished.emit(gen, result)

    def _on_failed(self, gen: int, message: str, user_facing: bool) -> None:
        if gen != self.generation:
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
