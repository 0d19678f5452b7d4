"""Region fill with hatch lines (paper 002): scan-line baseline and the zig-zag cover.

Regions come from the closed paths of a drawing by even-odd nesting: a ring inside an even
number of other rings is the outer ring of a region, the rings directly inside it are its
holes. ``source_index`` of a hatch stroke is the index of that outer ring in the drawing.

Both fills use the same hatch lines: in a frame rotated by ``-angle`` the lines are
horizontal, ``spacing`` apart, centred in each region's height.

* ``scanline`` (the baseline): one stroke per line piece inside the region, alternate lines
  in opposite directions.
* ``zigzag`` (paper 002): the region is cut into *monotone cells* at its critical points
  (every hatch line crosses a cell once; a boustrophedon decomposition found from the hatch
  lines themselves: two line pieces on neighbouring lines belong to one cell when the part of
  the region between the two lines that joins them touches no other piece). Inside a cell
  the pieces are joined end to end by the region's boundary between them, alternating right
  and left side (the laser stays on: one stroke per cell). Cells that meet along the same
  strip of region are joined into one stroke when the exit corner of one cell is joined to
  an entry corner of the next by a piece of the boundary that runs through their common
  strip; the walk through the cell graph is a path that visits each cell once
  (semi-Hamiltonian), searched greedily over all start corners within an effort bound.
  Nothing is marked twice: every piece of boundary is used at most once and no hatch line is
  traced twice; every connection runs along the region's boundary.

Everything here is in input units; the caller converts ``hatch_spacing_mm`` and
``hatch_inset_mm`` with :meth:`FieldMap.mm_to_units` and the points to bits with
:meth:`FieldMap.to_bits`.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LineString, MultiLineString, Polygon
from shapely.geometry.base import BaseGeometry

from galvo_core.drawing import Drawing

FILL_METHODS = ("scanline", "zigzag")
#: upper bound on chain steps spent searching for long cell paths, per region piece
MAX_EFFORT = 400_000


@dataclass(frozen=True, eq=False)
class HatchStroke:
    """One laser-on run of a fill: ``points`` (K, 2) input units, the laser on throughout.

    ``source_index``: index of the region's outer ring (a closed path) in the drawing;
    ``pass_index``: which hatch pass (angle) made it; ``cells``: how many monotone cells
    it covers (1 for a scan-line stroke).
    """

    source_index: int
    points: np.ndarray
    pass_index: int = 0
    cells: int = 1
    closed: bool = False

    @property
    def length(self) -> float:
        if len(self.points) < 2:
            return 0.0
        return float(np.hypot(*np.diff(self.points, axis=0).T).sum())


@dataclass(frozen=True)
class Region:
    """A connected fill region: ``polygon`` and the drawing index of its outer ring."""

    source_index: int
    polygon: Polygon
    holes: tuple[int, ...] = ()


# ------------------------------------------------------------------ regions
def _ring_polygon(points: np.ndarray) -> Polygon | None:
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) < 4:
        return None
    poly = Polygon(pts)
    if not poly.is_valid:
        poly = shapely.make_valid(poly)
        polys = [g for g in getattr(poly, "geoms", [poly]) if isinstance(g, Polygon)]
        if not polys:
            return None
        poly = max(polys, key=lambda g: g.area)
    if poly.area <= 0:
        return None
    return Polygon(poly.exterior)


def find_regions(drawing: Drawing) -> list[Region]:
    """Regions of the closed paths by even-odd nesting, holes respected.

    A closed path inside an even number of others is an outer ring; one inside an odd
    number is a hole of the smallest ring containing it. Open paths take no part.
    """
    idx: list[int] = []
    polys: list[Polygon] = []
    for i, p in enumerate(drawing.paths):
        if not p.closed:
            continue
        poly = _ring_polygon(p.points)
        if poly is not None:
            idx.append(i)
            polys.append(poly)
    n = len(polys)
    if n == 0:
        return []
    areas = np.array([p.area for p in polys])
    reps = np.array([p.representative_point().coords[0] for p in polys])
    tree = shapely.STRtree(polys)
    # pairs (container j, contained i): j contains a point of i and is larger
    pts = shapely.points(reps)
    i_pt, j_poly = tree.query(pts, predicate="within")
    keep = (i_pt != j_poly) & (areas[j_poly] > areas[i_pt])
    i_pt, j_poly = i_pt[keep], j_poly[keep]
    depth = np.bincount(i_pt, minlength=n)
    parent = np.full(n, -1)
    best = np.full(n, np.inf)
    for a, b in zip(i_pt.tolist(), j_poly.tolist(), strict=True):
        if areas[b] < best[a]:
            best[a] = areas[b]
            parent[a] = b
    holes: dict[int, list[int]] = {}
    for a in range(n):
        if depth[a] % 2 == 1 and parent[a] >= 0:
            holes.setdefault(int(parent[a]), []).append(a)
    out = []
    for a in range(n):
        if depth[a] % 2:
            continue
        hs = holes.get(a, [])
        poly = Polygon(polys[a].exterior, [polys[h].exterior for h in hs])
        if not poly.is_valid:
            fixed = shapely.make_valid(poly)
            poly = shapely.unary_union(
                [g for g in getattr(fixed, "geoms", [fixed]) if isinstance(g, Polygon)])
        out.append(Region(idx[a], poly, tuple(idx[h] for h in hs)))
    return out


def _pieces(geom: BaseGeometry) -> list[Polygon]:
    if geom.is_empty:
        return []
    if isinstance(geom, Polygon):
        return [geom]
    return [g for g in getattr(geom, "geoms", []) if isinstance(g, Polygon) and not g.is_empty]


def region_polygons(regions: Sequence[Region], inset_units: float = 0.0) -> list[
        tuple[int, Polygon]]:
    """(source_index, polygon piece) to hatch: each region shrunk by the inset."""
    out = []
    for r in regions:
        g: BaseGeometry = r.polygon
        if inset_units > 0:
            g = g.buffer(-inset_units, join_style="mitre", mitre_limit=4.0)
        for p in _pieces(g):
            out.append((r.source_index, shapely.orient_polygons(p) if hasattr(
                shapely, "orient_polygons") else p))
    return out


# ------------------------------------------------------------------ hatch topology
class _Hatch:
    """Hatch lines of one polygon piece in the rotated frame (lines are y = const).

    crossings: every crossing of a ring with a line, in ring order; segments: pairs of
    crossings on one line (inside the region between them); pieces: the boundary between
    consecutive crossings of a ring, each inside one strip between two lines.
    """

    def __init__(self, rings: list[np.ndarray], spacing: float) -> None:
        self.rings = rings
        ys = np.concatenate([r[:, 1] for r in rings])
        ymin, ymax = float(ys.min()), float(ys.max())
        h = ymax - ymin
        n_lines = max(1, math.ceil(h / spacing - 1e-9))
        # centred lines; a tiny irrational nudge keeps whole-number vertices off the lines
        self.y0 = ymin + (h - (n_lines - 1) * spacing) / 2.0 + spacing * 1.3e-7
        self.s = spacing
        self.n_lines = n_lines
        cx, ck, cup, cring, cedge = [], [], [], [], []
        for ri, r in enumerate(rings):
            nv = len(r)
            a = r
            b = np.roll(r, -1, axis=0)
            la = np.floor((a[:, 1] - self.y0) / spacing).astype(np.int64)
            lb = np.floor((b[:, 1] - self.y0) / spacing).astype(np.int64)
            cnt = np.abs(lb - la)
            tot = int(cnt.sum())
            if tot == 0:
                continue
            e = np.repeat(np.arange(nv), cnt)
            first = np.cumsum(cnt) - cnt
            j = np.arange(tot) - np.repeat(first, cnt)  # 0.. within the edge
            up = lb[e] > la[e]
            k = np.where(up, la[e] + 1 + j, la[e] - j)
            y = self.y0 + k * spacing
            ya, yb = a[e, 1], b[e, 1]
            t = np.clip((y - ya) / (yb - ya), 0.0, 1.0)
            x = a[e, 0] + t * (b[e, 0] - a[e, 0])
            cx.append(x)
            ck.append(k)
            cup.append(up)
            cring.append(np.full(tot, ri))
            cedge.append(e)
        if not cx:
            self.n = 0
            self.n_seg = 0
            return
        self.x = np.concatenate(cx)
        self.k = np.concatenate(ck)
        self.up = np.concatenate(cup)
        self.ring = np.concatenate(cring)
        self.edge = np.concatenate(cedge)
        n = self.n = len(self.x)
        # segments: crossings of a line sorted by x, paired
        order = np.lexsort((self.x, self.k))
        ks = self.k[order]
        # position within the line
        line_start = np.r_[0, np.flatnonzero(np.diff(ks)) + 1]
        counts = np.diff(np.r_[line_start, n])
        pos = np.arange(n) - np.repeat(line_start, counts)
        self.seg = np.empty(n, dtype=np.int64)
        self.end = np.empty(n, dtype=np.int64)  # 0 left, 1 right
        # segment ids: running pair index
        self.seg[order] = (np.arange(n) - pos) // 2 + pos // 2
        self.end[order] = pos % 2
        self.n_seg = n // 2
        self.seg_cross = np.empty((self.n_seg, 2), dtype=np.int64)
        self.seg_cross[self.seg, self.end] = np.arange(n)
        self.seg_k = self.k[self.seg_cross[:, 0]]
        # pieces: next/previous crossing along each ring
        nxt = np.empty(n, dtype=np.int64)
        prv = np.empty(n, dtype=np.int64)
        ring_bounds = np.r_[0, np.flatnonzero(np.diff(self.ring)) + 1, n]
        for a0, a1 in zip(ring_bounds[:-1], ring_bounds[1:], strict=True):
            ids = np.arange(a0, a1)
            nxt[ids] = np.roll(ids, -1)
            prv[ids] = np.roll(ids, 1)
        self.next = nxt
        self.prev = prv
        # the piece after crossing c lies above its line when c goes up, else below
        # nbr[c, side]: the other end of the piece at c on that side (side 1 = above)
        self.nbr = np.empty((n, 2), dtype=np.int64)
        side_after = self.up.astype(np.int64)
        self.nbr[np.arange(n), side_after] = nxt
        self.nbr[np.arange(n), 1 - side_after] = prv
        self.side_after = side_after

    # boundary points strictly between crossing c and its neighbour on `side`, in order
    def piece_points(self, c: int, side: int) -> np.ndarray:
        forward = self.side_after[c] == side
        a, b = (c, self.next[c]) if forward else (self.prev[c], c)
        r = self.rings[self.ring[a]]
        nv = len(r)
        ea, eb = int(self.edge[a]), int(self.edge[b])
        if b > a:
            cnt = eb - ea
        else:  # wrap round the ring
            cnt = eb + nv - ea
        if cnt <= 0:
            pts = np.empty((0, 2))
        else:
            pts = r[(ea + 1 + np.arange(cnt)) % nv]
        return pts if forward else pts[::-1]

    def point(self, c: int) -> np.ndarray:
        return np.array([self.x[c], self.y0 + self.k[c] * self.s])

    def segments_xy(self) -> np.ndarray:
        """(n_seg, 2, 2): left and right end of every segment."""
        y = self.y0 + self.seg_k * self.s
        xl = self.x[self.seg_cross[:, 0]]
        xr = self.x[self.seg_cross[:, 1]]
        return np.stack([np.stack([xl, y], 1), np.stack([xr, y], 1)], 1)

    # ---------------------------------------------------------- cells
    def cells(self) -> None:
        """Monotone cells: chains of segments joined by one-to-one strips."""
        ns = self.n_seg
        parent = list(range(2 * ns))

        def find(a: int) -> int:
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            return a

        seg = self.seg
        sa = self.side_after
        nxt = self.next
        for c in range(self.n):
            d = int(nxt[c])
            # piece c -> d: on side sa[c] of c's line; at d it lies on side 1 - sa[d]
            u = find(2 * int(seg[c]) + int(sa[c]))
            v = find(2 * int(seg[d]) + 1 - int(sa[d]))
            if u != v:
                parent[u] = v
        roots = np.array([find(a) for a in range(2 * ns)], dtype=np.int64)
        self.comp_dn = roots[0::2]
        self.comp_up = roots[1::2]
        n_b = np.bincount(self.comp_up, minlength=2 * ns)  # segments below each strip
        n_t = np.bincount(self.comp_dn, minlength=2 * ns)  # segments above each strip
        top_of = np.full(2 * ns, -1, dtype=np.int64)
        top_of[self.comp_dn] = np.arange(ns)
        one = (n_b[self.comp_up] == 1) & (n_t[self.comp_up] == 1)
        nxt_seg = np.where(one, top_of[self.comp_up], -1)
        has_prev = np.zeros(ns, dtype=bool)
        has_prev[nxt_seg[nxt_seg >= 0]] = True
        cell_of = np.full(ns, -1, dtype=np.int64)
        cell_segs: list[list[int]] = []
        # starts bottom-up so cells are numbered bottom to top
        starts = np.flatnonzero(~has_prev)
        starts = starts[np.argsort(self.seg_k[starts], kind="stable")]
        for s0 in starts.tolist():
            chain = [s0]
            cell_of[s0] = len(cell_segs)
            s = s0
            while nxt_seg[s] >= 0:
                s = int(nxt_seg[s])
                cell_of[s] = len(cell_segs)
                chain.append(s)
            cell_segs.append(chain)
        self.cell_of = cell_of
        self.cell_segs = cell_segs

    def _run(self, cell: int, from_top: bool, side: int) -> tuple[int, int]:
        """Exit crossing and exit direction (1 up / 0 down) of a cell entered at a corner."""
        segs = self.cell_segs[cell]
        n = len(segs)
        last = segs[0] if from_top else segs[-1]
        exit_side = side if n % 2 == 0 else 1 - side
        return int(self.seg_cross[last, exit_side]), 0 if from_top else 1

    def _step(self, exit_c: int, direction: int) -> tuple[int, bool, int] | None:
        """The cell reached through the boundary from an exit corner: (cell, from_top, side)."""
        q = int(self.nbr[exit_c, direction])
        g = int(self.seg[q])
        y = int(self.cell_of[g])
        segs = self.cell_segs[y]
        same_line = self.k[q] == self.k[exit_c]
        # q's segment faces the strip from below (same line going up / line above going
        # down) -> it is the top of its cell; else the bottom
        from_top = bool(same_line) if direction == 1 else not bool(same_line)
        if (segs[-1] if from_top else segs[0]) != g:
            return None
        return y, from_top, int(self.end[q])

    def chain(self, cell: int, from_top: bool, side: int, visited: np.ndarray,
              budget: list[int]) -> list[tuple[int, bool, int]]:
        out = [(cell, from_top, side)]
        seen = {cell}
        while budget[0] > 0:
            budget[0] -= 1
            c, d = self._run(*out[-1])
            nx = self._step(c, d)
            if nx is None or visited[nx[0]] or nx[0] in seen:
                break
            out.append(nx)
            seen.add(nx[0])
        return out

    def stroke_points(self, chain: list[tuple[int, bool, int]]) -> np.ndarray:
        pts: list[np.ndarray] = []
        prev_exit: tuple[int, int] | None = None
        for cell, from_top, side in chain:
            segs = self.cell_segs[cell]
            order = segs[::-1] if from_top else segs
            direction = 0 if from_top else 1
            sd = side
            if prev_exit is not None:
                pts.append(self.piece_points(*prev_exit))
            for i, s in enumerate(order):
                a = int(self.seg_cross[s, sd])
                b = int(self.seg_cross[s, 1 - sd])
                pts.append(self.point(a)[None])
                pts.append(self.point(b)[None])
                if i + 1 < len(order):
                    pts.append(self.piece_points(b, direction))
                sd = 1 - sd
                prev_exit = (b, direction)
        arr = np.concatenate(pts)
        keep = np.r_[True, (np.diff(arr, axis=0) != 0).any(axis=1)]
        return arr[keep]


def _rotation(angle_deg: float) -> np.ndarray:
    a = math.radians(angle_deg)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s], [s, c]])  # rotated frame -> drawing: p = R @ q


def _rings_rotated(poly: Polygon, rot: np.ndarray) -> list[np.ndarray]:
    rings = [poly.exterior, *poly.interiors]
    out = []
    for r in rings:
        pts = np.asarray(r.coords, dtype=np.float64)[:-1]
        if len(pts) >= 3:
            out.append(pts @ rot)  # q = R^T p  (row vectors: p @ R)
    return out


def _zigzag(h: _Hatch, max_effort: int) -> list[tuple[list[tuple[int, bool, int]], int]]:
    """Cover the cell graph by paths; returns (chain, number of cells) per stroke.

    From a start corner the walk is forced (the boundary leads from a cell's exit corner to
    exactly one corner of a neighbouring cell), so every one of the 4 start corners of every
    cell gives one path; the longest still unvisited path is taken, its cells are marked
    visited, the others are cut short at the first visited cell, and so on. Chains are
    searched at most ``max_effort`` steps in all (longer ones are followed to their end only
    when taken).
    """
    h.cells()
    nc = len(h.cell_segs)
    if nc == 0:
        return []
    visited = np.zeros(nc, dtype=bool)
    starts = [(c, ft, sd) for c in range(nc) for ft in (False, True) for sd in (0, 1)]
    cap = max(8, max_effort // len(starts))
    chains: list[list[tuple[int, bool, int]]] = []
    capped: list[bool] = []
    users: list[list[int]] = [[] for _ in range(nc)]
    heap: list[tuple[int, int]] = []
    for i, st in enumerate(starts):
        ch = h.chain(*st, visited, [cap])
        chains.append(ch)
        capped.append(len(ch) >= cap)
        for c, _, _ in ch:
            users[c].append(i)
        heap.append((-len(ch), i))
    heapq.heapify(heap)
    lengths = [len(ch) for ch in chains]
    out = []
    while heap:
        neg, i = heapq.heappop(heap)
        if -neg != lengths[i] or lengths[i] == 0:
            continue
        ch = chains[i][: lengths[i]]
        if capped[i] and lengths[i] == len(chains[i]):
            ch = h.chain(*ch[0], visited, [nc + 1])
        for c, _, _ in ch:
            visited[c] = True
        out.append((ch, len(ch)))
        for c, _, _ in ch:
            for j in users[c]:
                if lengths[j] == 0:
                    continue
                pos = next((p for p in range(lengths[j]) if visited[chains[j][p][0]]),
                           lengths[j])
                if pos != lengths[j]:
                    lengths[j] = pos
                    capped[j] = False
                    if pos:
                        heapq.heappush(heap, (-pos, j))
    return out


def hatch(
    regions_drawing: Drawing,
    *,
    fill: str,
    spacing_units: float,
    angle_deg: float = 0.0,
    passes: int = 1,
    angle_step_deg: float = 90.0,
    inset_units: float = 0.0,
    max_effort: int = MAX_EFFORT,
) -> list[HatchStroke]:
    """Hatch strokes filling the regions of the drawing's closed paths.

    ``fill``: 'none' (no strokes), 'scanline' or 'zigzag'. ``spacing_units`` and
    ``inset_units`` are input units; pass ``p`` uses ``angle_deg + p * angle_step_deg``.
    Strokes come region by region (file order of the outer rings), pass by pass, bottom to
    top of the rotated frame; order them for the job with :func:`galvo_core.order`.
    """
    if fill == "none":
        return []
    if fill not in FILL_METHODS:
        raise ValueError(f"fill must be one of none, {', '.join(FILL_METHODS)}; got {fill!r}")
    if not (spacing_units > 0 and math.isfinite(spacing_units)):
        raise ValueError(f"spacing_units must be a positive number, got {spacing_units!r}")
    pieces = region_polygons(find_regions(regions_drawing), inset_units)
    out: list[HatchStroke] = []
    for src, poly in pieces:
        for p in range(passes):
            rot = _rotation(angle_deg + p * angle_step_deg)
            out.extend(_hatch_piece(poly, src, p, rot, fill, spacing_units, max_effort))
    return out


def _hatch_piece(poly: Polygon, src: int, pass_index: int, rot: np.ndarray, fill: str,
                 spacing: float, max_effort: int) -> list[HatchStroke]:
    rings = _rings_rotated(poly, rot)
    if not rings:
        return []
    h = _Hatch(rings, spacing)
    if h.n == 0:
        return []
    out = []
    if fill == "scanline":
        xy = h.segments_xy()
        odd = (h.seg_k % 2).astype(bool)
        # serpentine raster: odd lines right to left, pieces of a line in that direction
        order = np.lexsort((np.where(odd, -xy[:, 0, 0], xy[:, 0, 0]), h.seg_k))
        for s in order.tolist():
            a, b = xy[s]
            if odd[s]:
                a, b = b, a
            if a[0] == b[0]:
                continue
            out.append(HatchStroke(src, np.array([a, b]) @ rot.T, pass_index, 1))
        return out
    for chain, ncells in _zigzag(h, max_effort):
        pts = h.stroke_points(chain)
        out.append(HatchStroke(src, pts @ rot.T, pass_index, ncells))
    return out


def monotone_cells(regions_drawing: Drawing, *, spacing_units: float, angle_deg: float = 0.0,
                   inset_units: float = 0.0) -> int:
    """How many monotone cells the zig-zag fill cuts the regions into (one pass)."""
    total = 0
    rot = _rotation(angle_deg)
    for _, poly in region_polygons(find_regions(regions_drawing), inset_units):
        rings = _rings_rotated(poly, rot)
        if not rings:
            continue
        h = _Hatch(rings, spacing_units)
        if h.n:
            h.cells()
            total += len(h.cell_segs)
    return total


# ------------------------------------------------------------------ metrics
def retraced_length(lines: Sequence[np.ndarray], tol: float = 1e-6) -> float:
    """Length marked more than once: total length minus the length of the union."""
    geoms = [LineString(p) for p in lines if len(p) >= 2]
    if not geoms:
        return 0.0
    total = sum(g.length for g in geoms)
    union = shapely.unary_union(MultiLineString(geoms) if len(geoms) > 1 else geoms[0])
    return max(0.0, total - union.length) if total - union.length > tol * total else 0.0


def coverage(regions: BaseGeometry, lines: Sequence[np.ndarray], spacing: float) -> float:
    """Fraction of the regions' area within ``spacing / 2`` of a hatch stroke."""
    if regions.is_empty or regions.area <= 0:
        return 1.0
    geoms = [LineString(p) for p in lines if len(p) >= 2]
    if not geoms:
        return 0.0
    bufs = shapely.buffer(np.array(geoms, dtype=object), spacing / 2.0, quad_segs=4)
    try:
        inter = regions.intersection(shapely.unary_union(bufs))
    except shapely.errors.GEOSException:  # robustness: snap everything to a fine grid
        grid = spacing * 1e-4
        cover = shapely.unary_union(shapely.set_precision(bufs, grid), grid_size=grid)
        inter = shapely.intersection(shapely.set_precision(regions, grid), cover,
                                     grid_size=grid)
    return float(inter.area / regions.area)


