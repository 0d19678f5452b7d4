"""Round joins of an offset outline redrawn with fewer vertices, error on both sides.

GEOS draws the round join of an offset (radius ``d`` around an input vertex C) with its
vertices *on* the circle, so every chord cuts inside and a chord may span at most
``2 acos(1 - tol / d)``: a right-angle join at d = 29.8 and tol = 1 needs 4 chords. The arc
tolerance is a bound on the distance from the true arc, on either side; with the inner
vertices placed a little *outside* the circle (radius R <= d + tol) a chord may touch the
circle of radius d - tol, which allows chords of up to ``2 acos((d - tol) / (d + tol))``:
3 chords for that join (what Clipper2 draws there, at 1.0009 tol). Every point of the new
join stays within ``tol`` of the true arc.

:func:`two_sided_arcs` finds the joins in an outline (runs of vertices on one circle of
radius ``d``, turning one way), keeps each run's end vertices (where the straight offset
edges attach) and replaces its inner vertices when that saves at least one. A polygon
whose new rings are not valid keeps its old rings. It works on GEOS's outline before any
thinning (where each join still ends on its tangent points) and says which vertices a
thinning must keep. Input units throughout (the caller's arc tolerance converted from
bits).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

__all__ = ["two_sided_arcs", "join_vertices"]

#: an inner join vertex: the circle through it and its neighbours has radius d within
#: this * d (GEOS's arc vertices are on the circle to rounding; the circle through three of
#: them is found to about 1e-16 d / (chord angle)^2)
_ON_CIRCLE = 1e-7
#: neighbouring inner vertices of one join: their circles' centres within this * d
_SAME_CENTRE = 1e-6
#: radii tried for the inner vertices, as fractions of tol above d (a hair under 1: the
#: centre is known to rounding only)
_RADII = np.linspace(1.0 - 1e-6, 0.0, 41)


def join_vertices(d: float, tol: float, phi: float) -> tuple[int, float] | None:
    """The fewest chords ``k`` (and the radius ``R`` of the ``k - 1`` inner vertices,
    equally spaced in angle) that draw a join of angle ``phi`` (radians, 0 < phi < 2 pi)
    and radius ``d`` from its end points on the circle within ``tol`` of the arc on both
    sides; ``None`` when tol >= d (no room) or nothing beats the one-sided count."""
    k, r = join_plan(d, tol, np.array([phi], dtype=np.float64))
    return (int(k[0]), float(r[0])) if k[0] else None


def join_plan(d: float, tol: float, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`join_vertices` for many join angles at once: ``(k, R)`` per angle, k = 0
    where nothing beats the one-sided count (or tol >= d)."""
    phi = np.asarray(phi, dtype=np.float64)
    k_out = np.zeros(len(phi), dtype=np.int64)
    r_out = np.zeros(len(phi))
    if not (0.0 < tol < d) or not len(phi):
        return k_out, r_out
    ok_phi = (phi > 0.0) & (phi < 2.0 * math.pi)
    one_sided = np.ceil(phi / (2.0 * math.acos(1.0 - tol / d)) - 1e-12)
    k0 = np.maximum(2.0, np.ceil(phi / (2.0 * math.acos((d - tol) / (d + tol))) - 1e-12))
    r = d + _RADII * tol  # (F,), largest first
    for extra in range(3):
        k = k0 + extra
        todo = ok_phi & (k_out == 0) & (k < one_sided)
        if not todo.any():
            break
        a = (phi[todo] / k[todo])[:, None]  # (n, 1)
        inner = r * np.cos(a / 2.0) >= d - tol  # no inner chord dips below d - tol
        # end chord from (d, 0) to (r cos a, r sin a): its point closest to the centre
        ex = r * np.cos(a) - d
        ey = r * np.sin(a)
        t = np.clip(-d * ex / (ex * ex + ey * ey), 0.0, 1.0)
        good = inner & (np.hypot(d + t * ex, t * ey) >= d - tol)
        hit = good.any(axis=1)
        idx = np.flatnonzero(todo)[hit]
        k_out[idx] = k[idx].astype(np.int64)
        r_out[idx] = r[np.argmax(good[hit], axis=1)]
    return k_out, r_out


