"""The galvo job file: build, write, load.

Two forms, chosen by the file name's extension (:func:`write_job`):

* **version 1**, UTF-8 JSON (``../shared/spec/job-format.md``), for any name but
  ``.gjob``: what tools that read JSON get (``-o JOB.json``);
* **version 2**, the compact binary form (``docs/job-format.md``) for ``*.gjob``: the same
  header as JSON, the big arrays (marks, segment kinds, control points, one row per stroke)
  as little-endian binary after it; about 9 bytes per mark instead of 75, written and read
  at memory speed.

:func:`load_job` reads both (by the file's first bytes, not its name).

A job holds its strokes as :class:`Stroke` objects whose geometry is arrays: ``marks``
(M, 2) int64 and ``segments`` a :class:`Segments` (segment kinds and the shared control
points, no object per segment). The v1 JSON is written in bulk (one formatting pass per
stroke over its numbers, the same bytes :func:`json.dumps` gives), not through one Python
object per number.

:func:`write_job` writes atomically (a temporary file in the same folder, flushed and
fsynced, then renamed over the target), so an interrupted write leaves the old file intact
and never a half-written one. :func:`load_job` validates what readers rely on and raises
:class:`~galvo_core.errors.InputError` naming the file and the place otherwise.
"""

from __future__ import annotations

import contextlib
import dataclasses
import gc
import json
import math
import os
import struct
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from dataclasses import field as dc_field
from operator import attrgetter
from typing import Any

import numpy as np

from galvo_core import __version__
from galvo_core.drawing import Warning
from galvo_core.errors import GalvoError, InputError, read_input_bytes
from galvo_core.field import FieldMap

FORMAT = "galvo-job"
VERSION = 1
#: the compact binary form (docs/job-format.md)
VERSION_COMPACT = 2
COMPACT_EXTENSIONS = (".gjob",)
#: first 8 bytes of a version 2 file
MAGIC = b"GALVOJOB"
GENERATOR = f"galvo-workstation {__version__}"

_KIND_NAMES = ("line", "cubic")
_WANT = {"line": 2, "cubic": 4}
_STROKE_KINDS = ("contour", "hatch")


