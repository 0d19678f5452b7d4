"""``process --pens --lmc`` end to end (a two-pen file, replayed by the independent decoder),
refusals that write nothing, framing and correction files, ``send --dry-run``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from _util import run_cli

from galvo_core.job import load_job
from galvo_core.lmc import END_OF_LIST, decode, expected_strokes

PENS = """
[laser]
jump_speed_mm_s = 3000
[pen.1]
mark_speed_mm_s = 400
power_percent = 30
frequency_khz = 25
passes = 2
[pen.2]
mark_speed_mm_s = 150
power_percent = 85
frequency_khz = 80
"""


def two_pen_plt() -> bytes:
    def ring(cx, cy, r, n=180):
        t = np.linspace(0, 2 * np.pi, n + 1)
        pts = [(round(cx + r * np.cos(a), 2), round(cy + r * np.sin(a), 2)) for a in t]
        return (f"PU{pts[0][0]},{pts[0][1]};PD" + ",".join(f"{x},{y}" for x, y in pts[1:])
                + ";PU;")
    # pen 2 first in the file; a square on pen 1 between two circles
    return ("IN;SP2;" + ring(1000, 1000, 400) + "SP1;PU200,200;PD1800,200,1800,1800,200,1800,"
            "200,200;PU;" + ring(2600, 1000, 300) + "SP2;" + ring(2600, 2400, 200)
            + "SP0;").encode()


@pytest.fixture
def files(tmp_path):
    plt = tmp_path / "two.plt"
    plt.write_bytes(two_pen_plt())
    pens = tmp_path / "pens.toml"
    pens.write_text(PENS)
    return tmp_path, plt, pens


def test_two_pen_export_replays_exactly(files):
    tmp, plt, pens = files
    r = run_cli("process", str(plt), "-o", str(tmp / "j.json"), "--pens", str(pens),
                "--lmc", str(tmp / "j.lmc"), "--lmc-text", str(tmp / "j.txt"))
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)
    job = load_job(tmp / "j.json")
    assert sorted({s.pen for s in job.strokes}) == [1, 2]
    assert [la["pen"] for la in job.layers] == [1, 2]
    assert [row["passes"] for row in summary["layers"]] == [2, 1]
    data = (tmp / "j.lmc").read_bytes()
    dec = decode(data)
    assert dec.ended  # exactly one end-of-list, the last record
    assert data[-12:] == END_OF_LIST.to_bytes(2, "little") + bytes(10)
    want = expected_strokes(job)
    # pen 1's strokes twice (its passes), then pen 2's, each exactly
    n1 = sum(1 for s in job.strokes if s.pen == 1)
    n2 = sum(1 for s in job.strokes if s.pen == 2)
    assert len(dec.strokes) == len(want) == 2 * n1 + n2
    bpm = 65536 / 110.0
    words = {1: (int(400 * bpm / 1000), round(30 * 40.95), round(20000 / 25)),
             2: (int(150 * bpm / 1000), round(85 * 40.95), round(20000 / 80))}
    for (layer, m), got in zip(want, dec.strokes, strict=True):
        np.testing.assert_array_equal(got.marks, m)
        s = got.settings
        assert (s["mark_speed"], s["mark_current"], s["q_switch_period"]) == words[layer.pen]
        assert s["jump_speed"] == int(3000 * bpm / 1000)
        assert got.marks.min() >= 0 and got.marks.max() <= 65535
    pens_seen = [la.pen for la, _ in want]
    assert pens_seen == [1] * (2 * n1) + [2] * n2
    text = (tmp / "j.txt").read_text().splitlines()
    assert len(text) == len(data) // 12 and text[-1].endswith("listEndOfList")
    # the time per layer: pen 1 marks twice at 400 mm/s, pen 2 once at 150 mm/s
    t = {row["pen"]: row["estimated_time_s"] for row in summary["layers"]}
    assert summary["stats"]["estimated_time_s"] == pytest.approx(t[1] + t[2])


@pytest.mark.parametrize("text, reason", [
    ("[pen.1]\nmark_speed_mm_s = -100\n", "mark_speed_mm_s must be > 0"),
    ("[pen.2]\npower_percent = 101\n", "power_percent must be >= 0 and <= 100"),
    ("[pen.1\n", "not valid TOML"),
    ("[pen.1]\nspeed = 3\n", "unknown key"),
])
def test_bad_pen_table_one_line_nothing_written(files, text, reason):
    tmp, plt, pens = files
    pens.write_text(text)
    outs = [tmp / "j.json", tmp / "j.lmc", tmp / "f.lmc"]
    r = run_cli("process", str(plt), "-o", str(outs[0]), "--pens", str(pens),
                "--lmc", str(outs[1]), "--frame-lmc", str(outs[2]))
    assert r.returncode == 2
    assert r.stderr.startswith(f"error: {pens}: ") and reason in r.stderr
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    assert not any(p.exists() for p in outs)


def test_frame_and_orientation_files(files):
    tmp, plt, pens = files
    r = run_cli("process", str(plt), "-o", str(tmp / "j.json"), "--frame-lmc",
                str(tmp / "f.lmc"), "--frame-loops", "5", "--frame-shape", "hull",
                "--lmc", str(tmp / "j.lmc"), "--flip-y")
    assert r.returncode == 0, r.stderr
    job = load_job(tmp / "j.json")
    dec = decode((tmp / "j.lmc").read_bytes())
    first = next(s for s in job.strokes if s.pen == 1).marks[0]  # layers in pen order
    assert dec.strokes[0].marks[0].tolist() == [int(first[0]), 65535 - int(first[1])]
    rec = np.frombuffer((tmp / "f.lmc").read_bytes(), dtype="<u2").reshape(-1, 6)
    assert not (rec[:, 0] == 0x8005).any()  # light only


def test_field_correction_applied_once(files):
    tmp, plt, pens = files
    grid = tmp / "g.toml"
    grid.write_text("span_mm = 80\ndx_mm = [[0.2, 0, -0.2], [0.1, 0, -0.1], [0.2, 0, -0.2]]\n"
                    "dy_mm = [[0.2, 0.1, 0.2], [0, 0, 0], [-0.2, -0.1, -0.2]]\n")
    r = run_cli("process", str(plt), "-o", str(tmp / "j.json"), "--field-correction-3x3",
                str(grid))
    assert r.returncode == 0, r.stderr
    job = load_job(tmp / "j.json")
    assert job.field_correction["applied"] is True
    r2 = run_cli("send", str(tmp / "j.json"), "--dry-run", "--field-correction-3x3",
                 str(grid))
    assert r2.returncode == 2 and "already field-corrected" in r2.stderr
    assert r2.stderr.count("\n") == 1


def test_send_dry_run(files):
    pytest.importorskip("galvo")
    tmp, plt, pens = files
    assert run_cli("process", str(plt), "-o", str(tmp / "j.json"), "--pens",
                   str(pens)).returncode == 0
    r = run_cli("send", str(tmp / "j.json"), "--dry-run")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["dry_run"] and out["what"] == "mark"
    assert out["packets"] == -(-out["records"] // 256)  # 256 records per 0xC00 packet
    r = run_cli("send", str(tmp / "j.json"), "--dry-run", "--frame", "--frame-loops", "3")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["loops"] == 3


def test_send_without_board_is_one_line(files, monkeypatch, capsys):
    galvo = pytest.importorskip("galvo")
    from galvo_core import cli

    tmp, plt, pens = files
    assert run_cli("process", str(plt), "-o", str(tmp / "j.json")).returncode == 0

    def refuse(self):  # what galvoplotter raises after its retries
        raise ConnectionRefusedError("Could not connect to the LMC controller.")

    from galvo_core import cli_lmc

    monkeypatch.setattr(galvo.GalvoController, "connect_if_needed", refuse)
    monkeypatch.setattr(cli_lmc, "_board_present", lambda: None)  # seen, then refuses
    assert cli.main(["send", str(tmp / "j.json")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: no BJJCZ (LMC) board") and err.count("\n") == 1
    assert "Could not connect" in err
    # no board on the bus at all (as on this machine): the same one line, at once
    monkeypatch.setattr(cli_lmc, "_board_present", lambda: "no device")
    assert cli.main(["send", str(tmp / "j.json")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: no BJJCZ (LMC) board") and "(no device)" in err
