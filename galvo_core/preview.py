"""Display geometry for the workstation's views (numpy only, never Qt).

Everything a view draws is computed here, so the GUI only hands arrays to plot items:

* polylines are returned as one ``(N, 2)`` float64 array with a row of NaN between
  consecutive pieces (one plot item draws them all with ``connect="finite"``), plus an
  ``ids`` array (``(N,)`` int64, -1 on the NaN rows) naming the source path of each row;
* positions are in *workpiece millimetres of the field*: a galvo bit ``X`` is at
  ``X * mm_per_bit`` mm, so the field is the square ``0 .. field_size_mm`` and a point ``p``
  of the drawing (input units) is at ``(p * magnification + offset_bits) * mm_per_bit``.
  Both views (original and processed) use the job's :class:`~galvo_core.field.FieldMap`,
  so they line up on the workpiece whatever the magnification.

Functions take a :class:`~galvo_core.drawing.Drawing`, fitted paths
(:class:`~galvo_core.fit.FittedPath`) or a :class:`~galvo_core.job.Job` and return arrays;
:func:`build_preview` assembles them all into one :class:`Preview` (what the GUI's worker
thread computes after each pipeline run). Geometry that depends only on the fit (flattened
curves, control points, deviation) is computed in input units and cached by the fitted
tuple's identity (:class:`PreviewCache`), so a change that only re-samples only rescales it.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numba import njit

from galvo_core.drawing import Drawing, Warning
from galvo_core.field import FieldMap
from galvo_core.fit import FittedPath
from galvo_core.geometry import flatten_cubic
from galvo_core.job import Job, Segments
from galvo_core.pipeline import Cancelled
from galvo_core.timing import joined_marks

__all__ = [
    "EMPTY",
    "FitArrays",
    "Preview",
    "PreviewCache",
    "Polylines",
    "bbox",
    "bits_to_mm",
    "build_preview",
    "control_geometry",
    "control_layer",
    "deviation_samples",
    "display_tolerance",
    "drawing_points",
    "field_outline_mm",
    "fit_arrays",
    "fitted_curve",
    "flatten_segments",
    "hatch_polylines",
    "jump_segments",
    "mark_points",
    "mm_to_bits",
    "mm_to_units",
    "nan_join",
    "nearest_id",
    "original_polylines",
    "path_for_position",
    "path_summary",
    "stroke_curves",
    "units_to_mm",
    "warning_path",
    "with_layers",
]

#: Layers whose geometry is computed only when shown (``build_preview(layers=...)``).
OPTIONAL_LAYERS = frozenset({"control", "deviation"})

#: An empty (0, 2) point array.
EMPTY = np.empty((0, 2), dtype=np.float64)
_NO_IDS = np.empty(0, dtype=np.int64)


@dataclass(frozen=True, eq=False)
class Polylines:
    """NaN-separated polylines: ``xy`` (N, 2) with NaN rows between pieces, ``ids`` (N,)
    the source index of each row (-1 on NaN rows)."""

    xy: np.ndarray = field(default_factory=lambda: EMPTY)
    ids: np.ndarray = field(default_factory=lambda: _NO_IDS)

    def __len__(self) -> int:
        return len(self.xy)

    @property
    def n_vertices(self) -> int:
        return int(np.count_nonzero(self.ids >= 0))

    def scaled(self, scale: float, offset: Sequence[float] = (0.0, 0.0)) -> Polylines:
        """``xy * scale + offset`` (NaN rows stay NaN), same ids."""
        return Polylines(self.xy * scale + np.asarray(offset, dtype=np.float64), self.ids)

    def select(self, index: int) -> np.ndarray:
        """The rows of source ``index`` (NaN-separated when it has several pieces)."""
        if not len(self.ids):
            return EMPTY
        keep = self.ids == index
        if not keep.any():
            return EMPTY
        # keep the NaN row after each selected piece so pieces stay separate
        nxt = np.zeros_like(keep)
        nxt[1:] = keep[:-1] & (self.ids[1:] < 0)
        return self.xy[keep | nxt]


# ------------------------------------------------------------------ joining and mapping
def nan_join(pieces: Iterable[np.ndarray], ids: Iterable[int] | None = None) -> Polylines:
    """Concatenate (K_i, 2) point arrays with one NaN row between consecutive pieces.

    Empty pieces are skipped. ``ids`` (one per piece, default 0, 1, 2, …) label the rows.
    """
    arrays: list[np.ndarray] = []
    labels: list[int] = []
    id_iter = iter(ids) if ids is not None else None
    for i, p in enumerate(pieces):
        label = next(id_iter) if id_iter is not None else i
        a = np.asarray(p, dtype=np.float64).reshape(-1, 2)
        if len(a):
            arrays.append(a)
            labels.append(int(label))
    if not arrays:
        return Polylines()
    lengths = np.fromiter((len(a) for a in arrays), dtype=np.int64, count=len(arrays))
    total = int(lengths.sum()) + len(arrays) - 1
    xy = np.full((total, 2), np.nan)
    row_ids = np.full(total, -1, dtype=np.int64)
    starts = np.concatenate(([0], np.cumsum(lengths + 1)[:-1]))
    stacked = np.concatenate(arrays)
    rows = np.repeat(starts - np.concatenate(([0], np.cumsum(lengths)[:-1])), lengths)
    rows += np.arange(len(stacked))
    xy[rows] = stacked
    row_ids[rows] = np.repeat(np.asarray(labels, dtype=np.int64), lengths)
    return Polylines(xy, row_ids)


def units_to_mm(fm: FieldMap, pts: np.ndarray) -> np.ndarray:
    """(N, 2) input units -> (N, 2) workpiece mm in the field (NaN stays NaN)."""
    return fm.to_bits_float(np.asarray(pts, dtype=np.float64).reshape(-1, 2)) * fm.mm_per_bit


def bits_to_mm(fm: FieldMap, bits: np.ndarray) -> np.ndarray:
    """(N, 2) galvo bits -> (N, 2) workpiece mm in the field."""
    return np.asarray(bits, dtype=np.float64).reshape(-1, 2) * fm.mm_per_bit


def mm_to_bits(fm: FieldMap, xy_mm: np.ndarray) -> np.ndarray:
    """Workpiece mm -> float galvo bits (the inverse of :func:`bits_to_mm`)."""
    return np.asarray(xy_mm, dtype=np.float64).reshape(-1, 2) / fm.mm_per_bit


def mm_to_units(fm: FieldMap, xy_mm: np.ndarray) -> np.ndarray:
    """Workpiece mm -> input units of the drawing (the inverse of :func:`units_to_mm`)."""
    return (mm_to_bits(fm, xy_mm) - np.asarray(fm.offset_bits)) / fm.magnification


def _units_affine(fm: FieldMap) -> tuple[float, tuple[float, float]]:
    """(scale, offset) with mm = units * scale + offset."""
    s = fm.magnification * fm.mm_per_bit
    return s, (fm.offset_bits[0] * fm.mm_per_bit, fm.offset_bits[1] * fm.mm_per_bit)


def field_outline_mm(fm: FieldMap) -> np.ndarray:
    """The field boundary, bits 0 .. field_bits, as a closed (5, 2) ring in mm."""
    s = fm.field_bits * fm.mm_per_bit
    return np.array([[0.0, 0.0], [s, 0.0], [s, s], [0.0, s], [0.0, 0.0]])


def bbox(xy: np.ndarray) -> tuple[float, float, float, float] | None:
    """(xmin, ymin, xmax, ymax) of the finite rows of ``xy``, None when there are none.

    One compiled pass without the interpreter lock (numpy's ``min`` over the million rows of
    a big job held it 0.1-0.2 s on the worker: a stall of the GUI thread)."""
    a = np.asarray(xy).reshape(-1, 2)
    if a.dtype.kind in "iu":  # galvo bits: always finite
        a = np.ascontiguousarray(a, dtype=np.int64)
        if not len(a):
            return None
        box = _bbox_int(a)
    else:
        box = _bbox_finite(np.ascontiguousarray(a, dtype=np.float64))
    if not box[0] <= box[2]:
        return None
    return float(box[0]), float(box[1]), float(box[2]), float(box[3])


@njit(cache=True, nogil=True)
def _bbox_finite(a: np.ndarray) -> np.ndarray:  # pragma: no cover - jit
    """[xmin, ymin, xmax, ymax] of the rows of ``a`` with both coordinates finite
    (xmin > xmax when there are none)."""
    out = np.array([np.inf, np.inf, -np.inf, -np.inf])
    for i in range(a.shape[0]):
        x = a[i, 0]
        y = a[i, 1]
        if np.isfinite(x) and np.isfinite(y):
            if x < out[0]:
                out[0] = x
            if x > out[2]:
                out[2] = x
            if y < out[1]:
                out[1] = y
            if y > out[3]:
                out[3] = y
    return out


@njit(cache=True, nogil=True)
def _bbox_int(a: np.ndarray) -> np.ndarray:  # pragma: no cover - jit
    """[xmin, ymin, xmax, ymax] of the (N >= 1, 2) integer rows ``a``."""
    x0 = x1 = a[0, 0]
    y0 = y1 = a[0, 1]
    for i in range(1, a.shape[0]):
        x = a[i, 0]
        y = a[i, 1]
        if x < x0:
            x0 = x
        elif x > x1:
            x1 = x
        if y < y0:
            y0 = y
        elif y > y1:
            y1 = y
    return np.array([float(x0), float(y0), float(x1), float(y1)])


# ------------------------------------------------------------------ drawing (original)
def original_polylines(drawing: Drawing) -> Polylines:
    """Every path of the drawing as given by the file (input units), ids = path index."""
    return nan_join((p.points for p in drawing.paths), range(len(drawing.paths)))


# ------------------------------------------------------------------ fitted geometry
def flatten_segments(segments: Sequence[tuple[str, np.ndarray]] | Segments, tol: float
                     ) -> np.ndarray:
    """One continuous polyline through ``(kind, points)`` segments ("line": (2, 2),
    "cubic": (4, 2)): every cubic flattened within ``tol`` (units of the points), lines as
    their end points. Consecutive segments share their joint (it appears once)."""
    if not segments:
        return EMPTY
    chunks = [np.asarray(segments[0][1], dtype=np.float64)[:1]]
    for kind, pts in segments:
        p = np.asarray(pts, dtype=np.float64)
        if kind == "cubic" and p.shape == (4, 2):
            chunks.append(flatten_cubic(p, tol)[1:])
        else:
            chunks.append(p[-1:])
    return np.concatenate(chunks)


def _joined_segments(items: Sequence[tuple[np.ndarray, np.ndarray]]
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(ctrl, nseg, is_cubic)`` of paths given as ``(is_cubic, points)`` arrays (the
    shared-points form of :class:`FittedPath` and :class:`Segments`, each with at least one
    segment): ``ctrl`` (S, 4, 2) every segment's control points, a line as the cubic with
    its inner points at thirds (the same straight line: B(t) = P0 + t (P3 - P0)); ``nseg``
    (P,) the segments of each path; ``is_cubic`` (S,). No Python work per segment."""
    kinds = [k for k, _ in items]
    nseg = np.fromiter(map(len, kinds), dtype=np.int64, count=len(items))
    is_cubic = np.concatenate(kinds).astype(bool)
    allc = np.asarray(np.concatenate([pt for _, pt in items]), dtype=np.float64)
    step = np.where(is_cubic, 3, 1)
    # a path's points: its start, then 1 per line and 3 per cubic; so segment j's first
    # control point is at (the steps before it) + (one start point per path up to its own)
    path_of = np.repeat(np.arange(len(nseg)), nseg)
    o = np.cumsum(step) - step + path_of
    # one compiled pass without the interpreter lock (numpy's masked gathers over a million
    # segments held it 0.1-0.2 s each while a big job file loaded: GUI-thread stalls)
    ctrl = np.empty((len(is_cubic), 4, 2))
    _gather_ctrl(np.ascontiguousarray(allc), o.astype(np.int64), is_cubic, ctrl)
    return ctrl, nseg, is_cubic