def _read_only(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


@contextlib.contextmanager
def gc_paused() -> Any:
    """Python's cyclic garbage collector paused while a block builds many objects that hold
    no reference cycles (strokes, their segments and mark views): with hundreds of
    thousands of strokes its passes over the growing heap took more time than the
    building itself (loading 827 k strokes: 3.5 s with it, 1.5 s without)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


_NO_KINDS = _read_only(np.zeros(0, dtype=bool))
_NO_POINTS = _read_only(np.zeros((0, 2)))


class Segments:
    """The fitted geometry of one stroke as arrays (input units).

    ``is_cubic`` (S,) bool: segment kinds in order (False: a line). ``points`` (C, 2)
    float64: the control points shared between consecutive segments, the start point
    then, per segment, its points after the start (a line: its end; a cubic: P1, P2, P3);
    C = 1 + lines + 3·cubics, or 0 without segments. The segments are continuous by
    construction.

    Behaves as the sequence of ``(kind, points)`` pairs of version 1 (``len``, iteration,
    indexing; each pair's points a read-only view), so code written for pairs keeps
    working; :meth:`reversed` and :meth:`rotated` give the same geometry traversed the
    other way or from another segment without leaving the arrays.
    """

    __slots__ = ("is_cubic", "points", "_offsets")

    def __init__(self, is_cubic: np.ndarray, points: np.ndarray) -> None:
        self.is_cubic = is_cubic
        self.points = points
        self._offsets: np.ndarray | None = None

    @classmethod
    def empty(cls) -> Segments:
        return cls(_NO_KINDS, _NO_POINTS)

    @classmethod
    def from_pairs(cls, pairs: Iterable[tuple[str, Any]]) -> Segments:
        """From ``(kind, points)`` pairs (a line 2 points, a cubic 4), each starting exactly
        where the previous one ended (else ValueError saying which)."""
        pairs = list(pairs)
        if not pairs:
            return cls.empty()
        kinds = [k for k, _ in pairs]
        arrs = [np.asarray(p, dtype=np.float64) for _, p in pairs]
        for k, (kind, p) in enumerate(zip(kinds, arrs, strict=True)):
            want = _WANT.get(kind)
            if want is None or p.shape != (want, 2):
                raise ValueError(f"segment {k} is not a line (2 points) or cubic (4 points)")
        flat = np.concatenate(arrs)
        cnt = np.array([len(p) for p in arrs])
        start = np.cumsum(cnt) - cnt
        bad = np.flatnonzero((flat[start[1:]] != flat[start[1:] - 1]).any(axis=1))
        if len(bad):
            k = int(bad[0]) + 1
            raise ValueError(f"segment {k} does not start where segment {k - 1} ended")
        keep = np.ones(len(flat), dtype=bool)
        keep[start[1:]] = False
        return cls(_read_only(cnt == 4), _read_only(flat[keep]))

    @property
    def offsets(self) -> np.ndarray:
        """Row of each segment's first point in ``points``."""
        if self._offsets is None:
            step = np.where(self.is_cubic, 3, 1)
            self._offsets = np.cumsum(step) - step
        return self._offsets

    def __len__(self) -> int:
        return len(self.is_cubic)

    def __bool__(self) -> bool:
        return len(self.is_cubic) > 0

    def __iter__(self) -> Iterator[tuple[str, np.ndarray]]:
        pts = self.points
        for o, c in zip(self.offsets.tolist(), self.is_cubic.tolist(), strict=True):
            yield _KIND_NAMES[c], pts[o:o + (4 if c else 2)]

    def __getitem__(self, i: int | slice) -> Any:
        if isinstance(i, slice):
            return tuple(self)[i]
        n = len(self.is_cubic)
        if not -n <= i < n:
            raise IndexError("segment index out of range")
        i %= n
        o = int(self.offsets[i])
        c = bool(self.is_cubic[i])
        return _KIND_NAMES[c], self.points[o:o + (4 if c else 2)]

    def reversed(self) -> Segments:
        """The same segments traversed from the end (each segment's points reversed)."""
        return Segments(self.is_cubic[::-1], self.points[::-1])

    def rotated(self, t: int) -> Segments:
        """A closed outline started at segment ``t`` (the last segment must end where the
        first starts)."""
        n = len(self.is_cubic)
        if n == 0 or t % n == 0:
            return self
        t %= n
        o = int(self.offsets[t])
        pts = np.concatenate([self.points[o:], self.points[1:o + 1]])
        return Segments(np.concatenate([self.is_cubic[t:], self.is_cubic[:t]]), pts)

    def __repr__(self) -> str:
        return f"Segments({len(self)} segments, {len(self.points)} points)"


@dataclass(frozen=True, eq=False)
class Stroke:
    """One laser-on run: ``marks`` (M, 2) int64 galvo bits in marking order.

    ``segments``: for contour strokes the fitted geometry in input units, continuous and in
    the direction of the marks, as :class:`Segments` (given as ``(kind, points)`` pairs it
    is converted); hatch strokes may have none.
    """

    kind: str
    source_index: int
    closed: bool
    marks: np.ndarray
    segments: Segments = dc_field(default_factory=Segments.empty)
    pen: int = 1

    def __post_init__(self) -> None:
        if not isinstance(self.segments, Segments):
            object.__setattr__(self, "segments", Segments.from_pairs(self.segments))

    def to_json(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "source_index": int(self.source_index),
            "closed": bool(self.closed),
            "pen": int(self.pen),
            "segments": [
                {"type": kind, "points": np.asarray(pts, dtype=float).tolist()}
                for kind, pts in self.segments
            ],
            "marks": np.asarray(self.marks, dtype=np.int64).tolist(),
        }


@dataclass(frozen=True, eq=False)
class StrokeColumns:
    """A job's strokes as columns (one array per field, the strokes' arrays joined in order):
    what the version 2 file stores, so writing it is a few array copies, not a Python loop
    over 10^5-10^6 strokes.

    ``strokes``: the tuple these columns describe (:meth:`Job.stroke_columns` uses them only
    for that very tuple). Per stroke (S rows): ``kind`` (0 contour, 1 hatch), ``closed``,
    ``pen``, ``source_index`` and the counts ``mark_count``, ``segment_count``,
    ``point_count``; joined: ``marks`` (M, 2) galvo bits, ``is_cubic`` (G,), ``points``
    (C, 2) input units.
    """

    strokes: tuple[Stroke, ...]
    kind: np.ndarray
    closed: np.ndarray
    pen: np.ndarray
    source_index: np.ndarray
    mark_count: np.ndarray
    marks: np.ndarray
    segment_count: np.ndarray
    is_cubic: np.ndarray
    point_count: np.ndarray
    points: np.ndarray

    @classmethod
    def of(cls, strokes: Sequence[Stroke]) -> StrokeColumns:
        """The columns of any strokes (a pass over them: what the pipeline avoids by
        giving its jobs columns made from its own arrays)."""
        from galvo_core.timing import joined_marks

        st = tuple(strokes)
        n = len(st)
        bad = set(map(attrgetter("kind"), st)) - set(_STROKE_KINDS)
        if bad:
            raise ValueError(f"stroke kind {sorted(bad)[0]!r} is not 'contour' or 'hatch'")
        # the marks, counts, sources and kinds joined once per strokes tuple (the pipeline's
        # stats and the preview ask for the same)
        jm = joined_marks(st)
        segs = list(map(attrgetter("segments"), st))
        return cls(
            st,
            kind=jm.hatch.astype(np.uint8),
            closed=np.fromiter(map(bool, map(attrgetter("closed"), st)), dtype=bool, count=n),
            pen=np.fromiter(map(int, map(attrgetter("pen"), st)), dtype=np.int64, count=n),
            source_index=jm.source,
            mark_count=jm.lens,
            marks=jm.marks,
            segment_count=np.fromiter(map(len, segs), dtype=np.int64, count=n),
            is_cubic=_cat(list(map(attrgetter("is_cubic"), segs)), bool, 0),
            point_count=np.fromiter(map(len, map(attrgetter("points"), segs)), dtype=np.int64,
                                    count=n),
            points=_cat(list(map(attrgetter("points"), segs)), np.float64, 2),
        )


@dataclass(frozen=True, eq=False)
class Job:
    source_name: str
    source_sha256: str
    field_map: FieldMap
    params: dict[str, Any]
    laser: dict[str, float]
    strokes: tuple[Stroke, ...]
    stats: dict[str, Any] = dc_field(default_factory=dict)
    warnings: tuple[Warning, ...] = ()
    # pen layers (issue 19): one row per pen the strokes use (galvo_core.layers
    # LayerSettings.as_dict()), the laser source, and whether a software field correction
    # was applied to the marks (None: not applied). Written only when set.
    layers: tuple[dict[str, Any], ...] = ()
    laser_source: str = "fiber"
    field_correction: dict[str, Any] | None = None
    # the strokes as columns when whoever made the job had them as arrays (the pipeline,
    # the .gjob loader): kept by dataclasses.replace() while the strokes stay the same
    # tuple, dropped when they change (and never pickled)
    columns: StrokeColumns | None = dc_field(default=None, repr=False)

    def __post_init__(self) -> None:
        if self.columns is not None and self.columns.strokes is not self.strokes:
            object.__setattr__(self, "columns", None)  # other strokes: not ours

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["columns"] = None  # they hold the strokes tuple: pickled strokes stay out
        return state

    def with_columns(self, columns: StrokeColumns) -> Job:
        """This job with ``columns`` (which must describe its very strokes tuple) kept for
        :meth:`stroke_columns`."""
        if columns.strokes is not self.strokes:
            raise ValueError("the columns describe other strokes than the job's")
        return dataclasses.replace(self, columns=columns)

    def stroke_columns(self) -> StrokeColumns:
        """The strokes as :class:`StrokeColumns`: the ones given with the job when they
        describe its strokes, else made from the strokes (not kept)."""
        c = self.columns
        if c is not None and c.strokes is self.strokes:
            return c
        return StrokeColumns.of(self.strokes)

    def header_json(self, version: int = VERSION) -> dict[str, Any]:
        """Every top-level key of the file but the strokes (shared by both forms; keys
        added here appear in both)."""
        stats = _jsonable(self.stats)
        # (10^4 warnings on big kerf jobs: made JSON-ready directly, not walked by _jsonable)
        stats["warnings"] = [w.as_dict() for w in self.warnings]
        fm = self.field_map
        out: dict[str, Any] = {
            "format": FORMAT,
            "version": version,
            "generator": GENERATOR,
            "source": {"name": self.source_name, "sha256": self.source_sha256},
            "field": {"size_mm": fm.field_size_mm, "bits": fm.field_bits},
            "magnification": fm.magnification,
            "offset_bits": [float(fm.offset_bits[0]), float(fm.offset_bits[1])],
            "params": _jsonable(self.params),
            "laser": dict(self.laser),
            "strokes": [],
            "stats": stats,
        }
        if self.layers:
            out["layers"] = _jsonable(list(self.layers))
            out["laser_source"] = self.laser_source
        if self.field_correction is not None:
            out["field_correction"] = _jsonable(self.field_correction)
        return out

    def to_json(self) -> dict[str, Any]:
        """The version 1 document as Python objects (slow for big jobs: one object per
        number; :func:`write_job` does not use it)."""
        doc = self.header_json(VERSION)
        doc["strokes"] = [s.to_json() for s in self.strokes]
        return doc


def _jsonable(v: Any) -> Any:
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def atomic_write_bytes(path: str | os.PathLike[str],
                       data: bytes | Sequence[bytes | memoryview | np.ndarray]) -> None:
    """Write ``data`` (bytes, or a sequence of buffers written one after the other) to
    ``path`` atomically; on any failure the old file stays as it was."""
    target = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(target))
    if not os.path.isdir(folder):
        raise GalvoError(f"{target}: the folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=os.path.basename(target)[-16:], dir=folder)
    try:
        # mkstemp makes the file private (0600): give it the mode a plain open() would, or
        # keep the mode of the file it replaces
        try:
            mode = os.stat(target).st_mode & 0o7777
        except OSError:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(tmp, mode)
        with os.fdopen(fd, "wb") as fh:
            if isinstance(data, (bytes, bytearray, memoryview)):
                fh.write(data)
            else:
                for part in data:
                    fh.write(part)  # type: ignore[arg-type]  # ndarray: a buffer
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, target)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError):
            raise GalvoError(f"{target}: cannot write ({exc.strerror or exc})") from exc
        raise


