"""Big job files read and written in a helper process, so the GUI thread never waits.

A worker *thread* does not keep the window responsive by itself: ``json.loads`` of a 50 MB
job file, and ``json.dumps`` of a big job, are single C calls that hold Python's GIL for
seconds, and the GUI thread cannot run until they return (bench/bench_gui.py measured a
13 s freeze loading back the job of a 1 M-point file from a worker thread). So the JSON
work of a big job runs in a separate process (``spawn``: no fork of a threaded Qt process),
and the job travels between the processes as many small pickles (strokes in chunks of at
most :data:`CHUNK_SEGMENTS` segments): the thread unpickling them releases the GIL between
chunks, so no single call blocks the GUI for long.

Writing needs no second process: :func:`job_json_bytes` makes the very bytes of
``write_job`` with one small ``json.dumps`` per stroke, so the GIL changes hands between
them. Small jobs are handled in the calling thread (a process start costs about a second).
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import os
import pickle
import tempfile
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path as FsPath
from typing import Any

from galvo_core.errors import GalvoError
from galvo_core.job import Job, Stroke

#: A job file bigger than this (bytes) is read in a helper process: ``json.loads`` holds
#: the GIL for the whole parse, about 14 ms of CPU per MB (an 8 MB job: 111 ms CPU, 440 ms
#: wall at load 4.8; read in the worker thread it stalled the GUI thread 168 ms), so the
#: bound keeps that one call near 30 ms of CPU; the helper process costs about a second.
BIG_JOB_BYTES = 2_000_000
#: A job with more marks + segments than this is written stroke by stroke.
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


def _child_load(path: str, out: str) -> tuple[str, Any]:  # runs in the helper process
    """Read the job file and write it to ``out`` as length-prefixed pickles (header, then
    stroke chunks); the parent reads them back one by one."""
    from galvo_core.job import load_job

    try:
        header, blobs = job_to_blobs(load_job(path))
        with open(out, "wb") as fh:
            for b in (header, *blobs):
                fh.write(len(b).to_bytes(8, "little"))
                fh.write(b)
        return "ok", len(blobs)
    except GalvoError as exc:
        return "error", str(exc)
    except Exception as exc:  # noqa: BLE001 - reported as one line
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
    """``load(path)`` here for a small file; a big one in a helper process, handed back
    through a temporary file read chunk by chunk (reading releases the GIL, and each
    unpickle is small)."""
    try:
        big = os.path.getsize(path) > BIG_JOB_BYTES
    except OSError:
        big = False
    if not big:
        return load(path)
    fd, tmp = tempfile.mkstemp(prefix="galvo-job-", suffix=".pickles")
    os.close(fd)
    try:
        _run(_child_load, os.fspath(path), tmp)
        blobs: list[bytes] = []
        with open(tmp, "rb") as fh:
            while True:
                n = fh.read(8)
                if len(n) < 8:
                    break
                blobs.append(fh.read(int.from_bytes(n, "little")))
    finally:
        try:
            os.unlink(tmp)
        except OSError:
            pass
    return job_from_blobs(blobs[0], blobs[1:], cancel)


_TOKEN = "\x00strokes\x00"


def job_json_bytes(job: Job, cancel: Callable[[], bool] | None = None) -> bytes:
    """Exactly the bytes :func:`galvo_core.job.write_job` writes, made stroke by stroke:
    many small ``json.dumps`` calls instead of one that holds the GIL for seconds."""
    import json

    head = dataclasses.replace(job, strokes=()).to_json()
    head["strokes"] = _TOKEN
    text = json.dumps(head, separators=(",", ":"), allow_nan=False)
    token = json.dumps(_TOKEN)
    assert text.count(token) == 1
    before, after = text.split(token)
    # encoded in groups of strokes, joined once as bytes: one join + encode of the whole
    # 50 MB text held the interpreter lock for 0.1 s (a GUI stall)
    chunks: list[bytes] = [(before + "[").encode("utf-8")]
    parts: list[str] = []
    for i, s in enumerate(job.strokes):
        if i % 256 == 0:
            if cancel is not None and cancel():
                from galvo_core.pipeline import Cancelled

                raise Cancelled()
            if parts:
                chunks.append("".join(parts).encode("utf-8"))
                parts = []
        if i:
            parts.append(",")
        parts.append(json.dumps(s.to_json(), separators=(",", ":"), allow_nan=False))
    parts.extend(("]", after))
    chunks.append("".join(parts).encode("utf-8"))
    return b"".join(chunks)


def job_items(job: Job) -> int:
    return sum(len(s.marks) + len(s.segments) for s in job.strokes)


def write_job_file(write: Callable[[Job, FsPath], None], job: Job, path: FsPath) -> None:
    """``write(job, path)``; the job file writer of galvo_core (:func:`write_job`) for a
    big job is replaced by the same bytes made stroke by stroke (:func:`job_json_bytes`),
    written atomically the same way."""
    from galvo_core.job import atomic_write_bytes, write_job

    if write is write_job and job_items(job) > BIG_JOB_ITEMS:
        atomic_write_bytes(path, job_json_bytes(job))
        return
    write(job, path)
