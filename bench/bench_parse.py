"""Importer benchmark (issue 3 §6): speed of ``galvo_core.hpgl.read_bytes`` and a path-by-path
comparison with the ``ezhpgl`` package on the shared PLT corpus.

Run it through ``bash bench/run_parse.sh`` (which builds ``bench/.venv-peers`` with ezhpgl and
numpy; the project is put on ``sys.path``, so both parsers run in this one process)::

    bench/.venv-peers/bin/python bench/bench_parse.py                 # print everything
    bench/.venv-peers/bin/python bench/bench_parse.py --write bench/RESULTS.md
    bench/.venv-peers/bin/python bench/bench_parse.py --corpus-only --examples 3

Part (a), speed: ``bench/gen_plt.py`` makes a 1,000,000-point PLT (seed 0); the bytes are read
once into memory; ``read_bytes`` is timed on them: the first call in the process (cold), then
``--runs`` more calls (the cold one doubles as the warm-up). ezhpgl is timed the same way on
the same bytes (its default limits are raised so that it accepts the file).

Part (b), comparison: see :func:`compare` for the matching rule and ``RESULTS.md`` for the
explanation of the differences.
"""

from __future__ import annotations

import argparse
import collections
import datetime as _dt
import glob
import importlib.util
import os
import platform
import re
import statistics
import sys
import time
from dataclasses import dataclass, field

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
if REPO not in sys.path:
    sys.path.insert(0, REPO)

from results_md import replace_section  # noqa: E402

from galvo_core.errors import InputError  # noqa: E402
from galvo_core.hpgl import read_bytes  # noqa: E402

try:
    import ezhpgl
except ImportError:  # the bench still measures our speed without the peer
    ezhpgl = None

CORPUS = os.environ.get("GALVO_PLT_CORPUS", "/work/shared/corpus/plt")
TOL = 0.5  # plotter units
PU_PER_MM = 40.0
SECTION = "## Import (issue 3)"
BENCH_DATE = "2026-11-23"
# ezhpgl needs plot extents for SC without IP, RO, IR... We retry with the extents our reader
# assumes by default (P1..P2 of an HP 7475A on ANSI A: 10000 x 7200 units = 250 x 180 mm).
FALLBACK_PROFILE_MM = (250.0, 180.0)


EXPLANATION = """\
### Why the paths differ (looked at case by case, ezhpgl 0.1.0a2)

Every unmatched path in the files ezhpgl parses in strict mode falls into one of the
classes below (the per-file columns above show which); the refused files' prefixes show the
same classes. Minimal inputs that reproduce each are given so they can be re-checked.

1. **No pen selected: ezhpgl draws nothing (6 files, about 41,500 of our paths).**
   `b_fabric_nesting.plt`, `randomledcontroller_pen3.plt`, `bird_...hpgl`, `marr.pgl` and
   `arcs.hp` never send SP; `space-columbia.plt` sends `SP0` before drawing. A plotter draws
   nothing without a pen, and ezhpgl follows that (its operations are simply absent). We
   import them (pen 1 when no SP was sent, pen 0 after SP0), because these files are
   plainly meant to be drawn, and say so in a warning (issue 20). This one rule accounts for
   most of the paths without partner.
2. **EP after FP, EP after RA/RR/WG: ezhpgl emits the polygon once per command.** A
   `PM2;FP;EP;` polygon is two operations in ezhpgl and one ring in ours (a ring is
   geometry, not paint: see the reader's docstring). These are the "dup" numbers in the last
   column (cfriisha 231, temagrin 893, polygons 5, ...): duplicates, not a geometry
   difference.
3. **CI inside polygon mode: ezhpgl centres the circle on the wrong point (their bug; 669
   paths, all in the two KiCad files cfriisha and temagrin).** KiCad writes a round pad as
   `PU;PA 4647,3728; PM 0; PA 4623,3728;CI 24;PM 2; FP; EP;`. CI is centred at the current
   pen position, (4623,3728), so the ring starts at (4647,3728), as ours does. ezhpgl stores
   the pen-up move from the centre to the start point and then takes that start point as
   the centre: its ring starts at (4671,3728), one radius to the right. Minimal:
   `IN;SP1;PU;PA4647,3728;PM0;PA4623,3728;CI24;PM2;EP;`. Without PM
   (`...PA4623,3728;CI24;`) ezhpgl gets it right.
4. **Labels move the pen (lo.hp, 2 of our paths against 6 of theirs).**
   `PD1500,1200;LO18;LBLEFT OF POINT<CR><ETX>;PD2500,1200;LO12;LBRIGHT OF POINT<ETX>
   PD2000,1500` (`<CR>`/`<ETX>` are the control bytes): ezhpgl moves the current position
   to the end of each label (back to the carriage-return point after a CR) and starts a new
   path after it. We skip labels without moving the pen, so our second triangle's last side
   starts at (2500,2700) where theirs starts at (4080.4,2700), the end of "RIGHT OF POINT".
   HP-GL does move the pen to the end of the label, so here ezhpgl was right (bug 3 below).
   Since issue 20 we move the pen over the label too (character cell from SI/SR or the
   default size, CR/LF, DI/DR) and apply the label origin LO (after LO4-9/14-19 the pen
   position before LB is restored, PCL5-II 23-65), so lo.hp agrees within 1 % in length
   and extent (tests/test_hpgl_ezhpgl.py).
   Neither parser draws letters: ezhpgl returns labels as glyph boxes in a substitute font
   (TEXT_APPROXIMATION, "labels" column), and we warn that labels are not drawn.
5. **IW clipping (input-window.hpgl 4 paths, fill.plt 25, iw.hp 1).** We cut pen-down
   lines at the IW window. `IW;` with no parameters means the hard-clip limits, i.e. the
   page that PS gave (iw.hp). ezhpgl keeps the whole line and attaches the window to the operation
   (`op.clip`) for its renderer. Our pieces lie on their lines ("on their lines" column) and
   theirs reach outside the window ("beyond IW" column).
6. **RO origin (felixfischer arcs.hpgl 1 path; 286x192.5_qh2.hpg all 108 paths agree after
   a shift of (10830,0); spectrum.plt's prefix after (10000,0)).** We rotate about the
   plotter origin, (x,y) -> (-y,x) for RO90. ezhpgl puts the origin in the corner of the
   rotated plot extents, x' = width - y, so it needs the extents: without them it refuses
   with MISSING_DEVICE_BOUNDS. The shapes are the same, only translated by one extent. The
   corpus golden for felixfischer arcs.hpgl has the RO90 arc at (8000,2000), which is where
   ours is. A galvo field has no page, so this only moves the drawing.
7. **Default P1/P2 for SC without IP (r_s-analyzer.hpgl: all 1918 paths agree after a
   shift of (-250,-596); test2h.hpgl).** Our defaults are those of an HP 7475A,
   (250,596)-(10250,7796). ezhpgl has no default and refuses. Given 250 x 180 mm extents,
   it puts P1 at (0,0). Same shapes, translated.
8. **The closing edge of PM1/PM2.** ezhpgl stores the edge that PM1/PM2 adds to close an
   open subpolygon as *pen-up*: EP does not stroke it, and its SVG leaves the outline open.
   Since issue 20 we give that edge the pen state at PM1/PM2 (PCL5 reference p. 21-37 points
   to "Pen Status"): drawn when the pen is down (the corpus goldens' closed rings), not drawn
   when it is up (GNU plotutils' open polylines `PM0;PD;PA...;PU;PM2;EP;`). The comparison
   counts that edge as drawn on their side (see `their_paths`), which matches us on every
   polygon closed with the pen down.
9. **Arcs, circles, wedges, rectangles: no differences.** Every AA/AR/CI/EW/WG/EA/RA path
   in the strict files (apart from classes 3 and 6) agrees point by point within 0.5 units,
   with the same number of points: both flatten by the HP-GL chord rule (5° default chord
   angle, CT1 tolerance mode). No file showed different chord counts. BZ appears only in a
   refused file (bz.hp).
10. **Refusals (44 files).** ezhpgl is strict by design: it stops at the first command it is
    unsure of and returns the valid prefix as `partial`. It refuses PCL/PJL wrappers it
    does not model (UNSUPPORTED_PCL/PJL, UNSUPPORTED_MODE_SWITCH), and it stops at
    INVALID_MNEMONIC on a leading ETX or NUL padding, HP 7475A device-control escapes
    (`.(;.I81;;17:`), vendor `!XX` commands and stray letters (`PUx;`). It also stops on
    unquoted CO comments, `PG` without `;`, trailing commas (`PD673,4271,673,7197,;`:
    MISSING_PARAMETER), opaque commands (`SM*`, `DT<ETX>,1`), and attribute variants it does
    not preview (`LA1,3`, FT10, PW forms). It refuses **every PE file in the corpus**
    (PE_INVALID_BYTE, or a wrapper before it). XT/YT tick marks are ignored
    (IGNORED_COMMAND): our XT/YT paths in test2h/test3h have no partner. Our PE decoding is
    therefore not cross-checked by the corpus. On a hand-made PE square
    (`PE<=m\\xcdm\\xcd=m\\xcd\\xbf=\\xbf\\xbf=\\xbfm\\xcd=m\\xcdm\\xcd`) both give
    (471,471),(471,0),(0,0),(0,471),(471,471).

### Importer bugs found (galvo_core; reported, not fixed here)

1. **IR with only P1 left P2 where it was, which stretched the picture. Found here; already
   fixed in the tree (commit f39873e) before this run.** In `_Reader.do_ir` the offset
   P2 - P1 was taken after P1 had been overwritten.
   `read_bytes(b"IN;PS10000,7200;SP1;IP0,0,1000,1000;IR50,50;SC0,10,0,10;PU0,0;PD10,10;")`
   gave (5000,3600)->(1000,1000). It now gives (5000,3600)->(6000,4600), which is also
   ezhpgl's answer. It affected the jem-green files that use `IR0,100`: the PE square of
   test3-model was 1595 x 4170 units and is now 1595 x 1595.
2. **After PM1, the move to the next subpolygon's first point is drawn when the pen is
   down.** `dgtlrift__hp2xx__pm.hp` is the HP manual's receptacle example:
   `PA2000,2000;PM0;PD3000,2000,3000,3000;PD2000,3000;PM1;PD2080,2160,...;PM1;PD2080,2660,...`.
   We return ring 2 as `(2000,3000),(2080,2160),...,(2080,2160),(2000,3000)`: a spike
   runs from where the pen was to the new subpolygon's start and back. Rings 3 and 4 start
   the same way, at (2080,2160) and (2080,2660). The HP PCL5/HP-GL/2 reference (PM):
   "the point after (PM1) becomes the first point of the next subpolygon ... When drawing
   the polygon, the pen always moves to this point in the up position, regardless of the
   current pen status." Right:
   `(2080,2160),(2480,2160),(2480,2340),(2080,2340),(2080,2160)`. ezhpgl does it this way.
   Check: `python -c "from galvo_core.hpgl import read_file;
   print(read_file('/work/shared/corpus/plt/dgtlrift__hp2xx__pm.hp').paths[1].points)"`.
3. **LB did not move the current pen position (fixed in issue 20, LO included)** (class 4
   above; `lo.hp`). After a label,
   HP-GL leaves the pen at the end of the text, or at the carriage-return point after CR/LF.
   A following PD therefore starts there. We keep the label's start point. Fixing it needs
   the character cell (SI/SR/DI/DR/LO/ES and the default size) but not the glyphs. Small
   in practice: it only matters when a file draws from a label's end without moving first.

Not a bug but worth a warning: SP0 followed by drawing (space-columbia.plt) is imported as
pen 0 with a warning; HP-GL would draw nothing (class 1). Since issue 20 paths drawn before
any SP are warned about too.
"""


