"""Vector kerf time before and after a change, against Clipper2, interleaved (issue 6).

Loads ``galvo_core/kerf.py`` as it was at a git revision (``--before``, default ``main``)
beside the working tree's, and times both and Clipper2 (even-odd union + InflatePaths per
pen, numpy in and out, as in kerf_corpus_time.py) one after the other on each run, best of
``--repeat``: on a shared machine the three then see the same load. Runs: the corpus runs
(fit-field magnification, kerf 0.1 mm, both sides) where Clipper2 takes at least 5 ms, and
the two samples at true size (kerf 0.1 mm; text_outline also 0.4 mm). Also checks that both
versions give the same ``origin`` length and the same warnings.

``PYTHONPATH=. bench/.venv-kerf/bin/python bench/kerf_before_after.py [--before REV]``
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_kerf as bk  # noqa: E402

from galvo_core import kerf  # noqa: E402
from galvo_core.field import make_field  # noqa: E402

MEANINGFUL_S = 0.005


def old_kerf(rev: str):
    src = subprocess.run(["git", "show", f"{rev}:galvo_core/kerf.py"], check=True,
                         capture_output=True, text=True, cwd=bk.ROOT).stdout
    path = os.path.join(tempfile.mkdtemp(), "kerf_before.py")
    with open(path, "w") as fh:
        fh.write(src)
    spec = importlib.util.spec_from_file_location("kerf_before", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def clipper_all(dr, d, side, bit):
    for pen in sorted({p.pen for p in dr.paths}):
        rings = bk.pen_rings(dr, pen)
        if rings:
            bk.clipper_offset(rings, d, side, bit)


CLOCK = time.perf_counter


def best3(fns, repeat):
    """Best time of each function, the functions run one after the other each round."""
    best = [float("inf")] * len(fns)
    for _ in range(repeat):
        for k, fn in enumerate(fns):
            t = CLOCK()
            fn()
            best[k] = min(best[k], CLOCK() - t)
    return best


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", default="main", help="git revision of the old kerf.py")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                    help="cpu: this process's CPU time (not inflated by other processes)")
    args = ap.parse_args()
    global CLOCK
    if args.clock == "cpu":
        CLOCK = time.process_time
    before = old_kerf(args.before)
    cases = []
    for name, dr in bk.corpus_drawings():
        fm = make_field(dr.bbox(), magnification=None, fit_field=True)
        x0, y0, x1, y1 = dr.bbox()
        if 0.1 > max(x1 - x0, y1 - y0) * fm.mm_per_unit:
            continue
        for side in ("outside", "inside"):
            cases.append((name, dr, fm, 0.1, side))
    for name, kmm in (("seal.plt", 0.1), ("text_outline.plt", 0.1), ("text_outline.plt", 0.4)):
        dr = bk.read_file(bk.SAMPLES / name)
        fm = make_field(dr.bbox(), magnification=bk.TRUE_MAG)
        for side in ("outside", "inside"):
            cases.append((f"{name} {kmm} mm", dr, fm, kmm, side))
    print("| run | side | before (ms) | after (ms) | Clipper2 (ms) | before / Clipper2 "
          "| after / Clipper2 |")
    print("|---|---|---|---|---|---|---|")
    for name, dr, fm, kmm, side in cases:
        d = fm.mm_to_units(kmm / 2)
        bit = fm.bits_to_units(1.0)
        kw = dict(kerf_mm=kmm, side=side, method="vector", fm=fm)

        def clip(dr=dr, d=d, side=side, bit=bit):
            clipper_all(dr, d, side, bit)

        def ours_before(dr=dr, kw=kw):
            return before.compensate_indexed(dr, **kw)

        def ours_after(dr=dr, kw=kw):
            return kerf.compensate_indexed(dr, **kw)

        if best3([clip], 3)[0] < MEANINGFUL_S and " mm" not in name:
            continue
        (ob, oo), (nb, no) = ours_before(), ours_after()
        same = (len(oo) == len(no)
                and [w.message for w in ob.warnings] == [w.message for w in nb.warnings])
        tb, ta, tc = best3([ours_before, ours_after, clip], args.repeat)
        note = "" if same else " (outputs differ in count or warnings)"
        print(f"| {name} | {side} | {tb * 1000:.1f} | {ta * 1000:.1f} | {tc * 1000:.1f} | "
              f"x{tb / tc:.2f} | x{ta / tc:.2f}{note} |", flush=True)

if __name__ == "__main__":
    main()
