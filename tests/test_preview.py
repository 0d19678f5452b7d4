"""galvo_core.preview: the display geometry the views draw (no Qt)."""

from __future__ import annotations

import numpy as np
import pytest
from _util import circle_plt

from galvo_core import preview as pv
from galvo_core.drawing import Drawing, Path, SourcePos
from galvo_core.field import FieldMap
from galvo_core.fit import FittedPath, Segment
from galvo_core.geometry import cubic_eval
from galvo_core.hpgl import read_bytes
from galvo_core.job import Job, Stroke
from galvo_core.params import Params
from galvo_core.pipeline import Cancelled, Pipeline


@pytest.fixture(scope="module")
def circle() -> Drawing:
    return read_bytes(circle_plt(), "circle.plt")


@pytest.fixture(scope="module")
def run(circle):
    pipe = Pipeline()
    params = Params(magnification=20.0, e_per=0.05)
    job = pipe.run(circle, params).job
    return pipe, params, job, pipe.fitted(circle, params)


def _job(strokes, fm=None, **params) -> Job:
    fm = fm or FieldMap(2.0, (100.0, 200.0), 65536, 110.0)
    return Job("t.plt", "", fm, {"e_per": 0.02, "eps_line": 0.02, **params}, {}, tuple(strokes))


# --- joining and mapping -----------------------------------------------------------------
def test_nan_join_separates_pieces_and_labels_rows():
    out = pv.nan_join([np.zeros((2, 2)), np.empty((0, 2)), np.ones((3, 2))], ids=[7, 8, 9])
    assert out.xy.shape == (6, 2)
    assert np.isnan(out.xy[2]).all()
    assert out.ids.tolist() == [7, 7, -1, 9, 9, 9]
    assert out.n_vertices == 5
    assert np.array_equal(out.select(9), np.ones((3, 2)))
    assert len(pv.nan_join([]).xy) == 0 and pv.nan_join([]).xy.shape == (0, 2)


def test_select_keeps_pieces_of_one_id_apart():
    out = pv.nan_join([np.zeros((2, 2)), np.ones((2, 2)), 2 * np.ones((2, 2))], ids=[1, 2, 1])
    sel = out.select(1)
    assert len(sel) == 5 and np.isnan(sel[2]).all()
    assert len(out.select(42)) == 0


def test_units_bits_mm_round_trip():
    fm = FieldMap(14.9, (1000.0, -50.0), 65536, 110.0)
    pts = np.array([[0.0, 0.0], [400.0, 123.0], [np.nan, np.nan]])
    mm = pv.units_to_mm(fm, pts)
    assert mm[0] == pytest.approx(np.array([1000.0, -50.0]) * fm.mm_per_bit)
    assert np.isnan(mm[2]).all()
    assert pv.mm_to_units(fm, mm[:2]) == pytest.approx(pts[:2])
    bits = np.array([[0, 0], [65535, 32768]])
    assert pv.mm_to_bits(fm, pv.bits_to_mm(fm, bits)) == pytest.approx(bits)
    ring = pv.field_outline_mm(fm)
    assert ring.shape == (5, 2) and ring.max() == pytest.approx(110.0)


def test_bbox_ignores_nan():
    assert pv.bbox(np.array([[1, 2], [np.nan, np.nan], [3, -1]])) == (1, -1, 3, 2)
    assert pv.bbox(np.full((2, 2), np.nan)) is None


# --- fitted geometry ----------------------------------------------------------------------
def test_flatten_segments_stays_within_tolerance():
    cubic = np.array([[0.0, 0.0], [10.0, 30.0], [40.0, -30.0], [50.0, 0.0]])
    line = np.array([[50.0, 0.0], [80.0, 0.0]])
    tol = 0.01
    poly = pv.flatten_segments([("cubic", cubic), ("line", line)], tol)
    assert np.array_equal(poly[0], cubic[0]) and np.array_equal(poly[-1], line[1])
    # every point of the curve is within tol of the polyline
    from galvo_core.geometry import point_polyline_distance

    dense = cubic_eval(cubic, np.linspace(0, 1, 2001))
    assert point_polyline_distance(dense, poly).max() <= tol * 1.0001
    # the joint appears once
    assert (np.hypot(*np.diff(poly, axis=0).T) > 0).all()


def _random_fit(rng, index: int, n_seg: int) -> FittedPath:
    """A continuous chain of random lines and cubics (a path of the fit)."""
    segs, p0 = [], rng.uniform(-50, 50, 2)
    for _ in range(n_seg):
        if rng.random() < 0.5:
            pts = np.vstack([p0, p0 + rng.uniform(-5, 5, (3, 2)).cumsum(axis=0)])
            segs.append(Segment("cubic", pts, 0, 1))
        else:
            pts = np.vstack([p0, p0 + rng.uniform(-5, 5, 2)])
            segs.append(Segment("line", pts, 0, 1))
        p0 = pts[-1]
    return FittedPath(index, 1, False, segs)