@njit(cache=True, nogil=True)
def _gather_ctrl(allc: np.ndarray, o: np.ndarray, is_cubic: np.ndarray,
                 ctrl: np.ndarray) -> None:  # pragma: no cover - jit
    """``ctrl[j]`` = the 4 control points of segment j, whose first point is ``allc[o[j]]``:
    a cubic's 4 points, a line's ends with its inner points at thirds."""
    for j in range(len(o)):
        b = o[j]
        if is_cubic[j]:
            for k in range(4):
                ctrl[j, k, 0] = allc[b + k, 0]
                ctrl[j, k, 1] = allc[b + k, 1]
        else:
            for a in range(2):
                p0 = allc[b, a]
                p3 = allc[b + 1, a]
                d = p3 - p0
                ctrl[j, 0, a] = p0
                ctrl[j, 1, a] = p0 + d / 3.0
                ctrl[j, 2, a] = p0 + 2.0 * d / 3.0
                ctrl[j, 3, a] = p3


@dataclass(frozen=True, eq=False)
class FitArrays:
    """A fit's paths with segments, joined once (what the curve, the control points and
    the deviation overlay all read; cached per fit by :func:`build_preview`): ``index``
    the positions in the fit of the paths with segments, then :func:`_joined_segments`
    (``ctrl``, ``nseg``, ``is_cubic``) and every segment's input range (``first``,
    ``last``)."""

    index: np.ndarray
    ctrl: np.ndarray
    nseg: np.ndarray
    is_cubic: np.ndarray
    first: np.ndarray
    last: np.ndarray


