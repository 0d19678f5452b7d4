"""Run a compiled per-item kernel over contiguous chunks of its items on a few threads.

The fitter's kernels (numba, ``nogil=True``) treat their items (pieces, paths) one at a
time and write each item's results to that item's own place in the output arrays, so a
call over items ``lo:hi`` of every per-item argument computes exactly what the whole call
computes for those items: the chunks can run at once on several threads, and the result is
the same, bit for bit, whatever the number of threads (tests compare the fits).

``GALVO_THREADS`` (environment, read at import) sets the number of threads; the default is
the number of CPUs this process may run on, at most :data:`MAX_THREADS`. ``1`` runs every
kernel in one call on the calling thread, as before this module existed.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np

__all__ = ["THREADS", "MAX_THREADS", "MIN_WORK", "chunk_bounds", "run_chunks"]

#: more threads than this gain little on the kernels' memory traffic
MAX_THREADS = 8
#: below this much work (the items' summed weights, about input points) one call on the
#: calling thread is cheaper than handing chunks to other threads
MIN_WORK = 20_000


def _threads_from_env() -> int:
    v = os.environ.get("GALVO_THREADS", "").strip()
    if v:
        try:
            return max(1, min(int(v), 64))
        except ValueError:
            pass  # (a bad value: the default)
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # (not on every platform)
        n = os.cpu_count() or 1
    return max(1, min(n, MAX_THREADS))


THREADS = _threads_from_env()

_pool: ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()
_inside = threading.local()  # set on a pool thread while it runs a chunk


def _get_pool() -> ThreadPoolExecutor:
    global _pool
    with _pool_lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(max_workers=THREADS - 1,
                                       thread_name_prefix="galvo-kernel")
        return _pool


def chunk_bounds(weights: np.ndarray, parts: int) -> list[tuple[int, int]]:
    """Up to ``parts`` contiguous, non-empty index ranges covering ``range(len(weights))``,
    each about an equal share of the summed (non-negative) weights."""
    m = len(weights)
    parts = max(1, min(parts, m))
    if parts == 1:
        return [(0, m)] if m else []
    cum = np.cumsum(np.maximum(np.asarray(weights, dtype=np.float64), 0.0) + 1.0)
    cuts = np.searchsorted(cum, cum[-1] * np.arange(1, parts) / parts, side="right")
    # (in Python: a few numbers, called once per kernel call, where numpy's calls cost more)
    edges = sorted({0, m, *(min(max(c, 1), m - 1) for c in cuts.tolist())})
    return list(zip(edges[:-1], edges[1:], strict=True))


def _run_marked(fn: Callable[[int, int], object], lo: int, hi: int) -> object:
    _inside.on = True
    try:
        return fn(lo, hi)
    finally:
        _inside.on = False


def run_chunks(fn: Callable[[int, int], object], weights: np.ndarray, *,
               min_work: float | None = None) -> list[object]:
    """Call ``fn(lo, hi)`` over chunks of the items (``len(weights)`` of them) that cover
    them all, in order, and return the calls' results in chunk order. With more than one
    thread and at least ``min_work`` summed weight, the chunks run at once (the first on the
    calling thread); otherwise one call ``fn(0, m)``. ``min_work`` defaults to
    :data:`MIN_WORK`. ``fn`` must write only its own items'
    places (every kernel here does). An exception in any chunk is raised here, after every
    chunk has ended."""
    m = len(weights)
    if (THREADS <= 1 or m < 2 or getattr(_inside, "on", False)
            or float(np.sum(weights)) < (MIN_WORK if min_work is None else min_work)):
        return [fn(0, m)]
    bounds = chunk_bounds(weights, THREADS)
    if len(bounds) == 1:
        return [fn(0, m)]
    pool = _get_pool()
    futs: list[Future[object]] = [pool.submit(_run_marked, fn, lo, hi)
                                  for lo, hi in bounds[1:]]
    try:
        # (marked as the pool's chunks are: a call to run_chunks inside ``fn`` runs inline,
        # not waiting for a pool thread busy with another chunk)
        first = _run_marked(fn, *bounds[0])
    finally:
        rest = []
        err: BaseException | None = None
        for f in futs:
            try:
                rest.append(f.result())
            except BaseException as e:  # noqa: BLE001 (re-raised below, after every chunk)
                err = err or e
    if err is not None:
        raise err
    return [first, *rest]
