"""Helpers for bench/bench_precision_peers.py (issue 16): corners, corner-to-corner runs,
the precision-aware peers (Potrace CLI, FontForge's simplify, Inkscape's path simplify) run
as separate programs, an SVG path reader, distances.

Corners, the same for every peer that is handed runs:
* typeface outlines: the typeface's own on-curve points where the outline turns by more than
  ``FONT_CORNER_DEG`` (the tangents of the two segments that meet there; DejaVu's joints are
  either under 5 degrees, smooth points written in whole font units, or over 10 degrees);
* corpus paths (no typeface): the turn-angle rule :func:`turn_corners`.

The peers are system programs (Debian packages ``potrace``, ``python3-fontforge``,
``inkscape``, installed by bench/run_fit.sh), never project dependencies.
"""

from __future__ import annotations

import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
sys.path.insert(0, HERE)

from fonts import TEXT, contours, dense, font_file, glyph_set  # noqa: E402

from galvo_core.geometry import flatten_cubic, point_polyline_distance  # noqa: E402

FONT_CORNER_DEG = 7.0
#: turn-angle rule for paths without a typeface: turn over +-L arc length > this
TURN_CORNER_DEG = 45.0
#: ... and, next to an edge at least the reach long, an edge turn over this
EDGE_CORNER_DEG = 30.0
SYSTEM_PY = "/usr/bin/python3"
INKSCAPE_TIMEOUT = 120.0  # Debian's python, where python3-fontforge lives


def child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


# --- typeface outlines with their corners ----------------------------------------------


@dataclass
class FontCase:
    """One style, whole-unit or exact: bench_precision's glyph set plus per contour the
    indices of its corner points (into its points) and the glyph it belongs to."""

    style: str
    whole: bool
    points: list[np.ndarray]
    truth: list[np.ndarray]
    own_segments: int
    corners: list[np.ndarray]
    glyph: list[int]


def _tangents(seg) -> tuple[np.ndarray, np.ndarray]:
    """Start and end tangents of a ("line" | "quad" | "cubic", p0, ..., p1) segment (a
    control point on its end: the next one)."""
    if seg[0] == "line":
        d = seg[2] - seg[1]
        return d, d
    pts = seg[1:]
    t0 = next((q - pts[0] for q in pts[1:] if np.any(q != pts[0])), pts[-1] - pts[0])
    t1 = next((pts[-1] - q for q in pts[-2::-1] if np.any(q != pts[-1])), pts[-1] - pts[0])
    return t0, t1


def _turn_deg(a: np.ndarray, b: np.ndarray) -> float:
    if not np.any(a) or not np.any(b):
        return 180.0
    return math.degrees(abs(math.atan2(a[0] * b[1] - a[1] * b[0], float(a @ b))))


def font_case(style: str, whole: bool, em: float = 1000.0, chord: float = 0.002,
              text: str = TEXT) -> FontCase:
    """``style``: a name of fonts.STYLES or fonts.HELDOUT, or a TTF/OTF path."""
    gs = glyph_set(style, em=em, whole=whole, chord=chord, text=text)
    f = font_file(style)
    cs = contours(f, text, em)
    glyph: list[int] = []
    for k, ch in enumerate(text):
        glyph += [k] * len(contours(f, ch, em))
    if len(glyph) != len(cs) or len(cs) != len(gs.points):
        raise RuntimeError("fonts.py changed: contours do not match glyph_set")
    corners = []
    for segs, pts in zip(cs, gs.points, strict=True):
        start = np.cumsum([0] + [len(dense([s], chord)) - 1 for s in segs])
        p = dense(segs, chord)
        idx = np.arange(len(p))
        if whole:
            p = np.round(p)
            keep = np.r_[True, (p[1:] != p[:-1]).any(axis=1)]
            idx = np.cumsum(keep) - 1
            p = p[keep]
        if not np.array_equal(p, pts):
            raise RuntimeError("fonts.py changed: dense points do not match glyph_set")
        c = [int(idx[start[k]]) for k in range(len(segs))
             if _turn_deg(_tangents(segs[k - 1])[1], _tangents(segs[k])[0]) > FONT_CORNER_DEG]
        c = sorted(set(min(i, len(p) - 2) for i in c)) if len(p) > 2 else []
        corners.append(np.array(c, dtype=np.intp))
    return FontCase(gs.style, whole, gs.points, gs.truth, gs.own_segments, corners, glyph)


# --- turn-angle corners (corpus) -----------------------------------------------------------