def two_sided_arcs(geom: BaseGeometry, d: float, tol: float, *, check: bool = True
                   ) -> tuple[BaseGeometry, np.ndarray]:
    """``geom`` (valid (Multi)Polygon: GEOS's offset by ``d``, round joins, before any
    thinning) with its round joins redrawn by :func:`join_plan`, and a mask over the
    result's vertices (``shapely.get_coordinates`` of its rings, polygon by polygon, each
    ring closed; empty when nothing changed) of those of the redrawn joins, their ends
    included, which a later thinning must keep: the joins already use the whole
    tolerance. Rings, polygons and their order are kept; a
    polygon that would come out invalid is kept as it was (with ``check=False`` the
    caller checks the result, which may then be invalid, and has ``geom`` to fall back
    on). Vectorised over all rings.

    A join is found from the outline alone: its inner vertices are those whose circle
    through them and their two neighbours has radius d (GEOS puts every arc vertex on the
    circle), with one centre along the run."""
    none = np.zeros(0, dtype=bool)
    if geom.is_empty or not (0.0 < tol < d):
        return geom, none
    parts = shapely.get_parts(geom)
    rings = _Rings.of(parts)
    runs = _join_runs(rings, d)
    if runs is None:
        return geom, none
    k, rr = join_plan(d, tol, np.where(runs.cand, np.abs(runs.phi), 0.0))
    use = runs.cand & (k > 0) & (k < runs.r_len - 1)
    if not use.any():
        return geom, none
    closed_xy, closed_ring, closed_prot, touched = _redrawn(rings, runs, use, k, rr)
    polys = shapely.polygons(shapely.linearrings(closed_xy, indices=closed_ring),
                             indices=rings.owner)
    changed = np.zeros(len(parts), dtype=bool)
    changed[rings.owner[touched]] = True
    polys, changed = _keep_valid(parts, polys, changed, check)
    if polys is None or not changed.any():
        return geom, none
    out = polys[0] if len(polys) == 1 else shapely.MultiPolygon(list(polys))
    return out, _keep_mask(rings, changed, closed_ring, closed_prot)


class _Rings:
    """The distinct vertices of every ring of some polygons (closing copies dropped), in
    order: ``xy``, ``ring`` (ring of each vertex), ``owner`` (polygon of each ring),
    ``size``/``start`` per ring, and each vertex's place, predecessor and successor in its
    ring."""

    def __init__(self, owner: np.ndarray, xy: np.ndarray, ring: np.ndarray) -> None:
        self.owner, self.xy, self.ring = owner, xy, ring
        self.n = len(owner)
        self.size = np.bincount(ring, minlength=self.n)
        self.start = np.concatenate(([0], np.cumsum(self.size)[:-1]))
        self.pos = np.arange(len(xy)) - self.start[ring]
        self.prev = self.start[ring] + (self.pos - 1) % self.size[ring]
        self.nxt = self.start[ring] + (self.pos + 1) % self.size[ring]

    @classmethod
    def of(cls, parts: np.ndarray) -> _Rings:
        n_holes = shapely.get_num_interior_rings(parts)
        owner = np.repeat(np.arange(len(parts)), n_holes + 1)
        xy_c, ring_c = shapely.get_coordinates(shapely.get_rings(parts), return_index=True)
        last = np.append(ring_c[1:] != ring_c[:-1], True)
        return cls(owner, xy_c[~last], ring_c[~last])


@dataclass(frozen=True)
class _Runs:
    """Candidate joins: each ring rotated to begin where a run begins (``xy``, ``same``:
    the edge into a vertex is a chord of the run), runs ``r_first..r_last`` (``run_id`` per
    vertex, ``r_len`` per run), each run's centre ``ctr``, signed sweep ``phi`` and whether
    it is a join (``cand``: on one circle of radius d, turning one way)."""

    xy: np.ndarray
    same: np.ndarray
    run_id: np.ndarray
    r_len: np.ndarray
    r_first: np.ndarray
    r_last: np.ndarray
    ctr: np.ndarray
    phi: np.ndarray
    cand: np.ndarray


