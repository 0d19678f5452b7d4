"""Marking points (issue 5): chord heights measured against the true curve, minimum and
maximum step, counts, the 3-D step search, the fixed and raw baselines."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _util import SAMPLES, circle_plt
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from galvo_core.errors import ParamError
from galvo_core.field import FieldMap
from galvo_core.fit import FittedPath, Segment
from galvo_core.hpgl import read_bytes, read_file
from galvo_core.params import Params
from galvo_core.pipeline import Pipeline
from galvo_core.sample import (
    E_MIN_RATIO,
    ROUNDING_BOUND_BITS,
    chord_heights,
    sample_curve,
    sample_path,
    sample_paths,
)

FM = FieldMap(1.0, (0.0, 0.0), 1 << 20, 110.0 * 16)  # 1 input unit = 1 bit, a huge field


def _path(*segs: tuple[str, list[list[float]]], closed: bool = False) -> FittedPath:
    return FittedPath(0, 1, closed, tuple(Segment(k, np.asarray(p, float), 0, 1)
                                          for k, p in segs), 0.0, 0)


def _bezier(ctrl: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Independent Bernstein evaluation (any dimension)."""
    t = t[:, None]
    s = 1.0 - t
    return s**3 * ctrl[0] + 3 * s * s * t * ctrl[1] + 3 * s * t * t * ctrl[2] + t**3 * ctrl[3]


def _brute_heights(fp: FittedPath, res, fm: FieldMap = FM, n: int = 400) -> np.ndarray:
    """Chord heights of one sampled path by dense sampling of the true curve (float marks)."""
    sid, t = res.params[0]
    pos = res.float_marks[0]
    ctrl = [fm.to_bits_float(s.points) for s in fp.segments]
    out = []
    for i in range(len(t) - 1):
        pts = []
        for g in range(int(sid[i]), int(sid[i + 1]) + 1):
            lo = t[i] if g == sid[i] else 0.0
            hi = t[i + 1] if g == sid[i + 1] else 1.0
            if hi <= lo:
                continue
            c = ctrl[g]
            if len(c) == 2:
                c = np.array([c[0], c[0] + (c[1] - c[0]) / 3, c[0] + 2 * (c[1] - c[0]) / 3,
                              c[1]])
            pts.append(_bezier(c, np.linspace(lo, hi, n)))
        p = np.vstack(pts)
        a, b = pos[i], pos[i + 1]
        ab = b - a
        den = ab @ ab
        s = np.clip(((p - a) @ ab) / den, 0, 1) if den > 0 else np.zeros(len(p))
        out.append(np.hypot(*(p - a - s[:, None] * ab).T).max())
    return np.asarray(out)


coord = st.floats(-3000, 3000, allow_nan=False)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(ctrl=st.lists(st.tuples(coord, coord), min_size=4, max_size=4),
       tol=st.sampled_from([0.25, 1.0, 3.0]))
# a cusp folded back on itself (found by hypothesis)
@example(ctrl=[(0.0, 0.0), (0.0, 21.0), (0.0, 0.0), (2.0, 0.0)], tol=0.25)
def test_chord_height_within_bound_on_random_cubics(ctrl, tol):
    c = np.asarray(ctrl, float) + 5000.0
    assume(np.ptp(c, axis=0).max() > 20.0)
    fp = _path(("cubic", c.tolist()))
    # a minimum step >= √2 means no two marks round to the same bit (no dedup changes the
    # chords); only the minimum step may exceed the tolerance, at cusps, and is counted
    res = sample_paths([fp], FM, chord_tol_bits=tol, min_step_bits=1.5)
    rep = res.report
    h = _brute_heights(fp, res)
    assert (h > tol * (1 + 1e-9) + 1e-9).sum() <= rep.min_step_overrides
    assert rep.chord_violations <= rep.min_step_overrides
    if rep.min_step_overrides == 0:
        assert rep.max_chord_height_bits <= tol * (1 + 1e-9)
    # the closed form is never below the truth
    assert rep.max_chord_height_bits >= h.max(initial=0.0) - 1e-6
    # rounding adds at most √2/2
    assert rep.max_chord_height_int_bits <= rep.max_chord_height_bits + ROUNDING_BOUND_BITS + 1e-9
    # first and last marks are the curve's ends, exactly (rounded)
    m = res.marks[0]
    assert m[0].tolist() == FM.to_bits(c[:1])[0].tolist()
    assert m[-1].tolist() == FM.to_bits(c[3:])[0].tolist()


