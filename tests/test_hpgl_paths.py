"""The importer's paths share their storage (issue 20: memory and time per path); what a
user of :class:`~galvo_core.drawing.Path` relies on must not show it."""

from __future__ import annotations

import dataclasses
import pickle
import tracemalloc

import numpy as np
import pytest

from galvo_core.drawing import Path, SourcePos
from galvo_core.hpgl import read_bytes


def _many(n: int) -> bytes:
    """``n`` two-point paths, one per line: ``PU x,0;PD x,10;`` (PD at column 7 or more)."""
    return b"IN;SP1;\n" + b"".join(b"PU%d,0;PD%d,10;\n" % (k, k) for k in range(n))


@pytest.mark.parametrize("compiled", [False, True])
def test_stored_paths_behave_like_built_ones(compiled: bool, monkeypatch) -> None:
    from galvo_core.hpgl import reader

    monkeypatch.setattr(reader, "_use_compiled", lambda size: compiled)
    n = 3000
    d = read_bytes(_many(n), "many.plt")
    assert len(d.paths) == n and d.n_points == 2 * n
    for k in (0, 1, 255, 256, 257, n - 1):
        p = d.paths[k]
        assert len(p) == 2
        assert p.points.tolist() == [[k, 0.0], [k, 10.0]]
        assert p.points is p.points  # one view, kept once read
        assert not p.points.flags.writeable
        assert p.pen == 1 and p.closed is False
        # line k + 2 (after "IN;SP1;"), the PD command's column
        col = len(b"PU%d,0;" % k) + 1
        assert p.start == SourcePos(k + 2, col)
        with pytest.raises(dataclasses.FrozenInstanceError):
            p.pen = 2  # type: ignore[misc]
        q = pickle.loads(pickle.dumps(p))
        assert np.array_equal(q.points, p.points) and (q.pen, q.closed, q.start) == (
            p.pen, p.closed, p.start)
        r = p.with_points([[0.0, 0.0], [1.0, 1.0], [0.0, 0.0]])
        assert (r.pen, r.start, len(r)) == (p.pen, p.start, 3)
        assert p.length == pytest.approx(10.0)


def test_built_path_keeps_its_arguments() -> None:
    src = np.array([[0.0, 0.0], [3.0, 4.0]])
    p = Path(src, 2, False, SourcePos(5, 6))
    src[0, 0] = 9.0  # a copy was taken
    assert p.points.tolist() == [[0.0, 0.0], [3.0, 4.0]] and p.pen == 2
    assert p.start == SourcePos(5, 6) and Path(src).start == SourcePos(0, 0)
    assert "Path(points=" in repr(p)


def test_paths_in_file_order_when_both_readers_take_part() -> None:
    # scanner runs (PU/PD/PA) and general-reader figures (CI, EA) interleaved
    data = b"IN;SP1;PU0,0;PD10,0;PU100,100;CI5;PU20,0;PD30,0;EA40,10;PU50,0;PD60,0;"
    d = read_bytes(data, "mix.plt")
    firsts = [tuple(p.points[0]) for p in d.paths]
    assert firsts == [(0.0, 0.0), (105.0, 100.0), (20.0, 0.0), (30.0, 0.0),
                      (50.0, 0.0)]


@pytest.mark.parametrize("compiled", [False, True])
def test_memory_per_path_is_small(compiled: bool, monkeypatch) -> None:
    """20,000 two-point paths (17 bytes of file each): the drawing holds well under 250
    bytes per path (each path with its own SourcePos and points array needed about 390),
    and reading it never needs more than 400 (the numpy reader of small files took 1,085:
    its per-byte temporaries over the whole run, and re's backtracking state)."""
    from galvo_core.hpgl import reader

    monkeypatch.setattr(reader, "_use_compiled", lambda size: compiled)
    n = 20_000
    data = _many(n)
    read_bytes(data, "warm.plt")
    tracemalloc.start()
    try:
        d = read_bytes(data, "many.plt")
        held, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert len(d.paths) == n
    assert held / n < 250
    assert peak / n < 400


def test_fp_after_ep_replaces_edges_across_blocks_and_keeps_the_order() -> None:
    """The general reader gathers its paths into blocks of a few hundred as it reads; FP
    after EP still replaces all of EP's edges by the rings (one region), and what was drawn
    between them stays after the rings, in file order."""
    def square(x: int) -> bytes:
        return b"PA%d,0;PD%d,0,%d,10,%d,10,%d,0;PU;PM1;" % (x, x + 10, x + 10, x, x)

    n = 1500  # EP's edges: far more than one block
    data = (b"IN;SP1;PM0;" + b"".join(square(20 * k) for k in range(n))
            + b"PM2;EP;PA0,100;PD0,200;PU;FP;")
    d = read_bytes(data, "rings.plt")
    assert len(d.paths) == n + 1
    for k in (0, 511, 512, 1023, n - 1):
        p = d.paths[k]
        assert p.closed and p.length == pytest.approx(40.0)
        assert p.points[0].tolist() == [20.0 * k, 0.0]
    assert d.paths[n].points.tolist() == [[0.0, 100.0], [0.0, 200.0]]
