"""Round joins redrawn with the error on both sides of the arc (galvo_core.offset_arcs):
fewer vertices, every point still within the arc tolerance of the true offset."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from galvo_core.offset_arcs import join_vertices, two_sided_arcs


def _one_sided(d, tol, phi):
    return math.ceil(phi / (2.0 * math.acos(1.0 - tol / d)) - 1e-12)


@settings(max_examples=200, deadline=None)
@given(
    st.floats(0.5, 5000.0),
    st.floats(0.001, 0.45),
    st.floats(0.05, 2 * math.pi - 0.05),
)
def test_join_within_tolerance_on_both_sides(d, rel_tol, phi):
    tol = rel_tol * d
    got = join_vertices(d, tol, phi)
    if got is None:
        return
    k, r = got
    assert k < _one_sided(d, tol, phi)
    assert d <= r <= d + tol
    th = phi * np.arange(1, k) / k
    poly = np.vstack([[d, 0.0], np.c_[r * np.cos(th), r * np.sin(th)],
                      [d * math.cos(phi), d * math.sin(phi)]])
    t = np.linspace(0.0, 1.0, 401)[:, None]
    pts = np.concatenate([a + t * (b - a) for a, b in zip(poly[:-1], poly[1:], strict=True)])
    rad = np.hypot(pts[:, 0], pts[:, 1])
    assert rad.max() <= d + tol * (1 + 1e-9)
    assert rad.min() >= d - tol * (1 + 1e-9)


def test_right_angle_join_takes_three_chords_where_one_sided_takes_four():
    # d = 29.8 bits, tol = 1 bit: a chord on the circle spans at most 29.8 degrees
    assert _one_sided(29.8, 1.0, math.pi / 2) == 4
    assert join_vertices(29.8, 1.0, math.pi / 2)[0] == 3


def _offset_error(geom, src, d):
    b = geom.boundary.segmentize(0.01 * d)
    pts = shapely.points(shapely.get_coordinates(b))
    return shapely.distance(pts, src.boundary) - d


@pytest.mark.parametrize("d,tol", [(29.8, 1.0), (2.0, 0.0671), (8.0, 0.0671)])
def test_grown_rectangle_has_clipper_like_joins_within_tolerance(d, tol):
    rect = shapely.Polygon([(0, 0), (200, 0), (200, 100), (0, 100)])
    g = rect.buffer(d, quad_segs=64)
    new, keep = two_sided_arcs(g, d, tol)
    assert new.is_valid
    k = join_vertices(d, tol, math.pi / 2)[0]
    # every corner: its two tangent points and k - 1 vertices between, ring closed
    assert len(shapely.get_coordinates(new)) == 4 * (k + 1) + 1
    xy = shapely.get_coordinates(new)
    assert len(keep) == len(xy)  # a mask over the result's vertices: the joins' own
    assert len(np.unique(xy[keep], axis=0)) == 4 * (k + 1)
    err = _offset_error(new, rect, d)
    assert err.max() <= tol * (1 + 1e-9) and err.min() >= -tol * (1 + 1e-9)


def test_shrunk_ring_with_a_hole_and_notch():
    """Inward offsets have round joins at reflex corners; holes grow with joins too."""
    outer = [(0, 0), (300, 0), (300, 200), (160, 200), (150, 120), (140, 200), (0, 200)]
    hole = [(60, 60), (60, 120), (100, 120), (100, 60)]
    poly = shapely.Polygon(outer, [hole])
    d, tol = 6.0, 0.05
    g = poly.buffer(-d, quad_segs=64)
    new, keep = two_sided_arcs(g, d, tol)
    assert new.is_valid and keep.any()
    assert len(shapely.get_coordinates(new)) < len(shapely.get_coordinates(g))
    assert shapely.get_num_interior_rings(new) == 1
    err = _offset_error(new, poly, d)
    assert err.max() <= tol * (1 + 1e-9) and err.min() >= -tol * (1 + 1e-9)


def test_nothing_to_do_is_returned_unchanged():
    tri = shapely.Polygon([(0, 0), (10, 0), (0, 10)])
    g = tri.buffer(-1.0, quad_segs=8)  # a shrunk convex polygon has no round joins
    new, keep = two_sided_arcs(g, 1.0, 0.01)
    assert new is g and len(keep) == 0
    assert two_sided_arcs(g, 1.0, 2.0)[0] is g  # tol >= d


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.5, 20.0), st.sampled_from([0.02, 0.0671, 0.3]))
def test_random_polygons_stay_valid_and_within_tolerance(seed, d, tol):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 12))
    ang = np.sort(rng.uniform(0, 2 * np.pi, n))
    rad = rng.uniform(10, 60, n)
    poly = shapely.Polygon(np.c_[rad * np.cos(ang), rad * np.sin(ang)])
    if not poly.is_valid or poly.area < 1:
        return
    q = max(8, math.ceil(math.pi / 2 / (2 * math.acos(1 - tol / 16 / d))))
    for side in (d, -d):
        g = poly.buffer(side, quad_segs=q)
        if g.is_empty:
            continue
        new, _ = two_sided_arcs(g, d, tol)
        assert new.is_valid
        assert len(shapely.get_coordinates(new)) <= len(shapely.get_coordinates(g))
        err = _offset_error(new, poly, d)
        # GEOS's own chords (where nothing was redrawn) sag by at most tol / 16 here
        assert err.max() <= tol * (1 + 1e-9) and err.min() >= -tol * (1 + 1e-9)


def test_thinning_keeps_the_redrawn_joins():
    """The mask lines up with the thinning's vertices: every vertex of a redrawn join is
    still there after kerf.reduce_vertices, with a budget that would drop some of them."""
    from galvo_core.kerf import reduce_vertices

    outer = [(0, 0), (300, 0), (300, 200), (160, 200), (150, 120), (140, 200), (0, 200)]
    poly = shapely.MultiPolygon([shapely.Polygon(outer, [[(60, 60), (60, 120), (100, 120)]]),
                                 shapely.Polygon([(400, 0), (500, 0), (450, 90)])])
    d, tol = 6.0, 0.3
    g = poly.buffer(d, quad_segs=32)
    new, keep = two_sided_arcs(g, d, tol)
    joins = shapely.get_coordinates(shapely.get_rings(shapely.get_parts(new)))[keep]
    assert len(joins) > 0
    loose = reduce_vertices(new, 2.0)  # (without the mask: joins thinned away)
    thin = reduce_vertices(new, 2.0, keep=keep)
    left = {tuple(p) for p in shapely.get_coordinates(thin)}
    assert all(tuple(p) in left for p in joins)
    assert shapely.get_num_coordinates(loose) < shapely.get_num_coordinates(thin)
    assert thin.is_valid


def _arc_and_neighbour():
    """A quarter disc of radius 29.8 drawn like GEOS's round join (33 vertices on the arc)
    and a triangle 0.3 outside the arc at 30 degrees: the redrawn join (3 chords, inner
    vertices at 30 and 60 degrees, up to d + tol = 30.8 out) would overlap the triangle."""
    t = np.linspace(0, np.pi / 2, 33)
    a = shapely.Polygon(np.vstack([[0.0, 0.0], np.c_[29.8 * np.cos(t), 29.8 * np.sin(t)]]))
    c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)
    b = shapely.Polygon([(30.1 * c, 30.1 * s), (45, 9), (45, 30)])
    return shapely.MultiPolygon([a, b])


def test_a_join_that_would_meet_a_neighbour_is_not_redrawn():
    g = _arc_and_neighbour()
    assert g.is_valid
    assert join_vertices(29.8, 1.0, math.pi / 2)[0] == 3
    new, keep = two_sided_arcs(g, 29.8, 1.0)
    assert new.is_valid
    assert shapely.get_num_coordinates(new) == shapely.get_num_coordinates(g)


def test_unchecked_joins_fall_back_to_the_geos_polygons_in_the_thinning():
    """With check=False the redrawn joins are not validated; the thinning validates its
    result and falls back to the GEOS outline (still thinned within the budget)."""
    from galvo_core.kerf import _reduce

    g = _arc_and_neighbour()
    new, keep = two_sided_arcs(g, 29.8, 1.0, check=False)
    assert not new.is_valid  # (the unchecked join overlaps the triangle)
    out, checked = _reduce(new, 0.2, keep, fallback=g)
    assert out.is_valid and checked
    assert shapely.get_num_coordinates(out) < shapely.get_num_coordinates(g)
    assert shapely.hausdorff_distance(out.boundary, g.boundary) <= 0.2 + 1e-9
