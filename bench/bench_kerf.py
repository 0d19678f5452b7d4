"""Kerf compensation benchmark (issue 6): galvo_core.kerf against an exact reference and
against Clipper2.

Run with ``bash bench/run_kerf.sh`` (it makes bench/.venv-kerf with numpy, shapely,
hypothesis and clipper2-py -- the Clipper2 2.0 bindings; pyclipr has no wheel here -- and
runs this file with the repository on PYTHONPATH). Prints a Markdown section and, with
``--write``, puts it into bench/RESULTS.md under "## Kerf (issue 6)", replacing only
that section.

Measures
* per method and side on the bundled seal and text_outline samples: largest deviation of
  the compensated outline from the exact offset (shapely buffer, 1024 segments per quarter
  circle), area of the symmetric difference, vertex count, time, validity;
* Clipper2 (even-odd union + InflatePaths, round joins, same arc tolerance), timed
  including the conversion from and to numpy arrays, against the same reference;
* acute corners: a 10° spike, distance of the compensated outline from the tip;
* validity over every corpus file with closed paths and over hypothesis polygons with holes.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time
from pathlib import Path as FsPath

import numpy as np
import shapely

ROOT = FsPath(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from results_md import replace_section  # noqa: E402

from galvo_core.drawing import Drawing, Path  # noqa: E402
from galvo_core.errors import GalvoError  # noqa: E402
from galvo_core.field import make_field  # noqa: E402
from galvo_core.hpgl import read_file  # noqa: E402
from galvo_core.kerf import (  # noqa: E402
    compensate_geometry,
    compensate_indexed,
    even_odd_region,
    quad_segs_for,
    reduce_tol_for,
)

try:
    import clipper2
except ImportError:  # pragma: no cover - the bench venv has it
    clipper2 = None

CORPUS = FsPath(os.environ.get("GALVO_CORPUS", ROOT.parent / "shared" / "corpus" / "plt"))
SAMPLES = ROOT / "resources" / "samples"
TRUE_MAG = 65536 / 110.0 / 40.0  # bits per unit at true size
E_PER = 0.02  # paper 000's default e_per, input units
METHODS = ("vector", "raster", "rectangle")


def timed(fn, repeat=3, clock=time.perf_counter):
    """Result and the best of ``repeat`` times by ``clock`` (wall time by default; the
    machine is shared: the minimum is the least noisy estimate)."""
    ts = []
    out = None
    for _ in range(repeat):
        t = clock()
        out = fn()
        ts.append(clock() - t)
    return out, min(ts)


def exact(region, d, side):
    return shapely.buffer(region, d if side == "outside" else -d, quad_segs=1024)


CHUNK = 500_000  # points per nearest-segment query (bounds memory on huge outlines)


def _nearest_dist(tree, pts):
    """Distance from each point (an (N, 2) array) to the nearest geometry in ``tree``,
    queried in chunks."""
    out = np.empty(len(pts))
    for i in range(0, len(pts), CHUNK):
        _, out[i:i + CHUNK] = tree.query_nearest(shapely.points(pts[i:i + CHUNK]),
                                                 return_distance=True, all_matches=False)
    return out


def _one_way(geom, ref, step):
    """Largest distance from the outline of geom (densified to ``step``) to ref's outline."""
    pts = shapely.get_coordinates(shapely.segmentize(geom.boundary, step))
    dist = _nearest_dist(_segment_tree(ref), pts)
    return float(dist.max()) if len(dist) else 0.0


def deviation(geom, ref, step=0.25):
    """Largest distance between the two outlines (symmetric Hausdorff of the outlines,
    densified to ``step`` units), and the area of the symmetric difference."""
    if geom.is_empty and ref.is_empty:
        return 0.0, 0.0
    if geom.is_empty or ref.is_empty:
        return math.inf, max(geom.area, ref.area)
    hd = max(_one_way(geom, ref, step), _one_way(ref, geom, step))
    return hd, float(shapely.symmetric_difference(geom, ref).area)


def _segment_tree(geom):
    rings = [shapely.get_coordinates(r) for r in shapely.get_rings(shapely.get_parts(geom))]
    segs = np.concatenate([np.stack([r[:-1], r[1:]], axis=1) for r in rings])
    return shapely.STRtree(shapely.linestrings(segs))


