"""Software field correction: a 65×65 grid of (dx, dy) shifts in galvo bits.

The grid's nodes sit every 1024 bits (node 64 at 65536) on both axes; the shift of a point
is the bilinear interpolation of its cell's four nodes, and a corrected mark is
``round(p + shift(p))``. Within one cell the bilinear map bends a straight line into a
parabola, so before correcting, every mark vector is cut where it crosses a grid line and
each piece is cut into ``n`` equal parts with ``|A| / (4 n²) <= tol_bits``, ``A`` the
piece's quadratic coefficient (the cell's cross term times the piece's dx·dy): the
corrected marks then follow the corrected line within ``tol_bits`` (plus the rounding to
whole bits), so straight lines stay straight on the work. A vector whose added points all
lie within ``tol_bits / 2`` of its corrected chord (the table is affine along it: a pure
offset, a scale) keeps no added point.

Tables come from:

* a BJJCZ ``.cor`` file, in both layouts MeerK40t and galvoplotter read: ``LMC1COR_1.0``
  (UTF-16 label, 0x1FA header bytes, 65×65 pairs of float64) and the integer layout
  (``JCZ_COR_2_1`` and older: 0x16 label bytes, 6 bytes, the float64 scale, 65×65 pairs of
  int32). The table is stored row by row with Y outer and X inner (as MeerK40t's
  correction-file generator writes it; ``x_outer=True`` reads the other order);
* a measured 3×3 grid (:func:`from_3x3`): where nine marks at the field's centre and its
  ±span/2 positions actually landed; the error is interpolated biquadratically (exact for
  the usual barrel/pincushion and trapezoid terms) and inverted by fixed-point iteration.

The shift is *added* to the position (the convention of the board's own table). A job
records whether its marks were corrected (``field_correction``); :func:`apply_to_job`
refuses a job that already was.
"""

from __future__ import annotations

import dataclasses
import math
import os
import struct
import tomllib
from dataclasses import dataclass
from typing import Any

import numpy as np

from galvo_core.errors import InputError, read_input_bytes

GRID = 65
CELL = 1024.0  # bits between nodes (65536 / 64)
V1_LABEL = "LMC1COR_1.0"
_V1_SIZE = 0x16 + 0x1FA + GRID * GRID * 16
_V2_SIZE = 0x16 + 0x0E + GRID * GRID * 8


