"""Scan order of a job's strokes: less idle travel between laser-on runs (paper 002 §6).

:func:`order_strokes` works on plain point arrays (input units or bits) and returns a
:class:`Placement` per stroke: which stroke comes next, whether an open stroke is marked back
to front, and where a closed stroke starts. :func:`apply_to_strokes` applies placements to
job :class:`~galvo_core.job.Stroke` objects, keeping marks and fitted segments consistent
(a reversed stroke has its segments reversed, cubic control points too; a rotated closed
stroke starts at a segment joint). :func:`order_job_strokes` does all of it for a job.

Methods:

* ``file``: as given.
* ``greedy``: nearest next stroke (grid search); open strokes may be reversed, closed ones
  may start at any allowed point. Never longer than the file order (falls back to it).
* ``optimized``: greedy, then 2-opt and Or-opt moves over nearest-neighbour candidate lists
  and a start-point pass for closed strokes, until no move helps or the time budget is
  spent. Never longer than greedy.

Precedence (``before`` pairs ``(a, b)``: stroke ``a`` before stroke ``b``) is kept by every
method except ``file``; :func:`nesting_constraints` makes the usual ones: inner contours
before the outer contours that contain them, a region's hatch before its contour.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely

ORDER_METHODS = ("file", "greedy", "optimized")
#: closed strokes offer at most this many start points to the search
MAX_STARTS = 48
NEIGHBOURS = 10


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
        self.closed = np.array([bool(c) for c in closed], dtype=bool)
        self.first = np.zeros((n, 2))
        self.last = np.zeros((n, 2))
        self.empty = np.zeros(n, dtype=bool)
        # candidate entry points: (point xy, stroke, code) code: 0 start, 1 end (reversed),
        # >= 2: closed start at point index code - 2
        cx: list[np.ndarray] = []
        cs: list[np.ndarray] = []
        cc: list[np.ndarray] = []
        for i, s in enumerate(strokes):
            p = np.asarray(s, dtype=np.float64).reshape(-1, 2)
            if len(p) == 0:
                self.empty[i] = True
                continue
            self.first[i] = p[0]
            self.last[i] = p[-1]
            if self.closed[i] and len(p) >= 3:
                m = len(p) - 1 if np.array_equal(p[0], p[-1]) else len(p)
                allowed = None if starts is None else starts[i]
                idx = np.arange(m) if allowed is None else np.unique(
                    np.asarray(allowed, dtype=np.int64) % m)
                if len(idx) == 0:
                    idx = np.array([0])
                if len(idx) > MAX_STARTS:
                    idx = idx[np.linspace(0, len(idx) - 1, MAX_STARTS).astype(np.int64)]
                cx.append(p[idx])
                cs.append(np.full(len(idx), i))
                cc.append(idx + 2)
            else:
                self.closed[i] = False
                cx.append(np.stack([p[0], p[-1]]))
                cs.append(np.array([i, i]))
                cc.append(np.array([0, 1]))
        self.cpt = np.concatenate(cx) if cx else np.zeros((0, 2))
        self.cstroke = np.concatenate(cs) if cs else np.zeros(0, dtype=np.int64)
        self.ccode = np.concatenate(cc) if cc else np.zeros(0, dtype=np.int64)
        self.cand_of: list[np.ndarray] = [np.zeros(0, dtype=np.int64)] * n
        if len(self.cstroke):
            order = np.argsort(self.cstroke, kind="stable")
            bounds = np.searchsorted(self.cstroke[order], np.arange(n + 1))
            self.cand_of = [order[bounds[i]:bounds[i + 1]] for i in range(n)]

    def entry_exit(self, cand: int) -> tuple[np.ndarray, np.ndarray]:
        i = int(self.cstroke[cand])
        code = int(self.ccode[cand])
        if code == 0:
            return self.first[i], self.last[i]
        if code == 1:
            return self.last[i], self.first[i]
        return self.cpt[cand], self.cpt[cand]


class _Grid:
    """Points in square buckets; nearest alive point by rings of buckets."""

    def __init__(self, pts: np.ndarray) -> None:
        self.pts = pts
        lo = pts.min(axis=0) if len(pts) else np.zeros(2)
        hi = pts.max(axis=0) if len(pts) else np.ones(2)
        span = max(float((hi - lo).max()), 1e-9)
        self.cell = max(span / max(1.0, math.sqrt(len(pts) / 2.0)), 1e-9)
        self.lo = lo
        ij = np.floor((pts - lo) / self.cell).astype(np.int64)
        self.ij = ij
        self.nx = int(ij[:, 0].max()) + 1 if len(pts) else 1
        self.ny = int(ij[:, 1].max()) + 1 if len(pts) else 1
        self.buckets: dict[tuple[int, int], list[int]] = {}
        self.alive = np.zeros(len(pts), dtype=bool)
        self.n_alive = 0

    def insert(self, ids: np.ndarray) -> None:
        for k in ids.tolist():
            if not self.alive[k]:
                self.alive[k] = True
                self.n_alive += 1
                key = (int(self.ij[k, 0]), int(self.ij[k, 1]))
                self.buckets.setdefault(key, []).append(k)

    def kill(self, ids: np.ndarray) -> None:
        for k in ids.tolist():
            if self.alive[k]:
                self.alive[k] = False
                self.n_alive -= 1

    def nearest(self, p: np.ndarray) -> int:
        if self.n_alive == 0:
            return -1
        ci = int(math.floor((p[0] - self.lo[0]) / self.cell))
        cj = int(math.floor((p[1] - self.lo[1]) / self.cell))
        best = -1
        bd = math.inf
        px, py = float(p[0]), float(p[1])
        pts = self.pts
        alive = self.alive
        rmax = max(self.nx, self.ny) + abs(ci) + abs(cj) + 1
        for r in range(rmax + 1):
            if r > 8:  # far away: look at every alive point at once
                ids = np.flatnonzero(alive)
                d = np.hypot(pts[ids, 0] - px, pts[ids, 1] - py)
                k = int(np.argmin(d))
                return int(ids[k]) if d[k] < bd else best
            for key in _ring(ci, cj, r):
                b = self.buckets.get(key)
                if not b:
                    continue
                live = [k for k in b if alive[k]]
                if len(live) != len(b):
                    self.buckets[key] = live
                for k in live:
                    d2 = (pts[k, 0] - px) ** 2 + (pts[k, 1] - py) ** 2
                    if d2 < bd:
                        bd = d2
                        best = k
            if best >= 0 and math.sqrt(bd) <= r * self.cell:
                return best
        return best


def _ring(ci: int, cj: int, r: int) -> list[tuple[int, int]]:
    if r == 0:
        return [(ci, cj)]
    out = [(ci + d, cj - r) for d in range(-r, r + 1)]
    out += [(ci + d, cj + r) for d in range(-r, r + 1)]
    out += [(ci - r, cj + d) for d in range(-r + 1, r)]
    out += [(ci + r, cj + d) for d in range(-r + 1, r)]
    return out


def _placement(prob: _Problem, cand: int) -> Placement:
    i = int(prob.cstroke[cand])
    code = int(prob.ccode[cand])
    if code >= 2:
        return Placement(i, False, code - 2)
    return Placement(i, code == 1, 0)


def _greedy(prob: _Problem, before: Sequence[tuple[int, int]]) -> list[int]:
    """Candidate ids in greedy order (one per non-empty stroke)."""
    n = prob.n
    succ: list[list[int]] = [[] for _ in range(n)]
    npred = np.zeros(n, dtype=np.int64)
    for a, b in before:
        if a != b and not prob.empty[a] and not prob.empty[b]:
            succ[a].append(b)
            npred[b] += 1
    grid = _Grid(prob.cpt)
    for i in range(n):
        if not prob.empty[i] and npred[i] == 0:
            grid.insert(prob.cand_of[i])
    out: list[int] = []
    todo = int((~prob.empty).sum())
    # start: the first stroke in file order that may go first, as given (or its first start)
    first = next((i for i in range(n) if not prob.empty[i] and npred[i] == 0), None)
    if first is None:
        return out
    cand = int(prob.cand_of[first][0])
    while True:
        i = int(prob.cstroke[cand])
        out.append(cand)
        grid.kill(prob.cand_of[i])
        for j in succ[i]:
            npred[j] -= 1
            if npred[j] == 0:
                grid.insert(prob.cand_of[j])
        if len(out) == todo:
            break
        _, ex = prob.entry_exit(cand)
        cand = grid.nearest(ex)
        if cand < 0:  # a precedence cycle: take the rest as they come
            rest = [int(prob.cand_of[k][0]) for k in range(n)
                    if not prob.empty[k] and k not in {int(prob.cstroke[c]) for c in out}]
            out.extend(rest)
            break
    return out


class _Tour:
    """A tour as arrays over positions: stroke, entry point S, exit point E, candidate."""

    def __init__(self, prob: _Problem, cands: list[int]) -> None:
        self.prob = prob
        self.cand = np.array(cands, dtype=np.int64)
        self.stroke = prob.cstroke[self.cand].copy()
        se = [prob.entry_exit(c) for c in cands]
        self.S = np.array([a for a, _ in se]).reshape(-1, 2)
        self.E = np.array([b for _, b in se]).reshape(-1, 2)
        self.pos = np.full(prob.n, -1, dtype=np.int64)
        self.pos[self.stroke] = np.arange(len(cands))

    def length(self) -> float:
        if len(self.S) < 2:
            return 0.0
        d = self.S[1:] - self.E[:-1]
        return float(np.hypot(d[:, 0], d[:, 1]).sum())

    def d(self, a: np.ndarray, b: np.ndarray) -> float:
        return math.hypot(float(a[0] - b[0]), float(a[1] - b[1]))

    def reverse(self, lo: int, hi: int) -> None:
        """Reverse positions lo..hi (inclusive): open strokes flip, closed stay."""
        sl = slice(lo, hi + 1)
        self.cand[sl] = self.cand[sl][::-1]
        self.stroke[sl] = self.stroke[sl][::-1]
        s_new = self.E[sl][::-1].copy()
        e_new = self.S[sl][::-1].copy()
        self.S[sl] = s_new
        self.E[sl] = e_new
        prob = self.prob
        idx = np.arange(lo, hi + 1)
        code = prob.ccode[self.cand[sl]]
        flip = code < 2
        # open strokes: the other end's candidate (codes 0 <-> 1 are consecutive ids)
        self.cand[idx[flip]] = np.where(code[flip] == 0, self.cand[idx[flip]] + 1,
                                        self.cand[idx[flip]] - 1)
        self.pos[self.stroke[sl]] = idx

    def move(self, i: int, j: int, flip: bool) -> None:
        """Move the stroke at position i to sit just before the stroke now at position j."""
        order = np.arange(len(self.cand))
        rest = np.delete(order, i)
        k = j if j < i else j - 1
        new = np.insert(rest, k, i)
        self.cand = self.cand[new]
        self.stroke = self.stroke[new]
        self.S = self.S[new]
        self.E = self.E[new]
        self.pos[self.stroke] = np.arange(len(new))
        if flip:
            self.reverse(k, k)


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


def _neighbours(prob: _Problem, k: int, window: int = 6) -> list[np.ndarray]:
    """For each stroke, up to k other strokes with an end point near one of its ends:
    points close in two shifted Z-orders (vectorised; an approximation of k-nearest)."""
    n = prob.n
    pts = prob.cpt
    empty = [np.zeros(0, dtype=np.int64)] * n
    if len(pts) < 2:
        return empty
    lo = pts.min(axis=0)
    span = max(float((pts.max(axis=0) - lo).max()), 1e-9)
    sa_l, sb_l = [], []
    for shift in (0.0, 0.31):
        q = np.floor((pts - lo + shift * span) / (span * (1.0 + shift)) * 65535.0)
        order = np.argsort(_morton(np.clip(q, 0, 65535).astype(np.int64)), kind="stable")
        for w in range(1, window + 1):
            sa_l.append(order[:-w])
            sb_l.append(order[w:])
    a = np.concatenate(sa_l)
    b = np.concatenate(sb_l)
    a, b = np.concatenate([a, b]), np.concatenate([b, a])
    sa, sb = prob.cstroke[a], prob.cstroke[b]
    keep = sa != sb
    a, b, sa, sb = a[keep], b[keep], sa[keep], sb[keep]
    dist = np.hypot(*(pts[a] - pts[b]).T)
    o = np.lexsort((dist, sb, sa))
    sa, sb, dist = sa[o], sb[o], dist[o]
    first = np.r_[True, (sa[1:] != sa[:-1]) | (sb[1:] != sb[:-1])]
    sa, sb, dist = sa[first], sb[first], dist[first]
    o = np.lexsort((dist, sa))
    sa, sb = sa[o], sb[o]
    bounds = np.searchsorted(sa, np.arange(n + 1))
    return [sb[bounds[i]:min(bounds[i + 1], bounds[i] + k)] for i in range(n)]


def _improve(prob: _Problem, tour: _Tour, before: Sequence[tuple[int, int]],
             deadline: float, seed: int = 0) -> None:
    """Local search, then iterated local search until the deadline.

    Local search (queue of strokes to look at, "don't-look bits"): 2-opt over the candidate
    lists (a block reversal: every open stroke in it is marked the other way round) and
    Or-opt (a block of 1-3 strokes moved next to a candidate neighbour, either way round).
    Then, while time is left: a double-bridge kick (three cuts close together, the middle
    blocks swapped), local search around the cuts, keep the result if it is shorter, else go
    back to the best tour. Precedence pairs are checked after every move (a move that breaks
    one is undone)."""
    n = len(tour.cand)
    if n < 3:
        return
    nb = [x.tolist() for x in _neighbours(prob, NEIGHBOURS)]
    pa = np.array([a for a, _ in before], dtype=np.int64)
    pb = np.array([b for _, b in before], dtype=np.int64)
    has_cons = len(pa) > 0
    rng = np.random.default_rng(seed)
    hyp = math.hypot
    # plain-list mirrors of the tour (fast scalar access), refreshed after every change
    L: dict[str, list] = {}

    def refresh() -> None:
        L["sx"], L["sy"] = tour.S[:, 0].tolist(), tour.S[:, 1].tolist()
        L["ex"], L["ey"] = tour.E[:, 0].tolist(), tour.E[:, 1].tolist()
        L["pos"] = tour.pos.tolist()

    refresh()

    def d(p: int, q: int) -> float:  # exit of position p to entry of position q
        if p < 0 or q >= n:
            return 0.0
        return hyp(L["ex"][p] - L["sx"][q], L["ey"][p] - L["sy"][q])

    def cons_ok() -> bool:
        return not has_cons or bool((tour.pos[pa] < tour.pos[pb]).all())

    def snapshot() -> tuple:
        return (tour.cand.copy(), tour.stroke.copy(), tour.S.copy(), tour.E.copy(),
                tour.pos.copy())

    def restore(sn: tuple) -> None:
        tour.cand[:], tour.stroke[:], tour.S[:], tour.E[:], tour.pos[:] = sn
        refresh()

    def rev_delta(lo: int, hi: int) -> float:
        """Gain of reversing positions lo..hi."""
        old = d(lo - 1, lo) + d(hi, hi + 1)
        new = 0.0
        ex, ey, sx, sy = L["ex"], L["ey"], L["sx"], L["sy"]
        if lo > 0:
            new += hyp(ex[lo - 1] - ex[hi], ey[lo - 1] - ey[hi])
        if hi + 1 < n:
            new += hyp(sx[lo] - sx[hi + 1], sy[lo] - sy[hi + 1])
        return old - new

    def apply_block(i: int, ln: int, at: int, flip: bool) -> None:
        """Move positions i..i+ln-1 to sit before position `at` (outside the block)."""
        order = np.arange(n)
        blk = order[i:i + ln]
        rest = np.concatenate([order[:i], order[i + ln:]])
        k = at if at < i else at - ln
        new = np.concatenate([rest[:k], blk, rest[k:]])
        tour.cand[:] = tour.cand[new]
        tour.stroke[:] = tour.stroke[new]
        tour.S[:] = tour.S[new]
        tour.E[:] = tour.E[new]
        tour.pos[tour.stroke] = np.arange(n)
        if flip:
            tour.reverse(k, k + ln - 1)

    def try_at(s: int) -> list[int] | None:
        """Best improving move around stroke s; applies it, returns strokes to re-examine."""
        pos = L["pos"]
        ex, ey, sx, sy = L["ex"], L["ey"], L["sx"], L["sy"]
        i = pos[s]
        best: tuple[float, tuple | None] = (1e-9, None)
        # Or-opt blocks of 1..3 strokes starting or ending at s: removal gain, ends
        blocks = []
        for ln in (1, 2, 3):
            for st in ((i,) if ln == 1 else (i, i - ln + 1)):
                j2 = st + ln - 1
                if st < 0 or j2 >= n:
                    continue
                rem = d(st - 1, st) + d(j2, j2 + 1)
                if st > 0 and j2 + 1 < n:
                    rem -= d(st - 1, j2 + 1)
                blocks.append((st, ln, rem, sx[st], sy[st], ex[j2], ey[j2]))
        for c in nb[s]:
            j = pos[c]
            if j < 0 or j == i:
                continue
            # 2-opt: the four block reversals that make s and c neighbours
            for lo, hi in ((i + 1, j), (j + 1, i), (i, j - 1), (j, i - 1)):
                if 0 <= lo <= hi < n:
                    g = rev_delta(lo, hi)
                    if g > best[0]:
                        best = (g, ("r", lo, hi))
            # Or-opt: a block next to c (before or after it), either way round
            for at in (j, j + 1):
                p, q = at - 1, at
                hp = p >= 0
                hq = q < n
                base = hyp(ex[p] - sx[q], ey[p] - sy[q]) if hp and hq else 0.0
                for st, ln, rem, ax, ay, bx, by in blocks:
                    if st <= at <= st + ln or rem <= best[0]:
                        continue
                    for flip in (False, True):
                        if flip:
                            fx, fy, tx, ty = bx, by, ax, ay  # enters at the old exit
                        else:
                            fx, fy, tx, ty = ax, ay, bx, by
                        add = -base
                        if hp:
                            add += hyp(ex[p] - fx, ey[p] - fy)
                        if hq:
                            add += hyp(tx - sx[q], ty - sy[q])
                        g = rem - add
                        if g > best[0]:
                            best = (g, ("m", st, ln, at, flip))
        mv = best[1]
        if mv is None:
            return None
        sn = snapshot() if has_cons else None
        if mv[0] == "r":
            _, lo, hi = mv
            touched = [lo - 1, lo, hi, hi + 1]
            tour.reverse(lo, hi)
            refresh()
        else:
            _, st, ln, at, flip = mv
            touched = [st - 1, st, st + ln - 1, st + ln, at - 1, at]
            ids = [int(tour.stroke[p]) for p in touched if 0 <= p < n]
            apply_block(st, ln, at, flip)
            refresh()
            if sn is not None and not cons_ok():
                restore(sn)
                return None
            return ids
        if sn is not None and not cons_ok():
            restore(sn)
            return None
        return [int(tour.stroke[p]) for p in touched if 0 <= p < n]

    def local_search(queue: list[int]) -> bool:
        inq = np.zeros(prob.n, dtype=bool)
        dq: deque[int] = deque()
        for s in queue:
            if not inq[s]:
                inq[s] = True
                dq.append(s)
        steps = 0
        while dq:
            steps += 1
            if (steps & 31) == 0 and time.perf_counter() > deadline:
                return False
            s = dq.popleft()
            inq[s] = False
            got = try_at(s)
            if got is not None:
                for t in [s, *got]:
                    for u in (t, *nb[t][:3]):
                        if not inq[u] and tour.pos[u] >= 0:
                            inq[u] = True
                            dq.append(u)
        return True

    if not local_search([int(s) for s in tour.stroke]):
        return
    _rotate_closed(prob, tour)
    best_len = tour.length()
    best = snapshot()
    if n < 8:
        return
    while time.perf_counter() < deadline:
        # double bridge over three cuts near each other: A B C D -> A C B D
        span = int(min(n - 1, 60))
        a = int(rng.integers(0, n - 3))
        l1 = int(rng.integers(1, span))
        l2 = int(rng.integers(1, span))
        b, c = min(a + l1, n - 2), min(a + l1 + l2, n - 1)
        if not a < b < c:
            continue
        order = np.arange(n)
        new = np.concatenate([order[:a], order[b:c], order[a:b], order[c:]])
        tour.cand[:] = tour.cand[new]
        tour.stroke[:] = tour.stroke[new]
        tour.S[:] = tour.S[new]
        tour.E[:] = tour.E[new]
        tour.pos[tour.stroke] = np.arange(n)
        refresh()
        if has_cons and not cons_ok():
            restore(best)
            continue
        around = [p for p in (a - 1, a, b - 1, b, c - 1, c, a + c - b - 1, a + c - b)
                  if 0 <= p < n]
        finished = local_search([int(tour.stroke[p]) for p in around])
        ln = tour.length()
        if ln < best_len - 1e-9:
            best_len = ln
            best = snapshot()
        else:
            restore(best)
        if not finished:
            break
    restore(best)


def _rotate_closed(prob: _Problem, tour: _Tour) -> None:
    """Best start point of every closed stroke between its neighbours."""
    n = len(tour.cand)
    for p in range(n):
        i = int(tour.stroke[p])
        if not prob.closed[i]:
            continue
        ids = prob.cand_of[i]
        pts = prob.cpt[ids]
        cost = np.zeros(len(ids))
        if p > 0:
            cost += np.hypot(*(pts - tour.E[p - 1]).T)
        if p + 1 < n:
            cost += np.hypot(*(pts - tour.S[p + 1]).T)
        k = int(np.argmin(cost))
        cur = int(np.flatnonzero(ids == tour.cand[p])[0]) if (ids == tour.cand[p]).any() else k
        if cost[k] < cost[cur] - 1e-12:
            tour.cand[p] = ids[k]
            tour.S[p] = pts[k]
            tour.E[p] = pts[k]


def order_strokes(
    strokes: Sequence[np.ndarray],
    *,
    method: str = "greedy",
    time_budget_s: float = 1.0,
    closed: Sequence[bool] | None = None,
    before: Sequence[tuple[int, int]] = (),
    starts: Sequence[np.ndarray | None] | None = None,
) -> list[Placement]:
    """The marking order of ``strokes`` (each (N, 2) points, any units).

    ``closed[i]``: stroke i is a closed ring (may start at any of its points, or at the
    indices in ``starts[i]`` when given); open strokes may be reversed. ``before``:
    precedence pairs (a, b), a marked before b (see :func:`nesting_constraints`).
    Empty strokes keep their place at the end. Returns one :class:`Placement` per stroke.
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
    tour = _Tour(prob, cands)
    empties = [Placement(i) for i in range(n) if prob.empty[i]]
    greedy = [_placement(prob, int(c)) for c in tour.cand] + empties
    ok_file = all(a < b for a, b in before)
    g_len = tour.length()
    f_len = travel_length(strokes, file_order, cl)
    if method == "greedy" or len(cands) < 3:
        return file_order if ok_file and f_len < g_len else greedy
    if ok_file and f_len < g_len:  # start from the better of the two
        tour = _Tour(prob, [int(prob.cand_of[i][0]) for i in range(n) if not prob.empty[i]])
        g_len = f_len
        greedy = file_order
    _rotate_closed(prob, tour)
    _improve(prob, tour, before, t0 + time_budget_s)
    out = [_placement(prob, int(c)) for c in tour.cand] + empties
    return out if tour.length() <= g_len + 1e-9 else greedy