def offset_error(geom, region, d, step=0.25):
    """Reference-free check of an offset outline: the largest | distance from a point of
    geom's outline (densified to ``step``) to the input region's outline - d |. Every
    point of the exact offset is exactly d from the input's outline; chords of arcs lie
    a sagitta closer."""
    if geom.is_empty or region.is_empty:
        return math.inf if geom.is_empty != region.is_empty else 0.0
    pts = shapely.get_coordinates(shapely.segmentize(geom.boundary, step))
    return float(np.abs(_nearest_dist(_segment_tree(region), pts) - d).max())


def rings_of(drawing: Drawing):
    return [p.points for p in drawing.paths if p.closed and len(p.points) >= 4]


def clipper_offset(rings, d, side, tol):
    """Clipper2: even-odd union (orients rings) then InflatePaths, round joins; numpy in
    and out."""
    u = clipper2.union([r[:-1] for r in rings], clipper2.FillRule.EVEN_ODD, precision=4)
    if len(u) == 0:
        return []
    o = clipper2.inflate_paths(u, d if side == "outside" else -d, clipper2.JoinType.ROUND,
                               clipper2.EndType.POLYGON, precision=4, arc_tolerance=tol)
    return [np.asarray(p) for p in o]


def clipper_geom(paths):
    closed = [np.vstack([p, p[:1]]) for p in paths if len(p) >= 3]
    return even_odd_region(closed) if closed else shapely.Polygon()


def output_region(drawing, pen=None):
    rings = [p.points for p in drawing.paths if p.closed and len(p.points) >= 4
             and (pen is None or p.pen == pen)]
    return even_odd_region(rings) if rings else shapely.Polygon()


# --------------------------------------------------------------------------- sections
def sample_table(lines, name, kerf_mm, mag=TRUE_MAG, arc_bits=1.0):
    dr = read_file(SAMPLES / name)
    fm = make_field(dr.bbox(), magnification=mag)
    d = fm.mm_to_units(kerf_mm / 2)
    tol = fm.bits_to_units(arc_bits)
    region = even_odd_region(rings_of(dr))
    lines.append(f"\n**{name}** ({len(dr.paths)} paths, {dr.n_points} points), kerf {kerf_mm} "
                 f"mm -> d = {d:.3f} units ({kerf_mm / 2 * 1000:.0f} µm), magnification "
                 f"{mag:.3f}, arc tolerance {arc_bits:g} bit = {tol:.4f} units "
                 f"(vector: GEOS quad_segs {quad_segs_for(d, tol)}, then thinned within "
                 f"{reduce_tol_for(d, tol):.4f} units); target deviation <= arc tol + e_per "
                 f"= {tol + E_PER:.4f} units\n")
    lines.append("| method | side | max dev (units) | max dev (µm) | offset error (units) "
                 "| sym. diff area (units²) | vertices | time (ms) | valid |")
    lines.append("|---|---|---|---|---|---|---|---|---|")
    cross = []
    res = {}
    for side in ("outside", "inside"):
        ref = exact(region, d, side)
        for m in METHODS:
            (out, origin), t = timed(lambda m=m, side=side: compensate_indexed(
                dr, kerf_mm=kerf_mm, side=side, method=m, fm=fm, arc_tol_bits=arc_bits),
                repeat=7 if m == "vector" else 2)
            geom = output_region(out)
            internal = compensate_geometry(region, d, side=side, method=m, tol=tol,
                                           res=fm.bits_to_units(1.0))
            valid = bool(internal.is_valid) and bool(geom.is_valid)
            dev, sd = deviation(geom, ref)
            err = offset_error(geom, region, d)
            nv = sum(len(p.points) - 1 for p in out.paths if p.closed)
            res[(m, side)] = (dev, t, nv)
            lines.append(f"| {m} | {side} | {dev:.4f} | {dev * fm.mm_per_unit * 1000:.2f} | "
                         f"{err:.4f} | {sd:.2f} | {nv} | {t * 1000:.1f} | {valid} |")
        if clipper2 is not None:
            paths, t = timed(lambda side=side: clipper_offset(rings_of(dr), d, side, tol), 7)
            geom = clipper_geom(paths)
            dev, sd = deviation(geom, ref)
            err = offset_error(geom, region, d)
            nv = sum(len(p) for p in paths)
            res[("clipper2", side)] = (dev, t, nv)
            lines.append(f"| Clipper2 {clipper2.CLIPPER2_VERSION} | {side} | {dev:.4f} | "
                         f"{dev * fm.mm_per_unit * 1000:.2f} | {err:.4f} | {sd:.2f} | {nv} | "
                         f"{t * 1000:.1f} | {bool(geom.is_valid)} |")
            fine = clipper_geom(clipper_offset(rings_of(dr), d, side, tol / 100))
            cross.append(f"{side} {deviation(fine, ref)[0]:.4f}")
    if cross:
        lines.append("\nReference cross-check: Clipper2 at arc tolerance tol/100 (no input "
                     "simplification) vs the GEOS reference, max distance (units): "
                     + ", ".join(cross))
    if clipper2 is not None:
        for side in ("outside", "inside"):
            v, c = res[("vector", side)], res[("clipper2", side)]
            lines.append(f"\nvector/Clipper2 ({side}): vertices x{v[2] / c[2]:.2f} (target <= "
                         f"1.2), time x{v[1] / c[1]:.2f} (target <= 5)")
    return res


