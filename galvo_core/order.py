"""Scan order of a job's strokes: less idle travel between laser-on runs (paper 002 §6).

:func:`order_strokes` works on plain point arrays (input units or bits) and returns a
:class:`Placement` per stroke: which stroke comes next, whether an open stroke is marked back
to front, and where a closed stroke starts. :func:`apply_to_strokes` applies placements to
job :class:`~galvo_core.job.Stroke` objects, keeping marks and fitted segments consistent
(a reversed stroke has its segments reversed, cubic control points too; a rotated closed
stroke starts at a segment joint). :func:`order_job_strokes` does all of it for a job.

Methods:

* ``file``: as given.
* ``greedy``: nearest next stroke (k-d tree, compiled); open strokes may be reversed, closed ones
  may start at any allowed point. Never longer than the file order (falls back to it).
* ``optimized``: greedy, then local search over the strokes' ends (2-opt block reversals
  and Or-opt moves of 1-3 strokes, over nearest-neighbour lists), the best direction / start
  point of every stroke for that order (exact: :func:`orient_strokes`), then iterated local
  search (double-bridge kicks within a few dozen strokes, each repaired by local search and
  kept if shorter) until it stops improving (a window of kicks gains less than
  :data:`STALL_GAIN`), after :data:`KICKS_PER_STROKE` kicks per stroke, or at the time
  budget, whichever comes first. Every move rewrites at most :data:`MOVE_SPAN` positions
  (longer ones only while their total work is linear), so the work grows linearly with the
  strokes. Never longer than greedy; the same result for the same input and ``seed`` unless
  the budget cuts the search at a different point.

Precedence (``before`` pairs ``(a, b)``: stroke ``a`` before stroke ``b``) is kept by every
method except ``file``; :func:`nesting_constraints` makes the usual ones: inner contours
before the outer contours that contain them, a region's hatch before its contour.
"""

from __future__ import annotations

import math
import random
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely
from numba import njit

ORDER_METHODS = ("file", "greedy", "optimized")
#: closed strokes offer at most this many start points to the search
MAX_STARTS = 48
NEIGHBOURS = 10
#: a kick's two swapped blocks are at most this many strokes long
KICK_SPAN = 50
#: the iterated local search stops after this many kicks per stroke (at least KICKS_MIN:
#: linear work), or
#: earlier when a window of max(STALL_WINDOW_MIN, strokes / 4) kicks shortened the travel by
#: no more than STALL_GAIN of it, or at the time budget, whichever comes first
KICKS_PER_STROKE = 2
KICKS_MIN = 2000
STALL_WINDOW_MIN = 500
STALL_GAIN = 1e-4
#: a 2-opt or Or-opt move rewrites at most this many tour positions (two per stroke): each
#: move then costs at most a constant, so a local search is linear in the strokes (no move
#: is left out below 10,000 strokes)
MOVE_SPAN = 20_000
#: longer moves are allowed until they have rewritten this many times the tour's positions
LONG_WORK = 40
#: the local searches that repair kicks make moves of at most this many positions (a kick is
#: local; no limit below 2,000 strokes): each kick then costs at most a constant
KICK_MOVE_SPAN = 4000


@dataclass(frozen=True, slots=True)
class Placement:
    """Stroke ``index`` (into the input) marked next; ``reverse``: open stroke back to front;
    ``rotate``: closed stroke starts at its point ``rotate`` (an index into its own points)."""

    index: int
    reverse: bool = False
    rotate: int = 0


# ------------------------------------------------------------------ helpers
def apply_placement(points: np.ndarray, closed: bool, pl: Placement) -> np.ndarray:
    """The points of one stroke as marked under a placement."""
    p = np.asarray(points)
    if closed and len(p) >= 2 and pl.rotate:
        ring = p[:-1] if np.array_equal(p[0], p[-1]) else p
        r = pl.rotate % len(ring)
        p = np.concatenate([ring[r:], ring[:r], ring[r:r + 1]])
    if pl.reverse:
        p = p[::-1]
    return p


def travel_length(strokes: Sequence[np.ndarray], placements: Sequence[Placement],
                  closed: Sequence[bool] | None = None) -> float:
    """Sum of the jumps between consecutive strokes (no jump before the first)."""
    cl = closed if closed is not None else [False] * len(strokes)
    tot = 0.0
    prev = None
    for pl in placements:
        p = apply_placement(strokes[pl.index], cl[pl.index], pl)
        if len(p) == 0:
            continue
        if prev is not None:
            tot += math.hypot(*(p[0] - prev).tolist())
        prev = p[-1]
    return tot


def orient_strokes(strokes: Sequence[np.ndarray], order: Sequence[int], *,
                   closed: Sequence[bool] | None = None,
                   starts: Sequence[np.ndarray | None] | None = None) -> list[Placement]:
    """Strokes in the fixed ``order`` (indices into ``strokes``), each marked the way round
    (open strokes) or from the start point (closed strokes: any point, or one of
    ``starts[i]``; at most :data:`MAX_STARTS` spread along the ring) that makes the travel
    shortest: exact for that order (a dynamic programme, two states per open stroke)."""
    n = len(strokes)
    cl = list(closed) if closed is not None else [False] * n
    prob = _Problem(strokes, cl, starts)
    seq = [int(i) for i in order if not prob.empty[int(i)]]
    best = iter(_placement(prob, c) for c in _orient(prob, seq))
    return [Placement(int(i)) if prob.empty[int(i)] else next(best) for i in order]