def _load_gen_plt():
    spec = importlib.util.spec_from_file_location("gen_plt", os.path.join(HERE, "gen_plt.py"))
    mod = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(mod)
    return mod


# ------------------------------------------------------------------------------- machine
def machine_info() -> dict[str, str]:
    cpu = "?"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {
        "nproc": str(os.cpu_count()),
        "cpu": cpu,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "ezhpgl": getattr(ezhpgl, "__version__", "not installed"),
        "load": " ".join(f"{x:.2f}" for x in os.getloadavg()),
    }


# --------------------------------------------------------------------------------- speed
def _timed(fn, data):
    """(wall seconds, CPU seconds of this process, result)."""
    c0 = time.process_time()
    t0 = time.perf_counter()
    out = fn(data)
    return time.perf_counter() - t0, time.process_time() - c0, out


@dataclass
class Speed:
    name: str
    n_points: int
    cold: float
    runs: list[float]
    cpu: list[float]  # CPU time of the same runs (less disturbed by other jobs)
    out_points: int
    out_paths: int
    note: str = ""
    fresh: list = field(default_factory=list)  # first call in new processes (ours only)

    @property
    def median(self) -> float:
        return statistics.median(self.runs)

    def row(self) -> str:
        med = self.median
        return (
            f"| {self.name} | {self.out_paths:,} | {self.out_points:,} | {self.cold:.3f} | "
            f"{self.n_points / self.cold / 1e6:.2f} | {med:.3f} | "
            f"{self.n_points / med / 1e6:.2f} | "
            f"{min(self.runs):.3f} / {max(self.runs):.3f} | {statistics.median(self.cpu):.3f} | "
            f"{self.n_points / statistics.median(self.cpu) / 1e6:.2f} |"
        )


_FRESH = r"""
import json, sys, time
t0 = time.perf_counter()
sys.path.insert(0, sys.argv[1])
from galvo_core.hpgl import read_bytes
t1 = time.perf_counter()
data = open(sys.argv[2], "rb").read()
c0 = time.process_time()
t2 = time.perf_counter()
d = read_bytes(data, "gen.plt")
t3 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "first": t3 - t2, "cpu": time.process_time() - c0,
                  "points": d.n_points}))
"""


def fresh_cold(path: str, n: int = 3) -> list[dict]:
    """The first read_bytes call in ``n`` new Python processes (import timed apart)."""
    import json
    import subprocess

    out = []
    for _ in range(n):
        res = subprocess.run(
            [sys.executable, "-c", _FRESH, REPO, path], capture_output=True, text=True, check=True
        )
        out.append(json.loads(res.stdout))
    return out