def test_closed_form_chord_height_matches_dense_sampling():
    rng = np.random.default_rng(7)
    ctrl = rng.uniform(0, 1000, (300, 4, 2))
    coef = np.stack([-ctrl[:, 0] + 3 * ctrl[:, 1] - 3 * ctrl[:, 2] + ctrl[:, 3],
                     3 * ctrl[:, 0] - 6 * ctrl[:, 1] + 3 * ctrl[:, 2],
                     3 * (ctrl[:, 1] - ctrl[:, 0]), ctrl[:, 0]], axis=1)
    ta = rng.uniform(0, 1, 300)
    tb = np.minimum(1, ta + rng.uniform(0, 0.3, 300))
    H, L = chord_heights(coef, ta, tb)
    for i in range(300):
        p = _bezier(ctrl[i], np.linspace(ta[i], tb[i], 3001))
        a, b = p[0], p[-1]
        ab = b - a
        raw = ((p - a) @ ab) / (ab @ ab)
        s = np.clip(raw, 0, 1)
        true = np.hypot(*(p - a - s[:, None] * ab).T).max()
        assert H[i] >= true - 1e-9  # never optimistic
        assert L[i] == pytest.approx(np.hypot(*ab))
        if raw.min() >= 0 and raw.max() <= 1:  # the curve stays over its chord: exact
            assert H[i] == pytest.approx(true, rel=1e-4, abs=1e-6)


def _circle_funcs(r: float):
    def f(t):
        return np.stack([r * np.cos(t), r * np.sin(t)], axis=1)

    def df(t):
        return np.stack([-r * np.sin(t), r * np.cos(t)], axis=1)

    def ddf(t):
        return np.stack([-r * np.cos(t), -r * np.sin(t)], axis=1)

    return f, df, ddf


@pytest.mark.parametrize("r,tol", [(50.0, 1.0), (1000.0, 1.0), (20000.0, 0.25), (3.0, 0.5)])
def test_circle_chord_heights_have_their_closed_form(r, tol):
    s = sample_curve(*_circle_funcs(r), 0.0, 2 * math.pi, e_min=E_MIN_RATIO * tol, e_max=tol)
    dth = np.diff(s.t)
    exact = r * (1 - np.cos(dth / 2))  # chord height of an arc of angle Δθ
    np.testing.assert_allclose(s.heights, exact, rtol=1e-6, atol=1e-9)
    assert exact.max() <= tol * (1 + 1e-9)
    assert (exact[:-1] >= E_MIN_RATIO * tol * (1 - 1e-9)).all()  # every step but the last long
    # the fewest chords of height <= tol: ceil(2π / θmax), θmax = 2·arccos(1 − tol/r)
    best = math.ceil(2 * math.pi / (2 * math.acos(max(-1.0, 1 - tol / r))))
    assert best <= len(dth) <= math.ceil(best * 1.06)


def test_helix_in_3d():
    r, c = 200.0, 30.0  # curvature r / (r² + c²)

    def f(t):
        return np.stack([r * np.cos(t), r * np.sin(t), c * t], axis=1)

    def df(t):
        return np.stack([-r * np.sin(t), r * np.cos(t), np.full_like(t, c)], axis=1)

    def ddf(t):
        return np.stack([-r * np.cos(t), -r * np.sin(t), np.zeros_like(t)], axis=1)

    s = sample_curve(f, df, ddf, 0.0, 6 * math.pi, e_min=0.9, e_max=1.0, min_step=2.0)
    assert s.points.shape[1] == 3
    dt = np.diff(s.t)
    # by symmetry the farthest point of a helix arc from its chord is the arc's middle,
    # at distance r(1 − cos(Δ/2)) (the radial offset, perpendicular to the chord)
    exact = r * (1 - np.cos(dt / 2))
    np.testing.assert_allclose(s.heights, exact, rtol=1e-6)
    assert s.heights.max() <= 1.0 and (s.heights[:-1] >= 0.9).all()
    assert s.points[0] == pytest.approx([r, 0, 0]) and s.t[-1] == 6 * math.pi
    # a uniform helix gets (nearly) uniform steps
    assert np.ptp(dt[:-1]) < 0.05 * dt[:-1].mean()


