"""The central data type: a drawing's pen-down paths in input units.

Every stage of the pipeline takes a :class:`Drawing` and returns a new one (or a
structure derived from it); nothing mutates a drawing once built.

Units
-----
*Input units* are HP-GL plotter units: 40 per millimetre of the drawing (0.025 mm).
Files that use SC/IP user units are converted to plotter units on import, so every
coordinate in a :class:`Drawing` is in plotter units, whatever the file used.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable, Mapping
from dataclasses import FrozenInstanceError, dataclass, field, replace
from itertools import chain, repeat
from types import MappingProxyType
from typing import Any

import numpy as np

#: HP-GL plotter units per millimetre of the drawing.
UNITS_PER_MM = 40.0


@dataclass(frozen=True, slots=True)
class SourcePos:
    """A place in the input file: 1-based line and column (column counts bytes)."""

    line: int
    col: int

    def __str__(self) -> str:
        return f"line {self.line}, column {self.col}"


@dataclass(frozen=True, slots=True)
class Warning:  # noqa: A001 - a drawing's warning, deliberately short name inside the module
    """A problem found while reading or processing that did not stop the work.

    ``line``/``col`` are 1-based positions in the input file (0, 0 when the warning
    does not belong to one place).
    """

    line: int
    col: int
    message: str

    def as_dict(self) -> dict[str, object]:
        """JSON-ready (plain int and str, whatever numpy scalars it was made with)."""
        return {"line": int(self.line), "col": int(self.col), "message": str(self.message)}

    def __str__(self) -> str:
        if self.line:
            return f"line {self.line}, column {self.col}: {self.message}"
        return self.message


def _frozen_points(points: object) -> np.ndarray:
    arr = np.array(points, dtype=np.float64, copy=True)
    if arr.ndim != 2 or arr.shape[1] != 2:
        arr = arr.reshape(-1, 2)
    arr.setflags(write=False)
    return arr


_NOWHERE = SourcePos(0, 0)
_set = object.__setattr__
_new_obj = object.__new__
_SP_LINE = SourcePos.__dict__["line"].__set__
_SP_COL = SourcePos.__dict__["col"].__set__


class Path:
    """One pen-down path.

    Attributes
    ----------
    points:
        float64 array of shape (N, 2), N >= 1, in input units, read-only. A single point
        (N == 1) is a dot (the pen went down and up without moving).
    pen:
        The pen number selected when the path was drawn (SP), 1 by default.
    closed:
        True when the path is a closed ring: its first point equals its last (N >= 4 for a
        ring that encloses area). Set by the importer for rectangles, circles, polygon-mode
        rings and for pen-down runs that return exactly to their start.
    start:
        Where in the file the path began.

    Immutable (assigning an attribute raises ``dataclasses.FrozenInstanceError``); equal
    only to itself. ``Path(points, pen=1, closed=False, start=SourcePos(0, 0))`` copies
    ``points``.

    The importer's paths share their storage: :func:`paths_from_store` makes many paths over
    one points array in one vectorised step; the ``points`` views of a store's 256 paths are
    made together the first time one of them is read (then kept), a ``start`` when asked
    for. Nothing else differs.
    """

    # _points: the (N, 2) array; for a stored path unset until first read. _store: the
    # start (a SourcePos) of a path built by __init__, the PathStore of a stored one, whose
    # path _k it is (below 256: CPython shares those ints, no int object per path)
    __slots__ = ("_points", "pen", "closed", "_store", "_k")
    _points: np.ndarray
    pen: int
    closed: bool
    _store: Any  # SourcePos or PathStore (type() checks below, faster than isinstance)
    _k: int
    __match_args__ = ("points", "pen", "closed", "start")

    def __init__(
        self,
        points: object,
        pen: int = 1,
        closed: bool = False,
        start: SourcePos | None = None,
    ) -> None:
        _set(self, "_points", _frozen_points(points))
        _set(self, "pen", pen)
        _set(self, "closed", closed)
        _set(self, "_store", _NOWHERE if start is None else start)

    @classmethod
    def from_points(
        cls,
        points: object,
        *,
        pen: int = 1,
        closed: bool | None = None,
        start: SourcePos | None = None,
    ) -> Path:
        """Build a path; ``closed=None`` means "closed when first point equals last"."""
        arr = _frozen_points(points)
        if closed is None:
            closed = len(arr) >= 3 and bool(np.array_equal(arr[0], arr[-1]))
        return cls(arr, pen=pen, closed=closed, start=start or _NOWHERE)

    @property
    def points(self) -> np.ndarray:
        st = self._store
        if type(st) is SourcePos:
            return self._points  # type: ignore[no-any-return]
        views = st.views  # a stored path: its store's views, made at the first read
        if views is None:
            views = st.make_views()
        return views[self._k]  # type: ignore[no-any-return]

    @property
    def start(self) -> SourcePos:
        st = self._store
        if type(st) is SourcePos:
            return st
        k = self._k  # a stored path: its position is in the store's arrays
        sp = _new_obj(SourcePos)
        _SP_LINE(sp, st.lines.item(k))
        _SP_COL(sp, st.cols.item(k))
        return sp  # type: ignore[no-any-return]

    def __len__(self) -> int:
        st = self._store
        if type(st) is SourcePos:
            return len(self._points)
        k = self._k
        return st.ends.item(k) - st.starts.item(k)  # type: ignore[no-any-return]

    def __setattr__(self, name: str, value: object) -> None:
        raise FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise FrozenInstanceError(f"cannot delete field {name!r}")

    def __repr__(self) -> str:
        return (f"Path(points={self.points!r}, pen={self.pen!r}, closed={self.closed!r}, "
                f"start={self.start!r})")

    def __reduce__(self) -> tuple[object, ...]:
        return (Path, (self.points, self.pen, self.closed, self.start))

    @property
    def length(self) -> float:
        """Polyline length in input units."""
        pts = self.points
        if len(pts) < 2:
            return 0.0
        return float(np.hypot(*np.diff(pts, axis=0).T).sum())

    def with_points(self, points: object, *, closed: bool | None = None) -> Path:
        """A copy with new points (same pen and source position)."""
        return Path(points, self.pen, self.closed if closed is None else closed, self.start)


class PathStore:
    """The shared storage of up to 256 paths (see :func:`paths_from_store`): path ``k`` is
    ``pts[starts[k]:ends[k]]`` and began at line ``lines[k]``, column ``cols[k]``."""

    __slots__ = ("pts", "starts", "ends", "lines", "cols", "views")

    def __init__(self, pts: np.ndarray, starts: np.ndarray, ends: np.ndarray,
                 lines: np.ndarray, cols: np.ndarray) -> None:
        self.pts = pts
        self.starts = starts
        self.ends = ends
        self.lines = lines
        self.cols = cols
        self.views: list[np.ndarray] | None = None

    def make_views(self) -> list[np.ndarray]:
        """The points view of every path of the store (in one go: loops in C), kept."""
        views = list(map(self.pts.__getitem__,
                         map(slice, self.starts.tolist(), self.ends.tolist())))
        self.views = views
        return views


_P_PEN = Path.__dict__["pen"].__set__
_P_CLOSED = Path.__dict__["closed"].__set__
_P_STORE = Path.__dict__["_store"].__set__
_P_K = Path.__dict__["_k"].__set__


_STORE_PATHS = 256  # paths per PathStore: their index is a small int (shared by CPython)


def paths_from_store(pts: np.ndarray, starts: np.ndarray, ends: np.ndarray, pens: list[int],
                     closed: list[bool], lines: np.ndarray, cols: np.ndarray) -> list[Path]:
    """Paths ``pts[starts[k]:ends[k]]`` (``pts`` a read-only float64 (N, 2) array, not
    copied), drawn with ``pens[k]``, ``closed[k]``, begun at ``lines[k]``, ``cols[k]``.

    Made in one vectorised step (loops in C: no per-path Python code): each path holds a
    store (one per 256 paths, over views of the arrays given) and its index there; its
    points view and its SourcePos are made when read.
    """
    m = len(pens)
    if m == 0:
        return []
    starts, ends, lines, cols = (np.asarray(a) for a in (starts, ends, lines, cols))
    n = _STORE_PATHS
    stores = [PathStore(pts, starts[i : i + n], ends[i : i + n], lines[i : i + n],
                        cols[i : i + n]) for i in range(0, m, n)]
    objs = list(map(_new_obj, repeat(Path, m)))
    any(map(_P_PEN, objs, pens))
    any(map(_P_CLOSED, objs, closed))
    any(map(_P_STORE, objs, chain.from_iterable(map(repeat, stores, repeat(n)))))
    any(map(_P_K, objs, chain.from_iterable(repeat(range(n), len(stores)))))
    return objs


@dataclass(frozen=True, eq=False)
class Drawing:
    """The pen-down paths of one file plus what is known about the file.

    Attributes
    ----------
    paths:
        Pen-down paths in file order. ``source_index`` in a job file is the index here.
    name:
        The file's name (no folder).
    sha256:
        Hex SHA-256 of the file's bytes.
    commands:
        How many times each mnemonic occurred (read-only mapping, upper case).
    warnings:
        Problems met while reading, in file order.
    """

    paths: tuple[Path, ...]
    name: str = ""
    sha256: str = ""
    commands: Mapping[str, int] = field(default_factory=dict)
    warnings: tuple[Warning, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "paths", tuple(self.paths))
        object.__setattr__(self, "commands", MappingProxyType(dict(self.commands)))
        object.__setattr__(self, "warnings", tuple(self.warnings))

    # --- derived facts ---------------------------------------------------------------
    @property
    def n_points(self) -> int:
        return sum(map(len, self.paths))

    @property
    def n_closed(self) -> int:
        return sum(1 for p in self.paths if p.closed)

    def bbox(self) -> tuple[float, float, float, float] | None:
        """(xmin, ymin, xmax, ymax) in input units, or None for an empty drawing."""
        if not self.paths:
            return None
        pts = np.concatenate([p.points for p in self.paths])
        lo = pts.min(axis=0)
        hi = pts.max(axis=0)
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])

    def size_mm(self) -> tuple[float, float]:
        """Width and height of the bounding box in mm of the drawing (40 units per mm)."""
        bb = self.bbox()
        if bb is None:
            return 0.0, 0.0
        return (bb[2] - bb[0]) / UNITS_PER_MM, (bb[3] - bb[1]) / UNITS_PER_MM

    def with_paths(self, paths: Iterable[Path], *, warnings: Iterable[Warning] = ()) -> Drawing:
        """A new drawing with other paths and extra warnings, same file metadata."""
        return replace(self, paths=tuple(paths), warnings=self.warnings + tuple(warnings))

    def quantum(self) -> float:
        """The grid the coordinates were rounded to (input units; 0 for exact coordinates):
        :func:`galvo_core.precision.drawing_quantum`."""
        from galvo_core.precision import drawing_quantum

        return float(drawing_quantum(self.paths)[0])

    def path_quanta(self) -> dict[str, int]:
        """How many paths have each coordinate grid (``{"1": 370, "0": 12}``; "0": exact),
        for files whose paths differ (labels and arcs off the grid of the rest)."""
        from galvo_core.precision import path_quanta

        if not self.paths:
            return {}
        q, n = np.unique(path_quanta([p.points for p in self.paths]), return_counts=True)
        return {f"{float(v):g}": int(c) for v, c in zip(q, n, strict=True)}

    def info(self) -> dict[str, object]:
        """A JSON-ready summary (what ``galvo-core info`` prints)."""
        bb = self.bbox()
        w, h = self.size_mm()
        return {
            "file": self.name,
            "sha256": self.sha256,
            "paths": len(self.paths),
            "points": self.n_points,
            "closed_paths": self.n_closed,
            "bbox": list(bb) if bb is not None else None,
            "size_mm": [w, h],
            "pens": sorted({p.pen for p in self.paths}),
            "quantum_units": self.quantum(),
            "path_quanta": self.path_quanta(),
            "commands": dict(sorted(self.commands.items())),
            "warnings": [w_.as_dict() for w_ in self.warnings],
        }


def sha256_hex(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()