def bench_speed(n_points: int, runs: int, peers: bool) -> tuple[list[Speed], int]:
    gen = _load_gen_plt()
    os.makedirs(os.path.join(HERE, "out"), exist_ok=True)
    path = os.path.join(HERE, "out", f"gen_{n_points}.plt")
    data = gen.generate_plt(n_points, 0)
    with open(path, "wb") as f:
        f.write(data)
    with open(path, "rb") as f:
        data = f.read()
    results = []

    def ours(b):
        return read_bytes(b, "gen.plt")

    cold, _, d = _timed(ours, data)
    tc = [_timed(ours, data)[:2] for _ in range(runs)]
    results.append(
        Speed(
            "galvo_core read_bytes",
            n_points,
            cold,
            [w for w, _ in tc],
            [c for _, c in tc],
            d.n_points,
            len(d.paths),
        )
    )
    results[0].fresh = fresh_cold(path)
    if peers and ezhpgl is not None:
        limits = ezhpgl.Limits(max_input_bytes=1 << 30, max_commands=1 << 26)
        glim = ezhpgl.GeometryLimits(max_operations=1 << 26, max_vertices=1 << 26)

        def theirs(b):
            return ezhpgl.parse(b, limits=limits, geometry_limits=glim)

        cold, _, doc = _timed(theirs, data)
        tc = [_timed(theirs, data)[:2] for _ in range(runs)]
        tp = their_paths(doc)
        results.append(
            Speed(
                f"ezhpgl {ezhpgl.__version__} parse",
                n_points,
                cold,
                [w for w, _ in tc],
                [c for _, c in tc],
                sum(len(p) for p in tp.paths),
                len(tp.paths),
                doc.completeness,
            )
        )
    return results, len(data)


# ------------------------------------------------------------------- ezhpgl -> our paths
@dataclass
class Theirs:
    paths: list[np.ndarray] = field(default_factory=list)  # plotter units
    cmds: list[str] = field(default_factory=list)  # source command of each path
    beyond_clip: list[bool] = field(default_factory=list)  # reaches outside op.clip (IW)
    closed_by_us: int = 0  # polygon contours whose PM1/PM2 closing edge we added (see below)
    labels: int = 0
    glyphs: int = 0
    hatch_lines: int = 0
    kinds: collections.Counter = field(default_factory=collections.Counter)


def _beyond(op, pts: np.ndarray) -> bool:
    c = op.clip
    if c is None or c.bounds is None or not len(pts):
        return False
    lo = np.array([c.bounds.min.x, c.bounds.min.y]) * PU_PER_MM - TOL
    hi = np.array([c.bounds.max.x, c.bounds.max.y]) * PU_PER_MM + TOL
    return bool((pts < lo).any() or (pts > hi).any())


def their_paths(doc, close_polygons: bool = True) -> Theirs:
    """ezhpgl's pen-down geometry as our kind of paths, in plotter units.

    * polyline / curve operations sharing a ``path_id`` are one pen-down path (ezhpgl emits one
      operation per command; a path continues across PD commands until the pen lifts);
    * each polygon contour gives one path per run of pen-down edges (EA/RA/EW/WG/EP/FP); an
      edge covers contour points start..end (an arc edge covers many);
    * ezhpgl stores the edge that PM1/PM2 adds to close an open subpolygon as *pen-up*; with
      ``close_polygons`` it is counted as drawn (HP: "PM1/PM2 forces closure by adding a
      point"; we and the HP-GL viewers in the corpus goldens stroke it): ``closed_by_us``;
    * labels are counted (ezhpgl gives glyph boxes, not strokes), hatch lines are counted;
    * all pages are overlaid (as our reader does). mm are converted back with 40 units/mm.
    """
    t = Theirs()
    cur: list[np.ndarray] | None = None
    cur_id = None
    cur_op = None

    def add(pts, op):
        t.paths.append(pts)
        t.cmds.append(op.source.command)
        t.beyond_clip.append(_beyond(op, pts))

    def flush():
        nonlocal cur
        if cur:
            add(np.concatenate(cur), cur_op)
        cur = None

    for page in doc.pages:
        for op in page.operations:
            g = op.geometry
            t.kinds[g.kind] += 1
            if g.kind in ("polyline", "curve"):
                pts = np.array([(p.x, p.y) for p in g.points], dtype=np.float64) * PU_PER_MM
                if not len(pts):
                    continue
                if cur is not None and op.path_id == cur_id:
                    if np.array_equal(cur[-1][-1], pts[0]):
                        pts = pts[1:]
                    if len(pts):
                        cur.append(pts)
                else:
                    flush()
                    cur = [pts]
                    cur_id = op.path_id
                    cur_op = op
                continue
            flush()
            if g.kind == "polygon":
                for c in g.contours:
                    pts = np.array([(p.x, p.y) for p in c.points], dtype=np.float64) * PU_PER_MM
                    edges = [(e.start, e.end, e.pen_down, e.source.command) for e in c.edges]
                    runs: list[list[int]] = []  # point indices of each pen-down run
                    for s, e, down, _cmd in edges:
                        if not down:
                            continue
                        if not (runs and runs[-1][-1] == s):
                            runs.append([s])
                        step = 1 if e >= s else -1
                        runs[-1].extend(range(s + step, e + step, step))
                    if close_polygons and runs and len(edges) >= 2:
                        s, e, down, cmd = edges[-1]
                        last = runs[-1]
                        if (
                            not down
                            and cmd == "PM"
                            and last[-1] == s
                            and len(last) > 2
                            and np.array_equal(pts[e], pts[last[0]])
                            and not np.array_equal(pts[s], pts[e])
                        ):
                            last.append(e)
                            t.closed_by_us += 1
                    for run in runs:
                        if len(run) > 1:
                            add(pts[run], op)
                if g.fill is not None:
                    t.hatch_lines += len(g.fill.hatch_lines)
            elif g.kind == "label":
                t.labels += 1
                if g.label is not None:
                    t.glyphs += len(g.label.glyphs)
    flush()
    return t


# ------------------------------------------------------------------------------ matching
def _dedup(p: np.ndarray) -> np.ndarray:
    if len(p) < 2:
        return p
    keep = np.ones(len(p), bool)
    keep[1:] = np.any(np.abs(np.diff(p, axis=0)) > 1e-6, axis=1)
    return p[keep]


def _dev(a: np.ndarray, b: np.ndarray) -> float:
    """Largest point distance between a and b (same length) in their best alignment: same
    order, reversed, or (closed rings, first = last) any starting vertex either way."""
    best = float(np.max(np.hypot(*(a - b).T)))
    best = min(best, float(np.max(np.hypot(*(a - b[::-1]).T))))
    if best <= 1e-9:
        return best
    if len(a) >= 4 and np.hypot(*(a[0] - a[-1])) <= TOL and np.hypot(*(b[0] - b[-1])) <= TOL:
        ra, rb = a[:-1], b[:-1]
        for k in np.nonzero(np.hypot(*(rb - ra[0]).T) <= TOL)[0]:
            for cand in (np.roll(rb, -k, axis=0), np.roll(rb[::-1], -(len(rb) - 1 - k), axis=0)):
                best = min(best, float(np.max(np.hypot(*(ra - cand).T))))
    return best