def test_3d_cubic_and_2d_cubic_through_the_generic_search():
    ctrl3 = np.array([[0, 0, 0], [300, 900, 100], [900, -400, 600], [1200, 500, -200.0]])
    p = ctrl3
    d1 = 3 * np.array([p[1] - p[0], p[2] - p[1], p[3] - p[2]])
    d2 = 6 * np.array([p[2] - 2 * p[1] + p[0], p[3] - 2 * p[2] + p[1]])

    def f(t):
        return _bezier(p, t)

    def df(t):
        t = t[:, None]
        return (1 - t) ** 2 * d1[0] + 2 * (1 - t) * t * d1[1] + t * t * d1[2]

    def ddf(t):
        t = t[:, None]
        return (1 - t) * d2[0] + t * d2[1]

    s = sample_curve(f, df, ddf, 0.0, 1.0, e_min=0.45, e_max=0.5)
    # every chord checked against a dense sampling in 3-D
    for i in range(len(s.t) - 1):
        q = f(np.linspace(s.t[i], s.t[i + 1], 800))
        a, b = q[0], q[-1]
        u = (b - a) / np.linalg.norm(b - a)
        dd = q - a
        perp = dd - (dd @ u)[:, None] * u
        assert np.linalg.norm(perp, axis=1).max() <= 0.5 + 1e-9
    # the 2-D projection, sampled by the generic search and by the closed-form path sampler,
    # gives the same marks: one step search, two measurements of the same chord height
    p = ctrl3[:, :2]
    d1 = d1[:, :2]
    d2 = d2[:, :2]
    s2 = sample_curve(f, df, ddf, 0.0, 1.0, e_min=E_MIN_RATIO * 0.5, e_max=0.5)
    res = sample_paths([_path(("cubic", p.tolist()))], FM, chord_tol_bits=0.5,
                       min_step_bits=0.0)
    np.testing.assert_allclose(res.params[0][1], s2.t, atol=1e-6)


def test_min_step_respected_and_overrides_counted_at_a_tight_bend():
    # a bend of radius 3 bits between two long lines: at tol 0.05 the tolerance would want
    # 0.8-bit chords there
    k = 0.5523 * 3
    fp = _path(("line", [[0, 0], [1000, 0]]),
               ("cubic", [[1000, 0], [1000 + k, 0], [1003, 3 - k], [1003, 3]]),
               ("line", [[1003, 3], [1003, 1000]]))
    res = sample_paths([fp], FM, chord_tol_bits=0.05, min_step_bits=2.0)
    steps = np.hypot(*np.diff(res.float_marks[0], axis=0).T)
    assert (steps[:-1] >= 2.0 * 0.999).all()
    assert res.report.min_step_overrides > 0
    assert res.report.chord_violations <= res.report.min_step_overrides
    res0 = sample_paths([fp], FM, chord_tol_bits=0.05, min_step_bits=0.0)
    steps0 = np.hypot(*np.diff(res0.float_marks[0], axis=0).T)
    assert steps0.min() < 1.5  # (0.8-bit chords, some merged by rounding to whole bits)
    # the generic search on a circle of radius 1.5: the same rule
    s = sample_curve(*_circle_funcs(1.5), 0.0, 2 * math.pi, e_min=0.045, e_max=0.05,
                     min_step=2.0)
    assert (s.lengths[:-1] >= 2.0 * 0.999).all() and s.overrides > 0


def test_min_step_keeps_corners_and_drops_smooth_joint_marks():
    # a tiny line between two lines at right angles: its ends are corners, kept
    fp = _path(("line", [[0, 0], [1000, 0]]), ("line", [[1000, 0], [1000, 1]]),
               ("line", [[1000, 1], [0, 1]]))
    m = sample_path(fp, FM, min_step_bits=2.0)
    assert m.tolist() == [[0, 0], [1000, 0], [1000, 1], [0, 1]]
    # a straight run cut into short collinear pieces: the inner joints go
    fp = _path(*[("line", [[i, 0.0], [i + 1.0, 0.0]]) for i in range(10)])
    m = sample_path(fp, FM, min_step_bits=2.5)
    steps = np.hypot(*np.diff(m, axis=0).T)
    assert (steps[:-1] >= 2.5).all() and m[0].tolist() == [0, 0] and m[-1].tolist() == [10, 0]


def _circle_quarters(r: float, c: float = 50_000.0) -> list[tuple[str, list[list[float]]]]:
    k = 4.0 / 3.0 * math.tan(math.pi / 8.0) * r
    out = []
    for q in range(4):
        a0, a1 = q * math.pi / 2, (q + 1) * math.pi / 2
        p0 = np.array([math.cos(a0), math.sin(a0)]) * r + c
        p3 = np.array([math.cos(a1), math.sin(a1)]) * r + c
        t0 = np.array([-math.sin(a0), math.cos(a0)])
        t3 = np.array([-math.sin(a1), math.cos(a1)])
        out.append(("cubic", [p0.tolist(), (p0 + k * t0).tolist(), (p3 - k * t3).tolist(),
                              p3.tolist()]))
    return out


