"""LMC (BJJCZ) list export: golden tests against galvoplotter's own encoder, and the
independent decoder's replay of exported jobs."""

from __future__ import annotations

import numpy as np
import pytest
from _lmc_util import make_job, rng_strokes
from hypothesis import given, settings
from hypothesis import strategies as st

from galvo_core.errors import InputError
from galvo_core.job import Job, Stroke
from galvo_core.layers import LayerSettings, PenTable
from galvo_core.lmc import (
    END_OF_LIST,
    JUMP_TO,
    MARK_TO,
    Orientation,
    bits_per_mm,
    decode,
    encode_job,
    expected_strokes,
    to_bytes,
    to_text,
)
from galvo_core.params import LaserParams

galvo = pytest.importorskip("galvo", reason="galvoplotter (the lmc extra) is not installed")


def galvoplotter_records(job: Job, table: PenTable) -> np.ndarray:
    """The same job built with galvoplotter's GalvoController(mock=True): layers by pen
    number, passes repeated, goto() to each stroke's start and mark() through its marks;
    the list packets it sends, padding (end-of-list records) stripped, one end-of-list
    appended."""
    bpm = bits_per_mm(job)
    by_pen: dict[int, list[Stroke]] = {}
    for s in job.strokes:
        by_pen.setdefault(s.pen, []).append(s)
    layers = [table.settings(p) for p in sorted(by_pen)]
    first = layers[0]
    la = first.laser
    c = galvo.GalvoController(
        mock=True, galvos_per_mm=bpm, mark_speed=la.mark_speed_mm_s,
        travel_speed=la.jump_speed_mm_s, power=la.power_percent, frequency=la.frequency_khz,
        pulse_width=first.pulse_width_ns, delay_laser_on=la.laser_on_delay_us,
        delay_laser_off=la.laser_off_delay_us, delay_polygon=la.polygon_delay_us,
        delay_jump_short=la.jump_delay_us, delay_jump_long=la.jump_delay_long_us)
    c.source = table.source
    packets: list[bytes] = []

    def send(data, read=True):  # noqa: ANN001 - galvoplotter's signature
        if len(data) == 0xC00:
            packets.append(bytes(data))
        return (0, 0, 0, 0x20)  # ready, not busy

    c.send = send
    c.marking_configuration()
    for k, layer in enumerate(layers):
        lp = layer.laser
        if k:
            c.delay_polygon = lp.polygon_delay_us  # its set() ignores delay_polygon=
            c.set(mark_speed=lp.mark_speed_mm_s, travel_speed=lp.jump_speed_mm_s,
                  power=lp.power_percent, frequency=lp.frequency_khz,
                  pulse_width=layer.pulse_width_ns, delay_on=lp.laser_on_delay_us,
                  delay_off=lp.laser_off_delay_us)
        for _ in range(layer.passes):
            for s in by_pen[layer.pen]:
                m = s.marks
                c.goto(int(m[0, 0]), int(m[0, 1]), long=lp.jump_delay_long_us,
                       short=lp.jump_delay_us, distance_limit=lp.long_jump_mm * bpm)
                for x, y in m[1:]:
                    c.mark(int(x), int(y))
    c.initial_configuration()
    rec = np.frombuffer(b"".join(packets), dtype="<u2").reshape(-1, 6)
    pad = np.array([END_OF_LIST, 0, 0, 0, 0, 0])
    n = len(rec)
    while n and (rec[n - 1] == pad).all():
        n -= 1
    return np.vstack([rec[:n], pad]).astype(np.uint16)


def two_pen_table(source: str = "fiber") -> PenTable:
    base = LayerSettings(0, LaserParams(mark_speed_mm_s=500, jump_speed_mm_s=3000,
                                        power_percent=40, frequency_khz=30,
                                        laser_on_delay_us=110, laser_off_delay_us=120,
                                        polygon_delay_us=50, jump_delay_us=20,
                                        jump_delay_long_us=300, long_jump_mm=5))
    p1 = base.replace(pen=1, passes=2, power_percent=35.5)
    p2 = base.replace(pen=2, mark_speed_mm_s=250, power_percent=80, frequency_khz=60,
                      laser_on_delay_us=90, polygon_delay_us=75)
    return PenTable(base, (p1, p2), source)


@pytest.mark.parametrize("source", ["fiber", "co2"])
def test_golden_two_pens_passes_matches_galvoplotter(source):
    table = two_pen_table(source)
    job = make_job(rng_strokes(1, 30, (2, 1)))  # pens interleaved in job order
    ours = encode_job(job, table)
    theirs = galvoplotter_records(job, table)
    assert len(ours) > 0xC00 // 12  # more than one of galvoplotter's packets
    assert ours.shape == theirs.shape
    bad = np.flatnonzero((ours != theirs).any(axis=1))
    assert not len(bad), f"record {bad[0]}: ours {ours[bad[0]]} galvoplotter {theirs[bad[0]]}"


