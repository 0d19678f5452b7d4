"""Kerf (laser trough) compensation: grow or shrink the design's regions (seed paper 003).

The beam marks a trough ``kerf_mm`` wide on the workpiece, so every region boundary is moved
by ``d = kerf_mm / 2`` (converted to input units with :meth:`FieldMap.mm_to_units`).

Sign convention (explicit, as design/methods.md §5 asks)
--------------------------------------------------------
``side="outside"`` **grows** the design's regions: outer rings move outwards, holes move
inwards (the paper's case: raised characters whose background is burnt away, so the trough
must run outside the strokes). ``side="inside"`` **shrinks** them (the trough runs inside
the outline). Regions come from the closed paths of one pen by the even-odd rule: a point
inside an odd number of rings is in the region (so a ring inside another is a hole, and
where two rings overlap the overlap is a hole, as a ray-crossing hatch fill would mark it).
Different pens are different layers and are compensated separately. Open paths, dots and
closed paths that enclose no area are left as they are (one warning says how many).

Methods
-------
``"vector"`` (default, the paper's *parallel movement*): the exact parallel offset of the
even-odd region by shapely/GEOS ``buffer`` with round joins. At a convex corner the offset
is an arc of radius ``d`` around the corner (the paper replaces the far-away intersection at
acute corners by that arc); concave corners are exact intersections. GEOS draws the arcs
finely, with ``quad_segs`` segments per quarter circle chosen so the sagitta of every chord,
``d (1 - cos(θ/2))``, is within 1/16 of the arc tolerance ``tol`` (``arc_tol_bits`` galvo
bits), and never fewer than 8 (GEOS is less exact below 8; see :func:`quad_segs_for`).
Each round join is then redrawn with its inner vertices just inside ``d + tol`` (the error
on both sides of the arc: :mod:`galvo_core.offset_arcs`), which takes fewer chords than
GEOS's on-circle ones (a right angle at d/tol = 30: 3 instead of 4, as Clipper2 draws it),
and the rest of the outline is thinned by Douglas-Peucker within the rest of the budget,
``tol - sagitta`` (:func:`reduce_vertices`: valid, same rings, else unthinned; the redrawn
joins are kept, and a polygon they would make invalid falls back to GEOS's), so every
point stays within ``tol`` of GEOS's exact offset while arcs end up with no more chords
than Clipper2 draws at the same tolerance, and densely sampled input curves lose the
vertices the tolerance does not need. (GEOS also drops concave input vertices less than
``d/100`` deep before buffering, as its exact reference does; bench/RESULTS.md compares
both with Clipper2 at a fine tolerance.) GEOS handles holes,
self-touching rings, rings that vanish and rings that merge. Each polygon of the region is
buffered on its own, except that polygons no more than ``2 d`` apart (whose grown versions
may meet) are buffered group by group as one MultiPolygon each (dense groups of many small
polygons: one by one, then unioned); one buffer of a MultiPolygon of thousands of parts
nodes them all together: 5x slower on a corpus file;
sliver holes that only the chords of meeting arcs leave (no point in them is farther than
``d`` from the region) are removed, as the laser would mark them as tiny loops.
Why GEOS and not Clipper2: shapely (GEOS) is already a dependency, is well kept, gives the
same result within the arc tolerance (bench/RESULTS.md, "Kerf (issue 6)"), and works on
floating-point coordinates;
Clipper2's Python bindings ``pyclipr`` ship no wheel for this platform (its source build
fails), so a Clipper2 dependency would be a build risk for every user.

``"raster"`` (the paper's *zero-point expansion*): rasterise the even-odd region at a
resolution of ``raster_res_bits`` (default: 1 galvo bit, coarsened so the raster has at most
about 4 Mpixel and the disc radius is at most 64 pixels), compute the Euclidean distance to
the nearest kept (``outside``) or removed (``inside``) pixel by two separable passes
(numpy only), threshold it at ``d`` and trace the level set back to rings by marching
squares with linear interpolation (vectorised: cycles are linked by pointer jumping), then
simplify within half a pixel. Accuracy: about two pixels (a pixel centre lies up to a pixel
inside the true boundary, corrected on average by half a pixel, plus half a pixel of
simplification). Time grows with the disc radius in pixels, as the paper says.

``"rectangle"`` (the paper's *solid rectangles*): hatch each region with horizontal scan
segments ``h = d/4`` apart, make each segment (standing for a strip of height ``h``) a solid
rectangle reaching ``d`` beyond it on every side, and take the union (GEOS ``union_all``);
``inside`` does the same to the complement within a bounding box and subtracts it. A
rectangle is the Minkowski sum with a square, so edges at 45° move by up to ``d·√2``;
horizontal edges are off by up to ``h/2``, and the staircase is simplified within ``h/2``:
the stated tolerance is ``(√2 - 1) d + h`` for ``outside``. Larger where the scan lines
sample badly or squares compound: for ``inside`` a convex corner of angle θ can be off by
``(√2 - 1) d / sin(θ/2) + h``, and a sharp tip pointing along the scan lines loses up to
``(h/2) / tan(θ/2)`` (bench/RESULTS.md has the numbers).

Mapping back to the source paths (``source_index``)
---------------------------------------------------
:func:`compensate_indexed` returns the new drawing and ``origin``: ``origin[k]`` is the index
in the *input* drawing of the path that output path ``k`` came from. The output keeps the
input's path order: for each input path in turn, an open path is copied unchanged; a closed
ring is replaced by the compensated rings assigned to it (zero, one or several). A
compensated ring is assigned to the *lowest index* among the source rings that its vertices
are nearest to; so a ring that splits into two keeps its index for both, and rings that
merge take the first (lowest) index. A source
ring that no output ring touches has vanished (``inside``: narrower than the kerf) or been
swallowed (``outside``: a hole closed up); each gives a warning naming the path and its
place in the file. Output rings keep ``pen`` and ``start`` of their source ring, are closed
(first point == last point), exteriors counter-clockwise, holes clockwise, each starting at
the vertex nearest to the source ring's first point.
"""

from __future__ import annotations

import ctypes
import glob
import math
import os
import threading
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from galvo_core.drawing import Drawing, Path, Warning
from galvo_core.errors import ParamError
from galvo_core.field import FieldMap
from galvo_core.geometry import point_segment_distance
from galvo_core.offset_arcs import two_sided_arcs
from galvo_core.params import KERF_METHODS, KERF_SIDES

#: default raster size limit (pixels) and largest disc radius (pixels) for ``raster``
RASTER_MAX_PIXELS = 4_000_000
RASTER_MAX_RADIUS_PX = 64.0
#: an explicit raster_res_bits may not make a raster larger than this
RASTER_HARD_LIMIT = 25_000_000
#: quad_segs bounds for the vector method
MAX_QUAD_SEGS = 512
#: GEOS buffers with fewer segments per quarter circle than this are less exact (see
#: quad_segs_for); the vector method never goes below it
GEOS_MIN_QUAD_SEGS = 8
#: the vector method's GEOS arcs are drawn with chords whose sagitta is at most this share
#: of the arc tolerance; the rest of the tolerance is the budget of the vertex reduction
ARC_SHARE = 1.0 / 16.0
#: output vertices sampled when mapping rings back to their sources
ASSIGN_STRIDE = 4
#: scan spacing of the rectangle method as a fraction of d
RECT_SPACING = 0.25
#: the even-odd ray test cuts the plane into columns of about this many edge ends each
CROSS_COLUMN_EDGES = 512
#: ... unless the plain ray count pairs at most this many times (points + edges)
CROSS_PLAIN_PAIRS = 8


# --------------------------------------------------------------------------- public API
def compensate(
    drawing: Drawing,
    *,
    kerf_mm: float,
    side: str,
    method: str,
    fm: FieldMap,
    arc_tol_bits: float = 1.0,
    raster_res_bits: float | None = None,
) -> Drawing:
    """A new drawing whose closed regions are grown (``outside``) or shrunk (``inside``) by
    ``kerf_mm / 2`` on the workpiece. ``kerf_mm == 0`` returns ``drawing`` itself.

    See the module docstring for the methods, the sign convention and how output paths map
    to input paths (use :func:`compensate_indexed` to get that mapping).
    """
    return compensate_indexed(drawing, kerf_mm=kerf_mm, side=side, method=method, fm=fm,
                              arc_tol_bits=arc_tol_bits, raster_res_bits=raster_res_bits)[0]


@dataclass(frozen=True, eq=False)
class KerfRegions:
    """What the kerf stage derives from the drawing alone, whatever the kerf width, side,
    method and field mapping: the closed rings that enclose area, the other paths, and per
    pen the rings' indices and their even-odd region (:func:`even_odd_region`: about half
    of a kerf change on the many-ring corpus files). Made by :func:`kerf_regions`; a
    caller that compensates one drawing at several kerf widths (the GUI's pipeline) keeps
    it and passes it to :func:`compensate_indexed`."""

    drawing: Drawing
    rings: tuple[int, ...]
    passthrough: frozenset[int]
    pens: tuple[tuple[tuple[int, ...], BaseGeometry], ...]
    bbox: tuple[float, float, float, float] | None
    #: per pen (its place in ``pens``), made when first needed: the tree of all its
    #: rings' segments that maps output vertices back to their source (see
    #: :class:`_SourceSegments`)
    segments: dict[int, _SourceSegments] = field(default_factory=dict)


def kerf_regions(drawing: Drawing, bbox: tuple[float, float, float, float] | None = None
                 ) -> KerfRegions:
    """The kerf-independent part of :func:`compensate_indexed` for ``drawing`` (``bbox``:
    ``drawing.bbox()`` when at hand)."""
    rings, passthrough = _split(drawing)
    pens = tuple((tuple(idx), even_odd_region([drawing.paths[i].points for i in idx]))
                 for idx in _by_pen(drawing, rings).values())
    return KerfRegions(drawing, tuple(rings), frozenset(passthrough), pens,
                       bbox if bbox is not None else drawing.bbox())