@dataclass(frozen=True, eq=False)
class FieldCorrection:
    """``dx``, ``dy``: (65, 65) float arrays of shifts in bits, indexed ``[iy, ix]`` (node
    ``(ix, iy)`` at ``(ix * 1024, iy * 1024)``); ``source`` names where they came from."""

    dx: np.ndarray
    dy: np.ndarray
    source: str = ""

    def __post_init__(self) -> None:
        for a in (self.dx, self.dy):
            if np.shape(a) != (GRID, GRID) or not np.isfinite(a).all():
                raise ValueError("a field correction is two finite 65x65 grids")

    @property
    def max_shift_bits(self) -> float:
        return float(np.hypot(self.dx, self.dy).max())

    def _cell(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        g = np.asarray(p, dtype=np.float64) / CELL
        i = np.clip(np.floor(g[:, 0]).astype(np.int64), 0, GRID - 2)
        j = np.clip(np.floor(g[:, 1]).astype(np.int64), 0, GRID - 2)
        return i, j, g[:, 0] - i, g[:, 1] - j

    def shift(self, pts: np.ndarray) -> np.ndarray:
        """The bilinear shift (N, 2) in bits at points (N, 2) in bits."""
        p = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
        i, j, u, v = self._cell(p)
        out = np.empty_like(p)
        for k, g in enumerate((self.dx, self.dy)):
            out[:, k] = ((1 - u) * (1 - v) * g[j, i] + u * (1 - v) * g[j, i + 1]
                         + (1 - u) * v * g[j + 1, i] + u * v * g[j + 1, i + 1])
        return out

    def cross_terms(self) -> tuple[np.ndarray, np.ndarray]:
        """Per cell (64, 64) [iy, ix]: the bilinear cross coefficient (bits per bit²)."""
        def xt(g: np.ndarray) -> np.ndarray:
            return (g[1:, 1:] - g[1:, :-1] - g[:-1, 1:] + g[:-1, :-1]) / (CELL * CELL)
        return xt(self.dx), xt(self.dy)

    def subdivide(self, marks: np.ndarray, tol_bits: float = 0.25) -> np.ndarray:
        """The polyline ``marks`` (M, 2) with points added (float bits) so that the
        bilinear map of each piece stays within ``tol_bits`` of its chord (module docs)."""
        m = np.asarray(marks, dtype=np.float64).reshape(-1, 2)
        if len(m) < 2:
            return m
        pts, _ = self._split_vectors(m[:-1], m[1:], tol_bits)
        return np.vstack([pts, m[-1:]])

    def _split_vectors(self, a: np.ndarray, b: np.ndarray,
                       tol_bits: float) -> tuple[np.ndarray, np.ndarray]:
        """For vectors a -> b (V, 2): the points of each (its start, then the points
        added), in order, and the vector each belongs to."""
        nv = len(a)
        d = b - a
        ids = [np.arange(nv)]
        ts = [np.zeros(nv)]
        for ax in (0, 1):
            lo = np.minimum(a[:, ax], b[:, ax])
            hi = np.maximum(a[:, ax], b[:, ax])
            k0 = np.floor(lo / CELL).astype(np.int64) + 1
            k1 = np.ceil(hi / CELL).astype(np.int64) - 1
            n = np.maximum(k1 - k0 + 1, 0)
            if not n.any():
                continue
            vid = np.repeat(np.arange(nv), n)
            off = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
            k = k0[vid] + off
            ids.append(vid)
            ts.append((k * CELL - a[vid, ax]) / d[vid, ax])
        vid = np.concatenate(ids)
        t = np.concatenate(ts)
        order = np.lexsort((t, vid))
        vid, t = vid[order], t[order]
        # piece ends: the next t of the same vector, or 1
        t_end = np.ones_like(t)
        same = vid[1:] == vid[:-1]
        t_end[:-1][same] = t[1:][same]
        keep = t_end - t > 1e-12
        vid, t, t_end = vid[keep], t[keep], t_end[keep]
        p0 = a[vid] + t[:, None] * d[vid]
        p1 = a[vid] + t_end[:, None] * d[vid]
        pd = p1 - p0
        i, j, _, _ = self._cell((p0 + p1) / 2)
        cx, cy = self.cross_terms()
        amp = np.maximum(np.abs(cx[j, i]), np.abs(cy[j, i])) * np.abs(pd[:, 0] * pd[:, 1])
        nsub = np.maximum(np.ceil(np.sqrt(amp / (4 * tol_bits))), 1).astype(np.int64)
        pid = np.repeat(np.arange(len(p0)), nsub)
        s = (np.arange(int(nsub.sum())) - np.repeat(np.cumsum(nsub) - nsub, nsub)) / nsub[pid]
        pts = p0[pid] + s[:, None] * pd[pid]
        # where the map is affine along a whole vector (a pure offset or scale, or a cell
        # without cross term), its added points lie on the corrected chord: drop them when
        # every one is within tol/2 of it (the curve then stays within tol of the chord)
        pv = vid[pid]
        added = np.concatenate([[False], pv[1:] == pv[:-1]])  # all but each vector's start
        if added.any():
            ca = a + self.shift(a)
            cb = b + self.shift(b)
            q = pts[added] + self.shift(pts[added])
            v = pv[added]
            dv = cb[v] - ca[v]
            w = q - ca[v]
            ln = np.maximum(np.hypot(dv[:, 0], dv[:, 1]), 1e-12)
            off = np.abs(dv[:, 0] * w[:, 1] - dv[:, 1] * w[:, 0]) / ln
            worst = np.zeros(nv)
            np.maximum.at(worst, v, off)
            drop = np.zeros(len(pts), dtype=bool)
            drop[np.flatnonzero(added)] = worst[v] <= tol_bits / 2
            pts, pv = pts[~drop], pv[~drop]
        return pts, pv

    def apply_many(self, strokes: list[np.ndarray], tol_bits: float = 0.25
                   ) -> list[np.ndarray]:
        """:meth:`apply` to many polylines at once (whole arrays, no loop per stroke)."""
        sizes = np.array([len(m) for m in strokes], dtype=np.int64)
        if not sizes.sum():
            return [np.zeros((0, 2), dtype=np.int64) for _ in strokes]
        allm = np.concatenate([np.asarray(m, dtype=np.float64).reshape(-1, 2)
                               for m in strokes])
        sid = np.repeat(np.arange(len(sizes)), sizes)
        inside = np.flatnonzero(sid[1:] == sid[:-1])  # vectors within a stroke
        pts, pv = self._split_vectors(allm[inside], allm[inside + 1], tol_bits)
        ends = np.cumsum(sizes)[sizes > 0] - 1  # each stroke's last mark
        key = np.concatenate([inside[pv], ends])
        order = np.argsort(key, kind="stable")
        p = np.vstack([pts, allm[ends]])[order]
        ps = sid[key[order]]
        c = np.floor(p + self.shift(p) + 0.5).astype(np.int64)
        keep = np.ones(len(c), dtype=bool)
        keep[1:] = (c[1:] != c[:-1]).any(axis=1) | (ps[1:] != ps[:-1])
        c, ps = c[keep], ps[keep]
        cuts = np.searchsorted(ps, np.arange(1, len(sizes)))
        return np.split(c, cuts)

    def apply(self, marks: np.ndarray, tol_bits: float = 0.25) -> np.ndarray:
        """Corrected marks (K, 2) int64: subdivided, shifted, rounded; consecutive repeats
        left by the rounding removed (the first and last mark always kept)."""
        m = np.asarray(marks)
        if len(m) == 0:
            return np.zeros((0, 2), dtype=np.int64)
        p = self.subdivide(m, tol_bits)
        c = np.floor(p + self.shift(p) + 0.5).astype(np.int64)
        if len(c) > 1:
            keep = np.concatenate([[True], (np.diff(c, axis=0) != 0).any(axis=1)])
            c = c[keep]
        return c


def apply_to_job(job: Any, corr: FieldCorrection, tol_bits: float = 0.25) -> Any:
    """A :class:`galvo_core.job.Job` with every stroke's marks corrected and
    ``field_correction`` saying so. Refuses (InputError) a job already corrected and marks
    that the correction pushes out of the field."""
    if job.field_correction is not None:
        raise InputError(job.source_name, "the job's marks are already field-corrected ("
                         f"{job.field_correction.get('source', '?')}); not applying a "
                         "correction twice")
    if job.field_map.field_bits != 65536:
        raise InputError(job.source_name, "a field correction needs a 65536-bit field, the "
                                          f"job has {job.field_map.field_bits}")
    out = corr.apply_many([s.marks for s in job.strokes], tol_bits)
    strokes = []
    for k, (s, c) in enumerate(zip(job.strokes, out, strict=True)):
        if len(c) and (c.min() < 0 or c.max() > 65535):
            bad = np.flatnonzero(((c < 0) | (c > 65535)).any(axis=1))
            raise InputError(job.source_name, f"strokes[{k}]: the field correction moves a "
                             f"mark to {tuple(int(v) for v in c[bad[0]])}, outside 0..65535")
        strokes.append(dataclasses.replace(s, marks=c))
    info = {"applied": True, "source": corr.source, "tol_bits": tol_bits,
            "max_shift_bits": corr.max_shift_bits}
    return dataclasses.replace(job, strokes=tuple(strokes), field_correction=info)


# ---------------------------------------------------------------------------- .cor files
def read_cor(path: str | os.PathLike[str], x_outer: bool = False) -> FieldCorrection:
    """Read a BJJCZ ``.cor`` file (either layout; module docstring)."""
    name, raw = read_input_bytes(path)
    label = raw[:0x16].decode("utf-16-le", errors="replace").rstrip("\x00")
    if label.startswith(V1_LABEL):
        if len(raw) < _V1_SIZE:
            raise InputError(name, f"LMC1COR_1.0 correction file is {len(raw)} bytes, "
                                   f"shorter than its {_V1_SIZE}")
        vals = np.frombuffer(raw, dtype="<f8", count=GRID * GRID * 2, offset=0x16 + 0x1FA)
    else:
        if len(raw) < _V2_SIZE:
            raise InputError(name, f"not a .cor correction file ({len(raw)} bytes; the "
                                   f"integer layout has {_V2_SIZE})")
        vals = np.frombuffer(raw, dtype="<i4", count=GRID * GRID * 2,
                             offset=0x16 + 0x0E).astype(np.float64)
    if not np.isfinite(vals).all():
        raise InputError(name, "the correction table holds values that are not numbers")
    t = vals.reshape(GRID, GRID, 2)
    if x_outer:
        t = t.transpose(1, 0, 2)
    if np.abs(t).max() > 32767:
        raise InputError(name, "a correction of more than 32767 bits: not a .cor table")
    return FieldCorrection(t[:, :, 0].copy(), t[:, :, 1].copy(), os.path.basename(name))


def write_cor(path: str | os.PathLike[str], corr: FieldCorrection,
              field_size_mm: float = 110.0) -> None:
    """Write the integer layout (``JCZ_COR_2_1``), Y outer, values rounded to whole bits."""
    from galvo_core.job import atomic_write_bytes

    label = "JCZ_COR_2_1".encode("utf-16-le").ljust(0x16, b"\0")[:0x16]
    head = label + b"\0" * 6 + struct.pack("<d", 65535 / field_size_mm)
    t = np.stack([corr.dx, corr.dy], axis=-1)
    atomic_write_bytes(path, head + np.round(t).astype("<i4").tobytes())


# ---------------------------------------------------------------------------- 3x3 grids
def _quad_weights(x: np.ndarray, nodes: tuple[float, float, float]) -> np.ndarray:
    """Lagrange weights (N, 3) of the three nodes at ``x``."""
    a, b, c = nodes
    return np.stack([(x - b) * (x - c) / ((a - b) * (a - c)),
                     (x - a) * (x - c) / ((b - a) * (b - c)),
                     (x - a) * (x - b) / ((c - a) * (c - b))], axis=1)


def from_3x3(errors_bits: np.ndarray, span_bits: float, centre: float = 32768.0,
             source: str = "3x3", iterations: int = 6) -> FieldCorrection:
    """A correction from nine measured errors. ``errors_bits`` (3, 3, 2) ``[iy, ix]``: where
    the mark aimed at ``(centre + (ix - 1) * span/2, centre + (iy - 1) * span/2)`` landed
    minus where it was aimed, in bits. The error field ``e`` is their biquadratic
    interpolation; the correction ``c`` at each node solves ``c = -e(p + c)`` (the mark,
    moved by ``c``, lands on ``p``), by fixed-point iteration."""
    e = np.asarray(errors_bits, dtype=np.float64)
    if e.shape != (3, 3, 2) or not np.isfinite(e).all():
        raise ValueError("a 3x3 measurement is 3 rows of 3 (dx, dy) errors")
    if not (math.isfinite(span_bits) and span_bits > 0):
        raise ValueError("span must be > 0")
    nodes = (centre - span_bits / 2, centre, centre + span_bits / 2)

    def err(p: np.ndarray) -> np.ndarray:
        wx = _quad_weights(p[:, 0], nodes)
        wy = _quad_weights(p[:, 1], nodes)
        return np.einsum("ni,nj,jik->nk", wx, wy, e)

    g = np.arange(GRID) * CELL
    gx, gy = np.meshgrid(g, g)  # [iy, ix]
    p = np.stack([gx.ravel(), gy.ravel()], axis=1)
    c = np.zeros_like(p)
    for _ in range(iterations):
        c = -err(p + c)
    return FieldCorrection(c[:, 0].reshape(GRID, GRID), c[:, 1].reshape(GRID, GRID), source)


def load_3x3(path: str | os.PathLike[str], field_bits: int = 65536,
             field_size_mm: float = 110.0) -> FieldCorrection:
    """Read a measured 3×3 grid from TOML::

        span_mm = 100            # distance between the outer rows (and columns) of marks
        # where each mark landed minus where it was aimed, mm; rows from -Y to +Y,
        # each row from -X to +X
        dx_mm = [[0.12, 0.0, -0.12], [0.1, 0.0, -0.1], [0.12, 0.0, -0.12]]
        dy_mm = [[0.12, 0.1, 0.12], [0.0, 0.0, 0.0], [-0.12, -0.1, -0.12]]
    """
    name = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            doc = tomllib.loads(fh.read().decode("utf-8"))
    except OSError as exc:
        raise InputError(name, f"cannot be read ({exc.strerror or exc})") from exc
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise InputError(name, f"not valid TOML: {exc}") from exc
    for key in doc:
        if key not in ("span_mm", "dx_mm", "dy_mm"):
            raise InputError(name, f"{key}: unknown key (known: span_mm, dx_mm, dy_mm)")
    bpm = field_bits / field_size_mm
    try:
        span = float(doc["span_mm"])
        dx = np.array(doc["dx_mm"], dtype=np.float64)
        dy = np.array(doc["dy_mm"], dtype=np.float64)
    except KeyError as exc:
        raise InputError(name, f"no {exc.args[0]}") from None
    except (TypeError, ValueError) as exc:
        raise InputError(name, f"span_mm is a number, dx_mm and dy_mm 3 rows of 3 numbers "
                               f"({exc})") from None
    if dx.shape != (3, 3) or dy.shape != (3, 3):
        raise InputError(name, "dx_mm and dy_mm must be 3 rows of 3 numbers")
    if not (math.isfinite(span) and 0 < span <= field_size_mm):
        raise InputError(name, f"span_mm must be in (0, {field_size_mm:g}]")
    if not (np.isfinite(dx).all() and np.isfinite(dy).all()):
        raise InputError(name, "dx_mm and dy_mm must be finite")
    return from_3x3(np.stack([dx, dy], axis=-1) * bpm, span * bpm,
                    source=os.path.basename(name))