def _join_runs(rings: _Rings, d: float) -> _Runs | None:
    """The runs of vertices on one circle of radius ``d`` turning one way (GEOS's round
    joins), found from the outline alone; None when there is none of 3 vertices or more."""
    xy, ring, start, size, pos = rings.xy, rings.ring, rings.start, rings.size, rings.pos
    prev, nxt, n_r = rings.prev, rings.nxt, rings.n
    cc, rad = _circumcircles(xy[prev], xy, xy[nxt])
    inner = (np.abs(rad - d) <= _ON_CIRCLE * d) & (size[ring] >= 4)
    # "same": the edge from a vertex's predecessor to it is a chord of one join
    with np.errstate(invalid="ignore"):  # (collinear triples: no finite centre)
        near_c = np.hypot(*(cc - cc[prev]).T) <= _SAME_CENTRE * d
    same = (inner | inner[prev]) & ~(inner & inner[prev] & ~near_c)
    # rotate every ring to begin at a vertex that starts a run (rings that are one whole
    # run, or have no join, are left alone)
    brk = ~same
    has_brk = np.bincount(ring, weights=brk, minlength=n_r) > 0
    big = np.iinfo(np.int64).max
    first_brk = np.full(n_r, big, dtype=np.int64)
    np.minimum.at(first_brk, ring[brk], pos[brk])
    first_brk[~has_brk] = 0
    rot = start[ring] + (pos + first_brk[ring]) % size[ring]  # new order -> old index
    xy, same = xy[rot], same[rot]
    same &= has_brk[ring]
    same[start] = False  # (a run never wraps past a ring's new start)
    # runs: maximal stretches start..end with same[] inside
    run_id = np.cumsum(~same) - 1
    n_run = int(run_id[-1]) + 1 if len(run_id) else 0
    r_len = np.bincount(run_id, minlength=n_run)
    r_first = np.flatnonzero(~same)
    r_last = r_first + r_len - 1
    cand = r_len >= 3
    if not cand.any():
        return None
    # each join's centre from its two ends and middle vertex (far apart: a well-conditioned
    # circle, where three neighbours a small angle apart would carry the rounding of large
    # coordinates into the centre)
    r_mid = r_first + r_len // 2
    ctr, rad = _circumcircles(xy[r_first], xy[r_mid], xy[r_last])
    cand &= np.abs(rad - d) <= _ON_CIRCLE * d
    ctr[~cand] = 0.0
    # turning of each candidate run around its centre: every step the same way
    v = xy - ctr[run_id]
    with np.errstate(invalid="ignore", over="ignore"):  # (only candidate runs are read)
        step = np.arctan2(v[:-1, 0] * v[1:, 1] - v[:-1, 1] * v[1:, 0],
                          v[:-1, 0] * v[1:, 0] + v[:-1, 1] * v[1:, 1])
    step = np.append(step, 0.0)
    inner_steps = same[1:]  # step i -> i + 1 lies inside a run
    stp = np.where(np.append(inner_steps, False), step, 0.0)
    pos_n = np.bincount(run_id, weights=(stp > 0), minlength=n_run)
    neg_n = np.bincount(run_id, weights=(stp < 0), minlength=n_run)
    phi = np.bincount(run_id, weights=stp, minlength=n_run)
    cand &= (pos_n == r_len - 1) | (neg_n == r_len - 1)
    return _Runs(xy=xy, same=same, run_id=run_id, r_len=r_len, r_first=r_first,
                 r_last=r_last, ctr=ctr, phi=phi, cand=cand)