def compensate_indexed(
    drawing: Drawing,
    *,
    kerf_mm: float,
    side: str,
    method: str,
    fm: FieldMap,
    arc_tol_bits: float = 1.0,
    raster_res_bits: float | None = None,
    regions: KerfRegions | None = None,
) -> tuple[Drawing, tuple[int, ...]]:
    """Like :func:`compensate`, also returning ``origin``: for each output path, the index
    of the input path it came from (non-decreasing). ``regions``: :func:`kerf_regions` of
    ``drawing`` when at hand (the result is the same)."""
    if regions is not None and regions.drawing is not drawing:
        raise ValueError("compensate_indexed: regions were made from another drawing")
    bbox = _check(drawing, kerf_mm, side, method, fm, arc_tol_bits, raster_res_bits,
                  None if regions is None else regions.bbox)
    n = len(drawing.paths)
    if kerf_mm == 0:
        return drawing, tuple(range(n))
    d = fm.mm_to_units(kerf_mm / 2.0)
    tol = fm.bits_to_units(arc_tol_bits)
    res_auto = raster_res_bits is None
    res = fm.bits_to_units(1.0 if raster_res_bits is None else raster_res_bits)

    if regions is None:
        regions = kerf_regions(drawing, bbox)
    rings, passthrough = regions.rings, regions.passthrough
    out_by_src: dict[int, list[np.ndarray]] = {}
    touched: set[int] = set()
    for k, (idx, region) in enumerate(regions.pens):
        result = _apply(region, d, side, method, tol, res, res_auto)
        reach = d + 2 * tol if method == "vector" else 1.5 * d + 2 * res
        assign, contrib = _assign(result, [drawing.paths[i].points for i in idx], reach,
                                  regions.segments, k)
        touched.update(idx[j] for j in contrib)
        for ring, j in assign:
            out_by_src.setdefault(idx[j], []).append(ring)

    starts = _starts_near([(ring, drawing.paths[i].points[0])
                           for i in sorted(out_by_src) for ring in out_by_src[i]])
    paths: list[Path] = []
    origin: list[int] = []
    k = 0
    for i, p in enumerate(drawing.paths):
        if i in passthrough:
            paths.append(p)
            origin.append(i)
            continue
        for _ in out_by_src.get(i, []):
            paths.append(p.with_points(starts[k], closed=True))
            origin.append(i)
            k += 1

    warnings: list[Warning] = []
    if passthrough:
        first = drawing.paths[min(passthrough)].start
        warnings.append(Warning(0, 0, (
            f"kerf compensation: {len(passthrough)} open or degenerate paths (not closed "
            f"rings enclosing area) were left as they are (the first at {first})")))
    for i in rings:
        if i in touched:
            continue
        p = drawing.paths[i]
        what = ("vanished: it is narrower than the kerf" if side == "inside" else
                "was swallowed: the grown regions cover it (a hole closed up)")
        warnings.append(Warning(p.start.line, p.start.col, (
            f"kerf compensation ({side}, {kerf_mm:g} mm): path {i} (pen {p.pen}, "
            f"{p.start}) {what}")))
    return drawing.with_paths(paths, warnings=warnings), tuple(origin)


def arc_sagitta(d: float, quad_segs: int) -> float:
    """Largest distance between an arc of radius ``d`` and its chords when a quarter
    circle is drawn with ``quad_segs`` chords (GEOS puts the chord ends on the circle)."""
    return d * (1.0 - math.cos(math.pi / (4.0 * quad_segs)))


def quad_segs_for(d: float, tol: float) -> int:
    """Segments per quarter circle of the vector method's GEOS buffer: the fewest whose
    chord sagitta on radius ``d`` is <= ``ARC_SHARE * tol`` (the rest of ``tol`` is left to
    :func:`reduce_vertices`, which thins the result to about Clipper2's vertex count).

    Never fewer than :data:`GEOS_MIN_QUAD_SEGS`: below 8 segments per quarter circle GEOS
    joins short concave runs through a point halfway to the vertex instead of 1/81 of the
    way, which put outlines up to ~10 % of ``d`` off on dense CAD polylines (measured:
    bench/RESULTS.md, "Kerf (issue 6)"). Never more than :data:`MAX_QUAD_SEGS`."""
    if d <= 0:
        return GEOS_MIN_QUAD_SEGS
    s = ARC_SHARE * tol
    if s >= d:
        q = 1
    else:
        theta = 2.0 * math.acos(1.0 - s / d)
        q = int(min(MAX_QUAD_SEGS, max(1, math.ceil((math.pi / 2.0) / theta))))
    return max(q, GEOS_MIN_QUAD_SEGS)


def reduce_tol_for(d: float, tol: float) -> float:
    """How far :func:`reduce_vertices` may move the vector method's outline: the arc
    tolerance less the sagitta of the GEOS arcs (so arcs stay within ``tol`` of the true
    circle), never negative."""
    return max(0.0, tol - arc_sagitta(d, quad_segs_for(d, tol)))


def reduce_vertices(geom: BaseGeometry, eps: float, keep: np.ndarray | None = None
                    ) -> BaseGeometry:
    """``geom`` (a valid (Multi)Polygon) with fewer vertices, each ring moved by at most
    ``eps`` (symmetric Hausdorff distance between the old and the new ring).

    Guaranteed, and checked on the result: it is valid, keeps every polygon and every hole
    (same counts, same order, same first vertex per ring), each ring's vertices are a
    subsequence of its old vertices, and every dropped vertex lies within ``eps`` of the
    chord that replaces it (so each chord is within ``eps`` of the stretch it replaces and
    the other way round). What fails a check is put back as it was: a ring, a polygon, or
    (when thinned polygons come to overlap) the polygons concerned; ``geom`` itself when
    nothing else gives a valid result.

    Which vertices to keep comes from GEOS's Douglas-Peucker on each ring on its own (fast:
    no repair of the whole geometry), for a polygon that comes out invalid from GEOS's
    topology-preserving variant on that polygon (its rings cannot cross or collapse). Each
    ring's first vertex is kept: GEOS drops a ring's end point by looking at that vertex
    alone, which can leave vertices dropped before it beyond ``eps``. The vertices where
    the mask ``keep`` is set (over the coordinates of the rings, polygon by polygon, each
    ring closed) are never dropped."""
    return _reduce(geom, eps, keep)[0]


def _reduce(geom: BaseGeometry, eps: float, keep: np.ndarray | None = None,
            fallback: BaseGeometry | None = None) -> tuple[BaseGeometry, bool]:
    """:func:`reduce_vertices`, and whether the result was checked to be valid. With
    ``fallback`` (a valid geometry with the same polygons in the same order, of which
    ``geom`` is a retouched, unchecked copy), a polygon that is not valid even with all
    its vertices is replaced by the fallback's, and a whole that is not valid becomes the
    fallback's reduction."""
    if eps <= 0 or geom.is_empty:
        return geom, False
    parts = shapely.get_parts(geom)
    n_holes = shapely.get_num_interior_rings(parts)
    owner = np.repeat(np.arange(len(parts)), n_holes + 1)  # part of each ring
    rings = shapely.get_rings(parts)
    xy, ring = shapely.get_coordinates(rings, return_index=True)
    fixed = keep if keep is not None and len(keep) == len(xy) else None
    kept = _kept_of(xy, ring, shapely.simplify(rings, eps, preserve_topology=False), eps,
                    fixed)
    polys = _polys_of(xy, ring, kept, owner)
    bad = np.flatnonzero(~shapely.is_valid(polys))
    checked = True  # the result is known to be valid
    if len(bad):
        on = np.isin(owner, bad)[ring]
        try:
            tps = shapely.simplify(parts[bad], eps, preserve_topology=True)
            tps_rings = shapely.get_rings(tps)
        except shapely.errors.GEOSException:
            tps_rings = None
        if tps_rings is not None and np.all(shapely.get_type_id(tps) == 3) and np.array_equal(
                shapely.get_num_interior_rings(tps), n_holes[bad]):
            sub = _kept_of(xy[on], np.unique(ring[on], return_inverse=True)[1], tps_rings, eps,
                           fixed[on] if fixed is not None else None)
            kept[on] = sub
        else:
            kept[on] = True
        polys = _polys_of(xy, ring, kept, owner)
        still = np.flatnonzero(~shapely.is_valid(polys))
        if len(still):
            kept[np.isin(owner, still)[ring]] = True
            polys = _polys_of(xy, ring, kept, owner)
            if fallback is not None:
                polys[still] = _reduced_parts(fallback, still, eps)
            else:
                checked = False
    if len(polys) == 1:
        return polys[0], checked
    out = shapely.MultiPolygon(list(polys))
    if not out.is_valid:
        # thinned polygons that now meet: those go back as they were
        i, j = shapely.STRtree(polys).query(polys, predicate="intersects")
        meet = np.unique(np.concatenate([i[i != j], j[i != j]]))
        kept[np.isin(owner, meet)[ring]] = True
        polys = _polys_of(xy, ring, kept, owner)
        out = shapely.MultiPolygon(list(polys))
        if not out.is_valid and fallback is not None:
            polys[meet] = _reduced_parts(fallback, meet, eps)
            out = shapely.MultiPolygon(list(polys))
            if not out.is_valid:
                return _reduce(fallback, eps)
        if not out.is_valid:
            return geom, False
    return out, True


def _reduced_parts(geom: BaseGeometry, idx: np.ndarray, eps: float) -> np.ndarray:
    """The polygons ``idx`` of ``geom``, each thinned by :func:`_reduce` on its own (each
    valid: a polygon that does not thin validly stays as it is)."""
    parts = shapely.get_parts(geom)[idx]
    out = np.empty(len(parts), dtype=object)
    for k, p in enumerate(parts):
        r, ok = _reduce(p, eps)
        out[k] = r if ok and r.geom_type == "Polygon" else p
    return out


def _kept_of(xy: np.ndarray, ring: np.ndarray, simplified: np.ndarray, eps: float,
             fixed: np.ndarray | None = None) -> np.ndarray:
    """Mask of the vertices ``xy`` (ring numbers ``ring``, 0..R-1, rows in ring order, each
    ring closed) that the simplified rings (an array of R geometries) kept, plus each
    ring's first and closing vertex. A ring is kept whole when fewer than 4 of its
    vertices remain or a dropped vertex lies farther than ``eps`` from its chord. (The
    result is built from the rings' own vertices and checked, whatever GEOS did.)"""
    oxy, oring = shapely.get_coordinates(simplified, return_index=True)
    okeys = _xy_hash(oxy, oring)
    keys = _xy_hash(xy, ring)
    if len(okeys):
        cand = _lookup(okeys, keys)
        # exact (ring, x, y) matches (a hash collision only drops a vertex, which the
        # chord check below then judges)
        kept = (okeys[cand] == keys) & (oring[cand] == ring) & np.all(oxy[cand] == xy, axis=1)
    else:
        kept = np.zeros(len(xy), dtype=bool)
    starts = np.flatnonzero(np.diff(ring, prepend=-1))
    kept[starts] = True  # each ring's first vertex ...
    kept[np.append(starts[1:] - 1, len(xy) - 1)] = True  # ... and its closing copy
    if fixed is not None:
        kept |= fixed
    n_rings = int(ring[-1]) + 1 if len(ring) else 0
    whole = np.bincount(ring[kept], minlength=n_rings) < 4
    whole[_far_rings(xy, ring, kept, eps, n_rings)] = True
    kept[whole[ring]] = True
    return kept


def _lookup(table_keys: np.ndarray, keys: np.ndarray) -> np.ndarray:
    """For each of ``keys`` (64-bit hashes), the index of an equal one in ``table_keys``
    (non-empty) if there is one, else of some other. An open-addressed table on the low
    bits, at least four times as many slots as keys; keys whose slot several table keys
    share are looked up by binary search among those."""
    size = 1 << (4 * len(table_keys)).bit_length()
    mask = np.uint64(size - 1)
    tslot = (table_keys & mask).astype(np.int64)
    count = np.bincount(tslot, minlength=size)
    table = np.zeros(size, dtype=np.int64)
    table[tslot] = np.arange(len(table_keys))
    slot = (keys & mask).astype(np.int64)
    out = table[slot]
    shared = count[slot] > 1
    if shared.any():
        sub = np.flatnonzero(count[tslot] > 1)
        sub = sub[np.argsort(table_keys[sub])]
        pos = np.searchsorted(table_keys[sub], keys[shared])
        out[shared] = sub[np.minimum(pos, len(sub) - 1)]
    return out