def turn_corners(p: np.ndarray, closed: bool, reach: float,
                 deg: float = TURN_CORNER_DEG) -> np.ndarray:
    """Corner indices of a polyline: vertices where the direction from the point ``reach``
    (arc length) behind to the vertex and from the vertex to the point ``reach`` ahead turn
    by more than ``deg`` degrees (the largest turn of each cluster of candidates closer than
    ``reach``), and every vertex where the polyline turns by more than ``EDGE_CORNER_DEG``
    next to an edge at least ``reach`` long (a polygon's corners, chamfers included). A
    closed path (last point = first) is taken cyclically."""
    n = len(p)
    if n < 3:
        return np.zeros(0, np.intp)
    if closed:
        core = p[:-1] if np.array_equal(p[0], p[-1]) else p
        m = len(core)
        ext = np.vstack([core, core, core])
        off = m
    else:
        ext, m, off = p, n, 0
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(ext, axis=0).T))]
    i = np.arange(off, off + m)
    b = np.clip(np.searchsorted(s, s[i] - reach, side="right") - 1, 0, len(ext) - 1)
    f = np.clip(np.searchsorted(s, s[i] + reach, side="left"), 0, len(ext) - 1)
    u, v = ext[i] - ext[b], ext[f] - ext[i]
    ang = np.degrees(np.abs(np.arctan2(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0],
                                       (u * v).sum(axis=1))))
    ang[~(u.any(axis=1) & v.any(axis=1))] = 0.0
    # joints of two long edges (a polygon's vertices, not a dense curve's): the edge turn
    e_in, e_out = ext[i] - ext[i - 1], ext[(i + 1) % len(ext)] - ext[i]
    long = (np.hypot(*e_in.T) >= reach) | (np.hypot(*e_out.T) >= reach)
    turn1 = np.degrees(np.abs(np.arctan2(e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0],
                                         (e_in * e_out).sum(axis=1))))
    sharp = np.flatnonzero(long & (turn1 > EDGE_CORNER_DEG))
    cand = np.flatnonzero(ang > deg)
    if not closed:
        cand = cand[(cand > 0) & (cand < n - 1)]
        sharp = sharp[(sharp > 0) & (sharp < n - 1)]
    if not len(cand):
        return sharp.astype(np.intp)
    out = []
    grp = [cand[0]]
    for c in cand[1:]:
        if s[off + c] - s[off + grp[-1]] < reach:
            grp.append(c)
        else:
            out.append(grp[int(np.argmax(ang[grp]))])
            grp = [c]
    out.append(grp[int(np.argmax(ang[grp]))])
    return np.array(sorted(set(out) | set(sharp.tolist())), dtype=np.intp)


def split_runs(p: np.ndarray, corners: np.ndarray, closed: bool) -> tuple[list[np.ndarray], bool]:
    """Corner-to-corner runs of a path (each includes both corners). A closed path whose
    last point equals its first is cut at every corner, the last run wrapping round; with
    no corner it is handed whole (returned flag True: hand it over closed)."""
    if closed:
        core = p[:-1] if len(p) > 1 and np.array_equal(p[0], p[-1]) else p
        if not len(corners):
            return [np.vstack([core, core[:1]])], True
        c = np.asarray(corners) % len(core)
        c = np.unique(c)
        runs = [core[c[k]:c[k + 1] + 1] for k in range(len(c) - 1)]
        runs.append(np.vstack([core[c[-1]:], core[:c[0] + 1]]))
        return [r for r in runs if len(r) >= 2], False
    cuts = [0] + [int(c) for c in corners if 0 < c < len(p) - 1] + [len(p) - 1]
    return [p[cuts[k]:cuts[k + 1] + 1] for k in range(len(cuts) - 1)], False


# --- results as polylines, distances ---------------------------------------------------------


def seg_dense(segs: list[np.ndarray], h: float = 0.002) -> np.ndarray:
    """Segments ((2, 2) lines or (4, 2) cubics) of one path as a dense polyline."""
    parts = [flatten_cubic(np.asarray(s, float), h) if len(s) == 4 else np.asarray(s, float)
             for s in segs]
    return np.vstack([parts[0]] + [q[1:] for q in parts[1:]])


def directed(a: np.ndarray, polys: list[np.ndarray]) -> float:
    """Max over the vertices of ``a`` of the distance to the nearest of ``polys``."""
    d = np.full(len(a), np.inf)
    for q in polys:
        d = np.minimum(d, point_polyline_distance(a, q))
    return float(d.max())