def is_compact_name(path: str | os.PathLike[str]) -> bool:
    """True for a file name that :func:`write_job` writes in the compact form (.gjob)."""
    return os.fspath(path).lower().endswith(COMPACT_EXTENSIONS)


def write_job(job: Job, path: str | os.PathLike[str]) -> None:
    """Write a job file atomically: version 2 (compact binary, docs/job-format.md) for a
    ``.gjob`` name, else version 1 (UTF-8 JSON, shared/spec/job-format.md)."""
    if is_compact_name(path):
        atomic_write_bytes(path, compact_job_parts(job))
    else:
        atomic_write_bytes(path, job_json_bytes(job))


# ------------------------------------------------------------------- version 1 (JSON)
_PLACEHOLDER = "\x00strokes\x00"


def _check_finite(a: np.ndarray, what: str) -> None:
    if a.size and not np.isfinite(a).all():
        raise ValueError(f"{what}: not a finite number (JSON has no NaN or infinity)")


def _pairs_text(flat: list[Any], fmt: str) -> str:
    """``[[a,b],[c,d],...]`` of a flat list of numbers, one formatting pass."""
    n = len(flat) // 2
    if n == 0:
        return "[]"
    return ("[" + ",".join([f"[{fmt},{fmt}]"] * n) + "]") % tuple(flat)