def nesting_constraints(strokes: Sequence[np.ndarray], closed: Sequence[bool],
                        kinds: Sequence[str] | None = None,
                        source_index: Sequence[int] | None = None, *,
                        inner_first: bool = True, hatch_first: bool = True
                        ) -> list[tuple[int, int]]:
    """Precedence pairs (a, b), a before b: each closed contour before the smallest closed
    contour containing it (``inner_first``), and each hatch stroke before the contour with
    its ``source_index`` (``hatch_first``; ``kinds`` 'hatch'/'contour')."""
    n = len(strokes)
    kinds = list(kinds) if kinds is not None else ["contour"] * n
    pairs: list[tuple[int, int]] = []
    cont = [i for i in range(n) if kinds[i] == "contour" and closed[i] and len(strokes[i]) >= 4]
    if inner_first and len(cont) > 1:
        polys = []
        keep = []
        for i in cont:
            g = shapely.Polygon(np.asarray(strokes[i], dtype=np.float64))
            if not g.is_valid:
                g = g.buffer(0)
            if g.area > 0:
                polys.append(g)
                keep.append(i)
        if polys:
            areas = np.array([g.area for g in polys])
            reps = shapely.points([np.asarray(strokes[i][0], dtype=np.float64) for i in keep])
            tree = shapely.STRtree(polys)
            a, b = tree.query(reps, predicate="intersects")
            ok = (a != b) & (areas[b] > areas[a])
            # a ring point on another ring: use a point strictly inside instead
            best: dict[int, tuple[float, int]] = {}
            for x, y in zip(a[ok].tolist(), b[ok].tolist(), strict=True):
                if areas[y] < best.get(x, (math.inf, -1))[0]:
                    best[x] = (float(areas[y]), y)
            for x, (_, y) in best.items():
                pairs.append((keep[x], keep[y]))
    if hatch_first and source_index is not None:
        contour_of: dict[int, int] = {}
        for i in range(n):
            if kinds[i] == "contour":
                contour_of.setdefault(int(source_index[i]), i)
        for i in range(n):
            if kinds[i] == "hatch" and int(source_index[i]) in contour_of:
                pairs.append((i, contour_of[int(source_index[i])]))
    return pairs


# ------------------------------------------------------------------ the search
class _Problem:
    def __init__(self, strokes: Sequence[np.ndarray], closed: Sequence[bool],
                 starts: Sequence[np.ndarray | None] | None) -> None:
        n = len(strokes)
        self.n = n
        self.closed = np.array([bool(c) for c in closed], dtype=bool).reshape(n)
        arrs = [np.asarray(s).reshape(-1, 2) for s in strokes]
        lens = np.array([len(a) for a in arrs], dtype=np.int64).reshape(n)
        self.empty = lens == 0
        self.first = np.zeros((n, 2))
        self.last = np.zeros((n, 2))
        nz = np.flatnonzero(~self.empty)
        if len(nz):
            allp = np.concatenate([arrs[i] for i in nz.tolist()]).astype(np.float64)
            off = np.cumsum(lens[nz]) - lens[nz]
            self.first[nz] = allp[off]
            self.last[nz] = allp[off + lens[nz] - 1]
        # candidate entry points: (point xy, stroke, code) code: 0 start, 1 end (reversed),
        # >= 2: closed start at point index code - 2; an open stroke (or a closed one of
        # fewer than 3 points, then open) has its two ends
        self.closed &= (lens >= 3) | self.empty
        ring_idx: dict[int, np.ndarray] = {}
        for i in np.flatnonzero(self.closed & ~self.empty).tolist():
            p = arrs[i]
            m = len(p) - 1 if np.array_equal(p[0], p[-1]) else len(p)
            allowed = None if starts is None else starts[i]
            idx = np.arange(m) if allowed is None else np.unique(
                np.asarray(allowed, dtype=np.int64) % m)
            if len(idx) == 0:
                idx = np.array([0])
            if len(idx) > MAX_STARTS:
                idx = idx[np.linspace(0, len(idx) - 1, MAX_STARTS).astype(np.int64)]
            ring_idx[i] = idx
        count = np.where(self.empty, 0, 2)
        for i, idx in ring_idx.items():
            count[i] = len(idx)
        cstart = np.concatenate([[0], np.cumsum(count)]).astype(np.int64)
        total = int(cstart[-1])
        self.cpt = np.zeros((total, 2))
        self.cstroke = np.repeat(np.arange(n, dtype=np.int64), count)
        self.ccode = np.zeros(total, dtype=np.int64)
        op = np.flatnonzero(~self.empty & ~self.closed)
        self.cpt[cstart[op]] = self.first[op]
        self.cpt[cstart[op] + 1] = self.last[op]
        self.ccode[cstart[op] + 1] = 1
        for i, idx in ring_idx.items():
            a = int(cstart[i])
            self.cpt[a:a + len(idx)] = arrs[i][idx]
            self.ccode[a:a + len(idx)] = idx + 2
        cands = np.arange(total, dtype=np.int64)
        bounds = cstart.tolist()
        self.cand_of: list[np.ndarray] = [cands[bounds[i]:bounds[i + 1]] for i in range(n)]

    def entry_exit(self, cand: int) -> tuple[np.ndarray, np.ndarray]:
        i = int(self.cstroke[cand])
        code = int(self.ccode[cand])
        if code == 0:
            return self.first[i], self.last[i]
        if code == 1:
            return self.last[i], self.first[i]
        return self.cpt[cand], self.cpt[cand]


def _grid_cell(pts: np.ndarray) -> float:
    """Bucket size of the greedy's grid: about two points per bucket where the points are
    (see :func:`_greedy`)."""
    if len(pts) == 0:
        return 1.0
    span = max(float((pts.max(axis=0) - pts.min(axis=0)).max()), 1e-9)
    return max(span / max(1.0, math.sqrt(len(pts) / 2.0)), 1e-9)


#: points per leaf of the greedy's k-d tree
_LEAF = 8


@njit(cache=True, nogil=True)
def _kd_build(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                        np.ndarray]:  # pragma: no cover
    """A balanced k-d tree over ``pts`` in implicit layout (node k's children 2k+1, 2k+2;
    node k holds ``perm[start[k]:start[k] + size[k]]``, split at the middle along the longer
    side of its box): ``perm``, node starts and sizes, boxes (min x, min y, max x, max y)."""
    C = len(pts)
    leaves = 1
    while leaves * _LEAF < C:
        leaves *= 2
    m = 2 * leaves - 1
    start = np.zeros(m, np.int64)
    size = np.zeros(m, np.int64)
    box = np.empty((m, 4))
    perm = np.arange(C)
    size[0] = C
    for k in range(m):
        s, z = start[k], size[k]
        if z == 0:
            box[k, 0] = np.inf
            box[k, 1] = np.inf
            box[k, 2] = -np.inf
            box[k, 3] = -np.inf
        else:
            idx = perm[s:s + z]
            box[k, 0] = pts[idx, 0].min()
            box[k, 1] = pts[idx, 1].min()
            box[k, 2] = pts[idx, 0].max()
            box[k, 3] = pts[idx, 1].max()
        if 2 * k + 1 < m:
            h = z // 2
            if z > 1:
                ax = 0 if box[k, 2] - box[k, 0] >= box[k, 3] - box[k, 1] else 1
                o = np.argsort(pts[perm[s:s + z], ax], kind="mergesort")
                perm[s:s + z] = perm[s:s + z][o]
            start[2 * k + 1], size[2 * k + 1] = s, h
            start[2 * k + 2], size[2 * k + 2] = s + h, z - h
    return perm, start, size, box