def acute_table(lines):
    """A 10° spike: how far the outline gets from the tip (exact: d outside)."""
    L = 400.0
    half = math.radians(5)
    tip = np.array([0.0, 0.0])
    ring = np.array([tip, (L * math.cos(half), L * math.sin(half)),
                     (L * math.cos(half), -L * math.sin(half)), tip])
    dr = Drawing((Path.from_points(ring),), name="spike")
    fm = make_field(dr.bbox(), magnification=TRUE_MAG)
    kerf = 0.2
    d = fm.mm_to_units(kerf / 2)
    mitre = d / math.sin(half)
    lines.append(f"\n**Acute corner**: a 10° spike, kerf {kerf} mm (d = {d:.3f} units); the "
                 f"plain intersection of the moved edges would be {mitre:.2f} units from the "
                 "tip (the paper's distortion)\n")
    lines.append("| method | farthest outline point beyond the tip (units) | / d |")
    lines.append("|---|---|---|")
    for m in METHODS:
        out = compensate_indexed(dr, kerf_mm=kerf, side="outside", method=m, fm=fm)[0]
        pts = out.paths[0].points
        # farthest point in the -x direction (beyond the tip)
        far = float(np.max(np.hypot(*(pts[pts[:, 0] < 0] - tip).T))) if (pts[:, 0] < 0).any() \
            else 0.0
        lines.append(f"| {m} | {far:.3f} | {far / d:.2f} |")


def corpus_drawings():
    """(name, drawing) of every corpus file that reads and has closed paths."""
    out = []
    for f in sorted(p for p in CORPUS.glob("*") if p.is_file()):
        try:
            dr = read_file(f)
        except GalvoError:
            continue
        if dr.n_closed:
            out.append((f.name, dr))
    return out


def pen_rings(dr, pen):
    return [p.points for p in dr.paths if p.closed and p.pen == pen and len(p.points) >= 4]


def vector_checks(name, dr, out, fm, kerf_mm, side, t_ours):
    """One corpus row of the vector method against the exact offset and Clipper2: the
    deviation from the GEOS reference and the reference-free offset error (both in bits),
    vertices and time of ours and of Clipper2 (per pen, summed)."""
    bit = fm.bits_to_units(1.0)
    d = fm.mm_to_units(kerf_mm / 2)
    step = max(0.25, bit / 4)
    row = {"name": name, "side": side, "dev": 0.0, "err": 0.0, "cdev": 0.0, "cerr": 0.0,
           "nv": 0, "nc": 0,
           "t": t_ours, "tc": 0.0}
    row["nv"] = sum(len(p.points) - 1 for p in out.paths if p.closed)
    for pen in sorted({p.pen for p in dr.paths}):
        rings = pen_rings(dr, pen)
        if not rings:
            continue
        reg = even_odd_region(rings)
        g = output_region(out, pen)
        ref = exact(reg, d, side)
        row["dev"] = max(row["dev"], deviation(g, ref, step)[0] / bit)
        row["err"] = max(row["err"], offset_error(g, reg, d, step) / bit)
        if clipper2 is not None:
            paths, tc = timed(lambda rings=rings: clipper_offset(rings, d, side, bit), 1)
            row["nc"] += sum(len(p) for p in paths)
            row["tc"] += tc
            cg = clipper_geom(paths)
            row["cdev"] = max(row["cdev"], deviation(cg, ref, step)[0] / bit)
            row["cerr"] = max(row["cerr"], offset_error(cg, reg, d, step) / bit)
    return row