def _stroke_text(s: Stroke) -> str:
    segs = s.segments
    if len(segs):
        pts = np.asarray(segs.points, dtype=np.float64)
        _check_finite(pts, "segment points")
        cub = segs.is_cubic
        # the v1 points of every segment: rows o..o+1 (line) or o..o+3 (cubic)
        cnt = np.where(cub, 4, 2)
        starts = np.cumsum(cnt) - cnt
        rows = np.arange(int(cnt.sum())) - np.repeat(starts - segs.offsets, cnt)
        vals = pts[rows].ravel().tolist()
        line = '{"type":"line","points":[[%r,%r],[%r,%r]]}'
        cubic = '{"type":"cubic","points":[[%r,%r],[%r,%r],[%r,%r],[%r,%r]]}'
        seg_text = "[" + ",".join([cubic if c else line for c in cub.tolist()]) % tuple(
            vals) + "]"
    else:
        seg_text = "[]"
    m = np.asarray(s.marks)
    marks_text = _pairs_text(m.astype(np.int64, copy=False).ravel().tolist(), "%d")
    return (f'{{"kind":{json.dumps(s.kind)},"source_index":{int(s.source_index)},'
            f'"closed":{"true" if s.closed else "false"},"pen":{int(s.pen)},'
            f'"segments":{seg_text},"marks":{marks_text}}}')