def _polys_of(xy: np.ndarray, ring: np.ndarray, kept: np.ndarray, owner: np.ndarray
              ) -> np.ndarray:
    """Polygons from the kept vertices: ring r belongs to polygon ``owner[r]`` (its
    exterior first, then its holes)."""
    rings = shapely.linearrings(xy[kept], indices=ring[kept])
    return shapely.polygons(rings, indices=owner)


def _xy_hash(xy: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """A 64-bit hash of each (ring, x, y), for matching exact coordinates by sorting
    (callers compare the matched coordinates themselves; -0.0 hashes as 0.0). Each word
    is folded in and then mixed (multiply, xor-shift), so coordinates that differ only in
    sign or order do not collide."""
    bits = np.ascontiguousarray(xy + 0.0).view(np.uint64)
    h = ring.astype(np.uint64)
    with np.errstate(over="ignore"):
        for word in (bits[:, 0], bits[:, 1]):
            h = (h ^ word) * np.uint64(0x9E3779B97F4A7C15)
            h ^= h >> np.uint64(29)
            h *= np.uint64(0xBF58476D1CE4E5B9)
            h ^= h >> np.uint64(32)
    return h


def _far_rings(xy: np.ndarray, ring: np.ndarray, kept: np.ndarray, eps: float,
               n_rings: int) -> np.ndarray:
    """Mask of the rings with a vertex not ``kept`` that lies farther than ``eps`` from
    the segment between the kept vertices before and after it (each ring's first and last
    rows are kept)."""
    far = np.zeros(n_rings, dtype=bool)
    drop = ~kept
    if not drop.any():
        return far
    idx = np.arange(len(xy))
    prev = np.maximum.accumulate(np.where(kept, idx, 0))
    nxt = np.minimum.accumulate(np.where(kept, idx, len(xy) - 1)[::-1])[::-1]
    dist = point_segment_distance(xy[drop], xy[prev[drop]], xy[nxt[drop]])
    far[ring[drop][dist > eps]] = True
    return far


def compensate_geometry(region: BaseGeometry, d: float, *, side: str, method: str,
                        tol: float, res: float, res_auto: bool = True) -> BaseGeometry:
    """The compensated region of a valid (Multi)Polygon: offset distance ``d``, arc
    tolerance ``tol`` and raster pixel ``res`` (coarsened when ``res_auto``), all in input
    units. Exposed for the benchmark and the tests."""
    return _apply(region, d, side, method, tol, res, res_auto)


# --------------------------------------------------------------------------- checks
def _check(drawing: Drawing, kerf_mm: float, side: str, method: str, fm: FieldMap,
           arc_tol_bits: float, raster_res_bits: float | None,
           bbox: tuple[float, float, float, float] | None = None
           ) -> tuple[float, float, float, float] | None:
    """Raise ParamError on a bad parameter; returns the drawing's bbox when it was needed
    (``bbox``, or computed)."""
    if isinstance(kerf_mm, bool) or not isinstance(kerf_mm, (int, float)) \
            or not math.isfinite(kerf_mm):
        raise ParamError(f"kerf_mm must be a finite number, got {kerf_mm!r}")
    if kerf_mm < 0:
        raise ParamError(f"kerf_mm must be >= 0 (the trough's width in mm), got {kerf_mm!r}")
    if side not in KERF_SIDES:
        raise ParamError(f"kerf_side must be one of {', '.join(KERF_SIDES)}; got {side!r}")
    if method not in KERF_METHODS:
        raise ParamError(f"kerf_method must be one of {', '.join(KERF_METHODS)}; got {method!r}")
    if not (isinstance(arc_tol_bits, (int, float)) and math.isfinite(arc_tol_bits)
            and arc_tol_bits > 0):
        raise ParamError(f"arc_tol_bits must be a positive finite number, got {arc_tol_bits!r}")
    if raster_res_bits is not None and not (
            isinstance(raster_res_bits, (int, float)) and math.isfinite(raster_res_bits)
            and raster_res_bits > 0):
        raise ParamError(
            f"raster_res_bits must be a positive finite number, got {raster_res_bits!r}")
    if kerf_mm == 0:
        return bbox
    bb = bbox if bbox is not None else drawing.bbox()
    size_mm = 0.0 if bb is None else max(bb[2] - bb[0], bb[3] - bb[1]) * fm.mm_per_unit
    if kerf_mm > size_mm:
        raise ParamError(
            f"kerf_mm = {kerf_mm:g} mm is larger than the drawing itself ({size_mm:.3g} mm on "
            f"the workpiece at magnification {fm.magnification:g}); the kerf is the width of "
            "the laser's trough, typically 0.02-0.2 mm")
    return bb


# --------------------------------------------------------------------------- inputs
def _split(drawing: Drawing) -> tuple[list[int], set[int]]:
    """Indices of closed rings that enclose area, and of everything else."""
    cand = [i for i, p in enumerate(drawing.paths) if p.closed and len(p.points) >= 4]
    area = _have_area([drawing.paths[i].points for i in cand]) if cand else np.zeros(0, bool)
    rings = [i for i, a in zip(cand, area.tolist(), strict=True) if a]
    return rings, set(range(len(drawing.paths))) - set(rings)


def _have_area(rings: list[np.ndarray]) -> np.ndarray:
    """Per ring, False when all its points lie on one line (a ring that encloses nothing):
    every point's cross product with the point farthest from the first (the first such)
    is zero."""
    sizes = np.array([len(r) for r in rings])
    start = np.cumsum(sizes) - sizes
    owner = np.repeat(np.arange(len(rings)), sizes)
    pts = np.concatenate(rings).astype(np.float64, copy=False)
    v = pts - pts[start][owner]
    n2 = (v * v).sum(axis=1)
    # the first farthest point of each ring
    top = np.maximum.reduceat(n2, start)
    at = np.flatnonzero(n2 == top[owner])
    first = at[np.r_[True, owner[at][1:] != owner[at][:-1]]]  # one per ring, in order
    far = v[first][owner]
    cross = np.abs(v[:, 0] * far[:, 1] - v[:, 1] * far[:, 0]) > 0
    return np.logical_or.reduceat(cross, start)


def _by_pen(drawing: Drawing, rings: list[int]) -> dict[int, list[int]]:
    out: dict[int, list[int]] = {}
    for i in rings:
        out.setdefault(drawing.paths[i].pen, []).append(i)
    return out


def _signed_area(pts: np.ndarray) -> float:
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.dot(x[:-1], y[1:]) - np.dot(x[1:], y[:-1]))


def _closed(pts: np.ndarray) -> np.ndarray:
    pts = np.asarray(pts, dtype=np.float64)
    if len(pts) and (pts[0] != pts[-1]).any():
        pts = np.vstack([pts, pts[:1]])
    return pts


def _all_closed(rings: Sequence[np.ndarray]) -> list[np.ndarray]:
    """:func:`_closed` of each ring (one comparison for all)."""
    rings = [np.asarray(r, dtype=np.float64) for r in rings]
    rings = [r for r in rings if len(r)]
    if not rings:
        return []
    sizes = np.array([len(r) for r in rings])
    pts = np.concatenate(rings)
    ends = np.cumsum(sizes)
    open_ = np.any(pts[ends - sizes] != pts[ends - 1], axis=1)
    return [np.vstack([r, r[:1]]) if o else r
            for r, o in zip(rings, open_.tolist(), strict=True)]


