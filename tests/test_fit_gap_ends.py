"""The gap-end rule of the fit (``fit._gap_ends_kept``) is for a curve's dense end beside a
design line; on a real polyline file (a Tektronix screen plot: strokes and text, whole units)
it must not split the thinned lines that serve a few short strokes beside a long one."""

from __future__ import annotations

from pathlib import Path

import pytest

from galvo_core import fit as fitmod
from galvo_core import hpgl

CORPUS = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "plt"
TEK = CORPUS / "vk2bea__hpgl-plotter__tektronix.hpgl"


@pytest.mark.skipif(not TEK.exists(), reason="corpus not present")
def test_polyline_strokes_are_not_split_at_their_long_steps(monkeypatch) -> None:
    d = hpgl.read_file(TEK)
    with_rule = fitmod.fit_drawing(d)
    monkeypatch.setattr(fitmod, "_gap_ends_kept", lambda W, K, tlen, *a: (K, tlen))
    without = fitmod.fit_drawing(d)
    n_with = sum(f.n_segments for f in with_rule)
    n_without = sum(f.n_segments for f in without)
    # (the rule unguarded made 957 segments of this file's 761: a quarter more marks)
    assert n_with <= 1.05 * n_without
    # and the bound still holds on every path (true distances both ways)
    for f, p in zip(with_rule, d.paths, strict=True):
        rep = fitmod.check_fit(p.points, f, fitmod.DEFAULT_E_PER, fitmod.DEFAULT_EPS_LINE,
                               report=True)
        assert rep["violation"] == 0.0