def job_json_bytes(job: Job) -> bytes:
    """The version 1 file's bytes: the same as ``json.dumps(job.to_json(),
    separators=(",", ":"))``, the strokes formatted in bulk."""
    doc = job.header_json(VERSION)
    doc["strokes"] = _PLACEHOLDER
    head = json.dumps(doc, separators=(",", ":"), allow_nan=False)
    token = json.dumps(_PLACEHOLDER)
    a = head.index(token)
    body = ",".join([_stroke_text(s) for s in job.strokes])
    return (head[:a] + "[" + body + "]" + head[a + len(token):]).encode("utf-8")


# ----------------------------------------------------------- version 2 (compact binary)
#: the arrays of a version 2 file: name -> (dtype, columns); rows per array in the spec
_ARRAYS: dict[str, tuple[str, int]] = {
    "stroke_kind": ("|u1", 0),
    "stroke_closed": ("|u1", 0),
    "stroke_pen": ("<i4", 0),
    "stroke_source_index": ("<i8", 0),
    "stroke_mark_start": ("<i8", 0),
    "stroke_segment_start": ("<i8", 0),
    "stroke_point_start": ("<i8", 0),
    "marks": ("<i4", 2),
    "segment_is_cubic": ("|u1", 0),
    "points": ("<f8", 2),
}
_ALIGN = 8
_PREFIX = struct.Struct("<8sII")  # magic, version, header length


def _starts(counts: np.ndarray) -> np.ndarray:
    out = np.zeros(len(counts) + 1, dtype=np.int64)
    if len(counts):
        np.cumsum(counts, out=out[1:])
    return out


def _cat(parts: list[np.ndarray], dtype: Any, cols: int) -> np.ndarray:
    shape = (0, cols) if cols else (0,)
    return np.concatenate(parts).astype(dtype, copy=False) if parts else np.zeros(shape, dtype)


def compact_job_parts(job: Job) -> list[bytes | np.ndarray]:
    """The version 2 file as a list of buffers (see docs/job-format.md), from the job's
    columns (:meth:`Job.stroke_columns`): no loop over the strokes when it has them."""
    col = job.stroke_columns()
    st = col.strokes
    arrays: dict[str, np.ndarray] = {
        "stroke_kind": col.kind,
        "stroke_closed": col.closed,
        "stroke_pen": col.pen,
        "stroke_source_index": col.source_index,
        "stroke_mark_start": _starts(col.mark_count),
        "stroke_segment_start": _starts(col.segment_count),
        "stroke_point_start": _starts(col.point_count),
    }
    allm = col.marks
    if len(allm) and (allm.min() < -(2**31) or allm.max() >= 2**31):
        raise ValueError("marks beyond the 32-bit range cannot be written to a .gjob file")
    arrays["marks"] = allm.astype("<i4")
    arrays["segment_is_cubic"] = col.is_cubic
    pts = col.points
    if not np.isfinite(pts).all():
        raise ValueError("segment points: not a finite number")
    arrays["points"] = pts
    head = job.header_json(VERSION_COMPACT)
    del head["strokes"]
    head["n_strokes"] = len(st)
    # offsets are counted from the end of the header (padded to 8 bytes)
    table: dict[str, Any] = {}
    pos = 0
    for name, (dtype, _cols) in _ARRAYS.items():
        a = np.ascontiguousarray(arrays[name], dtype=dtype)
        arrays[name] = a
        table[name] = {"dtype": dtype, "shape": list(a.shape), "offset": pos}
        pos += a.nbytes
        pos += -pos % _ALIGN
    head["arrays"] = table
    hb = json.dumps(head, separators=(",", ":"), allow_nan=False).encode("utf-8")
    hb += b" " * (-(_PREFIX.size + len(hb)) % _ALIGN)
    parts: list[bytes | np.ndarray] = [_PREFIX.pack(MAGIC, VERSION_COMPACT, len(hb)), hb]
    for name in _ARRAYS:
        a = arrays[name]
        parts.append(a.reshape(-1).view(np.uint8))
        if a.nbytes % _ALIGN:
            parts.append(b"\0" * (-a.nbytes % _ALIGN))
    return parts


def compact_job_bytes(job: Job) -> bytes:
    return b"".join(bytes(p) for p in compact_job_parts(job))


# ---------------------------------------------------------------------------- loading
def _req(obj: dict[str, Any], key: str, where: str, name: str) -> Any:
    if not isinstance(obj, dict) or key not in obj:
        raise InputError(name, f"job file has no '{key}' in {where}")
    return obj[key]


