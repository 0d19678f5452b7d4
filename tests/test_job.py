"""The job file: version 1 JSON written in bulk (the same bytes as json.dumps), the compact
version 2 (.gjob, docs/job-format.md) chosen by extension, both loaded back exactly, bad
files refused with one clear message, the array form of fitted paths and stroke segments."""

from __future__ import annotations

import json
import os
import struct

import numpy as np
import pytest
from _util import SAMPLES, run_cli

from galvo_core.errors import InputError
from galvo_core.fit import FittedPath, Segment, fit_path
from galvo_core.hpgl import read_file
from galvo_core.job import (
    MAGIC,
    Segments,
    Stroke,
    compact_job_bytes,
    job_json_bytes,
    load_job,
    write_job,
)
from galvo_core.params import Params
from galvo_core.pipeline import Pipeline


@pytest.fixture(scope="module")
def jobs():
    """A contour job with lines and cubics, and one with hatch strokes and greedy order
    (reversed strokes) on a kerf-compensated drawing."""
    d = read_file(SAMPLES / "seal.plt")
    plain = Pipeline().run(d, Params(fit_field=True, e_per=0.75)).job
    filled = Pipeline().run(d, Params(fit_field=True, e_per=0.75, fill="zigzag",
                                      hatch_spacing_mm=0.5, scan_order="greedy",
                                      kerf_mm=0.1)).job
    return plain, filled


def _same_job(a, b) -> None:
    assert (a.source_name, a.source_sha256) == (b.source_name, b.source_sha256)
    assert a.field_map == b.field_map
    assert a.params == b.params and a.laser == b.laser
    assert a.stats == b.stats and a.warnings == b.warnings
    assert len(a.strokes) == len(b.strokes)
    for x, y in zip(a.strokes, b.strokes, strict=True):
        assert (x.kind, x.source_index, x.closed, x.pen) == (y.kind, y.source_index, y.closed,
                                                              y.pen)
        assert x.marks.dtype == np.int64 and np.array_equal(x.marks, y.marks)
        assert np.array_equal(x.segments.is_cubic, y.segments.is_cubic)
        assert np.array_equal(x.segments.points, y.segments.points)  # bit for bit


def test_both_jobs_have_what_the_tests_need(jobs):
    plain, filled = jobs
    kinds = {bool(c) for s in plain.strokes for c in s.segments.is_cubic}
    assert kinds == {True, False}
    assert {s.kind for s in filled.strokes} == {"contour", "hatch"}


def test_json_writer_gives_the_bytes_of_json_dumps(jobs):
    for job in jobs:
        want = json.dumps(job.to_json(), separators=(",", ":"), allow_nan=False)
        assert job_json_bytes(job) == want.encode("utf-8")


def test_the_extension_chooses_the_form_and_both_load_back_exactly(jobs, tmp_path):
    for job in jobs:
        for name in ("job.json", "job.gjob", "JOB.GJOB", "job.txt"):
            out = tmp_path / name
            write_job(job, out)
            head = out.read_bytes()[:8]
            assert (head == MAGIC) == name.lower().endswith(".gjob")
            if head != MAGIC:
                assert json.loads(out.read_bytes())["version"] == 1
            _same_job(load_job(out), job)


def test_the_compact_form_is_small(jobs, tmp_path):
    for job in jobs:
        a, b = tmp_path / "a.json", tmp_path / "a.gjob"
        write_job(job, a)
        write_job(job, b)
        head = len(json.dumps(job.header_json()))
        n = sum(len(s.marks) for s in job.strokes)
        c = sum(len(s.segments.points) for s in job.strokes)
        # 8 bytes per mark, 16 per shared control point, a few dozen per stroke, the header
        assert os.path.getsize(b) <= 8 * n + 17 * c + 40 * len(job.strokes) + head + 1024
        assert os.path.getsize(b) - head < 0.6 * (os.path.getsize(a) - head)


def test_cli_writes_the_compact_form_by_extension(tmp_path):
    out = tmp_path / "job.gjob"
    r = run_cli("process", str(SAMPLES / "curve_1181.plt"), "-o", str(out), "--fit-field")
    assert r.returncode == 0, r.stderr
    assert out.read_bytes()[:8] == MAGIC
    js = tmp_path / "job.json"
    assert run_cli("process", str(SAMPLES / "curve_1181.plt"), "-o", str(js),
                   "--fit-field").returncode == 0
    _same_job(load_job(out), load_job(js))


def test_an_interrupted_compact_write_leaves_the_old_file(jobs, tmp_path, monkeypatch):
    out = tmp_path / "job.gjob"
    out.write_bytes(b"old")

    def die(fd):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "fsync", die)
    with pytest.raises(KeyboardInterrupt):
        write_job(jobs[0], out)
    assert out.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["job.gjob"]