def test_golden_field_size_pulse_width_and_one_pen():
    """A 70 mm field (its own bits per mm), a MOPA pulse width, default delays."""
    base = LayerSettings(0, LaserParams(mark_speed_mm_s=1234.5, jump_speed_mm_s=4000,
                                        power_percent=12.3, frequency_khz=45.7),
                         pulse_width_ns=200)
    table = PenTable(base, (), "fiber")
    job = make_job(rng_strokes(7, 12, (3,)), size_mm=70.0)
    np.testing.assert_array_equal(encode_job(job, table), galvoplotter_records(job, table))


def test_golden_jump_delays_short_long_and_none_repeated_marks():
    """Jumps on both sides of long_jump_mm, a short delay of 0 (no delay word: the drivers
    write none), marks repeated inside strokes (dropped, as galvoplotter's mark() does)."""
    rng = np.random.default_rng(11)
    strokes = []
    for i in range(60):
        c = rng.integers(20000, 45000, size=2) if i % 3 else rng.integers(2000, 63000, size=2)
        k = int(rng.integers(2, 12))
        m = c + np.cumsum(rng.integers(-300, 300, size=(k, 2)), axis=0)
        m = np.repeat(m, rng.integers(1, 3, size=k), axis=0)  # repeated marks
        strokes.append((1 + i % 2, [tuple(int(v) for v in p) for p in m]))
    las = LaserParams(jump_delay_us=0, jump_delay_long_us=250, long_jump_mm=15)
    table = PenTable(LayerSettings(0, las), (LayerSettings(2, las.__class__(
        **{**las.as_dict(), "jump_delay_us": 40.0, "long_jump_mm": 8.0})),))
    job = make_job(strokes)
    ours = encode_job(job, table)
    np.testing.assert_array_equal(ours, galvoplotter_records(job, table))
    kinds = ours[ours[:, 0] == 0x800D][:, 1].tolist()
    assert 250 in kinds and 40 in kinds


def test_units_of_the_words():
    table = two_pen_table()
    job = make_job(rng_strokes(3, 4, (1, 2)), size_mm=110.0)
    dec = decode(to_bytes(encode_job(job, table)))
    bpm = 65536 / 110.0
    s1 = dec.strokes[0].settings
    assert s1["mark_speed"] == int(500 * bpm / 1000) == 297
    assert s1["jump_speed"] == int(3000 * bpm / 1000)
    assert s1["mark_current"] == round(35.5 * 4095 / 100)
    assert s1["q_switch_period"] == round(20000 / 30)
    assert s1["laser_on_delay"] == (110, 0)
    last = dec.strokes[-1].settings
    assert last["mark_speed"] == int(250 * bpm / 1000)
    assert last["mark_current"] == round(80 * 4095 / 100)
    assert last["q_switch_period"] == round(20000 / 60)
    assert last["polygon_delay"] == (75, 0)


def test_decoder_replays_every_stroke_of_every_pass_in_layer_order():
    table = two_pen_table()
    job = make_job(rng_strokes(5, 9, (2, 1, 1)))
    dec = decode(to_bytes(encode_job(job, table)))
    assert dec.ended
    want = expected_strokes(job, table)
    # pen 1 (2 passes of its 6 strokes) then pen 2 (3 strokes)
    assert [la.pen for la, _ in want] == [1] * 12 + [2] * 3
    assert len(dec.strokes) == len(want)
    for (layer, m), got in zip(want, dec.strokes, strict=True):
        np.testing.assert_array_equal(got.marks, m)
        assert got.settings["mark_current"] == round(layer.laser.power_percent * 40.95)


def test_closed_stroke_passes_keep_their_jumps():
    """A closed stroke marked twice: the second pass starts where the first ended; the list
    still jumps (length 0) so each pass is its own laser-on run (galvoplotter's goto() would
    skip that jump and merge the passes)."""
    sq = [(100, 100), (900, 100), (900, 900), (100, 900), (100, 100)]
    table = PenTable(LayerSettings(0), (LayerSettings(1, passes=3),))
    rec = encode_job(make_job([(1, sq)]), table)
    jumps = rec[rec[:, 0] == JUMP_TO]
    assert len(jumps) == 3 and list(jumps[1, 1:5]) == [100, 100, 0, 0]
    assert (rec[:, 0] == MARK_TO).sum() == 12
    assert len(decode(to_bytes(rec)).strokes) == 3


