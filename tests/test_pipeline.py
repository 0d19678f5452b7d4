"""The staged pipeline: caching by the fields each stage reads, parameters, field mapping."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _util import SAMPLES, circle_plt

from galvo_core.drawing import Drawing, Path
from galvo_core.errors import ParamError
from galvo_core.field import FIT_MARGIN_BITS, make_field
from galvo_core.hpgl import read_bytes, read_file
from galvo_core.params import LaserParams, Params
from galvo_core.pipeline import Cancelled, Pipeline


@pytest.fixture(scope="module")
def circle() -> Drawing:
    return read_bytes(circle_plt(), "circle.plt")


def test_moving_e_per_refits_but_moving_magnification_only_resamples(circle):
    pipe = Pipeline()
    p = Params(magnification=20.0)
    assert pipe.run(circle, p).stages_run == ("fit", "sample")
    assert pipe.run(circle, p.replace(magnification=30.0)).stages_run == ("sample",)
    assert pipe.run(circle, p.replace(chord_tol_bits=3.0)).stages_run == ("sample",)
    assert pipe.run(circle, p.replace(e_per=0.1)).stages_run == ("fit", "sample")
    # back to the first settings: both cached
    assert pipe.run(circle, p).stages_run == ()


def test_cached_results_equal_fresh_ones(circle):
    a = Pipeline()
    a.run(circle, Params(magnification=20.0, e_per=0.1))
    ja = a.run(circle, Params(magnification=36.0, e_per=0.1)).job
    jb = Pipeline().run(circle, Params(magnification=36.0, e_per=0.1)).job
    assert [s.marks.tolist() for s in ja.strokes] == [s.marks.tolist() for s in jb.strokes]
    assert ja.stats == jb.stats


def test_more_magnification_more_marks_and_looser_tolerance_fewer(circle):
    pipe = Pipeline()
    n = [pipe.run(circle, Params(magnification=m)).job.stats["mark_points"] for m in (10, 20, 40)]
    assert n[0] < n[1] < n[2]
    t = [pipe.run(circle, Params(magnification=40, chord_tol_bits=c)).job.stats["mark_points"]
         for c in (0.5, 2, 8)]
    assert t[0] > t[1] > t[2]


def test_cancel_stops_a_run(circle):
    with pytest.raises(Cancelled):
        Pipeline().run(circle, Params(magnification=20.0), cancel=lambda: True)


@pytest.mark.parametrize(
    "kw",
    [dict(e_per=0), dict(e_per=-0.1), dict(eps_line=math.nan), dict(eps_sum=math.inf),
     dict(magnification=0), dict(chord_tol_bits=-1), dict(min_step_bits=-1),
     dict(interpolation="spline"), dict(kerf_side="left"), dict(fill="dots"),
     dict(scan_order="random"), dict(field_bits=1), dict(max_step_bits=1, min_step_bits=2),
     dict(e_per="0.1")],
)
def test_bad_parameters_are_refused_with_their_name(kw):
    with pytest.raises(ParamError) as ei:
        Params(**kw)
    assert next(iter(kw)) in str(ei.value)


def test_laser_parameters_validated():
    with pytest.raises(ParamError, match="mark_speed_mm_s"):
        LaserParams(mark_speed_mm_s=0)
    with pytest.raises(ParamError, match="power_percent"):
        LaserParams(power_percent=120)


def test_fit_field_uses_the_whole_field_and_centres():
    fm = make_field((100.0, 200.0, 1100.0, 700.0), magnification=None, fit_field=True)
    lo = fm.to_bits_float(np.array([[100.0, 200.0]]))[0]
    hi = fm.to_bits_float(np.array([[1100.0, 700.0]]))[0]
    assert lo[0] == pytest.approx(FIT_MARGIN_BITS) and hi[0] == pytest.approx(65535 - 16)
    assert (lo[1] + hi[1]) / 2 == pytest.approx(65535 / 2)


def test_out_of_field_refused_unless_clamped():
    d = Drawing((Path.from_points([(0, 0), (100000, 0)]),), name="wide.plt")
    with pytest.raises(ParamError, match="field"):
        Pipeline().run(d, Params(magnification=1.0))
    job = Pipeline().run(d, Params(magnification=1.0, clamp=True)).job
    marks = np.concatenate([s.marks for s in job.strokes])
    assert marks.min() >= 0 and marks.max() <= 65535
    assert any("clamped" in w.message for w in job.warnings)


def test_integer_coordinates_are_fitted_beyond_their_rounding_without_a_warning():
    """Issue 16: the fit detects the whole-unit grid and bounds its error by e_per beyond
    the rounding (e_per + 1/sqrt2 from the points): no warning, no hand-tuned e_per."""
    d = read_bytes(b"IN;SP1;PU0,0;PD100,3,200,10,300,24,400,41,500,65;PU;", "int.plt")
    job = Pipeline().run(d, Params()).job
    assert not any("rounded" in w.message for w in job.warnings)
    assert job.stats["max_fit_error"] <= 0.02 + 0.5**0.5 + 1e-9


def test_empty_drawing_gives_an_empty_job():
    d = read_bytes(b"IN;SP1;LBHELLO\x03;", "label.plt")
    job = Pipeline().run(d, Params()).job
    assert job.strokes == () and job.stats["mark_points"] == 0


def test_facts_of_a_drawing_are_computed_once(circle, monkeypatch):
    """The drawing's points are joined once for its bbox and coordinate grid, and each
    path's grid is detected once for the fit and the stats; all kept per drawing: a
    re-sample does not scan the points again. The facts are the drawing's own."""
    import galvo_core.pipeline as pl

    calls = {"join": 0, "path_quanta": 0}
    real_join, real_pq = pl._joined, pl.path_quanta

    def counting_join(arrs):  # type: ignore[no-untyped-def]
        calls["join"] += 1
        return real_join(arrs)

    def counting_pq(paths):  # type: ignore[no-untyped-def]
        calls["path_quanta"] += 1
        return real_pq(paths)

    monkeypatch.setattr(pl, "_joined", counting_join)
    monkeypatch.setattr(pl, "path_quanta", counting_pq)
    pipe = Pipeline()
    jobs = [pipe.run(circle, Params(magnification=m, chord_tol_bits=c)).job
            for m in (10.0, 12.0) for c in (1.0, 0.5)]
    assert calls == {"join": 1, "path_quanta": 1}
    fresh = Pipeline().run(circle, Params(magnification=12.0, chord_tol_bits=0.5)).job
    assert jobs[-1].stats == fresh.stats and jobs[-1].warnings == fresh.warnings
    assert pipe.bbox(circle) == circle.bbox()
    assert fresh.stats["quantum_units"] == circle.quantum()
    assert fresh.stats["input_points"] == circle.n_points