def test_vectorised_curve_and_control_layer_match_the_per_segment_geometry():
    """fitted_curve / control_layer work on all paths' arrays at once: path by path they
    give the vertices flatten_segments gives, and the control rows of each segment."""
    rng = np.random.default_rng(5)
    fitted = [_random_fit(rng, i, int(rng.integers(1, 9))) for i in range(40)]
    fitted.insert(3, FittedPath(99, 1, False, ()))  # a path without segments: nothing drawn
    tol = 0.003
    curve = pv.fitted_curve(fitted, tol)
    want = pv.nan_join((pv.flatten_segments([(s.kind, s.points) for s in fp.segments], tol)
                        for fp in fitted), (fp.source_index for fp in fitted))
    assert np.array_equal(curve.ids, want.ids)
    assert np.array_equal(np.isnan(curve.xy), np.isnan(want.xy))
    assert np.nanmax(np.abs(curve.xy - want.xy)) < 1e-9
    assert 99 not in curve.ids
    xy, role = pv.control_layer(fitted)
    anchors = np.concatenate([np.vstack([fp.segments[0].points[:1]]
                                        + [s.points[-1:] for s in fp.segments])
                              for fp in fitted if fp.segments])
    assert np.array_equal(xy[role == 1], anchors)
    handles = [np.vstack([s.points[0:2], s.points[2:4]]) for fp in fitted
               for s in fp.segments if s.kind == "cubic"]
    assert np.array_equal(xy[role == 2], np.concatenate([h[1:3] for h in handles]))
    assert np.array_equal(xy[role == 0], np.concatenate([h[[0, 3]] for h in handles]))


def test_control_layer_roles(run):
    _, _, _, fitted = run
    xy, role = pv.control_layer(fitted)
    assert len(xy) == len(role)
    assert np.isnan(xy[role == -1]).all()
    assert np.isfinite(xy[role >= 0]).all()
    n_cubics = sum(fp.n_cubics for fp in fitted)
    assert int((role == 2).sum()) == 2 * n_cubics  # P1 and P2 of every cubic
    inner = xy[role == 2]
    want = np.concatenate([s.points[1:3] for fp in fitted for s in fp.segments
                           if s.kind == "cubic"])
    assert np.array_equal(inner, want)
    anchors = xy[role == 1]
    n_segments = sum(len(fp.segments) for fp in fitted)
    assert len(anchors) == n_segments + len(fitted)  # each joint once, plus each start


def test_deviation_is_true_error_and_bounded_by_the_fit(circle, run):
    _, params, _, fitted = run
    a, b, err = pv.deviation_samples(circle, fitted)
    assert a.shape == b.shape and len(err) == len(a) > 0
    assert err.max() <= max(params.e_per, params.eps_line) * 1.001
    assert err.min() >= 0


def test_deviation_sees_a_bad_fit():
    pts = np.c_[np.linspace(0, 100, 11), np.zeros(11)]
    d = Drawing(paths=(Path.from_points(pts),))
    bulge = np.array([[0.0, 0.0], [30.0, 8.0], [70.0, 8.0], [100.0, 0.0]])
    fp = FittedPath(0, 1, False, (Segment("cubic", bulge, 0, 10),), 6.0, 11)
    _, _, err = pv.deviation_samples(d, (fp,))
    assert err.max() == pytest.approx(6.0, abs=0.1)  # the bulge's height, 0.75 * 8


def test_deviation_can_be_cancelled(circle, run):
    with pytest.raises(Cancelled):
        pv.deviation_samples(circle, run[3], cancel=lambda: True)


# --- job geometry ------------------------------------------------------------------------
def test_marks_jumps_hatch_from_strokes():
    s1 = Stroke("contour", 0, False, np.array([[0, 0], [10, 0]]))
    s2 = Stroke("contour", 1, False, np.array([[20, 5], [30, 5], [30, 9]]))
    h = Stroke("hatch", 1, False, np.array([[21, 6], [29, 6]]))
    job = _job([s1, s2, h])
    marks, ids = pv.mark_points(job)
    assert len(marks) == 7 and ids.tolist() == [0, 0, 1, 1, 1, 1, 1]
    jumps = pv.jump_segments(job)
    assert jumps.shape == (5, 2)
    assert jumps[0].tolist() == [10, 0] and jumps[1].tolist() == [20, 5]
    assert np.isnan(jumps[2]).all()
    assert jumps[3].tolist() == [30, 9] and jumps[4].tolist() == [21, 6]
    hatch = pv.hatch_polylines(job)
    assert hatch.n_vertices == 2 and set(hatch.ids[hatch.ids >= 0]) == {1}
    assert len(pv.jump_segments(_job([s1]))) == 0