# ------------------------------------------------------------------ bad compact files
def _head(raw: bytes) -> tuple[dict, int]:
    _, _, h = struct.unpack_from("<8sII", raw, 0)
    return json.loads(raw[16:16 + h]), 16 + h


def _with_head(raw: bytes, head: dict) -> bytes:
    hb = json.dumps(head).encode()
    hb += b" " * (-(16 + len(hb)) % 8)
    _, data0 = _head(raw)
    return struct.pack("<8sII", MAGIC, 2, len(hb)) + hb + raw[data0:]


def _refused(tmp_path, data: bytes, match: str) -> None:
    p = tmp_path / "bad.gjob"
    p.write_bytes(data)
    with pytest.raises(InputError, match=match) as e:
        load_job(p)
    assert str(e.value).startswith(str(p) + ": ")


def test_bad_compact_files_are_refused_with_the_place(jobs, tmp_path):
    raw = compact_job_bytes(jobs[1])
    head, data0 = _head(raw)
    _refused(tmp_path, raw[:10], "truncated")
    _refused(tmp_path, raw[:len(raw) - 9], "runs past the end")
    _refused(tmp_path, MAGIC + struct.pack("<II", 3, 0), "version 3")
    _refused(tmp_path, raw[:16] + b"\xff" + raw[17:], "header is not")
    h = json.loads(json.dumps(head))
    h["arrays"]["marks"]["dtype"] = "<f8"
    _refused(tmp_path, _with_head(raw, h), "arrays.marks.dtype")
    h = json.loads(json.dumps(head))
    h["n_strokes"] += 1
    _refused(tmp_path, _with_head(raw, h), "n_strokes")
    # a stroke offset out of order
    h = head["arrays"]["stroke_mark_start"]
    bad = bytearray(raw)
    struct.pack_into("<q", bad, data0 + h["offset"] + 8, 10**9)
    _refused(tmp_path, bytes(bad), "stroke_mark_start")
    # a mark outside the field
    m = head["arrays"]["marks"]
    bad = bytearray(raw)
    struct.pack_into("<i", bad, data0 + m["offset"] + 8 * 5, 70000)
    _refused(tmp_path, bytes(bad), r"strokes\[\d+\]\.marks leave the field")
    # a segment kind code that means nothing; a point count that does not match the kinds
    k = head["arrays"]["segment_is_cubic"]
    bad = bytearray(raw)
    bad[data0 + k["offset"]] = 7
    _refused(tmp_path, bytes(bad), "segment_is_cubic")
    bad = bytearray(raw)
    bad[data0 + k["offset"]] ^= 1
    _refused(tmp_path, bytes(bad), r"strokes\[\d+\]: \d+ control points")
    p = head["arrays"]["points"]
    bad = bytearray(raw)
    struct.pack_into("<d", bad, data0 + p["offset"], float("nan"))
    _refused(tmp_path, bytes(bad), "finite")


def test_v1_with_discontinuous_segments_is_refused(jobs, tmp_path):
    doc = jobs[0].to_json()
    s = next(s for s in doc["strokes"] if len(s["segments"]) > 1)
    s["segments"][1]["points"][0][0] += 0.5
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(doc))
    with pytest.raises(InputError, match=r"strokes\[\d+\]\.segments: segment 1 does not start"):
        load_job(p)


# ------------------------------------------------------------------ the array types
def test_segments_behave_as_the_v1_pairs_and_reverse_and_rotate_exactly(jobs):
    st = next(s for s in jobs[0].strokes if s.closed and len(s.segments) > 3)
    segs = st.segments
    pairs = list(segs)
    assert len(pairs) == len(segs) and segs[-1][0] == pairs[-1][0]
    for (k, p), c in zip(pairs, segs.is_cubic, strict=True):
        assert k == ("cubic" if c else "line") and p.shape == ((4 if c else 2), 2)
    rev = [(k, p[::-1]) for k, p in reversed(pairs)]
    for (k, p), (k2, p2) in zip(segs.reversed(), rev, strict=True):
        assert k == k2 and np.array_equal(p, p2)
    t = 2
    for (k, p), (k2, p2) in zip(segs.rotated(t), pairs[t:] + pairs[:t], strict=True):
        assert k == k2 and np.array_equal(p, p2)
    again = Segments.from_pairs(pairs)
    assert np.array_equal(again.points, segs.points)
    # a Stroke given pairs converts them; the dataclass replace (the order stage) too
    s2 = Stroke("contour", 0, True, st.marks, pairs)
    assert isinstance(s2.segments, Segments)
    assert np.array_equal(s2.segments.points, segs.points)