@pytest.mark.parametrize("name", ["seal.plt", "dense_logo.plt", "curve_1181.plt",
                                  "text_outline.plt", "arcs_circles.plt"])
def test_the_fit_bound_shown_holds_for_the_largest_fit_error(name):
    """What the job (and the GUI's job panel) states as the fit bound in effect is never
    below the largest fit error it reports, whatever grid each path was written on."""
    from _util import SAMPLES

    stats = Pipeline().run(read_file(SAMPLES / name), Params()).job.stats
    assert stats["max_fit_error"] <= stats["fit_bound_units"] * (1 + 1e-9)
    assert stats["fit_bound_units"] >= Params().e_per


def test_kerf_after_a_plain_run_refits_only_what_the_kerf_changed() -> None:
    """With the plain fit cached, a kerf change refits only the offset rings; the paths the
    kerf passes through keep their fit. The job is the one a fresh pipeline makes, and
    every kerf path is fitted on its input path's grid (whole units here), not on the
    offset's floats."""
    rng = np.random.default_rng(3)
    body = ["IN;SP1;"]
    for k in range(12):  # open wiggles (passed through) and closed squares (offset)
        pts = np.round(np.c_[np.linspace(0, 300, 40), 2000 * k + 30 * np.sin(
            np.linspace(0, 6, 40)) + rng.normal(0, 0.3, 40)]).astype(int)
        body.append(f"PU{pts[0, 0]},{pts[0, 1]};PD" + ",".join(
            f"{x},{y}" for x, y in pts[1:]) + ";")
        x0, y0 = 600, 2000 * k
        body.append(f"PU{x0},{y0};PD{x0 + 800},{y0},{x0 + 800},{y0 + 800},{x0},{y0 + 800},"
                    f"{x0},{y0};")
    d = read_bytes("".join(body).encode(), "mix.plt")
    plain = Params(fit_field=True)
    kerfed = plain.replace(kerf_mm=0.05)
    warm = Pipeline()
    base = warm.run(d, plain)
    res = warm.run(d, kerfed)
    fresh = Pipeline().run(d, kerfed)
    assert [s.marks.tolist() for s in res.job.strokes] == \
        [s.marks.tolist() for s in fresh.job.strokes]
    assert res.job.stats == fresh.job.stats
    passed = [i for i, o in enumerate(res.origin) if res.work.paths[i] is d.paths[o]]
    assert len(passed) == 12  # the wiggles
    for i in passed:  # the same fit as without kerf (the same arrays, not a refit)
        assert res.fitted[i].points is base.fitted[res.origin[i]].points
        assert res.fitted[i].source_index == i
    # the offset rings carry their input's grid: the fit's bound is e_per + 1/sqrt(2)
    assert res.job.stats["fit_bound_units"] == pytest.approx(
        max(kerfed.e_per, kerfed.eps_line) + 1 / math.sqrt(2))


