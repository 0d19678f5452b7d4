"""Focused tests of the HP-GL importer, one instruction (or one wrapper) at a time.

Expected values come from the HP-GL / HP-GL/2 reference (chord rule, scaling, tick
lengths, PE encoding) and are computed here independently of the importer's helpers.
"""

from __future__ import annotations

import gzip
import math
import random

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from galvo_core.errors import InputError
from galvo_core.hpgl import read_bytes, read_file
from galvo_core.hpgl.pe import decode_pe, encode_number


def read(src: str | bytes):
    data = src.encode("latin-1") if isinstance(src, str) else src
    return read_bytes(data, "unit.plt")


def pts(d, k: int = 0) -> np.ndarray:
    return np.asarray(d.paths[k].points)


def messages(d) -> list[str]:
    return [w.message for w in d.warnings]


def assert_no_position_warnings(d) -> None:
    """Only whole-file notes (line 0), nothing pointing at a place in the file."""
    assert [w for w in d.warnings if w.line != 0] == []


# ---------------------------------------------------------------------------- PE
def pe_pair(x: int, y: int, *, seven: bool = False) -> bytes:
    return encode_number(x, seven=seven) + encode_number(y, seven=seven)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(-(2**30), 2**30), min_size=2, max_size=40).filter(
    lambda v: len(v) % 2 == 0), st.booleans())
def test_pe_encode_decode_round_trip(values: list[int], seven: bool) -> None:
    body = (b"7" if seven else b"") + b"".join(encode_number(v, seven=seven) for v in values)
    res = decode_pe(body + b";", 0)
    got = [c for it in res.items for c in (it.x, it.y)]
    assert got == [float(v) for v in values]
    assert res.end == len(body) + 1
    assert res.problems == []


def test_pe_digits_are_in_their_ranges() -> None:
    for v in (0, 1, -1, 31, 32, -4096, 10**6):
        eight = encode_number(v)
        assert all(63 <= b <= 126 for b in eight[:-1]) and 191 <= eight[-1] <= 254
        seven = encode_number(v, seven=True)
        assert all(63 <= b <= 94 for b in seven[:-1]) and 95 <= seven[-1] <= 126


def test_pe_relative_moves_with_pen_up_and_absolute_flags() -> None:
    data = (b"IN;PE<=" + pe_pair(1000, 2000) + pe_pair(100, 0) + pe_pair(0, 50)
            + b"<" + pe_pair(500, 0) + pe_pair(-10, -10) + b";")
    d = read(data)
    assert len(d.paths) == 2
    np.testing.assert_array_equal(pts(d, 0), [[1000, 2000], [1100, 2000], [1100, 2050]])
    np.testing.assert_array_equal(pts(d, 1), [[1600, 2050], [1590, 2040]])


def test_pe_ending_with_a_pen_up_move_draws_nothing_there() -> None:
    d = read(b"IN;PE<=" + pe_pair(0, 0) + pe_pair(10, 0) + b"<" + pe_pair(50, 50) + b";"
             + b"PE<" + pe_pair(5, 5) + b";")
    assert len(d.paths) == 1
    np.testing.assert_array_equal(pts(d), [[0, 0], [10, 0]])


def test_pe_out_of_range_number_is_clamped() -> None:
    d = read(b"IN;PE<=" + pe_pair(0, 0) + encode_number(10**30) + encode_number(0) + b";")
    assert np.isfinite(pts(d)).all() and pts(d)[-1, 0] == 1e15
    assert any("out of range" in m for m in messages(d))


def test_pe_seven_bit_mode() -> None:
    data = b"IN;PE7<=" + pe_pair(-300, 40, seven=True) + pe_pair(25, -5, seven=True) + b";"
    d = read(data)
    np.testing.assert_array_equal(pts(d), [[-300, 40], [-275, 35]])


