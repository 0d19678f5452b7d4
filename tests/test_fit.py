"""Line + cubic fitting (paper 000 §2–3): the two-sided guarantee, counts, degenerate input."""

from __future__ import annotations

import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from galvo_core.drawing import Drawing, Path
from galvo_core.errors import ParamError
from galvo_core.fit import (
    DEFAULT_E_PER,
    DEFAULT_EPS_LINE,
    FitCancelled,
    FittedPath,
    check_fit,
    control_points,
    fit_drawing,
    fit_path,
    fit_paths,
    fit_report,
    segment_point_offsets,
)
from galvo_core.geometry import cubic_eval
from galvo_core.precision import path_quanta

EPS = 0.02


def assert_valid(points, fp: FittedPath, *, e_per=EPS, eps_line=EPS, closed=False):
    points = np.asarray(points, float)
    segs = fp.segments
    assert segs, "no segments"
    # continuity: each starts exactly where the previous ended
    for s0, s1 in zip(segs[:-1], segs[1:], strict=True):
        assert np.array_equal(s0.points[-1], s1.points[0])
        assert s0.last == s1.first
    assert segs[0].first == 0
    assert np.array_equal(segs[0].points[0], points[0])
    n_ext = len(points) + (1 if closed and not np.array_equal(points[0], points[-1]) else 0)
    assert segs[-1].last == n_ext - 1
    if closed:
        assert fp.closed
        assert np.array_equal(segs[-1].points[-1], segs[0].points[0])
    for s in segs:
        assert s.kind in ("line", "cubic")
        assert s.points.shape == ((2, 2) if s.kind == "line" else (4, 2))
        assert s.points.dtype == np.float64
    # the bound is beyond the rounding of points on a grid (issue 16): + q/sqrt2
    tol = max(e_per, eps_line) + path_quanta([points])[0] * 0.5**0.5
    e_in, e_out = check_fit(points, fp, e_per, eps_line)
    assert e_in <= tol * (1 + 1e-6), f"input point {e_in} from its segment"
    assert e_out <= tol * (1 + 1e-6), f"curve {e_out} from the input polyline"
    assert fp.max_error <= tol * (1 + 1e-6)
    assert fp.max_error == pytest.approx(e_in, abs=1e-6)
    return e_in, e_out


def ring(p):
    p = np.asarray(p, float)
    return np.vstack([p, p[:1]])


# --- exact counts ---------------------------------------------------------------------


def test_sampled_triangle_cubic_fits_back_to_one_cubic():
    """A cubic of the paper's family (P1, P2 at the same fraction t of the triangle sides),
    60 degrees of turning, sampled densely: one cubic, its ends exact, its control points
    close to the original ones."""
    p0, q, p3 = np.array([0.0, 0.0]), np.array([150.0, 90.0]), np.array([300.0, 0.0])
    t = 0.55
    c = np.array([p0, p0 + t * (q - p0), p3 + t * (q - p3), p3])
    pts = cubic_eval(c, np.linspace(0, 1, 3000))
    fp = fit_path(pts, closed=False)
    assert [s.kind for s in fp.segments] == ["cubic"]
    assert (fp.segments[0].first, fp.segments[0].last) == (0, 2999)
    np.testing.assert_array_equal(fp.segments[0].points[[0, 3]], c[[0, 3]])
    np.testing.assert_allclose(fp.segments[0].points, c, atol=1.0)
    assert_valid(pts, fp)


def test_polygon_keeps_exactly_its_corners_as_lines():
    corners = np.array([[0, 0], [400, 0], [400, 250], [150, 380], [0, 250]], float)
    rc = ring(corners)
    dense = np.vstack(
        [
            rc[i] + np.linspace(0, 1, 80, endpoint=False)[:, None] * (rc[i + 1] - rc[i])
            for i in range(5)
        ]
        + [rc[:1]]
    )
    fp = fit_path(dense, closed=True)
    assert [s.kind for s in fp.segments] == ["line"] * 5
    np.testing.assert_array_equal(np.array([s.points[0] for s in fp.segments]), corners)
    assert_valid(dense, fp, closed=True)


def test_circle_1181_points_paper_sanity(capsys):
    t = np.linspace(0, 2 * np.pi, 1181)
    p = np.c_[400 * np.cos(t), 400 * np.sin(t)]
    p[-1] = p[0]
    t0 = time.perf_counter()
    fp = fit_path(p, closed=True)
    dt = time.perf_counter() - t0
    cp = control_points(fp)
    with capsys.disabled():
        print(
            f"\ncircle r=400, 1181 points -> {cp} control points ({fp.n_cubics} cubics, "
            f"{fp.n_lines} lines) in {dt * 1e3:.1f} ms; paper 000: 40"
        )
    assert fp.n_lines == 0
    assert cp <= 40  # at least as good as the paper
    assert_valid(p, fp, closed=True)