@pytest.mark.parametrize("r", [300.0, 500.0, 20000.0])
def test_smooth_joints_are_not_forced_marks(r):
    """A circle drawn as four cubics meeting smoothly is sampled as one curve: chords run
    across the joints (measured against both cubics), so it takes no more chords than one
    circle needs. (Very long runs are cut at a joint every few dozen marks; the count bound
    holds there too.)"""
    tol = 1.0
    fp = _path(*_circle_quarters(r), closed=True)
    res = sample_paths([fp], FM, chord_tol_bits=tol, min_step_bits=2.0)
    chords = len(res.marks[0]) - 1
    # every chord but the last is at least E_MIN_RATIO·tol high; the cubic's radius differs
    # from r by < 0.03 %
    th_min = 2 * math.acos(1 - E_MIN_RATIO * tol / (r * 1.0003))
    assert chords <= math.ceil(2 * math.pi / th_min) + 1
    if r < 1000:  # short: one curve, the three inner joints all spanned by a chord
        sid, t = res.params[0]
        spans = np.sum(sid[1:] != sid[:-1] + (t[:-1] >= 1.0))
        assert spans == 3
    assert _brute_heights(fp, res).max() <= tol * (1 + 1e-9)
    assert res.report.max_chord_height_bits <= tol * (1 + 1e-9)
    assert res.report.chord_violations == 0


def test_a_corner_between_cubics_keeps_its_mark():
    """Cubics meeting at a corner are separate curves: the corner point is a mark."""
    a = ("cubic", [[0, 0], [300, 400], [700, 400], [1000, 0]])
    b = ("cubic", [[1000, 0], [1300, 400], [1700, 400], [2000, 0]])  # turns by ~106°
    m = sample_path(_path(a, b), FM, min_step_bits=2.0)
    assert [1000, 0] in m.tolist()


def test_a_mark_too_close_to_keep_goes_where_the_tolerance_still_holds():
    """A 1.4-bit line between a cubic and a chain of cubics (from a real nesting file): its
    end mark is closer than the minimum step to the cubic's end, but dropping it would let
    the next chord cut the bend by more than the tolerance; the filter drops the mark
    before it instead, so no chord breaks the tolerance and no mark is closer than the
    minimum step."""
    fp = _path(("line", [[51.96, 63.31], [50.96, 70.52]]),
               ("line", [[50.96, 70.52], [47.68, 85.56]]),
               ("cubic", [[47.68, 85.56], [46.56, 89.52], [45.54, 92.58], [44.21, 95.96]]),
               ("line", [[44.21, 95.96], [43.67, 97.24]]),
               ("cubic", [[43.67, 97.24], [41.95, 101.04], [39.76, 105.26], [37.92, 108.27]]),
               ("cubic", [[37.92, 108.27], [35.79, 111.76], [33.75, 114.59], [30.9, 118.03]]),
               ("cubic", [[30.9, 118.03], [23.75, 126.63], [14.94, 134.23], [4.54, 140.74]]))
    res = sample_paths([fp], FM, chord_tol_bits=1.0, min_step_bits=2.0)
    assert _brute_heights(fp, res).max() <= 1.0 + 1e-9
    assert res.report.chord_violations == 0
    steps = np.hypot(*np.diff(res.float_marks[0], axis=0).T)
    assert steps[:-1].min() >= 2.0


def test_lines_are_their_end_points_and_max_step_splits():
    fp = _path(("line", [[0, 0], [1000, 0]]), ("line", [[1000, 0], [1000, 1000]]))
    assert sample_path(fp, FM).tolist() == [[0, 0], [1000, 0], [1000, 1000]]
    m = sample_path(fp, FM, max_step_bits=300.0)
    steps = np.hypot(*np.diff(m, axis=0).T)
    assert len(m) == 1 + 4 + 4 and steps.max() <= 300
    # chords of a cubic are capped too
    big = _path(("cubic", [[0, 0], [4000, 3000], [8000, 3000], [12000, 0]]))
    res = sample_paths([big], FM, max_step_bits=500.0)
    steps = np.hypot(*np.diff(res.float_marks[0], axis=0).T)
    assert steps.max() <= 500 * (1 + 1e-9)
    assert res.report.max_chord_height_bits <= 1.0


