"""A path's fit depends on that path alone: fitting it on its own, with the other paths of
its file, or with them in another order gives the same segments, bit for bit
(:func:`galvo_core.fit.fit_paths` promises "the same result as one call per path"). An
operator who deletes one outline, or a cache that re-fits one layer, must not see another
outline change. (The quantum is the drawing's: a path too short to tell its grid takes the
file's, so the lone fits here are given the file's quantum, one unit.) Before this test the
smooth-stretch repair shared one re-fit budget and one split budget among all paths: 4 of
the 29 DejaVu Sans contours below (and 11 of 98 of DejaVu Sans ExtraLight at em 2048)
fitted differently alone."""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "bench"))
pytest.importorskip("fontTools")

import fonts  # noqa: E402

from galvo_core.fit import fit_paths  # noqa: E402


def _key(fp):
    return [(s.kind, np.asarray(s.points, dtype=np.float64).tobytes()) for s in fp.segments]


@pytest.mark.parametrize("style", ["sans", "sans-bold"])
def test_each_path_fits_the_same_alone_and_with_the_others(style):
    if not os.path.isfile(fonts.font_file(style)):
        pytest.skip(f"{fonts.font_file(style)} not installed")
    gs = fonts.glyph_set(style, em=1000.0, whole=True, text="aBgQRS&@8eJy%3")
    paths = gs.points
    together = fit_paths(paths, [True] * len(paths))
    backwards = fit_paths(paths[::-1], [True] * len(paths))[::-1]
    differ = [i for i, p in enumerate(paths)
              if _key(fit_paths([p], [True], quantum_units=1.0)[0]) != _key(together[i])]
    assert differ == []
    assert [_key(f) for f in backwards] == [_key(f) for f in together]