def test_pe_fractional_bits() -> None:
    # '>' 2: coordinates carry two binary fraction digits (units of 1/4)
    data = b"IN;PE>" + encode_number(2) + b"<=" + pe_pair(401, 802) + pe_pair(2, -6) + b";"
    d = read(data)
    np.testing.assert_allclose(pts(d), [[100.25, 200.5], [100.75, 199.0]])


def test_pe_pen_select() -> None:
    data = b"IN;PE:" + encode_number(3) + b"<=" + pe_pair(0, 0) + pe_pair(10, 10) + b";"
    d = read(data)
    assert d.paths[0].pen == 3


def test_pe_in_user_units() -> None:
    data = b"IN;IP0,0,1000,1000;SC0,10,0,10;PE<=" + pe_pair(1, 1) + pe_pair(2, 0) + b";"
    d = read(data)
    np.testing.assert_allclose(pts(d), [[100, 100], [300, 100]])


def test_unterminated_pe_followed_by_commands() -> None:
    # AutoCAD: the PE run is not ';'-terminated; 'PUSP0;' follows directly (upper-case
    # letters are PE continuation digits, so a strict reader would swallow them)
    data = (b"IN;SP1;PE<=" + pe_pair(10, 10) + pe_pair(5, 5) + pe_pair(0, 7)
            + b"PUSP0;PA0,0;PD0,100;")
    d = read(data)
    assert len(d.paths) == 2
    np.testing.assert_array_equal(pts(d, 0), [[10, 10], [15, 15], [15, 22]])
    assert d.paths[0].pen == 1
    np.testing.assert_array_equal(pts(d, 1), [[0, 0], [0, 100]])
    assert d.paths[1].pen == 0
    assert d.commands["PU"] == 1 and d.commands["SP"] == 2
    assert_no_position_warnings(d)


def test_pe_half_pair_is_reported() -> None:
    d = read(b"IN;PE<=" + pe_pair(0, 0) + pe_pair(5, 5) + encode_number(9) + b";")
    np.testing.assert_array_equal(pts(d), [[0, 0], [5, 5]])
    assert any("half a coordinate pair" in m for m in messages(d))


# ---------------------------------------------------------------------------- arcs
@pytest.mark.parametrize("angle", [None, 30.0, 7.0, 45.0, 0.5, 0.1])
def test_circle_chord_count_and_closed(angle: float | None) -> None:
    arg = "" if angle is None else f",{angle:g}"
    d = read(f"IN;PA500,300;CI100{arg};")
    p = pts(d)
    eff = 5.0 if angle is None else max(angle, 0.5)  # chord angle clamped to [0.5, 180]
    assert len(p) == math.ceil(360.0 / eff) + 1
    assert d.paths[0].closed
    np.testing.assert_array_equal(p[0], p[-1])
    np.testing.assert_allclose(np.hypot(p[:, 0] - 500, p[:, 1] - 300), 100.0, atol=1e-9)
    np.testing.assert_allclose(p[0], [600, 300], atol=1e-9)  # starts at 0 degrees


def test_circle_negative_radius_starts_at_180() -> None:
    p = pts(read("IN;PA0,0;CI-100;"))
    np.testing.assert_allclose(p[0], [-100, 0], atol=1e-9)


def test_circle_does_not_move_the_pen() -> None:
    d = read("IN;PA500,300;CI100;PD600,300;")
    np.testing.assert_array_equal(pts(d, 1), [[500, 300], [600, 300]])


def test_aa_negative_sweep() -> None:
    d = read("IN;PA100,0;PD;AA0,0,-90,30;")
    p = pts(d)
    ang = np.radians([0, -30, -60, -90])
    np.testing.assert_allclose(p, np.column_stack((100 * np.cos(ang), 100 * np.sin(ang))),
                               atol=1e-9)