def fit_arrays(fitted: Sequence[FittedPath]) -> FitArrays | None:
    """:class:`FitArrays` of ``fitted``, None when no path has a segment."""
    index = np.asarray([i for i, fp in enumerate(fitted) if len(fp.is_cubic)],
                       dtype=np.int64)
    if not len(index):
        return None
    fps = [fitted[i] for i in index]
    ctrl, nseg, is_cubic = _joined_segments([(fp.is_cubic, fp.points) for fp in fps])
    first = np.concatenate([fp.first for fp in fps]).astype(np.int64)
    last = np.concatenate([fp.last for fp in fps]).astype(np.int64)
    return FitArrays(index, ctrl, nseg, is_cubic, first, last)


@njit(cache=True, nogil=True)
def _flatten_kernel(ctrl: np.ndarray, n: np.ndarray, row0: np.ndarray,
                    out: np.ndarray) -> None:  # pragma: no cover - jit
    """Segment ``s``: its points at t = j / n[s], j = 1 .. n[s] (Bernstein form: t = 1 is
    P3 exactly) into ``out[row0[s] ..]``."""
    for s in range(ctrl.shape[0]):
        k = n[s]
        r = row0[s]
        for j in range(1, k + 1):
            t = j / k
            u = 1.0 - t
            b0 = u * u * u
            b1 = 3.0 * u * u * t
            b2 = 3.0 * u * t * t
            b3 = t * t * t
            out[r + j - 1, 0] = (b0 * ctrl[s, 0, 0] + b1 * ctrl[s, 1, 0] + b2 * ctrl[s, 2, 0]
                                 + b3 * ctrl[s, 3, 0])
            out[r + j - 1, 1] = (b0 * ctrl[s, 0, 1] + b1 * ctrl[s, 1, 1] + b2 * ctrl[s, 2, 1]
                                 + b3 * ctrl[s, 3, 1])


@njit(cache=True, nogil=True)
def _flatten_steps(ctrl: np.ndarray, is_cubic: np.ndarray, tol: float
                   ) -> np.ndarray:  # pragma: no cover - jit
    """Each segment's uniform steps, as :func:`galvo_core.geometry.flatten_cubic` counts
    them (|B''| <= 6 max|P_i - 2 P_(i+1) + P_(i+2)|, chord error <= |B''| h^2 / 8 <= tol);
    a line 1. Compiled without the interpreter lock (a million segments: the GUI thread
    runs meanwhile)."""
    out = np.ones(ctrl.shape[0], dtype=np.int64)
    for s in range(ctrl.shape[0]):
        if not is_cubic[s]:
            continue
        ax = ctrl[s, 2, 0] - 2.0 * ctrl[s, 1, 0] + ctrl[s, 0, 0]
        ay = ctrl[s, 2, 1] - 2.0 * ctrl[s, 1, 1] + ctrl[s, 0, 1]
        bx = ctrl[s, 3, 0] - 2.0 * ctrl[s, 2, 0] + ctrl[s, 1, 0]
        by = ctrl[s, 3, 1] - 2.0 * ctrl[s, 2, 1] + ctrl[s, 1, 1]
        m = 6.0 * max(np.hypot(ax, ay), np.hypot(bx, by))
        if m > 0.0:
            k = np.ceil(np.sqrt(m / (8.0 * tol)))
            if np.isfinite(k):
                out[s] = int(min(max(k, 1.0), 1_000_000.0))
    return out


def flatten_many(items: Sequence[tuple[np.ndarray, np.ndarray]], labels: Sequence[int],
                 tol: float) -> Polylines:
    """:func:`flatten_segments` of many paths at once, NaN-joined (:func:`nan_join`):
    ``items`` the paths as ``(is_cubic, points)`` arrays, ``labels`` their ids. Each cubic
    gets the uniform steps of :func:`galvo_core.geometry.flatten_cubic` (within ``tol``), a
    line its end point; vectorised, the points evaluated by one compiled call."""
    keep = [i for i, (k, _) in enumerate(items) if len(k)]
    if not keep:
        return Polylines()
    lab = np.asarray([labels[i] for i in keep], dtype=np.int64)
    ctrl, nseg, is_cubic = _joined_segments([items[i] for i in keep])
    return _flatten_joined(ctrl, nseg, is_cubic, lab, tol)


def _flatten_joined(ctrl: np.ndarray, nseg: np.ndarray, is_cubic: np.ndarray,
                    lab: np.ndarray, tol: float) -> Polylines:
    """:func:`flatten_many` of joined segments (:func:`_joined_segments`), ``lab`` the
    paths' ids."""
    ctrl = np.ascontiguousarray(ctrl)
    n = _flatten_steps(ctrl, np.ascontiguousarray(is_cubic), float(tol))
    # rows per path: its start point and every segment's points after the start
    seg_csum = np.cumsum(n)
    path_end_seg = np.cumsum(nseg) - 1
    rows = 1 + np.diff(np.concatenate(([0], seg_csum[path_end_seg])))
    pstart = np.concatenate(([0], np.cumsum(rows + 1)[:-1]))  # +1: the NaN row after each
    total = int(rows.sum()) + len(rows) - 1
    xy = np.full((total, 2), np.nan)
    first_seg = path_end_seg - nseg + 1
    xy[pstart] = ctrl[first_seg, 0]
    before = seg_csum - n - np.repeat(seg_csum[first_seg] - n[first_seg], nseg)
    row0 = np.repeat(pstart + 1, nseg) + before
    _flatten_kernel(ctrl, n, row0, xy)
    # ids: each path's label over its rows, -1 on the NaN row after it (one repeat)
    vals = np.full(2 * len(rows) - 1, -1, dtype=np.int64)
    vals[0::2] = lab
    reps = np.ones(2 * len(rows) - 1, dtype=np.int64)
    reps[0::2] = rows
    return Polylines(xy, np.repeat(vals, reps))


def fitted_curve(fitted: Sequence[FittedPath], tol: float,
                 arrays: FitArrays | None = None) -> Polylines:
    """The fitted lines and cubics of every path as polylines (input units, cubics within
    ``tol``), ids = source_index. ``arrays``: the fit's :func:`fit_arrays`, when kept."""
    fa = arrays if arrays is not None else fit_arrays(fitted)
    if fa is None:
        return Polylines()
    lab = np.fromiter((fitted[i].source_index for i in fa.index), dtype=np.int64,
                      count=len(fa.index))
    return _flatten_joined(fa.ctrl, fa.nseg, fa.is_cubic, lab, tol)