def both_ways(a: np.ndarray, b: np.ndarray) -> float:
    """fonts.curve_distance's measure (each vertex of one polyline to the other polyline,
    the larger of the two maxima) computed by GEOS (for the long corpus paths)."""
    import shapely

    def one(p, q):
        if len(q) < 2:
            return float(np.hypot(*(p - q[0]).T).max())
        return float(shapely.distance(shapely.points(p), shapely.LineString(q)).max())

    return max(one(a, b), one(b, a))


def set_distance(fitted: list[np.ndarray], truth: list[np.ndarray]) -> float:
    """Both-ways distance between two sets of polylines (each vertex of one set to the
    nearest polyline of the other)."""
    if not fitted:
        return math.inf
    return max(max(directed(f, truth) for f in fitted), max(directed(t, fitted) for t in truth))


# --- SVG path data --------------------------------------------------------------------------

_TOK = re.compile(r"[MmLlHhVvCcSsQqTtZzAa]|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def parse_svg_path(d: str) -> list[list[np.ndarray]]:
    """Subpaths of SVG path data as lists of segments: (2, 2) lines and (4, 2) cubics
    (quadratics raised to cubics); ``Z`` adds the closing line when it has length."""
    toks = _TOK.findall(d)
    out: list[list[np.ndarray]] = []
    cur = np.zeros(2)
    start = np.zeros(2)
    last_c = None
    cmd = None
    i = 0
    segs: list[np.ndarray] = []

    def num() -> float:
        nonlocal i
        v = float(toks[i])
        i += 1
        return v

    while i < len(toks):
        if toks[i].isalpha():
            cmd = toks[i]
            i += 1
            if cmd in "Zz":
                if np.any(cur != start):
                    segs.append(np.array([cur, start]))
                if segs:
                    out.append(segs)
                segs = []
                cur = start.copy()
                last_c = None
                continue
        rel = cmd.islower()
        base = cur if rel else np.zeros(2)
        c = cmd.upper()
        if c == "M":
            if segs:
                out.append(segs)
            segs = []
            cur = base + [num(), num()]
            start = cur.copy()
            cmd = "l" if rel else "L"
            last_c = None
        elif c == "L":
            p = base + [num(), num()]
            segs.append(np.array([cur, p]))
            cur = p
            last_c = None
        elif c in "HV":
            v = num()
            p = cur.copy()
            k = 0 if c == "H" else 1
            p[k] = (cur[k] if rel else 0.0) + v
            segs.append(np.array([cur, p]))
            cur = p
            last_c = None
        elif c == "C":
            p1, p2, p3 = (base + [num(), num()] for _ in range(3))
            segs.append(np.array([cur, p1, p2, p3]))
            cur, last_c = p3, p2
        elif c == "S":
            p1 = 2 * cur - last_c if last_c is not None else cur.copy()
            p2, p3 = (base + [num(), num()] for _ in range(2))
            segs.append(np.array([cur, p1, p2, p3]))
            cur, last_c = p3, p2
        elif c == "Q":
            q1, p3 = (base + [num(), num()] for _ in range(2))
            segs.append(np.array([cur, cur + 2 / 3 * (q1 - cur), p3 + 2 / 3 * (q1 - p3), p3]))
            cur, last_c = p3, None
        else:
            raise ValueError(f"SVG path command {cmd!r} not handled")
    if segs:
        out.append(segs)
    return out


# --- Potrace (bitmap tracing) -----------------------------------------------------------------


def rasterize(polys: list[np.ndarray], scale: float, margin: int = 4):
    """Even-odd fill of closed polylines (units) on pixels of 1/``scale`` unit: pixel
    (row from the bottom r, column i) is set when its centre lies inside. Returns the
    bitmap (rows top to bottom), and the unit coordinates of the bitmap's bottom-left."""
    allp = np.vstack(polys)
    x0 = math.floor(allp[:, 0].min()) - margin / scale
    y0 = math.floor(allp[:, 1].min()) - margin / scale
    w = int(math.ceil((allp[:, 0].max() - x0) * scale)) + margin
    h = int(math.ceil((allp[:, 1].max() - y0) * scale)) + margin
    diff = np.zeros((h, w + 1), np.int32)
    for p in polys:
        a, b = p[:-1], p[1:]
        ylo, yhi = np.minimum(a[:, 1], b[:, 1]), np.maximum(a[:, 1], b[:, 1])
        rlo = np.ceil((ylo - y0) * scale - 0.5).astype(np.int64)
        rhi = np.ceil((yhi - y0) * scale - 0.5).astype(np.int64)
        cnt = np.maximum(rhi - rlo, 0)
        e = np.repeat(np.arange(len(a)), cnt)
        r = np.repeat(rlo, cnt) + np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        yc = y0 + (r + 0.5) / scale
        t = (yc - a[e, 1]) / (b[e, 1] - a[e, 1])
        xc = a[e, 0] + t * (b[e, 0] - a[e, 0])
        col = np.clip(np.ceil((xc - x0) * scale - 0.5).astype(np.int64), 0, w)
        np.add.at(diff, (r, col), 1)
    img = (np.cumsum(diff, axis=1)[:, :w] % 2).astype(bool)
    return img[::-1], x0, y0


def write_pbm(path: str, img: np.ndarray) -> None:
    h, w = img.shape
    with open(path, "wb") as f:
        f.write(f"P4\n{w} {h}\n".encode())
        f.write(np.packbits(img, axis=1).tobytes())


POTRACE_UNIT = 100


def potrace_glyph(polys: list[np.ndarray], scale: float, opttol: float = 0.2,
                  tmp: str | None = None) -> tuple[list[list[np.ndarray]], float]:
    """Trace the even-odd fill of ``polys`` with the potrace CLI at ``scale`` px per unit
    (defaults but ``-O opttol`` px); the curves back in units and the CPU seconds of
    potrace itself."""
    img, x0, y0 = rasterize(polys, scale)
    d = tmp or tempfile.mkdtemp()
    pbm, svg = os.path.join(d, "g.pbm"), os.path.join(d, "g.svg")
    write_pbm(pbm, img)
    c0 = child_cpu()
    subprocess.run(["potrace", "-b", "svg", "-u", str(POTRACE_UNIT), "-O", str(opttol),
                    "-o", svg, pbm], check=True)
    secs = child_cpu() - c0
    txt = open(svg).read()
    out = []
    for dd in re.findall(r'<path d="([^"]*)"', txt):
        for sub in parse_svg_path(dd):
            out.append([np.c_[x0 + s[:, 0] / (POTRACE_UNIT * scale),
                              y0 + s[:, 1] / (POTRACE_UNIT * scale)] for s in sub])
    if tmp is None:
        shutil.rmtree(d, ignore_errors=True)
    return out, secs


def potrace_version() -> str:
    r = subprocess.run(["potrace", "--version"], capture_output=True, text=True)
    return r.stdout.split()[1].rstrip(".") if r.returncode == 0 else "missing"


# --- FontForge's simplify (Debian python3-fontforge, run by Debian's python) -----------------

FF_FLAGS = ("mergelines", "ignoreslopes", "ignoreextrema", "smoothcurves")

_FF_SCRIPT = r"""
import json, sys, time
import fontforge
inp = json.load(sys.stdin)
res = []
for tol in inp["tols"]:
    t0 = time.process_time()
    out = []
    for p in inp["paths"]:
        pts = p["points"]
        if len(pts) < 2:
            out.append([]); continue
        c = fontforge.contour()
        c.moveTo(*pts[0])
        for q in pts[1:]:
            c.lineTo(*q)
        if p["closed"]:
            c.closed = True
        layer = fontforge.layer()
        layer += c
        layer.simplify(tol, tuple(inp["flags"]))
        segs = []
        for cc in layer:
            q = list(cc)
            if cc.closed:
                q = q + q[:1]
            k = 0
            while k < len(q) - 1:
                if q[k + 1].on_curve:
                    segs.append([[q[k].x, q[k].y], [q[k + 1].x, q[k + 1].y]]); k += 1
                else:
                    segs.append([[r.x, r.y] for r in q[k:k + 4]]); k += 3
        out.append(segs)
    res.append({"tol": tol, "cpu_s": time.process_time() - t0, "paths": out})
print(json.dumps({"version": fontforge.version(), "results": res}))
"""


def fontforge_simplify(paths: list[tuple[np.ndarray, bool]], tols: list[float],
                       flags=FF_FLAGS) -> dict:
    """FontForge ``layer.simplify(tol, flags)`` of each path (handed as a contour of line
    segments); per tolerance the segments of each path and FontForge's own CPU seconds."""
    inp = json.dumps({"tols": tols, "flags": list(flags),
                      "paths": [{"points": np.asarray(p, float).tolist(), "closed": bool(c)}
                                for p, c in paths]})
    r = subprocess.run([SYSTEM_PY, "-c", _FF_SCRIPT], input=inp, capture_output=True,
                       text=True, check=True)
    out = json.loads(r.stdout)
    for res in out["results"]:
        res["paths"] = [[np.asarray(s, float) for s in segs] for segs in res["paths"]]
    return out


def fontforge_version() -> str:
    r = subprocess.run([SYSTEM_PY, "-c", "import fontforge; print(fontforge.version())"],
                       capture_output=True, text=True)
    return r.stdout.strip() if r.returncode == 0 else "missing"


# --- Inkscape's path simplify (batch, --actions) ---------------------------------------------

_PREFS = """<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<inkscape version="1.2" xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
 xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape">
  <group id="options">
    <group id="simplifythreshold" value="{thr!r}" />
    <group id="simplifyindividualpaths" value="0" />
  </group>
</inkscape>
"""


def _svg_doc(groups: list[list[np.ndarray]], closed: list[bool]) -> tuple[str, float]:
    allp = np.vstack([r for g in groups for r in g])
    lo, hi = allp.min(axis=0) - 1.0, allp.max(axis=0) + 1.0
    w, h = hi - lo
    body = []
    for k, (runs, cl) in enumerate(zip(groups, closed, strict=True)):
        ds = []
        for r in runs:
            s = " ".join(f"{x!r},{y!r}" for x, y in r.tolist())
            ds.append(f"M {s}" + (" Z" if cl and len(runs) == 1 else ""))
        body.append(f'<path id="p{k}" style="fill:none;stroke:none" d="{" ".join(ds)}"/>')
    doc = (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w!r}" height="{h!r}" '
           f'viewBox="{lo[0]!r} {lo[1]!r} {w!r} {h!r}">\n' + "\n".join(body) + "\n</svg>\n")
    return doc, float(np.hypot(*np.ptp(allp, axis=0)))