@njit(cache=True, nogil=True)
def _wake(j, cstart, alive, seq, n_seq, leaf_of, cnt):  # type: ignore[no-untyped-def]
    """Stroke ``j``'s candidates become alive (numbered from ``n_seq`` in the order they
    wake), counted up the k-d tree to its root; returns the next number."""
    for k in range(cstart[j], cstart[j + 1]):
        if not alive[k]:
            alive[k] = True
            seq[k] = n_seq
            n_seq += 1
            v = leaf_of[k]
            while True:
                cnt[v] += 1
                if v == 0:
                    break
                v = (v - 1) // 2
    return n_seq


@njit(cache=True, nogil=True)
def _greedy_walk(pts: np.ndarray, ext: np.ndarray, cstroke: np.ndarray, cstart: np.ndarray,
                 empty: np.ndarray, succ_start: np.ndarray, succ: np.ndarray,
                 npred: np.ndarray, first: int, cell: float) -> np.ndarray:  # pragma: no cover
    """The greedy walk (compiled): from the first candidate of stroke ``first``, always the
    nearest alive candidate to the current exit (strokes become alive when all their
    predecessors are done); a k-d tree with alive counts per node finds it.

    Ties (the same squared distance) go the way a search by rings of square buckets of side
    ``cell`` decides them (the rule this walk had with such a grid): the nearest point first
    met when the buckets are visited ring by ring around the query's bucket (a ring's
    buckets: bottom row, top row, left column, right column; a bucket's points in the order
    they became alive), unless that search would have gone beyond ring 8 (the nearest
    further than 8 cells): then the lowest index. Returns the candidates in order (fewer
    than the strokes when a precedence cycle leaves none alive)."""
    n = len(cstart) - 1
    C = len(pts)
    out = np.empty(n, np.int64)
    if first < 0 or C == 0:
        return out[:0]
    lox = pts[:, 0].min()
    loy = pts[:, 1].min()
    bi = np.empty(C, np.int64)
    bj = np.empty(C, np.int64)
    nx = 1
    ny = 1
    for k in range(C):
        bi[k] = np.int64(math.floor((pts[k, 0] - lox) / cell))
        bj[k] = np.int64(math.floor((pts[k, 1] - loy) / cell))
        nx = max(nx, bi[k] + 1)
        ny = max(ny, bj[k] + 1)
    perm, nstart, nsize, box = _kd_build(pts)
    m = len(nstart)
    first_leaf = m // 2
    leaf_of = np.empty(C, np.int64)
    for k in range(first_leaf, m):
        for q in range(nstart[k], nstart[k] + nsize[k]):
            leaf_of[perm[q]] = k
    cnt = np.zeros(m, np.int64)
    alive = np.zeros(C, np.bool_)
    seq = np.zeros(C, np.int64)  # when each point became alive
    n_seq = 0
    todo = 0
    for i in range(n):
        if not empty[i]:
            todo += 1
    stack = np.empty(64 * 2, np.int64)
    n_out = 0
    i = -1
    cand = cstart[first]
    while True:
        if i < 0:  # the start: every stroke without predecessors becomes alive
            for j in range(n):
                if not empty[j] and npred[j] == 0:
                    n_seq = _wake(j, cstart, alive, seq, n_seq, leaf_of, cnt)
        i = cstroke[cand]
        out[n_out] = cand
        n_out += 1
        for k in range(cstart[i], cstart[i + 1]):
            if alive[k]:
                alive[k] = False
                v = leaf_of[k]
                while True:
                    cnt[v] -= 1
                    if v == 0:
                        break
                    v = (v - 1) // 2
        for q in range(succ_start[i], succ_start[i + 1]):
            j = succ[q]
            npred[j] -= 1
            if npred[j] == 0:
                n_seq = _wake(j, cstart, alive, seq, n_seq, leaf_of, cnt)
        if n_out == todo or cnt[0] == 0:
            break
        px = ext[cand, 0]
        py = ext[cand, 1]
        ci = np.int64(math.floor((px - lox) / cell))
        cj = np.int64(math.floor((py - loy) / cell))
        # nearest alive point; among equals the grid's first (ring, place in ring, seq)
        # and the lowest index
        bd = np.inf
        best = -1
        br = 0
        bt = 0
        bs = 0
        low = -1
        top = 0
        stack[0] = 0
        top = 1
        while top:
            top -= 1
            v = stack[top]
            if cnt[v] == 0:
                continue
            dx = max(box[v, 0] - px, 0.0, px - box[v, 2])
            dy = max(box[v, 1] - py, 0.0, py - box[v, 3])
            if dx * dx + dy * dy > bd:
                continue
            if v >= first_leaf:
                for q in range(nstart[v], nstart[v] + nsize[v]):
                    k = perm[q]
                    if not alive[k]:
                        continue
                    ex = pts[k, 0] - px
                    ey = pts[k, 1] - py
                    d2 = ex * ex + ey * ey
                    if d2 > bd:
                        continue
                    a = bi[k] - ci
                    c = bj[k] - cj
                    r = max(abs(a), abs(c))
                    if r == 0:
                        t = 0
                    elif c == -r:
                        t = a + r
                    elif c == r:
                        t = 2 * r + 1 + a + r
                    elif a == -r:
                        t = 4 * r + 2 + c + r - 1
                    else:
                        t = 6 * r + 1 + c + r - 1
                    if d2 < bd:
                        bd, best, br, bt, bs, low = d2, k, r, t, seq[k], k
                    else:
                        if r < br or (r == br and (t < bt or (t == bt and seq[k] < bs))):
                            best, br, bt, bs = k, r, t, seq[k]
                        low = min(low, k)
            else:
                lc = 2 * v + 1
                rc = lc + 1
                # nearer child last (popped first)
                cl = 0.5 * (box[lc, 0] + box[lc, 2]) - px
                cr = 0.5 * (box[lc, 1] + box[lc, 3]) - py
                dl = cl * cl + cr * cr
                cl = 0.5 * (box[rc, 0] + box[rc, 2]) - px
                cr = 0.5 * (box[rc, 1] + box[rc, 3]) - py
                if dl <= cl * cl + cr * cr:
                    stack[top] = rc
                    stack[top + 1] = lc
                else:
                    stack[top] = lc
                    stack[top + 1] = rc
                top += 2
        # the grid search stops at the first ring r >= br with sqrt(bd) <= r * cell; past
        # ring 8 it took the lowest index instead
        rmax = max(nx, ny) + abs(ci) + abs(cj) + 1
        if rmax >= 9 and (br > 8 or math.sqrt(bd) > 8 * cell):
            best = low
        cand = best
    return out[:n_out]