def test_ar_is_relative_to_the_current_point() -> None:
    a = pts(read("IN;PA300,200;PD;AA200,200,-135,15;"))
    b = pts(read("IN;PA300,200;PD;AR-100,0,-135,15;"))
    np.testing.assert_allclose(a, b)
    assert len(a) == 135 // 15 + 1


def test_pen_up_arc_moves_only() -> None:
    d = read("IN;PA100,0;AA0,0,90;PD0,200;")
    np.testing.assert_allclose(pts(d), [[0, 100], [0, 200]], atol=1e-9)


def test_ct1_chord_tolerance() -> None:
    d = read("IN;CT1;PA100,0;PD;AA0,0,360,10;")
    p = pts(d)
    chord = math.degrees(2 * math.acos(1 - 10 / 100))
    assert len(p) == math.ceil(360 / chord) + 1
    mids = (p[1:] + p[:-1]) / 2
    assert (100 - np.hypot(mids[:, 0], mids[:, 1])).max() <= 10 + 1e-9
    # CT0 (or CT;) back to chord angles
    assert len(pts(read("IN;CT1;CT;PA100,0;PD;AA0,0,360,10;"))) == 37


def test_at_three_point_arc() -> None:
    d = read("IN;PA0,0;PD;AT100,100,200,0;")
    p = pts(d)
    np.testing.assert_allclose(p[0], [0, 0])
    np.testing.assert_allclose(p[-1], [200, 0])
    np.testing.assert_allclose(np.hypot(p[:, 0] - 100, p[:, 1]), 100, atol=1e-9)
    assert np.min(np.hypot(p[:, 0] - 100, p[:, 1] - 100)) < 1e-6  # through the middle point
    assert len(p) == 180 // 5 + 1


def test_rt_relative_three_point_arc_and_collinear_points() -> None:
    a = pts(read("IN;PA0,0;PD;AT100,100,200,0;"))
    b = pts(read("IN;PA0,0;PD;RT100,100,200,0;"))
    np.testing.assert_allclose(a, b)
    # collinear: a straight line through the points
    np.testing.assert_allclose(pts(read("IN;PA0,0;PD;AT50,0,100,0;")), [[0, 0], [50, 0],
                                                                        [100, 0]])


# ---------------------------------------------------------------------------- figures
@pytest.mark.parametrize("cmd", ["EA110,70", "RA110,70", "ER100,50", "RR100,50"])
def test_rectangles_are_closed_rings(cmd: str) -> None:
    d = read(f"IN;PA10,20;{cmd};PD10,0;")
    np.testing.assert_array_equal(pts(d, 0), [[10, 20], [110, 20], [110, 70], [10, 70],
                                              [10, 20]])
    assert d.paths[0].closed
    # the pen stays where it was
    np.testing.assert_array_equal(pts(d, 1), [[10, 20], [10, 0]])


def test_wedge_is_centre_arc_centre() -> None:
    p = pts(read("IN;PA1000,1000;EW500,0,90;"))
    np.testing.assert_array_equal(p[0], [1000, 1000])
    np.testing.assert_array_equal(p[-1], [1000, 1000])
    np.testing.assert_allclose(p[1], [1500, 1000])
    np.testing.assert_allclose(p[-2], [1000, 1500], atol=1e-9)
    assert len(p) == 90 // 5 + 1 + 2


def test_full_wedge_is_a_circle_without_duplicate_end() -> None:
    d = read("IN;PA0,0;WG100,0,360;")
    p = pts(d)
    assert d.paths[0].closed and len(p) == 73
    assert not np.array_equal(p[-2], p[-1])


# ---------------------------------------------------------------------------- scaling
def test_sc_type0_anisotropic() -> None:
    d = read("IN;IP0,0,1000,500;SC0,10,0,10;PA10,10;PD;PA0,0;")
    np.testing.assert_allclose(pts(d), [[1000, 500], [0, 0]])


