"""Fill benchmark (issue 7, paper 002): zig-zag vs scan-line vs vpype vs MeerK40t.

Run in the bench's own venv (bench/.venv-fill, made by bench/run_fill.sh): vpype and
meerk40t are imported there only. Hatch strokes only (contours are the same for every
method and are left out), spacing 0.05 mm at true size (magnification = field bits / field mm
/ 40), hatch angle 0 degrees and 15 degrees.

Baselines: the issue's scan-line fill in plain raster order (one set of lines across the
whole drawing, row after row, alternating direction, one stroke per piece: paper 002 Fig.
1(a)), the same lines per region (galvo_core's ``fill="scanline"`` in file order), and the
per-region lines ordered greedily. Every method's strokes are timed with the same
galvo_core.timing.estimate (default LaserParams: mark 100 mm/s, and a fast variant: mark
1000 mm/s). Prints markdown tables and, per sample, the zig-zag's time against each baseline
and against the best peer; bench/out/fill.json has everything.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench_order import vpype_greedy_linesort  # noqa: E402

from galvo_core.fill import (  # noqa: E402
    coverage,
    find_regions,
    hatch,
    monotone_cells,
    region_polygons,
    retraced_length,
)
from galvo_core.hpgl import read_file  # noqa: E402
from galvo_core.order import order_strokes  # noqa: E402
from galvo_core.params import LaserParams, Params  # noqa: E402
from galvo_core.pipeline import Pipeline  # noqa: E402
from galvo_core.timing import estimate  # noqa: E402

SAMPLES = ROOT / "resources" / "samples"
SPACING_MM = 0.05
LASERS = {"100": LaserParams(), "1000": LaserParams(mark_speed_mm_s=1000.0)}


def ordered(lines: list[np.ndarray], method: str = "greedy") -> list[np.ndarray]:
    pl = order_strokes(lines, method=method, time_budget_s=2.0)
    return [lines[p.index][::-1] if p.reverse else lines[p.index] for p in pl]


def raster_fill(region, spacing_units: float, angle: float) -> list[np.ndarray]:
    """The issue's baseline ("scanline: parallel hatch lines, one stroke per segment,
    alternating direction", in plain raster order), as paper 002 Fig. 1(a): one set of lines
    across the whole drawing, row after row, every row's pieces in the row's direction."""
    import shapely

    a = np.radians(angle)
    rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    g = shapely.transform(region, lambda q: q @ rot)  # rotated frame: rows are y = const
    x0, y0, x1, y1 = g.bounds
    n = max(1, int(np.ceil((y1 - y0) / spacing_units - 1e-9)))
    ys = y0 + ((y1 - y0) - (n - 1) * spacing_units) / 2 + spacing_units * 1.3e-7 \
        + np.arange(n) * spacing_units
    rows = shapely.intersection(shapely.linestrings(
        [[(x0 - 1, y), (x1 + 1, y)] for y in ys]), g)
    out = []
    for k, r in enumerate(rows):
        segs = [np.asarray(ln.coords) for ln in getattr(r, "geoms", [r])
                if not ln.is_empty and ln.length > 0]
        segs = [sg[np.argsort(sg[:, 0])][[0, -1]] for sg in segs]
        segs.sort(key=lambda sg: sg[0, 0], reverse=bool(k % 2))
        out.extend(sg[::-1] if k % 2 else sg for sg in segs)
    return [p @ rot.T for p in out]


def vpype_fill(lines: list[np.ndarray], mm_per_unit: float) -> list[np.ndarray]:
    """vpype linemerge (default tolerance 0.05 mm) + linesort (its greedy loop)."""
    import vpype as vp

    scale = mm_per_unit / 25.4 * 96.0  # vpype's unit is the CSS pixel
    lc = vp.LineCollection([(p[:, 0] + 1j * p[:, 1]) * scale for p in lines])
    lc.merge(tolerance=0.05 / 25.4 * 96.0, flip=True)
    new = vpype_greedy_linesort(lc)
    return [np.c_[ln.real, ln.imag] / scale for ln in new]


def meerk40t_fill(drawing, spacing_units: float, angle: float) -> list[np.ndarray] | None:
    """MeerK40t's optimized Eulerian hatch fill (meerk40t.fill.fills.eulerian_fill)."""
    try:
        from meerk40t.core.units import UNITS_PER_MM
        from meerk40t.fill.fills import eulerian_fill
    except Exception as exc:  # pragma: no cover - peer not installable
        print(f"meerk40t not available: {exc}", file=sys.stderr)
        return None
    k = UNITS_PER_MM / 40.0  # meerk40t native units per input unit (at true size)
    out: list[np.ndarray] = []
    for reg in find_regions(drawing):
        outl: list = []
        for ring in [reg.polygon.exterior, *reg.polygon.interiors]:
            pts = np.asarray(ring.coords) * k
            outl.extend(complex(x, y) for x, y in pts)
            outl.append(None)
        pts = eulerian_fill({"hatch_distance": f"{spacing_units / 40.0}mm",
                             "hatch_angle": f"{angle}deg"}, outl, None)
        cur: list = []
        for p in pts:
            if p is None:
                if len(cur) > 1:
                    out.append(np.array(cur) / k)
                cur = []
            else:
                cur.append(p)
        if len(cur) > 1:
            out.append(np.array(cur) / k)
    return out


