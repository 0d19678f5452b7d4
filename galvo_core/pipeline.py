"""The staged, cached pipeline that the CLI and the GUI both call.

    Drawing ─field─▶ FieldMap ─kerf─▶ Drawing ─fit─▶ fitted paths ─sample─▶ marks
            ─fill─▶ hatch strokes ─order─▶ Job

The field mapping is chosen on the file's own drawing (so kerf does not move it); kerf
compensation (paper 003) happens on the region outlines before fitting, so the fitted curves
and marks follow the compensated outline; the hatch (paper 002) fills the compensated
regions; the order stage orders every stroke of the job.

Caching. Each stage's result is cached under a key made of *everything it depends on*: the
input drawing (by identity; the cache entry holds the drawing, so its identity cannot be
reused while the entry lives), the whole parameter group the stage reads
(:meth:`Params.group`, frozen and hashable), the whole :class:`FieldMap` when the stage
converts through the field, and the key of the stage before it. So moving ``e_per`` refits
but does not re-read or re-offset; moving the magnification re-samples but does not refit;
and no change of any parameter can return a result computed under other values.
"""

from __future__ import annotations

import dataclasses
import math
import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from operator import attrgetter
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from galvo_core.drawing import Drawing, Warning
from galvo_core.errors import Cancelled
from galvo_core.field import FieldMap, check_in_field, make_field
from galvo_core.fit import FittedPath, fit_drawing, with_source_index
from galvo_core.job import Job, Segments, Stroke, StrokeColumns, gc_paused
from galvo_core.params import UNITS_PER_MM, Params
from galvo_core.precision import drawing_quantum, path_quanta
from galvo_core.sample import (
    ROUNDING_BOUND_BITS,
    SampleReport,
    polyline_marks,
    sample_geometry,
    sample_paths,
)
from galvo_core.timing import estimate_with_dwell, joined_marks

if TYPE_CHECKING:
    from galvo_core.fill import HatchStroke

__all__ = ["Cancelled", "Pipeline", "RunResult", "coordinate_quantum", "process"]


# kerf, fill and order (and shapely, 0.1 s of a process's start) are imported when a run
# first needs them, not for every job: these are their functions under the names the
# stages call (and benchmarks wrap)
def compensate_indexed(*args: Any, **kw: Any) -> Any:
    from galvo_core.kerf import compensate_indexed as f

    return f(*args, **kw)


def kerf_regions(*args: Any, **kw: Any) -> Any:
    from galvo_core.kerf import kerf_regions as f

    return f(*args, **kw)


def hatch(*args: Any, **kw: Any) -> Any:
    from galvo_core.fill import hatch as f

    return f(*args, **kw)


def order_job_strokes(strokes: Sequence[Stroke], fm: FieldMap, *, method: str,
                      **kw: Any) -> list[Stroke]:
    if method == "file":  # as made: nothing to import
        return list(strokes)
    from galvo_core.order import order_job_strokes as f

    return f(strokes, fm, method=method, **kw)  # type: ignore[return-value]

T = TypeVar("T")
#: the fit stage's batches end at this many input points (cancel is checked between them:
#: ~0.1 s each); up to 16,384 small paths share one batch (its fixed cost is per batch)
FIT_BATCH_POINTS = 65536
Cancel = Callable[[], bool] | None


class _Cache:
    """A small LRU of stage results. Each entry holds the input drawing it was computed
    from and is returned only for that very object (ids are reused after garbage
    collection; the held reference prevents it while the entry lives, the identity check
    makes it certain)."""

    def __init__(self, size: int) -> None:
        self.size = size
        self.data: OrderedDict[Hashable, tuple[object, Any]] = OrderedDict()
        self.lock = threading.Lock()

    def peek(self, anchor: object, key: Hashable) -> Any:
        """The entry for ``anchor`` and ``key`` if there is one (None otherwise); no make."""
        with self.lock:
            hit = self.data.get((id(anchor), key))
            return hit[1] if hit is not None and hit[0] is anchor else None

    def get(self, anchor: object, key: Hashable, make: Callable[[], T]) -> T:
        full = (id(anchor), key)
        with self.lock:
            hit = self.data.get(full)
            if hit is not None and hit[0] is anchor:
                self.data.move_to_end(full)
                return hit[1]  # type: ignore[no-any-return]
        value = make()
        with self.lock:
            self.data[full] = (anchor, value)
            self.data.move_to_end(full)
            while len(self.data) > self.size:
                self.data.popitem(last=False)
        return value