def test_counts_grow_with_magnification_and_shrink_with_tolerance():
    d = read_bytes(circle_plt(), "circle.plt")
    pipe = Pipeline()
    n = [pipe.run(d, Params(magnification=m)).job.stats["mark_points"] for m in (5, 10, 20, 40)]
    assert n == sorted(n) and len(set(n)) == 4
    # chords scale like sqrt(r / tol): four times the magnification, about twice the marks
    assert 1.7 < n[3] / n[1] < 2.3
    t = [pipe.run(d, Params(magnification=30, chord_tol_bits=c)).job.stats["mark_points"]
         for c in (0.25, 1.0, 4.0)]
    assert t[0] > t[1] > t[2]
    assert 1.7 < t[0] / t[1] < 2.3


def test_paper_000_table_1_counts():
    """Paper 000 Table 1: curve_1181 gives 207 marks at 36x and 288 at 72x."""
    d = read_file(SAMPLES / "curve_1181.plt")
    pipe = Pipeline()
    for mag, paper in ((36, 207), (72, 288)):
        job = pipe.run(d, Params(magnification=mag)).job
        st_ = job.stats
        assert abs(st_["mark_points"] - paper) <= 0.05 * paper
        assert st_["max_chord_height_bits"] <= 1.0 and st_["chord_height_violations"] == 0
        assert st_["max_chord_height_int_bits"] <= 1.0 + ROUNDING_BOUND_BITS


def test_fixed_baseline_handles_vertical_curves_and_raw_is_the_input():
    # a semicircle-like cubic that goes vertical at both ends (slope dy/dx infinite)
    fp = _path(("cubic", [[0, 0], [0, 1000], [1000, 1000], [1000, 0]]))
    res = sample_paths([fp], FM, interpolation="fixed", fixed_step_bits=16,
                       fixed_slope_tol=0.05)
    m = res.marks[0]
    assert 5 < len(m) < 300 and np.isfinite(res.report.max_chord_height_bits)
    assert m[0].tolist() == [0, 0] and m[-1].tolist() == [1000, 0]
    # a tighter slope threshold gives more, shorter chords
    tight = sample_paths([fp], FM, interpolation="fixed", fixed_slope_tol=0.01)
    assert len(tight.marks[0]) > len(m)
    assert tight.report.max_chord_height_bits < res.report.max_chord_height_bits
    raw = np.array([[0.4, 0.2], [10.6, 0.0], [10.6, 0.2], [20, 5]])
    r = sample_paths([fp], FM, interpolation="raw", raw_points=[raw])
    assert r.marks[0].tolist() == [[0, 0], [11, 0], [20, 5]]
    assert r.report.max_chord_height_bits is None
    with pytest.raises(ParamError):
        sample_paths([fp], FM, interpolation="spline")


def test_empty_paths_and_dots():
    dot = _path(("line", [[5, 5], [5, 5]]))
    empty = FittedPath(1, 1, False, (), 0.0, 0)
    res = sample_paths([dot, empty, dot], FM)
    assert [m.tolist() for m in res.marks] == [[[5, 5]], [], [[5, 5]]]


def test_outside_points_counted_before_clamping():
    fm = FieldMap(1.0, (0.0, 0.0), 1000, 110.0)
    fp = _path(("line", [[10, 10], [1500, 10]]))
    res = sample_paths([fp], fm)
    assert res.report.outside_points == 1


def test_pipeline_stats_carry_the_measurements():
    d = read_file(SAMPLES / "curve_1181.plt")
    stats = Pipeline().run(d, Params(magnification=36)).job.stats
    for key in ("mark_points", "control_points", "strokes", "laser_switches",
                "mark_length_mm", "jump_length_mm", "estimated_time_s",
                "max_chord_height_bits", "max_chord_height_int_bits", "max_fit_error",
                "dwell_points", "outside_points", "min_step_overrides"):
        assert key in stats
    raw = Pipeline().run(d, Params(magnification=36, interpolation="raw")).job.stats
    assert raw["mark_points"] == 1181 and raw["max_chord_height_bits"] is None
    fixed = Pipeline().run(d, Params(magnification=36, interpolation="fixed")).job.stats
    assert fixed["max_chord_height_bits"] > 1.0  # the legacy method has no height bound