def match_paths(ours: list[np.ndarray], theirs: list[np.ndarray], shift=(0.0, 0.0)):
    """One-to-one matching. Returns (pairs, unmatched_ours, unmatched_theirs).

    Two passes in our file order: first exact partners (every point within 0.001 unit), then
    within 0.5 unit, each time taking the candidate with the smallest largest deviation (dense
    hatching 0.1 unit apart must not steal each other's partners)."""
    sx, sy = shift
    buckets: dict[tuple[int, int, int], list[int]] = collections.defaultdict(list)
    tb = []
    for j, q in enumerate(theirs):
        lo = q.min(axis=0)
        hi = q.max(axis=0)
        tb.append((lo, hi))
        buckets[(len(q), int(np.floor(lo[0])), int(np.floor(lo[1])))].append(j)
    used = np.zeros(len(theirs), bool)
    partner = [-1] * len(ours)
    moved = [p + (sx, sy) if (sx or sy) else p for p in ours]
    for tol in (1e-3, TOL):
        for i, p in enumerate(moved):
            if partner[i] >= 0:
                continue
            lo = p.min(axis=0)
            hi = p.max(axis=0)
            fx, fy = int(np.floor(lo[0])), int(np.floor(lo[1]))
            best, best_j = tol, -1
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    for j in buckets.get((len(p), fx + dx, fy + dy), ()):
                        if used[j]:
                            continue
                        tlo, thi = tb[j]
                        if np.max(np.abs(tlo - lo)) > tol or np.max(np.abs(thi - hi)) > tol:
                            continue
                        d = _dev(p, theirs[j])
                        if d < best or (best_j < 0 and d <= best):
                            best, best_j = d, j
                            if d <= 1e-9:
                                break
            if best_j >= 0:
                used[best_j] = True
                partner[i] = best_j
    pairs = [(i, j) for i, j in enumerate(partner) if j >= 0]
    um_o = [i for i, j in enumerate(partner) if j < 0]
    um_t = [j for j in range(len(theirs)) if not used[j]]
    return pairs, um_o, um_t


def near_lines(points: np.ndarray, paths: list[np.ndarray], tol: float = TOL) -> np.ndarray:
    """For each point, True when it lies within ``tol`` of a segment (or dot) of ``paths``."""
    if not len(points) or not paths:
        return np.zeros(len(points), bool)
    segs_a, segs_b = [], []
    for q in paths:
        if len(q) == 1:
            segs_a.append(q)
            segs_b.append(q)
        else:
            segs_a.append(q[:-1])
            segs_b.append(q[1:])
    a = np.concatenate(segs_a)
    b = np.concatenate(segs_b)
    allp = np.concatenate([a, b, points])
    ext = float(np.max(allp.max(axis=0) - allp.min(axis=0))) or 1.0
    cell = max(4.0 * tol, ext / 1024.0)
    length = np.hypot(*(b - a).T)
    while True:  # split into pieces no longer than a cell, keep the total bounded
        k = np.maximum(1, np.ceil(length / cell)).astype(np.int64)
        if k.sum() <= 4_000_000:
            break
        cell *= 2
    idx = np.repeat(np.arange(len(a)), k)
    start = np.cumsum(k) - k
    part = np.arange(k.sum()) - np.repeat(start, k)
    t0 = part / np.repeat(k, k)
    t1 = (part + 1) / np.repeat(k, k)
    d = b[idx] - a[idx]
    pa = a[idx] + d * t0[:, None]
    pb = a[idx] + d * t1[:, None]
    mid = (pa + pb) / 2
    origin = allp.min(axis=0)
    ci = np.floor((mid - origin) / cell).astype(np.int64)
    W = int(np.ceil(ext / cell)) + 4
    key = (ci[:, 0] + 1) * W + (ci[:, 1] + 1)
    order = np.argsort(key, kind="stable")
    key, pa, pb = key[order], pa[order], pb[order]
    qi = np.floor((points - origin) / cell).astype(np.int64)
    hit = np.zeros(len(points), bool)
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            qk = (qi[:, 0] + 1 + dx) * W + (qi[:, 1] + 1 + dy)
            lo = np.searchsorted(key, qk, "left")
            hi = np.searchsorted(key, qk, "right")
            cnt = hi - lo
            if not cnt.sum():
                continue
            qrep = np.repeat(np.arange(len(points)), cnt)
            first = np.repeat(np.cumsum(cnt) - cnt, cnt)
            sidx = np.repeat(lo, cnt) + (np.arange(cnt.sum()) - first)
            p = points[qrep]
            s0, s1 = pa[sidx], pb[sidx]
            v = s1 - s0
            vv = np.einsum("ij,ij->i", v, v)
            tt = np.where(vv > 0, np.einsum("ij,ij->i", p - s0, v) / np.where(vv > 0, vv, 1), 0)
            tt = np.clip(tt, 0, 1)
            dist = np.hypot(*(s0 + v * tt[:, None] - p).T)
            ok = np.zeros(len(points), bool)
            np.logical_or.at(ok, qrep[dist <= tol], True)
            hit |= ok
    return hit


# ------------------------------------------------------------------------------- compare
_SKIP_RE = re.compile(rb"[\x00-\x20;,]*")


def _our_cmds(data: bytes, drawing) -> list[str]:
    """The mnemonic at each of our paths' source position (line/column -> byte offset)."""
    starts = [0] + [m.end() for m in re.finditer(rb"\n", data)]
    out = []
    for p in drawing.paths:
        ln, col = p.start.line, p.start.col
        if ln < 1 or ln > len(starts):
            out.append("?")
            continue
        off = starts[ln - 1] + col - 1
        off = _SKIP_RE.match(data, off).end()
        mn = data[off : off + 2]
        if not (len(mn) == 2 and mn.isalpha()):  # inside PE data: name the PE command
            pe = data.rfind(b"PE", max(0, off - 65536), off)
            mn = b"PE" if pe >= 0 else b"?"
        out.append(mn.decode("latin-1").upper())
    return out


def _median_time(fn, reps: int) -> float:
    ts = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


@dataclass
class FileResult:
    name: str
    size: int
    our_paths: int = 0
    our_points: int = 0
    our_time: float = float("nan")
    our_error: str = ""
    their_mode: str = ""  # strict | strict+profile | prefix (CODE) | refused (CODE)
    their_refusal: str = ""
    their_paths: int = 0
    their_points: int = 0
    their_time: float = float("nan")
    their_labels: int = 0
    their_hatch: int = 0
    matched: int = 0
    matched_shift: int = 0
    shift: tuple[float, float] = (0.0, 0.0)
    on_lines: int = 0  # our unmatched paths whose every point lies on their lines
    their_dups: int = 0  # their unmatched paths equal to another of their paths (EP+FP...)
    their_beyond_clip: int = 0  # their unmatched paths reaching outside their clip window
    their_closed: int = 0  # polygon closing edges added to theirs (see their_paths)
    um_ours_by_cmd: collections.Counter = field(default_factory=collections.Counter)
    um_theirs_by_cmd: collections.Counter = field(default_factory=collections.Counter)
    examples: list[str] = field(default_factory=list)

    @property
    def best(self) -> int:
        return max(self.matched, self.matched_shift)