def inkscape_simplify(groups: list[list[np.ndarray]], closed: list[bool], tol: float):
    """Inkscape ``path-simplify`` of all paths at once (each path: its runs as subpaths;
    a one-run closed path closed with Z); None when it runs over ``INKSCAPE_TIMEOUT``
    seconds (it first resamples every path at the tolerance).
    Inkscape's threshold is relative to the
    selection's bounding-box diagonal: it is set to ``tol`` / diagonal so that the distance
    it works with is ``tol`` units. Returns per path its segments and the CPU seconds of
    the inkscape process (start-up included)."""
    d = tempfile.mkdtemp()
    try:
        doc, diag = _svg_doc(groups, closed)
        src, dst = os.path.join(d, "in.svg"), os.path.join(d, "out.svg")
        open(src, "w").write(doc)
        prof = os.path.join(d, "profile")
        os.makedirs(prof)
        open(os.path.join(prof, "preferences.xml"), "w").write(_PREFS.format(thr=tol / diag))
        env = dict(os.environ, INKSCAPE_PROFILE_DIR=prof, HOME=d)
        env.pop("DISPLAY", None)
        c0 = child_cpu()
        try:
            subprocess.run(["inkscape", src, "--actions",
                            f"select-all:all;path-simplify;export-filename:{dst};"
                            "export-plain-svg;export-do"],
                           check=True, env=env, capture_output=True, timeout=INKSCAPE_TIMEOUT)
        except subprocess.TimeoutExpired:
            return None
        secs = child_cpu() - c0
        txt = open(dst).read()
        out: list[list[np.ndarray]] = [[] for _ in groups]
        for m in re.finditer(r"<path\b[^>]*>", txt):
            tag = m.group(0)
            pid = re.search(r'\bid="p(\d+)"', tag)
            dd = re.search(r'\bd="([^"]*)"', tag)
            if pid and dd:
                out[int(pid.group(1))] = [s for sub in parse_svg_path(dd.group(1)) for s in sub]
        return out, secs
    finally:
        shutil.rmtree(d, ignore_errors=True)


def inkscape_startup() -> float:
    """CPU seconds of an inkscape batch run that does nothing but open a tiny file."""
    d = tempfile.mkdtemp()
    try:
        src = os.path.join(d, "in.svg")
        open(src, "w").write(_svg_doc([[np.array([[0.0, 0.0], [1.0, 1.0]])]], [False])[0])
        env = dict(os.environ, INKSCAPE_PROFILE_DIR=os.path.join(d, "p"), HOME=d)
        env.pop("DISPLAY", None)
        c0 = child_cpu()
        subprocess.run(["inkscape", src, "--actions", "select-all:all"], check=True, env=env,
                       capture_output=True)
        return child_cpu() - c0
    finally:
        shutil.rmtree(d, ignore_errors=True)


def inkscape_version() -> str:
    r = subprocess.run(["inkscape", "--version"], capture_output=True, text=True)
    return r.stdout.split()[1] if r.returncode == 0 and r.stdout else "missing"