def _greedy_min_step(pts: np.ndarray, prot: np.ndarray, min_step: float) -> list[int]:
    """The minimum-step rule written as the plain loop over every mark (reference)."""
    keep = [0]
    for i in range(1, len(pts)):
        if math.dist(pts[i], pts[keep[-1]]) >= min_step:
            keep.append(i)
        elif prot[i]:
            while (len(keep) > 1 and not prot[keep[-1]]
                   and math.dist(pts[i], pts[keep[-1]]) < min_step):
                keep.pop()
            keep.append(i)
    return keep


def test_min_step_filter_walks_only_near_short_chords_with_the_same_result():
    from galvo_core.sample import _min_step_filter

    rng = np.random.default_rng(11)
    for trial in range(300):
        sizes = rng.integers(1, 40, rng.integers(1, 6))
        strokes, prots = [], []
        for n in sizes:
            steps = np.where(rng.random((n, 1)) < 0.3, rng.uniform(0, 2, (n, 2)),
                             rng.uniform(-8, 8, (n, 2)))
            strokes.append(np.cumsum(steps, axis=0))
            pr = rng.random(n) < 0.15
            pr[0] = pr[-1] = True
            prots.append(pr)
        pts = np.concatenate(strokes)
        prot = np.concatenate(prots)
        first = np.zeros(len(pts), dtype=bool)
        first[np.cumsum(sizes) - sizes] = True
        want = []
        for s0, s, pr in zip(np.cumsum(sizes) - sizes, strokes, prots, strict=True):
            want += [s0 + k for k in (_greedy_min_step(s, pr, 3.0) if len(s) >= 3
                                      else range(len(s)))]
        got = _min_step_filter(pts, prot, 3.0, first=first)
        assert got.tolist() == want, trial
        if len(sizes) == 1 and len(pts) >= 3:  # one stroke, no `first`
            assert _min_step_filter(pts, prot, 3.0).tolist() == want