def _parse_theirs(data: bytes):
    """ezhpgl as a user would call it: strict; on refusal, with extents; then tolerant prefix."""
    try:
        return ezhpgl.parse(data), "strict", ""
    except ezhpgl.ParseError as exc:
        first = exc.diagnostic.code
    prof = ezhpgl.DeviceProfile(plot_size_mm=FALLBACK_PROFILE_MM)
    if first == "MISSING_DEVICE_BOUNDS":
        try:
            return ezhpgl.parse(data, profile=prof), "strict+extents", first
        except ezhpgl.ParseError as exc:
            first2 = exc.diagnostic.code
            doc = ezhpgl.parse(data, strict=False, profile=prof)
            return doc, f"prefix ({first2})", first
    doc = ezhpgl.parse(data, strict=False)
    return doc, f"prefix ({first})", first


def compare_file(path: str, reps: int, n_examples: int) -> FileResult:
    name = os.path.basename(path)
    with open(path, "rb") as f:
        data = f.read()
    r = FileResult(name, len(data))
    try:
        d = read_bytes(data, name)
    except InputError as exc:
        r.our_error = str(exc).split(": ", 1)[-1]
        d = None
    if d is not None:
        r.our_time = _median_time(lambda: read_bytes(data, name), reps)
        r.our_paths, r.our_points = len(d.paths), d.n_points
    if ezhpgl is None:
        return r
    doc, mode, refusal = _parse_theirs(data)
    r.their_mode, r.their_refusal = mode, refusal
    if mode == "strict":
        r.their_time = _median_time(lambda: ezhpgl.parse(data), reps)
    elif mode == "strict+extents":
        prof = ezhpgl.DeviceProfile(plot_size_mm=FALLBACK_PROFILE_MM)
        r.their_time = _median_time(lambda: ezhpgl.parse(data, profile=prof), reps)
    else:
        prof = (
            ezhpgl.DeviceProfile(plot_size_mm=FALLBACK_PROFILE_MM)
            if refusal == ("MISSING_DEVICE_BOUNDS")
            else None
        )
        r.their_time = _median_time(lambda: ezhpgl.parse(data, strict=False, profile=prof), reps)
    t = their_paths(doc)
    r.their_paths, r.their_points = len(t.paths), sum(len(p) for p in t.paths)
    r.their_labels, r.their_hatch = t.labels, t.hatch_lines
    r.their_closed = t.closed_by_us
    if d is None:
        return r
    ours = [_dedup(p.points) for p in d.paths]
    theirs = [_dedup(p) for p in t.paths]
    pairs, um_o, um_t = match_paths(ours, theirs)
    r.matched = len(pairs)
    # a global translation (default P1/P2, RO origin): try the shift that maps most of our
    # path starts onto theirs, when absolute matching leaves paths over
    if um_o and theirs and ours:
        cand = collections.Counter()
        ts = np.array([q[0] for q in theirs])
        for p in ours[:200]:
            for q0 in ts[:200]:
                cand[tuple(np.round(q0 - p[0], 1))] += 1
        (sx, sy), _ = cand.most_common(1)[0]
        if (sx, sy) != (0.0, 0.0):
            p2, o2, t2 = match_paths(ours, theirs, (sx, sy))
            if len(p2) > len(pairs):
                r.matched_shift, r.shift = len(p2), (float(sx), float(sy))
                pairs, um_o, um_t = p2, o2, t2
    oc = _our_cmds(data, d)
    seen: dict[bytes, int] = {}
    for j, q in enumerate(theirs):
        seen.setdefault(np.round(q * 2).astype(np.int64).tobytes(), j)
    r.their_dups = sum(
        1 for j in um_t if seen[np.round(theirs[j] * 2).astype(np.int64).tobytes()] != j
    )
    r.their_beyond_clip = sum(1 for j in um_t if t.beyond_clip[j])
    r.um_ours_by_cmd = collections.Counter(oc[i] for i in um_o)
    r.um_theirs_by_cmd = collections.Counter(t.cmds[j] for j in um_t)
    if um_o:
        sx, sy = r.shift
        pts = np.concatenate([ours[i] for i in um_o]) + (sx, sy)
        hit = near_lines(pts, theirs)
        sizes = [len(ours[i]) for i in um_o]
        pos = np.cumsum([0] + sizes)
        r.on_lines = sum(1 for k in range(len(um_o)) if hit[pos[k] : pos[k + 1]].all())
    for i in um_o[:n_examples]:
        p = d.paths[i]
        q = ours[i]
        r.examples.append(
            f"ours #{i} ({oc[i]} at {p.start}, {len(q)} pts): {np.round(q[:4], 2).tolist()}"
        )
    for j in um_t[:n_examples]:
        q = theirs[j]
        r.examples.append(f"theirs #{j} ({t.cmds[j]}, {len(q)} pts): {np.round(q[:4], 2).tolist()}")
    return r


def corpus_files() -> list[str]:
    files = sorted(glob.glob(os.path.join(CORPUS, "*")))
    return [f for f in files if os.path.isfile(f) and "__expected" not in os.path.basename(f)]


# -------------------------------------------------------------------------------- report
def _fmt_t(s: float) -> str:
    return "—" if s != s else f"{s * 1e3:.2f}"


def _top(c: collections.Counter, n: int = 3) -> str:
    return ", ".join(f"{k}×{v}" for k, v in c.most_common(n)) or ""


