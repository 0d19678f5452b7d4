"""Pen tables: TOML loading and its refusals, layer order, time per layer."""

from __future__ import annotations

import numpy as np
import pytest

from galvo_core.errors import InputError
from galvo_core.field import FieldMap
from galvo_core.job import Job, Stroke
from galvo_core.layers import LayerSettings, PenTable, apply_pens, load_pen_table
from galvo_core.params import LaserParams
from galvo_core.timing import estimate

GOOD = """
source = "fiber"
[laser]
mark_speed_mm_s = 500
jump_speed_mm_s = 3000
[pen.1]
power_percent = 40
passes = 2
colour = "#ff0000"
[pen.2]
mark_speed_mm_s = 200
power_percent = 80
frequency_khz = 60
enabled = false
pulse_width_ns = 100
"""


def write(tmp_path, text, name="pens.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_load_good_table(tmp_path):
    t = load_pen_table(write(tmp_path, GOOD))
    p1, p2 = t.settings(1), t.settings(2)
    assert (p1.laser.mark_speed_mm_s, p1.laser.power_percent, p1.passes) == (500, 40, 2)
    assert p1.laser.jump_speed_mm_s == 3000  # from the profile
    assert p1.colour == "#ff0000"
    assert (p2.laser.mark_speed_mm_s, p2.laser.frequency_khz, p2.enabled) == (200, 60, False)
    assert p2.pulse_width_ns == 100
    # a pen the table does not list uses the profile
    p7 = t.settings(7)
    assert p7.pen == 7 and p7.laser.mark_speed_mm_s == 500 and p7.passes == 1
    assert [la.pen for la in t.layers([7, 2, 1, 2])] == [1, 2, 7]
    assert hash(t) == hash(load_pen_table(write(tmp_path, GOOD, "b.toml")))


@pytest.mark.parametrize("text, reason", [
    ("[pen.1]\nmark_speed_mm_s = -5\n", r"pen\.1: mark_speed_mm_s must be > 0"),
    ("[pen.2]\npower_percent = 120\n", r"pen\.2: power_percent must be >= 0 and <= 100"),
    ("[pen.1\npower_percent = 1\n", "not valid TOML"),
    ("[pen.1]\npowr_percent = 10\n", r"pen\.1\.powr_percent: unknown key"),
    ("speed = 3\n", "speed: unknown key"),
    ("[pen.1]\npasses = 0\n", r"pen\.1: passes must be an integer in 1\.\.1000"),
    ("[pen.1]\npasses = 1.5\n", r"pen\.1\.passes must be a whole number"),
    ("[pen.x]\npasses = 1\n", r"pen\.x: a pen number"),
    ("[laser]\nfrequency_khz = 0\n", "laser: frequency_khz must be > 0"),
    ("[pen.1]\ncolour = \"red\"\n", "colour must look like"),
    ("source = \"uv\"\n", "source must be one of fiber, co2"),
    ("[pen.1]\nenabled = 1\n", r"pen\.1\.enabled must be true or false"),
])
def test_bad_tables_are_refused_naming_file_and_place(tmp_path, text, reason):
    p = write(tmp_path, text)
    with pytest.raises(InputError, match=reason) as ei:
        load_pen_table(p)
    assert str(ei.value).startswith(f"{p}: ")
    assert "\n" not in str(ei.value)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="cannot be read"):
        load_pen_table(tmp_path / "none.toml")


def job_of(strokes):
    fm = FieldMap(1.0, (0.0, 0.0), 65536, 110.0)
    ss = tuple(Stroke("contour", i, False, np.asarray(m, dtype=np.int64), (), pen)
               for i, (pen, m) in enumerate(strokes))
    return Job("t.plt", "", fm, {}, LaserParams().as_dict(), ss, {"estimated_time_s": 0.0})


SQ = [(1000, 1000), (9000, 1000), (9000, 9000), (1000, 9000), (1000, 1000)]
LINE = [(20000, 20000), (40000, 20000)]


def test_time_per_layer_uses_each_layers_settings_and_passes():
    slow = LaserParams(mark_speed_mm_s=50)
    fast = LaserParams(mark_speed_mm_s=1000)
    t = PenTable(LayerSettings(0), (LayerSettings(1, slow, passes=3), LayerSettings(2, fast)))
    job = apply_pens(job_of([(2, LINE), (1, SQ)]), t)
    rows = job.stats["layers"]
    assert [r["pen"] for r in rows] == [1, 2]
    mpb = 110 / 65536
    one_pass = estimate([np.array(SQ)], slow, mpb)
    # three passes of the square: three times its marking, plus two jumps of length 0
    assert rows[0]["estimated_time_s"] == pytest.approx(
        3 * one_pass["estimated_time_s"] + 2 * (slow.jump_delay_us * 1e-6 + 10e-6))
    # pen 2 after pen 1: the jump into it at pen 2's speed counts in pen 2
    assert rows[1]["estimated_time_s"] > estimate([np.array(LINE)], fast, mpb)[
        "estimated_time_s"]
    assert job.stats["estimated_time_s"] == pytest.approx(sum(r["estimated_time_s"]
                                                              for r in rows))
    assert [la["pen"] for la in job.layers] == [1, 2]
    assert job.layers[0]["mark_speed_mm_s"] == 50 and job.layers[0]["passes"] == 3


def test_disabled_layer_takes_no_time():
    t = PenTable(LayerSettings(0), (LayerSettings(2, enabled=False),))
    on = apply_pens(job_of([(1, SQ), (2, LINE)]), PenTable())
    off = apply_pens(job_of([(1, SQ), (2, LINE)]), t)
    assert off.stats["layers"][1]["estimated_time_s"] == 0.0
    assert off.stats["estimated_time_s"] < on.stats["estimated_time_s"]


def test_job_layers_round_trip(tmp_path):
    from galvo_core.job import load_job, write_job
    from galvo_core.lmc import job_pen_table

    t = load_pen_table(write(tmp_path, GOOD))
    job = apply_pens(job_of([(1, SQ), (2, LINE)]), t)
    write_job(job, tmp_path / "j.json")
    back = load_job(tmp_path / "j.json")
    assert back.layers == job.layers and back.laser_source == "fiber"
    t2 = job_pen_table(back)
    for pen in (1, 2):
        assert t2.settings(pen) == t.settings(pen).replace(colour=t.settings(pen).display_colour)


def test_dump_round_trip(tmp_path):
    from galvo_core.layers import dump_pen_table

    t = load_pen_table(write(tmp_path, GOOD))
    t = t.with_pen(t.settings(5).replace(passes=4, enabled=False, jump_delay_us=12.5))
    p = write(tmp_path, dump_pen_table(t), "dump.toml")
    assert load_pen_table(p) == t
