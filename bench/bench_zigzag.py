"""Zig-zag fill before/after (issue 21): strokes, cells, region pieces and CPU time of
``hatch(fill="zigzag")`` on every bundled sample and a dozen corpus drawings with closed
paths, at hatch angles 0 and 15 degrees, spacing 0.05 mm at true size (2 input units).

Run it once per code version and compare::

    python bench/bench_zigzag.py --root /path/to/old/checkout --out bench/out/zz_before.json
    python bench/bench_zigzag.py --out bench/out/zz_after.json
    python bench/bench_zigzag.py --compare bench/out/zz_before.json bench/out/zz_after.json

``--root`` puts that checkout's galvo_core first on the path (the old code). CPU time is
``time.process_time`` (median of ``--repeat`` runs).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FILES = (
    "resources/samples/seal.plt",
    "resources/samples/text_outline.plt",
    "resources/samples/dense_logo.plt",
    "resources/samples/arcs_circles.plt",
    "resources/samples/curve_1181.plt",
    "corpus:cfriisha__hpgl2hitachi__v12v7a3-b_cu.plt",
    "corpus:drepetto__chiplotle__bird_by_brian_whitman_and_kelly_dobson.hpgl",
    "corpus:dylanvanassche__java-hpgl2gcode__randomledcontroller_pen3.plt",
    "corpus:drepetto__chiplotle__foal_release-0.1.hpgl",
    "corpus:temagrin__kicadhpgl2gcode__laser-b_cu.plt",
    "corpus:bblanchon__hpglviewer__gl-c-f.plt",
    "corpus:artifexsoftware__ghostpdl__origins.pcl",
    "corpus:dgtlrift__hp2xx__spectrum.plt",
    "corpus:ertantoygar__textilecadinterpreter__lectra_astm_test.hpgl",
    "corpus:vk2bea__hpgl-plotter__space-shuttle.hpgl",
    "corpus:felixfischer__hpgl-viewer__circles.hpgl",
    "corpus:h42i__monoplots__noten.hpgl",
)


def run(root: Path, repeat: int) -> list[dict]:
    sys.path.insert(0, str(root))
    sys.path.insert(1, str(ROOT / "bench"))
    from tile_real import source_path  # noqa: PLC0415

    from galvo_core import fill  # noqa: PLC0415
    from galvo_core.hpgl import read_file  # noqa: PLC0415

    print(f"galvo_core from {Path(fill.__file__).parent}", file=sys.stderr)
    rows = []
    for name in FILES:
        p = source_path(name)
        if not p.exists():
            continue
        d = read_file(p)
        for angle in (0.0, 15.0):
            times = []
            for _ in range(repeat):
                t0 = time.process_time()
                st = fill.hatch(d, fill="zigzag", spacing_units=2.0, angle_deg=angle)
                times.append(time.process_time() - t0)
            cells = fill.monotone_cells(d, spacing_units=2.0, angle_deg=angle)
            pieces = len(fill.region_polygons(fill.find_regions(d)))
            rows.append({"file": p.name, "angle": angle, "strokes": len(st), "cells": cells,
                         "pieces": pieces, "cpu_s": statistics.median(times)})
            print(rows[-1], file=sys.stderr)
    return rows


def compare(before: list[dict], after: list[dict]) -> None:
    a = {(r["file"], r["angle"]): r for r in after}
    print("| file | angle | pieces | cells | strokes before | strokes after | "
          "CPU s before | CPU s after |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    tot = [0, 0, 0.0, 0.0]
    for r in before:
        n = a.get((r["file"], r["angle"]))
        if n is None:
            continue
        flag = "" if n["strokes"] <= r["strokes"] else " **more**"
        print(f"| {r['file'][:48]} | {r['angle']:g} | {r['pieces']} | {r['cells']} | "
              f"{r['strokes']} | {n['strokes']}{flag} | {r['cpu_s']:.3f} | {n['cpu_s']:.3f} |")
        tot[0] += r["strokes"]
        tot[1] += n["strokes"]
        tot[2] += r["cpu_s"]
        tot[3] += n["cpu_s"]
    print(f"| **total** | | | | {tot[0]} | {tot[1]} | {tot[2]:.2f} | {tot[3]:.2f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, default=ROOT, help="checkout whose galvo_core runs")
    ap.add_argument("--out", type=Path, help="write the rows here (JSON)")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--compare", type=Path, nargs=2, metavar=("BEFORE", "AFTER"))
    args = ap.parse_args()
    if args.compare:
        compare(json.loads(args.compare[0].read_text()), json.loads(args.compare[1].read_text()))
        return
    rows = run(args.root.resolve(), args.repeat)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
