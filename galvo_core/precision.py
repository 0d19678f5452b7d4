"""The coordinate quantum of a drawing: the grid its points were rounded to (issue 16).

Most PLT files write whole plotter units, HP-GL/2 files with decimals write steps of 0.1,
0.01 or 0.001 unit, and a file using SC/IP scaling writes a grid of step ``q`` and some
offset (user units k mapped to ``q·k + offset`` plotter units). Every input point is then
the design point rounded to that grid, up to ``q/2`` off per axis (``q/√2`` on the
diagonal). The fitter treats each point as its *rounding square* (side ``q``): see
:mod:`galvo_core.fit`.

Detection, per axis: the steps between the sorted distinct coordinates must all be whole
multiples of one step ``q`` (their greatest common divisor, found by Euclid's algorithm on
floats with a tolerance that absorbs the float error of parsing and scaling: 1e-6 of ``q``
plus 1e-12 of the largest coordinate). Float input with no grid gives 0. Too little
evidence (fewer than ``MIN_DISTINCT`` distinct values on both axes, or a step larger than a
twentieth of the extent: a rectangle's corners say nothing about a grid) gives 0 too. The
quantum of the two axes is the larger one (the rounding rectangle's bigger side; a scaled
file with unequal steps is treated as squares of the larger step).

Units: the coordinates' (input units). 0.0 means "no rounding" (exact input).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "MIN_DISTINCT",
    "axis_quantum",
    "coordinate_quantum",
    "drawing_quantum",
    "path_quanta",
    "on_grid",
]

#: distinct values an axis needs before a grid is believed
MIN_DISTINCT = 8
#: a grid step may be at most this fraction of the axis's extent
_MAX_STEP_SHARE = 1.0 / 20.0
#: relative tolerance of "a whole multiple of q"
_REL_TOL = 1e-6
#: the drawing's grid is detected on an even sample of at most this many points
_SAMPLE = 1 << 16
#: a path's own grid is first looked for on a sample of this many of its points
_PATH_SAMPLE = 4096
#: decimal grids tried for paths off the drawing's grid (coarsest first)
_DECIMAL_STEPS = (1.0, 0.1, 0.01, 0.001)
#: paths off every decimal grid get their own detection when at most this many are left
_OWN_GRID_PATHS = 64
#: at most this many distinct steps go through Euclid's algorithm (then all are verified)
_GCD_SAMPLE = 64


def _fgcd(a: float, b: float, tol: float) -> float:
    """Greatest common divisor of two positive floats: Euclid, remainders within ``tol``
    of 0 (or of the divisor) count as 0."""
    if a < b:
        a, b = b, a
    for _ in range(64):
        if b <= tol:
            return a
        r = a % b
        if r <= tol or b - r <= tol:
            return b
        a, b = b, r
    return 0.0


def axis_quantum(values: object) -> tuple[float, float]:
    """(q, offset) of one axis's coordinates: every value is ``offset + k·q`` (k whole,
    within the tolerance of the module doc), q the largest such step; (0.0, 0.0) when there
    is no grid or too little evidence for one. ``offset`` is in [0, q)."""
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    v = v[np.isfinite(v)]
    if len(v) == 0:
        return 0.0, 0.0
    u = np.unique(v)
    if len(u) < MIN_DISTINCT:
        return 0.0, 0.0
    scale = float(np.abs(u).max())
    extent = float(u[-1] - u[0])
    d = np.diff(u)
    ftol = 1e-12 * max(scale, 1.0)  # float noise of the coordinates themselves
    dmin = float(d.min())
    if dmin <= 4.0 * ftol:
        return 0.0, 0.0
    # Euclid over a sample of the distinct steps (the smallest first: most informative)
    ds = np.unique(d)
    cand = ds[: _GCD_SAMPLE // 2]
    if len(ds) > len(cand):
        pick = np.linspace(len(cand), len(ds) - 1, _GCD_SAMPLE // 2).astype(np.intp)
        cand = np.concatenate([cand, ds[pick]])
    g = float(cand[0])
    for x in cand[1:].tolist():
        g = _fgcd(g, x, _REL_TOL * g + ftol)
        if g <= 4.0 * ftol:
            return 0.0, 0.0
    if g > _MAX_STEP_SHARE * extent:
        return 0.0, 0.0
    # every step a whole multiple of g
    tol = _REL_TOL * g + ftol * 4.0
    k = d / g
    if np.abs(d - np.round(k) * g).max() > tol * np.maximum(1.0, np.sqrt(np.round(k))).max():
        return 0.0, 0.0
    g = float(f"{g:.9g}")  # (0.09999999999999432 -> 0.1)
    off = float(u[0] % g)
    if g - off <= tol:
        off = 0.0
    return g, off


def coordinate_quantum(points: object) -> float:
    """The grid step ``q`` of points (N, 2) (input units): the larger of the two axes'
    steps (:func:`axis_quantum`), 0.0 for exact (off-grid) input or too few points."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if len(p) == 0:
        return 0.0
    qx, _ = axis_quantum(p[:, 0])
    qy, _ = axis_quantum(p[:, 1])
    if qx == 0.0 and qy == 0.0:
        return 0.0
    if qx == 0.0 or qy == 0.0:
        # one axis on a grid, the other not (or too few values): believe the grid only if
        # the other axis has too few values to say (e.g. a path of horizontal hatch lines)
        other = p[:, 1] if qx else p[:, 0]
        if len(np.unique(other)) >= MIN_DISTINCT:
            return 0.0
    return max(qx, qy)


