"""galvo-core as a user runs it: exit codes, one-line errors, JSON, job files."""

from __future__ import annotations

import json
import re

import pytest
from _util import SAMPLES, circle_plt, run_cli, run_cli_subprocess

from galvo_core.job import load_job


def test_info_reports_geometry_as_json():
    r = run_cli("info", str(SAMPLES / "curve_1181.plt"))
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout)
    for key in ("paths", "points", "closed_paths", "bbox", "size_mm", "commands", "warnings"):
        assert key in info
    assert info["points"] == 1181
    assert info["paths"] == 1 and info["closed_paths"] == 1
    xmin, ymin, xmax, ymax = info["bbox"]
    assert info["size_mm"] == pytest.approx([(xmax - xmin) / 40, (ymax - ymin) / 40])
    assert info["commands"]["PD"] > 0


@pytest.mark.parametrize(
    "content, reason",
    [
        (b"", "empty"),
        (b"<svg xmlns='http://www.w3.org/2000/svg'></svg>", "SVG"),
        (b"0\nSECTION\n2\nHEADER\n", "DXF"),
        (bytes(range(256)) * 8, "not HP-GL"),
    ],
)
def test_refused_files_exit_2_with_one_error_line(tmp_path, content, reason):
    f = tmp_path / "bad.plt"
    f.write_bytes(content)
    r = run_cli("info", str(f))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:")
    assert "bad.plt" in lines[0] and reason.lower() in lines[0].lower()
    assert "Traceback" not in r.stderr and r.stdout == ""


def test_missing_file_and_bad_option_exit_2(tmp_path):
    r = run_cli("info", str(tmp_path / "nope.plt"))
    assert r.returncode == 2 and r.stderr.startswith("error:") and "nope.plt" in r.stderr
    r = run_cli("process", str(SAMPLES / "curve_1181.plt"), "-o", str(tmp_path / "j.json"),
                "--e-per", "banana")
    assert r.returncode == 2 and r.stderr.startswith("error:")
    assert not (tmp_path / "j.json").exists()


@pytest.mark.parametrize("opt, value", [("--e-per", "0"), ("--e-per", "-1"),
                                         ("--eps-line", "nan"), ("--magnification", "-3"),
                                         ("--chord-tol-bits", "0")])
def test_bad_values_refused_without_output(tmp_path, opt, value):
    out = tmp_path / "job.json"
    r = run_cli("process", str(SAMPLES / "curve_1181.plt"), "-o", str(out), f"{opt}={value}")
    assert r.returncode == 2, r.stdout
    assert r.stderr.startswith("error:") and "Traceback" not in r.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_help_for_every_subcommand():
    for sub in ("info", "process", "report"):
        r = run_cli(sub, "--help")
        assert r.returncode == 0 and "usage:" in r.stdout


def test_process_writes_a_job_per_spec(tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt())
    out = tmp_path / "job.json"
    r = run_cli("process", str(src), "-o", str(out), "--magnification", "36",
                "--e-per", "0.05", "--chord-tol-bits", "2")
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)
    assert summary["stats"]["mark_points"] > 0
    # where the time went, per stage (wall seconds): the read, the stages run, the write
    t = summary["timings_s"]
    assert list(t)[0] == "read" and list(t)[-1] == "write"
    assert {"fit", "sample"} <= set(t) and all(v >= 0 for v in t.values())
    doc = json.loads(out.read_text("utf-8"))
    assert doc["format"] == "galvo-job" and doc["version"] == 1
    assert doc["magnification"] == 36.0
    assert doc["params"]["e_per"] == 0.05 and doc["params"]["chord_tol_bits"] == 2.0
    for key in ("eps_line", "eps_sum", "min_step_bits", "interpolation", "kerf_mm", "fill",
                "scan_order", "hatch_spacing_mm"):
        assert key in doc["params"]
    for key in ("mark_speed_mm_s", "jump_speed_mm_s", "frequency_khz", "laser_on_delay_us"):
        assert key in doc["laser"]
    (stroke,) = doc["strokes"]
    assert stroke["kind"] == "contour" and stroke["source_index"] == 0 and stroke["closed"]
    segs = stroke["segments"]
    assert any(s["type"] == "cubic" for s in segs)
    # continuous segments, marks in their direction starting at the first segment's start
    for a, b in zip(segs, segs[1:], strict=False):
        assert a["points"][-1] == b["points"][0]
    x0, y0 = segs[0]["points"][0]
    ox, oy = doc["offset_bits"]
    assert stroke["marks"][0] == [round(x0 * 36 + ox), round(y0 * 36 + oy)]
    marks = stroke["marks"]
    assert all(0 <= v <= 65535 and isinstance(v, int) for m in marks for v in m)
    job = load_job(out)
    assert job.stats["mark_points"] == len(marks)
    assert doc["source"]["sha256"] == __import__("hashlib").sha256(src.read_bytes()).hexdigest()


