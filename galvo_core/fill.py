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
  and left side (the laser stays on). Cells are joined into one stroke along a path that
  visits each cell once (a semi-Hamiltonian path of the cell graph, searched depth-first with
  Warnsdorff's rule, component by component, within a number of steps linear in the cells;
  when they are spent, greedy walks cover the rest: strokes <= cells always); the join from
  one cell to the next is the piece of boundary between the exit corner and the next cell's
  corner. Theorem 2 of the paper (a
  convex cell can be covered from any boundary point to any other) makes the exit corner a
  free choice: a cell whose zig-zag would end on the wrong side gets one more hatch line
  half-way between two of its lines (in its narrowest strip), and a cell entered and left at
  the same end (a U-turn) is covered by a run along one side on the boundary up to its far
  end and the zig-zag back, whose lines stop ``UTURN_OFFSET`` spacings short of that side and
  are joined there by chords (the boundary shifted inward). Nothing is marked twice: every
  piece of boundary is used at most once, no hatch line is traced twice, the joins between
  cells run along the boundary, and no stroke leaves the region or crosses a hole.

Everything here is in input units; the caller converts ``hatch_spacing_mm`` and
``hatch_inset_mm`` with :meth:`FieldMap.mm_to_units` and the points to bits with
:meth:`FieldMap.to_bits`.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LineString, MultiLineString, Polygon
from shapely.geometry.base import BaseGeometry

from galvo_core.drawing import Drawing
from galvo_core.kerf import _components