def on_grid(points: object, q: float, offset: tuple[float, float] = (0.0, 0.0)) -> bool:
    """True when every coordinate of ``points`` is ``offset + k·q`` (k whole) within the
    tolerance of the module doc (``q`` > 0)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if len(p) == 0 or q <= 0.0:
        return len(p) == 0
    return bool(_on_grid_each(p, q, offset).all())


#: points per numpy call of :func:`_on_grid_each` (a drawing's million points are verified
#: in short calls: a GUI thread waiting on the GIL is not held up for the whole test)
_GRID_CHUNK = 1 << 16


def _on_grid_each(p: np.ndarray, q: float, offset: tuple[float, float],
                  chunk: int = _GRID_CHUNK) -> np.ndarray:
    """Per point: both coordinates on the grid (see :func:`on_grid`), ``chunk`` points per
    numpy call (the same answer for any chunk: the tolerance's scale is the largest
    coordinate of all the points)."""
    n = len(p)
    scale = 0.0
    for c in range(0, n, chunk):
        scale = max(scale, float(np.abs(p[c:c + chunk]).max()))
    tol = _REL_TOL * q + 4e-12 * max(scale, 1.0)
    off = np.asarray(offset, dtype=np.float64)
    out = np.empty(n, dtype=bool)
    for c in range(0, n, chunk):
        r = (p[c:c + chunk] - off) / q
        m = np.abs(r - np.round(r)) * q <= tol
        np.logical_and(m[:, 0], m[:, 1], out=out[c:c + chunk])  # (.all(axis=1), faster)
    return out


def drawing_quantum(paths: Sequence[object]) -> tuple[float, tuple[float, float]]:
    """(q, (offset_x, offset_y)) of all the points of a drawing's paths together (each an
    (N, 2) array or a :class:`~galvo_core.drawing.Path`): see :func:`coordinate_quantum`."""
    arrs = [np.asarray(getattr(p, "points", p), dtype=np.float64).reshape(-1, 2) for p in paths]
    if not any(len(a) for a in arrs):
        return 0.0, (0.0, 0.0)
    return _quantum_of(np.concatenate(arrs))


def _quantum_of(allp: np.ndarray) -> tuple[float, tuple[float, float]]:
    """:func:`drawing_quantum` of the points ``allp`` (N, 2), N > 0."""
    q, off, _ = _quantum_each(allp)
    return q, off


def _quantum_each(
    allp: np.ndarray,
) -> tuple[float, tuple[float, float], np.ndarray | None]:
    """:func:`_quantum_of` and, where its verification on all the points made it, the
    per-point test of :func:`_on_grid_each` (all True then; else None)."""
    # detected on an even sample of at most _SAMPLE points, then verified on all of them
    sample = allp[:: max(1, len(allp) // _SAMPLE)]
    qx, ox = axis_quantum(sample[:, 0])
    qy, oy = axis_quantum(sample[:, 1])
    q = coordinate_quantum(sample)
    if q == 0.0:
        return 0.0, (0.0, 0.0), None
    # a grid of the larger step: offsets of that axis; the other axis's own offset
    off = (ox if qx == q else 0.0, oy if qy == q else 0.0)
    if len(sample) < len(allp):
        each = _on_grid_each(allp, q, off)
        if not each.all():
            return 0.0, (0.0, 0.0), None
        return q, off, each
    return q, off, None


def path_quanta(paths: Sequence[object]) -> np.ndarray:
    """Per path its quantum (input units): the drawing's (:func:`drawing_quantum`) for a path
    whose points lie on the drawing's grid, else the path's own (:func:`coordinate_quantum`
    of its points alone, 0.0 when they are exact or too few to tell)."""
    arrs = [np.asarray(getattr(p, "points", p), dtype=np.float64).reshape(-1, 2) for p in paths]
    out = np.zeros(len(arrs))
    n = np.fromiter(map(len, arrs), dtype=np.intp, count=len(arrs))
    good = np.zeros(len(arrs), dtype=bool)
    allp = np.concatenate(arrs) if n.sum() else None
    q, off, ok = (0.0, (0.0, 0.0), None) if allp is None else _quantum_each(allp)
    if q > 0.0 and allp is not None:
        if ok is None:  # (else the verification's)
            ok = _on_grid_each(allp, q, off)
        nz = np.flatnonzero(n)
        good[nz] = np.logical_and.reduceat(ok, np.cumsum(n[nz]) - n[nz])
        out[good] = q
    rest = np.flatnonzero(~good & (n >= MIN_DISTINCT))
    if len(rest) == 0:
        return out
    # off the drawing's grid: the coarsest decimal grid a path lies on (one vectorised test
    # per step for all such paths; exact paths are told by their first 64 points), else its
    # own grid (detected on a sample, verified on all) when few paths are left
    m = np.minimum(n[rest], 64)
    head = np.concatenate([arrs[i][:64] for i in rest.tolist()])
    hst = np.cumsum(m) - m
    undecided = np.ones(len(rest), dtype=bool)
    for step in _DECIMAL_STEPS:
        cand = undecided & np.logical_and.reduceat(_on_grid_each(head, step, (0.0, 0.0)), hst)
        for i in np.flatnonzero(cand).tolist():
            if on_grid(arrs[rest[i]], step):
                out[rest[i]] = step
                undecided[i] = False
    left = rest[undecided]
    if len(left) <= _OWN_GRID_PATHS:
        for i in left.tolist():
            a_ = arrs[i]
            if coordinate_quantum(a_[:: max(1, len(a_) // _PATH_SAMPLE)]) > 0.0:
                out[i] = drawing_quantum([a_])[0]
    return out