def test_kerf_layer_only_when_kerf_is_set():
    seg = (("line", np.array([[0.0, 0.0], [100.0, 0.0]])),)
    s = Stroke("contour", 0, False, np.array([[100, 200], [300, 200]]), seg)
    off = pv.build_preview(_job([s], kerf_mm=0.0))
    on = pv.build_preview(_job([s], kerf_mm=0.1))
    assert len(off.kerf) == 0
    assert on.kerf.n_vertices == 2
    # without a fit the fitted-curve layer shows the job's stored segments
    assert off.fitted.n_vertices == 2


def test_preview_of_a_run_lines_up_in_mm(circle, run):
    _, params, job, fitted = run
    p = pv.build_preview(job, circle, fitted)
    fm = job.field_map
    # the original points and the marks are in the same workpiece mm
    o_mm = p.units_to_mm(p.original_points)
    m_mm = p.marks * p.mm_per_bit
    assert pv.bbox(o_mm) == pytest.approx(pv.bbox(m_mm), abs=2 * fm.mm_per_bit)
    assert p.bounds is not None
    assert p.bounds[0] <= pv.bbox(o_mm)[0] + 1e-9
    assert p.n_control_points > 0
    assert len(p.deviation_level) == len(p.deviation_err) > 0
    assert 0 <= p.deviation_level.min() and p.deviation_level.max() <= 1
    # the bound in effect: e_per beyond the file's rounding (its grid's half diagonal)
    q = job.params["quantum_units"]
    assert p.tolerance_um == pytest.approx((0.05 + q / 2**0.5) * fm.mm_per_unit * 1000)
    assert len(p.hatch) == 0 and len(p.kerf) == 0
    # hover: mm -> units -> mm
    assert p.units_to_mm(p.mm_to_units(np.array([12.5, 40.0]))) == pytest.approx([12.5, 40.0])


def test_resample_only_run_reuses_the_fit_geometry(circle):
    pipe = Pipeline()
    cache = pv.PreviewCache()
    p1 = Params(magnification=20.0)
    j1 = pipe.run(circle, p1).job
    a = pv.build_preview(j1, circle, pipe.fitted(circle, p1), cache=cache)
    p2 = p1.replace(magnification=40.0)
    j2 = pipe.run(circle, p2).job
    b = pv.build_preview(j2, circle, pipe.fitted(circle, p2), cache=cache)
    assert b.fitted.xy is a.fitted.xy  # same arrays: the GUI changes only the transform
    assert b.control_xy is a.control_xy and b.original.xy is a.original.xy
    assert b.deviation_level is a.deviation_level
    assert b.units_scale == pytest.approx(2 * a.units_scale)
    assert len(b.marks) > len(a.marks)


def test_empty_job_and_drawing():
    fm = FieldMap(1.0, (0.0, 0.0), 65536, 110.0)
    job = _job([], fm)
    p = pv.build_preview(job, Drawing(paths=()), ())
    assert p.bounds is None
    assert len(p.marks) == 0 and len(p.fitted) == 0 and len(p.control_xy) == 0
    assert p.pick(1.0, 1.0, 5.0) is None
    assert p.path_bounds(0) is None


def test_pick_and_path_bounds(circle, run):
    _, _, job, fitted = run
    p = pv.build_preview(job, circle, fitted)
    x, y = p.units_to_mm(circle.paths[0].points[0])
    assert p.pick(x + 0.01, y, 0.5) == 0
    assert p.pick(x + 500.0, y, 0.5) is None
    box = p.path_bounds(0)
    assert box is not None and box[0] <= x <= box[2]
    left, right = p.path_geometry(0)
    assert len(left) == len(circle.paths[0].points) and len(right) > 0


def test_path_for_position_and_summary(run, circle):
    paths = tuple(Path.from_points([(i, 0), (i, 1)], start=SourcePos(2 + 3 * i, 1))
                  for i in range(4))
    d = Drawing(paths=paths)
    assert pv.path_for_position(d, 2, 1) == 0
    assert pv.path_for_position(d, 6, 9) == 1  # after path 1 started, before path 2
    assert pv.path_for_position(d, 1, 1) == 0  # before everything: the first
    assert pv.path_for_position(d, 99, 1) == 3
    assert pv.path_for_position(Drawing(paths=()), 1, 1) is None
    _, _, job, fitted = run
    info = pv.path_summary(0, job, circle, fitted)
    assert info["input_points"] == len(circle.paths[0].points)
    assert info["mark_points"] == len(job.strokes[0].marks)
    assert info["control_points"] > 0 and info["mark_length_mm"] > 0


def test_display_tolerance_follows_the_fit_tolerance():
    assert pv.display_tolerance({"e_per": 0.04, "eps_line": 0.08}, None) == pytest.approx(0.01)
    assert pv.display_tolerance({}, None) == pytest.approx(0.005)