# --- shapes ---------------------------------------------------------------------------


def ellipse(n=2000, a=300, b=90):
    t = np.linspace(0, 2 * np.pi, n)
    p = np.c_[a * np.cos(t), b * np.sin(t)]
    p[-1] = p[0]
    return p


def spiral(n=3000):
    t = np.linspace(0.5, 6 * np.pi, n)
    return np.c_[10 * t * np.cos(t), 10 * t * np.sin(t)]


def s_curve(n=1500):
    x = np.linspace(0, 400, n)
    return np.c_[x, 60 * np.sin(x / 400 * 2 * np.pi)]


def rounded_rect(w=400, h=200, r=40, n_arc=60):
    pts = []
    for cx, cy, a0 in [
        (w - r, r, -np.pi / 2),
        (w - r, h - r, 0),
        (r, h - r, np.pi / 2),
        (r, r, np.pi),
    ]:
        a = np.linspace(a0, a0 + np.pi / 2, n_arc)
        pts.append(np.c_[cx + r * np.cos(a), cy + r * np.sin(a)])
    return ring(np.vstack(pts))


def glyph_d(n=400):
    """A 'D'-like outline: straight stem with corners, a bowl of half an ellipse."""
    stem = np.array([[0.0, 0.0], [0.0, 500.0]])
    a = np.linspace(np.pi / 2, -np.pi / 2, n)
    bowl = np.c_[0 + 300 * np.cos(a), 250 + 250 * np.sin(a)]
    return ring(np.vstack([stem[:1], stem[1:], bowl[1:-1]]))


@pytest.mark.parametrize(
    "name,points,closed",
    [
        ("ellipse", ellipse(), True),
        ("spiral", spiral(), False),
        ("s_curve", s_curve(), False),
        ("rounded_rect", rounded_rect(), True),
        ("glyph_d", glyph_d(), True),
    ],
)
def test_shapes_meet_the_guarantee(name, points, closed):
    fp = fit_path(points, closed=closed)
    assert_valid(points, fp, closed=closed)
    assert fp.n_cubics >= 1
    assert control_points(fp) < len(points) / 5


def test_rounded_rectangle_keeps_straight_sides_as_lines_and_corners_as_cubics():
    p = rounded_rect()
    fp = fit_path(p, closed=True)
    long_lines = [
        s for s in fp.segments if s.kind == "line" and np.hypot(*np.diff(s.points, axis=0)[0]) > 100
    ]
    assert len(long_lines) == 4
    assert fp.n_cubics >= 4


def test_glyph_stem_corners_stay_corners():
    p = glyph_d()
    fp = fit_path(p, closed=True)
    starts = np.array([s.points[0] for s in fp.segments])
    for corner in ([0.0, 0.0], [0.0, 500.0]):
        assert np.any(np.all(starts == corner, axis=1))
    # the stem itself is one line
    assert fp.segments[0].kind == "line"
    np.testing.assert_array_equal(fp.segments[0].points, [[0, 0], [0, 500]])


def test_closed_path_without_closing_point_is_closed():
    t = np.linspace(0, 2 * np.pi, 500, endpoint=False)
    p = np.c_[100 * np.cos(t), 100 * np.sin(t)]
    fp = fit_path(p, closed=True)
    assert fp.segments[-1].last == len(p)  # index N = point 0 again
    assert_valid(p, fp, closed=True)


# --- random smooth curves (hypothesis) -------------------------------------------------


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 100_000), st.integers(200, 1500), st.sampled_from([0.0, 0.002, 0.005]))
def test_random_sums_of_sines(seed, n, noise):
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(0, rng.uniform(100, 800), n))
    y = sum(
        rng.uniform(5, 60) * np.sin(x / rng.uniform(8, 80) + rng.uniform(0, 6)) for _ in range(3)
    )
    p = np.c_[x, y] + rng.normal(0, noise, (n, 2)) if noise else np.c_[x, y]
    fp = fit_path(p, closed=False)
    assert_valid(p, fp)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 100_000), st.integers(50, 1500), st.sampled_from([0.0, 0.003]))