def _strokes_case(rng: np.random.Generator, grid: bool
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random strokes (points, protected, first of a stroke); ``grid``: integer points, so
    that distances exactly equal to the minimum step (2.0) occur."""
    sizes = rng.integers(1, 40, rng.integers(1, 8))
    if grid:
        steps = rng.integers(-3, 4, (int(sizes.sum()), 2)).astype(np.float64)
    else:
        n = int(sizes.sum())
        steps = np.where(rng.random((n, 1)) < 0.4, rng.uniform(0, 1.5, (n, 2)),
                         rng.uniform(-6, 6, (n, 2)))
    pts = np.cumsum(steps, axis=0)
    first = np.zeros(len(pts), dtype=bool)
    first[np.cumsum(sizes) - sizes] = True
    last = np.r_[first[1:], True]
    prot = first | last | (rng.random(len(pts)) < 0.1)
    return pts, prot, first


def test_compiled_min_step_walk_keeps_what_the_python_walk_keeps():
    """The sampler's min-step pass walks every stroke compiled, with the chord questions
    answered beforehand; its marks and forced count must be the Python walk's, also where
    a question was not answered beforehand or a distance equals the minimum exactly."""
    from galvo_core.sample import _min_step_filter, _min_step_keep

    rng = np.random.default_rng(5)
    redone = 0
    for trial in range(400):
        pts, prot, first = _strokes_case(rng, grid=trial % 2 == 1)
        n = len(pts)
        salt = int(rng.integers(1, 1 << 30))

        def merge_ok(a: int, b: int, salt: int = salt) -> bool:
            return (a * 7919 + b * 104729 + salt) % 5 != 0  # a tolerance that often breaks

        ok2 = np.full(n, -1, dtype=np.int8)
        ok3 = np.full(n, -1, dtype=np.int8)
        answered = rng.random(n) < (0.7 if trial % 4 < 2 else 1.0)
        for a in np.flatnonzero(answered).tolist():
            if a + 2 < n:
                ok2[a] = merge_ok(a, a + 2)
            if a + 3 < n:
                ok3[a] = merge_ok(a, a + 3)
        dd = np.hypot(*np.diff(pts, axis=0).T)
        forced: list[int] = []
        want = _min_step_filter(pts, prot, 2.0, first=first, d=dd, merge_ok=merge_ok,
                                forced=forced)
        keep, nforced = _min_step_keep(pts, prot, first, dd, 2.0, ok2, ok3, merge_ok)
        assert np.flatnonzero(keep).tolist() == want.tolist(), trial
        assert nforced == len(forced), trial
        redone += int(not answered.all())
    assert redone > 0


def test_strokes_are_split_into_the_rows_of_each_path():
    from galvo_core.sample import _SAME_RUN, _split_rows

    rng = np.random.default_rng(2)
    for trial in range(60):
        runs = [(int(rng.integers(0, 5)), int(rng.integers(1, 3 * _SAME_RUN)))
                for _ in range(rng.integers(1, 6))]
        lens = np.concatenate([np.full(k, m) for m, k in runs]).astype(np.int64)
        pc = np.r_[0, np.cumsum(lens)]
        r = rng.integers(0, 100, (int(pc[-1]), 2))
        got = _split_rows(r, pc)
        assert len(got) == len(lens), trial
        for x, a, b in zip(got, pc[:-1].tolist(), pc[1:].tolist(), strict=True):
            assert x.shape == (b - a, 2) and np.array_equal(x, r[a:b]), trial


def test_a_stroke_end_rounded_onto_its_twin_keeps_the_true_end():
    """Two marks rounding to the same integer mark at a stroke's end: the end stays and
    its twin before it goes (unless the twin is the stroke's start)."""
    from galvo_core.sample import _MarkRows, _rounded

    pos = np.array([[0.0, 0.0], [10.2, 0.0], [10.4, 0.1], [10.1, 0.2],  # stroke 1
                    [20.0, 0.0], [20.3, 0.0],                            # stroke 2: a dot
                    [30.0, 0.0], [40.0, 0.0], [40.2, 0.0]])              # stroke 3
    pid = np.array([0, 0, 0, 0, 1, 1, 2, 2, 2])
    first = np.r_[True, pid[1:] != pid[:-1]]
    last = np.r_[pid[1:] != pid[:-1], True]
    n = len(pid)
    mk = _MarkRows(np.arange(n), np.linspace(0.1, 1, n), pos, pid, np.full(n, np.nan),
                   np.full(n, np.nan), first, last, first | last)
    r, out = _rounded(mk)
    # stroke 1: marks 1, 2, 3 round to (10, 0): 1 and 2 go, the true end 3 stays
    # stroke 2: the twin is the start: the end goes; stroke 3: 7 goes, 8 stays
    assert out.st.tolist() == mk.st[[0, 3, 4, 6, 8]].tolist()
    assert r.tolist() == [[0, 0], [10, 0], [20, 0], [30, 0], [40, 0]]
    assert out.last_of.tolist() == [False, True, True, False, True]


def test_exact_integer_maximum_is_the_largest_of_all_chords_measured():
    """The sampler measures only the integer chords whose bound can hold the maximum, in
    batches: the value must be the largest exact height over every chord, whatever the
    bounds (any upper bounds) and however many chords there are."""
    from galvo_core.sample import _CubicSet, _int_heights_exact, _max_int_heights

    rng = np.random.default_rng(9)
    for trial, n in enumerate((5, 3000, 6000)):
        coef = rng.normal(0, 20, (n, 4, 2))
        cs = _CubicSet(coef)
        sa = np.arange(n)
        ta = rng.uniform(0, 0.5, n)
        tb = ta + rng.uniform(0.01, 0.5, n)
        pts = cs.point(sa, ta)
        rf = np.round(pts + rng.normal(0, 0.3, pts.shape))
        rf = np.r_[rf, rf[-1:]]  # chord i: rf[i] -> rf[i + 1]
        exact = _int_heights_exact(cs, sa, ta, sa, tb, rf[:-1], rf[1:])
        counts = rng.random(n) < 0.9
        counts[0] = True
        # upper bounds: the exact value plus any slack, most of them far above the answer
        bound = np.where(counts, exact + rng.exponential(3.0, n), -np.inf)
        got = _max_int_heights(cs, bound, sa, ta, sa, tb, rf, int(counts.sum()))
        assert got == float(exact[counts].max()), trial


def test_reported_heights_equal_a_fresh_closed_form_measurement():
    """The sampler reuses the step search's own measurement of each chord (and takes 0 for
    a chord on a line): the report must be what measuring every chord again gives."""
    rng = np.random.default_rng(3)
    paths = []
    for i in range(40):
        c = rng.uniform(0, 3000, (4, 2)) + 5000.0
        segs = [("cubic", c.tolist()), ("line", [c[3].tolist(), (c[3] + [40.0, 3.0]).tolist()])]
        paths.append(FittedPath(i, 1, False, tuple(Segment(k, np.asarray(p, float), 0, 1)
                                                  for k, p in segs), 0.0, 0))
    for tol, ms, mx in ((1.0, 2.0, None), (0.25, 0.0, 7.0), (0.5, 6.0, None)):
        res = sample_paths(paths, FM, chord_tol_bits=tol, min_step_bits=ms, max_step_bits=mx)
        hs, spanning = [], 0
        for sid, t in res.params:
            for i in range(len(t) - 1):
                sa, ta = int(sid[i]), float(t[i])
                if ta >= 1.0 and sid[i + 1] > sa:
                    sa, ta = sa + 1, 0.0
                if sa != sid[i + 1]:
                    spanning += 1
                    continue
                h, _ = chord_heights(res.coef[sa:sa + 1], np.array([ta]), np.array([t[i + 1]]))
                hs.append(float(h[0]))
        assert res.report.chords == sum(len(t) - 1 for _, t in res.params)
        assert res.report.max_chord_height_bits >= max(hs)
        if not spanning:
            assert res.report.max_chord_height_bits == max(hs)
            assert res.report.chord_violations == sum(h > tol * (1 + 1e-9) for h in hs)
        brute = max(_brute_heights(fp, _Single(res, i)).max(initial=0.0)
                    for i, fp in enumerate(paths))
        assert res.report.max_chord_height_bits >= brute - 1e-6


class _Single:
    """One stroke of a multi-path result, shaped like a one-path result for _brute_heights
    (segment ids made local to the path)."""

    def __init__(self, res, i: int) -> None:
        sid, t = res.params[i]
        self.params = [(sid - 2 * i, t)]
        self.float_marks = [res.float_marks[i]]


def test_resampling_a_cached_fit_gives_what_a_fresh_fit_gives():
    """Geometry and field-mapped arrays are kept per fit; results must not depend on it."""
    d = read_bytes(circle_plt(), "circle.plt")
    pipe = Pipeline()
    runs = [(m, c) for m in (10.0, 20.0, 10.0) for c in (1.0, 0.3)]
    for m, c in runs:
        p = Params(magnification=m, chord_tol_bits=c)
        assert pipe.run(d, p).job.stats == Pipeline().run(d, p).job.stats


@pytest.mark.parametrize("interpolation", ["adaptive", "fixed"])
def test_chunks_of_paths_give_what_one_batch_gives(monkeypatch, interpolation):
    """The sampler works on whole paths in chunks (bounded temporaries): chunks of a few
    segments give the same marks, parameters and report as one batch of every path."""
    import galvo_core.sample as sm
    from galvo_core.fit import fit_drawing

    d = read_file(SAMPLES / "seal.plt")
    fitted = list(fit_drawing(d))
    fm = FieldMap(0.2, (0.0, 0.0), 65536, 110.0)  # small: many marks closer than min step
    kw = dict(interpolation=interpolation, chord_tol_bits=0.5, min_step_bits=3.0)
    one = sm.sample_paths(fitted, fm, **kw)
    assert sum(len(fp.is_cubic) for fp in fitted) < sm.CHUNK_SEGMENTS
    monkeypatch.setattr(sm, "CHUNK_SEGMENTS", 5)
    many = sm.sample_paths(fitted, fm, **kw)
    assert len(many.marks) == len(one.marks) == len(fitted)
    for a, b in zip(one.marks, many.marks, strict=True):
        assert np.array_equal(a, b)
    for (sa, ta), (sb, tb) in zip(one.params, many.params, strict=True):
        assert np.array_equal(sa, sb) and np.array_equal(ta, tb)
    assert one.report == many.report
    assert one.report.min_step_overrides > 0 and one.report.chords > 0, one.report


def test_sampling_without_the_chunks_gives_the_same_marks_and_report():
    """``keep_chunks=False`` (the pipeline's call) drops only the float marks and
    parameters kept for tests: the marks and what was measured are the same."""
    from galvo_core.sample import sample_geometry

    d = read_file(SAMPLES / "seal.plt")
    p = Pipeline()
    params = Params(fit_field=True)
    fm = p.field_map(d, params)
    fitted = p.fitted(d, params, fm)
    full = sample_paths(fitted, fm, geometry=sample_geometry(fitted))
    lean = sample_paths(fitted, fm, geometry=sample_geometry(fitted), keep_chunks=False)
    assert full.chunks and not lean.chunks
    assert len(full.marks) == len(lean.marks) == len(fitted)
    assert all(np.array_equal(a, b) for a, b in zip(full.marks, lean.marks, strict=True))
    assert full.report == lean.report