def report(machine, speed, speed_bytes, n_points, runs, corpus, reps) -> str:
    L = []
    L.append(
        f"Date: {BENCH_DATE} (run {_dt.datetime.now().isoformat(timespec='seconds')}). "
        f"Command: `bash bench/run_parse.sh`."
    )
    L.append("")
    L.append(
        f"Machine: {machine['nproc']} cores (nproc), {machine['cpu']}, Python "
        f"{machine['python']}, numpy {machine['numpy']}, ezhpgl {machine['ezhpgl']} "
        f"(load average at the start: {machine['load']}; other work shares this machine)."
    )
    L.append("")
    if speed:
        L.append("### (a) Speed: 1,000,000-point PLT")
        L.append("")
        L.append(
            f"`bench/gen_plt.py` {n_points:,} points, seed 0, {speed_bytes:,} bytes, parsed "
            f"from memory. Cold = first call in the process (after import); then {runs} "
            f"runs (the cold one is the warm-up); median reported. Mpts/s = "
            f"{n_points:,} points / time. CPU s = this process's CPU time for the same runs "
            f"(less disturbed by other jobs on the machine than wall time). Load average "
            f"after this part: {machine.get('load_after_speed', '?')}."
        )
        L.append("")
        L.append(
            "| parser | paths | points out | cold s | cold Mpts/s | median s | "
            "median Mpts/s | min / max s | median CPU s | Mpts/CPU-s |"
        )
        L.append("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
        for s in speed:
            L.append(s.row())
        L.append("")
        ours = speed[0]
        if ours.fresh:
            fr = [f["first"] for f in ours.fresh]
            im = [f["import"] for f in ours.fresh]
            L.append(
                f"Cold in a new process (`galvo_core.hpgl` imported, file read, then the "
                f"first `read_bytes` call), {len(fr)} new processes: "
                f"{', '.join(f'{x:.3f}' for x in fr)} s (median "
                f"{n_points / statistics.median(fr):,.0f} points/s); the import itself "
                f"took {statistics.median(im) * 1e3:.0f} ms (median)."
            )
            L.append("")
        ok = n_points / ours.median >= 1e6
        cpu_rate = n_points / statistics.median(ours.cpu)
        L.append(
            f"Target ≥ 1,000,000 points/s (wall-clock median): **{'met' if ok else 'NOT met'}** "
            f"in this run ({n_points / ours.median:,.0f} points/s; best run "
            f"{n_points / min(ours.runs):,.0f}). Per CPU second: {cpu_rate:,.0f} points/s. "
            f"The machine has {machine['nproc']} cores and the load average was "
            f"{machine['load']} at the start, so the wall time includes time spent waiting for "
            "a core: rerun on a quiet machine before reading the wall-clock numbers as the "
            "parser's speed."
        )
        L.append("")
    if corpus:
        L.append("### (b) Corpus comparison with ezhpgl")
        L.append("")
        L.append(_method_text(reps))
        L.append("")
        L.append(
            "| file | bytes | ours paths / pts | ours ms | ezhpgl mode | ezhpgl paths / pts "
            "| ezhpgl ms | their labels / hatch | agree | unmatched ours: by cmd; on their "
            "lines | unmatched theirs: by cmd; dup; beyond IW |"
        )
        L.append("| --- | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | --- | --- |")
        for r in corpus:
            short = r.name.replace("__", "/", 1)
            if len(short) > 48:
                short = short[:45] + "..."
            theirs = (
                f"| {r.their_mode} | {r.their_paths:,} / {r.their_points:,} | "
                f"{_fmt_t(r.their_time)} | {r.their_labels} / {r.their_hatch} |"
            )
            if r.our_error:
                L.append(f"| {short} | {r.size:,} | refused | {_fmt_t(r.our_time)} {theirs} | | |")
                continue
            if r.our_paths:
                agree = f"{r.best:,}/{r.our_paths:,} ({100.0 * r.best / r.our_paths:.0f} %)"
            else:
                agree = "—"
            if r.matched_shift > r.matched:
                agree += f" shift {r.shift[0]:g},{r.shift[1]:g}"
            um_o = r.our_paths - r.best
            um_t = r.their_paths - r.best
            o_note = f"{_top(r.um_ours_by_cmd)}; {r.on_lines}/{um_o}" if um_o else ""
            t_note = (
                f"{_top(r.um_theirs_by_cmd)}; {r.their_dups}; {r.their_beyond_clip}" if um_t else ""
            )
            L.append(
                f"| {short} | {r.size:,} | {r.our_paths:,} / {r.our_points:,} | "
                f"{_fmt_t(r.our_time)} {theirs} {agree} | {o_note} | {t_note} |"
            )
        L.append("")
        L.append(_summary(corpus))
    return "\n".join(L) + "\n"


def _method_text(reps: int) -> str:
    return (
        "Each file (every file in the corpus except `__expected` ones) is read into memory and "
        "parsed by both in this one process. Times: median of "
        f"{reps} calls after one untimed call. ezhpgl is called as a user would: "
        "`ezhpgl.parse(data)` (strict); when it refuses with MISSING_DEVICE_BOUNDS (SC without "
        "IP, RO, IR need plot extents in its generic profile) it is called again with "
        f"`DeviceProfile(plot_size_mm={FALLBACK_PROFILE_MM})` (the 10000 x 7200-unit field our "
        "reader assumes); on any other refusal `strict=False`, which returns the valid prefix "
        "up to the first command it is unsure of (mode `prefix (CODE)`). Its geometry (mm, "
        "Y up) is converted back to plotter units (x 40); operations sharing a `path_id` are "
        "joined into one pen-down path, each polygon contour (EA/RA/WG/EW/EP/FP) gives one path "
        "per run of pen-down edges; labels (glyph boxes, not strokes) and hatch lines are "
        "counted, not compared. Pages are overlaid on both sides.\n\n"
        "Matching rule: both sides' paths have consecutive duplicate points removed; our path "
        "*agrees* with one of theirs when both have the same number of points and every point "
        "is within 0.5 plotter units of the corresponding point, in the same or reversed order, "
        "or (for closed rings, first = last) from any starting vertex in either direction. "
        "Matching is one-to-one, in our file order, in two passes: exact partners first "
        "(within 0.001 unit), then within 0.5 unit, each time taking the candidate with the "
        "smallest deviation (hatching 0.1 unit apart must not steal partners). The one "
        "normalisation on their side: the edge that closes an open polygon at PM1/PM2, which "
        "ezhpgl stores pen-up, is counted as drawn (class 8 below). When paths remain "
        "unmatched, a global translation (the most common offset between path starts) is also "
        "tried and kept if it matches more (`shift x,y`: a different origin, not different "
        "shapes). *agree* = matched / our paths. Unmatched ours: the command each came from "
        "(the mnemonic at the path's source position), then how many have every vertex within "
        "0.5 units of one of their segments (same strokes, cut or clipped differently). "
        "Unmatched theirs: source command, how many duplicate another of their paths (EP after "
        "FP), how many reach outside their clip window (IW, or the assumed extents)."
    )


def _summary(corpus: list[FileResult]) -> str:
    both = [r for r in corpus if not r.our_error and r.their_mode]
    strict = [r for r in both if r.their_mode.startswith("strict")]
    full = [
        r for r in strict if r.our_paths and r.best == r.our_paths and r.their_paths == r.our_paths
    ]
    op = sum(r.our_paths for r in strict)
    mp = sum(r.best for r in strict)
    refused_ours = [r.name for r in corpus if r.our_error]
    refused_theirs = [r for r in corpus if r.their_mode.startswith("prefix")]
    codes = collections.Counter(r.their_mode[8:-1] for r in refused_theirs)
    extents = sum(1 for r in strict if r.their_mode == "strict+extents")
    empty_theirs = [r for r in strict if r.their_paths == 0 and r.our_paths]
    op2 = op - sum(r.our_paths for r in empty_theirs)
    shifted = [r for r in strict if r.matched_shift > r.matched]
    big = [r for r in strict if r.our_points >= 50_000 and r.their_points]
    big_txt = ""
    if big:
        big_txt = (
            "Rates on the corpus files of 50,000 points or more (points / median time): "
            + "; ".join(
                f"{r.name.split('__')[-1]} ours {r.our_points / r.our_time / 1e6:.2f}, ezhpgl "
                f"{r.their_points / r.their_time / 1e6:.2f} Mpts/s"
                for r in big
            )
            + ". "
        )
    n_shift = sum(r.matched_shift for r in shifted)
    tot_o = sum(r.our_time for r in strict if r.our_time == r.our_time)
    tot_t = sum(r.their_time for r in strict if r.their_time == r.their_time)
    return (
        f"Summary: {len(corpus)} files. We refuse {len(refused_ours)} "
        f"({', '.join(refused_ours) or 'none'}). ezhpgl parses {len(strict)} files in strict "
        f"mode ({extents} of them only once given plot extents) and refuses "
        f"{len(refused_theirs)} ({_top(codes, 20)}; for those its tolerant prefix is "
        "compared, not counted below). On the files it parses, "
        f"{mp:,} of our {op:,} paths agree ({100.0 * mp / max(op, 1):.1f} %); {len(full)} files "
        f"agree path for path. On {len(empty_theirs)} of those files ezhpgl draws nothing at all "
        f"(no pen selected: no SP, or SP0; {sum(r.our_paths for r in empty_theirs):,} of our "
        f"paths); without them {mp:,} of {op2:,} paths agree ({100.0 * mp / max(op2, 1):.1f} %), "
        f"{n_shift:,} of them (in {len(shifted)} files) only after a global translation. "
        f"{big_txt}"
        f"Summed parse time over the {len(strict)} files ezhpgl parses in strict mode: ours "
        f"{tot_o * 1e3:.0f} ms, ezhpgl {tot_t * 1e3:.0f} ms."
    )


def write_section(path: str, body: str) -> None:
    replace_section(SECTION, SECTION + "\n\n" + body, path)


# ------------------------------------------------------------ issue 20: ratios per file
RATIO_SECTION = "## Import speed and memory against ezhpgl (issue 20)"
RATIO_MIN_BYTES = 100_000
RATIO_GEN_POINTS = (100_000, 1_000_000, 5_000_000)

_MEM = r"""
import json, sys
sys.path.insert(0, sys.argv[1])
which, path = sys.argv[2], sys.argv[3]
data = open(path, "rb").read()
if which == "ours":
    import galvo_core.hpgl.scan  # noqa: F401  (numba loaded: the compiled scanner, as timed)
    from galvo_core.hpgl import read_bytes
    # warm-up through every compiled path (scanner, PE in it and the PE decoder the general
    # reader calls for a PE it warns about, IW clipping) and the general reader
    read_bytes(b"IN;SP1;PU0,0;PD10,10;PE;PE:;LBa\x03PM0;PD1,1;PM2;EP;CI5;IW0,0,5,5;PD9,9;"
               b"PU;", "warm.plt")
    def parse(b):
        return read_bytes(b, "f.plt")
else:
    import ezhpgl
    lim = ezhpgl.Limits(max_input_bytes=1 << 30, max_commands=1 << 26)
    glim = ezhpgl.GeometryLimits(max_operations=1 << 26, max_vertices=1 << 26)
    strict = sys.argv[4] == "strict"
    ezhpgl.parse(b"IN;SP1;PU0,0;PD10,10;", limits=lim, geometry_limits=glim)
    def parse(b):
        return ezhpgl.parse(b, strict=strict, limits=lim, geometry_limits=glim)
import gc
import re
def status():
    with open("/proc/self/status") as f:
        text = f.read()
    return {k: int(re.search(k + r":\s+(\d+)", text).group(1)) for k in ("VmHWM", "VmRSS")}
gc.collect()
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")  # reset the peak RSS (VmHWM) to the current RSS
before = status()["VmRSS"]
out = parse(data)
after = status()["VmHWM"]
print(json.dumps({"extra_kb": after - before, "bytes": len(data)}))
"""


def _peak_extra(which: str, path: str, strict: bool) -> float:
    """Peak memory a parse adds, per input byte: the peak RSS during the call (VmHWM, reset
    with /proc/self/clear_refs just before) minus the RSS before it, in a new process with
    the file's bytes already read and the parser warmed up (Linux)."""
    import json
    import subprocess

    res = subprocess.run(
        [sys.executable, "-c", _MEM, REPO, which, path, "strict" if strict else "lenient"],
        capture_output=True, text=True, check=True,
    )
    d = json.loads(res.stdout)
    return d["extra_kb"] * 1024.0 / d["bytes"]


def _cpu_median(fn, data: bytes, reps: int) -> float:
    fn(data)  # warm-up (numba's compiled scanner loaded, caches filled)
    ts = []
    for _ in range(reps):
        c0 = time.process_time()
        fn(data)
        ts.append(time.process_time() - c0)
    return statistics.median(ts)


def bench_ratios(reps: int) -> tuple[list[dict], dict[str, str]]:
    """CPU time (median of ``reps`` after a warm-up, both parsers in this process) and peak
    extra memory (new processes) per corpus file over 100 kB and per generated file."""
    import galvo_core.hpgl.scan  # noqa: F401  (the compiled scanner, as in the workstation)

    if ezhpgl is None:
        raise SystemExit("--ratios needs ezhpgl (bash bench/run_parse.sh installs it)")
    lim = ezhpgl.Limits(max_input_bytes=1 << 30, max_commands=1 << 26)
    glim = ezhpgl.GeometryLimits(max_operations=1 << 26, max_vertices=1 << 26)
    items: list[tuple[str, str]] = [
        (os.path.basename(p), p) for p in corpus_files() if os.path.getsize(p) > RATIO_MIN_BYTES
    ]
    gen = _load_gen_plt()
    os.makedirs(os.path.join(HERE, "out"), exist_ok=True)
    for n in RATIO_GEN_POINTS:
        path = os.path.join(HERE, "out", f"gen_{n}.plt")
        if not os.path.exists(path):
            with open(path, "wb") as f:
                f.write(gen.generate_plt(n, 0))
        items.append((f"gen_plt {n:,} points", path))
    rows = []
    for name, path in items:
        with open(path, "rb") as f:
            data = f.read()
        try:
            read_bytes(data, name)
            ours_ok = True
        except InputError:
            ours_ok = False
        strict = True
        try:
            ezhpgl.parse(data, limits=lim, geometry_limits=glim)
        except Exception:  # noqa: BLE001 - refused in strict mode: lenient, marked
            strict = False
        if not ours_ok:
            continue
        t_ours = _cpu_median(lambda b: read_bytes(b, "f.plt"), data, reps)
        t_theirs = _cpu_median(
            lambda b, st=strict: ezhpgl.parse(b, strict=st, limits=lim, geometry_limits=glim),
            data, reps)
        m_ours = _peak_extra("ours", path, strict)
        m_theirs = _peak_extra("theirs", path, strict)
        row = {"name": name, "bytes": len(data), "strict": strict, "ours": t_ours,
               "theirs": t_theirs, "mem_ours": m_ours, "mem_theirs": m_theirs}
        rows.append(row)
        print(f"{name}: {len(data):,} B ours {t_ours * 1e3:.2f} ms ezhpgl"
              f"{'' if strict else ' (lenient, partial)'} {t_theirs * 1e3:.2f} ms ratio "
              f"{t_ours / t_theirs:.2f} | extra memory B/B ours {m_ours:.2f} "
              f"ezhpgl {m_theirs:.2f}", flush=True)
    return rows, machine_info()


def ratio_report(rows: list[dict], machine: dict[str, str], reps: int) -> str:
    strict = [r for r in rows if r["strict"]]
    worst = max((r["ours"] / r["theirs"] for r in strict), default=float("nan"))
    worst_mem = max((r["mem_ours"] for r in rows), default=float("nan"))
    lines = [
        f"Command: `bash bench/run_parse.sh --ratios` (bench/bench_parse.py --ratios, "
        f"{reps} timed calls per parser and file; any Python with ezhpgl, numpy and numba "
        f"runs it, e.g. the project's .venv with the test extra). "
        f"Date {_dt.date.today().isoformat()}; "
        f"machine: {machine['nproc']} cores, {machine['cpu']}, Python {machine['python']}, "
        f"numpy {machine['numpy']}, ezhpgl {machine['ezhpgl']}; the machine was loaded "
        f"(other sessions; load average at the end {machine['load']}), so CPU time, not wall "
        "time, is compared.",
        "",
        "Method: both parsers in one process on the same bytes (already in memory): one "
        "warm-up call each (our compiled scanner loaded, as in the workstation), then the "
        f"median CPU time (`time.process_time`) of {reps} calls. ezhpgl in strict mode; on "
        "files it refuses strictly it runs in lenient mode, which stops or skips at what it "
        "refuses (\"partial\"): those rows are listed but their ratio compares unequal work. "
        "Memory: the peak RSS a parse adds (VmHWM after the call, reset through "
        "/proc/self/clear_refs just before it, minus VmRSS before it; a new process with the "
        "file already read and the parser warmed up), per input byte; the result (paths, "
        "positions, ezhpgl's document) is part of it.",
        "",
        "| file | bytes | ours ms | ezhpgl ms | time ratio | ours extra B/B | ezhpgl extra B/B |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        mode = "" if r["strict"] else " (lenient, partial)"
        lines.append(
            f"| {r['name']} | {r['bytes']:,} | {r['ours'] * 1e3:.2f} | "
            f"{r['theirs'] * 1e3:.2f}{mode} | {r['ours'] / r['theirs']:.2f} | "
            f"{r['mem_ours']:.2f} | {r['mem_theirs']:.2f} |")
    lines += [
        "",
        f"Worst time ratio over the files ezhpgl reads strictly: {worst:.2f}. "
        f"Largest extra memory per input byte (ours): {worst_mem:.2f}.",
    ]
    return "\n".join(lines) + "\n"


STARTUP_SECTION = "## CLI start-up (issue 20)"


def bench_startup(runs: int) -> str:
    """CPU and wall time of ``galvo-core --help`` and ``galvo-core info`` on a small sample,
    each in a new process (warm: bytecode and numba caches written by a first, untimed run)."""
    import resource
    import subprocess

    sample = os.path.join(REPO, "resources", "samples", "arcs_circles.plt")
    env = dict(os.environ, PYTHONPATH=REPO)
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # a real install has its bytecode cached
    cases = [("--help", ["--help"]), ("info arcs_circles.plt (1 kB)", ["info", sample])]
    big = os.path.join(HERE, "out", "gen_100000.plt")
    if os.path.exists(big):
        cases.append(("info gen_plt 100,000 points (1.1 MB)", ["info", big]))
    rows = []
    for label, args in cases:
        cmd = [sys.executable, "-m", "galvo_core.cli", *args]
        subprocess.run(cmd, env=env, capture_output=True, check=False)  # warm the caches
        cpu, wall = [], []
        for _ in range(runs):
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run(cmd, env=env, capture_output=True, check=False)
            wall.append(time.perf_counter() - t0)
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
        rows.append(f"| `galvo-core {label}` | {statistics.median(cpu):.3f} | "
                    f"{min(cpu):.3f} | {statistics.median(wall):.3f} |")
        print(rows[-1], flush=True)
    m = machine_info()
    return "\n".join([
        f"Command: `python bench/bench_parse.py --startup` ({runs} runs each, new processes "
        f"after one untimed run that writes the bytecode and numba caches). Date "
        f"{_dt.date.today().isoformat()}; {m['nproc']} cores, {m['cpu']}, Python "
        f"{m['python']}; the machine was loaded (load average {m['load']}): the CPU time "
        "(user + system of the child) is the number to compare, wall time is shown too.",
        "",
        "| command | CPU s (median) | CPU s (min) | wall s (median) |",
        "| --- | ---: | ---: | ---: |",
        *rows,
        "",
        "`info` and `--help` import neither the pipeline (numba, which pulls in scipy; "
        "shapely) nor the compiled scanner for a small file; before issue 20 `info` on the "
        "same sample took 0.33-0.38 s CPU (0.39 s warm in the issue).",
    ]) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=7, help="timed runs after the cold one (>= 5)")
    ap.add_argument("--reps", type=int, default=5, help="timed calls per corpus file")
    ap.add_argument("--speed-only", action="store_true")
    ap.add_argument("--corpus-only", action="store_true")
    ap.add_argument("--examples", type=int, default=0, help="print N unmatched paths per file")
    ap.add_argument(
        "--wait-quiet",
        type=float,
        default=0.0,
        metavar="S",
        help="before timing, wait up to S seconds for the 1-minute load to fall below nproc/2",
    )
    ap.add_argument("--write", metavar="RESULTS.md", help="replace our section in this file")
    ap.add_argument("--ratios", action="store_true",
                    help="issue 20: time and memory ratios to ezhpgl per file (own section)")
    ap.add_argument("--startup", action="store_true",
                    help="issue 20: start-up time of galvo-core --help / info (own section)")
    a = ap.parse_args(argv)
    if a.startup:
        body = bench_startup(max(a.runs, 5))
        print(body)
        if a.write:
            replace_section(STARTUP_SECTION, STARTUP_SECTION + "\n\n" + body, a.write)
            print("wrote", a.write)
        return 0
    if a.ratios:
        rows, machine = bench_ratios(a.reps)
        body = ratio_report(rows, machine, a.reps)
        print(body)
        if a.write:
            replace_section(RATIO_SECTION, RATIO_SECTION + "\n\n" + body, a.write)
            print("wrote", a.write)
        return 0
    if a.runs < 5:
        ap.error("--runs must be at least 5")
    deadline = time.monotonic() + a.wait_quiet
    while os.getloadavg()[0] >= (os.cpu_count() or 1) / 2 and time.monotonic() < deadline:
        time.sleep(5)
    machine = machine_info()
    print("machine:", machine, flush=True)
    speed, nbytes = [], 0
    if not a.corpus_only:
        speed, nbytes = bench_speed(a.points, a.runs, peers=True)
        machine["load_after_speed"] = " ".join(f"{x:.2f}" for x in os.getloadavg())
        for s in speed:
            if s.fresh:
                print("fresh-process cold:", s.fresh)
            print(
                f"speed {s.name}: cold {s.cold:.3f}s median {s.median:.3f}s "
                f"cpu {[round(x, 3) for x in s.cpu]} "
                f"({a.points / s.median:,.0f} pts/s) runs {[round(x, 3) for x in s.runs]} "
                f"-> {s.out_paths} paths {s.out_points} points {s.note}",
                flush=True,
            )
    corpus = []
    if not a.speed_only:
        for path in corpus_files():
            r = compare_file(path, a.reps, a.examples)
            corpus.append(r)
            print(
                f"{r.name}: ours {r.our_error or f'{r.our_paths}p/{r.our_points}'} "
                f"{_fmt_t(r.our_time)}ms | ezhpgl {r.their_mode} {r.their_paths}p/"
                f"{r.their_points} {_fmt_t(r.their_time)}ms lbl={r.their_labels} "
                f"| matched {r.matched} shift {r.matched_shift}@{r.shift} "
                f"on_lines {r.on_lines} | um ours {_top(r.um_ours_by_cmd, 4)} "
                f"| um theirs {_top(r.um_theirs_by_cmd, 4)} dup {r.their_dups} "
                f"beyondclip {r.their_beyond_clip} closed {r.their_closed}",
                flush=True,
            )
            for e in r.examples:
                print("    ", e)
        print(_summary(corpus))
    body = report(machine, speed, nbytes, a.points, a.runs, corpus, a.reps)
    if corpus:
        body += "\n" + EXPLANATION
    if a.write:
        write_section(a.write, body)
        print("wrote", a.write)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