def _redrawn(rings: _Rings, runs: _Runs, use: np.ndarray, k: np.ndarray, rr: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The rings with the joins ``use`` redrawn (``k`` chords each, inner vertices at radius
    ``rr``): closed coordinates, their ring, whether each is protected (a redrawn join's
    vertex, ends included), and the rings touched."""
    xy, same, ring = runs.xy, runs.same, rings.ring
    r_first, r_last, ctr, phi = runs.r_first, runs.r_last, runs.ctr, runs.phi
    # the new joins: first vertex, k - 1 inner ones, last vertex
    u = np.flatnonzero(use)
    ku = k[u]
    a0 = np.arctan2(xy[r_first[u], 1] - ctr[u, 1], xy[r_first[u], 0] - ctr[u, 0])
    n_in = ku - 1
    jrun = np.repeat(np.arange(len(u)), n_in)
    jj = np.arange(int(n_in.sum())) - np.repeat(np.cumsum(n_in) - n_in, n_in) + 1
    th = a0[jrun] + phi[u][jrun] * jj / ku[jrun]
    new_xy = ctr[u][jrun] + rr[u][jrun, None] * np.c_[np.cos(th), np.sin(th)]
    new_key = r_first[u][jrun] + jj / ku[jrun]  # between the run's first and last
    drop = np.zeros(len(xy), dtype=bool)
    inner_v = same.copy()  # a run's vertices past its first ...
    inner_v[r_last] = False  # ... and before its last
    drop[inner_v & use[runs.run_id]] = True
    ends_v = np.zeros(len(xy), dtype=bool)  # the used joins' end vertices
    ends_v[r_first[u]] = True
    ends_v[r_last[u]] = True
    # merge the kept vertices (positions in xy, rings in order) and the new ones (after
    # their run's first vertex): both lists are sorted, so each one's place in the merged
    # list is its own rank plus the count of the other list before it
    kept_at = np.flatnonzero(~drop)
    n_all = len(kept_at) + len(new_key)
    p_new = np.searchsorted(kept_at, new_key) + np.arange(len(new_key))
    p_old = np.searchsorted(new_key, kept_at) + np.arange(len(kept_at))
    all_xy = np.empty((n_all, 2))
    all_xy[p_old] = xy[kept_at]
    all_xy[p_new] = new_xy
    all_ring = np.empty(n_all, dtype=ring.dtype)
    all_ring[p_old] = ring[kept_at]
    all_ring[p_new] = ring[r_first[u]][jrun]
    all_prot = np.ones(n_all, dtype=bool)
    all_prot[p_old] = ends_v[kept_at]
    # close the rings
    starts2 = np.flatnonzero(np.diff(all_ring, prepend=-1))
    at = np.append(starts2[1:], len(all_xy))
    closed_xy = np.insert(all_xy, at, all_xy[starts2], axis=0)
    closed_ring = np.insert(all_ring, at, all_ring[starts2])
    closed_prot = np.insert(all_prot, at, all_prot[starts2])
    return closed_xy, closed_ring, closed_prot, np.unique(ring[r_first[u]])


def _keep_valid(parts: np.ndarray, polys: np.ndarray, changed: np.ndarray, check: bool
                ) -> tuple[np.ndarray | None, np.ndarray]:
    """The unchanged polygons exactly as they came; with ``check``, a changed polygon that
    is not valid, or now meets another, keeps its old rings (None: give up on all)."""
    polys[~changed] = parts[~changed]
    ch = np.flatnonzero(changed)
    bad = ch[~(shapely.is_valid(polys[ch]) & ~shapely.is_empty(polys[ch]))] if check else ch[:0]
    polys[bad] = parts[bad]
    changed[bad] = False
    if check and len(polys) > 1 and changed.any():
        # the polygons were valid together; a changed one that now meets another (even
        # at a point) keeps its old rings, and so does the other if it changed
        ch = np.flatnonzero(changed)
        i, j = shapely.STRtree(polys).query(polys[ch], predicate="intersects")
        meet = np.unique(np.concatenate([ch[i][ch[i] != j], j[ch[i] != j]]))
        meet = meet[changed[meet]]
        polys[meet] = parts[meet]
        changed[meet] = False
        if len(meet) and not shapely.MultiPolygon(list(polys)).is_valid:
            return None, changed  # (a reverted polygon meets another changed one: rare)
    return polys, changed


def _keep_mask(rings: _Rings, changed: np.ndarray, closed_ring: np.ndarray,
               closed_prot: np.ndarray) -> np.ndarray:
    """The mask over the result's vertices (rings in order, each closed): a changed ring's
    from ``closed_prot``, the others' all False."""
    n_r = rings.n
    new_ring = changed[rings.owner]
    cnt = np.where(new_ring, np.bincount(closed_ring, minlength=n_r), rings.size + 1)
    first = np.concatenate(([0], np.cumsum(cnt)[:-1]))
    mask = np.zeros(int(cnt.sum()), dtype=bool)
    sel = new_ring[closed_ring]
    row0 = np.concatenate(([0], np.cumsum(np.bincount(closed_ring, minlength=n_r))[:-1]))
    dest = first[closed_ring[sel]] + (np.flatnonzero(sel) - row0[closed_ring[sel]])
    mask[dest] = closed_prot[sel]
    return mask


def _circumcircles(a: np.ndarray, b: np.ndarray, c: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Centre (K, 2) and radius (K,) of the circle through a[k], b[k], c[k] (inf radius
    where they are collinear)."""
    ax, ay = a[:, 0] - b[:, 0], a[:, 1] - b[:, 1]
    cx, cy = c[:, 0] - b[:, 0], c[:, 1] - b[:, 1]
    den = 2.0 * (ax * cy - ay * cx)
    a2 = ax * ax + ay * ay
    c2 = cx * cx + cy * cy
    with np.errstate(divide="ignore", invalid="ignore"):
        ux = (cy * a2 - ay * c2) / den
        uy = (ax * c2 - cx * a2) / den
    r = np.hypot(ux, uy)
    r[~np.isfinite(r)] = np.inf
    return np.c_[ux + b[:, 0], uy + b[:, 1]], r
