"""The kernel threads (galvo_core.parallel): chunks cover the items once, in order; errors
reach the caller; and a fit or a thinning split over threads is the one-thread result, bit
for bit (the operator's preview must not depend on the machine's core count)."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from _util import waved_ellipse, whole_units

from galvo_core import fit as fitmod
from galvo_core import parallel
from galvo_core.thin import thin_many


@pytest.mark.parametrize("parts", [1, 2, 3, 7])
def test_chunks_cover_every_item_once_in_order(parts: int) -> None:
    rng = np.random.default_rng(parts)
    for m in (1, 2, 5, 40):
        w = rng.integers(0, 1000, m)
        b = parallel.chunk_bounds(w, parts)
        assert b[0][0] == 0 and b[-1][1] == m
        assert all(lo < hi for lo, hi in b)
        assert all(b[i][1] == b[i + 1][0] for i in range(len(b) - 1))
        assert len(b) <= min(parts, m)
    # one heavy item among light ones gets a chunk of its own share
    b = parallel.chunk_bounds(np.r_[np.ones(10), 1000.0, np.ones(10)], 2)
    assert len(b) == 2


def _threads(monkeypatch: pytest.MonkeyPatch, n: int, fns: list[str] | None = None) -> list[str]:
    """Run every kernel in up to n chunks whatever its size; the names of the threads that
    ran chunks are collected (and into ``fns`` the names of the chunk functions)."""
    monkeypatch.setattr(parallel, "THREADS", n)
    monkeypatch.setattr(parallel, "MIN_WORK", 0)
    seen: list[str] = []
    real = parallel._run_marked

    def run_marked(fn, lo, hi):  # type: ignore[no-untyped-def]
        seen.append(threading.current_thread().name)
        if fns is not None:
            fns.append(fn.__name__)
        return real(fn, lo, hi)

    monkeypatch.setattr(parallel, "_run_marked", run_marked)
    return seen


def test_a_failing_chunk_raises_in_the_caller(monkeypatch: pytest.MonkeyPatch) -> None:
    _threads(monkeypatch, 3)
    done: list[tuple[int, int]] = []

    def fn(lo: int, hi: int) -> int:
        done.append((lo, hi))
        if lo > 0:
            raise ValueError(f"chunk {lo}")
        return hi - lo

    with pytest.raises(ValueError, match="chunk"):
        parallel.run_chunks(fn, np.ones(9))
    assert len(done) == 3  # every chunk ran to its end before the error was raised
    assert parallel.run_chunks(lambda lo, hi: hi - lo, np.ones(1)) == [1]


def _outlines() -> list[np.ndarray]:
    return [whole_units(waved_ellipse(11, k, 6000)) for k in range(6)]


def _fit_arrays(paths: list[np.ndarray]) -> list[tuple[np.ndarray, ...]]:
    f = fitmod.fit_paths(paths, [True] * len(paths))
    return [(x.is_cubic, x.points, x.first, x.last, np.float64(x.max_error)) for x in f]


def test_a_threaded_fit_is_the_one_thread_fit(monkeypatch: pytest.MonkeyPatch) -> None:
    paths = _outlines()
    monkeypatch.setattr(parallel, "THREADS", 1)
    one = _fit_arrays(paths)
    seen = _threads(monkeypatch, 3)
    three = _fit_arrays(paths)
    assert any(name.startswith("galvo-kernel") for name in seen)  # chunks ran on the pool
    assert len(one) == len(three)
    for a, b in zip(one, three, strict=True):
        for x, y in zip(a, b, strict=True):
            assert np.array_equal(x, y)


def test_threaded_repairs_are_the_one_thread_repairs(monkeypatch: pytest.MonkeyPatch) -> None:
    # the smooth-stretch repairs (fit._smooth_stretches) run per path in chunks of paths:
    # each path's repairs in the same order, its budget its own, so the same segments
    paths = _outlines()
    monkeypatch.setattr(parallel, "THREADS", 1)
    one = _fit_arrays(paths)
    names: list[str] = []
    _threads(monkeypatch, 3, names)
    three = _fit_arrays(paths)
    assert names.count("repairs") >= 2  # the repairs were split over chunks of paths
    for a, b in zip(one, three, strict=True):
        for x, y in zip(a, b, strict=True):
            assert np.array_equal(x, y)


def test_threaded_thinning_is_the_one_thread_thinning(monkeypatch: pytest.MonkeyPatch) -> None:
    paths = _outlines() + [np.zeros((0, 2)), np.array([[1.0, 2.0]])]
    monkeypatch.setattr(parallel, "THREADS", 1)
    one = thin_many(paths, 0.6)
    seen = _threads(monkeypatch, 4)
    four = thin_many(paths, 0.6)
    assert seen
    assert all(np.array_equal(a, b) for a, b in zip(one, four, strict=True))


def test_threaded_minimax_is_the_one_thread_minimax(monkeypatch: pytest.MonkeyPatch) -> None:
    """The refinement of the fit's near misses (galvo_core.minimax) gives each piece the same
    cubic whether its pieces run in one call or in chunks on the pool."""
    from _util import flattened_cubic

    from galvo_core.minimax import minimax_cubics

    rng = np.random.default_rng(7)
    work, i0, i1, ctrl = [], [], [], []
    n = 0
    for _ in range(12):
        c = np.cumsum(rng.uniform(20.0, 120.0, size=(4, 2)), axis=0)
        p = np.round(flattened_cubic(*c, chord=0.01))
        p = p[np.r_[True, (p[1:] != p[:-1]).any(axis=1)]]
        work.append(p)
        i0.append(n)
        i1.append(n + len(p) - 1)
        n += len(p)
        start = c.copy()
        start[[0, 3]] = p[[0, -1]]
        start[1:3] += rng.uniform(-1.5, 1.5, size=(2, 2))  # a near miss to refine
        ctrl.append(start)
    W = np.vstack(work)
    arc = np.r_[0.0, np.cumsum(np.hypot(*np.diff(W, axis=0).T))]
    args = (W, arc, np.array(i0), np.array(i1), np.array(ctrl), np.full(len(i0), 0.727))
    monkeypatch.setattr(parallel, "THREADS", 1)
    one, ok1 = minimax_cubics(*args)
    seen = _threads(monkeypatch, 3)
    three, ok3 = minimax_cubics(*args)
    assert any(name.startswith("galvo-kernel") for name in seen)  # chunks ran on the pool
    assert ok1.any()  # some pieces were refined within the bound
    assert np.array_equal(ok1, ok3) and np.array_equal(one, three)