@dataclass
class _Run:
    """What one run recomputed and how long each stage took (local to :meth:`Pipeline.run`)."""

    cancel: Cancel
    ran: list[str] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)

    def stage(self, name: str, make: Callable[[], T]) -> Callable[[], T]:
        def timed() -> T:
            self.check()
            t0 = time.perf_counter()
            out = make()
            self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - t0
            self.ran.append(name)
            return out

        return timed

    def check(self) -> None:
        if self.cancel is not None and self.cancel():
            raise Cancelled()


@dataclass(frozen=True, eq=False)
class RunResult:
    """One finished run: the job and what it was made from.

    ``work``: the drawing after kerf compensation (``drawing`` itself without kerf) and
    ``origin[i]`` the input path that ``work.paths[i]`` came from; ``fitted``: the fitted
    paths of ``work``; ``sample_report``: what the sampler measured; ``stages_run``: the
    stages recomputed (the rest came from the cache); ``timings``: seconds per recomputed
    stage (plus "order" and "stats", which always run).
    """

    job: Job
    drawing: Drawing
    params: Params
    field_map: FieldMap
    work: Drawing
    origin: tuple[int, ...]
    fitted: tuple[FittedPath, ...]
    sample_report: SampleReport | None
    stages_run: tuple[str, ...]
    timings: dict[str, float]
    seconds: float


@dataclass(frozen=True, eq=False)
class _Marks:
    marks: tuple[np.ndarray, ...]
    report: SampleReport