def test_random_beziers_sampled_unevenly(seed, n, noise):
    rng = np.random.default_rng(seed)
    c = rng.uniform(-300, 300, (4, 2))
    t = np.sort(np.concatenate([[0, 1], rng.uniform(0, 1, n) ** rng.uniform(0.5, 2)]))
    p = cubic_eval(c, t) + (rng.normal(0, noise, (len(t), 2)) if noise else 0)
    fp = fit_path(p, closed=False)
    assert_valid(p, fp)


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 100_000), st.sampled_from([0.05, 0.5]), st.sampled_from([0.01, 0.1]))
def test_other_tolerances(seed, e_per, eps_line):
    """Any positive tolerances: the guarantee scales with them (sparse points, r = 20)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(30, 300))
    t = np.sort(rng.uniform(0, 2 * np.pi, n))
    p = np.c_[20 * np.cos(t) * rng.uniform(0.5, 2), 20 * np.sin(t)]
    fp = fit_path(p, closed=False, e_per=e_per, eps_line=eps_line)
    assert_valid(p, fp, e_per=e_per, eps_line=eps_line)


def test_sparse_points_do_not_let_the_curve_bulge():
    """Few points far apart on a sharp arc: any cubic through them would bulge between
    them, so the fit must fall back to lines or tight cubics, never a bulging curve."""
    t = np.linspace(0, np.pi / 2, 6)
    p = np.c_[100 * np.cos(t), 100 * np.sin(t)]
    fp = fit_path(p, closed=False)
    assert_valid(p, fp)


# --- parameters -----------------------------------------------------------------------


@pytest.mark.parametrize("name", ["eps_line", "e_per", "eps_sum"])
@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf"), float("-inf")])
def test_bad_parameters_refused_by_name(name, bad):
    with pytest.raises(ParamError, match=name):
        fit_path(np.zeros((3, 2)), closed=False, **{name: bad})
    with pytest.raises(ParamError, match=name):
        fit_drawing(Drawing((Path.from_points([[0, 0], [1, 1]]),)), **{name: bad})


def test_any_positive_value_accepted():
    p = s_curve(300)
    for v in (1e-9, 1e-3, 7.0, 1e6):
        fp = fit_path(p, closed=False, eps_line=v, e_per=v, eps_sum=v)
        assert_valid(p, fp, e_per=v, eps_line=v)


# --- degenerate input ------------------------------------------------------------------


def test_dot_is_one_zero_length_line():
    fp = fit_path([[5.0, 7.0]], closed=False)
    assert len(fp.segments) == 1
    s = fp.segments[0]
    assert s.kind == "line" and (s.first, s.last) == (0, 0)
    np.testing.assert_array_equal(s.points, [[5, 7], [5, 7]])
    assert control_points(fp) == 1


def test_repeated_point_and_zero_length_closed_path_are_dots():
    fp = fit_path([[1.0, 1.0]] * 6, closed=False)
    assert [(s.kind, s.first, s.last) for s in fp.segments] == [("line", 0, 5)]
    fpc = fit_path([[2.0, 3.0]] * 4, closed=True)
    assert fpc.closed and len(fpc.segments) == 1
    np.testing.assert_array_equal(fpc.segments[0].points, [[2, 3], [2, 3]])


def test_two_point_path_and_duplicates():
    fp = fit_path([[0.0, 0.0], [3.0, 4.0]], closed=False)
    assert [s.kind for s in fp.segments] == ["line"]
    p = np.array([[0, 0], [0, 0], [1, 0], [1, 0], [2, 0], [2, 0], [2, 5], [2, 5]], float)
    fp = fit_path(p, closed=False)
    # kept: the first of each run of repeats (0, 4, 6); repeats go with the next segment
    assert [(s.first, s.last) for s in fp.segments] == [(0, 4), (4, 7)]
    assert_valid(p, fp)


def test_collinear_run_is_one_line():
    x = np.linspace(0, 1000, 5001)
    fp = fit_path(np.c_[x, 2 * x + 1], closed=False)
    assert [s.kind for s in fp.segments] == ["line"]


@pytest.mark.parametrize("offset", [1e7, -1e7])
def test_huge_coordinates(offset):
    t = np.linspace(0, 2 * np.pi, 1500)
    p = offset + np.c_[300 * np.cos(t), 200 * np.sin(t)]
    p[-1] = p[0]
    fp = fit_path(p, closed=True)
    assert fp.n_cubics >= 4
    assert_valid(p, fp, closed=True)


def test_tiny_spacing():
    t = np.linspace(0, np.pi, 500)
    p = 1e-4 * np.c_[np.cos(t), np.sin(t)]  # spacing ~6e-7 units
    # default tolerance: the whole arc is within 0.02 of one line
    fp = fit_path(p, closed=False)
    assert [s.kind for s in fp.segments] == ["line"]
    assert_valid(p, fp)
    # tolerances scaled down with the drawing: cubics again
    fp = fit_path(p, closed=False, eps_line=1e-9, e_per=1e-9, eps_sum=1e-10)
    assert fp.n_cubics >= 2
    assert_valid(p, fp, e_per=1e-9, eps_line=1e-9)


def test_nan_points_refused():
    with pytest.raises(ParamError):
        fit_path([[0.0, 0.0], [np.nan, 1.0]], closed=False)


# --- drawing level --------------------------------------------------------------------


def test_fit_drawing_and_report():
    paths = (
        Path.from_points(ellipse(800), pen=2),
        Path.from_points([[1.0, 1.0]]),
        Path.from_points(s_curve(600)),
    )
    d = Drawing(paths, name="t.plt")
    fitted = fit_drawing(d)
    assert [f.source_index for f in fitted] == [0, 1, 2]
    assert [f.pen for f in fitted] == [2, 1, 1]
    assert fitted[0].closed and not fitted[2].closed
    for f, p in zip(fitted, paths, strict=True):
        assert f.n_input == len(p.points)
        assert_valid(p.points, f, closed=p.closed)
    rep = fit_report(d)
    assert rep["input_points"] == 800 + 1 + 600
    assert rep["control_points"] == sum(control_points(f) for f in fitted)
    assert rep["lines"] + rep["cubics"] == sum(len(f.segments) for f in fitted)
    assert 0 < rep["thinned_points"] < rep["input_points"]
    assert rep["max_error"] <= EPS
    assert rep["seconds"] >= 0


def _same_fit(a: FittedPath, b: FittedPath) -> bool:
    if (a.source_index, a.pen, a.closed, a.n_input, a.n_thinned, a.max_error) != (
        b.source_index,
        b.pen,
        b.closed,
        b.n_input,
        b.n_thinned,
        b.max_error,
    ) or len(a.segments) != len(b.segments):
        return False
    return all(
        x.kind == y.kind
        and x.first == y.first
        and x.last == y.last
        and np.array_equal(x.points, y.points)
        and not x.points.flags.writeable
        for x, y in zip(a.segments, b.segments, strict=True)
    )


def _mixed_drawing(seed: int) -> list[tuple[np.ndarray, bool]]:
    rng = np.random.default_rng(seed)
    out: list[tuple[np.ndarray, bool]] = [
        (np.zeros((0, 2)), False),
        (np.array([[1.0, 1.0]]), False),
        (np.array([[2.0, 2.0]] * 3), True),
        (np.array([[0.0, 0.0], [5.0, 0.0], [5.0, 0.0]]), False),
    ]
    for _ in range(20):
        kind = int(rng.integers(0, 4))
        if kind == 0:
            p = ellipse(int(rng.integers(50, 600)))
            out.append((p[:-1] if rng.random() < 0.5 else p, True))
        elif kind == 1:
            out.append((s_curve(int(rng.integers(100, 800))), False))
        elif kind == 2:  # integer staircase
            n = int(rng.integers(5, 60))
            out.append((np.cumsum(rng.integers(-3, 4, (n, 2)), axis=0).astype(float), False))
        else:  # an s-curve ending on repeats of its last point
            p = s_curve(300)
            out.append((np.vstack([p, p[-1:], p[-1:]]), False))
    return out


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("e_per", [0.02, 0.75])
def test_fit_paths_is_fit_path_per_path(seed, e_per):
    items = _mixed_drawing(seed)
    pts = [p for p, _ in items]
    cl = [c for _, c in items]
    many = fit_paths(
        pts,
        cl,
        e_per=e_per,
        source_indices=range(5, 5 + len(items)),
        pens=[1 + i % 3 for i in range(len(items))],
    )
    for i, ((p, c), f) in enumerate(zip(items, many, strict=True)):
        one = fit_path(p, closed=c, e_per=e_per, source_index=5 + i, pen=1 + i % 3)
        assert _same_fit(f, one), i
        if len(p):
            assert_valid(p, f, e_per=e_per, closed=c)


def test_fit_drawing_batches_and_cancel():
    items = _mixed_drawing(3)
    d = Drawing(
        tuple(
            Path.from_points(p, closed=c) if len(p) else Path.from_points([[0.0, 0.0]])
            for p, c in items
        )
    )
    whole = fit_drawing(d)
    small = fit_drawing(d, batch=3)
    assert all(_same_fit(a, b) for a, b in zip(whole, small, strict=True))
    assert [f.source_index for f in small] == list(range(len(items)))
    calls = []

    def cancel() -> bool:
        calls.append(1)
        return len(calls) > 2

    with pytest.raises(FitCancelled):
        fit_drawing(d, batch=3, cancel=cancel)
    assert len(calls) == 3


def test_core_does_not_import_qt():
    import subprocess
    import sys

    code = (
        "import sys, galvo_core.fit, galvo_core.thin, galvo_core.runs, galvo_core.geometry;"
        "bad=[m for m in sys.modules if m.startswith(('PySide6','pyqtgraph','PyQt'))];"
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_rounded_polygon_corners_move_onto_the_design():
    # a polygon at generic slopes, sampled every unit and rounded to whole units: the fit
    # puts its corners nearer the design's corners than the rounded input points are
    corners = np.array([[0.3, 0.2], [380.4, 130.45], [300.6, 370.35], [60.25, 400.4],
                        [-80.45, 200.7]])
    rc = ring(corners)
    parts = [rc[i] + np.linspace(0, 1, int(np.hypot(*(rc[i + 1] - rc[i]))),
                                 endpoint=False)[:, None] * (rc[i + 1] - rc[i])
             for i in range(5)]
    pts = np.round(np.vstack(parts + [rc[:1]]))
    pts = pts[np.r_[True, (np.diff(pts, axis=0) != 0).any(axis=1)]]
    fp = fit_path(pts, closed=True)
    joints = fp.points[segment_point_offsets(fp.is_cubic)]
    ours = np.array([np.hypot(*(joints - c).T).min() for c in corners])
    rounded = np.hypot(*(np.round(corners) - corners).T)
    assert (ours <= rounded + 1e-9).all()
    assert ours.mean() < 0.6 * rounded.mean()
    rep = check_fit(pts, fp, DEFAULT_E_PER, DEFAULT_EPS_LINE, report=True)
    assert rep["quantum_units"] == 1.0 and rep["violation"] == 0.0


def test_window_sums_equal_numpy_reduceat_bit_for_bit():
    """The local fits' per-window sums (compiled) are np.add.reduceat's numbers exactly
    (first term plus numpy's pairwise sum) of the powers s, s^2, s^2 s, s^2 s^2, for
    windows of 4 to 3000 points (blocks of 128, several levels of halving)."""
    from galvo_core.fit import _window_sums

    rng = np.random.default_rng(11)
    cnt = np.r_[4, 5, 8, 9, 127, 128, 129, 136, 255, 257, 1000, 3000, rng.integers(4, 400, 50)]
    n = int(cnt.sum()) + 10
    # windows lo..hi (inclusive, overlapping) of a path's input points W at arc lengths arc,
    # the fit's point ``at`` inside each: s scaled to (arc - arc[at]) / (arc[hi] - arc[lo])
    arc = np.cumsum(rng.uniform(0.0, 3.0, n))
    W = rng.normal(size=(n, 2)) * rng.lognormal(0.0, 4.0, size=(n, 1))
    lo = rng.integers(0, n - cnt)
    hi = lo + cnt - 1
    at = lo + rng.integers(0, cnt)
    mom, rx, ry = np.empty((5, len(cnt))), np.empty((3, len(cnt))), np.empty((3, len(cnt)))
    _window_sums(arc, W, lo, hi, at, mom, rx, ry)
    own = np.repeat(np.arange(len(cnt)), cnt)
    idx = lo[own] + np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    sv = (arc[idx] - arc[at][own]) / (arc[hi] - arc[lo])[own]
    starts = np.cumsum(cnt) - cnt
    s2 = sv * sv
    pw = np.stack([np.ones_like(sv), sv, s2, s2 * sv, s2 * s2])
    assert np.array_equal(mom, np.add.reduceat(pw, starts, axis=1))
    assert np.array_equal(rx, np.add.reduceat(pw[:3] * W[idx, 0], starts, axis=1))
    assert np.array_equal(ry, np.add.reduceat(pw[:3] * W[idx, 1], starts, axis=1))


def test_batches_by_points_cover_every_path_once_and_change_nothing() -> None:
    """The pipeline fits in batches that end at a number of input points (cancel is checked
    between them): every path in exactly one batch, in order, no batch over its path cap,
    a batch past the point cap only by its last path, and the same fit as one batch."""
    from galvo_core.fit import _batches

    rng = np.random.default_rng(7)
    sizes = [2, 2, 3, 400, 2, 5000, 7, 2, 2, 90, 3000, 2, 4]
    paths = []
    for i, n in enumerate(sizes):
        t = np.linspace(0, 2 * np.pi, n)
        pts = np.c_[100 * i + 30 * np.cos(t), 40 * np.sin(t) + rng.normal(0, 0.01, n)]
        paths.append(Path(pts))
    d = Drawing(tuple(paths))
    ranges = _batches(d.paths, 4, 1000)
    assert [r[0] for r in ranges][0] == 0 and ranges[-1][1] == len(paths)
    assert all(a[1] == b[0] for a, b in zip(ranges, ranges[1:], strict=False))
    for b0, b1 in ranges:
        assert 1 <= b1 - b0 <= 4
        pts = [len(p) for p in paths[b0:b1]]
        assert sum(pts[:-1]) < 1000  # only the last path takes the batch past the cap
    # the point cap ended some batch before its path cap (the 5000-point path)
    assert any(b1 - b0 < 4 and b1 < len(paths) for b0, b1 in ranges)
    one = fit_drawing(d, batch=len(paths))
    split = fit_drawing(d, batch=4, batch_points=1000)
    for a, b in zip(one, split, strict=True):
        np.testing.assert_array_equal(a.points, b.points)
        np.testing.assert_array_equal(a.is_cubic, b.is_cubic)


def test_local_fit_3x3_kernels_match_numpy_det_and_solve() -> None:
    """The local fits' compiled 3x3 LU gives np.linalg.det's determinant and
    np.linalg.solve's solutions (to the last bits here; checked to 1e-12 relative so
    another BLAS's rounding does not fail it), on the moment matrices of windows (sums of
    1, s .. s^4), also singular and permuted ones; where a matrix is not used (not good)
    the solution is the right-hand side."""
    from galvo_core.fit import _det3, _lu3, _solve3

    rng = np.random.default_rng(5)
    mats = []
    for _ in range(400):
        sv = rng.uniform(-1.0, 1.0, rng.integers(4, 60))
        m = np.array([[np.sum(sv ** (i + j)) for j in range(3)] for i in range(3)])
        mats.append(m)
    mats.append(np.ones((3, 3)))  # singular
    mats.append(np.array([[0.0, 1.0, 2.0], [3.0, 0.0, 1.0], [1.0, 4.0, 0.0]]))  # pivots
    mats.append(np.zeros((3, 3)))
    A = np.array(mats)
    lu = np.empty_like(A)
    piv = np.empty((len(A), 3), dtype=np.intp)
    lim = 1e-9 * np.abs(A).max(axis=(1, 2)) ** 3
    good = np.empty(len(A), dtype=bool)
    _lu3(A, lu, piv, lim, good)
    det = np.array([_det3(lu[m], piv[m]) for m in range(len(A))])
    want = np.linalg.det(A)
    assert np.allclose(det, want, rtol=1e-12, atol=0.0)
    assert det[-3] == 0.0 and det[-1] == 0.0
    assert np.array_equal(good, np.abs(want) > lim)
    # at the limit itself the decision is the determinant's (the log-exp one)
    at = np.abs(det[:5])
    _lu3(A[:5], lu[:5], piv[:5], at, good[:5])
    assert not good[:5].any()
    _lu3(A[:5], lu[:5], piv[:5], np.nextafter(at, 0.0), good[:5])
    assert good[:5].all()
    _lu3(A, lu, piv, lim, good)
    assert good[:-3].all() and not good[-3] and good[-2] and not good[-1]
    rx = rng.normal(size=(3, len(A)))
    ry = rng.normal(size=(3, len(A)))
    cx = np.empty((len(A), 3))
    cy = np.empty((len(A), 3))
    _solve3(lu, piv, good, rx, ry, cx, cy)
    Ag = A.copy()
    Ag[~good] = np.eye(3)
    assert np.allclose(cx, np.linalg.solve(Ag, rx.T[:, :, None])[:, :, 0], rtol=1e-9, atol=1e-12)
    assert np.allclose(cy, np.linalg.solve(Ag, ry.T[:, :, None])[:, :, 0], rtol=1e-9, atol=1e-12)
    assert np.array_equal(cx[~good], rx.T[~good])
    assert np.allclose(np.einsum("mij,mj->mi", Ag, cx), rx.T, rtol=1e-7, atol=1e-9)