def test_marks_of_a_curve_bulging_past_the_field_edge_are_clamped_not_left_outside() -> None:
    """Fit field puts the input points inside the field; a fitted curve may still bulge
    past its edge by up to the fit's bound (e_per 0.75 here, ~31 bits). Those marks are
    clamped with a warning: no mark of the job is outside the field (the job loads back)."""
    d = read_file(SAMPLES / "seal.plt")
    res = Pipeline().run(d, Params(fit_field=True, e_per=0.75, fill="zigzag",
                                   hatch_spacing_mm=0.5, scan_order="greedy", kerf_mm=0.1))
    top = res.job.field_map.max_bit
    assert all(((s.marks >= 0) & (s.marks <= top)).all() for s in res.job.strokes)
    if res.sample_report.outside_points:  # the case this guards: say what was done
        assert any("clamped" in w.message for w in res.job.warnings)


def test_fit_counts_in_the_stats_are_the_fitted_paths_own():
    """The control points, lines, cubics and largest fit error of the stats (counted on the
    fit's joined arrays) are those of the fitted paths one by one, dots included."""
    from galvo_core.fit import control_points

    dots = b"IN;SP1;PU0,0;PD0,0;PU9000,9000;PD9000,9000;PU;"
    seen = []
    for d in (read_bytes(dots + (SAMPLES / "seal.plt").read_bytes(), "dots.plt"),
              read_file(SAMPLES / "arcs_circles.plt")):
        pipe = Pipeline()
        params = Params(fit_field=True)
        st = pipe.run(d, params).job.stats
        fitted = pipe.fitted(d, params)
        assert st["control_points"] == sum(control_points(f) for f in fitted)
        assert st["lines"] == sum(f.n_lines for f in fitted)
        assert st["cubics"] == sum(f.n_cubics for f in fitted)
        assert st["max_fit_error"] == max(f.max_error for f in fitted)
        seen.append((sum(control_points(f) == 1 for f in fitted), st["cubics"]))
    assert seen[0][0] == 2 and seen[0][1] > 0 and seen[1][1] > 0