def test_drawing_too_large_for_field_is_refused_or_clamped(tmp_path):
    src = tmp_path / "circle.plt"
    src.write_bytes(circle_plt(r=4000, cx=5000, cy=5000))
    out = tmp_path / "job.json"
    r = run_cli("process", str(src), "-o", str(out), "--magnification", "36")
    assert r.returncode == 2 and "field" in r.stderr and not out.exists()
    r = run_cli("process", str(src), "-o", str(out), "--magnification", "36", "--clamp")
    assert r.returncode == 0
    assert any("clamped" in w["message"] for w in json.loads(r.stdout)["warnings"])
    r = run_cli("process", str(src), "-o", str(out), "--fit-field")
    assert r.returncode == 0
    doc = json.loads(out.read_text())
    xs = [m[0] for s in doc["strokes"] for m in s["marks"]]
    assert min(xs) >= 0 and max(xs) <= 65535 and max(xs) - min(xs) > 60000


def test_report_prints_table1_and_magnifications():
    r = run_cli("report", str(SAMPLES / "curve_1181.plt"), "--json", "--magnification", "36",
                "72")
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    t = rep["table1"]
    assert t["input_points"] == 1181
    assert t["control_points"] < t["points_after_thinning"] < t["input_points"]
    assert t["max_true_error"] <= 0.02
    m36, m72 = rep["magnifications"]
    assert m36["raw"]["mark_points"] == m72["raw"]["mark_points"]
    assert m36["adaptive"]["mark_points"] < m72["adaptive"]["mark_points"] < 1181


def test_process_exports_plt_and_svg_that_read_back(tmp_path):
    out = tmp_path / "job.json"
    r = run_cli("process", str(SAMPLES / "curve_1181.plt"), "-o", str(out), "--magnification",
                "36", "--plt", str(tmp_path / "job.plt"), "--svg", str(tmp_path / "job.svg"))
    assert r.returncode == 0, r.stderr
    doc = json.loads(out.read_text())
    info = json.loads(run_cli("info", str(tmp_path / "job.plt")).stdout)
    assert info["points"] == sum(len(s["marks"]) for s in doc["strokes"])
    svg = (tmp_path / "job.svg").read_text()
    assert svg.lstrip().startswith(("<?xml", "<svg"))
    assert re.search(r"<path[^>]* d=\"M[^\"]*C", svg), "fitted cubics are written as C commands"


def test_kerf_fill_and_order_options_reach_the_job(tmp_path):
    out = tmp_path / "job.json"
    base = ("process", str(SAMPLES / "seal.plt"), "-o", str(out), "--fit-field")
    r = run_cli(*base, "--fill", "scanline", "--hatch-spacing-mm", "0.3")
    assert r.returncode == 0, r.stderr
    scan = json.loads(r.stdout)["stats"]
    r = run_cli(*base, "--fill", "zigzag", "--hatch-spacing-mm", "0.3", "--scan-order",
                "greedy", "--kerf-mm", "0.2")
    assert r.returncode == 0, r.stderr
    zig = json.loads(r.stdout)["stats"]
    assert zig["laser_switches"] < scan["laser_switches"]
    doc = json.loads(out.read_text())
    assert doc["params"]["kerf_mm"] == 0.2 and doc["params"]["fill"] == "zigzag"
    assert doc["params"]["scan_order"] == "greedy"
    assert {s["kind"] for s in doc["strokes"]} == {"contour", "hatch"}
    r = run_cli(*base, "--kerf-mm", "-0.1")
    assert r.returncode == 2 and r.stderr.startswith("error:") and "kerf_mm" in r.stderr