def fill_metrics(
    regions_drawing: Drawing,
    strokes: Sequence[HatchStroke],
    *,
    spacing_units: float,
    inset_units: float = 0.0,
    laser: object | None = None,
    field_map: object | None = None,
    contour_marks: Sequence[np.ndarray] = (),
    with_coverage: bool = True,
) -> dict[str, float | int]:
    """Strokes, laser switches, mark and jump length (input units), re-traced length,
    coverage and, given a laser and a field map, the estimated time of the hatch strokes in
    the order given (plus ``contour_marks`` after them) via :func:`timing.estimate`."""
    from galvo_core.timing import estimate

    pts = [s.points for s in strokes]
    mark = sum(s.length for s in strokes)
    jump = 0.0
    for a, b in zip(pts[:-1], pts[1:], strict=False):
        jump += float(np.hypot(*(b[0] - a[-1])))
    out: dict[str, float | int] = {
        "strokes": len(strokes),
        "laser_switches": len(strokes),
        "cells": sum(s.cells for s in strokes),
        "mark_length": mark,
        "jump_length": jump,
        "retraced_length": retraced_length(pts),
    }
    if with_coverage:
        polys = [poly for _, poly in region_polygons(find_regions(regions_drawing),
                                                     inset_units)]
        out["coverage"] = coverage(shapely.unary_union(polys), pts, spacing_units)
    if laser is not None and field_map is not None:
        fm = field_map
        marks = [fm.to_bits(p) for p in pts] + list(contour_marks)  # type: ignore[attr-defined]
        t = estimate(marks, laser, fm.mm_per_bit)  # type: ignore[arg-type,attr-defined]
        out.update({f"est_{k}": v for k, v in t.items()})
    return out
