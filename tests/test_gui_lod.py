"""Coarse display levels of big layers (app.views): what the whole-drawing zoom draws
instead of every vertex must look the same to a pixel."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pytestqt")

from app.views import LOD_FACTORS, LinesItem, _one_per_cell, decimate  # noqa: E402
from galvo_core.geometry import point_polyline_distance  # noqa: E402

pytestmark = pytest.mark.gui


def dense_walk(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    ang = np.cumsum(rng.normal(0, 0.05, n))
    return np.cumsum(np.c_[np.cos(ang), np.sin(ang)] * 0.01, axis=0)


@pytest.mark.parametrize("cell", [0.02, 0.1, 0.5])
def test_decimate_keeps_every_vertex_within_a_cell_diagonal(cell):
    pieces = [dense_walk(4000, s) + 10 * s for s in range(3)]
    xy = np.concatenate([np.vstack((p, [[np.nan, np.nan]])) for p in pieces])[:-1]
    out = decimate(xy, cell)
    assert len(out) < len(xy)
    # pieces stay pieces, with their ends
    assert np.isnan(out[:, 0]).sum() == 2
    kept = np.split(out, np.flatnonzero(np.isnan(out[:, 0])))
    for p, k in zip(pieces, kept, strict=True):
        k = k[np.isfinite(k[:, 0])]
        assert np.array_equal(k[0], p[0]) and np.array_equal(k[-1], p[-1])
        d = point_polyline_distance(p, k)
        assert d.max() <= cell * np.sqrt(2) + 1e-12


def test_one_point_per_cell():
    pts = np.random.default_rng(1).uniform(0, 10, (50_000, 2))
    out = _one_per_cell(pts, 1.0)
    cells = {(int(x), int(y)) for x, y in np.floor(out)}
    assert len(out) == len(cells) == 100  # every occupied cell once


def test_big_lines_get_coarse_levels_coarsest_first(qtbot):
    xy = dense_walk(60_000)
    prepared = LinesItem.prepare(xy, lod=0.01)
    levels = prepared[-1]
    assert levels and [lv for lv, _ in levels] == sorted((lv for lv, _ in levels),
                                                          reverse=True)
    assert levels[0][0] == pytest.approx(0.01 * LOD_FACTORS[0])
    assert LinesItem.prepare(xy[:100], lod=0.01)[-1] is None  # small layers: full only


def test_deviation_chords_joined_into_polylines_draw_the_same_chords(qtbot):
    """The overlay's chords of one colour bin become polylines where they follow one
    another: the polylines' edges are exactly the chords, none lost, none added."""
    from app.views import DeviationItem, _chain_chords

    walk = dense_walk(30_001)
    a, b = walk[:-1].copy(), walk[1:].copy()
    b[1000] += 0.5  # a gap: the next chord does not start where this one ends
    level = np.clip(np.abs(np.sin(np.arange(len(a)) / 700.0)), 0, 1)
    bins = np.minimum((level * 16).astype(int), 15)
    for k in np.unique(bins):
        idx = np.flatnonzero(bins == k)
        xy = _chain_chords(a[idx], b[idx], idx)
        edges = np.isfinite(xy[:-1, 0]) & np.isfinite(xy[1:, 0])
        got = np.hstack((xy[:-1][edges], xy[1:][edges]))
        assert np.array_equal(got, np.hstack((a[idx], b[idx])))
    paths, _, n, coarse = DeviationItem.prepare(a, b, level, lod=0.01)
    assert n == len(a) and len(paths) == len(np.unique(bins))
    assert coarse and [g for g, _ in coarse] == sorted((g for g, _ in coarse), reverse=True)
    assert DeviationItem.prepare(a[:100], b[:100], level[:100], lod=0.01)[-1] is None


def _edges(path) -> set:
    out, prev = set(), None
    for i in range(path.elementCount()):
        e = path.elementAt(i)
        if e.isLineTo():
            out.add((prev, (e.x, e.y)))
        prev = (e.x, e.y)
    return out


def test_big_paths_built_in_pieces_have_the_same_edges(qtbot, monkeypatch):
    """A big QPainterPath is built in pieces (the worker releases the interpreter lock
    between them): the same line segments as one call, at every piece boundary too."""
    import pyqtgraph as pg

    from app import views

    xy = dense_walk(5_000)
    xy[::37] = np.nan
    xy[999] = np.nan  # a NaN row at a piece boundary
    monkeypatch.setattr(views, "QPATH_CHUNK", 500)
    whole = pg.arrayToQPath(xy[:, 0], xy[:, 1], connect="finite")
    pieces = views._qpath(xy[:, 0], xy[:, 1])
    assert _edges(pieces) == _edges(whole) and len(_edges(whole)) > 4000


def test_marker_levels_from_one_grid_are_one_point_per_cell_of_each():
    from app.views import _levels_per_cell

    pts = np.random.default_rng(2).uniform(-3, 7, (40_000, 2))
    levels = _levels_per_cell(pts, 0.05)
    assert [g for g, _ in levels] == pytest.approx([0.05 * f for f in LOD_FACTORS])
    for g, kept in levels:
        assert np.array_equal(kept, _one_per_cell(pts, g))


def test_two_point_pieces_get_no_coarse_level_but_longer_pieces_do():
    # jumps (pairs) keep both ends at any grid: no level is built for them; a layer whose
    # pieces are longer is still decimated
    rng = np.random.default_rng(7)
    n = 30_000
    pairs = np.full((3 * n - 1, 2), np.nan)
    pairs[0::3] = rng.random((n, 2)) * 1000
    pairs[1::3] = pairs[0::3] + 0.01
    assert LinesItem.prepare(pairs, lod=1.0)[4] is None
    line = np.cumsum(rng.random((3 * n - 1, 2)) * 0.01, axis=0)
    line[2::7] = np.nan
    assert LinesItem.prepare(line, lod=1.0)[4] is not None