def load_job(path: str | os.PathLike[str]) -> Job:
    """Read and validate a job file written by :func:`write_job` (or by anyone following the
    spec): version 1 (JSON) or version 2 (compact), told apart by the first bytes. Raises
    InputError naming the file and the place of the problem."""
    name, raw = read_input_bytes(path)
    if raw[:len(MAGIC)] == MAGIC:
        return job_from_compact(raw, name)
    try:
        doc = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise InputError(name, f"not UTF-8 text (byte {exc.start})") from exc
    except json.JSONDecodeError as exc:
        raise InputError(name, f"not valid JSON: {exc.msg} at line {exc.lineno}, "
                               f"column {exc.colno}") from exc
    return job_from_json(doc, name)


def _header(doc: Any, name: str, version: int) -> tuple[FieldMap, dict[str, Any]]:
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise InputError(name, "not a galvo job file (no \"format\": \"galvo-job\")")
    if doc.get("version") != version:
        raise InputError(name, f"job format version {doc.get('version')!r} is not supported "
                               f"here (this reader expects version {version}: 1 is JSON, "
                               "2 the compact .gjob form)")
    fld = _req(doc, "field", "the file", name)
    try:
        bits = int(_req(fld, "bits", "field", name))
        size_mm = float(_req(fld, "size_mm", "field", name))
        mag = float(_req(doc, "magnification", "the file", name))
    except (TypeError, ValueError) as exc:
        raise InputError(name, "field.bits, field.size_mm and magnification must be "
                               "numbers") from exc
    off = _req(doc, "offset_bits", "the file", name)
    if not (isinstance(off, list) and len(off) == 2):
        raise InputError(name, "offset_bits must be a list of two numbers")
    fm = FieldMap(mag, (float(off[0]), float(off[1])), bits, size_mm)
    _req(doc, "source", "the file", name)
    return fm, doc


def _finish(doc: dict[str, Any], fm: FieldMap, strokes: list[Stroke], name: str) -> Job:
    src = doc["source"]
    stats = dict(doc.get("stats", {}))
    warns = tuple(
        Warning(int(w.get("line", 0)), int(w.get("col", 0)), str(w.get("message", "")))
        for w in stats.pop("warnings", []) if isinstance(w, dict)
    )
    layers = doc.get("layers", [])
    if not (isinstance(layers, list) and all(isinstance(r, dict) for r in layers)):
        raise InputError(name, "layers must be a list of tables")
    corr = doc.get("field_correction")
    if corr is not None and not isinstance(corr, dict):
        raise InputError(name, "field_correction must be a table")
    return Job(str(src.get("name", "")), str(src.get("sha256", "")), fm,
               dict(doc.get("params", {})), dict(doc.get("laser", {})), tuple(strokes), stats,
               warns, tuple(layers), str(doc.get("laser_source", "fiber")), corr)


def job_from_json(doc: Any, name: str = "<job>") -> Job:
    with gc_paused():
        return _job_from_json(doc, name)


def _job_from_json(doc: Any, name: str = "<job>") -> Job:
    fm, doc = _header(doc, name, VERSION)
    bits = fm.field_bits
    strokes_in = _req(doc, "strokes", "the file", name)
    if not isinstance(strokes_in, list):
        raise InputError(name, "strokes must be a list")
    strokes: list[Stroke] = []
    for i, s in enumerate(strokes_in):
        where = f"strokes[{i}]"
        kind = _req(s, "kind", where, name)
        if kind not in _STROKE_KINDS:
            raise InputError(name, f"{where}.kind must be 'contour' or 'hatch', not {kind!r}")
        try:
            marks = np.asarray(_req(s, "marks", where, name), dtype=np.int64).reshape(-1, 2)
        except (ValueError, TypeError) as exc:
            raise InputError(name, f"{where}.marks must be a list of [X, Y] integers") from exc
        if len(marks) and (marks.min() < 0 or marks.max() > bits - 1):
            raise InputError(name, f"{where}.marks leave the field 0..{bits - 1}")
        segs = _segments_v1(_req(s, "segments", where, name), where, name)
        strokes.append(Stroke(kind, int(_req(s, "source_index", where, name)),
                              bool(_req(s, "closed", where, name)), marks, segs,
                              int(s.get("pen", 1))))
    return _finish(doc, fm, strokes, name)