def control_geometry(fitted: Sequence[FittedPath]) -> tuple[Polylines, np.ndarray, np.ndarray]:
    """Control points of the fit (input units).

    Returns ``(handles, anchors, knots)``: ``handles`` the handle lines of every cubic
    (P0–P1 and P2–P3, NaN-separated pairs, ids = source_index); ``anchors`` (K, 2) the end
    points of every segment (each joint once); ``knots`` (L, 2) the inner control points
    P1, P2 of the cubics.
    """
    pairs: list[np.ndarray] = []
    pair_ids: list[int] = []
    anchors: list[np.ndarray] = []
    knots: list[np.ndarray] = []
    for fp in fitted:
        if not fp.segments:
            continue
        anchors.append(fp.segments[0].points[:1])
        for s in fp.segments:
            anchors.append(s.points[-1:])
            if s.kind == "cubic":
                pairs.extend((s.points[0:2], s.points[2:4]))
                pair_ids.extend((fp.source_index, fp.source_index))
                knots.append(s.points[1:3])
    return (
        nan_join(pairs, pair_ids),
        np.concatenate(anchors) if anchors else EMPTY,
        np.concatenate(knots) if knots else EMPTY,
    )


def _piece_indices(first: int, last: int, n: int, closed: bool) -> np.ndarray:
    idx = np.arange(first, last + 1)
    if closed and n:
        return idx % n
    return idx[(idx >= 0) & (idx < n)]


@njit(cache=True, nogil=True)
def _deviation_kernel(src: np.ndarray, off: np.ndarray, npts: np.ndarray, closed: np.ndarray,
                      ctrl: np.ndarray, first: np.ndarray, last: np.ndarray, ks: np.ndarray,
                      starts: np.ndarray, a_out: np.ndarray, b_out: np.ndarray,
                      e_out: np.ndarray) -> None:  # pragma: no cover - jit
    """Segment ``j``: ``ks[j]`` samples (Bernstein form, uniform parameters), each sample's
    distance to the source points ``first .. last`` of its path (the path's points are
    ``src[off[j] : off[j] + npts[j]]``; indices modulo ``npts`` when ``closed``); chords
    ``starts[j] ..`` of the outputs."""
    for j in range(ctrl.shape[0]):
        k = ks[j]
        if k == 0:
            continue
        n = npts[j]
        o = off[j]
        p0x, p0y = ctrl[j, 0, 0], ctrl[j, 0, 1]
        p1x, p1y = ctrl[j, 1, 0], ctrl[j, 1, 1]
        p2x, p2y = ctrl[j, 2, 0], ctrl[j, 2, 1]
        p3x, p3y = ctrl[j, 3, 0], ctrl[j, 3, 1]
        lo = first[j]
        hi = last[j]
        if not closed[j]:
            lo = max(lo, 0)
            hi = min(hi, n - 1)
        prev_x = 0.0
        prev_y = 0.0
        prev_e = 0.0
        for i in range(k):
            t = i / (k - 1)
            u = 1.0 - t
            x = u * u * u * p0x + 3.0 * u * u * t * p1x + 3.0 * u * t * t * p2x + t * t * t * p3x
            y = u * u * u * p0y + 3.0 * u * u * t * p1y + 3.0 * u * t * t * p2y + t * t * t * p3y
            best = np.inf
            qx = src[o + lo % n, 0]
            qy = src[o + lo % n, 1]
            if hi == lo:
                best = (x - qx) ** 2 + (y - qy) ** 2
            for m in range(lo + 1, hi + 1):
                rx = src[o + m % n, 0]
                ry = src[o + m % n, 1]
                vx = rx - qx
                vy = ry - qy
                den = vx * vx + vy * vy
                dx = x - qx
                dy = y - qy
                s = 0.0
                if den > 0.0:
                    s = (dx * vx + dy * vy) / den
                    s = min(max(s, 0.0), 1.0)
                ex = dx - s * vx
                ey = dy - s * vy
                d = ex * ex + ey * ey
                if d < best:
                    best = d
                qx = rx
                qy = ry
            e = np.sqrt(best)
            if i > 0:
                r = starts[j] + i - 1
                a_out[r, 0] = prev_x
                a_out[r, 1] = prev_y
                b_out[r, 0] = x
                b_out[r, 1] = y
                e_out[r] = max(prev_e, e)
            prev_x = x
            prev_y = y
            prev_e = e


def drawing_points(drawing: Drawing) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All points of the drawing's paths in one (N, 2) float64 array, each path's point
    count and its first row (what :func:`deviation_samples` reads; one per drawing)."""
    pts = [p.points for p in drawing.paths]
    n = np.fromiter(map(len, pts), dtype=np.int64, count=len(pts))
    src = np.ascontiguousarray(np.concatenate(pts), dtype=np.float64).reshape(-1, 2) \
        if len(pts) else EMPTY
    return src, n, np.cumsum(n) - n


def deviation_samples(
    drawing: Drawing,
    fitted: Sequence[FittedPath],
    *,
    min_samples: int = 4,
    max_samples: int = 64,
    cancel: Callable[[], bool] | None = None,
    points: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    arrays: FitArrays | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The true error of the fit, sample by sample along the curve.

    Every fitted segment is sampled at ``k`` parameters (``2 × its input points``, clipped to
    ``min_samples .. max_samples``); each sample's error is its Euclidean distance to the
    input polyline that the segment replaces (the points ``first .. last`` of the source
    path). Returns ``(a, b, err)``: the sample chords as start points ``a`` (K, 2) and end
    points ``b`` (K, 2) in input units, and ``err`` (K,) the larger error of the chord's two
    ends, in input units. Segments whose source points are unknown are skipped.

    Compiled (numba), one call for the whole drawing: a loop over samples and the source
    points each segment replaces, so the work is about ``max_samples`` × the input points
    at most; Python only gathers each segment's control points once. ``points``: the
    drawing's :func:`drawing_points` when the caller keeps them (they do not change);
    ``arrays`` the fit's :func:`fit_arrays` likewise.
    """
    if cancel is not None and cancel():
        raise Cancelled()
    if points is None:
        points = drawing_points(drawing)
    src, all_len, all_off = points
    si = np.fromiter((fp.source_index for fp in fitted), dtype=np.int64, count=len(fitted))
    ns = np.fromiter((len(fp.is_cubic) for fp in fitted), dtype=np.int64, count=len(fitted))
    ok = (si >= 0) & (si < len(all_len)) & (ns > 0)
    ok[ok] &= all_len[si[ok]] > 0
    keep = np.flatnonzero(ok)
    if not len(keep):
        return EMPTY, EMPTY, np.empty(0)
    fps = [fitted[i] for i in keep.tolist()]
    plen, poff = all_len[si[keep]], all_off[si[keep]]
    # the fits' arrays, joined: segment kinds, input ranges, control points
    if arrays is None or not np.array_equal(arrays.index, keep):
        arrays = fit_arrays(fps)
        assert arrays is not None
    ctrl, nseg, first, last = arrays.ctrl, arrays.nseg, arrays.first, arrays.last
    if cancel is not None and cancel():
        raise Cancelled()
    off = np.repeat(poff, nseg)
    npts = np.repeat(plen, nseg)
    closed = np.repeat(np.fromiter((bool(fp.closed) for fp in fps), dtype=bool,
                                   count=len(fps)), nseg)
    count = np.where(closed, np.maximum(last - first + 1, 0),
                     np.maximum(np.minimum(last, npts - 1) - np.maximum(first, 0) + 1, 0))
    ks = np.where(count > 0, np.clip(2 * count, min_samples, max_samples), 0)
    chords = np.maximum(ks - 1, 0)
    total = int(chords.sum())
    if not total:
        return EMPTY, EMPTY, np.empty(0)
    starts = np.concatenate(([0], np.cumsum(chords)[:-1]))
    a = np.empty((total, 2))
    b = np.empty((total, 2))
    e = np.empty(total)
    _deviation_kernel(src, off, npts, closed, ctrl, first, last, ks, starts, a, b, e)
    return a, b, e