def test_fitted_path_arrays_and_segment_objects_agree():
    t = np.linspace(0, np.pi, 400)
    pts = np.column_stack([1000 * np.cos(t), 1000 * np.sin(t)])
    pts = np.vstack([pts, [[-1000, -500], [1000, -500]]])
    fp = fit_path(pts, closed=True, e_per=0.2, eps_line=0.2)
    assert fp.n_cubics > 0 and fp.n_lines > 0
    segs = fp.segments
    assert len(segs) == len(fp.is_cubic) == len(fp.first)
    assert segs[0].points[0].tolist() == fp.points[0].tolist()
    for a, b in zip(segs, segs[1:], strict=False):
        assert np.array_equal(a.end, b.start) and a.last == b.first
    assert np.array_equal(segs[-1].end, segs[0].start)  # closed
    assert len(fp.points) == 1 + fp.n_lines + 3 * fp.n_cubics
    for a in (fp.is_cubic, fp.points, fp.first, fp.last):
        assert not a.flags.writeable
    same = FittedPath(fp.source_index, fp.pen, fp.closed, segs, fp.max_error, fp.n_input,
                      fp.n_thinned)
    assert np.array_equal(same.points, fp.points)
    assert np.array_equal(same.is_cubic, fp.is_cubic)
    with pytest.raises(ValueError, match="does not start"):
        FittedPath(0, 1, False, (Segment("line", np.array([[0.0, 0], [1, 0]]), 0, 1),
                                 Segment("line", np.array([[2.0, 0], [3, 0]]), 1, 2)))
    with pytest.raises(AttributeError):
        fp.closed = False  # type: ignore[misc]


def test_a_run_and_both_writers_build_no_object_per_segment(tmp_path):
    """Arrays end to end: processing, ordering (reversing and rotating closed strokes) and
    writing a job never build a Segment object or a (kind, points) pair per segment."""
    import galvo_core.job as jobmod

    d = read_file(SAMPLES / "seal.plt")
    p = Pipeline()
    calls = {"pairs": 0}
    real_iter = jobmod.Segments.__iter__

    def counting_iter(self):  # type: ignore[no-untyped-def]
        calls["pairs"] += 1
        return real_iter(self)

    jobmod.Segments.__iter__ = counting_iter  # type: ignore[method-assign]
    try:
        job = p.run(d, Params(fit_field=True, e_per=0.75, scan_order="greedy", fill="zigzag",
                              hatch_spacing_mm=0.5)).job
        write_job(job, tmp_path / "a.gjob")
        write_job(job, tmp_path / "a.json")
    finally:
        jobmod.Segments.__iter__ = real_iter  # type: ignore[method-assign]
    assert calls["pairs"] == 0
    fitted = p.fitted(d, Params(fit_field=True, e_per=0.75))
    assert all(fp._segments is None for fp in fitted)  # no Segment objects were built
    assert sum(len(s.segments) for s in job.strokes) == sum(fp.n_segments for fp in fitted)