def _segments_v1(segs_in: Any, where: str, name: str) -> Segments:
    """A v1 stroke's ``segments`` list as :class:`Segments`: the points of all segments as
    one array (a few Python operations per segment, one numpy conversion per stroke),
    validated (kinds, point counts, continuity) with the place of the first problem."""
    if not isinstance(segs_in, list):
        raise InputError(name, f"{where}.segments must be a list")
    if not segs_in:
        return Segments.empty()
    try:
        kinds = [sg["type"] for sg in segs_in]
        pts_lists = [sg["points"] for sg in segs_in]
        counts = [len(p) for p in pts_lists]
        ok = [_WANT.get(k) == c for k, c in zip(kinds, counts, strict=True)]
        flat = np.array([xy for p in pts_lists for xy in p], dtype=np.float64)
    except (TypeError, KeyError, ValueError):
        ok = [False]
        flat = np.zeros((0, 2))
    if not all(ok) or flat.ndim != 2 or flat.shape[1:] != (2,):
        for k, sg in enumerate(segs_in):  # find the place (the slow way, only on errors)
            here = f"{where}.segments[{k}]"
            typ = _req(sg, "type", here, name)
            try:
                pts = np.asarray(_req(sg, "points", here, name), dtype=float)
            except (ValueError, TypeError):
                pts = None
            if _WANT.get(typ) is None or pts is None or pts.shape != (_WANT[typ], 2):
                raise InputError(name, f"{here} is not a line (2 points) or cubic (4 points)")
        raise InputError(name, f"{where}.segments: points must be [x, y] numbers")
    cnt = np.array(counts)
    start = np.cumsum(cnt) - cnt
    # continuity: each segment starts where the previous one ended
    bad = np.flatnonzero((flat[start[1:]] != flat[start[1:] - 1]).any(axis=1))
    if len(bad):
        k = int(bad[0]) + 1
        raise InputError(name, f"{where}.segments: segment {k} does not start where segment "
                               f"{k - 1} ended (they must be continuous)")
    keep = np.ones(len(flat), dtype=bool)
    keep[start[1:]] = False
    pts = flat[keep]
    if not np.isfinite(pts).all():
        raise InputError(name, f"{where}.segments: points must be finite numbers")
    return Segments(_read_only(cnt == 4), _read_only(pts))