# ------------------------------------------------------------------ job geometry
def stroke_curves(job: Job, tol: float, kinds: Iterable[str] = ("contour",)) -> Polylines:
    """The fitted segments stored in the job's strokes of ``kinds`` (input units), flattened
    within ``tol``; ids = source_index. Strokes without segments contribute nothing."""
    want = set(kinds)
    strokes = [s for s in job.strokes if s.kind in want and s.segments]
    return flatten_many([(s.segments.is_cubic, s.segments.points) for s in strokes],
                        [s.source_index for s in strokes], tol)


def _all_marks(strokes: Sequence[Any]) -> tuple[np.ndarray, np.ndarray]:
    """Every mark of ``strokes`` in order as one (M, 2) int64 array, and each stroke's mark
    count (one concatenation, no Python work per mark; a job's strokes tuple is joined once:
    :func:`galvo_core.timing.joined_marks`)."""
    j = joined_marks(strokes)
    return j.marks, j.lens


def mark_points(job: Job, kinds: Iterable[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Every mark of the job's strokes (of ``kinds``; all when None) in marking order:
    ``(bits (M, 2) int64, ids (M,) source_index)``."""
    want = None if kinds is None else set(kinds)
    strokes = [s for s in job.strokes if want is None or s.kind in want]
    if not strokes:
        return np.empty((0, 2), dtype=np.int64), _NO_IDS
    marks, lens = _all_marks(strokes)
    src = np.fromiter((s.source_index for s in strokes), dtype=np.int64, count=len(strokes))
    return marks, np.repeat(src, lens)


def jump_segments(job: Job) -> np.ndarray:
    """The laser-off moves between consecutive strokes (last mark -> next first mark) as
    NaN-separated pairs, galvo bits (float)."""
    return _jumps_from(*_all_marks(job.strokes))


def _jumps_from(marks: np.ndarray, lens: np.ndarray) -> np.ndarray:
    lens = lens[lens > 0]
    if len(lens) < 2:
        return EMPTY
    ends = np.cumsum(lens)
    firsts = marks[ends - lens].astype(np.float64)
    lasts = marks[ends - 1].astype(np.float64)
    starts, stops = firsts[1:], lasts[:-1]
    moving = (starts != stops).any(axis=1)
    starts, stops = starts[moving], stops[moving]
    out = np.full((3 * len(starts), 2), np.nan)
    out[0::3] = stops
    out[1::3] = starts
    return out[:-1] if len(out) else EMPTY


def hatch_polylines(job: Job) -> Polylines:
    """The marks of the job's hatch strokes as polylines (galvo bits), ids = source_index."""
    if not joined_marks(job.strokes).hatch.any():
        return Polylines()
    strokes = [s for s in job.strokes if s.kind == "hatch"]
    return nan_join((np.asarray(s.marks, dtype=np.float64) for s in strokes),
                    (s.source_index for s in strokes))


# ------------------------------------------------------------------ picking
def nearest_id(xy: np.ndarray, ids: np.ndarray, point: Sequence[float],
               max_dist: float = np.inf) -> int | None:
    """The id of the row of ``xy`` nearest to ``point`` (rows with id < 0 or NaN ignored),
    None when there is none within ``max_dist``."""
    if not len(ids):
        return None
    d = np.hypot(xy[:, 0] - point[0], xy[:, 1] - point[1])
    d = np.where((ids >= 0) & np.isfinite(d), d, np.inf)
    i = int(np.argmin(d))
    if not np.isfinite(d[i]) or d[i] > max_dist:
        return None
    return int(ids[i])


def path_for_position(drawing: Drawing, line: int, col: int) -> int | None:
    """The path whose start in the file is nearest to (line, col): fewest lines away, then
    fewest columns; ties go to the earlier path. None for a drawing without paths or without
    source positions."""
    best: tuple[tuple[int, int], int] | None = None
    for i, p in enumerate(drawing.paths):
        s = p.start
        if (s.line, s.col) == (0, 0):
            continue
        key = (abs(s.line - line), abs(s.col - col))
        if best is None or key < best[0]:
            best = (key, i)
    return best[1] if best is not None else None


# ------------------------------------------------------------------ the whole preview
def control_layer(fitted: Sequence[FittedPath], arrays: FitArrays | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The control points and handle lines as ONE NaN-separated array for one plot item.

    Returns ``(xy, role)``: rows ``P0, P1, NaN, P2, P3, NaN`` per cubic (the handle lines)
    followed by every anchor (segment end point, each joint once) as a single row followed
    by NaN. ``role`` per row: 1 = anchor (draw a marker), 2 = inner control point P1/P2
    (draw a marker), 0 = an anchor end of a handle line (no marker: the anchor is drawn once
    from the anchor rows), -1 = NaN separator.
    """
    fa = arrays if arrays is not None else fit_arrays(fitted)
    if fa is None:
        return EMPTY, np.empty(0, dtype=np.int8)
    ctrl, nseg, is_cubic = fa.ctrl, fa.nseg, fa.is_cubic
    cub = ctrl[is_cubic]
    nh = 6 * len(cub) - 1  # P0, P1, NaN, P2, P3, NaN per cubic, without the last NaN
    hx = np.full((max(nh, 0), 2), np.nan)
    h_role = np.full(max(nh, 0), -1, dtype=np.int8)
    if len(cub):
        for r, (k, hr) in enumerate(((0, 0), (1, 2), (2, 2), (3, 0))):
            rows = np.arange(len(cub)) * 6 + (r if r < 2 else r + 1)
            hx[rows] = cub[:, k]
            h_role[rows] = hr
    # anchors: each path's start, then every segment's end (each joint once)
    last_seg = np.cumsum(nseg) - 1
    starts = ctrl[last_seg - nseg + 1, 0]
    pos = np.arange(len(ctrl)) + np.repeat(np.arange(len(nseg)), nseg) + 1
    anchors = np.empty((len(ctrl) + len(nseg), 2))
    anchors[pos] = ctrl[:, 3]
    anchors[np.concatenate(([0], (last_seg + np.arange(len(nseg)) + 2)[:-1]))] = starts
    a = np.full((2 * len(anchors), 2), np.nan)
    a[0::2] = anchors
    a_role = np.full(len(a), -1, dtype=np.int8)
    a_role[0::2] = 1
    if not len(hx):
        return a, a_role
    xy = np.concatenate((hx, np.full((1, 2), np.nan), a))
    role = np.concatenate((h_role, np.array([-1], dtype=np.int8), a_role))
    return xy, role


@dataclass(frozen=True, eq=False)
class Preview:
    """Everything the two views draw.

    Each layer is given in its *native* space, so a run that changed only the magnification
    or offset hands the GUI the very same arrays again (cached) and the GUI only changes the
    affine map to workpiece mm:

    * input units (``original``, ``fitted``, ``control_xy``, ``kerf``, ``deviation_*``):
      ``mm = units * units_scale + units_offset``;
    * galvo bits (``marks``, ``jumps``, ``hatch``): ``mm = bits * mm_per_bit``;
    * ``field_outline`` and ``bounds`` are already in mm.

    ``deviation_level`` is each deviation chord's error as a fraction of the fit tolerance
    (``max(e_per, eps_line)`` beyond the file's rounding, ``+ q/√2``), clipped to 0..1 (the
    colour); ``deviation_err`` the error in
    input units; ``um_per_unit`` converts it to µm on the workpiece.
    """

    field_map: FieldMap
    units_scale: float
    units_offset: tuple[float, float]
    mm_per_bit: float
    field_outline: np.ndarray
    original: Polylines
    original_points: np.ndarray
    original_point_ids: np.ndarray
    fitted: Polylines
    control_xy: np.ndarray
    control_role: np.ndarray
    marks: np.ndarray
    mark_ids: np.ndarray
    jumps: np.ndarray
    hatch: Polylines
    kerf: Polylines
    deviation_a: np.ndarray
    deviation_b: np.ndarray
    deviation_err: np.ndarray
    deviation_level: np.ndarray
    tolerance_units: float
    #: bounding box (mm) of everything drawn, None when nothing is
    bounds: tuple[float, float, float, float] | None
    #: the optional layers computed ("control", "deviation"); None: all of them
    layers: frozenset[str] | None = None

    def has_layer(self, key: str) -> bool:
        """True when this preview holds the geometry of layer ``key`` (computed)."""
        return self.layers is None or key not in OPTIONAL_LAYERS or key in self.layers

    @property
    def um_per_unit(self) -> float:
        return self.units_scale * 1000.0

    @property
    def tolerance_um(self) -> float:
        return self.tolerance_units * self.um_per_unit

    @property
    def max_deviation_um(self) -> float:
        if not len(self.deviation_err):
            return 0.0
        return float(self.deviation_err.max()) * self.um_per_unit

    @property
    def n_control_points(self) -> int:
        return int(np.count_nonzero(self.control_role > 0))

    def units_to_mm(self, xy: np.ndarray) -> np.ndarray:
        return np.asarray(xy, dtype=np.float64) * self.units_scale + np.asarray(
            self.units_offset)

    def mm_to_units(self, xy_mm: np.ndarray) -> np.ndarray:
        return (np.asarray(xy_mm, dtype=np.float64) - np.asarray(self.units_offset)
                ) / self.units_scale

    def mm_to_bits(self, xy_mm: np.ndarray) -> np.ndarray:
        return np.asarray(xy_mm, dtype=np.float64) / self.mm_per_bit

    def pick(self, x_mm: float, y_mm: float, radius_mm: float) -> int | None:
        """The source path nearest to (x, y) mm within ``radius_mm``: by the original points
        and the fitted curve, or by the marks when there is no drawing; None if none."""
        best: tuple[float, int] | None = None
        candidates = (
            (self.original.xy, self.original.ids, "units"),
            (self.fitted.xy, self.fitted.ids, "units"),
            (self.marks, self.mark_ids, "bits"),
        )
        for xy, ids, space in candidates:
            if not len(ids):
                continue
            if space == "units":
                p = self.mm_to_units(np.array([[x_mm, y_mm]]))[0]
                r = radius_mm / self.units_scale
                scale = self.units_scale
            else:
                p = self.mm_to_bits(np.array([[x_mm, y_mm]]))[0]
                r = radius_mm / self.mm_per_bit
                scale = self.mm_per_bit
            d = np.hypot(xy[:, 0] - p[0], xy[:, 1] - p[1])
            d = np.where((ids >= 0) & np.isfinite(d), d, np.inf)
            i = int(np.argmin(d))
            if d[i] <= r and (best is None or d[i] * scale < best[0]):
                best = (float(d[i]) * scale, int(ids[i]))
        return best[1] if best is not None else None

    def path_geometry(self, index: int) -> tuple[np.ndarray, np.ndarray]:
        """The selection highlight of path ``index``: (original polyline in units,
        processed polyline in units — the fitted curve, else the marks mapped to units)."""
        left = self.original.select(index)
        right = self.fitted.select(index)
        if not len(right) and len(self.mark_ids):
            m = self.marks[self.mark_ids == index]
            right = self.mm_to_units(m * self.mm_per_bit) if len(m) else EMPTY
        return left, right

    def path_bounds(self, index: int) -> tuple[float, float, float, float] | None:
        """Bounding box (mm) of path ``index`` in either view, None when it draws nothing."""
        left, right = self.path_geometry(index)
        b = _union(bbox(left), bbox(right))
        return _affine_box(b, self.units_scale, self.units_offset)


class PreviewCache:
    """Fit-only geometry (input units) by the identity of the objects it came from (a small
    LRU; each value holds those objects, so an id cannot be reused while cached)."""

    def __init__(self, size: int = 12) -> None:
        # one run's entries: bbox, original, points, fit arrays, curve, control, deviation,
        # level
        self.size = size
        self._data: OrderedDict[tuple[Any, ...], tuple[Any, ...]] = OrderedDict()

    def get(self, key: tuple[Any, ...], make: Callable[[], tuple[Any, ...]]) -> tuple[Any, ...]:
        if key in self._data:
            self._data.move_to_end(key)
            return self._data[key]
        value = make()
        self._data[key] = value
        while len(self._data) > self.size:
            self._data.popitem(last=False)
        return value


def _union(*boxes: tuple[float, float, float, float] | None
           ) -> tuple[float, float, float, float] | None:
    bs = [b for b in boxes if b is not None]
    if not bs:
        return None
    return (min(b[0] for b in bs), min(b[1] for b in bs), max(b[2] for b in bs),
            max(b[3] for b in bs))


def _affine_box(b: tuple[float, float, float, float] | None, scale: float,
                off: tuple[float, float]) -> tuple[float, float, float, float] | None:
    if b is None:
        return None
    return (b[0] * scale + off[0], b[1] * scale + off[1], b[2] * scale + off[0],
            b[3] * scale + off[1])


def display_tolerance(job_params: dict[str, Any], drawing: Drawing | None,
                      bbox: tuple[float, float, float, float] | None = None) -> float:
    """How closely flattened cubics follow the fit for display, in input units: a quarter of
    the fit tolerance (so the deviation shown is the fit's, not the flattening's), but not
    finer than a millionth of the drawing's diagonal (``bbox``: the drawing's, when the
    caller has it)."""
    e = [float(job_params.get(k, 0.0) or 0.0) for k in ("e_per", "eps_line")]
    e = [v for v in e if v > 0] or [0.02]
    tol = min(e) / 4.0
    bb = bbox if bbox is not None else drawing.bbox() if drawing is not None else None
    if bb is not None:
        tol = max(tol, float(np.hypot(bb[2] - bb[0], bb[3] - bb[1])) * 1e-6)
    return tol


def _optional_layers(drawing: Drawing | None, fit_tuple: tuple[FittedPath, ...],
                     cache: PreviewCache, cancel: Callable[[], bool] | None, e_tol: float,
                     control: bool, deviation: bool) -> tuple[np.ndarray, ...]:
    """``(control_xy, control_role, dev_a, dev_b, dev_err, dev_level)`` of a fit: the
    control points when ``control``, the deviation overlay when ``deviation`` (and there is
    a drawing), empty arrays otherwise; cached by the fit's identity."""
    def fa() -> FitArrays | None:
        return cache.get(("fit arrays", id(fit_tuple)),
                         lambda: (fit_tuple, fit_arrays(fit_tuple)))[1]

    if control:
        _, c_xy, c_role = cache.get(("control", id(fit_tuple)),
                                    lambda: (fit_tuple, *control_layer(fit_tuple, fa())))
    else:
        c_xy, c_role = EMPTY, np.empty(0, dtype=np.int8)
    if deviation and drawing is not None:
        def make_dev() -> tuple[Any, ...]:
            pts = cache.get(("points", id(drawing)),
                            lambda: (drawing, drawing_points(drawing)))[1]
            return (fit_tuple, drawing, *deviation_samples(drawing, fit_tuple, cancel=cancel,
                                                           points=pts, arrays=fa()))

        _, _, dev_a, dev_b, dev_e = cache.get(("deviation", id(fit_tuple), id(drawing)),
                                              make_dev)
        (_, dev_level) = cache.get(
            ("level", id(dev_e), e_tol),
            lambda: (dev_e, np.clip(dev_e / e_tol, 0.0, 1.0) if e_tol > 0 else dev_e * 0.0))
    else:
        dev_a, dev_b, dev_e, dev_level = EMPTY, EMPTY, np.empty(0), np.empty(0)
    return c_xy, c_role, dev_a, dev_b, dev_e, dev_level


def with_layers(pv: Preview, drawing: Drawing | None,
                fitted: tuple[FittedPath, ...] | None, layers: Iterable[str], *,
                cache: PreviewCache | None = None,
                cancel: Callable[[], bool] | None = None) -> Preview:
    """``pv`` (a preview of ``fitted`` and ``drawing``) with the optional layers of
    ``layers`` it lacks computed; every other array is ``pv``'s own (the same objects, so
    the views redraw only the new layers). A layer switched on after the run."""
    if fitted is None or pv.layers is None:
        return pv
    want = frozenset(layers) & OPTIONAL_LAYERS
    missing = want - pv.layers
    if not missing:
        return pv
    c_xy, c_role, dev_a, dev_b, dev_e, dev_level = _optional_layers(
        drawing, fitted, cache if cache is not None else PreviewCache(), cancel,
        pv.tolerance_units, "control" in missing, "deviation" in missing)
    changes: dict[str, Any] = {"layers": frozenset(pv.layers | missing)}
    if "control" in missing:
        changes.update(control_xy=c_xy, control_role=c_role)
    if "deviation" in missing:
        changes.update(deviation_a=dev_a, deviation_b=dev_b, deviation_err=dev_e,
                       deviation_level=dev_level)
    return replace(pv, **changes)


def build_preview(
    job: Job,
    drawing: Drawing | None = None,
    fitted: tuple[FittedPath, ...] | None = None,
    *,
    cache: PreviewCache | None = None,
    cancel: Callable[[], bool] | None = None,
    layers: Iterable[str] | None = None,
) -> Preview:
    """All display geometry of a run (or of a loaded job file: no drawing, no fit).

    ``layers`` (keys of the GUI's layers; None: all) limits the costly optional layers to
    those shown: the control points (``"control"``) and the deviation overlay
    (``"deviation"``) are left empty when not asked for. ``Preview.layers`` says which were.

    Without ``fitted`` the fitted-curve layer is taken from the job's contour strokes' stored
    segments (no control points, no deviation). The kerf layer shows the job's contour-stroke
    segments when the job's ``kerf_mm`` > 0, else nothing; the hatch layer the marks of its
    hatch strokes (nothing when there are none). Fit-only geometry is cached in ``cache`` by
    the identity of ``drawing`` and ``fitted``: a run that only re-sampled costs little.
    """
    fm = job.field_map
    scale, offset = _units_affine(fm)
    cache = cache if cache is not None else PreviewCache()
    # the fit's bound in effect from the input points (the tolerances beyond the paths'
    # rounding, in the job's stats); jobs without it: the tolerances beyond the file's grid
    e_tol = float(job.stats.get("fit_bound_units") or 0.0) or (
        max(float(job.params.get("e_per", 0.0) or 0.0),
            float(job.params.get("eps_line", 0.0) or 0.0))
        + float(job.params.get("quantum_units", 0.0) or 0.0) / math.sqrt(2.0))
    d_box = cache.get(("bbox", id(drawing)), lambda: (drawing, drawing.bbox()))[1] \
        if drawing is not None else None
    tol_units = display_tolerance(job.params, drawing, d_box)

    if drawing is not None:
        def make_original() -> tuple[Any, ...]:
            orig = original_polylines(drawing)
            finite = orig.ids >= 0
            return drawing, orig, orig.xy[finite], orig.ids[finite], bbox(orig.xy)

        _, original, o_pts, o_ids, o_box = cache.get(("original", id(drawing)), make_original)
    else:
        original, o_pts, o_ids, o_box = Polylines(), EMPTY, _NO_IDS, None

    want = None if layers is None else frozenset(layers)

    def shown(key: str) -> bool:
        return want is None or key in want

    if fitted is not None:
        fit_tuple = fitted
        key = (id(fit_tuple), id(drawing), round(tol_units, 12))

        def make_curve() -> tuple[Any, ...]:
            fa = cache.get(("fit arrays", id(fit_tuple)),
                           lambda: (fit_tuple, fit_arrays(fit_tuple)))[1]
            curve = fitted_curve(fit_tuple, tol_units, fa)
            return fit_tuple, drawing, curve, bbox(curve.xy)

        _, _, curve, c_box = cache.get(("curve", *key), make_curve)
        c_xy, c_role, dev_a, dev_b, dev_e, dev_level = _optional_layers(
            drawing, fit_tuple, cache, cancel, e_tol, shown("control"), shown("deviation"))
    else:
        curve = stroke_curves(job, tol_units)
        c_box = bbox(curve.xy)
        c_xy, c_role = EMPTY, np.empty(0, dtype=np.int8)
        dev_a, dev_b, dev_e, dev_level = EMPTY, EMPTY, np.empty(0), np.empty(0)

    # the kerf layer: the compensated outline the laser follows, which is the fitted curve
    # of the compensated drawing (the job's contour segments): the same arrays, drawn again
    kerf_on = float(job.params.get("kerf_mm", 0.0) or 0.0) > 0.0
    kerf = curve if kerf_on else Polylines()

    joined = joined_marks(job.strokes)  # once for the marks, the jumps and the stats
    marks_bits, lens = joined.marks, joined.lens
    mark_ids = np.repeat(joined.source, lens)
    marks = marks_bits.astype(np.float64)
    jumps = _jumps_from(marks_bits, lens)
    hatch = hatch_polylines(job)

    bounds = _union(_affine_box(_union(o_box, c_box, bbox(kerf.xy)), scale, offset),
                    _affine_box(_union(bbox(marks_bits), bbox(hatch.xy)), fm.mm_per_bit, (0, 0)))
    return Preview(
        field_map=fm,
        units_scale=scale,
        units_offset=offset,
        mm_per_bit=fm.mm_per_bit,
        field_outline=field_outline_mm(fm),
        original=original,
        original_points=o_pts,
        original_point_ids=o_ids,
        fitted=curve,
        control_xy=c_xy,
        control_role=c_role,
        marks=marks,
        mark_ids=mark_ids,
        jumps=jumps,
        hatch=hatch,
        kerf=kerf,
        deviation_a=dev_a,
        deviation_b=dev_b,
        deviation_err=dev_e,
        deviation_level=dev_level,
        tolerance_units=e_tol,
        bounds=bounds,
        layers=None if want is None else frozenset(want & OPTIONAL_LAYERS),
    )


def path_summary(index: int, job: Job | None, drawing: Drawing | None = None,
                 fitted: Sequence[FittedPath] | None = None) -> dict[str, Any]:
    """Counts of one source path (for the selection read-out): input points, lines, cubics,
    control points, largest fit error (µm), mark points, hatch marks, mark length (mm)."""
    from galvo_core.fit import control_points

    out: dict[str, Any] = {"path": index}
    if drawing is not None and 0 <= index < len(drawing.paths):
        p = drawing.paths[index]
        out["input_points"] = len(p.points)
        out["closed"] = bool(p.closed)
    fm = job.field_map if job is not None else None
    for fp in fitted or ():
        if fp.source_index == index:
            out["lines"] = fp.n_lines
            out["cubics"] = fp.n_cubics
            out["control_points"] = control_points(fp)
            if fm is not None:
                out["max_fit_error_um"] = fp.max_error * fm.mm_per_unit * 1000.0
    if job is not None and fm is not None:
        for s in job.strokes:
            if s.source_index != index:
                continue
            key = "hatch_marks" if s.kind == "hatch" else "mark_points"
            out[key] = out.get(key, 0) + len(s.marks)
            if s.kind != "hatch" and len(s.marks) > 1:
                step = np.diff(np.asarray(s.marks, dtype=np.float64), axis=0)
                out["mark_length_mm"] = out.get("mark_length_mm", 0.0) + float(
                    np.hypot(step[:, 0], step[:, 1]).sum() * fm.mm_per_bit)
    return out


def warning_path(drawing: Drawing | None, warning: Warning) -> int | None:
    """The path a warning points at (by its file position), None when it has none."""
    if drawing is None or not warning.line:
        return None
    return path_for_position(drawing, warning.line, warning.col)


def beam_timeline(job: Job) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The beam's path through the job in marking order, for a marking simulation.

    Returns ``(xy, t, on)``: ``xy`` (K, 2) the beam positions in galvo bits (the first mark
    of each stroke is reached by a jump, the others by marking moves), ``t`` (K,) the time
    in seconds at which the beam reaches each position, ``on`` (K,) True when the move *to*
    that position is marked (laser on). Moves take distance / speed (the mark and jump
    speeds of ``job.laser``), at least one point period, jumps add their delay and each
    stroke its laser on/off delays; the whole timeline is then scaled so that it ends at
    the job's ``estimated_time_s`` (when the job has one), the figure the window shows.
    """
    marks, lens = _all_marks(job.strokes)
    if not len(marks):
        return EMPTY, np.empty(0), np.empty(0, dtype=bool)
    lens = lens[lens > 0]
    laser = job.laser
    mpb = job.field_map.mm_per_bit
    xy = marks.astype(np.float64)
    step = np.zeros(len(xy))
    step[1:] = np.hypot(*np.diff(xy, axis=0).T) * mpb
    starts = np.concatenate(([0], np.cumsum(lens)[:-1]))
    on = np.ones(len(xy), dtype=bool)
    on[starts] = False  # each stroke's first mark is reached by a jump
    on[0] = False
    period = float(laser.get("point_period_us", 10.0)) * 1e-6
    mark_v = float(laser.get("mark_speed_mm_s", 100.0))
    jump_v = float(laser.get("jump_speed_mm_s", 2000.0))
    dt = np.where(on, np.maximum(step / mark_v, period), step / jump_v)
    long_mm = float(laser.get("long_jump_mm", 10.0))
    jd = np.where(step > long_mm, float(laser.get("jump_delay_long_us", 200.0)),
                  float(laser.get("jump_delay_us", 8.0))) * 1e-6
    dt = np.where(on, dt, dt + jd)
    dt[starts[1:]] += (float(laser.get("laser_off_delay_us", 100.0))
                       + float(laser.get("laser_on_delay_us", 100.0))) * 1e-6
    dt[0] = 0.0
    t = np.cumsum(dt)
    total = float(job.stats.get("estimated_time_s") or 0.0)
    if total > 0 and t[-1] > 0:
        t *= total / t[-1]
    return xy, t, on