def _same_columns(a, b) -> None:
    assert a.strokes is b.strokes
    for name in ("kind", "closed", "pen", "source_index", "mark_count", "marks",
                 "segment_count", "is_cubic", "point_count", "points"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape and np.array_equal(x, y), name


def test_a_pipeline_job_carries_its_strokes_as_columns(tmp_path):
    """A job in file order gets the columns of its strokes from the stages' arrays (the
    .gjob writer then copies arrays instead of looping over the strokes): they are exactly
    the strokes' own, and the file is byte for byte the one written from the strokes."""
    import dataclasses

    from galvo_core.job import StrokeColumns

    d = read_file(SAMPLES / "seal.plt")
    p = Pipeline()
    runs = [Params(fit_field=True, e_per=0.75),
            Params(fit_field=True, e_per=0.75, fill="zigzag", hatch_spacing_mm=0.5,
                   kerf_mm=0.1),
            Params(magnification=100.0, clamp=True, e_per=0.75)]
    for params in runs:
        job = p.run(d, params).job
        assert job.columns is not None
        _same_columns(job.columns, StrokeColumns.of(job.strokes))
        bare = dataclasses.replace(job, columns=None)
        assert bare.columns is None
        assert compact_job_bytes(job) == compact_job_bytes(bare)
    assert {s.kind for s in job.strokes} == {"contour"}
    assert runs[2].clamp and "clamped" in " ".join(w.message for w in job.warnings)
    # ordered strokes: the columns follow the order (strokes moved, closed ones started
    # at another joint, some reversed)
    greedy = p.run(d, Params(fit_field=True, e_per=0.75, scan_order="greedy")).job
    assert greedy.columns is not None
    _same_columns(greedy.columns, StrokeColumns.of(greedy.strokes))
    write_job(greedy, tmp_path / "g.gjob")
    _same_job(load_job(tmp_path / "g.gjob"), greedy)


def test_an_ordered_job_carries_its_columns_in_the_order(monkeypatch):
    """The order stage moves strokes, starts closed ones at another segment joint and
    reverses others; the job's columns (what the .gjob writer copies) follow every move:
    they equal the columns made from the ordered strokes themselves, with and without fill,
    on a drawing where the order rotates and reverses."""
    import galvo_core.order as order
    from galvo_core.job import StrokeColumns

    seen: list[tuple[int, int, bool]] = []
    real = order.apply_to_strokes

    def spy(strokes, placements, fm, *, moves=None):  # type: ignore[no-untyped-def]
        out = real(strokes, placements, fm, moves=moves)
        seen.extend(moves or [])
        return out

    monkeypatch.setattr(order, "apply_to_strokes", spy)
    # open strokes a line then an arc, stacked: the nearest end of the next is its far end,
    # so the order reverses every other one (a line-then-cubics stroke is not a palindrome)
    prog = ["IN;SP1;"]
    for k in range(8):
        y = 800 * k
        arc = [(700 + 300 * np.cos(a), y + 300 * np.sin(a)) for a in np.linspace(np.pi, 0, 60)]
        pts = [(0.0, y), (200.0, y), (400.0, y)] + arc
        prog.append(f"PU{pts[0][0]:.0f},{pts[0][1]:.0f};PD"
                    + ",".join(f"{x:.0f},{yy:.0f}" for x, yy in pts[1:]) + ";")
    from galvo_core.hpgl import read_bytes

    drawings = [read_bytes("".join(prog).encode(), "line_arcs.plt")]
    drawings += [read_file(SAMPLES / n) for n in ("seal.plt", "dense_logo.plt",
                                                  "arcs_circles.plt")]
    p = Pipeline()
    for d in drawings:
        for params in (Params(fit_field=True, scan_order="greedy"),
                       Params(fit_field=True, scan_order="optimized", order_time_budget_s=0.2,
                              fill="zigzag", hatch_spacing_mm=0.3, kerf_mm=0.05)):
            job = p.run(d, params).job
            assert job.columns is not None and job.columns.strokes is job.strokes
            _same_columns(job.columns, StrokeColumns.of(job.strokes))
    # the runs did move, rotate and reverse strokes (else this test would prove little)
    assert any(i != k for k, (i, _t, _r) in enumerate(seen))
    assert sum(t > 0 for _i, t, _r in seen) >= 5
    assert sum(r for _i, _t, r in seen) >= 5
    asym = [i for i, _t, r in seen[:16] if r]  # reversed among the line-arc drawing's first
    assert len(asym) >= 4


def test_columns_of_a_run_with_a_path_without_marks(monkeypatch):
    """A path the sampler gives no marks makes no stroke: its segments and control points
    leave the columns too."""
    import galvo_core.pipeline as pl
    from galvo_core.job import StrokeColumns

    real = pl.sample_paths

    def one_empty(fitted, *a, **k):  # type: ignore[no-untyped-def]
        res = real(fitted, *a, **k)
        res.marks[1] = res.marks[1][:0]
        return res

    monkeypatch.setattr(pl, "sample_paths", one_empty)
    d = read_file(SAMPLES / "seal.plt")
    p = Pipeline()
    job = p.run(d, Params(fit_field=True, e_per=0.75)).job
    fitted = p.fitted(d, Params(fit_field=True, e_per=0.75))
    assert len(job.strokes) == len(fitted) - 1 and fitted[1].n_segments > 0
    _same_columns(job.columns, StrokeColumns.of(job.strokes))


def test_writing_a_job_with_columns_makes_no_pass_over_its_strokes(tmp_path, monkeypatch):
    """The .gjob of a pipeline job, and of a job loaded from a .gjob, is written from its
    columns alone; columns never describe other strokes (replace, pickle)."""
    import dataclasses
    import pickle

    import galvo_core.job as jobmod

    d = read_file(SAMPLES / "seal.plt")
    job = Pipeline().run(d, Params(fit_field=True, e_per=0.75)).job
    want = compact_job_bytes(job)

    def refuse(strokes):  # type: ignore[no-untyped-def]
        raise AssertionError("a pass over the strokes")

    monkeypatch.setattr(jobmod.StrokeColumns, "of", classmethod(lambda cls, s: refuse(s)))
    write_job(job, tmp_path / "a.gjob")
    assert (tmp_path / "a.gjob").read_bytes() == want
    loaded = load_job(tmp_path / "a.gjob")
    write_job(loaded, tmp_path / "b.gjob")
    assert (tmp_path / "b.gjob").read_bytes() == want
    # the same strokes keep their columns, other strokes drop them
    assert dataclasses.replace(job, laser_source="co2").columns is job.columns
    assert dataclasses.replace(job, strokes=job.strokes[1:]).columns is None
    assert pickle.loads(pickle.dumps(job)).columns is None
    with pytest.raises(ValueError):
        job.with_columns(loaded.columns)
