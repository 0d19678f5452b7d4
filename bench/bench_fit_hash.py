"""Fitted arrays per typeface row, hashed (issue 16, fifth session): ``fit_paths`` at the
defaults on the training set (fonts.STYLES, fonts.TEXT, ems 1000 and 2048) and the held-out
set (fonts.HELDOUT, fonts.HELDOUT_TEXT, fonts.HELDOUT_EMS), whole-unit and exact input; per
row the segment count and a hash of the fitted arrays (kinds, points, first/last,
max_error), and one hash over all rows. Equal hashes between two checkouts = the same fit
bit for bit (a change meant for speed only must keep them).

Usage: python bench/bench_fit_hash.py [--code DIR]   (run it for two checkouts and diff)
"""

from __future__ import annotations

import argparse
import hashlib
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--code", help="import galvo_core from this checkout")
    a = ap.parse_args()
    root = os.path.abspath(a.code) if a.code else os.path.join(HERE, "..")
    sys.path.insert(0, root)
    sys.path.insert(1, HERE)  # (this checkout's fonts.py: the same glyphs for both)
    import fonts

    from galvo_core import fit as fitmod

    print(f"# {fitmod.__file__}")
    total = hashlib.sha256()
    sets = ((fonts.STYLES, fonts.TEXT, (1000.0, 2048.0)),
            (fonts.HELDOUT, fonts.HELDOUT_TEXT, fonts.HELDOUT_EMS))
    for styles, text, ems in sets:
        for st in styles:
            for whole in (True, False):
                for em in ems:
                    with fonts.font_errors(st):
                        gs = fonts.glyph_set(st, em=em, whole=whole, text=text)
                        h = hashlib.sha256()
                        n = 0
                        for fp in fitmod.fit_paths(gs.points, [True] * len(gs.points)):
                            for arr in (fp.is_cubic, fp.points, fp.first, fp.last):
                                h.update(np.ascontiguousarray(arr).tobytes())
                            h.update(np.float64(fp.max_error).tobytes())
                            n += len(fp.is_cubic)
                        total.update(h.digest())
                        print(f"{st:18s} {'whole' if whole else 'exact'} {em:6.0f} "
                              f"{n:5d} segments  {h.hexdigest()[:16]}", flush=True)
    print(f"all rows {total.hexdigest()[:16]}")


if __name__ == "__main__":
    main()
