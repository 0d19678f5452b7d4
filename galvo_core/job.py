"""The galvo job file (shared/spec/job-format.md, format version 1): build, write, load.

:func:`write_job` writes atomically (a temporary file in the same folder, flushed and
fsynced, then renamed over the target), so an interrupted write leaves the old file intact
and never a half-written one. :func:`load_job` validates what readers rely on and raises
:class:`~galvo_core.errors.InputError` naming the file and the place otherwise.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from dataclasses import field as dc_field
from typing import Any

import numpy as np

from galvo_core import __version__
from galvo_core.drawing import Warning
from galvo_core.errors import GalvoError, InputError
from galvo_core.field import FieldMap

FORMAT = "galvo-job"
VERSION = 1
GENERATOR = f"galvo-workstation {__version__}"


@dataclass(frozen=True, eq=False)
class Stroke:
    """One laser-on run: ``marks`` (M, 2) int64 galvo bits in marking order.

    ``segments``: for contour strokes, (kind, points) pairs of the fitted geometry in input
    units, continuous and in the direction of the marks; hatch strokes may have none.
    """

    kind: str
    source_index: int
    closed: bool
    marks: np.ndarray
    segments: tuple[tuple[str, np.ndarray], ...] = ()
    pen: int = 1

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

    def to_json(self) -> dict[str, Any]:
        stats = dict(self.stats)
        stats["warnings"] = [w.as_dict() for w in self.warnings]
        fm = self.field_map
        out: dict[str, Any] = {
            "format": FORMAT,
            "version": VERSION,
            "generator": GENERATOR,
            "source": {"name": self.source_name, "sha256": self.source_sha256},
            "field": {"size_mm": fm.field_size_mm, "bits": fm.field_bits},
            "magnification": fm.magnification,
            "offset_bits": [float(fm.offset_bits[0]), float(fm.offset_bits[1])],
            "params": _jsonable(self.params),
            "laser": dict(self.laser),
            "strokes": [s.to_json() for s in self.strokes],
            "stats": _jsonable(stats),
        }
        if self.layers:
            out["layers"] = _jsonable(list(self.layers))
            out["laser_source"] = self.laser_source
        if self.field_correction is not None:
            out["field_correction"] = _jsonable(self.field_correction)
        return out


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


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` atomically; on any failure the old file stays as it was."""
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
            fh.write(data)
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


def write_job(job: Job, path: str | os.PathLike[str]) -> None:
    """Write a job file (UTF-8 JSON) atomically."""
    text = json.dumps(job.to_json(), separators=(",", ":"), allow_nan=False)
    atomic_write_bytes(path, text.encode("utf-8"))


# ---------------------------------------------------------------------------- loading
def _req(obj: dict[str, Any], key: str, where: str, name: str) -> Any:
    if not isinstance(obj, dict) or key not in obj:
        raise InputError(name, f"job file has no '{key}' in {where}")
    return obj[key]


def load_job(path: str | os.PathLike[str]) -> Job:
    """Read and validate a job file written by :func:`write_job` (or by anyone following the
    spec). Raises InputError naming the file and the place of the problem."""
    name = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise InputError(name, f"cannot be read ({exc.strerror or exc})") from exc
    try:
        doc = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise InputError(name, f"not UTF-8 text (byte {exc.start})") from exc
    except json.JSONDecodeError as exc:
        raise InputError(name, f"not valid JSON: {exc.msg} at line {exc.lineno}, "
                               f"column {exc.colno}") from exc
    return job_from_json(doc, name)


def job_from_json(doc: Any, name: str = "<job>") -> Job:
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise InputError(name, "not a galvo job file (no \"format\": \"galvo-job\")")
    if doc.get("version") != VERSION:
        raise InputError(name, f"job format version {doc.get('version')!r} is not supported "
                               f"(this program reads version {VERSION})")
    fld = _req(doc, "field", "the file", name)
    bits = int(_req(fld, "bits", "field", name))
    size_mm = float(_req(fld, "size_mm", "field", name))
    mag = float(_req(doc, "magnification", "the file", name))
    off = _req(doc, "offset_bits", "the file", name)
    if not (isinstance(off, list) and len(off) == 2):
        raise InputError(name, "offset_bits must be a list of two numbers")
    fm = FieldMap(mag, (float(off[0]), float(off[1])), bits, size_mm)
    src = _req(doc, "source", "the file", name)
    strokes_in = _req(doc, "strokes", "the file", name)
    if not isinstance(strokes_in, list):
        raise InputError(name, "strokes must be a list")
    strokes: list[Stroke] = []
    for i, s in enumerate(strokes_in):
        where = f"strokes[{i}]"
        kind = _req(s, "kind", where, name)
        if kind not in ("contour", "hatch"):
            raise InputError(name, f"{where}.kind must be 'contour' or 'hatch', not {kind!r}")
        try:
            marks = np.asarray(_req(s, "marks", where, name), dtype=np.int64).reshape(-1, 2)
        except (ValueError, TypeError) as exc:
            raise InputError(name, f"{where}.marks must be a list of [X, Y] integers") from exc
        if len(marks) and (marks.min() < 0 or marks.max() > bits - 1):
            raise InputError(name, f"{where}.marks leave the field 0..{bits - 1}")
        segs = []
        for k, sg in enumerate(_req(s, "segments", where, name)):
            typ = _req(sg, "type", f"{where}.segments[{k}]", name)
            pts = np.asarray(_req(sg, "points", f"{where}.segments[{k}]", name), dtype=float)
            want = {"line": 2, "cubic": 4}.get(typ)
            if want is None or pts.shape != (want, 2):
                raise InputError(name, f"{where}.segments[{k}] is not a line (2 points) or "
                                       "cubic (4 points)")
            segs.append((typ, pts))
        strokes.append(Stroke(kind, int(_req(s, "source_index", where, name)),
                              bool(_req(s, "closed", where, name)), marks, tuple(segs),
                              int(s.get("pen", 1))))
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


def strokes_marks(strokes: Sequence[Stroke]) -> list[np.ndarray]:
    return [s.marks for s in strokes]
