"""Curves that a file flattens coarsely (long chords a few degrees apart, in whole units) are
fitted as curves: the long-segment rule meant for lines of the design must not turn every
chord into a line (galvo_core.fit._coarse_chords)."""

from __future__ import annotations

import numpy as np
import pytest

from galvo_core import fit as fm
from galvo_core.geometry import flatten_cubic, point_polyline_distance


def _coarse_circle(r: float, n: int, phase: float = 0.3) -> np.ndarray:
    t = phase + np.linspace(0.0, 2.0 * np.pi, n + 1)
    return np.round(np.c_[5000.0 + r * np.cos(t), 3000.0 + r * np.sin(t)])


def _dense(fp) -> np.ndarray:
    parts = [flatten_cubic(np.asarray(s.points), 0.01) if s.kind == "cubic"
             else np.asarray(s.points) for s in fp.segments]
    return np.vstack(parts)


@pytest.mark.parametrize(("r", "n"), [(1000.0, 90), (2500.0, 140), (400.0, 36)])
def test_a_coarsely_flattened_circle_becomes_a_few_cubics_near_the_design(r, n):
    # chords of 70, 112 and 70 units whose design bulges 0.61, 0.63 and 1.5 beyond them
    # (the last: more than the bound allows beside a chord, so lines are right there too)
    pts = _coarse_circle(r, n)
    fp = fm.fit_paths([pts], [True])[0]
    rep = fm.check_fit(pts, fp, 0.02, 0.02, report=True)
    assert not rep["violation"]
    sag = r * (1.0 - np.cos(np.pi / n))
    cubics = sum(s.kind == "cubic" for s in fp.segments)
    if sag < 0.7:
        # the design leaves little of the bound beside each chord, so the cubics are short,
        # but far fewer than a line per chord (what the long-segment rule gave)
        assert len(fp.segments) <= n // 3
        assert cubics >= len(fp.segments) // 2
        # and the curves follow the design (the circle), not the chords
        t = np.linspace(0.0, 2.0 * np.pi, 20000)
        truth = np.c_[5000.0 + r * np.cos(t), 3000.0 + r * np.sin(t)]
        d = _dense(fp)
        far = max(point_polyline_distance(d, truth).max(),
                  point_polyline_distance(truth, d).max())
        chords = point_polyline_distance(truth, pts).max()
        assert far < chords
    else:
        assert len(fp.segments) >= n // 2


def test_long_design_lines_beside_a_dense_curve_stay_lines():
    # a "D": a long straight stem (one segment, 800 units) and a densely written bowl, in
    # whole units: the stem is a line of the design and no cubic may swallow it
    t = np.linspace(-np.pi / 2, np.pi / 2, 900)
    bowl = np.c_[1000.0 + 400.0 * np.cos(t), 400.0 + 400.0 * np.sin(t)]
    pts = np.round(np.vstack([[[1000.0, 0.0]], bowl[1:-1], [[1000.0, 800.0]], [[1000.0, 0.0]]]))
    pts = pts[np.r_[True, (np.diff(pts, axis=0) != 0).any(axis=1)]]
    fp = fm.fit_paths([pts], [True])[0]
    stem = [s for s in fp.segments if s.kind == "line"
            and abs(np.asarray(s.points)[:, 0] - 1000.0).max() < 1.0
            and np.ptp(np.asarray(s.points)[:, 1]) > 700.0]
    assert len(stem) == 1


def test_a_spoolers_coarse_letter_is_fitted_as_curves():
    # a real engraving-spooler file (gravostyle): an "S" written as chords of 40-70 units
    from pathlib import Path

    from galvo_core.hpgl import read_file

    f = (Path(__file__).resolve().parents[2] / "shared" / "corpus" / "plt"
         / "chrisand1998__gravostyle-spooler-hpgl-to-gcode__samplespoolerhpgl.spl")
    if not f.is_file():
        pytest.skip(f"corpus file {f} not present")
    p = max(read_file(f).paths, key=lambda p: len(p.points))
    fp = fm.fit_paths([p.points], [p.closed])[0]
    assert not fm.check_fit(p.points, fp, 0.02, 0.02, report=True)["violation"]
    cubics = sum(s.kind == "cubic" for s in fp.segments)
    # (before: 231 segments, three in four of them lines, for 339 points)
    assert len(fp.segments) <= len(p.points) // 4
    assert cubics >= 0.6 * len(fp.segments)


def test_the_swallowed_line_refit_leaves_no_hole(monkeypatch):
    # the re-fit of cubics that swallow a design line (fit._lone_lines_out), made to run on
    # every long chord of the spooler's coarse "S" (its chords not told apart from design
    # lines): the path's segments still follow one another and keep the bound (the re-fit's
    # merge rounds once joined two cubics' rests and left a hole of five thinned points)
    from pathlib import Path

    from galvo_core.hpgl import read_file

    f = (Path(__file__).resolve().parents[2] / "shared" / "corpus" / "plt"
         / "chrisand1998__gravostyle-spooler-hpgl-to-gcode__samplespoolerhpgl.spl")
    if not f.is_file():
        pytest.skip(f"corpus file {f} not present")
    real = fm._lone_lines_out
    init = fm._BatchFitter.__init__
    calls = []

    def every_chord(*args, coarse=None, **kw):
        calls.append(len(args[10]))

        def with_chords(self, *a, **kw):  # (the re-fit still knows the chords)
            init(self, *a, **kw)
            if coarse is not None and len(coarse) == len(self.work):
                self.coarse = coarse

        monkeypatch.setattr(fm._BatchFitter, "__init__", with_chords)
        try:
            return real(*args, coarse=None, **kw)
        finally:
            monkeypatch.setattr(fm._BatchFitter, "__init__", init)

    monkeypatch.setattr(fm, "_lone_lines_out", every_chord)
    p = max(read_file(f).paths, key=lambda p: len(p.points))
    fp = fm.fit_paths([p.points], [p.closed])[0]
    assert calls
    segs = fp.segments
    assert all(a.last == b.first for a, b in zip(segs[:-1], segs[1:], strict=True))
    assert not fm.check_fit(p.points, fp, 0.02, 0.02, report=True)["violation"]