def _segments(rings: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """All edges of closed rings as (S, 2) start and end points."""
    a = np.concatenate([r[:-1] for r in rings]) if rings else np.zeros((0, 2))
    b = np.concatenate([r[1:] for r in rings]) if rings else np.zeros((0, 2))
    return a, b


def even_odd_region(rings: Sequence[np.ndarray]) -> BaseGeometry:
    """The valid (Multi)Polygon that the closed rings enclose by the even-odd rule.

    Rings may touch, cross themselves and each other. The rings fall into groups that
    lines parallel to the axes separate (:func:`_box_groups`); rings of different groups
    lie outside one another, so the region is the union of the groups' regions, which are
    disjoint. Fast path, for the groups of simple rings that do not touch one another:
    nesting by containment (:func:`_nest`). General path, for the other groups
    (:func:`_even_odd_general`): cancel the edges that occur an even number of times,
    node the remaining linework, polygonize it and keep the faces with an odd ray-crossing
    count.
    """
    rings = _all_closed(rings)
    rings = [r for r in rings if len(r) >= 4]
    if not rings:
        return shapely.Polygon()
    lrs = _linearrings(rings)
    polys = shapely.polygons(lrs)
    general = ~shapely.is_valid(polys)
    if len(rings) > 1:
        label = _box_groups(shapely.bounds(lrs))
        size = np.bincount(label)
        bad = np.zeros(len(size), dtype=bool)  # per group: needs the general path
        bad[label[general]] = True
        # the rings of the other groups with more than one ring: do they touch?
        cand = np.flatnonzero(~bad[label] & (size[label] > 1))
        if len(cand):
            _touching_groups(lrs, cand, label, bad)
        general = bad[label]
    if not general.any():
        return _nest(polys)
    region = _even_odd_general([r for r, g in zip(rings, general.tolist(), strict=True) if g])
    if general.all():
        return region
    simple = shapely.get_parts(_nest(polys[~general]))
    parts = np.concatenate([simple, shapely.get_parts(region)]) if not region.is_empty \
        else simple
    return shapely.multipolygons(parts) if len(parts) > 1 else parts[0]


def _touching_groups(lrs: np.ndarray, cand: np.ndarray, label: np.ndarray,
                     bad: np.ndarray) -> None:
    """Mark in ``bad`` (per group) the groups in which two of the rings ``lrs[cand]``
    intersect. Pairs whose boxes meet are tested a few per group at a time, and a group
    is not tested further once it is marked (most groups of rings that overlap are
    found at their first pairs)."""
    ci, cj = shapely.STRtree(lrs[cand]).query(lrs[cand])
    k = ci < cj
    i, j = cand[ci[k]], cand[cj[k]]
    order = np.argsort(label[i], kind="stable")
    i, j = i[order], j[order]
    g = label[i]
    rank = np.arange(len(g)) - np.searchsorted(g, g)  # place of the pair in its group
    first = np.unique(i)
    shapely.prepare(lrs[first[shapely.get_num_coordinates(lrs[first]) >= 256]])
    lo = 0
    hi = 4
    while len(i):
        now = (rank >= lo) & (rank < hi)
        hit = shapely.intersects(lrs[i[now]], lrs[j[now]])
        bad[g[now][hit]] = True
        left = (rank >= hi) & ~bad[g]
        i, j, g, rank = i[left], j[left], g[left], rank[left]
        lo, hi = hi, 4 * hi


def _even_odd_general(rings: list[np.ndarray]) -> BaseGeometry:
    """The even-odd region of closed rings that may touch and cross (themselves and each
    other): first cancel the edges that occur an even number of times over all rings
    (either direction; see :func:`_odd_edges`: a ray crosses two equal edges both or
    neither, so no point's parity changes), node the remaining linework (GEOS union),
    polygonize the faces and keep the faces whose interior point has an odd ray-crossing
    count against the remaining edges. Odd faces that share an edge (where two rings run
    along one another the union keeps one line, which changes no parity) are merged by a
    coverage union; the others already are the region's polygons."""
    a, b, keep, rep = _odd_edges(rings)
    if not keep.any():
        return shapely.Polygon()
    lines = _edge_runs(a, b, keep, [len(r) - 1 for r in rings])
    try:
        noded = shapely.union_all(lines)
    except shapely.errors.GEOSException:  # noding failed to converge: snap to a fine grid
        x0, y0, x1, y1 = shapely.total_bounds(lines)
        noded = shapely.union_all(lines, grid_size=1e-9 * max(x1 - x0, y1 - y0, 1.0))
    faces = _polygonize(shapely.get_parts(noded))
    faces = faces[shapely.area(faces) > 0]
    if len(faces) == 0:
        return shapely.Polygon()
    pts = shapely.get_coordinates(shapely.point_on_surface(faces))
    odd = _odd_crossings(pts, a[rep], b[rep])
    inside = faces[odd]
    if len(inside) == 0:
        return shapely.Polygon()
    shared = _sharing_an_edge(inside)
    if shared.any():
        merged = shapely.get_parts(shapely.coverage_union_all(inside[shared]))
        inside = np.concatenate([merged, inside[~shared]])
    out = shapely.multipolygons(inside) if len(inside) > 1 else inside[0]
    if not shapely.is_valid(out):
        out = shapely.make_valid(shapely.union_all(faces[odd]))
    return _polygonal(out)


#: GEOS's C API through ctypes (which releases the GIL during the call), or False when
#: shapely's GEOS library cannot be found; None until first asked for
_GEOS_C: ctypes.CDLL | bool | None = None
_GEOS_LOCK = threading.Lock()


def _geos_c() -> ctypes.CDLL | None:
    """shapely's own libgeos_c (the same library, so the same results), with the few
    functions :func:`_polygonize` calls declared; None when it cannot be loaded."""
    global _GEOS_C
    with _GEOS_LOCK:
        if _GEOS_C is None:
            _GEOS_C = False
            base = os.path.dirname(os.path.dirname(shapely.__file__))
            libs = sorted(glob.glob(os.path.join(base, "shapely.libs", "libgeos_c*.so*")))
            try:
                if len(libs) != 1 or not hasattr(shapely.Point(0, 0), "_geom"):
                    raise OSError("no single bundled libgeos_c")
                lib = ctypes.CDLL(libs[0])
                vp, sz = ctypes.c_void_p, ctypes.c_size_t
                lib.GEOS_init_r.restype = vp
                lib.GEOS_init_r.argtypes = []
                lib.GEOS_finish_r.argtypes = [vp]
                lib.GEOS_finish_r.restype = None
                lib.GEOSPolygonize_r.restype = vp
                lib.GEOSPolygonize_r.argtypes = [vp, ctypes.POINTER(vp), ctypes.c_uint]
                lib.GEOSWKBWriter_create_r.restype = vp
                lib.GEOSWKBWriter_create_r.argtypes = [vp]
                lib.GEOSWKBWriter_destroy_r.argtypes = [vp, vp]
                lib.GEOSWKBWriter_destroy_r.restype = None
                lib.GEOSWKBWriter_write_r.restype = vp
                lib.GEOSWKBWriter_write_r.argtypes = [vp, vp, vp, ctypes.POINTER(sz)]
                lib.GEOSFree_r.argtypes = [vp, vp]
                lib.GEOSFree_r.restype = None
                lib.GEOSGeom_destroy_r.argtypes = [vp, vp]
                lib.GEOSGeom_destroy_r.restype = None
                lib.GEOSversion.restype = ctypes.c_char_p
                if not lib.GEOSversion().decode().startswith(
                        ".".join(map(str, shapely.geos_version))):
                    raise OSError("libgeos_c is not shapely's version")
                _GEOS_C = lib
            except (OSError, AttributeError):
                _GEOS_C = False
        return _GEOS_C if isinstance(_GEOS_C, ctypes.CDLL) else None


def _polygonize(lines: np.ndarray) -> np.ndarray:
    """The faces of ``shapely.polygonize(lines)`` (noded linework), identical, but with the
    interpreter lock released during GEOS's polygonizer: shapely's ``polygonize`` holds it
    for the whole call (40-45 ms on the 5,500 lines of b_fabric_nesting), which stalls the
    window's GUI thread when this runs on its worker. The same GEOS function of the same
    library is called through ctypes on the lines' own GEOS geometries and its result
    comes back as WKB (exact doubles). Falls back to shapely when the library is not at
    hand or GEOS fails (shapely then raises its own error)."""
    lib = _geos_c()
    if lib is None or len(lines) == 0:
        return shapely.get_parts(shapely.polygonize(lines))
    vp = ctypes.c_void_p
    ptrs = (vp * len(lines))(*[g._geom for g in lines.tolist()])  # noqa: SLF001
    ctx = lib.GEOS_init_r()
    try:
        res = lib.GEOSPolygonize_r(ctx, ptrs, len(lines))  # GIL released (ctypes)
        if not res:
            return shapely.get_parts(shapely.polygonize(lines))
        writer = lib.GEOSWKBWriter_create_r(ctx)
        size = ctypes.c_size_t()
        buf = lib.GEOSWKBWriter_write_r(ctx, writer, res, ctypes.byref(size))
        lib.GEOSWKBWriter_destroy_r(ctx, writer)
        lib.GEOSGeom_destroy_r(ctx, res)
        if not buf:
            return shapely.get_parts(shapely.polygonize(lines))
        wkb = ctypes.string_at(buf, size.value)
        lib.GEOSFree_r(ctx, buf)
    finally:
        lib.GEOS_finish_r(ctx)
    return shapely.get_parts(shapely.from_wkb(wkb))


def _sharing_an_edge(faces: np.ndarray) -> np.ndarray:
    """Mask of the polygons (faces of one polygonized linework, so a shared edge has the
    same end points in both) that have an edge in common with another one."""
    xy, ring = shapely.get_coordinates(shapely.get_rings(faces), return_index=True)
    owner = np.repeat(np.arange(len(faces)), shapely.get_num_interior_rings(faces) + 1)
    same = ring[1:] == ring[:-1]  # consecutive vertices of one ring: an edge
    p, q = xy[:-1][same], xy[1:][same]
    face = owner[ring[1:][same]]
    swap = (p[:, 0] > q[:, 0]) | ((p[:, 0] == q[:, 0]) & (p[:, 1] > q[:, 1]))
    key = np.concatenate([np.where(swap[:, None], q, p), np.where(swap[:, None], p, q)],
                         axis=1)
    inv, _, cnt = _group_rows(key)
    out = np.zeros(len(faces), dtype=bool)
    out[face[cnt[inv] > 1]] = True
    return out


def _group_rows(key: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Classes of equal rows of a float array: per row its class, per class its first row
    and its size (like ``np.unique(..., return_index, return_inverse, return_counts)`` on
    rows, classes in no particular order; -0.0 equals 0.0). Rows whose 64-bit hash is
    unique are classes of their own; the others are sorted by hash and neighbours
    compared exactly (sorted as rows when two different rows share a hash)."""
    key = np.ascontiguousarray(key, dtype=np.float64) + 0.0
    n = len(key)
    bits = key.view(np.uint64)
    h = np.zeros(n, dtype=np.uint64)
    with np.errstate(over="ignore"):
        for k in range(key.shape[1]):
            h = (h ^ bits[:, k]) * np.uint64(0x9E3779B97F4A7C15)
            h ^= h >> np.uint64(29)
            h *= np.uint64(0xBF58476D1CE4E5B9)
            h ^= h >> np.uint64(32)
    hs = np.sort(h)
    rep = hs[1:][hs[1:] == hs[:-1]]  # hash values of more than one row
    inv = np.arange(n)
    if not len(rep):
        return inv, np.arange(n), np.ones(n, dtype=np.int64)
    many = np.flatnonzero(np.isin(h, rep))
    order = np.argsort(h[many], kind="stable")
    hm, km = h[many][order], key[many][order]
    same = np.all(km[1:] == km[:-1], axis=1)
    if np.any((hm[1:] == hm[:-1]) & ~same):  # a hash collision: sort the rows themselves
        _, ufirst, uinv, ucnt = np.unique(key[many], axis=0, return_index=True,
                                          return_inverse=True, return_counts=True)
    else:
        start = np.ones(len(many), dtype=bool)
        start[1:] = ~same
        grp = np.cumsum(start) - 1
        uinv = np.empty(len(many), dtype=np.int64)
        uinv[order] = grp
        ufirst, ucnt = order[start], np.bincount(grp)
    single = np.ones(n, dtype=bool)
    single[many] = False
    one = np.flatnonzero(single)
    inv[one] = np.arange(len(one))
    inv[many] = len(one) + uinv.ravel()
    return (inv, np.concatenate([one, many[ufirst]]),
            np.concatenate([np.ones(len(one), dtype=np.int64), ucnt]))


def _box_groups(bounds: np.ndarray) -> np.ndarray:
    """Group numbers (0..G-1) of boxes (rows xmin, ymin, xmax, ymax) such that boxes of
    different groups are separated by a line parallel to an axis with a gap between them
    (so rings in different groups neither touch nor enclose one another): the boxes are
    split recursively where a sweep along x or y finds a gap, until neither splits any
    group. Boxes that touch or overlap are always in one group (a group may also hold
    boxes that no such cut separates, e.g. four arranged like a pinwheel)."""
    n = len(bounds)
    label = np.zeros(n, dtype=np.int64)
    if n < 2:
        return label
    origin = bounds[:, :2].min(axis=0)
    big = 2.0 * float((bounds[:, 2:] - origin).max()) + 1.0
    groups, stale, axis = 1, 0, 0
    while stale < 2:
        off = label * big  # groups apart along the sweep (rounding only joins more)
        lo = bounds[:, axis] - origin[axis] + off
        hi = bounds[:, axis + 2] - origin[axis] + off
        order = np.argsort(lo, kind="stable")
        start = np.ones(n, dtype=bool)
        start[1:] = lo[order][1:] > np.maximum.accumulate(hi[order])[:-1]
        label[order] = np.cumsum(start) - 1
        now = int(label.max()) + 1
        stale = stale + 1 if now == groups else 0
        groups = now
        axis = 1 - axis
    return label


def _odd_edges(rings: Sequence[np.ndarray]
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """All edges of the closed rings, (a, b); a mask of those that take part in the
    even-odd rule; and the indices of one kept edge per class of equal kept edges.

    Kept: not zero-length, and in a class of equal edges (the same two end points, either
    direction) of odd size. The ray-crossing parity of every point is the same over the
    kept edges as over all edges, and the same over one edge per class: two equal edges
    are crossed by a ray both or neither (the half-open rule does not depend on
    direction), and a zero-length edge never. Stacked hatch strips and shared outline
    pieces cancel this way."""
    a, b = _segments(rings)
    swap = (a[:, 0] > b[:, 0]) | ((a[:, 0] == b[:, 0]) & (a[:, 1] > b[:, 1]))
    key = np.concatenate([np.where(swap[:, None], b, a), np.where(swap[:, None], a, b)],
                         axis=1)
    inv, first, cnt = _group_rows(key)
    nonzero = ~np.all(a == b, axis=1)
    odd = cnt % 2 == 1
    keep = nonzero & odd[inv]
    rep = first[odd]
    return a, b, keep, rep[nonzero[rep]]


def _edge_runs(a: np.ndarray, b: np.ndarray, keep: np.ndarray, sizes: list[int]
               ) -> np.ndarray:
    """LineStrings of the kept edges: each maximal run of consecutive kept edges of one
    ring becomes one line (fewer, longer lines node faster than single edges)."""
    ring_of = np.repeat(np.arange(len(sizes)), sizes)
    idx = np.nonzero(keep)[0]
    new_run = np.ones(len(idx), dtype=bool)
    new_run[1:] = (np.diff(idx) != 1) | (ring_of[idx[1:]] != ring_of[idx[:-1]])
    run = np.cumsum(new_run) - 1
    # a run's points: the start of each edge, then the end of the run's last edge
    last = np.ones(len(idx), dtype=bool)
    last[:-1] = new_run[1:]
    pts = np.concatenate([a[idx], b[idx[last]]])
    pid = np.concatenate([run, run[last]])
    order = np.argsort(pid, kind="stable")
    return shapely.linestrings(pts[order], indices=pid[order])


def _linearrings(rings: Sequence[np.ndarray]) -> np.ndarray:
    """An array of LinearRings from closed coordinate arrays of different lengths."""
    return shapely.linearrings(np.concatenate(rings), indices=np.repeat(
        np.arange(len(rings)), [len(r) for r in rings]))


def _nest(polys: np.ndarray) -> BaseGeometry:
    """Even-odd of simple, pairwise disjoint rings (as polygons): depth by containment."""
    n = len(polys)
    if n == 1:
        return shapely.orient_polygons(polys[0])
    tree = shapely.STRtree(polys)
    reps = shapely.points(shapely.get_coordinates(shapely.get_exterior_ring(polys))[
        np.cumsum([0] + [int(c) for c in shapely.get_num_coordinates(polys)[:-1]])])
    # a ring's first vertex lies strictly inside every ring that contains it (no touching)
    inner, outer = tree.query(reps, predicate="within")
    keep = inner != outer
    inner, outer = inner[keep], outer[keep]
    depth = np.bincount(inner, minlength=n)
    areas = shapely.area(polys)
    parent = np.full(n, -1)
    # parent = the smallest container
    order = np.argsort(-areas[outer], kind="stable")
    parent[inner[order]] = outer[order]
    shells = np.nonzero(depth % 2 == 0)[0]
    holes: dict[int, list[np.ndarray]] = {}
    for h in np.nonzero(depth % 2 == 1)[0]:
        holes.setdefault(int(parent[h]), []).append(
            shapely.get_coordinates(shapely.get_exterior_ring(polys[h])))
    out = [shapely.Polygon(shapely.get_coordinates(shapely.get_exterior_ring(polys[s])),
                           holes.get(int(s), [])) for s in shells]
    geom = shapely.MultiPolygon(out) if len(out) > 1 else out[0]
    return shapely.orient_polygons(geom)


def _odd_crossings(pts: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each point, whether a horizontal ray to +x crosses an odd number of the edges
    (a, b) (the parity of :func:`_crossings`; the edges must form closed rings mod 2, as
    :func:`_odd_edges` leaves them: every vertex in an even number of edges).

    Linear in the points and edges for any layout: the plane is cut into vertical columns
    (equal numbers of edge ends each, boundaries half-way between two vertex x values, so
    no vertex lies on one) and each point's ray is replaced by a path with the same
    crossing parity (a closed curve crosses closed rings an even number of times): along
    its line to its column's right boundary, then up that boundary. The first leg meets
    only the edges of its column; the second is a count of the boundary's crossing heights
    above the point (a binary search). A point where the path meets an edge exactly at its
    corner (a tie) is counted with the plain ray instead. :func:`_crossings` alone pairs
    every point with every edge spanning its height: for drawings side by side that is
    every edge to the right on the same rows, quadratic in the number of drawings."""
    n, m = len(pts), len(a)
    if n == 0 or m == 0:
        return np.zeros(n, dtype=bool)
    # few point-edge pairs (most layouts of a few drawings): the plain count is cheaper
    sy = np.sort(pts[:, 1])
    ylo_, yhi_ = np.minimum(a[:, 1], b[:, 1]), np.maximum(a[:, 1], b[:, 1])
    pairs = int(np.maximum(np.searchsorted(sy, yhi_) - np.searchsorted(sy, ylo_), 0).sum())
    if pairs <= CROSS_PLAIN_PAIRS * (n + m):
        return _crossings(pts, a, b) % 2 == 1
    n_col = min(m // CROSS_COLUMN_EDGES, 1 << 16)
    xs = np.sort(np.concatenate([a[:, 0], b[:, 0]]))
    if n_col >= 2:
        q = np.linspace(0, len(xs) - 1, n_col + 1)[1:-1].astype(np.int64)
        lo_x, hi_x = xs[q], xs[np.minimum(q + 1, len(xs) - 1)]
        # the first vertex x above each quantile, so the boundary falls strictly between two
        nxt = np.searchsorted(xs, lo_x, side="right")
        ok = nxt < len(xs)
        lo_x, hi_x = lo_x[ok], xs[nxt[ok]]
        mid = 0.5 * (lo_x + hi_x)
        bnd = np.unique(mid[(mid > lo_x) & (mid < hi_x)])
    else:
        bnd = np.zeros(0)
    if len(bnd) == 0:
        return _crossings(pts, a, b) % 2 == 1
    nc = len(bnd) + 1
    right = np.r_[bnd, np.inf]  # right boundary of each column
    px, py = pts[:, 0], pts[:, 1]
    pcol = np.searchsorted(bnd, px, side="right")
    # points by column, then height
    porder = np.lexsort((py, pcol))
    pstart = np.searchsorted(pcol[porder], np.arange(nc + 1))
    spy = py[porder]
    cnt_h = np.zeros(n, dtype=np.int64)
    tie = np.zeros(n, dtype=bool)
    ax, ay, bx, by = a[:, 0], a[:, 1], b[:, 0], b[:, 1]
    xlo, xhi = np.minimum(ax, bx), np.maximum(ax, bx)
    ylo, yhi = np.minimum(ay, by), np.maximum(ay, by)
    # ---- first leg: the edges of each column (an edge in every column its x range meets)
    ec0 = np.searchsorted(bnd, xlo, side="right")
    ec1 = np.searchsorted(bnd, xhi, side="right")
    slanted = np.flatnonzero(yhi > ylo)  # a horizontal edge is never crossed (half-open)
    rep = (ec1 - ec0 + 1)[slanted]
    e_id = np.repeat(slanted, rep)
    e_col = np.repeat(ec0[slanted], rep) + (
        np.arange(len(e_id)) - np.repeat(np.cumsum(rep) - rep, rep))
    o = np.argsort(e_col, kind="stable")
    e_id, e_col = e_id[o], e_col[o]
    estart = np.searchsorted(e_col, np.arange(nc + 1))
    lo = np.empty(len(e_id), dtype=np.int64)
    hi = np.empty(len(e_id), dtype=np.int64)
    for c in range(nc):
        s0, s1 = int(estart[c]), int(estart[c + 1])
        if s0 == s1:
            continue
        p0, p1 = int(pstart[c]), int(pstart[c + 1])
        col_y = spy[p0:p1]
        ids = e_id[s0:s1]
        lo[s0:s1] = p0 + np.searchsorted(col_y, ylo[ids], side="left")
        hi[s0:s1] = p0 + np.searchsorted(col_y, yhi[ids], side="left")
    for row, k in _pairs_in_chunks(lo, hi - lo):
        pi = porder[k]
        e = e_id[row]
        x = ax[e] + (py[pi] - ay[e]) * (bx[e] - ax[e]) / (by[e] - ay[e])
        lim = right[e_col[row]]
        hit = (x > px[pi]) & (x < lim)
        cnt_h += np.bincount(pi[hit], minlength=n)
        tie[pi[(x > px[pi]) & (x == lim)]] = True
    # ---- second leg: up each column's right boundary (edges strictly across it)
    rep = np.maximum(ec1 - ec0, 0)
    crossing = np.flatnonzero(rep)
    rep = rep[crossing]
    v_id = np.repeat(crossing, rep)
    v_col = np.repeat(ec0[crossing], rep) + (
        np.arange(len(v_id)) - np.repeat(np.cumsum(rep) - rep, rep))
    xb = bnd[v_col]
    yc = ay[v_id] + (xb - ax[v_id]) * (by[v_id] - ay[v_id]) / (bx[v_id] - ax[v_id])
    o = np.lexsort((yc, v_col))
    yc, v_col = yc[o], v_col[o]
    vstart = np.searchsorted(v_col, np.arange(nc + 1))
    above = np.zeros(n, dtype=np.int64)
    for c in range(nc - 1):
        s0, s1 = int(vstart[c]), int(vstart[c + 1])
        p0, p1 = int(pstart[c]), int(pstart[c + 1])
        if s0 == s1 or p0 == p1:
            continue
        ys = yc[s0:s1]
        qy = spy[p0:p1]
        r = np.searchsorted(ys, qy, side="right")
        above[porder[p0:p1]] = (s1 - s0) - r
        t = r != np.searchsorted(ys, qy, side="left")
        tie[porder[p0:p1][t]] = True
    odd = (cnt_h + above) % 2 == 1
    if tie.any():
        ti = np.flatnonzero(tie)
        odd[ti] = _crossings(pts[ti], a, b) % 2 == 1
    return odd


def _crossings(pts: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each point, how many edges a horizontal ray to +x crosses (half-open rule)."""
    n = len(pts)
    if n == 0 or len(a) == 0:
        return np.zeros(n, dtype=np.int64)
    order = np.argsort(pts[:, 1], kind="stable")
    py = pts[order, 1]
    ylo = np.minimum(a[:, 1], b[:, 1])
    yhi = np.maximum(a[:, 1], b[:, 1])
    lo = np.searchsorted(py, ylo, side="left")
    hi = np.searchsorted(py, yhi, side="left")
    counts = np.zeros(n, dtype=np.int64)
    for seg, k in _pairs_in_chunks(lo, np.maximum(hi - lo, 0)):
        p = pts[order[k]]
        ax, ay, bx, by = a[seg, 0], a[seg, 1], b[seg, 0], b[seg, 1]
        x = ax + (p[:, 1] - ay) * (bx - ax) / (by - ay)
        hit = x > p[:, 0]
        counts += np.bincount(order[k[hit]], minlength=n)
    return counts


#: pairs handled per step of :func:`_pairs_in_chunks` (bounds the temporary arrays)
PAIR_CHUNK = 4_000_000


def _pairs_in_chunks(lo: np.ndarray, cnt: np.ndarray
                     ) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Every pair (row, k) with ``lo[row] <= k < lo[row] + cnt[row]``, about
    :data:`PAIR_CHUNK` pairs at a time (whole rows per step): arrays ``row`` and ``k``."""
    sel = np.flatnonzero(cnt > 0)
    csum = np.cumsum(cnt[sel])
    start = 0
    while start < len(sel):
        stop = int(np.searchsorted(csum, (csum[start - 1] if start else 0) + PAIR_CHUNK,
                                   side="right"))
        stop = max(stop, start + 1)
        rows = sel[start:stop]
        rc = cnt[rows]
        row = np.repeat(rows, rc)
        yield row, lo[row] + (np.arange(len(row)) - np.repeat(np.cumsum(rc) - rc, rc))
        start = stop


def _polygonal(geom: BaseGeometry) -> BaseGeometry:
    """Keep only the polygons of a geometry (GEOS may return collections)."""
    parts = shapely.get_parts(shapely.get_parts(geom))  # a collection's multis flattened too
    polys = parts[(shapely.get_type_id(parts) == shapely.GeometryType.POLYGON)
                  & ~shapely.is_empty(parts)]
    if not len(polys):
        return shapely.Polygon()
    return shapely.multipolygons(polys) if len(polys) > 1 else polys[0]


# --------------------------------------------------------------------------- methods
def _apply(region: BaseGeometry, d: float, side: str, method: str, tol: float,
           res: float, res_auto: bool) -> BaseGeometry:
    if region.is_empty or d <= 0:
        return region
    checked = False  # known to be valid
    if method == "vector":
        out, checked = _vector(region, d, side, tol)
    elif method == "raster":
        out = _raster(region, d, side, res, res_auto)
    else:
        out = _rectangle(region, d, side)
    out = _polygonal(out)
    if not checked and not out.is_valid:
        out = _polygonal(shapely.make_valid(out))
    return shapely.orient_polygons(out)


def _vector(region: BaseGeometry, d: float, side: str, tol: float
            ) -> tuple[BaseGeometry, bool]:
    """GEOS buffer of each polygon of the region on its own (the offset of a union is the
    union of the offsets), except that polygons no more than ``2 d`` apart (their grown
    versions may meet) are buffered together, group by group, as one MultiPolygon; shrunk
    polygons cannot meet. Much faster than one buffer of a MultiPolygon of thousands of
    parts, which nodes them all together, and than unioning the grown parts of a group.
    The chords of the arcs can leave false holes (outside) and false slivers (inside) that
    the exact offset has not; both are found and removed."""
    q = quad_segs_for(d, tol)
    parts = shapely.get_parts(region)
    if side == "inside":
        grown = shapely.buffer(parts, -d, quad_segs=q, join_style="round")
        keep = ~shapely.is_empty(grown)
        grown, parts = grown[keep], parts[keep]
        pieces, src = _polygon_parts(grown)
        polys = _without_false_slivers(pieces, parts[src], d, tol)
    else:
        polys = _without_false_holes(_grown_groups(parts, d, q), region, d, tol)
    if not polys:
        return shapely.Polygon(), True
    out = polys[0] if len(polys) == 1 else shapely.MultiPolygon(polys)
    # round joins redrawn with the error on both sides of the arc (fewer vertices), kept
    # as they are by the thinning, which has the rest of the outline
    # (their validity is checked once, on the thinned result, which falls back to GEOS's
    # polygons where the redrawn ones are not valid)
    joined, joins = two_sided_arcs(out, d, tol, check=False)
    if not len(joins):
        return _reduce(out, reduce_tol_for(d, tol))
    return _reduce(joined, reduce_tol_for(d, tol), joins, fallback=out)


#: a group of grown polygons with at most this many meeting pairs per polygon is buffered
#: as one MultiPolygon; denser groups (many small polygons overlapping when grown) are
#: buffered one by one and unioned, which is faster there (measured over the corpus:
#: 2.4 pairs per polygon and below one MultiPolygon buffer is 1.5-3x faster, at 3.1 and
#: 3.8 the union is 1.5-4x faster)
GROUP_PAIRS_PER_PART = 3.0


def _grown_groups(parts: np.ndarray, d: float, q: int) -> list[BaseGeometry]:
    """The polygons of the parts grown by ``d``: a part farther than ``2 d`` from all the
    others is buffered on its own; the others group by group (connected by being at most
    ``2 d`` apart), as one MultiPolygon, which GEOS buffers as their union, or (dense
    groups, see :data:`GROUP_PAIRS_PER_PART`) one by one, then unioned."""
    if len(parts) < 2:
        return list(_polygon_parts(shapely.buffer(parts, d, quad_segs=q,
                                                  join_style="round"))[0])
    lo = shapely.bounds(parts)
    m = 2.0 * d
    i, j = shapely.STRtree(parts).query(
        shapely.box(lo[:, 0] - m, lo[:, 1] - m, lo[:, 2] + m, lo[:, 3] + m))
    k = i < j
    i, j = i[k], j[k]
    first = np.unique(i)
    # prepared, large parts answer fast (a part in another's hole: 25x on seal.plt); for
    # small ones preparing costs more than it saves
    shapely.prepare(parts[first[shapely.get_num_coordinates(parts[first]) >= 256]])
    near = shapely.dwithin(parts[i], parts[j], m)
    i, j = i[near], j[near]
    label = _components(len(parts), i, j)
    size = np.bincount(label, minlength=len(parts))
    together = size[label] > 1
    alone = shapely.buffer(parts[~together], d, quad_segs=q, join_style="round")
    pairs = np.bincount(label[i], minlength=len(parts))
    dense = pairs > GROUP_PAIRS_PER_PART * size
    out = [alone]
    sparse_ids = np.flatnonzero(together & ~dense[label])
    if len(sparse_ids):
        order = sparse_ids[np.argsort(label[sparse_ids], kind="stable")]
        sizes = np.unique(label[order], return_counts=True)[1]
        groups = shapely.multipolygons(parts[order],
                                       indices=np.repeat(np.arange(len(sizes)), sizes))
        out.append(shapely.buffer(groups, d, quad_segs=q, join_style="round"))
    for g in np.flatnonzero(dense & (size > 1)):
        grown = shapely.buffer(parts[label == g], d, quad_segs=q, join_style="round")
        out.append(np.array([shapely.union_all(grown)], dtype=object))
    return list(_polygon_parts(np.concatenate(out))[0])


def _polygon_parts(geoms: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The non-empty polygons of an array of (Multi)Polygons, with the index of the
    geometry each came from."""
    parts, src = shapely.get_parts(geoms, return_index=True)
    keep = (shapely.get_type_id(parts) == shapely.GeometryType.POLYGON) \
        & ~shapely.is_empty(parts)
    return parts[keep], src[keep]


#: a small hole is probed on a grid of this many points per side (plus two inner points)
PROBE_GRID = 7


def _without_false_holes(polys: list[BaseGeometry], region: BaseGeometry, d: float,
                         size: float) -> list[BaseGeometry]:
    """The grown polygons without the false holes: where the chords of two arcs meet, the
    buffer can leave a sliver hole a fraction of the arc tolerance wide where the exact
    offset has none (the laser would mark it as a tiny loop). A hole smaller than ``size``
    across (bounding-box diagonal) is false when no probe point inside it lies farther
    than ``d`` from the region (every point of a true hole does); probes: a
    ``PROBE_GRID`` grid over its box, its centroid and a point on its surface."""
    if not polys:
        return polys
    arr = np.array(polys, dtype=object)
    n_holes = shapely.get_num_interior_rings(arr)
    if not n_holes.any():
        return polys
    rings, owner = shapely.get_rings(arr, return_index=True)
    hole = np.ones(len(rings), dtype=bool)
    hole[np.cumsum(n_holes + 1) - n_holes - 1] = False  # each polygon's exterior first
    b = shapely.bounds(rings)
    small = np.flatnonzero(hole & (np.hypot(b[:, 2] - b[:, 0], b[:, 3] - b[:, 1]) < size))
    false = [k for k in small.tolist()
             if not _farther_inside(shapely.Polygon(rings[k]), region, d)]
    if not false:
        return polys
    drop = np.zeros(len(rings), dtype=bool)
    drop[false] = True
    out = list(polys)
    for i in np.unique(owner[false]).tolist():
        mine = np.flatnonzero(owner == i)
        out[i] = shapely.Polygon(rings[mine[0]], [rings[k] for k in mine[1:] if not drop[k]])
    return out


def _without_false_slivers(pieces: np.ndarray, sources: np.ndarray, d: float,
                           width: float) -> list[BaseGeometry]:
    """The shrunk polygons (``pieces``, each from the input polygon in ``sources``) without
    the false slivers: where a stroke is about ``2 d`` wide, the chords of the arcs can
    leave a thin polygon (mean width under ``width``) where the exact inward offset has
    nothing; the laser would mark it as a thin loop. A thin polygon is kept only when a
    fine inward offset of its source around it (clipped to its box grown by more than
    ``d``, so the clip edges cannot reach it) meets it: a true remnant, however thin,
    does. (Probing for a point deeper than ``d``, as for holes, misses true remnants
    narrower than the probe grid.)"""
    thin = 2.0 * shapely.area(pieces) < width * shapely.length(shapely.get_exterior_ring(pieces))
    keep = ~thin
    if thin.any():
        keep[thin] = _meets_fine_offset(pieces[thin], sources[thin], d)
    return list(pieces[keep])


#: segments per quarter circle of the fine local offset that judges a thin shrunk polygon
#: (sagitta d (1 - cos(pi / 256)), about 7.5e-5 d)
FINE_QUAD_SEGS = 64


def _meets_fine_offset(polys: np.ndarray, regions: np.ndarray, d: float) -> np.ndarray:
    """Per polygon: whether the fine inward offset of its region, clipped around it,
    meets it."""
    b = shapely.bounds(polys)
    m = 1.5 * d
    near = shapely.intersection(regions, shapely.box(b[:, 0] - m, b[:, 1] - m, b[:, 2] + m,
                                                     b[:, 3] + m))
    fine = shapely.buffer(near, -d, quad_segs=FINE_QUAD_SEGS, join_style="round")
    return np.asarray(shapely.intersects(fine, polys), dtype=bool)


def _across(ring: BaseGeometry) -> float:
    """Bounding-box diagonal of a ring (the size :func:`_without_false_holes` compares)."""
    x0, y0, x1, y1 = ring.bounds
    return math.hypot(x1 - x0, y1 - y0)


def _farther_inside(hole: BaseGeometry, region: BaseGeometry, d: float) -> bool:
    """Whether a probe point inside ``hole`` lies farther than ``d`` from ``region``."""
    x0, y0, x1, y1 = hole.bounds
    gx, gy = np.meshgrid(np.linspace(x0, x1, PROBE_GRID), np.linspace(y0, y1, PROBE_GRID))
    probes = np.concatenate([shapely.points(gx.ravel(), gy.ravel()),
                             [hole.centroid, hole.point_on_surface()]])
    probes = probes[shapely.contains_properly(hole, probes)]
    return bool(len(probes)) and bool((shapely.distance(region, probes) > d).any())


def _components(n: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Connected components of the graph on 0..n-1 with edges (i[k], j[k]): each node's
    label is the smallest node of its component (each round hooks every root onto the
    smallest root it is joined to, then jumps pointers until every label is a root)."""
    label = np.arange(n)
    while len(i):
        li, lj = label[i], label[j]
        lo, hi = np.minimum(li, lj), np.maximum(li, lj)
        diff = lo != hi
        if not diff.any():
            break
        lo, hi = lo[diff], hi[diff]
        order = np.lexsort((lo, hi))  # per root hi: its smallest lo first
        first = np.ones(len(order), dtype=bool)
        first[1:] = hi[order][1:] != hi[order][:-1]
        label[hi[order][first]] = lo[order][first]
        while True:
            nxt = label[label]
            if np.array_equal(nxt, label):
                break
            label = nxt
        i, j = i[diff], j[diff]
    return label


def _scan(rings: Sequence[np.ndarray], y0: float, h: float, n: int
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Even-odd intervals of closed rings on the scan lines y = y0 + k h, k = 0..n-1:
    arrays (k, x_in, x_out), sorted by k then x."""
    a, b = _segments(rings)
    ylo = np.minimum(a[:, 1], b[:, 1])
    yhi = np.maximum(a[:, 1], b[:, 1])
    k0 = np.clip(np.ceil((ylo - y0) / h).astype(np.int64) - 1, 0, n)
    k1 = np.clip(np.ceil((yhi - y0) / h).astype(np.int64) + 1, 0, n)
    cnt = np.maximum(k1 - k0, 0)
    seg = np.repeat(np.arange(len(a)), cnt)
    k = k0[seg] + (np.arange(len(seg)) - np.repeat(np.cumsum(cnt) - cnt, cnt))
    y = y0 + k * h
    ok = (ylo[seg] <= y) & (y < yhi[seg])
    seg, k, y = seg[ok], k[ok], y[ok]
    ax, ay, bx, by = a[seg, 0], a[seg, 1], b[seg, 0], b[seg, 1]
    x = ax + (y - ay) * (bx - ax) / (by - ay)
    order = np.lexsort((x, k))
    k, x = k[order], x[order]
    # crossings per row are even (half-open rule on closed rings): pair them up
    return k[0::2], x[0::2], x[1::2]


def _geom_rings(geom: BaseGeometry) -> list[np.ndarray]:
    polys = shapely.get_parts(geom)
    rings = shapely.get_rings(polys)
    return [shapely.get_coordinates(r) for r in rings]


def _rectangle(region: BaseGeometry, d: float, side: str) -> BaseGeometry:
    h = d * RECT_SPACING
    if side == "outside":
        return _grow_rect(region, d, h).simplify(h / 2.0, preserve_topology=True)
    x0, y0, x1, y1 = region.bounds
    m = 2 * d + 2 * h
    box = shapely.box(x0 - m, y0 - m, x1 + m, y1 + m)
    comp = box.difference(region)
    grown = _grow_rect(comp, d, h)
    return region.difference(grown).simplify(h / 2.0, preserve_topology=True)


def _grow_rect(region: BaseGeometry, d: float, h: float) -> BaseGeometry:
    """The paper's solid rectangles: the hatch segments of the region, ``h`` apart, each
    standing for a strip of height ``h``, thickened by ``d`` on every side and united."""
    x0, y0, x1, y1 = region.bounds
    n = int(math.ceil((y1 - y0) / h)) + 1
    ys0 = y0 + ((y1 - y0) - (n - 1) * h) / 2.0
    k, xa, xb = _scan(_geom_rings(region), ys0, h, n)
    y = ys0 + k * h
    ext = d + h / 2.0
    return shapely.union_all(shapely.box(xa - d, y - ext, xb + d, y + ext))


def _raster(region: BaseGeometry, d: float, side: str, res: float, auto: bool
            ) -> BaseGeometry:
    """Pick the pixel size (``auto``: at least ``res``, coarsened to the pixel and radius
    limits) and run the raster method."""
    r = float(res)
    if auto:
        x0, y0, x1, y1 = region.bounds
        w, hgt = (x1 - x0) + 2 * d, (y1 - y0) + 2 * d
        r = max(r, math.sqrt(w * hgt / RASTER_MAX_PIXELS), d / RASTER_MAX_RADIUS_PX)
    return _raster_at(region, d, side, r)


def _raster_at(region: BaseGeometry, d: float, side: str, r: float) -> BaseGeometry:
    x0, y0, x1, y1 = region.bounds
    level = d / r + 0.5  # pixel centres lie on average half a pixel inside the boundary
    margin = int(math.ceil(level)) + 3
    W = int(math.ceil((x1 - x0) / r)) + 2 * margin
    H = int(math.ceil((y1 - y0) / r)) + 2 * margin
    if W * H > RASTER_HARD_LIMIT:
        raise ParamError(
            f"the raster kerf method would need {W} x {H} pixels at {r:g} units per pixel; "
            "choose a coarser raster_res_bits or the vector method")
    gx0 = x0 - margin * r
    gy0 = y0 - margin * r
    img = _rasterise(_geom_rings(region), gx0, gy0, r, W, H)
    feature = img if side == "outside" else ~img
    dist = np.sqrt(_edt2(feature, int(math.ceil(level)) + 2))
    field = (level - dist) if side == "outside" else (dist - level)
    rings = _marching_squares(field)
    if not rings:
        return shapely.Polygon()
    rings = [np.column_stack([gx0 + (rr[:, 0] + 0.5) * r, gy0 + (rr[:, 1] + 0.5) * r])
             for rr in rings]
    geom = _nest_rings(rings)
    return geom.simplify(0.5 * r, preserve_topology=True)


def _rasterise(rings: list[np.ndarray], gx0: float, gy0: float, r: float, W: int, H: int
               ) -> np.ndarray:
    """Even-odd fill at pixel centres: img[i, j] covers (gx0 + (j+.5) r, gy0 + (i+.5) r)."""
    k, xa, xb = _scan(rings, gy0 + 0.5 * r, r, H)
    ja = np.clip(np.ceil((xa - gx0) / r - 0.5).astype(np.int64), 0, W)
    jb = np.clip(np.ceil((xb - gx0) / r - 0.5).astype(np.int64), 0, W)
    diff = np.zeros(H * (W + 1), dtype=np.int32)
    diff += np.bincount(k * (W + 1) + ja, minlength=H * (W + 1)).astype(np.int32)
    diff -= np.bincount(k * (W + 1) + jb, minlength=H * (W + 1)).astype(np.int32)
    return (np.cumsum(diff.reshape(H, W + 1), axis=1)[:, :W] > 0)


def _edt2(feature: np.ndarray, cap: int) -> np.ndarray:
    """Squared Euclidean distance (pixels) from each pixel centre to the nearest feature
    pixel, exact up to ``cap`` and at least cap² beyond. Two separable passes: the 1-D
    distance along each column, then the lower envelope of shifted parabolas along each
    row, limited to ``|shift| <= cap``."""
    H, W = feature.shape
    big = cap + 1
    idx = np.arange(H)[:, None]
    prev = np.where(feature, idx, -10 * big - 10)
    prev = np.maximum.accumulate(prev, axis=0)
    nxt = np.where(feature, idx, H + 10 * big + 10)
    nxt = np.minimum.accumulate(nxt[::-1], axis=0)[::-1]
    g = np.minimum(np.minimum(idx - prev, nxt - idx), big).astype(np.float32)
    g2 = g * g
    out = g2.copy()
    inf = np.float32(big * big)
    for s in range(1, cap + 1):
        s2 = np.float32(s * s)
        if s2 >= inf:
            break
        np.minimum(out[:, s:], g2[:, :-s] + s2, out=out[:, s:])
        np.minimum(out[:, :-s], g2[:, s:] + s2, out=out[:, :-s])
    return out


def _marching_squares(f: np.ndarray) -> list[np.ndarray]:
    """Closed rings of the level set f = 0 (inside: f > 0) in pixel coordinates (x = column,
    y = row), exteriors counter-clockwise, holes clockwise. The field is padded with an
    outside border, so every ring closes. Saddles are resolved by the cell's mean value."""
    f = np.pad(f.astype(np.float64), 1, constant_values=-1.0)
    f[f == 0] = -1e-9  # no value exactly on the level
    H, W = f.shape
    ins = f > 0
    c0 = ins[:-1, :-1]  # (i, j)      bottom-left
    c1 = ins[:-1, 1:]   # (i, j+1)    bottom-right
    c2 = ins[1:, 1:]    # (i+1, j+1)  top-right
    c3 = ins[1:, :-1]   # (i+1, j)    top-left
    case = c0.astype(np.uint8) | (c1 << 1) | (c2 << 2) | (c3 << 3)
    ci, cj = np.nonzero((case != 0) & (case != 15))
    if len(ci) == 0:
        return []
    b = np.stack([c0[ci, cj], c1[ci, cj], c2[ci, cj], c3[ci, cj]], axis=1)
    nH = H * W
    # edge ids of the cell's CCW edges: bottom H(i,j), right V(i,j+1), top H(i+1,j), left V(i,j)
    e = np.stack([ci * W + cj, nH + ci * W + cj + 1, (ci + 1) * W + cj, nH + ci * W + cj],
                 axis=1)
    bn = np.roll(b, -1, axis=1)
    io = b & ~bn   # edge k goes inside -> outside (CCW)
    oi = ~b & bn
    nio = io.sum(axis=1)
    single = nio == 1
    src = [e[single][io[single]]]
    dst = [e[single][oi[single]]]
    sad = nio == 2
    if sad.any():
        si, sj = ci[sad], cj[sad]
        centre = (f[si, sj] + f[si, sj + 1] + f[si + 1, sj + 1] + f[si + 1, sj]) > 0
        es, ios = e[sad], io[sad]
        ks = np.nonzero(ios)[1].reshape(-1, 2)  # the two in->out edges, (0,2) or (1,3)
        rows = np.arange(len(es))[:, None]
        step = np.where(centre, 1, -1)[:, None]
        src.append(es[rows, ks].ravel())
        dst.append(es[rows, (ks + step) % 4].ravel())
    s = np.concatenate(src)
    t = np.concatenate(dst)
    ids = np.unique(s)
    si_ = np.searchsorted(ids, s)
    nxt = np.empty(len(ids), dtype=np.int64)
    nxt[si_] = np.searchsorted(ids, t)
    # crossing points
    horiz = ids < nH
    loc = np.where(horiz, ids, ids - nH)
    pi, pj = loc // W, loc % W
    qi = np.where(horiz, pi, pi + 1)
    qj = np.where(horiz, pj + 1, pj)
    fa, fb = f[pi, pj], f[qi, qj]
    tt = fa / (fa - fb)
    px = pj + np.where(horiz, tt, 0.0)
    py = pi + np.where(horiz, 0.0, tt)
    # cycles: min label by pointer jumping, then rank from the head by list ranking
    n = len(ids)
    lab = np.arange(n)
    p = nxt.copy()
    m = lab.copy()
    for _ in range(max(1, int(np.ceil(np.log2(n + 1))) + 1)):
        m = np.minimum(m, m[p])
        p = p[p]
    head = m == lab
    # break each cycle before its head: the node whose next is a head ends the list
    nb = np.where(head[nxt], lab, nxt)
    dist = np.where(nb == lab, 0, 1)
    p = nb.copy()
    for _ in range(max(1, int(np.ceil(np.log2(n + 1))) + 1)):
        dist = dist + dist[p]
        p = p[p]
    order = np.lexsort((-dist, m))
    ms = m[order]
    cuts = np.nonzero(np.diff(ms))[0] + 1
    # coordinates: x = column - 1 (undo the pad), y = row - 1
    xy = np.column_stack([px[order] - 1.0, py[order] - 1.0])
    out = []
    for part in np.split(xy, cuts):
        if len(part) >= 3:
            out.append(np.vstack([part, part[:1]]))
    return out


def _nest_rings(rings: list[np.ndarray]) -> BaseGeometry:
    """Polygons from disjoint simple rings (CCW shells, CW holes, as marching squares
    makes them): each hole goes to the smallest shell containing it."""
    areas = np.array([_signed_area(r) for r in rings])
    shells = [i for i in range(len(rings)) if areas[i] > 0]
    holes = [i for i in range(len(rings)) if areas[i] < 0]
    if not shells:
        return shapely.Polygon()
    shell_polys = shapely.polygons(_linearrings([rings[i] for i in shells]))
    tree = shapely.STRtree(shell_polys)
    assigned: dict[int, list[np.ndarray]] = {}
    if holes:
        pts = shapely.points(np.array([rings[h][0] for h in holes]))
        hi, si = tree.query(pts, predicate="within")
        sa = areas[np.array(shells)][si]
        best: dict[int, tuple[float, int]] = {}
        for h, s, a in zip(hi.tolist(), si.tolist(), sa.tolist(), strict=True):
            if h not in best or a < best[h][0]:
                best[h] = (a, s)
        for h, (_, s) in best.items():
            assigned.setdefault(s, []).append(rings[holes[h]])
    polys = [shapely.Polygon(rings[shells[k]], assigned.get(k, [])) for k in range(len(shells))]
    return shapely.MultiPolygon(polys) if len(polys) > 1 else polys[0]


# --------------------------------------------------------------------------- output
#: consecutive segments per LineString in the trees that find candidate segments
CHUNK_SEGMENTS = 4


def _chunk_tree(a: np.ndarray, b: np.ndarray, sizes: Sequence[int],
                k: int = CHUNK_SEGMENTS) -> tuple[shapely.STRtree, np.ndarray, np.ndarray]:
    """An STRtree of LineStrings of up to ``k`` consecutive segments (a[s], b[s]) of one
    ring each (rings of ``sizes`` segments, in order), the index of each chunk's first
    segment and its number of segments. Far fewer geometries than one per segment, which
    is what costs time; distances are then taken segment by segment."""
    per = np.asarray(sizes, dtype=np.int64)
    n = len(a)
    ring = np.repeat(np.arange(len(per)), per)
    pos = np.arange(n) - np.repeat(np.cumsum(per) - per, per)
    new = pos % k == 0
    chunk = np.cumsum(new) - 1
    first = np.flatnonzero(new)
    last = np.ones(n, dtype=bool)
    last[:-1] = new[1:] | (ring[1:] != ring[:-1])
    # each segment's start, then its end where it is the last of its chunk
    at = np.arange(n) + np.cumsum(last) - last
    xy = np.empty((n + int(last.sum()), 2))
    ids = np.empty(len(xy), dtype=np.int64)
    xy[at], ids[at] = a, chunk
    xy[at[last] + 1], ids[at[last] + 1] = b[last], chunk[last]
    tree = shapely.STRtree(shapely.linestrings(xy, indices=ids))
    return tree, first, np.diff(np.append(first, n))


def _nearest_segment(pts: np.ndarray, a: np.ndarray, b: np.ndarray, sizes: Sequence[int],
                     reach: float, points: np.ndarray | None = None,
                     chunks: tuple[shapely.STRtree, np.ndarray, np.ndarray] | None = None,
                     fallback: bool = True) -> np.ndarray:
    """Index of the segment (a[k], b[k]) nearest to each point (the lowest index among
    equally near ones). Candidates within ``reach`` come from one bulk STRtree query of
    chunks of segments (much faster than GEOS nearest-neighbour queries); points with
    none fall back to the nearest-neighbour query (-1 for them without ``fallback``).
    ``points``: ``pts`` as shapely Points, if at hand; ``chunks``: :func:`_chunk_tree`
    of the segments, if at hand."""
    n = len(pts)
    tree, first, count = chunks if chunks is not None else _chunk_tree(a, b, sizes)
    if points is None:
        points = shapely.points(pts)
    pi, ci = tree.query(points, predicate="dwithin", distance=reach)
    cnt = count[ci]
    pi = np.repeat(pi, cnt)
    si = np.repeat(first[ci], cnt) + (np.arange(len(pi)) - np.repeat(np.cumsum(cnt) - cnt, cnt))
    none_ = np.iinfo(np.int64).max
    best = np.full(n, none_, dtype=np.int64)
    if len(pi):
        dd = point_segment_distance(pts[pi], a[si], b[si])
        dmin = np.full(n, np.inf)
        np.minimum.at(dmin, pi, dd)  # per point: the smallest distance ...
        at = dd == dmin[pi]
        np.minimum.at(best, pi[at], si[at])  # ... and the lowest segment at it
    best[best == none_] = -1
    miss = np.nonzero(best < 0)[0]
    if len(miss) and fallback:
        seg_tree = shapely.STRtree(shapely.linestrings(np.stack([a, b], axis=1)))
        _, seg = seg_tree.query_nearest(shapely.points(pts[miss]), all_matches=False)
        best[miss] = seg
    return best


@dataclass(frozen=True, eq=False)
class _SourceSegments:
    """All segments of a pen's source rings, in ring order, with the tree of their chunks
    (:func:`_chunk_tree`): it does not depend on the kerf, so it is made once per drawing
    (when most of the segments are needed, as on nested many-ring files: 0.1 s on
    b_fabric_nesting) and queried at each kerf width."""

    a: np.ndarray
    b: np.ndarray
    owner: np.ndarray  # the source ring of each segment
    tree: shapely.STRtree
    first: np.ndarray
    count: np.ndarray

    @staticmethod
    def of(sources: list[np.ndarray]) -> _SourceSegments:
        a, b = _segments(sources)
        sizes = [len(s) - 1 for s in sources]
        tree, first, count = _chunk_tree(a, b, sizes)
        return _SourceSegments(a, b, np.repeat(np.arange(len(sources)), sizes), tree,
                               first, count)


#: the tree of all the source segments is made (and kept) once the segments of the
#: candidate sources are at least this share of them
SOURCE_TREE_SHARE = 0.5


def _nearest_source(pts: np.ndarray, sources: list[np.ndarray], reach: float,
                    kept: dict[int, _SourceSegments] | None = None, key: int = 0
                    ) -> np.ndarray:
    """Index of the source ring nearest to each point (every point lies within ``reach`` of
    some source, else the nearest-neighbour fallback finds it). A point within ``reach`` of
    only one source's bounding box has that source as its nearest; the others are settled
    segment by segment, with a tree of the segments of the sources that can be nearest to
    them (short pieces: a whole ring would make every distance O(ring size))."""
    n, m = len(pts), len(sources)
    near = np.full(n, -1, dtype=np.int64)
    begin = np.cumsum([0] + [len(s) for s in sources[:-1]])
    pts_all = np.concatenate(sources)
    lo = np.minimum.reduceat(pts_all, begin, axis=0) - reach
    hi = np.maximum.reduceat(pts_all, begin, axis=0) + reach
    boxes = shapely.STRtree(shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]))
    points = shapely.points(pts)
    pi, si = boxes.query(points)  # (point, box) pairs: the point is in the box
    count = np.bincount(pi, minlength=n)
    one = count[pi] == 1
    near[pi[one]] = si[one]
    rest = np.flatnonzero(count != 1)
    if (count == 0).any():
        cand = np.arange(m)  # a point beyond every box: any source may be nearest
    else:
        cand = np.unique(si[count[pi] > 1])
    if not len(rest):
        return near
    subset = [sources[j] for j in cand.tolist()]
    sizes = [len(s) - 1 for s in subset]
    every = kept.get(key) if kept is not None else None
    if every is None and kept is not None and \
            sum(sizes) >= SOURCE_TREE_SHARE * (len(pts_all) - m):
        every = kept[key] = _SourceSegments.of(sources)
    if every is not None:
        # the same answer as from the candidates' segments alone: a segment within reach
        # of a point belongs to a source whose box (grown by reach) holds the point, so to
        # a candidate; chunks are cut per ring, and segment order follows source order
        seg = _nearest_segment(pts[rest], every.a, every.b, (), reach, points[rest],
                               (every.tree, every.first, every.count), fallback=False)
        found = seg >= 0
        near[rest[found]] = every.owner[seg[found]]
        rest = rest[~found]
        if not len(rest):
            return near
    a, b = _segments(subset)
    owner = np.repeat(cand, sizes)
    near[rest] = owner[_nearest_segment(pts[rest], a, b, sizes, reach, points[rest])]
    return near


def _assign(result: BaseGeometry, sources: list[np.ndarray], reach: float,
            kept: dict[int, _SourceSegments] | None = None, key: int = 0
            ) -> tuple[list[tuple[np.ndarray, int]], set[int]]:
    """Each output ring with the (local) index of its source ring: the lowest index among
    the source rings nearest to its vertices. Also the set of source rings that some
    output vertex is nearest to. ``reach``: how far output vertices lie from their source
    (the offset distance plus the method's tolerance), used to find candidates fast.
    ``kept[key]``: the sources' segment tree, kept across calls (see
    :func:`_nearest_source`)."""
    rings = _geom_rings(result) if not result.is_empty else []
    rings = [r for r in rings if len(r) >= 4]
    if not rings:
        return [], set()
    if len(sources) == 1:
        return [(r, 0) for r in rings], {0}
    # every ASSIGN_STRIDE-th vertex of each output ring (at least one per ring) ...
    pts = np.concatenate([r[:-1:ASSIGN_STRIDE] for r in rings])
    which = np.repeat(np.arange(len(rings)), [len(r[:-1:ASSIGN_STRIDE]) for r in rings])
    near = _nearest_source(pts, sources, reach, kept, key)
    lowest = np.full(len(rings), np.iinfo(np.int64).max)
    np.minimum.at(lowest, which, near)
    contrib = set(near.tolist())
    # ... and the source rings no sampled vertex was nearest to are checked whole: one
    # within reach of an output ring contributes to it (a short stretch of a merged
    # outline), the others have vanished
    missing = [j for j in range(len(sources)) if j not in contrib]
    if missing:
        out_tree = shapely.STRtree(_linearrings(rings))
        src_lines = _linearrings([sources[j] for j in missing])
        mi, ri = out_tree.query(src_lines, predicate="dwithin", distance=reach)
        for m, r in zip(mi.tolist(), ri.tolist(), strict=True):
            contrib.add(missing[m])
            lowest[r] = min(int(lowest[r]), missing[m])
    return [(r, int(j)) for r, j in zip(rings, lowest, strict=True)], contrib


def _starts_near(rings_points: list[tuple[np.ndarray, np.ndarray]]) -> list[np.ndarray]:
    """Each closed ring rotated to start at its vertex nearest to its point (the first
    such vertex), all rings at once."""
    if not rings_points:
        return []
    bodies = [r[:-1] for r, _ in rings_points]
    sizes = np.array([len(b) for b in bodies])
    xy = np.concatenate(bodies)
    ring = np.repeat(np.arange(len(bodies)), sizes)
    p = np.array([q for _, q in rings_points], dtype=np.float64)
    d2 = ((xy - p[ring]) ** 2).sum(axis=1)
    order = np.lexsort((np.arange(len(xy)), d2, ring))  # per ring: nearest, then first
    begin = np.cumsum(sizes) - sizes
    k = order[begin] - begin
    return [np.concatenate([b[j:], b[:j + 1]]) for b, j in zip(bodies, k.tolist(), strict=True)]