def test_end_to_end_in_a_subprocess(tmp_path):
    """The one test that starts ``galvo-core`` as a separate program: exit codes, the JSON
    summary on stdout, one error line on stderr, the job on disk."""
    out = tmp_path / "job.json"
    r = run_cli_subprocess("process", str(SAMPLES / "curve_1181.plt"), "-o", str(out),
                           "--magnification", "36")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["stats"]["strokes"] >= 1
    assert json.loads(out.read_text())["version"] == 1
    bad = run_cli_subprocess("info", str(tmp_path / "missing.plt"))
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1
    assert bad.stderr.startswith("error: ") and "Traceback" not in bad.stderr


def test_report_gives_segments_and_worst_error_per_path_within_its_bound():
    """Issue 16: `report` prints, per path, its segments and its worst true error against
    the bound in effect (e_per beyond the file's rounding); none above it."""
    r = run_cli("report", str(SAMPLES / "dense_logo.plt"), "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["table1"]["quantum_units"] == 1.0  # a whole-unit file
    paths = out["paths"]
    assert len(paths) > 10
    assert sum(p["segments"] for p in paths) == out["table1"]["lines"] + out["table1"]["cubics"]
    for p in paths:
        assert p["lines"] + p["cubics"] == p["segments"]
        assert p["max_error"] <= p["bound"] * (1 + 1e-9)


def test_one_blas_thread_unless_the_user_chose_otherwise():
    """galvo_core asks OpenBLAS for one thread before numpy loads (its pool cost 0.1-0.3 s
    of every CLI start on a busy machine), but an explicit setting of the user's stands."""
    import os
    import subprocess
    import sys

    code = ("import os, galvo_core, numpy; "
            "print(os.environ['OPENBLAS_NUM_THREADS'], os.environ['OMP_NUM_THREADS'])")
    env = {k: v for k, v in os.environ.items()
           if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=120, check=True).stdout.split()
    assert out == ["1", "1"]
    env["OPENBLAS_NUM_THREADS"] = "2"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=120, check=True).stdout.split()
    assert out == ["2", "1"]


def test_a_plain_process_run_imports_no_kerf_fill_or_order(tmp_path):
    """`process` without kerf, fill or a scan order does not import them (nor shapely, a
    tenth of a second of every start); with them, it does."""
    import subprocess
    import sys

    from _util import ROOT, SAMPLES

    code = ("import sys; from galvo_core.cli import main; rc = main(sys.argv[1:]); "
            "print(rc, sorted(m for m in ('shapely', 'galvo_core.kerf', 'galvo_core.fill', "
            "'galvo_core.order') if m in sys.modules))")
    src = str(SAMPLES / "seal.plt")
    plain = subprocess.run([sys.executable, "-c", code, "process", src, "-o",
                            str(tmp_path / "a.gjob"), "--fit-field"], capture_output=True,
                           text=True, cwd=ROOT, check=True)
    assert plain.stdout.splitlines()[-1] == "0 []"
    full = subprocess.run([sys.executable, "-c", code, "process", src, "-o",
                           str(tmp_path / "b.gjob"), "--fit-field", "--kerf-mm", "0.1",
                           "--fill", "zigzag", "--scan-order", "greedy"], capture_output=True,
                          text=True, cwd=ROOT, check=True)
    assert full.stdout.splitlines()[-1] == ("0 ['galvo_core.fill', 'galvo_core.kerf', "
                                            "'galvo_core.order', 'shapely']")