def job_from_compact(raw: bytes, name: str = "<job>") -> Job:
    """A version 2 (compact) job from the file's bytes (docs/job-format.md)."""
    if len(raw) < _PREFIX.size:
        raise InputError(name, "compact job file truncated in its first 16 bytes")
    _magic, version, hlen = _PREFIX.unpack_from(raw, 0)
    if version != VERSION_COMPACT:
        raise InputError(name, f"compact job format version {version} is not supported "
                               f"(this program reads version {VERSION_COMPACT})")
    data0 = _PREFIX.size + hlen
    if data0 > len(raw) or data0 % _ALIGN:
        raise InputError(name, f"compact job header length {hlen} does not fit the file "
                               f"({len(raw)} bytes)")
    try:
        doc = json.loads(raw[_PREFIX.size:data0].decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise InputError(name, f"header is not UTF-8 text (byte {exc.start + 16})") from exc
    except json.JSONDecodeError as exc:
        raise InputError(name, f"header is not valid JSON: {exc.msg} at byte "
                               f"{exc.pos + 16}") from exc
    fm, doc = _header(doc, name, VERSION_COMPACT)
    table = _req(doc, "arrays", "the header", name)
    n = _req(doc, "n_strokes", "the header", name)
    if not isinstance(n, int) or n < 0:
        raise InputError(name, "n_strokes must be a non-negative integer")
    buf = memoryview(raw)[data0:]
    arr: dict[str, np.ndarray] = {}
    for key, (dtype, cols) in _ARRAYS.items():
        ent = _req(table, key, "arrays", name)
        where = f"arrays.{key}"
        if not isinstance(ent, dict) or ent.get("dtype") != dtype:
            raise InputError(name, f"{where}.dtype must be {dtype!r}")
        shape, off = ent.get("shape"), ent.get("offset")
        if (not isinstance(shape, list) or len(shape) != (2 if cols else 1)
                or not all(isinstance(x, int) and x >= 0 for x in shape)
                or (cols and shape[1] != cols)):
            raise InputError(name, f"{where}.shape must be [rows{', ' + str(cols) if cols else ''}]"
                                   f", not {shape!r}")
        if not isinstance(off, int) or off < 0 or off % _ALIGN:
            raise InputError(name, f"{where}.offset must be a multiple of 8 >= 0")
        count = shape[0] * (cols or 1)
        nbytes = count * np.dtype(dtype).itemsize
        if off + nbytes > len(buf):
            raise InputError(name, f"{where} runs past the end of the file (truncated?)")
        arr[key] = np.frombuffer(buf, dtype=dtype, count=count, offset=off).reshape(shape)
    with gc_paused():
        return _strokes_from_arrays(arr, n, fm, doc, name)


def _offsets(a: np.ndarray, n: int, total: int, key: str, name: str) -> np.ndarray:
    if (len(a) != n + 1 or a[0] != 0 or a[-1] != total
            or (n and (np.diff(a) < 0).any())):
        raise InputError(name, f"arrays.{key} must be {n + 1} non-decreasing offsets from 0 "
                               f"to {total}")
    return a.astype(np.int64)


def _strokes_from_arrays(arr: dict[str, np.ndarray], n: int, fm: FieldMap,
                         doc: dict[str, Any], name: str) -> Job:
    for key in ("stroke_kind", "stroke_closed", "stroke_pen", "stroke_source_index"):
        if len(arr[key]) != n:
            raise InputError(name, f"arrays.{key} must have n_strokes = {n} rows")
    kind = arr["stroke_kind"]
    if n and kind.max() > 1:
        i = int(np.argmax(kind > 1))
        raise InputError(name, f"strokes[{i}]: kind code {int(kind[i])} is not 0 (contour) "
                               "or 1 (hatch)")
    marks = arr["marks"].astype(np.int64)  # one conversion for all strokes
    mstart = _offsets(arr["stroke_mark_start"], n, len(marks), "stroke_mark_start", name)
    bits = fm.field_bits
    if len(marks):
        bad = (marks < 0) | (marks > bits - 1)
        if bad.any():
            row = int(np.argmax(bad.any(axis=1)))
            i = int(np.searchsorted(mstart, row, side="right")) - 1
            raise InputError(name, f"strokes[{i}].marks leave the field 0..{bits - 1}")
    is_cubic = arr["segment_is_cubic"]
    if len(is_cubic) and is_cubic.max() > 1:
        raise InputError(name, "arrays.segment_is_cubic must hold 0 (line) or 1 (cubic)")
    is_cubic = is_cubic.astype(bool)
    is_cubic.setflags(write=False)
    sstart = _offsets(arr["stroke_segment_start"], n, len(is_cubic), "stroke_segment_start",
                      name)
    pts = arr["points"].copy()
    pts.setflags(write=False)
    pstart = _offsets(arr["stroke_point_start"], n, len(pts), "stroke_point_start", name)
    if not np.isfinite(pts).all():
        raise InputError(name, "arrays.points: not every coordinate is a finite number")
    # points per stroke: 0 without segments, else 1 + lines + 3 cubics
    cs = np.r_[0, np.cumsum(np.where(is_cubic, 3, 1))]
    per = cs[sstart[1:]] - cs[sstart[:-1]]
    nseg = np.diff(sstart)
    want = np.where(nseg > 0, per + 1, 0)
    wrong = np.flatnonzero(want != np.diff(pstart))
    if len(wrong):
        i = int(wrong[0])
        raise InputError(name, f"strokes[{i}]: {int(np.diff(pstart)[i])} control points for "
                               f"its segments, which need {int(want[i])}")
    ms, ss, ps = mstart.tolist(), sstart.tolist(), pstart.tolist()
    kinds = [_STROKE_KINDS[k] for k in kind.tolist()]
    closed = arr["stroke_closed"].astype(bool).tolist()
    pen = arr["stroke_pen"].tolist()
    src = arr["stroke_source_index"].tolist()
    empty = Segments.empty()
    strokes = []
    for i in range(n):
        segs = (Segments(is_cubic[ss[i]:ss[i + 1]], pts[ps[i]:ps[i + 1]])
                if ss[i + 1] > ss[i] else empty)
        strokes.append(Stroke(kinds[i], src[i], closed[i], marks[ms[i]:ms[i + 1]], segs,
                              pen[i]))
    job = _finish(doc, fm, strokes, name)
    # the arrays just read are the job's columns: writing it again needs no stroke loop
    return job.with_columns(StrokeColumns(
        job.strokes, kind=kind.copy(), closed=arr["stroke_closed"].astype(bool),
        pen=arr["stroke_pen"].astype(np.int64),
        source_index=arr["stroke_source_index"].astype(np.int64),
        mark_count=np.diff(mstart), marks=marks, segment_count=np.diff(sstart),
        is_cubic=is_cubic, point_count=np.diff(pstart), points=pts))