FILL_METHODS = ("scanline", "zigzag")
#: search steps for long cell paths per monotone cell of a region piece (plus EFFORT_BASE);
#: when they are spent the cells left are covered by greedy walks (linear, no search)
EFFORT_PER_CELL = 100
EFFORT_BASE = 3000
#: the old name of the per-piece bound (now per cell)
MAX_EFFORT = EFFORT_PER_CELL
#: a U-turn cell's lines stop this many spacings short of the side run along the boundary
#: (horizontally); below 1, so every point between them stays within half a spacing of a mark
UTURN_OFFSET = 0.9
#: search steps spent looking for a cheaper cover once one stroke covers a whole piece
FULL_COVER_EXTRA = 3000
#: each start of a stroke's search gets this share of the steps the stroke has left (the
#: starts with the fewest free neighbours first, so they get the most)
ALLOC_DIV = 4


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
        # piece c -> next[c]: on side sa[c] of c's line; at next[c] it lies on side
        # 1 - sa[next[c]]; the strips (segment, side) a piece joins are one strip
        d = self.next
        roots = _components(2 * ns, 2 * self.seg + self.side_after,
                            2 * self.seg[d] + 1 - self.side_after[d])
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

    # ---------------------------------------------------------- cell walk (paper 002, Thm 2)
    def _prepare_walk(self) -> None:
        a = np.concatenate(self.rings)
        b = np.concatenate([np.roll(r, -1, axis=0) for r in self.rings])
        self._ea, self._eb = a, b
        self._ring_cat = a
        self._ring_len = np.array([len(r) for r in self.rings], dtype=np.int64)
        self._ring_off = np.cumsum(self._ring_len) - self._ring_len
        self._tiny = 1e-9 * max(1.0, float(np.abs(a).max()))
        self._rungs: dict[tuple[int, bool], tuple | None] = {}
        self._uok: dict[tuple[int, int, int, bool, bool], bool] = {}
        self._extra_cost: dict[int, float | None] = {}
        self._opt_cache: dict[tuple[int, int, int | None], list[tuple]] = {}

    def _base_rungs(self, c: int) -> tuple:
        """(y (N,), xs (N, 2), pieces[side][j]: boundary points between rung j and j+1, up)."""
        segs = self.cell_segs[c]
        sa = np.array(segs, dtype=np.int64)
        y = self.y0 + self.seg_k[sa] * self.s
        xs = np.stack([self.x[self.seg_cross[sa, 0]], self.x[self.seg_cross[sa, 1]]], 1)
        if len(sa) < 2:
            return y, xs, [[], []]
        cr = self.seg_cross[sa[:-1]]
        pcs = self._pieces_up(np.concatenate([cr[:, 0], cr[:, 1]]))
        m = len(sa) - 1
        return y, xs, [pcs[:m], pcs[m:]]

    def _pieces_up(self, cs: np.ndarray) -> list[np.ndarray]:
        """:meth:`piece_points` ``(c, 1)`` for every crossing c of ``cs`` at once."""
        fwd = self.side_after[cs] == 1
        a = np.where(fwd, cs, self.prev[cs])
        b = np.where(fwd, self.next[cs], cs)
        ring = self.ring[a]
        nv = self._ring_len[ring]
        ea, eb = self.edge[a], self.edge[b]
        cnt = np.maximum(np.where(b > a, eb - ea, eb + nv - ea), 0)
        tot = int(cnt.sum())
        if tot == 0:
            return [np.empty((0, 2))] * len(cs)
        first = np.cumsum(cnt) - cnt
        jj = np.arange(tot) - np.repeat(first, cnt)
        cr = np.repeat(cnt, cnt)
        jj = np.where(np.repeat(fwd, cnt), jj, cr - 1 - jj)
        idx = (np.repeat(ea, cnt) + 1 + jj) % np.repeat(nv, cnt) + np.repeat(
            self._ring_off[ring], cnt)
        pts = self._ring_cat[idx]
        ends = (first + cnt).tolist()
        return [pts[i:j] for i, j in zip(first.tolist(), ends, strict=True)]

    def _split(self, p0: np.ndarray, piece: np.ndarray, p1: np.ndarray, ym: float
               ) -> tuple[float, np.ndarray, np.ndarray] | None:
        poly = np.vstack([p0[None], piece, p1[None]])
        cr = np.flatnonzero((poly[:-1, 1] < ym) != (poly[1:, 1] < ym))
        if len(cr) != 1:
            return None
        i = int(cr[0])
        pa, pb = poly[i], poly[i + 1]
        t = (ym - pa[1]) / (pb[1] - pa[1])
        return float(pa[0] + t * (pb[0] - pa[0])), poly[1:i + 1], poly[i + 1:-1]

    def _with_extra(self, c: int) -> tuple | None:
        """The cell's rungs with one more hatch line half-way between two of its lines, in
        the narrowest strip where that line meets the cell's two sides once each and nothing
        else: the zig-zag then has one line more, so it ends on the other side (the parity
        fix that lets a cell be left at the corner the next cell needs)."""
        key = (c, True)
        if key in self._rungs:
            return self._rungs[key]
        y, xs, pcs = self._base_rungs(c)
        out = None
        n = len(y)
        if n >= 2:
            w = xs[:, 1] - xs[:, 0]
            approx = np.minimum(w[:-1], w[1:])
            for j in np.argsort(approx, kind="stable")[:6].tolist():
                ym = 0.5 * (y[j] + y[j + 1])
                sl = self._split(np.array([xs[j, 0], y[j]]), pcs[0][j],
                                 np.array([xs[j + 1, 0], y[j + 1]]), ym)
                sr = self._split(np.array([xs[j, 1], y[j]]), pcs[1][j],
                                 np.array([xs[j + 1, 1], y[j + 1]]), ym)
                if sl is None or sr is None or not sl[0] < sr[0]:
                    continue
                xa, xb = sl[0], sr[0]
                ea, eb = self._ea, self._eb
                cr = (ea[:, 1] < ym) != (eb[:, 1] < ym)
                if cr.any():
                    t = (ym - ea[cr, 1]) / (eb[cr, 1] - ea[cr, 1])
                    xc = ea[cr, 0] + t * (eb[cr, 0] - ea[cr, 0])
                    if ((xc > xa + self._tiny) & (xc < xb - self._tiny)).any():
                        continue
                y2 = np.insert(y, j + 1, ym)
                xs2 = np.insert(xs, j + 1, [xa, xb], axis=0)
                p2 = [pcs[0][:j] + [sl[1], sl[2]] + pcs[0][j + 1:],
                      pcs[1][:j] + [sr[1], sr[2]] + pcs[1][j + 1:]]
                out = (y2, xs2, p2)
                self._extra_cost[c] = xb - xa
                break
        self._rungs[key] = out
        return out

    def _rungs_of(self, c: int, extra: bool) -> tuple | None:
        if extra:
            return self._with_extra(c)
        key = (c, False)
        if key not in self._rungs:
            self._rungs[key] = self._base_rungs(c)
        return self._rungs[key]

    @staticmethod
    def _oriented(r: tuple, from_top: bool) -> tuple:
        y, xs, pcs = r
        if not from_top:
            return r
        return (y[::-1], xs[::-1], [[p[::-1] for p in reversed(pcs[sd])] for sd in (0, 1)])

    def _uturn_ok(self, c: int, e: int, s: int, extra: bool, cap: bool) -> bool:
        """Can the cell be entered at corner (end e, side s) and left at (e, 1 - s)?

        Theorem 2 of paper 002: a run along side s (the boundary) to the far end, then the
        zig-zag back, its lines kept half a spacing off side s and joined there by chords
        (the boundary shifted inward), so nothing is marked twice."""
        key = (c, e, s, extra, cap)
        if key in self._uok:
            return self._uok[key]
        r = self._rungs_of(c, extra)
        ok = r is not None
        if ok:
            y, xs, pcs = self._oriented(r, e == 1)  # type: ignore[arg-type]
            n = len(y)
            ok = (n % 2 == 0) if cap else (n % 2 == 1)
            if ok and n > 1:
                a = UTURN_OFFSET * self.s
                sign = 1.0 if s == 0 else -1.0
                m = n if cap else n - 1  # rungs 0..m-1 are shortened on side s
                ok = bool(((xs[:m, 1] - xs[:m, 0]) > a * 1.05).all())
                for sd, want in ((s, 1.0), (1 - s, -1.0)):
                    if not ok or m < 2:
                        break
                    ps = pcs[sd][:m - 1]
                    lens = np.fromiter((len(q) for q in ps), dtype=np.int64, count=len(ps))
                    if not lens.any():
                        continue
                    p = np.concatenate(ps)
                    j = np.repeat(np.arange(m - 1), lens)
                    ox0, ox1 = xs[j, s] + sign * a, xs[j + 1, s] + sign * a
                    t = (p[:, 1] - y[j]) / (y[j + 1] - y[j])
                    cx = ox0 + t * (ox1 - ox0)
                    ok = bool((want * sign * (cx - p[:, 0]) > self._tiny).all())
        self._uok[key] = ok
        return ok

    def _target(self, c: int, end: int, side: int) -> tuple[int, int, int] | None:
        """Where the boundary piece from the corner (end, side) of cell c leads:
        (cell, end, side) of the corner at its other end; None when that is no cell end."""
        segs = self.cell_segs[c]
        g0 = segs[-1] if end == 1 else segs[0]
        q = int(self.seg_cross[g0, side])
        q2 = int(self.nbr[q, end])
        g = int(self.seg[q2])
        c2 = int(self.cell_of[g])
        e2 = end if self.k[q2] == self.k[q] else 1 - end
        segs2 = self.cell_segs[c2]
        if (segs2[-1] if e2 == 1 else segs2[0]) != g:
            return None
        return c2, e2, int(self.end[q2])

    def _is_cap(self, c: int, end: int) -> bool:
        t = self._target(c, end, 0)
        return t is not None and t[0] == c and t[1] == end

    def _cost(self, c: int, extra: bool, uturn: bool) -> float:
        cost = 0.0
        if extra:
            self._with_extra(c)
            cost += float(self._extra_cost.get(c) or 0.0)
        if uturn:
            cost += 2.0 * self.s
        return cost

    def _options(self, c: int, e: int, s: int | None) -> list[tuple]:
        """Ways to leave cell c entered at (e, s) (s None: the stroke starts here):
        (next (cell, end, side), exit end, exit side, uturn, extra, cap, cost)."""
        key = (c, e, s)
        hit = self._opt_cache.get(key)
        if hit is not None:
            return hit
        n = len(self.cell_segs[c])
        out = []
        for t in (0, 1):  # through: leave at the other end, side t
            extra = s is not None and t != (s if n % 2 == 0 else 1 - s)
            if extra and self._with_extra(c) is None:
                continue
            nx = self._target(c, 1 - e, t)
            if nx is None or nx[0] == c:
                continue
            out.append((nx, 1 - e, t, False, extra, False, self._cost(c, extra, False)))
        if s is not None:  # U-turn: leave at the same end, other side
            nx = self._target(c, e, 1 - s)
            if nx is not None and nx[0] != c:
                far_cap = self._is_cap(c, 1 - e)
                for extra in (False, True):
                    for cap in ((False, True) if far_cap else (False,)):
                        if self._uturn_ok(c, e, s, extra, cap):
                            out.append((nx, e, 1 - s, True, extra, cap,
                                        self._cost(c, extra, True)))
                            break
                    else:
                        continue
                    break
        self._opt_cache[key] = out
        return out

    def walk(self, effort_per_cell: int = EFFORT_PER_CELL) -> list[list[tuple]]:
        """Cover the cells by few paths (semi-Hamiltonian paths of the cell graph): each path
        is one stroke. A path element is (cell, entry end, entry side, uturn, extra, cap,
        exit side).

        Exact where it is cheap, bounded everywhere: stroke by stroke, the longest path
        through the connected part of the cells left that holds the cell with the fewest
        free neighbours is searched depth-first (Warnsdorff's rule first), within a share
        of ``EFFORT_BASE + effort_per_cell * cells`` steps for the whole piece (a search
        that ends before its share is exact: the longest path there is); when the piece's
        steps are spent, the cells left are covered by greedy walks (each step to the free
        neighbour with the fewest free neighbours, no backtracking; every cell is entered
        once). Every path covers at least one new cell, so strokes <= cells, and the work
        is linear in the cells. :attr:`effort` counts the search and walk steps."""
        self.cells()
        nc = len(self.cell_segs)
        self.effort = 0
        if nc == 0:
            return []
        self._prepare_walk()
        nbrs: list[list[int]] = [[] for _ in range(nc)]
        for c in range(nc):
            for end in (0, 1):
                for side in (0, 1):
                    t = self._target(c, end, side)
                    if t is not None and t[0] != c:
                        nbrs[c].append(t[0])
                        nbrs[t[0]].append(c)
        nbrs = [list(dict.fromkeys(n)) for n in nbrs]
        visited = np.zeros(nc, dtype=bool)
        total = EFFORT_BASE + max(0, int(effort_per_cell)) * nc
        paths: list[list[tuple]] = []
        depth_cap = max(50, sys.getrecursionlimit() - 200)
        # search state of the current stroke: cells left, best path, path so far, effort
        st: dict = {}

        def free_nbrs(c: int) -> int:
            seen = st["seen"]
            return sum(1 for d in nbrs[c] if not seen[d])

        def dfs(c: int, e: int, s: int | None, cost: float, depth: int) -> bool:
            seen, cur = st["seen"], st["cur"]
            st["budget"] -= 1
            seen[c] = True
            opts = []
            if st["budget"] > 0 and depth < depth_cap:
                opts = [o for o in self._options(c, e, s) if not seen[o[0][0]]]
                # Warnsdorff: the neighbour with the fewest free neighbours first
                opts.sort(key=lambda o: (free_nbrs(o[0][0]), o[6]))
            done = False
            for nx, _ee, t, ut, extra, cap, oc in opts:
                cur.append((c, e, s, ut, extra, cap, t))
                done = dfs(nx[0], nx[1], nx[2], cost + oc, depth + 1)
                cur.pop()
                if done or st["budget"] <= 0:
                    break
            if not done:
                n_cells = len(cur) + 1
                best = st["best"]
                if n_cells > best[0] or (n_cells == best[0] and cost < best[1]):
                    st["best"] = (n_cells, cost, [*cur, (c, e, s, False, False, False, None)])
                if n_cells == st["left"] and st["full_at"] < 0:
                    st["full_at"] = st["budget"]
                # as long as no path can be: stop when it costs nothing or after a little
                # more search
                done = n_cells == st["left"] and (
                    cost == 0.0 or st["full_at"] - st["budget"] > FULL_COVER_EXTRA)
            seen[c] = False
            return done

        def component(c0: int) -> list[int]:
            """The cells left that are connected to c0 (c0 first)."""
            mark = {c0}
            out = [c0]
            for c in out:
                for d in nbrs[c]:
                    if not visited[d] and d not in mark:
                        mark.add(d)
                        out.append(d)
            return out

        def greedy(c0: int) -> list[tuple]:
            """The longer of the two greedy walks from c0 (entered at either end)."""
            best: list[tuple] = []
            seen = st["seen"] = visited.copy()
            for e0 in (0, 1):
                path: list[tuple] = []
                c, e, s = c0, e0, None
                while True:
                    self.effort += 1
                    seen[c] = True
                    opts = [o for o in self._options(c, e, s) if not seen[o[0][0]]]
                    if not opts:
                        path.append((c, e, s, False, False, False, None))
                        break
                    nx, _ee, t, ut, extra, cap, _oc = min(
                        opts, key=lambda o: (free_nbrs(o[0][0]), o[6]))
                    path.append((c, e, s, ut, extra, cap, t))
                    c, e, s = nx
                for el in path:
                    seen[el[0]] = False
                if len(path) > len(best):
                    best = path
            return best

        pending = sorted(range(nc), key=lambda c: len(nbrs[c]))
        head = 0
        while head < nc:
            while head < nc and visited[pending[head]]:
                head += 1
            if head >= nc:
                break
            c_first = pending[head]
            if total <= 0:  # the bounded construction
                path = greedy(c_first)
                for el in path:
                    visited[el[0]] = True
                paths.append(path)
                continue
            comp = component(c_first)
            self.effort += len(comp)
            total -= len(comp)
            st["seen"] = visited
            free = [free_nbrs(c) for c in comp]
            # a cell with one free neighbour can only end a path: no path holds more than
            # two of them (the longest possible path, found: the search is done)
            leaves = sum(1 for f in free if f <= 1)
            st.update(left=len(comp) - max(0, leaves - 2), best=(0, 0.0, []), cur=[],
                      seen=visited.copy(), full_at=-1, budget=0)
            starts = [c for _, c in sorted(zip(free, comp, strict=True),
                                           key=lambda fc: fc[0])]
            share = min(total, EFFORT_BASE + max(0, int(effort_per_cell)) * len(comp))
            fin = False
            for c0 in starts:
                for e0 in (0, 1):
                    if share <= 0:
                        break
                    allow = min(share, max(200, share // ALLOC_DIV))
                    st["budget"] = allow
                    st["full_at"] = -1 if st["best"][0] < st["left"] else allow
                    fin = dfs(c0, e0, None, 0.0, 0)
                    used = allow - max(0, st["budget"])
                    share -= used
                    total -= used
                    self.effort += used
                    if fin:
                        break
                if fin or share <= 0:
                    break
            best = st["best"]
            if not best[0]:
                best = (1, 0.0, greedy(c_first))
            for el in best[2]:
                visited[el[0]] = True
            paths.append(best[2])
        return paths

    def stroke_points(self, path: list[tuple]) -> np.ndarray:
        pts: list[np.ndarray] = []
        a = UTURN_OFFSET * self.s
        for i, (c, e, s, ut, extra, cap, t) in enumerate(path):
            n0 = len(self.cell_segs[c])
            n = n0 + (1 if extra else 0)
            if s is None:  # first cell: pick the entry side that ends at the exit side t
                if t is None:
                    s = 0
                else:
                    s = t if n % 2 == 0 else 1 - t
            r = self._oriented(self._rungs_of(c, extra), e == 1)  # type: ignore[arg-type]
            y, xs, pcs = r

            ends = (np.column_stack([xs[:, 0], y]), np.column_stack([xs[:, 1], y]))

            def pt(j: int, sd: int, ends: tuple = ends) -> np.ndarray:
                return ends[sd][j:j + 1]

            if not ut:
                sd = s
                for j in range(n):
                    pts += [pt(j, sd), pt(j, 1 - sd)]
                    if j + 1 < n:
                        pts.append(pcs[1 - sd][j])
                    sd = 1 - sd
                exit_end, exit_side = 1 - e, sd
            else:
                sign = 1.0 if s == 0 else -1.0

                def o(j: int, sd: int = s, y: np.ndarray = y, xs: np.ndarray = xs,
                      sign: float = sign) -> np.ndarray:
                    return np.array([[xs[j, sd] + sign * a, y[j]]])

                pts.append(pt(0, s))
                for j in range(n - 1):  # the run along side s
                    pts += [pcs[s][j], pt(j + 1, s)]
                if cap:
                    segs = self.cell_segs[c]
                    g = segs[0] if e == 1 else segs[-1]
                    pts += [self.piece_points(int(self.seg_cross[g, s]), 1 - e),
                            pt(n - 1, 1 - s), o(n - 1)]
                    cur = s
                else:
                    pts.append(pt(n - 1, 1 - s))
                    cur = 1 - s
                for j in range(n - 2, -1, -1):
                    if cur == 1 - s:
                        pts += [pcs[1 - s][j][::-1], pt(j, 1 - s), o(j)]
                        cur = s
                    else:
                        pts += [o(j), pt(j, 1 - s)]
                        cur = 1 - s
                exit_end, exit_side = e, cur
            if i + 1 < len(path):
                segs = self.cell_segs[c]
                g = segs[-1] if exit_end == 1 else segs[0]
                assert t is None or exit_side == t
                pts.append(self.piece_points(int(self.seg_cross[g, exit_side]), exit_end))
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


def hatch(
    regions_drawing: Drawing,
    *,
    fill: str,
    spacing_units: float,
    angle_deg: float = 0.0,
    passes: int = 1,
    angle_step_deg: float = 90.0,
    inset_units: float = 0.0,
    max_effort: int = EFFORT_PER_CELL,
) -> list[HatchStroke]:
    """Hatch strokes filling the regions of the drawing's closed paths.

    ``fill``: 'none' (no strokes), 'scanline' or 'zigzag'. ``spacing_units`` and
    ``inset_units`` are input units; pass ``p`` uses ``angle_deg + p * angle_step_deg``.
    Strokes come region by region (file order of the outer rings), pass by pass, bottom to
    top of the rotated frame; order them for the job with :func:`galvo_core.order`.
    ``max_effort``: zig-zag search steps per monotone cell of a region piece (plus
    :data:`EFFORT_BASE`), after which greedy walks cover the cells left (see
    :meth:`_Hatch.walk`; 0: greedy walks only).
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
    for path in h.walk(max_effort):
        pts = h.stroke_points(path)
        out.append(HatchStroke(src, pts @ rot.T, pass_index, len(path)))
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
