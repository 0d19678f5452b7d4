"""Exports (HP-GL marks / segments, SVG), job files per the spec, atomic writes, CLI errors."""

from __future__ import annotations

import json
import os
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from _util import SAMPLES, circle_plt, run_cli

from galvo_core.errors import GalvoError, ParamError
from galvo_core.export import plt_bytes, write_plt, write_svg
from galvo_core.hpgl import read_bytes, read_file
from galvo_core.job import load_job, write_job
from galvo_core.params import Params
from galvo_core.pipeline import Pipeline


@pytest.fixture(scope="module")
def job():
    d = read_file(SAMPLES / "curve_1181.plt")
    return Pipeline().run(d, Params(magnification=36)).job


def test_plt_of_the_marks_reads_back_point_for_point(job, tmp_path):
    out = tmp_path / "marks.plt"
    write_plt(job, out)
    back = read_file(out)
    assert back.warnings == ()
    assert len(back.paths) == len(job.strokes)
    for p, s in zip(back.paths, job.strokes, strict=True):
        assert np.array_equal(p.points, s.marks)


def test_plt_of_the_segments_reads_back_close_to_the_fitted_curve(job):
    back = read_bytes(plt_bytes(job, what="segments"), "segments.plt")
    assert len(back.paths) == 1
    pts = back.paths[0].points
    # every read-back point lies on the fitted geometry (BZ flattened within 0.1 unit)
    from galvo_core.geometry import nearest_on_cubic, point_segment_distance

    best = np.full(len(pts), np.inf)
    for kind, seg in job.strokes[0].segments:
        if kind == "cubic":
            d = nearest_on_cubic(seg, pts)[1]
        else:
            d = point_segment_distance(pts, seg[0], seg[1])
        best = np.minimum(best, d)
    assert best.max() < 0.1
    with pytest.raises(ParamError):
        plt_bytes(job, what="everything")


def test_svg_has_cubic_paths_in_mm_and_optional_marks(job, tmp_path):
    out = tmp_path / "job.svg"
    write_svg(job, out)
    root = ET.parse(out).getroot()
    ns = "{http://www.w3.org/2000/svg}"
    assert root.get("width") == "110mm" and root.get("viewBox") == "0 0 110 110"
    paths = root.findall(f".//{ns}path")
    assert len(paths) == 1
    d = paths[0].get("d")
    assert d.startswith("M") and d.count("C") == job.stats["cubics"] and d.endswith("Z")
    nums = [float(v) for v in re.findall(r"-?\d+\.?\d*", d)]
    assert 0 <= min(nums) and max(nums) <= 110  # millimetres in the field
    # the first point is the first mark, in mm, y flipped
    fm = job.field_map
    m0 = job.strokes[0].marks[0] * fm.mm_per_bit
    assert nums[0] == pytest.approx(m0[0], abs=fm.mm_per_bit)
    assert nums[1] == pytest.approx(110 - m0[1], abs=fm.mm_per_bit)
    assert root.findall(f".//{ns}circle") == []
    write_svg(job, out, marks=True)
    dots = ET.parse(out).getroot().findall(f".//{ns}circle")
    assert len(dots) == job.stats["mark_points"]


def test_job_file_follows_the_spec_and_round_trips(job, tmp_path):
    out = tmp_path / "job.json"
    write_job(job, out)
    doc = json.loads(out.read_text("utf-8"))
    for key in ("format", "version", "generator", "source", "field", "magnification",
                "offset_bits", "params", "laser", "strokes", "stats"):
        assert key in doc
    assert doc["format"] == "galvo-job" and doc["version"] == 1
    assert doc["field"] == {"size_mm": 110.0, "bits": 65536}
    for key in ("eps_line", "e_per", "eps_sum", "chord_tol_bits", "min_step_bits",
                "interpolation", "kerf_mm", "fill", "scan_order"):
        assert key in doc["params"]
    for key in ("input_points", "control_points", "mark_points", "strokes", "mark_length_mm",
                "jump_length_mm", "estimated_time_s", "max_fit_error",
                "max_chord_height_bits", "laser_switches", "warnings"):
        assert key in doc["stats"]
    mag, (ox, oy) = doc["magnification"], doc["offset_bits"]
    for s in doc["strokes"]:
        assert s["kind"] in ("contour", "hatch")
        segs = s["segments"]
        for a, b in zip(segs, segs[1:], strict=False):
            assert a["points"][-1] == b["points"][0]
        x0, y0 = segs[0]["points"][0]
        assert s["marks"][0] == [round(x0 * mag + ox), round(y0 * mag + oy)]
        assert all(isinstance(v, int) and 0 <= v <= 65535 for m in s["marks"] for v in m)
    back = load_job(out)
    assert back.stats["mark_points"] == job.stats["mark_points"]
    for a, b in zip(back.strokes, job.strokes, strict=True):
        assert np.array_equal(a.marks, b.marks)
        assert [k for k, _ in a.segments] == [k for k, _ in b.segments]


@pytest.mark.parametrize("writer", ["job", "plt", "svg"])
def test_an_interrupted_write_leaves_the_old_file_intact(job, tmp_path, monkeypatch, writer):
    out = tmp_path / f"out.{writer}"
    out.write_bytes(b"the old file\n")
    before = out.read_bytes()

    def boom(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(GalvoError, match="cannot write"):
        if writer == "job":
            write_job(job, out)
        elif writer == "plt":
            write_plt(job, out)
        else:
            write_svg(job, out)
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]  # no temp file left

    # a failure in the middle of writing the bytes: the same
    monkeypatch.undo()
    real_fsync = os.fsync

    def die(fd):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "fsync", die)
    with pytest.raises(KeyboardInterrupt):
        write_job(job, out)
    monkeypatch.setattr(os, "fsync", real_fsync)
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]


def test_cli_refuses_out_of_field_and_bad_values_with_exit_2(tmp_path):
    src = tmp_path / "big.plt"
    src.write_bytes(circle_plt(r=4000, cx=5000, cy=5000))
    out = tmp_path / "job.json"
    r = run_cli("process", str(src), "-o", str(out), "--magnification", "36")
    assert r.returncode == 2 and r.stderr.startswith("error:") and "field" in r.stderr
    assert not out.exists()
    for opt, val in (("--chord-tol-bits", "0"), ("--min-step-bits", "-1"),
                     ("--interpolation", "spline"), ("--max-step-bits", "1")):
        r = run_cli("process", str(SAMPLES / "curve_1181.plt"), "-o", str(out), opt, val)
        assert r.returncode == 2, (opt, r.stderr)
        assert r.stderr.startswith("error:") and "Traceback" not in r.stderr
        assert not out.exists()
    r = run_cli("process", str(SAMPLES / "curve_1181.plt"), "-o", str(out),
                "--magnification", "36", "--interpolation", "fixed")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["stats"]["mark_points"] > 0
