"""The staged, cached pipeline that the CLI and the GUI both call.

    Drawing ─fit─▶ fitted paths ─field─▶ FieldMap ─sample─▶ marks ─order─▶ Job

Each stage's result is cached under the drawing's identity and the :class:`Params` fields
that stage reads (:data:`galvo_core.params.STAGE_FIELDS`): moving ``e_per`` refits but does
not re-read the file; moving the magnification re-samples but does not refit.
"""

from __future__ import annotations

import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from galvo_core.drawing import Drawing, Warning
from galvo_core.field import FieldMap, check_in_field, make_field
from galvo_core.fit import FittedPath, control_points, fit_path
from galvo_core.job import Job, Stroke
from galvo_core.params import STAGE_FIELDS, Params
from galvo_core.sample import sample_path
from galvo_core.timing import dwell_count, estimate

T = TypeVar("T")


class Cancelled(Exception):
    """Raised inside a run when its ``cancel`` callback says stop."""


class _LRU:
    def __init__(self, size: int) -> None:
        self.size = size
        self.data: OrderedDict[Hashable, Any] = OrderedDict()
        self.lock = threading.Lock()

    def get(self, key: Hashable, make: Callable[[], T]) -> T:
        with self.lock:
            if key in self.data:
                self.data.move_to_end(key)
                return self.data[key]  # type: ignore[no-any-return]
        value = make()
        with self.lock:
            self.data[key] = value
            while len(self.data) > self.size:
                self.data.popitem(last=False)
        return value


def _key(params: Params, stage: str) -> tuple[Any, ...]:
    return tuple(getattr(params, f) for f in STAGE_FIELDS[stage])


@dataclass(frozen=True)
class RunInfo:
    """What a run recomputed (for tests of the caching and for the GUI's progress)."""

    stages_run: tuple[str, ...]
    seconds: float


