"""The sampler alone on a re-sample (issue 18, round 4): ``sample_paths`` on a cached fit
and cached sampler geometry, the chord tolerance alternating 1.00 / 1.01 bit (what a chord
tolerance change costs; a magnification change adds the field mapping of the geometry).

    PYTHONPATH=. python bench/bench_resample.py FILE [FILE ...] [--repeats 7] [--profile]

Prints per file the median and best CPU time (time.process_time) of ``--repeats`` runs,
and with ``--profile`` cProfile's top functions over five more runs.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import statistics
import time

from galvo_core.hpgl import read_file
from galvo_core.params import Params
from galvo_core.pipeline import Pipeline
from galvo_core.sample import sample_geometry, sample_paths


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--profile", action="store_true")
    a = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f}; CPU ms (process_time)")
    for f in a.files:
        d = read_file(f)
        p = Params(fit_field=True)
        pl = Pipeline()
        fm = pl.field_map(d, p)
        fitted = pl.fitted(d, p, fm)
        geo = sample_geometry(fitted)

        def one(tol: float, fitted=fitted, fm=fm, ms=p.min_step_bits, geo=geo) -> None:
            sample_paths(fitted, fm, chord_tol_bits=tol, min_step_bits=ms, geometry=geo)

        one(1.0)  # compile, map the geometry
        ts = []
        for i in range(a.repeats):
            t = time.process_time()
            one(1.0 + 0.01 * (i % 2))
            ts.append(time.process_time() - t)
        print(f"{os.path.basename(f)}: {len(fitted)} paths; sample_paths median "
              f"{statistics.median(ts) * 1e3:.1f} ms, best {min(ts) * 1e3:.1f} ms")
        if a.profile:
            pr = cProfile.Profile()
            pr.enable()
            for _ in range(5):
                one(1.0)
            pr.disable()
            pstats.Stats(pr).sort_stats("tottime").print_stats(15)


if __name__ == "__main__":
    main()