def test_disabled_layer_and_dots():
    table = PenTable(LayerSettings(0), (LayerSettings(2, enabled=False),))
    job = make_job([(1, [(10, 10), (20, 20)]), (2, [(50, 50), (60, 60)]), (1, [(5, 5)])])
    dec = decode(to_bytes(encode_job(job, table)))
    assert [len(s.marks) for s in dec.strokes] == [2, 1]
    assert dec.strokes[1].dots == 1


def test_orientation_and_field_refusal():
    job = make_job([(1, [(0, 10), (65535, 20)])])
    rec = encode_job(job, orientation=Orientation(swap_xy=True, flip_x=True))
    marks = rec[(rec[:, 0] == JUMP_TO) | (rec[:, 0] == MARK_TO)][:, 1:3]
    # swap: (10, 0), (20, 65535); then flip x: 65535 - x
    assert marks.tolist() == [[65525, 0], [65515, 65535]]
    # e.g. pushed out by a field correction: refused, naming the stroke and the mark
    out = make_job([(1, [(5, 5), (6, 6)]), (1, [(0, 0), (-3, 5)])])
    with pytest.raises(InputError, match=r"strokes\[1\] mark 1 \(-3, 5\)"):
        encode_job(out)
    with pytest.raises(InputError, match="controller takes at most 65536"):
        encode_job(make_job([(1, [(0, 0)])], bits=1 << 17))


def test_text_dump_one_line_per_record():
    rec = encode_job(make_job([(1, [(10, 10), (20, 20)])]))
    lines = to_text(rec).splitlines()
    assert len(lines) == len(rec)
    assert lines[-1] == "8002:0000:0000:0000:0000:0000 listEndOfList"
    assert any(ln.startswith("8005:0014:0014:0000:000e:0000 listMarkTo") for ln in lines)


def test_write_lmc_and_bad_layers_named(tmp_path):
    from galvo_core.job import load_job, write_job
    from galvo_core.layers import apply_pens
    from galvo_core.lmc import job_pen_table, write_lmc

    job = apply_pens(make_job([(1, [(10, 10), (20, 20)])]), two_pen_table())
    n = write_lmc(job, str(tmp_path / "a.lmc"))
    assert (tmp_path / "a.lmc").stat().st_size == 12 * n
    write_lmc(job, str(tmp_path / "a.txt"), text=True)
    assert len((tmp_path / "a.txt").read_text().splitlines()) == n
    write_job(job, tmp_path / "j.json")
    doc = (tmp_path / "j.json").read_text().replace('"power_percent":35.5', '"power_percent":-3')
    (tmp_path / "j.json").write_text(doc)
    with pytest.raises(InputError, match=r"j\.json: layers\[0\]: power_percent must be"):
        job_pen_table(load_job(tmp_path / "j.json"), name=str(tmp_path / "j.json"))


coord = st.integers(0, 65535)
stroke_st = st.tuples(st.integers(0, 4), st.lists(st.tuples(coord, coord), min_size=1,
                                                  max_size=8))


@settings(max_examples=60, deadline=None)
@given(st.lists(stroke_st, min_size=1, max_size=12), st.integers(1, 3), st.booleans(),
       st.booleans(), st.booleans(), st.sampled_from(["fiber", "co2"]))
def test_any_job_replays_exactly(strokes, passes, swap, fx, disable, source):
    """Whatever the strokes (dots, repeats, strokes starting where the last ended), pens,
    passes, orientation and source: the decoder finds exactly the expected strokes with
    their pen's words, and one end-of-list at the end."""
    table = PenTable(LayerSettings(0), (
        LayerSettings(1, LaserParams(mark_speed_mm_s=123, power_percent=11), passes=passes),
        LayerSettings(3, LaserParams(mark_speed_mm_s=456, power_percent=77),
                      enabled=not disable)), source)
    job = make_job(strokes)
    o = Orientation(swap_xy=swap, flip_x=fx)
    dec = decode(to_bytes(encode_job(job, table, o)))
    want = expected_strokes(job, table, o)
    assert dec.ended and len(dec.strokes) == len(want)
    bpm = bits_per_mm(job)
    for (layer, m), got in zip(want, dec.strokes, strict=True):
        if len(m) > 1 and (m[1:] != m[0]).any():
            np.testing.assert_array_equal(got.marks, m)
        else:
            assert got.dots == 1 and got.marks.tolist() == [m[0].tolist()]
        assert got.settings["mark_speed"] == int(layer.laser.mark_speed_mm_s * bpm / 1000)