class Pipeline:
    """Cached stages. Thread-safe for one caller at a time per pipeline (the GUI's worker)."""

    def __init__(self, cache_size: int = 4) -> None:
        self._fit = _LRU(cache_size)
        self._marks = _LRU(cache_size)
        self.last_info = RunInfo((), 0.0)

    # ---------------------------------------------------------------- stages
    def fitted(self, drawing: Drawing, params: Params,
               cancel: Callable[[], bool] | None = None) -> tuple[FittedPath, ...]:
        key = (id(drawing), drawing.sha256, _key(params, "fit"))

        def make() -> tuple[FittedPath, ...]:
            self._ran.append("fit")
            out = []
            for i, p in enumerate(drawing.paths):
                if cancel is not None and i % 64 == 0 and cancel():
                    raise Cancelled()
                out.append(fit_path(p.points, closed=p.closed, eps_line=params.eps_line,
                                    e_per=params.e_per, eps_sum=params.eps_sum,
                                    source_index=i, pen=p.pen))
            return tuple(out)

        return self._fit.get(key, make)

    def field_map(self, drawing: Drawing, params: Params) -> FieldMap:
        default_mag = params.field_bits / params.field_size_mm / 40.0  # true size
        mag = params.magnification
        if mag is None and not params.fit_field:
            mag = default_mag
        return make_field(drawing.bbox(), magnification=mag, fit_field=params.fit_field,
                          field_bits=params.field_bits, field_size_mm=params.field_size_mm,
                          offset_bits=params.offset_bits)

    def marks(self, drawing: Drawing, params: Params, fitted: tuple[FittedPath, ...],
              fm: FieldMap, cancel: Callable[[], bool] | None = None) -> tuple[np.ndarray, ...]:
        key = (id(drawing), drawing.sha256, _key(params, "fit"), _key(params, "sample"),
               fm.magnification, fm.offset_bits, fm.field_bits)

        def make() -> tuple[np.ndarray, ...]:
            self._ran.append("sample")
            out = []
            for i, fp in enumerate(fitted):
                if cancel is not None and i % 256 == 0 and cancel():
                    raise Cancelled()
                out.append(sample_path(
                    fp, fm, interpolation=params.interpolation,
                    chord_tol_bits=params.chord_tol_bits, min_step_bits=params.min_step_bits,
                    max_step_bits=params.max_step_bits,
                    raw_points=drawing.paths[fp.source_index].points,
                ))
            return tuple(out)

        return self._marks.get(key, make)

    # ---------------------------------------------------------------- the whole run
    def run(self, drawing: Drawing, params: Params,
            cancel: Callable[[], bool] | None = None) -> Job:
        """Process a drawing into a job. Raises ParamError for values that cannot work (a
        drawing that leaves the field without ``clamp``), Cancelled when ``cancel()`` says so."""
        t0 = time.perf_counter()
        self._ran: list[str] = []
        fitted = self.fitted(drawing, params, cancel)
        fm = self.field_map(drawing, params)
        warnings: list[Warning] = list(drawing.warnings)
        quantum = coordinate_quantum(drawing)
        if quantum is not None and params.e_per < 0.5 * quantum:
            warnings.append(Warning(0, 0, (
                f"the file's coordinates are whole multiples of {quantum:g} unit: its points "
                f"are rounded by up to {0.5 * quantum:g} unit, more than e_per = "
                f"{params.e_per:g}, so smooth runs stay as lines; an e_per of about "
                f"{0.75 * quantum:g} lets curves be fitted")))
        out_msg = check_in_field(fm, drawing.bbox(), clamp=params.clamp)
        if out_msg:
            warnings.append(Warning(0, 0, out_msg))
        marks = self.marks(drawing, params, fitted, fm, cancel)
        strokes = []
        clamped = 0
        for fp, m in zip(fitted, marks, strict=True):
            if len(m) == 0:
                continue
            if params.clamp:
                c = np.clip(m, 0, fm.max_bit)
                clamped += int((c != m).any(axis=1).sum())
                m = c
            strokes.append(Stroke("contour", fp.source_index, fp.closed, m,
                                  tuple((s.kind, s.points) for s in fp.segments), fp.pen))
        stats = self.stats(drawing, params, fitted, fm, strokes)
        if clamped:
            warnings.append(Warning(0, 0, f"{clamped} marks were outside the field and clamped"))
        if stats["dwell_points"]:
            warnings.append(Warning(0, 0, (
                f"dwell: {stats['dwell_points']} consecutive marks closer than "
                f"{params.laser.mark_speed_mm_s * params.laser.point_period_us * 1e-3:.2f} µm "
                "(mark speed × 10 µs): the beam stands still there and may burn")))
        job = Job(drawing.name, drawing.sha256, fm, params.processing_dict(),
                  params.laser.as_dict(), tuple(strokes), stats, tuple(warnings))
        self.last_info = RunInfo(tuple(self._ran), time.perf_counter() - t0)
        return job

    @staticmethod
    def stats(drawing: Drawing, params: Params, fitted: tuple[FittedPath, ...], fm: FieldMap,
              strokes: list[Stroke]) -> dict[str, Any]:
        ms = [s.marks for s in strokes]
        t = estimate(ms, params.laser, fm.mm_per_bit)
        return {
            "input_points": drawing.n_points,
            "control_points": sum(control_points(f) for f in fitted),
            "lines": sum(1 for f in fitted for s in f.segments if s.kind == "line"),
            "cubics": sum(1 for f in fitted for s in f.segments if s.kind == "cubic"),
            "mark_points": t["mark_points"],
            "strokes": len(strokes),
            "laser_switches": t["laser_switches"],
            "corners": t["corners"],
            "mark_length_mm": t["mark_length_mm"],
            "jump_length_mm": t["jump_length_mm"],
            "estimated_time_s": t["estimated_time_s"],
            "max_fit_error": max((f.max_error for f in fitted), default=0.0),
            "max_fit_error_um": max((f.max_error for f in fitted), default=0.0)
            * fm.mm_per_unit * 1000.0,
            "dwell_points": dwell_count(ms, params.laser, fm.mm_per_bit),
        }


def coordinate_quantum(drawing: Drawing) -> float | None:
    """1.0 when every coordinate is a whole number (CAD-style integer plotter units), None
    when the file has fractional coordinates (or no points)."""
    pts = [p.points for p in drawing.paths if len(p.points)]
    if not pts:
        return None
    allp = np.concatenate(pts)
    if len(allp) < 3 or not np.array_equal(allp, np.round(allp)):
        return None
    return 1.0


_default = Pipeline()


def process(drawing: Drawing, params: Params | None = None) -> Job:
    """Process with the module's shared pipeline (convenience for scripts and the CLI)."""
    return _default.run(drawing, params or Params())
