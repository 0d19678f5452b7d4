"""Round joins of an offset outline redrawn with fewer vertices, error on both sides.

GEOS draws the round join of an offset (radius ``d`` around an input vertex C) with its
vertices *on* the circle, so every chord cuts inside and a chord may span at most
``2 acos(1 - tol / d)``: a right-angle join at d = 29.8 and tol = 1 needs 4 chords. The arc
tolerance is a bound on the distance from the true arc, on either side; with the inner
vertices placed a little *outside* the circle (radius R <= d + tol) a chord may touch the
circle of radius d - tol, which allows chords of up to ``2 acos((d - tol) / (d + tol))``:
3 chords for that join (what Clipper2 draws there, at 1.0009 tol). Every point of the new
join stays within ``tol`` of the true arc.

:func:`two_sided_arcs` finds the joins in an outline (runs of at least three consecutive
vertices on one circle of radius ``d`` around an input vertex, turning one way), keeps
each run's end vertices (where the straight offset edges attach) and replaces its inner
vertices when that saves at least one. A polygon whose new rings are not valid keeps its
old rings. It works on GEOS's outline before any thinning (where each join still ends on
its tangent points) and says which vertices a thinning must keep. Input units throughout
(the caller's arc tolerance converted from bits).
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

__all__ = ["two_sided_arcs", "join_vertices"]

#: a vertex is on the circle of radius d around C when | |v - C| - d | <= this * d
_ON_CIRCLE = 1e-9
#: radii tried for the inner vertices, as fractions of tol above d
_RADII = np.linspace(1.0 - 1e-9, 0.0, 41)


def join_vertices(d: float, tol: float, phi: float) -> tuple[int, float] | None:
    """The fewest chords ``k`` (and the radius ``R`` of the ``k - 1`` inner vertices,
    equally spaced in angle) that draw a join of angle ``phi`` (radians, 0 < phi < 2 pi)
    and radius ``d`` from its end points on the circle within ``tol`` of the arc on both
    sides; ``None`` when tol >= d (no room) or nothing beats the one-sided count."""
    if not (0.0 < tol < d) or not (0.0 < phi < 2.0 * math.pi):
        return None
    one_sided = math.ceil(phi / (2.0 * math.acos(1.0 - tol / d)) - 1e-12)
    k0 = max(1, math.ceil(phi / (2.0 * math.acos((d - tol) / (d + tol))) - 1e-12))
    for k in range(k0, one_sided):
        a = phi / k
        for f in _RADII:
            r = d + f * tol
            if k > 1 and r * math.cos(a / 2.0) < d - tol:
                continue  # an inner chord dips below d - tol
            if k == 1:
                if d * math.cos(a / 2.0) >= d - tol:
                    return 1, d
                break
            # end chord from (d, 0) to (r cos a, r sin a): its closest point to C
            ex = r * math.cos(a) - d
            ey = r * math.sin(a)
            t = min(1.0, max(0.0, -d * ex / (ex * ex + ey * ey)))
            px = d + t * ex
            py = t * ey
            if math.hypot(px, py) >= d - tol:
                return k, r
    return None


def two_sided_arcs(
    geom: BaseGeometry, centres: np.ndarray, d: float, tol: float
) -> tuple[BaseGeometry, np.ndarray]:
    """``geom`` (valid (Multi)Polygon: GEOS's offset by ``d``, round joins, before any
    thinning, of a region whose vertices are ``centres`` (M, 2)) with its round joins
    redrawn by :func:`join_vertices`, and the (K, 2) vertices of the redrawn joins (their
    ends included), which a later thinning must keep: the joins already use the whole
    tolerance. Rings, polygons and their order are kept; a polygon that would come out
    invalid is kept as it was."""
    none = np.zeros((0, 2))
    if geom.is_empty or not (0.0 < tol < d) or len(centres) == 0:
        return geom, none
    parts = shapely.get_parts(geom)
    n_holes = shapely.get_num_interior_rings(parts)
    owner = np.repeat(np.arange(len(parts)), n_holes + 1)
    rings = shapely.get_rings(parts)
    xy, ring = shapely.get_coordinates(rings, return_index=True)
    tree = shapely.STRtree(shapely.points(centres))
    near, dist = tree.query_nearest(
        shapely.points(xy), return_distance=True, all_matches=False
    )
    cen = np.full(len(xy), -1, dtype=np.int64)
    cen[near[0]] = near[1]
    dd = np.full(len(xy), np.inf)
    dd[near[0]] = dist
    on = np.abs(dd - d) <= _ON_CIRCLE * d
    starts = np.flatnonzero(np.diff(ring, prepend=-1))
    ends = np.append(starts[1:], len(xy))
    new_rings: list[np.ndarray] = []
    fixed: list[list[np.ndarray]] = []
    changed = np.zeros(len(parts), dtype=bool)
    for r, (s, e) in enumerate(zip(starts.tolist(), ends.tolist(), strict=True)):
        pts = xy[s:e]
        got = _ring_joins(pts, cen[s:e], on[s:e], centres, d, tol)
        keep: list[np.ndarray] = []
        if got is not None:
            changed[owner[r]] = True
            pts, keep = got
        new_rings.append(pts)
        fixed.append(keep)
    if not changed.any():
        return geom, none
    polys = list(parts)
    protect: list[np.ndarray] = []
    for p in np.flatnonzero(changed).tolist():
        mine = np.flatnonzero(owner == p).tolist()
        rs = [new_rings[i] for i in mine]
        cand = shapely.Polygon(rs[0], rs[1:])
        if cand.is_valid and not cand.is_empty:
            polys[p] = cand
            for i in mine:
                protect.extend(fixed[i])
    out = polys[0] if len(polys) == 1 else shapely.MultiPolygon(polys)
    if not out.is_valid:
        return geom, none
    return out, (np.concatenate(protect) if protect else none)


def _ring_joins(
    pts: np.ndarray, cen: np.ndarray, on: np.ndarray, centres: np.ndarray, d: float,
    tol: float,
) -> tuple[np.ndarray, list[np.ndarray]] | None:
    """One closed ring (first point repeated last) with its joins redrawn, and the
    vertices of each redrawn join; None when nothing changes."""
    n = len(pts) - 1  # distinct vertices
    if n < 4:
        return None
    c = cen[:n]
    o = on[:n]
    # runs of consecutive on-circle vertices with one centre; start after a break so a run
    # never wraps past index 0 unless the whole ring is one run (then leave it alone)
    same = o & np.roll(o, 1) & (c == np.roll(c, 1))
    if same.all() or not o.any():
        return None
    first = int(np.flatnonzero(~same)[0])
    order = (np.arange(n) + first) % n
    out: list[np.ndarray] = []
    joins: list[np.ndarray] = []
    i = 0
    while i < n:
        j = i + 1
        while j < n and same[order[j]]:
            j += 1
        run = order[i:j]  # a maximal run (or a single vertex)
        if len(run) >= 3 and o[run[0]]:
            rep = _join(pts[run], centres[c[run[0]]], d, tol)
            if rep is not None:
                out.append(rep)
                joins.append(rep)
                i = j
                continue
        out.append(pts[run])
        i = j
    if not joins:
        return None
    body = np.concatenate(out)
    return np.vstack([body, body[:1]]), joins


def _join(run: np.ndarray, ctr: np.ndarray, d: float, tol: float) -> np.ndarray | None:
    """The vertices of one join (first and last kept, inner ones redrawn) or None."""
    v = run - ctr
    ang = np.unwrap(np.arctan2(v[:, 1], v[:, 0]))
    step = np.diff(ang)
    if not (np.all(step > 0) or np.all(step < 0)):
        return None  # not turning one way: not a join
    phi = float(abs(ang[-1] - ang[0]))
    got = join_vertices(d, tol, phi)
    if got is None:
        return None
    k, r = got
    if k >= len(run) - 1:
        return None
    th = ang[0] + (ang[-1] - ang[0]) * np.arange(1, k) / k
    inner = ctr + r * np.c_[np.cos(th), np.sin(th)]
    return np.vstack([run[:1], inner, run[-1:]])
