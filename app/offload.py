"""Big job files read and written in a helper process, so the GUI thread never waits.

A worker *thread* does not keep the window responsive by itself: ``json.loads`` of a 50 MB
job file, and ``json.dumps`` of a big job, are single C calls that hold Python's GIL for
seconds, and the GUI thread cannot run until they return (bench/bench_gui.py measured a
13 s freeze loading back the job of a 1 M-point file from a worker thread). So the JSON
work of a big job runs in a separate process (``spawn``: no fork of a threaded Qt process),
and the job travels between the processes as many small pickles (strokes in chunks of at
most :data:`CHUNK_SEGMENTS` segments): the thread unpickling them releases the GIL between
chunks, so no single call blocks the GUI for long.

Small jobs are handled in the calling thread (a process start costs about a second).
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import os
import pickle
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path as FsPath
from typing import Any

from galvo_core.errors import GalvoError
from galvo_core.job import Job, Stroke

#: A job file bigger than this (bytes) is read in a helper process.
BIG_JOB_BYTES = 8_000_000
#: A job with more marks + segments than this is written in a helper process.
BIG_JOB_ITEMS = 300_000
#: Strokes travel in pickles of at most this many segments (one stroke is never split).
CHUNK_SEGMENTS = 20_000


def _stroke_chunks(strokes: tuple[Stroke, ...]) -> list[bytes]:
    out: list[bytes] = []
    group: list[Stroke] = []
    n = 0
    for s in strokes:
        group.append(s)
        n += len(s.segments) + 1
        if n >= CHUNK_SEGMENTS:
            out.append(pickle.dumps(group, protocol=pickle.HIGHEST_PROTOCOL))
            group, n = [], 0
    if group:
        out.append(pickle.dumps(group, protocol=pickle.HIGHEST_PROTOCOL))
    return out


def job_to_blobs(job: Job) -> tuple[bytes, list[bytes]]:
    """The job as a header pickle (without strokes) and stroke chunks."""
    header = pickle.dumps(dataclasses.replace(job, strokes=()),
                          protocol=pickle.HIGHEST_PROTOCOL)
    return header, _stroke_chunks(job.strokes)


def job_from_blobs(header: bytes, blobs: list[bytes],
                   cancel: Callable[[], bool] | None = None) -> Job:
    """The inverse of :func:`job_to_blobs` (one small unpickle per chunk)."""
    job = pickle.loads(header)
    strokes: list[Stroke] = []
    for b in blobs:
        if cancel is not None and cancel():
            from galvo_core.pipeline import Cancelled

            raise Cancelled()
        strokes.extend(pickle.loads(b))
    return dataclasses.replace(job, strokes=tuple(strokes))


def _child_load(path: str) -> tuple[str, Any]:  # runs in the helper process
    from galvo_core.job import load_job

    try:
        return "ok", job_to_blobs(load_job(path))
    except GalvoError as exc:
        return "error", str(exc)
    except Exception as exc:  # noqa: BLE001 - reported as one line
        return "error", f"{path}: {type(exc).__name__}: {exc}"


def _child_write(module: str, name: str, header: bytes, blobs: list[bytes],
                 path: str) -> tuple[str, Any]:  # runs in the helper process
    import importlib

    try:
        fn = getattr(importlib.import_module(module), name)
        fn(job_from_blobs(header, blobs), path)
        return "ok", path
    except GalvoError as exc:
        return "error", str(exc)
    except Exception as exc:  # noqa: BLE001
        return "error", f"{path}: {type(exc).__name__}: {exc}"


def _run(fn: Callable[..., tuple[str, Any]], *args: Any) -> Any:
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=1, mp_context=ctx) as ex:
        status, value = ex.submit(fn, *args).result()
    if status != "ok":
        raise GalvoError(value)
    return value


def load_job_file(path: FsPath, load: Callable[[FsPath], Job],
                  cancel: Callable[[], bool] | None = None) -> Job:
    """``load(path)`` here for a small file; a big one in a helper process."""
    try:
        big = os.path.getsize(path) > BIG_JOB_BYTES
    except OSError:
        big = False
    if not big:
        return load(path)
    header, blobs = _run(_child_load, os.fspath(path))
    return job_from_blobs(header, blobs, cancel)


def job_items(job: Job) -> int:
    return sum(len(s.marks) + len(s.segments) for s in job.strokes)


def write_job_file(write: Callable[[Job, FsPath], None], job: Job, path: FsPath) -> None:
    """``write(job, path)`` here for a small job or a writer that is not a module-level
    function of galvo_core; a big job in a helper process."""
    module, name = getattr(write, "__module__", ""), getattr(write, "__qualname__", "")
    if (job_items(job) <= BIG_JOB_ITEMS or not module.startswith("galvo_core.")
            or "." in name or "<" in name):
        write(job, path)
        return
    header, blobs = job_to_blobs(job)
    _run(_child_write, module, name, header, blobs, os.fspath(path))