def test_sc_type1_isotropic_centred_by_default() -> None:
    d = read("IN;IP0,0,1000,500;SC0,10,0,10,1;PA0,0;PD10,10;")
    np.testing.assert_allclose(pts(d), [[250, 0], [750, 500]])
    d = read("IN;IP0,0,1000,500;SC0,10,0,10,1,0,0;PA0,0;PD10,10;")
    np.testing.assert_allclose(pts(d), [[0, 0], [500, 500]])
    d = read("IN;IP0,0,1000,500;SC0,10,0,10,1,100,100;PA0,0;PD10,10;")
    np.testing.assert_allclose(pts(d), [[500, 0], [1000, 500]])


def test_sc_type2_point_factor() -> None:
    d = read("IN;IP100,200,5000,5000;SC0,2,0,3,2;PA0,0;PD10,10;")
    np.testing.assert_allclose(pts(d), [[100, 200], [120, 230]])


def test_sc_default_p1_p2_and_sc_off() -> None:
    d = read("IN;SC0,100,0,100;PA0,0;PD100,100;SC;PA0,0;")
    np.testing.assert_allclose(pts(d), [[250, 596], [10250, 7796], [0, 0]])


def test_ip_with_two_numbers_keeps_the_size() -> None:
    d = read("IN;IP0,0,100,100;IP500,500;SC0,1,0,1;PA0,0;PD1,1;")
    np.testing.assert_allclose(pts(d), [[500, 500], [600, 600]])


def test_ir_percentages_of_the_page() -> None:
    d = read("IN;PS1000,2000;IR10,20,60,70;SC0,100,0,100;PA0,0;PD100,100;")
    np.testing.assert_allclose(pts(d), [[100, 400], [600, 1400]])


def test_ir_with_p1_only_moves_p2_along() -> None:
    d = read("IN;PS1000,2000;IP0,0,100,100;IR50,50;SC0,1,0,1;PA0,0;PD1,1;")
    np.testing.assert_allclose(pts(d), [[500, 1000], [600, 1100]])


@pytest.mark.parametrize(("angle", "expected"), [
    (0, [[0, 0], [100, 0], [100, 50]]),
    (90, [[0, 0], [0, 100], [-50, 100]]),
    (180, [[0, 0], [-100, 0], [-100, -50]]),
    (270, [[0, 0], [0, -100], [50, -100]]),
])
def test_ro_rotates_about_the_plotter_origin(angle: int, expected: list) -> None:
    d = read(f"IN;RO{angle};PA0,0;PD100,0,100,50;")
    p = pts(d)
    np.testing.assert_array_equal(p, expected)
    assert not np.signbit(p[p == 0]).any()  # no -0.0


# ---------------------------------------------------------------------------- polygons
def test_polygon_mode_emits_each_ring_once() -> None:
    d = read("IN;PA0,0;PM0;PD100,0,100,100,0,100;PM1;PU20,20;PD80,20,80,80,20,80;PM2;"
             "FP;EP;SP2;EP;")
    assert len(d.paths) == 2
    np.testing.assert_array_equal(pts(d, 0), [[0, 0], [100, 0], [100, 100], [0, 100],
                                              [0, 0]])
    np.testing.assert_array_equal(pts(d, 1), [[20, 20], [80, 20], [80, 80], [20, 80],
                                              [20, 20]])
    assert all(p.closed and p.pen == 1 for p in d.paths)


def test_polygon_without_edge_or_fill_is_not_drawn() -> None:
    d = read("IN;PA0,0;PM0;PD100,0,100,100;PM2;PU;")
    assert d.paths == ()
    assert any("never edged or filled" in m for m in messages(d))


def test_polygon_mode_with_circle_inside() -> None:
    d = read("IN;PA500,500;PM0;CI100;PM2;EP;")
    assert len(d.paths) == 1 and d.paths[0].closed and len(pts(d)) == 73