def corpus_table(lines, kerf_mm=0.1, methods=METHODS):
    lines.append(f"\n**Corpus** ({CORPUS.name}/, fit to the field, kerf {kerf_mm} mm, both "
                 "sides): files with closed paths; validity = GEOS is_valid of the compensated "
                 "region and of the region rebuilt from the output paths\n")
    lines.append("| method | files | rings in | invalid | worst time (s) | total time (s) |")
    lines.append("|---|---|---|---|---|---|")
    drawings = corpus_drawings()
    vec_rows = []
    for m in methods:
        invalid = 0
        worst = 0.0
        total = 0.0
        nr = 0
        bad = []
        for name, dr in drawings:
            fm = make_field(dr.bbox(), magnification=None, fit_field=True)
            x0, y0, x1, y1 = dr.bbox()
            if kerf_mm > max(x1 - x0, y1 - y0) * fm.mm_per_unit:
                continue
            for side in ("outside", "inside"):
                t = time.perf_counter()
                try:
                    out, _ = compensate_indexed(dr, kerf_mm=kerf_mm, side=side, method=m, fm=fm)
                except GalvoError as exc:
                    bad.append(f"{name}: {exc}")
                    continue
                dt = time.perf_counter() - t
                worst = max(worst, dt)
                total += dt
                ok = all(output_region(out, pen).is_valid for pen in {p.pen for p in dr.paths})
                if not ok:
                    invalid += 1
                    bad.append(f"{name} ({side})")
                if m == "vector":
                    vec_rows.append(vector_checks(name, dr, out, fm, kerf_mm, side, dt))
            nr += sum(1 for p in dr.paths if p.closed)
        lines.append(f"| {m} | {len(drawings)} | {nr} | {invalid} | {worst:.2f} | {total:.2f} |")
        for b in bad[:5]:
            lines.append(f"|  | problem: {b} | | | | |")
    if vec_rows:
        vector_corpus_summary(lines, vec_rows)


def vector_corpus_summary(lines, rows):
    """The vector method over the corpus: deviation, vertices and time against Clipper2."""
    worst_dev = max(rows, key=lambda r: r["dev"])
    worst_err = max(rows, key=lambda r: r["err"])
    lines.append(f"\n**Vector method over the corpus** ({len(rows)} file x side runs, 1 bit "
                 "arc tolerance at each file's fit-field magnification):\n")
    lines.append(f"- deviation from the GEOS reference: max {worst_dev['dev']:.3f} bits "
                 f"({worst_dev['name']}, {worst_dev['side']}); reference-free offset error "
                 f"(| distance to the input outline - d |): max {worst_err['err']:.3f} bits "
                 f"({worst_err['name']}, {worst_err['side']})")
    with_c = [r for r in rows if r["nc"] > 0]
    if with_c:
        cd = max(with_c, key=lambda r: r["cdev"])
        ce = max(with_c, key=lambda r: r["cerr"])
        lines.append(f"- Clipper2 at the same arc tolerance, same measures: deviation from the "
                     f"GEOS reference max {cd['cdev']:.3f} bits ({cd['name']}, {cd['side']}); "
                     f"offset error max {ce['cerr']:.3f} bits ({ce['name']}, {ce['side']})")
        ratio = np.array([r["nv"] / r["nc"] for r in with_c])
        k = int(np.argmax(ratio))
        over = [f"{r['name']} ({r['side']}, x{r['nv'] / r['nc']:.2f})" for r in with_c
                if r["nv"] > 1.2 * r["nc"]]
        lines.append(f"- vertices / Clipper2's at the same arc tolerance: median "
                     f"x{np.median(ratio):.2f}, worst x{ratio[k]:.2f} ({with_c[k]['name']}, "
                     f"{with_c[k]['side']}); runs above x1.2: {len(over)}"
                     + (f" ({'; '.join(over[:6])})" if over else ""))
        slow = max(with_c, key=lambda r: r["t"])
        tr = np.array([r["t"] / r["tc"] for r in with_c if r["tc"] > 0])
        lines.append(f"- time / Clipper2's (even-odd union + offset, one run each): median "
                     f"x{np.median(tr):.2f}; slowest file {slow['name']} ({slow['side']}): "
                     f"{slow['t']:.2f} s, Clipper2 {slow['tc']:.2f} s")


