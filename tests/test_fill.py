"""Fill (paper 002): zig-zag cells, one stroke per monotone cell or fewer, inside the region,
covering it, nothing marked twice."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from _util import SAMPLES
from shapely.geometry import LineString

from galvo_core.drawing import Drawing, Path
from galvo_core.fill import (
    coverage,
    fill_metrics,
    find_regions,
    hatch,
    monotone_cells,
    region_polygons,
    retraced_length,
)
from galvo_core.hpgl.reader import read_file


def ring(pts, reverse: bool = False) -> Path:
    p = np.asarray(pts, dtype=float)
    if reverse:
        p = p[::-1]
    return Path.from_points(np.vstack([p, p[:1]]), closed=True)


T = np.linspace(0, 2 * np.pi, 240, endpoint=False)


def circle(r: float, cx: float = 0.0, cy: float = 0.0) -> np.ndarray:
    return np.c_[cx + r * np.cos(T), cy + r * np.sin(T)]


SQUARE = Drawing((ring([(0, 0), (100, 0), (100, 100), (0, 100)]),))
DISC = Drawing((ring(circle(80)),))
ANNULUS = Drawing((ring(circle(100)), ring(circle(50), reverse=True)))
E_SHAPE = Drawing((ring([(0, 0), (60, 0), (60, 20), (20, 20), (20, 40), (50, 40), (50, 60),
                         (20, 60), (20, 80), (60, 80), (60, 100), (0, 100)]),))
SHAPES = {"square": SQUARE, "disc": DISC, "annulus": ANNULUS, "E": E_SHAPE}


def region_geom(d: Drawing):
    return shapely.unary_union([r.polygon for r in find_regions(d)])


def check_inside(d: Drawing, strokes, eps: float = 1e-6) -> None:
    regs = {r.source_index: r.polygon for r in find_regions(d)}
    for s in strokes:
        g = LineString(s.points) if len(s.points) > 1 else shapely.Point(s.points[0])
        assert g.within(regs[s.source_index].buffer(eps)), s.source_index


@pytest.mark.parametrize("angle", [0.0, 30.0, 90.0, 137.0])
@pytest.mark.parametrize("shape", ["square", "disc"])
def test_convex_region_is_one_stroke(shape: str, angle: float) -> None:
    d = SHAPES[shape]
    assert monotone_cells(d, spacing_units=2.0, angle_deg=angle) == 1
    st = hatch(d, fill="zigzag", spacing_units=2.0, angle_deg=angle)
    assert len(st) == 1 and st[0].cells == 1
    m = fill_metrics(d, st, spacing_units=2.0)
    assert m["coverage"] >= 0.995
    assert m["retraced_length"] == 0.0


def test_cell_counts_annulus_and_e() -> None:
    assert monotone_cells(ANNULUS, spacing_units=2.0) == 4
    # an E with its arms along the hatch is crossed once by every line; across, 4 cells
    assert monotone_cells(E_SHAPE, spacing_units=2.0, angle_deg=0.0) == 1
    assert monotone_cells(E_SHAPE, spacing_units=2.0, angle_deg=90.0) == 4
    for d, ang, cells in ((ANNULUS, 0.0, 4), (E_SHAPE, 90.0, 4), (E_SHAPE, 0.0, 1)):
        st = hatch(d, fill="zigzag", spacing_units=2.0, angle_deg=ang)
        assert 1 <= len(st) <= cells
        assert sum(s.cells for s in st) == cells
    # the E's cell graph is a star (spine + 3 arms): a path through it needs U-turns in the
    # arms (paper 002, Theorem 2); with them the whole E is one stroke
    assert len(hatch(E_SHAPE, fill="zigzag", spacing_units=2.0, angle_deg=90.0)) == 1


@pytest.mark.parametrize("angle", [0.0, 30.0, 45.0, 71.0, 90.0, 137.0])
@pytest.mark.parametrize("shape", ["square", "disc", "annulus", "E"])
def test_cells_joined_into_one_stroke(shape: str, angle: float) -> None:
    """Theorem 2 of paper 002: a cell can be left at whichever corner the next cell needs,
    so a connected region (convex, with a hole, or an E) is one stroke: inside, covering,
    nothing marked twice, not even a crossing of the stroke with itself."""
    d = SHAPES[shape]
    cells = monotone_cells(d, spacing_units=2.0, angle_deg=angle)
    st = hatch(d, fill="zigzag", spacing_units=2.0, angle_deg=angle)
    assert len(st) <= cells
    if shape in ("square", "disc", "annulus"):
        assert len(st) == 1
    assert len(st) == 1 or shape == "E"
    assert sum(s.cells for s in st) == cells
    check_inside(d, st)
    m = fill_metrics(d, st, spacing_units=2.0)
    assert m["retraced_length"] == 0.0
    assert m["coverage"] >= 0.995
    assert all(LineString(s.points).is_simple for s in st)


@pytest.mark.parametrize("fill", ["scanline", "zigzag"])
@pytest.mark.parametrize("shape", list(SHAPES))
@pytest.mark.parametrize("angle", [0.0, 45.0, 71.0])
def test_inside_covering_no_retrace(fill: str, shape: str, angle: float) -> None:
    d = SHAPES[shape]
    st = hatch(d, fill=fill, spacing_units=2.0, angle_deg=angle)
    check_inside(d, st)
    pts = [s.points for s in st]
    # the zig-zag covers the region; bare scan lines leave slanted corners a little short
    assert coverage(region_geom(d), pts, 2.0) >= (0.995 if fill == "zigzag" else 0.99)
    assert retraced_length(pts) == 0.0
    if fill == "scanline":
        assert all(len(p) == 2 for p in pts)


def test_seal_and_text_samples() -> None:
    for name, sp in (("seal.plt", 4.0), ("text_outline.plt", 3.0)):
        d = read_file(SAMPLES / name)
        z = hatch(d, fill="zigzag", spacing_units=sp, angle_deg=15.0)
        s = hatch(d, fill="scanline", spacing_units=sp, angle_deg=15.0)
        cells = monotone_cells(d, spacing_units=sp, angle_deg=15.0)
        assert len(z) <= cells < len(s)
        # one stroke per connected piece of region is the least possible; cells are joined
        # into paths (seal: one stroke per piece; text: 18 for 14 pieces at 15 degrees)
        pieces = len(region_polygons(find_regions(d)))
        assert pieces <= len(z) <= pieces + 4
        check_inside(d, z)
        mz = fill_metrics(d, z, spacing_units=sp)
        assert mz["retraced_length"] == 0.0
        assert mz["coverage"] >= 0.995
        # same hatch lines: the zig-zag marks the scan lines plus boundary joins
        ms = fill_metrics(d, s, spacing_units=sp, with_coverage=False)
        assert mz["mark_length"] >= ms["mark_length"] * 0.999


def test_source_index_holes_and_nesting() -> None:
    # a square (0), an annulus (1, 2 its hole), an island inside the hole (3), open path (4)
    d = Drawing((
        ring([(300, 0), (400, 0), (400, 100), (300, 100)]),
        ring(circle(100)),
        ring(circle(50), reverse=True),
        ring(circle(20)),
        Path.from_points([(0, 200), (100, 200)]),
    ))
    regs = find_regions(d)
    assert sorted(r.source_index for r in regs) == [0, 1, 3]
    assert next(r for r in regs if r.source_index == 1).holes == (2,)
    st = hatch(d, fill="zigzag", spacing_units=2.0)
    assert {s.source_index for s in st} == {0, 1, 3}
    check_inside(d, st)
    # nothing in the hole between r=20 and r=50
    hole = shapely.Point(0, 0).buffer(49).difference(shapely.Point(0, 0).buffer(21))
    assert not any(LineString(s.points).intersects(hole) for s in st if s.source_index != 0)


def test_passes_inset_none() -> None:
    st = hatch(DISC, fill="zigzag", spacing_units=2.0, passes=2, angle_step_deg=90.0)
    assert {s.pass_index for s in st} == {0, 1}
    ins = hatch(DISC, fill="zigzag", spacing_units=2.0, inset_units=5.0)
    inner = region_geom(DISC).buffer(-5.0 + 1e-6)
    assert all(LineString(s.points).within(inner) for s in ins)
    assert hatch(DISC, fill="none", spacing_units=2.0) == []
    with pytest.raises(ValueError):
        hatch(DISC, fill="spiral", spacing_units=2.0)


def comb(teeth: int) -> Drawing:
    """A bar with `teeth` teeth on top and as many below, shifted: many monotone cells
    whose graph has no path through all of them (a zig-zag needs several strokes)."""
    pts = [(0.0, 0.0)]
    for k in range(teeth):  # teeth below, left to right
        x = 30.0 * k
        pts += [(x + 5, 0.0), (x + 5, -40.0), (x + 20, -40.0), (x + 20, 0.0)]
    pts += [(30.0 * teeth, 0.0), (30.0 * teeth, 20.0)]
    for k in range(teeth - 1, -1, -1):  # teeth above, right to left
        x = 30.0 * k + 12
        pts += [(x + 15, 20.0), (x + 15, 60.0), (x, 60.0), (x, 20.0)]
    pts += [(0.0, 20.0)]
    return Drawing((ring(pts),))


@pytest.mark.parametrize("effort", [0, 300])
def test_zigzag_bounded_search_keeps_the_guarantees(effort: int) -> None:
    """With no search steps at all (greedy walks only) and with the default share, a comb of
    many cells is covered inside the region, nothing marked twice, strokes <= cells."""
    d = comb(12)
    st = hatch(d, fill="zigzag", spacing_units=2.0, max_effort=effort)
    cells = monotone_cells(d, spacing_units=2.0)
    assert cells >= 25
    assert len(st) <= cells and sum(s.cells for s in st) == cells
    check_inside(d, st)
    m = fill_metrics(d, st, spacing_units=2.0)
    assert m["retraced_length"] == 0.0
    assert m["coverage"] >= 0.995
    assert all(LineString(s.points).is_simple for s in st)


def test_zigzag_search_work_is_linear_in_the_cells() -> None:
    """Search and walk steps of a region piece stay within a constant per cell (plus a
    constant), however many cells it has and whether or not one path covers them; the
    old fixed budget spent 400 000 steps on pieces of a few dozen cells."""
    from galvo_core.fill import EFFORT_BASE, EFFORT_PER_CELL, _Hatch, _rings_rotated, _rotation

    effort = []
    cells = []
    for teeth in (8, 80):
        (_, poly), = region_polygons(find_regions(comb(teeth)))
        h = _Hatch(_rings_rotated(poly, _rotation(0.0)), 2.0)
        paths = h.walk()
        cells.append(len(h.cell_segs))
        effort.append(h.effort)
        assert sum(len(p) for p in paths) == cells[-1]
        assert h.effort <= EFFORT_BASE + (EFFORT_PER_CELL + 4) * cells[-1]
    assert cells[1] >= 9 * cells[0]