def _placement(prob: _Problem, cand: int) -> Placement:
    i = int(prob.cstroke[cand])
    code = int(prob.ccode[cand])
    if code >= 2:
        return Placement(i, False, code - 2)
    return Placement(i, code == 1, 0)


def _greedy(prob: _Problem, before: Sequence[tuple[int, int]]) -> list[int]:
    """Candidate ids in greedy order (one per non-empty stroke): :func:`_greedy_walk`."""
    n = prob.n
    pairs = np.array([(a, b) for a, b in before
                      if a != b and not prob.empty[a] and not prob.empty[b]],
                     dtype=np.int64).reshape(-1, 2)
    by = np.argsort(pairs[:, 0], kind="stable")
    succ = np.ascontiguousarray(pairs[by, 1])
    succ_start = np.searchsorted(pairs[by, 0], np.arange(n + 1)).astype(np.int64)
    npred = np.bincount(pairs[:, 1], minlength=n).astype(np.int64)
    # start: the first stroke in file order that may go first, as given (or its first start)
    free = np.flatnonzero(~prob.empty & (npred == 0))
    first = int(free[0]) if len(free) else -1
    cstart = np.searchsorted(prob.cstroke, np.arange(n + 1)).astype(np.int64)
    _, ext = _cand_xy(prob)
    pts = np.ascontiguousarray(prob.cpt, dtype=np.float64)
    out = _greedy_walk(pts, np.ascontiguousarray(ext), prob.cstroke.astype(np.int64), cstart,
                       prob.empty, succ_start, succ, npred, first, _grid_cell(pts)).tolist()
    if first >= 0 and len(out) < int((~prob.empty).sum()):
        # a precedence cycle: take the rest as they come
        done = set(prob.cstroke[out].tolist())
        out += [int(prob.cand_of[k][0]) for k in range(n)
                if not prob.empty[k] and k not in done]
    return out


def _morton(q: np.ndarray) -> np.ndarray:
    """Z-order keys of (N, 2) integers in 0..65535."""
    def spread(v: np.ndarray) -> np.ndarray:
        v = v.astype(np.uint64) & np.uint64(0xFFFF)
        v = (v | (v << np.uint64(8))) & np.uint64(0x00FF00FF)
        v = (v | (v << np.uint64(4))) & np.uint64(0x0F0F0F0F)
        v = (v | (v << np.uint64(2))) & np.uint64(0x33333333)
        v = (v | (v << np.uint64(1))) & np.uint64(0x55555555)
        return v
    return spread(q[:, 0]) | (spread(q[:, 1]) << np.uint64(1))


def _cand_xy(prob: _Problem) -> tuple[np.ndarray, np.ndarray]:
    """Entry and exit point of every candidate, (C, 2) each."""
    s = prob.cstroke
    code = prob.ccode
    ent = prob.cpt.copy()
    ext = prob.cpt.copy()
    op = code < 2
    ext[op & (code == 0)] = prob.last[s[op & (code == 0)]]
    ext[op & (code == 1)] = prob.first[s[op & (code == 1)]]
    return ent, ext


def _cands_length(prob: _Problem, cands: Sequence[int]) -> float:
    """Travel of a candidate sequence (sum of the jumps, none before the first)."""
    if len(cands) < 2:
        return 0.0
    ent, ext = _cand_xy(prob)
    c = np.asarray(cands, dtype=np.int64)
    d = ent[c[1:]] - ext[c[:-1]]
    return float(np.hypot(d[:, 0], d[:, 1]).sum())


def _orient(prob: _Problem, seq: Sequence[int]) -> list[int]:
    """For strokes in the fixed order ``seq``, the candidate of each (an open stroke's
    direction, a closed stroke's start point) that makes the travel shortest: an exact
    dynamic programme over each stroke's candidates (O(n) for open strokes: 2 states each)."""
    if not len(seq):
        return []
    ent, ext = _cand_xy(prob)
    ex_l, ey_l = ext[:, 0].tolist(), ext[:, 1].tolist()
    nx_l, ny_l = ent[:, 0].tolist(), ent[:, 1].tolist()
    hyp = math.hypot
    cand_of = [prob.cand_of[s].tolist() for s in seq]
    cost = [0.0] * len(cand_of[0])
    back: list[list[int]] = []
    for k in range(1, len(seq)):
        pc, qc = cand_of[k - 1], cand_of[k]
        if len(pc) * len(qc) <= 4:  # open to open: plain floats
            new, arg = [], []
            for q in qc:
                bx, by = nx_l[q], ny_l[q]
                best, bi = math.inf, 0
                for i, p in enumerate(pc):
                    v = cost[i] + hyp(ex_l[p] - bx, ey_l[p] - by)
                    if v < best:
                        best, bi = v, i
                new.append(best)
                arg.append(bi)
        else:
            d = ext[pc][:, None, :] - ent[qc][None, :, :]
            tot = np.asarray(cost)[:, None] + np.hypot(d[..., 0], d[..., 1])
            a = tot.argmin(axis=0)
            new = tot[a, np.arange(len(qc))].tolist()
            arg = a.tolist()
        cost = new
        back.append(arg)
    j = int(np.argmin(cost))
    out = [cand_of[-1][j]]
    for k in range(len(seq) - 1, 0, -1):
        j = back[k - 1][j]
        out.append(cand_of[k - 1][j])
    return out[::-1]


