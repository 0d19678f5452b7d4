"""The staged, cached pipeline that the CLI and the GUI both call.

    Drawing ─field─▶ FieldMap ─kerf─▶ Drawing ─fit─▶ fitted paths ─sample─▶ marks
            ─fill─▶ hatch strokes ─order─▶ Job

The field mapping is chosen on the file's own drawing (so kerf does not move it); kerf
compensation (paper 003) happens on the region outlines before fitting, so the fitted curves
and marks follow the compensated outline; the hatch (paper 002) fills the compensated
regions; the order stage orders every stroke of the job.

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
from typing import Any, TypeVar, cast

import numpy as np

from galvo_core.drawing import Drawing, Warning
from galvo_core.field import FieldMap, check_in_field, make_field
from galvo_core.fill import HatchStroke, hatch
from galvo_core.fit import FitCancelled, FittedPath, control_points, fit_drawing
from galvo_core.job import Job, Stroke
from galvo_core.kerf import compensate_indexed
from galvo_core.order import order_job_strokes
from galvo_core.params import STAGE_FIELDS, Params
from galvo_core.precision import drawing_quantum
from galvo_core.sample import ROUNDING_BOUND_BITS, SampleReport, polyline_marks, sample_paths
from galvo_core.timing import estimate_with_dwell

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
        self._kerf = _LRU(cache_size)
        self._fit = _LRU(cache_size)
        self._fill = _LRU(cache_size)
        self._marks = _LRU(cache_size)
        # facts of a drawing or a fit that every run needs (bbox, coordinate quantum,
        # counts, the stroke segments): computed once per object, not per run
        self._facts = _LRU(4 * cache_size)
        self.last_info = RunInfo((), 0.0)

    def _fact(self, obj: Any, name: str, make: Callable[[], T]) -> T:
        """``make()`` cached by ``obj``'s identity (the entry keeps ``obj`` alive, so the id
        cannot be reused while it is cached; drawings and fits are immutable)."""
        if not isinstance(obj, (tuple, Drawing)):  # a mutable sequence: not cached
            return make()
        held, value = self._facts.get((id(obj), name), lambda: (obj, make()))
        if held is not obj:  # pragma: no cover - an id reused after eviction
            value = make()
            with self._facts.lock:
                self._facts.data[(id(obj), name)] = (obj, value)
        return cast(T, value)

    def bbox(self, drawing: Drawing) -> tuple[float, float, float, float] | None:
        """``drawing.bbox()``, cached."""
        return self._fact(drawing, "bbox", drawing.bbox)

    # ---------------------------------------------------------------- stages
    def compensated(self, drawing: Drawing, params: Params,
                    fm: FieldMap) -> tuple[Drawing, tuple[int, ...]]:
        """The kerf stage (paper 003): the drawing with its regions offset, and for each of
        its paths the index of the input path it came from (identity without kerf)."""
        if params.kerf_mm == 0:
            return drawing, tuple(range(len(drawing.paths)))
        key = (id(drawing), drawing.sha256, _key(params, "kerf"), fm.magnification)

        def make() -> tuple[Drawing, tuple[int, ...]]:
            self._ran.append("kerf")
            return compensate_indexed(drawing, kerf_mm=params.kerf_mm, side=params.kerf_side,
                                      method=params.kerf_method, fm=fm,
                                      arc_tol_bits=params.arc_tol_bits)

        return self._kerf.get(key, make)

    def hatched(self, work: Drawing, params: Params, fm: FieldMap) -> list[HatchStroke]:
        """The fill stage (paper 002): hatch strokes of the (compensated) regions."""
        if params.fill == "none":
            return []
        key = (id(work), work.sha256, _key(params, "fill"), fm.magnification)

        def make() -> list[HatchStroke]:
            self._ran.append("fill")
            return hatch(work, fill=params.fill,
                         spacing_units=fm.mm_to_units(params.hatch_spacing_mm),
                         angle_deg=params.hatch_angle_deg, passes=params.hatch_passes,
                         angle_step_deg=params.hatch_angle_step_deg,
                         inset_units=fm.mm_to_units(params.hatch_inset_mm))

        return self._fill.get(key, make)

    def fitted(self, drawing: Drawing, params: Params,
               cancel: Callable[[], bool] | None = None) -> tuple[FittedPath, ...]:
        key = (id(drawing), drawing.sha256, _key(params, "fit"))

        def make() -> tuple[FittedPath, ...]:
            self._ran.append("fit")
            # all paths of a batch are thinned and fitted together; cancel() between batches
            try:
                return fit_drawing(drawing, eps_line=params.eps_line, e_per=params.e_per,
                                   eps_sum=params.eps_sum, batch=512, cancel=cancel)
            except FitCancelled:
                raise Cancelled() from None

        return self._fit.get(key, make)

    def field_map(self, drawing: Drawing, params: Params) -> FieldMap:
        default_mag = params.field_bits / params.field_size_mm / 40.0  # true size
        mag = params.magnification
        if mag is None and not params.fit_field:
            mag = default_mag
        # an outward kerf grows the drawing by kerf/2 on the workpiece: leave room for it
        grow_bits = (params.kerf_mm / 2 if params.kerf_side == "outside" else 0.0) / (
            params.field_size_mm / params.field_bits)
        return make_field(self.bbox(drawing), magnification=mag, fit_field=params.fit_field,
                          field_bits=params.field_bits, field_size_mm=params.field_size_mm,
                          offset_bits=params.offset_bits, margin_bits=grow_bits)

    def marks(self, drawing: Drawing, params: Params, fitted: tuple[FittedPath, ...],
              fm: FieldMap, cancel: Callable[[], bool] | None = None) -> tuple[np.ndarray, ...]:
        """One stroke of marks per fitted path (int64 bits, before any clamping), cached by
        the fit and sample fields and the field mapping; what the sampler measured is kept
        for :meth:`stats` (``self.sample_report``)."""
        key = (id(drawing), drawing.sha256, _key(params, "fit"), _key(params, "sample"),
               fm.magnification, fm.offset_bits, fm.field_bits, fm.field_size_mm)

        def make() -> _Marks:
            self._ran.append("sample")
            if cancel is not None and cancel():
                raise Cancelled()
            res = sample_paths(
                fitted, fm, interpolation=params.interpolation,
                chord_tol_bits=params.chord_tol_bits, min_step_bits=params.min_step_bits,
                max_step_bits=params.max_step_bits, fixed_step_bits=params.fixed_step_bits,
                fixed_slope_tol=params.fixed_slope_tol,
                raw_points=[drawing.paths[fp.source_index].points for fp in fitted],
                cancel=cancel,
            )
            return _Marks(res.marks, res.report)

        out = self._marks.get(key, make)
        self.sample_report: SampleReport | None = out.report
        return out

    # ---------------------------------------------------------------- the whole run
    def run(self, drawing: Drawing, params: Params,
            cancel: Callable[[], bool] | None = None) -> Job:
        """Process a drawing into a job. Raises ParamError for values that cannot work (a
        drawing that leaves the field without ``clamp``), Cancelled when ``cancel()`` says so."""
        t0 = time.perf_counter()
        self._ran: list[str] = []
        fm = self.field_map(drawing, params)
        work, origin = self.compensated(drawing, params, fm)
        fitted = self.fitted(work, params, cancel)
        warnings: list[Warning] = list(work.warnings)
        # the fit detects each path's grid itself (galvo_core.precision) and bounds its
        # error beyond the rounding: no warning needed; the quantum is kept for the stats
        self.quantum = self._fact(drawing, "quantum", lambda: coordinate_quantum(drawing))
        out_msg = check_in_field(fm, self.bbox(work), clamp=params.clamp)
        if out_msg:
            warnings.append(Warning(0, 0, out_msg))
        marks = self.marks(work, params, fitted, fm, cancel)
        strokes = []
        clamped = 0

        def clamp(m: np.ndarray) -> np.ndarray:
            nonlocal clamped
            if not params.clamp:
                return m
            c = np.clip(m, 0, fm.max_bit)
            clamped += int((c != m).any(axis=1).sum())
            return c

        segs = self._fact(fitted, "segments", lambda: [
            tuple((s.kind, s.points) for s in fp.segments) for fp in fitted])
        for fp, m, sg in zip(fitted, marks, segs, strict=True):
            if len(m) == 0:
                continue
            strokes.append(Stroke("contour", origin[fp.source_index], fp.closed, clamp(m),
                                  sg, fp.pen))
        for h in self.hatched(work, params, fm):
            src = origin[h.source_index]
            hm = polyline_marks(h.points, fm, min_step_bits=params.min_step_bits)
            strokes.append(Stroke("hatch", src, False, clamp(hm), (),
                                  work.paths[h.source_index].pen))
        if cancel is not None and cancel():
            raise Cancelled()
        strokes = cast(list[Stroke], order_job_strokes(
            strokes, fm, method=params.scan_order, time_budget_s=params.order_time_budget_s))
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

    def stats(self, drawing: Drawing, params: Params, fitted: tuple[FittedPath, ...],
              fm: FieldMap, strokes: list[Stroke]) -> dict[str, Any]:
        """Counts, lengths, the time estimate (:mod:`galvo_core.timing`) and what the
        sampler measured: the largest chord height before and after rounding (bits, against
        the true curve; None for raw marks), chords above the tolerance, min-step
        overrides, marks outside the field (before clamping), dwell points."""
        ms = [s.marks for s in strokes]
        t, dwell = estimate_with_dwell(ms, params.laser, fm.mm_per_bit)
        rep = getattr(self, "sample_report", None)
        n_input = self._fact(drawing, "n_points", lambda: drawing.n_points)
        fit_err, n_control, n_lines, n_cubics = self._fact(fitted, "counts", lambda: (
            max((f.max_error for f in fitted), default=0.0),
            sum(control_points(f) for f in fitted),
            sum(1 for f in fitted for s in f.segments if s.kind == "line"),
            sum(1 for f in fitted for s in f.segments if s.kind == "cubic")))
        out: dict[str, Any] = {
            "input_points": n_input,
            "control_points": n_control,
            "lines": n_lines,
            "cubics": n_cubics,
            "mark_points": t["mark_points"],
            "strokes": len(strokes),
            "laser_switches": t["laser_switches"],
            "jumps": t["jumps"],
            "corners": t["corners"],
            "mark_length_mm": t["mark_length_mm"],
            "jump_length_mm": t["jump_length_mm"],
            "estimated_time_s": t["estimated_time_s"],
            "mark_time_s": t["mark_time_s"],
            "jump_time_s": t["jump_time_s"],
            "delay_time_s": t["delay_time_s"],
            "max_fit_error": fit_err,
            "max_fit_error_um": fit_err * fm.mm_per_unit * 1000.0,
            "chord_tol_bits": params.chord_tol_bits,
            "max_chord_height_bits": None,
            "max_chord_height_int_bits": None,
            "chord_height_violations": 0,
            "min_step_overrides": 0,
            "rounding_bound_bits": ROUNDING_BOUND_BITS,
            "outside_points": 0,
            "dwell_points": dwell,
        }
        if rep is not None:
            out.update({
                "max_chord_height_bits": rep.max_chord_height_bits,
                "max_chord_height_int_bits": rep.max_chord_height_int_bits,
                "chord_height_violations": rep.chord_violations,
                "min_step_overrides": rep.min_step_overrides,
                "outside_points": rep.outside_points,
            })
        return out


class _Marks(tuple):  # type: ignore[type-arg]
    """The sampled strokes (a tuple of (M, 2) int64 arrays) with the sampler's report."""

    report: SampleReport

    def __new__(cls, marks: list[np.ndarray], report: SampleReport) -> _Marks:
        obj = super().__new__(cls, marks)
        obj.report = report
        return obj


def coordinate_quantum(drawing: Drawing) -> float | None:
    """The drawing's grid step (input units, :func:`galvo_core.precision.drawing_quantum`),
    None when its points are exact (off any grid) or it has none."""
    q, _ = drawing_quantum(drawing.paths)
    return q if q > 0.0 else None


_default = Pipeline()


def process(drawing: Drawing, params: Params | None = None) -> Job:
    """Process with the module's shared pipeline (convenience for scripts and the CLI)."""
    return _default.run(drawing, params or Params())