def hypothesis_validity(lines, n=300):
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    counts = {m: [0, 0] for m in METHODS}

    @st.composite
    def polys(draw):
        k = draw(st.integers(3, 12))
        rings = []
        for _ in range(draw(st.integers(1, 4))):
            cx = draw(st.floats(-50, 50))
            cy = draw(st.floats(-50, 50))
            ang = np.sort(np.array(draw(st.lists(st.floats(0, 2 * math.pi), min_size=k,
                                                  max_size=k))))
            rad = np.array(draw(st.lists(st.floats(2, 60), min_size=k, max_size=k)))
            pts = np.column_stack([cx + rad * np.cos(ang), cy + rad * np.sin(ang)])
            if draw(st.booleans()):  # sometimes a scrambled, self-intersecting ring
                pts = pts[np.array(draw(st.permutations(list(range(k)))))]
            rings.append(np.vstack([pts, pts[:1]]))
        return rings, draw(st.floats(0.2, 20)), draw(st.sampled_from(["outside", "inside"]))

    @settings(max_examples=n, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(polys())
    def run(case):
        rings, d, side = case
        dr = Drawing(tuple(Path.from_points(r) for r in rings))
        fm = make_field(dr.bbox(), magnification=TRUE_MAG)
        if dr.bbox() is None or max(dr.size_mm()) * 40 * fm.mm_per_unit < 2 * d * \
                fm.mm_per_unit:
            return
        kerf = 2 * d * fm.mm_per_unit
        for m in METHODS:
            try:
                out, _ = compensate_indexed(dr, kerf_mm=kerf, side=side, method=m, fm=fm,
                                            raster_res_bits=max(1.0, d / 20 * TRUE_MAG))
            except GalvoError:
                continue
            counts[m][0] += 1
            if not output_region(out).is_valid:
                counts[m][1] += 1

    run()
    lines.append(f"\n**Hypothesis polygons** (1-4 star-shaped rings of 3-12 vertices, half of "
                 f"them scrambled into self-intersecting rings, overlapping, d 0.2-20 units, "
                 f"{n} examples):\n")
    for m in METHODS:
        lines.append(f"- {m}: {counts[m][0]} runs, {counts[m][1]} invalid outputs")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--write", action="store_true", help="update bench/RESULTS.md")
    ap.add_argument("--quick", action="store_true", help="samples only (no corpus sweep)")
    ap.add_argument("--corpus-methods", default=",".join(METHODS),
                    help="methods for the corpus sweep (comma-separated; default all)")
    args = ap.parse_args()
    lines = ["## Kerf (issue 6)", ""]
    lines.append(f"Date {time.strftime('%Y-%m-%d', time.gmtime())}. Machine: "
                 f"{platform.machine()} {platform.processor() or ''} "
                 f"{os.cpu_count()} CPUs, Python {platform.python_version()}, shapely "
                 f"{shapely.__version__} (GEOS {shapely.geos_version_string}), clipper2-py "
                 f"{getattr(clipper2, '__version__', 'missing')} (Clipper2 "
                 f"{getattr(clipper2, 'CLIPPER2_VERSION', '-')}). Command: "
                 "`bash bench/run_kerf.sh`. Reference: shapely buffer of the even-odd region "
                 "with 1024 segments per quarter circle. Deviation: symmetric Hausdorff "
                 "distance between the outlines, densified to 0.25 unit. Times: best of 7 "
                 "(vector, Clipper2) or 2 (raster, rectangle) on a shared 2-CPU machine.")
    for name in ("seal.plt", "text_outline.plt"):
        sample_table(lines, name, 0.1)
    sample_table(lines, "text_outline.plt", 0.4)
    acute_table(lines)
    if not args.quick:
        corpus_table(lines, methods=tuple(args.corpus_methods.split(",")))
        hypothesis_validity(lines)
    text = "\n".join(lines) + "\n"
    print(text)
    if args.write:
        write_section(text)
    return 0


def write_section(text: str) -> None:
    replace_section("## Kerf (issue 6)", text)


if __name__ == "__main__":
    raise SystemExit(main())