def _end_neighbours(prob: _Problem, k: int, window: int = 6,
                    shifts: tuple[float, ...] = (0.0, 0.31, 0.62)) -> list[list[int]]:
    """For each stroke end (2s: first point of stroke s, 2s+1: its last point; both ends of a
    closed stroke stand for its start point, wherever that is), up to k ends of other strokes
    near it, nearest first: points close in shifted Z-orders (vectorised; an approximation of
    k-nearest)."""
    n = prob.n
    pts = prob.cpt
    if len(pts) < 2:
        return [[] for _ in range(2 * n)]
    lo = pts.min(axis=0)
    span = max(float((pts.max(axis=0) - lo).max()), 1e-9)
    a_l, b_l = [], []
    for shift in shifts:
        q = np.floor((pts - lo + shift * span) / (span * (1.0 + shift)) * 65535.0)
        order = np.argsort(_morton(np.clip(q, 0, 65535).astype(np.int64)), kind="stable")
        for w in range(1, window + 1):
            a_l.append(order[:-w])
            b_l.append(order[w:])
    a = np.concatenate(a_l)
    b = np.concatenate(b_l)
    a, b = np.concatenate([a, b]), np.concatenate([b, a])
    keep = prob.cstroke[a] != prob.cstroke[b]
    a, b = a[keep], b[keep]
    dv = pts[a] - pts[b]
    d2 = dv[:, 0] * dv[:, 0] + dv[:, 1] * dv[:, 1]

    def ends(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(row, end) pairs: an open candidate is one end, a closed one both."""
        s, code = prob.cstroke[c], prob.ccode[c]
        op = np.flatnonzero(code < 2)
        cl = np.flatnonzero(code >= 2)
        if len(cl) == 0:
            return op, 2 * s + code
        rows = np.concatenate([op, cl, cl])
        return rows, np.concatenate([2 * s[op] + code[op], 2 * s[cl], 2 * s[cl] + 1])

    ra, ea = ends(a)
    b, d2 = b[ra], d2[ra]
    rb, eb = ends(b)
    ea, d2 = ea[rb], d2[rb]
    # one row per (end, end) pair, the nearest of its candidate points
    key = ea * (2 * n) + eb
    o = np.argsort(key)
    key, d2 = key[o], d2[o]
    heads = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    d2 = np.minimum.reduceat(d2, heads)
    key = key[heads]
    ea, eb = key // (2 * n), key % (2 * n)
    # nearest first within each end (distances ranked on 30 bits)
    rank = (d2 / max(float(d2.max()), 1e-300) * (2**30 - 1)).astype(np.int64)
    o = np.argsort((ea << 31) | rank)
    ea, eb = ea[o], eb[o]
    bounds = np.searchsorted(ea, np.arange(2 * n + 1)).tolist()
    ebl = eb.tolist()
    return [ebl[bounds[i]:min(bounds[i + 1], bounds[i] + k)] for i in range(2 * n)]


class _EndTour:
    """A tour over stroke ends, changed by 2-opt / Or-opt moves that can be undone.

    End 2s is the first point of stroke s, 2s+1 its last (both ends of a closed stroke are its
    current start point). ``t[0]`` is a dummy end D whose jumps cost nothing (so the open path
    is a cycle and its two ends are free), then each stroke's entry end and exit end:
    ``t[2k+1], t[2k+2]`` for the k-th stroke; a jump joins ``t[2k]`` and ``t[2k+1]``.
    Reversing positions ``lo..hi`` (``lo`` odd, ``hi`` even) reverses whole strokes, each
    entered at its other end. ``pos[e]`` is the position of end e. Lengths are exact: every
    move reports its gain, and :meth:`length` agrees with the running total."""

    def __init__(self, prob: _Problem, cands: Sequence[int],
                 before: Sequence[tuple[int, int]]) -> None:
        n = prob.n
        self.prob = prob
        self.D = 2 * n
        xy = np.zeros((2 * n + 1, 2))
        xy[0:2 * n:2] = prob.first
        xy[1:2 * n:2] = prob.last
        self.X: list[float] = xy[:, 0].tolist()
        self.Y: list[float] = xy[:, 1].tolist()
        self.cpx, self.cpy = prob.cpt[:, 0].tolist(), prob.cpt[:, 1].tolist()
        self.cstroke = prob.cstroke.tolist()
        self.ccode = prob.ccode.tolist()
        self.first_cand = [int(c[0]) if len(c) else -1 for c in prob.cand_of]
        self.start_cand: dict[int, int] = {}
        self.t: list[int] = [self.D]
        self.pos = [0] * (2 * n + 1)
        self.written = 0  # tour positions rewritten by moves (work done)
        self.ls_steps = 0  # ends looked at by local searches
        self.load(cands)
        self.M = len(self.t) - 1  # the last position
        # moves longer than MOVE_SPAN positions while their total stays under LONG_WORK * M
        self.span_cap = self.M
        self.long_work = 0
        # precedence pairs the starting tour keeps (a cycle of pairs cannot be kept)
        self.cons_of: list[list[tuple[int, int]]] = [[] for _ in range(n)]
        pos = self.pos
        for a, b in before:
            if a != b and not prob.empty[a] and not prob.empty[b] and pos[2 * a] < pos[2 * b]:
                self.cons_of[a].append((a, b))
                self.cons_of[b].append((a, b))
        self.has_cons = any(self.cons_of)
        self.log: list[tuple[int, list[int]]] | None = None  # undo records when not None

    def load(self, cands: Sequence[int]) -> None:
        """Set the tour (and the closed strokes' start points) from a candidate sequence."""
        t, X, Y = self.t, self.X, self.Y
        del t[1:]
        for c in cands:
            s, code = self.cstroke[c], self.ccode[c]
            if code >= 2:
                self.start_cand[s] = c
                X[2 * s] = X[2 * s + 1] = self.cpx[c]
                Y[2 * s] = Y[2 * s + 1] = self.cpy[c]
            e = 2 * s + (code == 1)
            t.append(e)
            t.append(e ^ 1)
        for i, e in enumerate(t):
            self.pos[e] = i

    def cands(self) -> list[int]:
        """The tour as a candidate sequence."""
        out = []
        for e in self.t[1::2]:
            s = e >> 1
            c = self.start_cand.get(s)
            out.append(self.first_cand[s] + (e & 1) if c is None else c)
        return out

    def length(self) -> float:
        t, X, Y, hyp = self.t, self.X, self.Y, math.hypot
        tot = 0.0
        for i in range(2, len(t) - 1, 2):
            a, b = t[i], t[i + 1]
            tot += hyp(X[a] - X[b], Y[a] - Y[b])
        return tot

    def jump(self, a: int, b: int) -> float:
        """Length of a jump between ends a and b (0 to or from D)."""
        if a == self.D or b == self.D:
            return 0.0
        return math.hypot(self.X[a] - self.X[b], self.Y[a] - self.Y[b])

    # ---- changes
    def _write(self, r0: int, new: list[int]) -> None:
        t, pos = self.t, self.pos
        m = len(new)
        self.written += m
        t[r0:r0 + m] = new
        if m > 64:
            list(map(pos.__setitem__, new, range(r0, r0 + m)))
        else:
            for k in range(r0, r0 + m):
                pos[t[k]] = k
        if m > MOVE_SPAN:  # long moves: allowed while their work stays linear overall
            self.long_work += m
            if self.long_work > LONG_WORK * self.M:
                self.span_cap = MOVE_SPAN

    def commit(self, r0: int, new: list[int]) -> bool:
        """Put ``new`` (whole strokes) at positions r0..; False (and nothing changed) if that
        breaks a precedence pair."""
        old = self.t[r0:r0 + len(new)]
        self._write(r0, new)
        if self.has_cons:
            t, pos, cons_of = self.t, self.pos, self.cons_of
            for k in range(r0, r0 + len(new), 2):
                for a, b in cons_of[t[k] >> 1]:
                    if pos[2 * a] > pos[2 * b]:
                        self._write(r0, old)
                        return False
        if self.log is not None:
            self.log.append((r0, old))
        return True

    def undo(self) -> None:
        """Back to the tour when :attr:`log` was last emptied."""
        log = self.log or []
        while log:
            r0, old = log.pop()
            self._write(r0, old)

    # ---- moves
    def best_move(self, t1: int, nbs: list[int]) -> tuple[float, tuple[int, int, int, int]]:
        """The best 2-opt or Or-opt move that makes end t1 meet one of the ends ``nbs``
        (nearest first: the scan stops at the first one too far to gain) and its gain;
        ``(-1, ...)`` when none gains."""
        t, pos, X, Y, M, D, hyp = self.t, self.pos, self.X, self.Y, self.M, self.D, math.hypot
        span_cap = self.span_cap
        i = pos[t1]
        x1, y1 = X[t1], Y[t1]
        odd = i & 1
        t2 = t[i - 1] if odd else (t[i + 1] if i < M else D)
        g1 = 0.0 if t2 == D else hyp(x1 - X[t2], y1 - Y[t2])
        x2, y2 = X[t2], Y[t2]
        best_g = 1e-9
        best = (-1, 0, 0, 0)
        # 2-opt: jumps (t1, t2), (t3, t4) -> (t1, t3), (t2, t4)
        for t3 in nbs:
            x3, y3 = X[t3], Y[t3]
            g = g1 - hyp(x1 - x3, y1 - y3)
            if g <= 0.0:
                break
            j = pos[t3]
            if (j & 1) != odd or abs(j - i) > span_cap:
                continue
            t4 = t[j - 1] if odd else (t[j + 1] if j < M else D)
            if t3 == t2 or t4 == t1:
                continue
            if t4 != D:
                x4, y4 = X[t4], Y[t4]
                g += hyp(x3 - x4, y3 - y4)
                if t2 != D:
                    g -= hyp(x2 - x4, y2 - y4)
            if g > best_g:
                best_g = g
                best = (0, i, j, 0)
        # Or-opt: the block of k strokes that ends at t1, moved so that t1 meets c
        for k in (1, 2, 3):
            if odd:
                lo, hi = i, i + 2 * k - 1
                if hi > M:
                    break
                a, b = t1, t[hi]
                xo, yo = X[b], Y[b]
            else:
                lo, hi = i - 2 * k + 1, i
                if lo < 1:
                    break
                a, b = t[lo], t1
                xo, yo = X[a], Y[a]
            p = t[lo - 1]
            q = t[hi + 1] if hi < M else D
            if p == D:
                rem = 0.0 if q == D else hyp(X[b] - X[q], Y[b] - Y[q])
            elif q == D:
                rem = hyp(X[p] - X[a], Y[p] - Y[a])
            else:
                xp, yp, xq, yq = X[p], Y[p], X[q], Y[q]
                rem = (hyp(xp - X[a], yp - Y[a]) + hyp(X[b] - xq, Y[b] - yq)
                       - hyp(xp - xq, yp - yq))
            if rem <= best_g:
                continue
            for c in nbs:
                xc, yc = X[c], Y[c]
                dc = hyp(x1 - xc, y1 - yc)
                if dc >= rem:
                    break
                j = pos[c]
                if lo <= j <= hi or abs(j - i) > span_cap:
                    continue
                if j & 1:  # c an entry: y - other end .. t1 - c
                    if j - 1 == hi:
                        continue
                    y = t[j - 1]
                    g = rem - dc
                    if y != D:
                        xy_, yy = X[y], Y[y]
                        g += hyp(xy_ - xc, yy - yc) - hyp(xy_ - xo, yy - yo)
                else:  # c an exit: c - t1 .. other end - z
                    if j == lo - 1:
                        continue
                    z = t[j + 1] if j < M else D
                    g = rem - dc
                    if z != D:
                        xz, yz = X[z], Y[z]
                        g += hyp(xc - xz, yc - yz) - hyp(xo - xz, yo - yz)
                if g > best_g:
                    best_g = g
                    best = (1, lo, hi, j)
        return best_g, best

    def apply(self, t1: int, mv: tuple[int, int, int, int]) -> list[int] | None:
        """Make a move from :meth:`best_move`; the ends whose jumps changed, or None if the
        move would break a precedence pair (the tour is then unchanged)."""
        t, M, D = self.t, self.M, self.D
        kind, a, b, j = mv
        if kind == 0:  # 2-opt between positions a (t1) and b (t3)
            if a & 1:
                lo, hi = min(a, b), max(a, b) - 1
            else:
                lo, hi = min(a, b) + 1, max(a, b)
            touched = [t[lo - 1], t[lo], t[hi], t[hi + 1] if hi < M else D]
            ok = self.commit(lo, t[lo:hi + 1][::-1])
        else:  # Or-opt: block a..b into the jump at end position j, t1 next to that end
            lo, hi = a, b
            seg = t[lo:hi + 1]
            g = j - 1 if j & 1 else j  # the jump (t[g], t[g + 1])
            if (seg[-1] if j & 1 else seg[0]) != t1:
                seg.reverse()
            touched = [t[lo - 1], t[lo], t[hi], t[hi + 1] if hi < M else D,
                       t[g], t[g + 1] if g < M else D]
            if g > hi:
                ok = self.commit(lo, t[hi + 1:g + 1] + seg)
            else:
                ok = self.commit(g + 1, seg + t[g + 1:lo])
        return touched if ok else None

    def kick(self, s1: int, s2: int, s3: int) -> tuple[float, list[int]] | None:
        """Double bridge A B C D -> A C B D, B = strokes s1..s2-1, C = s2..s3-1: the change
        of length and the ends at the three cuts (None if it breaks a precedence pair)."""
        t, M, D, jump = self.t, self.M, self.D, self.jump
        g1, g2, g3 = 2 * s1, 2 * s2, 2 * s3
        e = [t[g1], t[g1 + 1], t[g2], t[g2 + 1], t[g3], t[g3 + 1] if g3 < M else D]
        delta = (jump(e[0], e[3]) + jump(e[4], e[1]) + jump(e[2], e[5])
                 - jump(e[0], e[1]) - jump(e[2], e[3]) - jump(e[4], e[5]))
        if not self.commit(g1 + 1, t[g2 + 1:g3 + 1] + t[g1 + 1:g2 + 1]):
            return None
        return delta, e


def _local_search(tour: _EndTour, nb: list[list[int]], queue: list[int],
                  deadline: float) -> tuple[float, bool]:
    """Best move per end from a queue of ends to look at ("don't-look bits": an end goes back
    in the queue when one of its jumps changes) until none gains. Returns the total gain and
    False if the deadline came first."""
    D = tour.D
    inq = set()
    dq: deque[int] = deque()
    for e in queue:
        if e != D and e not in inq:
            inq.add(e)
            dq.append(e)
    best_move, apply, perf = tour.best_move, tour.apply, time.perf_counter
    gained = 0.0
    steps = 0
    while dq:
        steps += 1
        tour.ls_steps += 1
        if (steps & 15) == 0 and perf() > deadline:
            return gained, False
        t1 = dq.popleft()
        inq.discard(t1)
        gain, mv = best_move(t1, nb[t1])
        if mv[0] < 0:
            continue
        touched = apply(t1, mv)
        if touched is None:
            continue
        gained += gain
        for e in touched:
            if e != D and e not in inq:
                inq.add(e)
                dq.append(e)
    return gained, True


def _improve(prob: _Problem, cands: Sequence[int], before: Sequence[tuple[int, int]],
             deadline: float, seed: int = 0, max_kicks: int | None = None,
             stats: dict | None = None) -> list[int]:
    """A candidate sequence no longer than ``cands`` (and keeping the precedence pairs that
    ``cands`` keeps): local search, the best direction / start point of every stroke for that
    order (:func:`_orient`), then iterated local search until it stops improving, after
    :data:`KICKS_PER_STROKE` kicks per stroke or at the deadline (or after ``max_kicks``
    kicks): a double bridge within :data:`KICK_SPAN` strokes, local search around its cuts,
    kept if shorter, else undone. Deterministic for a given seed up to where the deadline
    cuts it. ``stats`` (a dict), if given, receives the work done: ``kicks``,
    ``ls_steps`` (ends looked at by the local searches), ``written`` (tour positions
    rewritten by moves)."""
    m = len(cands)
    if m < 3:
        return list(cands)
    nb = _end_neighbours(prob, NEIGHBOURS)
    tour = _EndTour(prob, cands, before)
    kicks = 0

    def finish() -> list[int]:
        if stats is not None:
            stats.update(kicks=kicks, ls_steps=tour.ls_steps, written=tour.written)
        return _orient(prob, [e >> 1 for e in tour.t[1::2]])

    if not _local_search(tour, nb, tour.t[1:], deadline)[1]:
        return finish()
    old_entries = tour.t[1::2]
    tour.load(_orient(prob, [e >> 1 for e in old_entries]))
    turned = [e for e, f in zip(tour.t[1::2], old_entries, strict=True) if e != f]
    if not _local_search(tour, nb, turned + [e ^ 1 for e in turned], deadline)[1]:
        return finish()
    rng = random.Random(seed)
    span = min(m - 1, KICK_SPAN)
    tour.span_cap = KICK_MOVE_SPAN  # a kick is repaired near its cuts
    tour.log = []
    limit = max(KICKS_MIN, KICKS_PER_STROKE * m) if max_kicks is None else max_kicks
    window = max(STALL_WINDOW_MIN, m // 4)
    length = tour.length()
    window_start = length
    while time.perf_counter() < deadline and kicks < limit:
        if max_kicks is None and kicks and kicks % window == 0:
            # stopped improving: the last window of kicks gained (almost) nothing
            if window_start - length <= STALL_GAIN * window_start:
                break
            window_start = length
        kicks += 1
        s1 = rng.randrange(0, m - 1)
        s2 = min(s1 + rng.randint(1, span), m - 1)
        s3 = min(s2 + rng.randint(1, span), m)
        got = tour.kick(s1, s2, s3) if s1 < s2 < s3 else None
        if got is None:
            continue
        delta, ends = got
        gain, finished = _local_search(tour, nb, ends, deadline)
        if gain - delta > 1e-9:  # shorter: keep
            tour.log.clear()
            length -= gain - delta
        else:
            tour.undo()
        if not finished:
            break
    tour.log = None
    return finish()


def order_strokes(
    strokes: Sequence[np.ndarray],
    *,
    method: str = "greedy",
    time_budget_s: float = 1.0,
    closed: Sequence[bool] | None = None,
    before: Sequence[tuple[int, int]] = (),
    starts: Sequence[np.ndarray | None] | None = None,
    seed: int = 0,
) -> list[Placement]:
    """The marking order of ``strokes`` (each (N, 2) points, any units).

    ``closed[i]``: stroke i is a closed ring (may start at any of its points, or at the
    indices in ``starts[i]`` when given); open strokes may be reversed. ``before``:
    precedence pairs (a, b), a marked before b (see :func:`nesting_constraints`).
    Empty strokes keep their place at the end. Returns one :class:`Placement` per stroke.
    ``optimized`` is deterministic for a given ``seed`` except where the time budget cuts it.
    """
    if method not in ORDER_METHODS:
        raise ValueError(f"method must be one of {', '.join(ORDER_METHODS)}; got {method!r}")
    n = len(strokes)
    cl = list(closed) if closed is not None else [False] * n
    file_order = [Placement(i) for i in range(n)]
    if method == "file" or n < 2:
        return file_order
    t0 = time.perf_counter()
    prob = _Problem(strokes, cl, starts)
    cands = _greedy(prob, before)
    empties = [Placement(i) for i in range(n) if prob.empty[i]]
    greedy = [_placement(prob, int(c)) for c in cands] + empties
    ok_file = all(a < b for a, b in before)
    g_len = _cands_length(prob, cands)
    f_len = travel_length(strokes, file_order, cl)
    if method == "greedy" or len(cands) < 3:
        return file_order if ok_file and f_len < g_len else greedy
    if ok_file and f_len < g_len:  # start from the better of the two
        cands = [int(prob.cand_of[i][0]) for i in range(n) if not prob.empty[i]]
        g_len = f_len
        greedy = file_order
    if time.perf_counter() >= t0 + time_budget_s:  # the greedy pass took the budget
        return greedy
    better = _improve(prob, cands, before, t0 + time_budget_s, seed)
    out = [_placement(prob, int(c)) for c in better] + empties
    return out if _cands_length(prob, better) <= g_len + 1e-9 else greedy


# ------------------------------------------------------------------ job strokes
def _joint_indices(marks: np.ndarray, segments: Sequence[tuple[str, np.ndarray]],
                   fm: object) -> np.ndarray | None:
    """Mark indices where a fitted segment starts (where a closed stroke may be cut)."""
    if not segments:
        return None
    sb = fm.to_bits(_segment_starts(segments))  # type: ignore[attr-defined]
    ring = marks[:-1] if len(marks) > 1 and np.array_equal(marks[0], marks[-1]) else marks
    out = []
    j = 0
    for b in sb:
        hit = np.flatnonzero((ring[j:] == b).all(axis=1))
        if len(hit) == 0:
            continue
        j += int(hit[0])
        out.append(j)
    return np.array(out, dtype=np.int64) if out else np.array([0], dtype=np.int64)


def _segment_starts(segs: Any) -> np.ndarray:
    """(S, 2) start point of every segment: from a job.Segments' arrays, or from pairs."""
    if hasattr(segs, "offsets"):
        return np.asarray(segs.points, dtype=np.float64)[segs.offsets]
    return np.array([np.asarray(p)[0] for _, p in segs], dtype=np.float64)


def _reverse_segments(segs: Sequence[tuple[str, np.ndarray]]) -> tuple[
        tuple[str, np.ndarray], ...]:
    return tuple((k, np.asarray(p)[::-1].copy()) for k, p in reversed(segs))


def apply_to_strokes(strokes: Sequence[object], placements: Sequence[Placement],
                     fm: object, *, moves: list[tuple[int, int, bool]] | None = None
                     ) -> list[object]:
    """Job strokes in the new order, marks and segments reversed / rotated to match.
    ``moves``: if given, gets per new stroke (old index, the segment its segments now start
    at, reversed) — what :meth:`galvo_core.job.StrokeColumns` need to follow the order."""
    from dataclasses import replace

    from galvo_core.job import Stroke

    out = []
    for pl in placements:
        s = strokes[pl.index]
        marks = s.marks  # type: ignore[attr-defined]
        segs = s.segments  # type: ignore[attr-defined]
        arrays = hasattr(segs, "rotated")  # job.Segments: turned without per-segment objects
        if not arrays:
            segs = tuple(segs)
        t = 0
        if pl.rotate and s.closed:  # type: ignore[attr-defined]
            marks = apply_placement(marks, True, Placement(pl.index, False, pl.rotate))
            if len(segs):
                sb = fm.to_bits(_segment_starts(segs))  # type: ignore[attr-defined]
                hit = np.flatnonzero((sb == marks[0]).all(axis=1))
                if len(hit):
                    t = int(hit[0])
                    segs = segs.rotated(t) if arrays else segs[t:] + segs[:t]
        if moves is not None:
            moves.append((pl.index, t % len(segs) if len(segs) else 0, bool(pl.reverse)))
        if pl.reverse:
            marks = marks[::-1].copy()
            segs = segs.reversed() if arrays else _reverse_segments(segs)
        if marks is s.marks and segs is s.segments:  # type: ignore[attr-defined]
            out.append(s)  # as it was (frozen): no copy
        elif type(s) is Stroke:
            out.append(Stroke(s.kind, s.source_index, s.closed, marks, segs, s.pen))
        else:
            out.append(replace(s, marks=marks, segments=segs))  # type: ignore[type-var]
    return out


def order_job_strokes(strokes: Sequence[object], fm: object, *, method: str,
                      time_budget_s: float = 1.0, inner_first: bool = True,
                      hatch_first: bool = True,
                      moves: list[tuple[int, int, bool]] | None = None) -> list[object]:
    """Order a job's strokes (contour and hatch :class:`~galvo_core.job.Stroke`) in place of
    the pipeline's order stage; closed contours start only at segment joints. ``moves``: see
    :func:`apply_to_strokes`."""
    if method == "file":
        if moves is not None:
            moves.extend((i, 0, False) for i in range(len(strokes)))
        return list(strokes)
    marks = [np.asarray(s.marks) for s in strokes]  # type: ignore[attr-defined]
    closed = [bool(s.closed) for s in strokes]  # type: ignore[attr-defined]
    kinds = [s.kind for s in strokes]  # type: ignore[attr-defined]
    src = [int(s.source_index) for s in strokes]  # type: ignore[attr-defined]
    before = nesting_constraints(marks, closed, kinds, src, inner_first=inner_first,
                                 hatch_first=hatch_first)
    starts = [_joint_indices(m, s.segments, fm) if c else None  # type: ignore[attr-defined]
              for m, s, c in zip(marks, strokes, closed, strict=True)]
    pls = order_strokes(marks, method=method, time_budget_s=time_budget_s, closed=closed,
                        before=before, starts=starts)
    return apply_to_strokes(strokes, pls, fm, moves=moves)