def measure(name: str, lines: list[np.ndarray], fm, region, spacing_units: float,
            seconds: float) -> dict:
    marks = [fm.to_bits(p) for p in lines]
    row = {"method": name, "strokes": len(lines), "seconds": seconds,
           "retraced_mm": retraced_length(lines) * fm.mm_per_unit,
           "coverage": coverage(region, lines, spacing_units)}
    for k, laser in LASERS.items():
        t = estimate(marks, laser, fm.mm_per_bit)
        row[f"time_{k}"] = t["estimated_time_s"]
        row["mark_mm"] = t["mark_length_mm"]
        row["jump_mm"] = t["jump_length_mm"]
        row["switches"] = t["laser_switches"]
    return row


def main() -> None:
    import shapely

    results = []
    for sample in ("seal.plt", "text_outline.plt"):
        d = read_file(SAMPLES / sample)
        fm = Pipeline().field_map(d, Params())
        sp = fm.mm_to_units(SPACING_MM)
        region = shapely.unary_union([p for _, p in region_polygons(find_regions(d))])
        for angle in (0.0, 15.0):
            cells = monotone_cells(d, spacing_units=sp, angle_deg=angle)
            rows = []
            t0 = time.perf_counter()
            raster = raster_fill(region, sp, angle)
            rows.append(measure("scanline, plain raster (issue baseline)", raster, fm, region,
                                sp, time.perf_counter() - t0))
            t0 = time.perf_counter()
            scan = [s.points for s in hatch(d, fill="scanline", spacing_units=sp,
                                             angle_deg=angle)]
            t_scan = time.perf_counter() - t0
            rows.append(measure("scanline, raster per region", scan, fm, region, sp, t_scan))
            t0 = time.perf_counter()
            scan_g = ordered(scan)
            rows.append(measure("scanline + greedy order", scan_g, fm, region, sp,
                                t_scan + time.perf_counter() - t0))
            t0 = time.perf_counter()
            zz = [s.points for s in hatch(d, fill="zigzag", spacing_units=sp, angle_deg=angle)]
            t_z = time.perf_counter() - t0
            rows.append(measure("zigzag (file order)", zz, fm, region, sp, t_z))
            t0 = time.perf_counter()
            zz_o = ordered(zz, "optimized")
            rows.append(measure("zigzag + optimized order", zz_o, fm, region, sp,
                                t_z + time.perf_counter() - t0))
            t0 = time.perf_counter()
            try:
                vp_lines = vpype_fill(scan, fm.mm_per_unit)
                rows.append(measure("vpype linemerge+linesort", vp_lines, fm, region, sp,
                                    t_scan + time.perf_counter() - t0))
            except ImportError as exc:
                print(f"vpype not available: {exc}", file=sys.stderr)
            t0 = time.perf_counter()
            mk = meerk40t_fill(d, sp, angle)
            if mk is not None:
                mk = ordered(mk)  # MeerK40t's own output order is per region; order it too
                rows.append(measure("MeerK40t eulerian_fill + greedy", mk, fm, region, sp,
                                    time.perf_counter() - t0))
            results.append({"sample": sample, "angle": angle, "cells": cells, "rows": rows})
    (ROOT / "bench" / "out").mkdir(exist_ok=True)
    for res in results:
        by = {r["method"]: r for r in res["rows"]}
        zz = by["zigzag + optimized order"]
        base = by["scanline, plain raster (issue baseline)"]
        peers = [r for m, r in by.items() if m.startswith(("vpype", "MeerK40t"))]
        res["summary"] = {}
        for k in LASERS:
            res["summary"][k] = {
                "vs_raster": zz[f"time_{k}"] / base[f"time_{k}"] - 1.0,
                "vs_region_raster": zz[f"time_{k}"] / by["scanline, raster per region"][
                    f"time_{k}"] - 1.0,
                "vs_scan_greedy": zz[f"time_{k}"] / by["scanline + greedy order"][
                    f"time_{k}"] - 1.0,
                "vs_best_peer": zz[f"time_{k}"] / min(r[f"time_{k}"] for r in peers)
                if peers else float("nan"),
            }
    (ROOT / "bench" / "out" / "fill.json").write_text(json.dumps(results, indent=1))
    for res in results:
        print(f"\n{res['sample']}, hatch angle {res['angle']:g} deg, spacing {SPACING_MM} mm, "
              f"{res['cells']} monotone cells\n")
        print("| method | strokes | jump mm | mark mm | re-traced mm | coverage | "
              "time s @100 mm/s | time s @1000 mm/s | compute s |")
        print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
        for r in res["rows"]:
            print(f"| {r['method']} | {r['strokes']} | {r['jump_mm']:.0f} | {r['mark_mm']:.0f} | "
                  f"{r['retraced_mm']:.1f} | {100 * r['coverage']:.2f} % | {r['time_100']:.2f} | "
                  f"{r['time_1000']:.2f} | {r['seconds']:.2f} |")
        for k, v in res["summary"].items():
            print(f"\n@{k} mm/s zigzag+optimized: {100 * v['vs_raster']:+.0f} % vs plain raster, "
                  f"{100 * v['vs_region_raster']:+.0f} % vs raster per region, "
                  f"{100 * v['vs_scan_greedy']:+.0f} % vs scanline+greedy, "
                  f"{v['vs_best_peer']:.2f}x best peer", end="")
        print()


if __name__ == "__main__":
    main()