# ---------------------------------------------------------------------------- Béziers
def _bezier(ctrl: np.ndarray, t: np.ndarray) -> np.ndarray:
    t = t[:, None]
    return ((1 - t) ** 3 * ctrl[0] + 3 * (1 - t) ** 2 * t * ctrl[1]
            + 3 * (1 - t) * t**2 * ctrl[2] + t**3 * ctrl[3])


def _dist_to_polyline(q: np.ndarray, poly: np.ndarray) -> np.ndarray:
    a, b = poly[:-1], poly[1:]
    ab = b - a
    t = np.clip(((q[:, None, :] - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300),
                0, 1)
    proj = a + t[..., None] * ab
    return np.hypot(*(q[:, None, :] - proj).transpose(2, 0, 1)).min(axis=1)


def test_bz_flattened_within_tolerance() -> None:
    d = read("IN;PA0,0;PD;BZ0,1000,1000,1000,1000,0,1000,-500,2000,-500,2000,0;")
    p = pts(d)
    c1 = np.array([[0, 0], [0, 1000], [1000, 1000], [1000, 0]], float)
    c2 = np.array([[1000, 0], [1000, -500], [2000, -500], [2000, 0]], float)
    t = np.linspace(0, 1, 2001)
    true = np.vstack((_bezier(c1, t), _bezier(c2, t)))
    assert _dist_to_polyline(true, p).max() <= 0.1 + 1e-9
    np.testing.assert_allclose(p[0], [0, 0])
    np.testing.assert_allclose(p[-1], [2000, 0])
    assert np.min(np.hypot(*(p - [1000, 0]).T)) < 1e-9  # through the joint


def test_br_relative_equals_bz() -> None:
    a = pts(read("IN;PA100,100;PD;BZ100,300,300,300,300,100;"))
    b = pts(read("IN;PA100,100;PD;BR0,200,200,200,200,0;"))
    np.testing.assert_allclose(a, b)


# ---------------------------------------------------------------------------- ticks
def test_xt_yt_ticks_default_and_tl() -> None:
    # default P1/P2 (250,596)-(10250,7796): 0.5 % of 7200 = 36 (XT), of 10000 = 50 (YT)
    d = read("IN;PA1000,1000;XT;YT;TL2,3;XT;TL1;YT;")
    np.testing.assert_allclose(pts(d, 0), [[1000, 964], [1000, 1036]])
    np.testing.assert_allclose(pts(d, 1), [[950, 1000], [1050, 1000]])
    np.testing.assert_allclose(pts(d, 2), [[1000, 1000 - 216], [1000, 1000 + 144]])
    np.testing.assert_allclose(pts(d, 3), [[1000, 1000], [1100, 1000]])


# ---------------------------------------------------------------------------- text
def test_label_with_custom_terminator_hides_its_text() -> None:
    d = read("IN;DT#;PA0,0;LBPD99,99 ETX\x03 inside#PD10,10;")
    # the text is not read as commands; the label moves the pen over its 18 printable
    # characters (default cell 1.5 x 0.187 cm), and PD draws from there
    np.testing.assert_allclose(pts(d), [[18 * 112.2, 0], [10, 10]])
    assert d.commands["LB"] == 1


def test_label_with_dt_mode_and_reset() -> None:
    d = read("IN;DT*,1;LBabc*DT;LBdef\x03PA0,0;PD5,5;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [5, 5]])
    assert d.commands["LB"] == 2
    assert_no_position_warnings(d)


def test_label_keeps_control_bytes_in_its_text() -> None:
    d = read(b"IN;DT!;LB\x00\x01\x0e\x0f\r\nPD9,9;!PA0,0;PD5,5;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [5, 5]])


def test_unterminated_label_ends_at_the_line_end() -> None:
    d = read("IN;LBno terminator PD50,50\nPA0,0;PD5,5;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [5, 5]])
    w = [w for w in d.warnings if "label without" in w.message]
    assert w and (w[0].line, w[0].col) == (1, 4)


def test_comments_quoted_and_unquoted() -> None:
    for src in ('IN;CO"PD100,100; more";PA0,0;PD5,5;', "IN;CO PD100,100;PA0,0;PD5,5;",
                "IN;CO this is a note\nPA0,0;PD5,5;"):
        d = read(src)
        np.testing.assert_array_equal(pts(d), [[0, 0], [5, 5]])


def test_symbol_mode_character_is_not_a_command() -> None:
    d = read("IN;SMY;PA0,0;PD;PA10,10;SM;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [10, 10]])
    assert_no_position_warnings(d)
    assert any("symbol mode" in m for m in messages(d))


# ---------------------------------------------------------------------------- wrappers
def test_pcl_wrapped_with_binary_raster_data() -> None:
    binary = b"\x1bPD9\x00;"  # 6 bytes of data that look like commands and escapes
    data = (b"\x1bE\x1b%0BIN;PA0,0;PD100,100;\x1b%0A\x1b*v6W" + binary
            + b"\x1b*p100x100Y\x1b%1BPU;PA0,0;PD0,50;\x1b%0A\x1bE")
    d = read(data)
    assert len(d.paths) == 2
    np.testing.assert_array_equal(pts(d, 0), [[0, 0], [100, 100]])
    np.testing.assert_array_equal(pts(d, 1), [[0, 0], [0, 50]])
    assert_no_position_warnings(d)


def test_pjl_enter_language_hpgl2() -> None:
    data = (b"\x1b%-12345X@PJL JOB\r\n@PJL COMMENT PD1,1\r\n@PJL ENTER LANGUAGE=HPGL2\r\n"
            b"IN;PA0,0;PD10,10;\x1b%-12345X@PJL EOJ\r\n\x1b%-12345X")
    d = read(data)
    assert len(d.paths) == 1
    np.testing.assert_array_equal(pts(d), [[0, 0], [10, 10]])


@pytest.mark.parametrize("prefix", [b"\x1b.(\x1b.I81;;17:\x1b.N;19:",
                                    b".(;.I81;;17:.N;19:",
                                    b"\x1b.(;\x1b.I81;;17:\x1b.N;19:\x1b.@;2:"])
def test_7475a_device_control(prefix: bytes) -> None:
    d = read(prefix + b"IN;SC;PU;SP1;PA100,100;PD;PA200,100;PU;")
    np.testing.assert_array_equal(pts(d), [[100, 100], [200, 100]])
    assert_no_position_warnings(d)


# ---------------------------------------------------------------------------- syntax
def test_separators_signs_and_case() -> None:
    d = read("in;pa0,0;pd10 20-30+40,5,0;Pu;PA 0 , 0 ;PD.5,-.5;")
    np.testing.assert_allclose(pts(d, 0), [[0, 0], [10, 20], [-30, 40], [5, 0]])
    np.testing.assert_allclose(pts(d, 1), [[0, 0], [0.5, -0.5]])


def test_pd_typo_colon_warned_and_bezier_drawn() -> None:
    d = read("IN;\nPA1016,5080;\nPD:\nBZ1016,8128,5588,5080,4572,7112;\n")
    assert len(d.paths) == 1 and len(pts(d)) > 10
    w = [w for w in d.warnings if "unexpected" in w.message]
    assert w and (w[0].line, w[0].col) == (3, 3)


def test_odd_coordinate_count_warned() -> None:
    d = read("IN;PA0,0;PD10,10,20;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [10, 10]])
    assert any("odd number" in m for m in messages(d))


def test_iw_window_clips_and_iw_without_numbers() -> None:
    d = read("IN;IW0,0,100,100;PA-50,50;PD150,50;PU;IW;PA-50,60;PD150,60;")
    np.testing.assert_allclose(pts(d, 0), [[0, 50], [100, 50]])
    np.testing.assert_allclose(pts(d, 1), [[-50, 60], [150, 60]])  # no page: no window
    assert any("clipped" in w.message and w.line == 1 for w in d.warnings)
    # after PS, IW; is the page
    d = read("PS1000,1000;IW;PA500,500;PD2000,500;")
    np.testing.assert_allclose(pts(d), [[500, 500], [1000, 500]])


def test_file_level_warnings_have_no_position() -> None:
    d = read("IN;LBtext\x03PA0,0;PD5,5;LT2;PD6,6;PG;PD7,7;PG;")
    notes = [w for w in d.warnings if w.line == 0]
    assert {w.col for w in notes} == {0}
    assert any("label" in w.message for w in notes)
    assert any("line types" in w.message for w in notes)
    assert any("pages" in w.message for w in notes)


# ---------------------------------------------------------------------------- refusals
NOT_HPGL = {
    "empty": b"",
    "whitespace": b" \r\n\t ",
    "nul-only": b"\x00" * 4096,
    "png": b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(40),
    "svg": b'<?xml version="1.0"?>\n<svg xmlns="http://www.w3.org/2000/svg"></svg>',
    "svg-bare": b'<svg width="10" height="10"><path d="M0 0 L 1 1"/></svg>',
    "dxf": b"  0\r\nSECTION\r\n  2\r\nHEADER\r\n  0\r\nENDSEC\r\n  0\r\nEOF\r\n",
    "summa-dmpl": b";:H A EC N U,0,0 D,100,0,100,100 P6 e@\r\n",
    "summa-opos": b"\x1b;@:\r\nSET MARKER_X_DIS=1000\r\nEND\r\n;:H A U,1,1 D,2,2 e@",
    "gzip": gzip.compress(b"IN;PD100,100;" * 50),
    "random-binary": random.Random(7).randbytes(8192),
    "pcl-without-hpgl2": b"\x1bE\x1b&l26A\x1b&l0O\x1b(s0p12h10v0s0b3T Hello world\r\n\x0c\x1bE",
    "pjl-pcl-job": b"\x1b%-12345X@PJL JOB\r\n@PJL ENTER LANGUAGE=PCL\r\n\x1bE\x1b*t300R"
                   b"\x1b*r1A\x1b*b4W\x00\x01PD\x1b*rB\x1bE\x1b%-12345X@PJL EOJ\r\n",
    "text": b"Dear customer,\nplease find attached the drawing.\n" * 20,
}


@pytest.mark.parametrize("kind", sorted(NOT_HPGL))
def test_refusals_name_the_file_and_give_a_reason(kind: str) -> None:
    with pytest.raises(InputError) as ei:
        read_bytes(NOT_HPGL[kind], f"{kind}.plt")
    err = ei.value
    assert err.file == f"{kind}.plt"
    assert str(err).startswith(f"{kind}.plt: ") and len(err.reason) > 8


@pytest.mark.parametrize(("kind", "words"), [("empty", "empty"), ("nul-only", "empty"),
                                             ("png", "PNG"), ("svg", "SVG"), ("dxf", "DXF"),
                                             ("summa-dmpl", "Summa"), ("gzip", "gzip"),
                                             ("pcl-without-hpgl2", "PCL")])
def test_refusal_reasons_say_what_the_file_is(kind: str, words: str) -> None:
    with pytest.raises(InputError, match=words):
        read_bytes(NOT_HPGL[kind], "x.plt")


def test_read_file_errors_name_the_path(tmp_path) -> None:
    f = tmp_path / "drawing.plt"
    f.write_bytes(b"")
    with pytest.raises(InputError) as ei:
        read_file(f)
    assert "drawing.plt" in str(ei.value)
    with pytest.raises(InputError, match="no such file"):
        read_file(tmp_path / "missing.plt")
    with pytest.raises(InputError, match="folder"):
        read_file(tmp_path)


def test_first_move_after_pm1_starts_the_next_subpolygon_with_the_pen_up():
    # hp2xx pm.hp: the pen is down when PM1 comes; the next PD's first point must not be
    # joined to the previous sub-polygon (that spike would be marked by the laser)
    d = read_bytes(b"IN;SP1;PA0,0;PM0;PD100,0,100,100,0,100;PM1;"
                   b"PD20,20,80,20,80,80,20,80,20,20;PM2;EP;", "pm.plt")
    assert len(d.paths) == 2
    inner = d.paths[1].points
    assert inner[0].tolist() == [20.0, 20.0] and inner[-1].tolist() == [20.0, 20.0]
    assert len(inner) == 5 and d.paths[1].closed


def test_drawing_with_pen_zero_is_imported_with_a_warning():
    d = read_bytes(b"IN;SP0;PU0,0;PD100,0;PU;", "pen0.plt")
    assert len(d.paths) == 1 and d.paths[0].pen == 0
    assert any("pen 0" in w.message for w in d.warnings)


def _clip_reference(pts, win):
    """IW clipping written segment by segment (Liang-Barsky, scalar floats): the pieces of
    the polyline inside the window, a piece going on while its segments touch end to start.
    On ties the later parameter wins (numpy's maximum/minimum: the sign of a zero)."""
    xmin, ymin, xmax, ymax = win
    if len(pts) == 1:
        x, y = pts[0]
        return [pts] if xmin <= x <= xmax and ymin <= y <= ymax else []
    out, cur, prev_full_end = [], [], False
    for k in range(len(pts) - 1):
        a, d = pts[k], pts[k + 1] - pts[k]
        t0, t1, vis = np.float64(0.0), np.float64(1.0), True
        for p, q in ((-d[0], a[0] - xmin), (d[0], xmax - a[0]), (-d[1], a[1] - ymin),
                     (d[1], ymax - a[1])):
            if p == 0:
                vis &= not q < 0
            elif p < 0:
                t0 = t0 if t0 > q / p else q / p
            else:
                t1 = t1 if t1 < q / p else q / p
        vis &= t0 <= t1
        if not vis:
            prev_full_end = False
            continue
        s, e = a + t0 * d, a + t1 * d
        if cur and prev_full_end and t0 == 0.0:
            cur.append(e)
        else:
            if cur:
                out.append(np.array(cur))
            cur = [s, e]
        prev_full_end = t1 == 1.0
    if cur:
        out.append(np.array(cur))
    return out


@pytest.mark.parametrize("compiled", [False, True])
def test_iw_clipping_matches_a_segment_by_segment_reference(compiled: bool) -> None:
    """The input window's clipping (numpy, vectorised; compiled, used once numba is
    loaded) cuts polylines exactly as the scalar per-segment rule: same pieces, same
    coordinates to the bit (signed zeros too)."""
    from galvo_core.hpgl.reader import _clip_polyline

    if compiled:
        scan = pytest.importorskip("galvo_core.hpgl.scan")

        def clip(pts, win):  # type: ignore[no-untyped-def]
            if len(pts) == 1:
                return _clip_polyline(pts, win)
            cp, cs, cn = scan.clip_polyline(pts, *win)
            return [cp[cs[k]:cs[k + 1]] for k in range(cn)]
    else:
        clip = _clip_polyline
    rng = np.random.default_rng(7)
    for t in range(3000):
        n = int(rng.integers(1, 10))
        pts = (rng.integers(-5, 6, size=(n, 2)).astype(float) if t % 2
               else rng.uniform(-6, 6, size=(n, 2)))
        if t % 5 == 0:
            pts[rng.random(pts.shape) < 0.3] = -0.0
        win = (-3.0, -2.0, 3.0, 4.0) if t % 3 else (0.0, 0.0, 0.0, 5.0)
        got, want = clip(pts, win), _clip_reference(pts, win)
        assert [g.tobytes() for g in got] == [w.tobytes() for w in want]
        assert [g.shape for g in got] == [w.shape for w in want]
