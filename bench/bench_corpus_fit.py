"""Our fit at the defaults on every corpus file: segments (lines / cubics), paths over the
stated bound (``check_fit`` at each path's detected quantum, as the fit uses it) and CPU
seconds per file; ``--compare DIR``: the same for another checkout, side by side.

Usage: python bench/bench_corpus_fit.py [--only SUBSTR ...] [--compare /path/to/checkout]
       [--json F]
(the corpus is ../shared/corpus/plt next to the checkout; files our reader refuses are left
out). The first day's table and the seventh session's before/after are in bench/RESULTS.md,
"Coarsely flattened curves".
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
CORPUS = HERE.parents[1] / "shared" / "corpus" / "plt"


def measure(only: list[str]) -> dict[str, dict]:
    """Per corpus file (the galvo_core on sys.path): lines, cubics, paths over, CPU s."""
    from galvo_core.errors import InputError
    from galvo_core.fit import check_fit, fit_paths, warm_up
    from galvo_core.hpgl import read_file
    from galvo_core.precision import path_quanta

    warm_up()
    out: dict[str, dict] = {}
    for f in sorted(CORPUS.iterdir()):
        if not f.is_file() or "__expected" in f.name or (only and not any(o in f.name
                                                                            for o in only)):
            continue
        try:
            d = read_file(f)
        except InputError:
            continue
        paths = [p for p in d.paths if len(p.points) >= 2]
        if not paths:
            continue
        t = time.process_time()
        fps = fit_paths([p.points for p in paths], [p.closed for p in paths])
        t = time.process_time() - t
        qs = path_quanta([p.points for p in paths])
        over = sum(bool(check_fit(p.points, fp, 0.02, 0.02, quantum_units=float(q),
                                  report=True)["violation"])
                   for p, fp, q in zip(paths, fps, qs, strict=True))
        kinds = [s.kind for fp in fps for s in fp.segments]
        out[f.name] = {"lines": kinds.count("line"), "cubics": kinds.count("cubic"),
                       "over": over, "cpu_s": t}
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", nargs="*", default=[], help="file name substrings")
    ap.add_argument("--compare", help="another checkout, measured in a subprocess")
    ap.add_argument("--json")
    ap.add_argument("--raw", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.raw:  # (the --compare subprocess)
        json.dump(measure(a.only), sys.stdout)
        return
    sys.path.insert(0, str(HERE.parent))
    ours = measure(a.only)
    other: dict[str, dict] = {}
    if a.compare:
        env = dict(os.environ, PYTHONPATH=a.compare)
        res = subprocess.run([sys.executable, __file__, "--raw", "--only", *a.only],
                             env=env, cwd="/", capture_output=True, text=True, check=True)
        other = json.loads(res.stdout)
    print("| file | segments (cubics) | over | cpu s |" + (" other: segments (cubics) | over |"
                                                          if other else ""))
    print("| --- | ---: | ---: | ---: |" + (" ---: | ---: |" if other else ""))
    tot = [0, 0]
    for name, r in ours.items():
        row = f"| {name} | {r['lines'] + r['cubics']} ({r['cubics']}) | {r['over']} | " \
              f"{r['cpu_s']:.2f} |"
        tot[0] += r["lines"] + r["cubics"]
        if name in other:
            o = other[name]
            row += f" {o['lines'] + o['cubics']} ({o['cubics']}) | {o['over']} |"
            tot[1] += o["lines"] + o["cubics"]
        print(row)
    print(f"\n{len(ours)} files, {tot[0]} segments, "
          f"{sum(r['over'] for r in ours.values())} paths over the bound"
          + (f"; other: {tot[1]} segments" if other else ""))
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"ours": ours, "other": other}, fh, indent=0)


if __name__ == "__main__":
    main()