class Pipeline:
    """Cached stages. One caller at a time per pipeline (the GUI's worker, the CLI)."""

    def __init__(self, cache_size: int = 4) -> None:
        self._cache = _Cache(6 * cache_size)
        # facts of a drawing (bbox, coordinate quantum, point count) and of a fit (counts,
        # segments): computed once per object, not per run
        self._facts = _Cache(8 * cache_size)

    def _fact(self, obj: object, name: str, make: Callable[[], T]) -> T:
        return self._facts.get(obj, name, make)

    def bbox(self, drawing: Drawing) -> tuple[float, float, float, float] | None:
        """``drawing.bbox()``, cached."""
        return self._fact(drawing, "bbox", lambda: _bbox(_joined(_point_arrays(drawing))))

    def _input_facts(self, drawing: Drawing) -> None:
        """The input drawing's bounding box, point count, coordinate grid and each path's
        grid from one pass over its paths and one join of their points (each alone passes
        over them again: 10-300 ms each at 1 M points, more for many paths); the arrays are
        not kept. Made by :meth:`run` (a worker), not by :meth:`field_map` or :meth:`bbox`,
        which a window may call on its own thread."""
        if self._facts.peek(drawing, "path quanta") is not None:
            return
        arrs = _point_arrays(drawing)
        allp = _joined(arrs)
        # drawing.quantum(): drawing_quantum of the paths, which joins them the same way
        facts: dict[str, Any] = {
            "n_points": len(allp), "bbox": _bbox(allp),
            "quantum": (float(drawing_quantum([allp])[0]) if len(allp) else 0.0,)}
        del allp
        facts["path quanta"] = path_quanta(arrs)
        for name, value in facts.items():
            self._fact(drawing, name, _const(value))

    # ---------------------------------------------------------------- stages
    def field_map(self, drawing: Drawing, params: Params) -> FieldMap:
        """The field mapping of ``drawing`` (reads the field group; an outward kerf grows
        the drawing by kerf/2 on the workpiece, so the margin reads the kerf group too)."""
        true_size = params.field_bits / params.field_size_mm / UNITS_PER_MM
        mag = params.magnification
        if mag is None and not params.fit_field:
            mag = true_size
        grow_bits = (params.kerf_mm / 2 if params.kerf_side == "outside" else 0.0) / (
            params.field_size_mm / params.field_bits)
        return make_field(self.bbox(drawing), magnification=mag, fit_field=params.fit_field,
                          field_bits=params.field_bits, field_size_mm=params.field_size_mm,
                          offset_bits=params.offset_bits, margin_bits=grow_bits)

    @staticmethod
    def _kerf_key(params: Params, fm: FieldMap) -> Hashable:
        return None if params.kerf_mm == 0 else (params.group("kerf"), fm)

    def compensated(self, drawing: Drawing, params: Params, fm: FieldMap,
                    run: _Run | None = None) -> tuple[Drawing, tuple[int, ...]]:
        """The kerf stage (paper 003): the drawing with its regions offset, and for each of
        its paths the index of the input path it came from (identity without kerf)."""
        if params.kerf_mm == 0:
            return drawing, tuple(range(len(drawing.paths)))
        run = run or _Run(None)

        def make() -> tuple[Drawing, tuple[int, ...]]:
            # the rings' even-odd regions do not depend on the kerf: once per drawing
            regions = self._fact(drawing, "kerf_regions",
                                 lambda: kerf_regions(drawing, self.bbox(drawing)))
            return compensate_indexed(drawing, kerf_mm=params.kerf_mm, side=params.kerf_side,
                                      method=params.kerf_method, fm=fm,
                                      arc_tol_bits=params.arc_tol_bits, regions=regions)

        return self._cache.get(drawing, ("kerf", self._kerf_key(params, fm)),
                               run.stage("kerf", make))

    def fitted(self, drawing: Drawing, params: Params, fm: FieldMap | None = None,
               run: _Run | None = None) -> tuple[FittedPath, ...]:
        """The fit stage (paper 000 §2-3) on the (compensated) drawing."""
        fm = fm or self.field_map(drawing, params)
        run = run or _Run(None)
        work, origin = self.compensated(drawing, params, fm, run)

        def fit(d: Drawing, quanta: np.ndarray | None = None) -> tuple[FittedPath, ...]:
            # all paths of a batch are thinned and fitted together; cancel() between batches
            # (at most FIT_BATCH_POINTS input points each, ~0.1 s) raises errors.Cancelled
            return tuple(fit_drawing(d, eps_line=params.eps_line, e_per=params.e_per,
                                     eps_sum=params.eps_sum, batch_points=FIT_BATCH_POINTS,
                                     cancel=run.cancel, quantum_units=quanta))

        def make() -> tuple[FittedPath, ...]:
            if work is drawing:  # the grids the stats report too: detected once
                return fit(work, self.input_quanta(drawing))
            # the kerf's paths keep the grid of the input path they came from: the file's
            # precision, not the offset's floats (a path the kerf passes through is fitted
            # as without kerf; an offset ring of rounded input is as uncertain as its input)
            q_work = self.input_quanta(drawing)[np.asarray(origin, dtype=np.intp)]
            base = self._cache.peek(drawing, ("fit", None, params.group("fit")))
            if base is None:
                return fit(work, q_work)
            return self._refit_changed(drawing, work, origin, q_work, base, fit)

        key = ("fit", self._kerf_key(params, fm), params.group("fit"))
        return self._cache.get(drawing, key, run.stage("fit", make))

    def input_quanta(self, drawing: Drawing) -> np.ndarray:
        """Each input path's grid (:func:`galvo_core.precision.path_quanta`), cached."""
        return self._fact(drawing, "path quanta", lambda: path_quanta(_point_arrays(drawing)))

    @staticmethod
    def _refit_changed(drawing: Drawing, work: Drawing, origin: Sequence[int],
                       q_work: np.ndarray, base: tuple[FittedPath, ...],
                       fit: Callable[[Drawing, np.ndarray], tuple[FittedPath, ...]]
                       ) -> tuple[FittedPath, ...]:
        """The fit of the kerf's ``work`` drawing from the input drawing's cached fit
        ``base``: a path the kerf passed through unchanged (the same object, with the same
        grid) keeps its fit; only the others are fitted. A path's fit depends only on its
        points, closedness and grid (``fit_paths`` fits each path as on its own), so this
        is the fit of the whole ``work`` drawing with the grids ``q_work``."""
        src = drawing.paths
        same = [i for i, (p, o) in enumerate(zip(work.paths, origin, strict=True))
                if p is src[o]]
        if not same:
            return fit(work, q_work)
        keep = np.zeros(len(work.paths), dtype=bool)
        keep[same] = True
        redo = np.flatnonzero(~keep).tolist()
        fresh = fit(work.with_paths([work.paths[i] for i in redo]), q_work[redo]) \
            if redo else ()
        out: list[FittedPath | None] = [None] * len(work.paths)
        for i in same:
            out[i] = with_source_index(base[origin[i]], i)
        for k, i in enumerate(redo):
            out[i] = with_source_index(fresh[k], i)
        return tuple(out)  # type: ignore[arg-type]

    def marks(self, drawing: Drawing, params: Params, fm: FieldMap,
              run: _Run | None = None) -> _Marks:
        """One stroke of marks per fitted path (int64 bits, before any clamping) with what
        the sampler measured."""
        run = run or _Run(None)
        work, _ = self.compensated(drawing, params, fm, run)
        fitted = self.fitted(drawing, params, fm, run)

        def make() -> _Marks:
            res = sample_paths(
                fitted, fm, interpolation=params.interpolation,
                chord_tol_bits=params.chord_tol_bits, min_step_bits=params.min_step_bits,
                max_step_bits=params.max_step_bits, fixed_step_bits=params.fixed_step_bits,
                fixed_slope_tol=params.fixed_slope_tol,
                # the input points are read only by "raw" (a list over 10^4-10^5 paths)
                raw_points=[work.paths[fp.source_index].points for fp in fitted]
                if params.interpolation == "raw" else None,
                cancel=run.cancel,
                geometry=self._fact(fitted, "sample_geometry", lambda: sample_geometry(fitted)),
                keep_chunks=False,  # only the marks and the report are kept
            )
            return _Marks(tuple(res.marks), res.report)

        key = ("sample", self._kerf_key(params, fm), params.group("fit"),
               params.group("sample"), fm)
        return self._cache.get(drawing, key, run.stage("sample", make))

    def hatched(self, drawing: Drawing, params: Params, fm: FieldMap,
                run: _Run | None = None) -> tuple[tuple[HatchStroke, np.ndarray], ...]:
        """The fill stage (paper 002): hatch strokes of the (compensated) regions, each with
        its marks (int64 bits, before any clamping)."""
        if params.fill == "none":
            return ()
        run = run or _Run(None)
        work, _ = self.compensated(drawing, params, fm, run)

        def make() -> tuple[tuple[HatchStroke, np.ndarray], ...]:
            strokes = hatch(work, fill=params.fill,
                            spacing_units=fm.mm_to_units(params.hatch_spacing_mm),
                            angle_deg=params.hatch_angle_deg, passes=params.hatch_passes,
                            angle_step_deg=params.hatch_angle_step_deg,
                            inset_units=fm.mm_to_units(params.hatch_inset_mm))
            run.check()
            return tuple((h, polyline_marks(h.points, fm, min_step_bits=params.min_step_bits))
                         for h in strokes)

        key = ("fill", self._kerf_key(params, fm), params.group("fill"), fm,
               params.min_step_bits)
        return self._cache.get(drawing, key, run.stage("fill", make))

    # ---------------------------------------------------------------- the whole run
    def run(self, drawing: Drawing, params: Params, cancel: Cancel = None) -> RunResult:
        """Process a drawing into a job. Raises ParamError for values that cannot work (a
        drawing that leaves the field without ``clamp``), Cancelled when ``cancel()`` says so."""
        t0 = time.perf_counter()
        run = _Run(cancel)
        self._input_facts(drawing)
        fm = self.field_map(drawing, params)
        work, origin = self.compensated(drawing, params, fm, run)
        fitted = self.fitted(drawing, params, fm, run)
        warnings: list[Warning] = list(work.warnings)
        # the fit detects each path's grid itself (galvo_core.precision) and bounds its
        # error beyond the rounding: no warning needed; the quantum goes into the stats
        out_msg = check_in_field(fm, self.bbox(work), clamp=params.clamp)
        if out_msg:
            warnings.append(Warning(0, 0, out_msg))
        sampled = self.marks(drawing, params, fm, run)
        hatched = self.hatched(drawing, params, fm, run)
        # the input points are in the field (else out_msg), but a fitted curve may bulge past
        # its edge by up to the fit's bound: those marks are clamped, never left outside
        rep = sampled.report
        bulge = not params.clamp and not out_msg and rep is not None and rep.outside_points > 0
        strokes, clamped, cols = self._strokes(work, origin, fitted, sampled, hatched, params,
                                               fm, clamp=params.clamp or bulge)
        run.check()
        t1 = time.perf_counter()
        moves: list[tuple[int, int, bool]] = []
        ordered: tuple[Stroke, ...] = tuple(order_job_strokes(  # type: ignore[arg-type]
            strokes, fm, method=params.scan_order, time_budget_s=params.order_time_budget_s,
            moves=moves))
        t2 = time.perf_counter()
        stats = self.stats(drawing, params, fitted, fm, ordered, sampled.report, work)
        if clamped:
            warnings.append(Warning(0, 0, f"{clamped} marks were outside the field and clamped"
                                    + ("" if params.clamp else " (curves that bulge past the "
                                       "field edge within the fit tolerance)")))
        if stats["dwell_points"]:
            warnings.append(Warning(0, 0, (
                f"dwell: {stats['dwell_points']} consecutive marks closer than "
                f"{params.laser.mark_speed_mm_s * params.laser.point_period_us * 1e-3:.2f} µm "
                "(mark speed × point period): the beam stands still there and may burn")))
        job_params = params.processing_dict()
        job_params["quantum_units"] = stats["quantum_units"]  # detected, not set
        job = Job(drawing.name, drawing.sha256, fm, job_params,
                  params.laser.as_dict(), ordered, stats, tuple(warnings))
        # the columns of the strokes as made, in the order's order (rotated, reversed)
        job = job.with_columns((cols if params.scan_order == "file"
                                else cols.moved(moves)).finish(ordered))
        t3 = time.perf_counter()
        run.timings["order"] = t2 - t1
        run.timings["stats"] = t3 - t2
        return RunResult(job, drawing, params, fm, work, origin, fitted, sampled.report,
                         tuple(run.ran), dict(run.timings), t3 - t0)

    def _strokes(self, work: Drawing, origin: tuple[int, ...], fitted: tuple[FittedPath, ...],
                 sampled: _Marks, hatched: tuple[tuple[HatchStroke, np.ndarray], ...],
                 params: Params, fm: FieldMap, *, clamp: bool = False
                 ) -> tuple[list[Stroke], int, _Columns]:
        """The job's strokes in the stages' order (contours, then hatch), clamped to the field
        when ``clamp``; how many marks were clamped; and their columns but the marks (from
        the stages' arrays: no pass over the strokes)."""
        clamped = 0
        marks: list[np.ndarray] = list(sampled.marks)
        keep = [i for i, m in enumerate(marks) if len(m)] if not all(map(len, marks)) \
            else None
        hatch_marks = [hm for _, hm in hatched]
        if clamp:
            marks, n1 = _clamped(marks, fm.max_bit)
            hatch_marks, n2 = _clamped(hatch_marks, fm.max_bit)
            clamped = n1 + n2
        with gc_paused():  # one object per stroke, no cycles: no collector passes
            segs = self._fact(fitted, "segments", lambda: [
                Segments(fp.is_cubic, fp.points) for fp in fitted])
            # per fit (a fit belongs to one compensated drawing, so to one ``origin``)
            src, closed, pens = self._fact(fitted, "stroke columns", lambda: (
                [origin[fp.source_index] for fp in fitted], [fp.closed for fp in fitted],
                [fp.pen for fp in fitted]))
            if keep is not None:  # paths without marks make no stroke
                marks, segs = [marks[i] for i in keep], [segs[i] for i in keep]
                src, closed, pens = [src[i] for i in keep], [closed[i] for i in keep], \
                    [pens[i] for i in keep]
            strokes = _new_strokes("contour", src, closed, marks, segs, pens)
            hatch_pens = [work.paths[h.source_index].pen for h, _ in hatched]
            if hatched:
                strokes += _new_strokes(
                    "hatch", [origin[h.source_index] for h, _ in hatched],
                    [False] * len(hatched), hatch_marks, [Segments.empty()] * len(hatched),
                    hatch_pens)
        return strokes, clamped, self._columns(fitted, keep, hatch_pens)

    def _columns(self, fitted: tuple[FittedPath, ...], keep: list[int] | None,
                 hatch_pens: list[int]) -> _Columns:
        """The columns of :meth:`_strokes`' strokes but the marks: the contours' from the
        fit's arrays (the sampler's gathered geometry), the hatch strokes' appended."""
        geo = self._fact(fitted, "sample_geometry", lambda: sample_geometry(fitted))
        closed, pens = self._fact(fitted, "stroke column arrays", lambda: (
            np.fromiter((fp.closed for fp in fitted), dtype=bool, count=len(fitted)),
            np.fromiter((fp.pen for fp in fitted), dtype=np.int64, count=len(fitted))))
        nseg, npts, is_cubic, points = geo.path_n, geo.path_npts, geo.is_cubic, geo.points
        if keep is not None:  # paths without marks make no stroke
            on = np.zeros(len(fitted), dtype=bool)
            on[keep] = True
            is_cubic = is_cubic[np.repeat(on, nseg)]
            points = points[np.repeat(on, npts)]
            closed, pens, nseg, npts = closed[on], pens[on], nseg[on], npts[on]
        nh = len(hatch_pens)
        if nh:
            closed = np.concatenate([closed, np.zeros(nh, dtype=bool)])
            pens = np.concatenate([pens, np.array(hatch_pens, dtype=np.int64)])
            nseg = np.concatenate([nseg, np.zeros(nh, dtype=np.int64)])
            npts = np.concatenate([npts, np.zeros(nh, dtype=np.int64)])
        return _Columns(closed, pens, nseg, is_cubic, npts, points)

    def stats(self, drawing: Drawing, params: Params, fitted: tuple[FittedPath, ...],
              fm: FieldMap, strokes: Sequence[Stroke], report: SampleReport | None,
              work: Drawing | None = None) -> dict[str, Any]:
        """Counts, lengths, the time estimate (:mod:`galvo_core.timing`) and what the
        sampler measured: the largest chord height before and after rounding (bits, against
        the true curve; None for raw marks), chords above the tolerance, min-step
        overrides, marks outside the field (before clamping), dwell points."""
        # the job's marks joined once (remembered for its strokes tuple: the preview and the
        # simulation reuse them)
        t, dwell = estimate_with_dwell(joined_marks(strokes), params.laser, fm.mm_per_bit)
        n_input = self._fact(drawing, "n_points", lambda: drawing.n_points)
        quantum = self._fact(drawing, "quantum", lambda: (drawing.quantum(),))[0] or 0.0
        # the fit uses each input path's own grid (a kerf path its input path's): its bound
        # is the largest path's
        path_q = float(self.input_quanta(drawing).max(initial=0.0))
        fit_err, n_control, n_lines, n_cubics = self._fact(fitted, "counts", lambda: (
            _fit_counts(fitted, self._fact(fitted, "sample_geometry",
                                           lambda: sample_geometry(fitted)))))
        out: dict[str, Any] = {
            "input_points": n_input,
            # the file's coordinate grid (0: exact) and the fit's bound from the input
            # points in effect: the tolerances beyond each path's rounding
            # (galvo_core.precision), here the largest over the paths
            "quantum_units": quantum,
            "fit_bound_units": max(params.e_per, params.eps_line) + path_q / math.sqrt(2.0),
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
        if report is not None:
            out.update({
                "max_chord_height_bits": report.max_chord_height_bits,
                "max_chord_height_int_bits": report.max_chord_height_int_bits,
                "chord_height_violations": report.chord_violations,
                "min_step_overrides": report.min_step_overrides,
                "outside_points": report.outside_points,
            })
        return out


@dataclass(frozen=True, eq=False)
class _Columns:
    """:class:`~galvo_core.job.StrokeColumns` of the strokes made by a run, but what the
    strokes' tuple gives at once (marks, kinds, sources: :func:`joined_marks`, made for the
    stats anyway)."""

    closed: np.ndarray
    pen: np.ndarray
    segment_count: np.ndarray
    is_cubic: np.ndarray
    point_count: np.ndarray
    points: np.ndarray

    def moved(self, moves: Sequence[tuple[int, int, bool]]) -> _Columns:
        """These columns for the strokes reordered by the order stage: per new stroke (old
        index, first segment after the rotation, reversed), as
        :func:`galvo_core.order.apply_to_strokes` turns each stroke's segments (rotated
        first, then reversed), gathered by index arrays instead of per stroke."""
        mv = np.array(moves, dtype=np.int64).reshape(-1, 3)
        idx, rot, rev = mv[:, 0], mv[:, 1], mv[:, 2].astype(bool)
        nseg, npts = self.segment_count[idx], self.point_count[idx]
        seg0 = np.cumsum(self.segment_count) - self.segment_count  # old first rows
        pt0 = np.cumsum(self.point_count) - self.point_count
        # each old segment's first point row within its stroke (Segments.offsets)
        step = np.where(self.is_cubic, 3, 1)
        at = np.cumsum(step) - step
        has = nseg > 0
        o = np.zeros(len(idx), dtype=np.int64)  # the rotation's first point within the stroke
        o[has] = at[seg0[idx[has]] + rot[has]] - at[seg0[idx[has]]]
        # segments: new row i of a stroke is old (rot + i) mod n, i counted from the end
        # when reversed
        i = np.arange(int(nseg.sum()), dtype=np.int64) - np.repeat(np.cumsum(nseg) - nseg, nseg)
        n = np.repeat(nseg, nseg)
        i = np.where(np.repeat(rev, nseg), n - 1 - i, i)
        segs = np.repeat(seg0[idx], nseg) + (np.repeat(rot, nseg) + i) % np.maximum(n, 1)
        # points: a rotation by o is points[o:] + points[1:o + 1] (Segments.rotated)
        j = np.arange(int(npts.sum()), dtype=np.int64) - np.repeat(np.cumsum(npts) - npts, npts)
        m, oo = np.repeat(npts, npts), np.repeat(o, npts)
        j = np.where(np.repeat(rev, npts), m - 1 - j, j)
        j = np.where(j < m - oo, oo + j, j - (m - oo) + 1)
        pts = np.repeat(pt0[idx], npts) + j
        return _Columns(self.closed[idx], self.pen[idx], nseg, self.is_cubic[segs], npts,
                        self.points[pts])

    def finish(self, strokes: tuple[Stroke, ...]) -> StrokeColumns:
        jm = joined_marks(strokes)
        return StrokeColumns(strokes, kind=jm.hatch.astype(np.uint8), closed=self.closed,
                             pen=self.pen, source_index=jm.source, mark_count=jm.lens,
                             marks=jm.marks, segment_count=self.segment_count,
                             is_cubic=self.is_cubic, point_count=self.point_count,
                             points=self.points)


def _const(value: T) -> Callable[[], T]:
    return lambda: value


def _point_arrays(drawing: Drawing) -> list[np.ndarray]:
    """Each path's points as an (N, 2) float64 array (the path's own when it is one)."""
    out = []
    for p in drawing.paths:
        a = np.asarray(p.points, dtype=np.float64)
        out.append(a if a.ndim == 2 and a.shape[1] == 2 else a.reshape(-1, 2))
    return out


def _joined(arrs: list[np.ndarray]) -> np.ndarray:
    """Every point of a drawing's paths (their (N, 2) arrays), in one array."""
    return np.concatenate(arrs) if arrs else np.zeros((0, 2))


def _bbox(allp: np.ndarray) -> tuple[float, float, float, float] | None:
    """:meth:`Drawing.bbox` of the joined points (None without points)."""
    if not len(allp):
        return None
    x, y = allp[:, 0], allp[:, 1]
    return float(x.min()), float(y.min()), float(x.max()), float(y.max())


def _fit_counts(fitted: Sequence[FittedPath], geo: Any) -> tuple[float, int, int, int]:
    """The largest fit error, the control points (:func:`galvo_core.fit.control_points`
    summed), lines and cubics of a fit, from the sampler's gathered arrays ``geo``."""
    n = len(fitted)
    err = np.fromiter(map(attrgetter("max_error"), fitted), dtype=np.float64, count=n)
    nseg, npts = geo.path_n, geo.path_npts
    # control_points: 0 without segments, 1 for a dot (one line from a point to itself),
    # else the stored points
    one = np.flatnonzero(nseg == 1)
    first = (np.cumsum(npts) - npts)[one]
    dot = ~geo.is_cubic[geo.path_first[one]] & (
        geo.points[first] == geo.points[first + 1]).all(axis=1)
    n_control = int(npts[nseg > 0].sum()) - int((npts[one[dot]] - 1).sum())
    n_cubics = int(np.count_nonzero(geo.is_cubic))
    return (float(err.max()) if n else 0.0, n_control, len(geo.is_cubic) - n_cubics, n_cubics)


def _clamped(marks: list[np.ndarray], max_bit: int) -> tuple[list[np.ndarray], int]:
    """``marks`` clipped to the field (0 .. max_bit) and how many marks moved: one pass over
    all strokes joined; the strokes that did not move keep their arrays."""
    if not marks:
        return marks, 0
    allm = np.concatenate(marks)
    moved = ((allm < 0) | (allm > max_bit)).any(axis=1)
    n = int(moved.sum())
    if not n:
        return marks, 0
    lens = np.fromiter(map(len, marks), dtype=np.int64, count=len(marks))
    ends = np.cumsum(lens)
    cs = np.concatenate(([0], np.cumsum(moved)))
    hit = np.flatnonzero(cs[ends] - cs[ends - lens])
    out = list(marks)
    for i in hit.tolist():
        out[i] = np.clip(marks[i], 0, max_bit)
    return out, n


_STROKE_FIELDS = ("kind", "source_index", "closed", "marks", "segments", "pen")
# Stroke's own constructor costs ~0.7 µs per field (a frozen dataclass sets each through
# object.__setattr__) plus __post_init__: 25 ms for 40 k strokes on every re-sample. The
# fields are written straight into the instance dict instead, when Stroke is still the
# plain dataclass this expects (else its constructor is used).
_FAST_STROKES = (tuple(f.name for f in dataclasses.fields(Stroke)) == _STROKE_FIELDS
                 and not hasattr(Stroke, "__slots__"))


def _new_strokes(kind: str, src: list[int], closed: list[bool], marks: list[np.ndarray],
                 segs: list[Segments], pens: list[int]) -> list[Stroke]:
    """``Stroke(kind, src[i], closed[i], marks[i], segs[i], pens[i])`` for every i (the
    segments already :class:`Segments`)."""
    if not _FAST_STROKES:
        return [Stroke(kind, s, c, m, sg, p)
                for s, c, m, sg, p in zip(src, closed, marks, segs, pens, strict=True)]
    new = object.__new__
    out: list[Stroke] = []
    append = out.append
    for s, c, m, sg, p in zip(src, closed, marks, segs, pens, strict=True):
        st = new(Stroke)
        d = st.__dict__
        d["kind"] = kind
        d["source_index"] = s
        d["closed"] = c
        d["marks"] = m
        d["segments"] = sg
        d["pen"] = p
        append(st)
    return out


def coordinate_quantum(drawing: Drawing) -> float | None:
    """The drawing's grid step (input units, :meth:`Drawing.quantum`), None when its points
    are exact (off any grid) or it has none."""
    q = drawing.quantum()
    return q if q > 0.0 else None


def process(drawing: Drawing, params: Params | None = None) -> Job:
    """Process with a fresh pipeline (convenience for scripts)."""
    return Pipeline().run(drawing, params or Params()).job