# ------------------------------------------------------------------ job strokes
def _joint_indices(marks: np.ndarray, segments: Sequence[tuple[str, np.ndarray]],
                   fm: object) -> np.ndarray | None:
    """Mark indices where a fitted segment starts (where a closed stroke may be cut)."""
    if not segments:
        return None
    starts = np.array([np.asarray(p)[0] for _, p in segments], dtype=np.float64)
    sb = fm.to_bits(starts)  # type: ignore[attr-defined]
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


def _reverse_segments(segs: Sequence[tuple[str, np.ndarray]]) -> tuple[
        tuple[str, np.ndarray], ...]:
    return tuple((k, np.asarray(p)[::-1].copy()) for k, p in reversed(segs))


def apply_to_strokes(strokes: Sequence[object], placements: Sequence[Placement],
                     fm: object) -> list[object]:
    """Job strokes in the new order, marks and segments reversed / rotated to match."""
    from dataclasses import replace

    out = []
    for pl in placements:
        s = strokes[pl.index]
        marks = s.marks  # type: ignore[attr-defined]
        segs = tuple(s.segments)  # type: ignore[attr-defined]
        if pl.rotate and s.closed:  # type: ignore[attr-defined]
            marks = apply_placement(marks, True, Placement(pl.index, False, pl.rotate))
            if segs:
                sb = fm.to_bits(np.array([np.asarray(p)[0] for _, p in segs]))  # type: ignore
                hit = np.flatnonzero((sb == marks[0]).all(axis=1))
                if len(hit):
                    t = int(hit[0])
                    segs = segs[t:] + segs[:t]
        if pl.reverse:
            marks = marks[::-1].copy()
            segs = _reverse_segments(segs)
        out.append(replace(s, marks=marks, segments=segs))  # type: ignore[type-var]
    return out


def order_job_strokes(strokes: Sequence[object], fm: object, *, method: str,
                      time_budget_s: float = 1.0, inner_first: bool = True,
                      hatch_first: bool = True) -> list[object]:
    """Order a job's strokes (contour and hatch :class:`~galvo_core.job.Stroke`) in place of
    the pipeline's order stage; closed contours start only at segment joints."""
    if method == "file":
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
    return apply_to_strokes(strokes, pls, fm)
