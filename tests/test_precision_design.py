"""Rounded input, third round of issue 16: when the vertices move onto the design, and a
thinned line that bulges off the design is split."""

from __future__ import annotations

import numpy as np

from galvo_core import fit as fitmod
from galvo_core.fit import check_fit, fit_paths
from galvo_core.geometry import point_segment_distance


def _rounded_arc(radius: float, length: float, q: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(-0.5, 0.5, int(length) + 1) * length / radius
    xy = np.c_[radius * np.sin(t), radius * np.cos(t) - radius]
    c, s = np.cos(0.5), np.sin(0.5)  # turned 29 degrees off the grid
    exact = xy @ np.array([[c, s], [-s, c]]) + [0.3, 0.1]
    pts = np.round(exact / q) * q
    keep = np.r_[True, (pts[1:] != pts[:-1]).any(axis=1)]
    return exact, pts[keep]


def test_line_bulging_off_the_design_is_split_on_the_design_estimate():
    exact, pts = _rounded_arc(400.0, 48.0)  # sagitta 0.72 unit
    arc = np.r_[0.0, np.cumsum(np.hypot(*np.diff(pts, axis=0).T))]
    n = len(pts)
    la = np.array([0])
    lpts = np.array([[pts[0], pts[-1]]])
    lfirst, llast = np.array([0]), np.array([n - 1])
    eps = np.full(n, 1.2)
    lerr = fitmod._line_errors(pts, lpts, lfirst, llast)
    la2, pts2, f2, l2, e2, key2, more = fitmod._split_bulging_lines(
        pts, arc, la, lpts, lfirst, llast, lerr, 3 * la, np.ones(n), eps)
    assert more and len(la2) == 2
    m = (n - 1) // 2
    assert f2.tolist() == [0, m] and l2.tolist() == [m, n - 1]
    v = pts2[0, 1]
    assert np.array_equal(pts2[1, 0], v)  # the halves meet
    assert np.abs(v - pts[m]).max() <= 0.5  # inside the middle point's rounding square
    assert (e2 <= 1.2).all()
    assert np.allclose(e2, fitmod._line_errors(pts, pts2, f2, l2))
    # the new vertex is nearer the design than the old line was at the middle
    d_design = float(np.hypot(*(exact - v).T).min())
    d_old = float(point_segment_distance(exact[len(exact) // 2][None], lpts[:, 0],
                                         lpts[:, 1])[0])
    assert d_design < 0.5 * d_old


def test_straight_rounded_line_is_not_split():
    t = np.linspace(0.0, 1.0, 60)[:, None]
    exact = np.array([0.3, 0.1]) + t * np.array([59.0, 23.7])
    pts = np.round(exact)
    n = len(pts)
    arc = np.r_[0.0, np.cumsum(np.hypot(*np.diff(pts, axis=0).T))]
    lpts = np.array([[pts[0], pts[-1]]])
    la, lfirst, llast = np.array([0]), np.array([0]), np.array([n - 1])
    lerr = fitmod._line_errors(pts, lpts, lfirst, llast)
    out = fitmod._split_bulging_lines(pts, arc, la, lpts, lfirst, llast, lerr, 3 * la,
                                      np.ones(n), np.full(n, 0.727))
    assert not out[-1] and len(out[0]) == 1


def _ends_on_input(fp, pts) -> bool:
    ends = np.concatenate([s.points[[0, -1]] for s in fp.segments])
    d = np.abs(ends[:, None, :] - pts[None, :, :]).max(axis=2).min(axis=1)
    return bool((d == 0).all())


def test_vertices_move_onto_the_design_only_where_the_rounding_counts():
    # a wobbly closed curve rounded to q: at e_per 0.02, q = 0.01 (q/sqrt2 under e_per/2)
    # keeps every segment end on an input point; q = 0.05 moves some inside their squares
    t = np.linspace(0.0, 2.0 * np.pi, 900, endpoint=False)
    r = 60.0 + 6.0 * np.sin(3.0 * t)
    exact = np.c_[r * np.cos(t), r * np.sin(t)]
    for q, on_points in ((0.01, True), (0.05, False)):
        pts = np.round(exact / q) * q
        fp = fit_paths([pts], [True], quantum_units=q)[0]
        assert _ends_on_input(fp, pts) is on_points
        rep = check_fit(pts, fp, 0.02, 0.02, report=True, quantum_units=q)
        assert not rep["violation"]


def test_corners_of_a_short_run_of_lines_keep_their_place():
    """A ten-point contour of lines only (Cantarell "y" at 3000 units per em: every vertex a
    multiple of 3, so its grid is detected as 3): one vertex turns by 1 degree, so its two lines
    form a run, but the corners at the run's ends have no curve to estimate: a window of 20
    points reaching across the other corners gave estimates 1.5 units off and moved them
    there. The corners stay on their input points."""
    p = np.array([[20919.0, -651.0], [21174.0, -651.0], [21414.0, 0.0], [21978.0, 1446.0],
                  [21738.0, 1446.0], [21303.0, 234.0], [20877.0, 1446.0], [20610.0, 1446.0],
                  [21180.0, 0.0], [20919.0, -651.0]])
    fp = fitmod.fit_paths([p], [True])[0]
    ends = np.array([np.asarray(s.points)[-1] for s in fp.segments])
    for corner in p[[1, 3, 5, 6, 8]]:
        assert np.hypot(*(ends - corner).T).min() < 1e-9, corner
