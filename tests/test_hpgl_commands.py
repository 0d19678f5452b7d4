"""One test per command: those of paper 001's Table 1 ("Main orders in PLT file": PA PR PE
PU PD EA ER RA RR BA BR AA AR CI AT RT EP FP) and the other HP-GL/2 commands the reader
acts on, each asserting what the reference says the command does to the geometry.

References: HP's "PCL 5 Printer Language Technical Reference Manual, Part II" (HP-GL/2
chapters 17-22; "PCL5-II") with the page number printed on the page where it was checked
(17-21 pen status; 20-25 CI; 21-2 the commands that use the polygon buffer; 21-18 EA; 21-34
to 21-37 PM; 21-39 RA); otherwise the chapter and the instruction's own section, which is
where to look ("ch. 20, AA"). Paper 001 names the absolute Bézier ``BA``; the reader takes
it as HP-GL/2's ``BZ``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from galvo_core.hpgl import read_bytes


def read(text: str):
    return read_bytes(text.encode("latin-1"), "cmd.plt")


def pts(d, k: int = 0) -> np.ndarray:
    return d.paths[k].points


# ------------------------------------------------------------------ Table 1: moves
def test_pu_moves_without_drawing_and_lifts_the_pen() -> None:
    """ch. 20, PU: "moves to each point in turn without drawing"; PU without parameters
    "raises the pen without changing the cursor position"."""
    d = read("IN;SP1;PD;PU100,0,100,100;PD200,100;")
    assert len(d.paths) == 2
    np.testing.assert_array_equal(pts(d, 0), [[0, 0]])  # the PD;PU dot
    np.testing.assert_array_equal(pts(d, 1), [[100, 100], [200, 100]])


def test_pd_draws_to_each_point_in_turn() -> None:
    """ch. 20, PD: draws from the current location to each point in turn; PD without
    parameters lowers the pen without moving."""
    d = read("IN;SP1;PU10,10;PD;PD20,10,20,20;")
    np.testing.assert_array_equal(pts(d), [[10, 10], [20, 10], [20, 20]])


def test_pa_sets_absolute_mode_for_later_pu_pd() -> None:
    """ch. 20, PA: establishes absolute plotting; with no argument it only sets the mode."""
    d = read("IN;SP1;PR;PA;PU10,10;PD20,20;")
    np.testing.assert_array_equal(pts(d), [[10, 10], [20, 20]])


def test_pr_moves_by_increments() -> None:
    """ch. 20, PR: each pair is an increment from the current location."""
    d = read("IN;SP1;PU10,10;PD;PR5,0,0,5,-5,0;")
    np.testing.assert_array_equal(pts(d), [[10, 10], [15, 10], [15, 15], [10, 15]])


def test_odd_coordinate_is_ignored() -> None:
    """ch. 20, PU/PD: "If an odd number of coordinates are specified, the final (unpaired)
    coordinate is ignored"."""
    d = read("IN;SP1;PU0,0;PD10,0,10;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [10, 0]])


def test_pe_polyline_encoded_pen_up_flag_and_relative_pairs() -> None:
    """ch. 20, PE: pairs are relative unless flagged '=', '<' makes the next move pen-up;
    base-64 digits, the low bit the sign. ``PE<=??x`` would be (0,0); here: a pen-up move to
    absolute (0,0), then (+10,0) relative."""
    from galvo_core.hpgl.pe import encode_number as enc

    body = b"<=" + enc(0) + enc(0) + enc(10) + enc(0) + b";"
    d = read_bytes(b"IN;SP1;PE" + body, "pe.plt")
    np.testing.assert_array_equal(pts(d), [[0, 0], [10, 0]])


# ------------------------------------------------------------------ Table 1: arcs, circle
def test_aa_arc_counterclockwise_from_the_current_point() -> None:
    """ch. 20, AA: the arc starts at the current location, centre X,Y, positive sweep
    counterclockwise; afterwards the pen is at the arc's end. Default chord angle 5 degrees:
    a 90-degree arc has 18 chords."""
    d = read("IN;SP1;PU100,0;PD;AA0,0,90;")
    p = pts(d)
    assert len(p) == 19
    np.testing.assert_allclose(p[0], [100, 0])
    np.testing.assert_allclose(p[-1], [0, 100], atol=1e-9)
    np.testing.assert_allclose(np.hypot(*p.T), 100.0)
    assert np.all(np.diff(np.arctan2(p[:, 1], p[:, 0])) > 0)  # counterclockwise


def test_aa_with_the_pen_up_only_moves() -> None:
    """ch. 20, AA: with the pen up nothing is drawn but the pen moves to the arc's end."""
    d = read("IN;SP1;PU100,0;AA0,0,90;PD0,200;")
    np.testing.assert_allclose(pts(d), [[0, 100], [0, 200]], atol=1e-9)


def test_ar_centre_is_relative_to_the_current_point() -> None:
    """ch. 20, AR: the centre is an increment from the current location."""
    d = read("IN;SP1;PU100,0;PD;AR-100,0,-90;")
    np.testing.assert_allclose(pts(d)[-1], [0, -100], atol=1e-9)


def test_ci_draws_a_circle_around_the_pen_and_leaves_the_pen_there() -> None:
    """PCL5-II p. 20-25, CI: a circle of the given radius around the current location, 72
    chords with the default 5-degree chord angle, drawn with an automatic pen down; the pen
    then returns to the centre with its previous up/down status."""
    d = read("IN;SP1;PU500,500;CI100;PD600,500;")
    ring = pts(d, 0)
    assert len(ring) == 73 and d.paths[0].closed
    np.testing.assert_allclose(np.hypot(*(ring - 500).T), 100.0)
    np.testing.assert_array_equal(pts(d, 1), [[500, 500], [600, 500]])


def test_at_arc_through_three_points() -> None:
    """ch. 20, AT: an arc from the current location through the intermediate point to the
    end point; the pen ends at the end point."""
    d = read("IN;SP1;PU100,0;PD;AT0,100,-100,0;")
    p = pts(d)
    np.testing.assert_allclose(p[0], [100, 0])
    np.testing.assert_allclose(p[-1], [-100, 0])
    np.testing.assert_allclose(np.hypot(*p.T), 100.0, atol=1e-9)
    assert p[:, 1].max() == pytest.approx(100.0, abs=1.0)


def test_rt_is_at_with_increments() -> None:
    """ch. 20, RT: AT's points given as increments from the current location."""
    a = read("IN;SP1;PU100,0;PD;AT0,100,-100,0;")
    r = read("IN;SP1;PU100,0;PD;RT-100,100,-200,0;")
    np.testing.assert_allclose(pts(r), pts(a), atol=1e-9)


# ------------------------------------------------------------------ Table 1: rectangles
@pytest.mark.parametrize("cmd,args", [("EA", "300,200"), ("ER", "200,100"),
                                      ("RA", "300,200"), ("RR", "200,100")])
def test_rectangles_from_the_current_point_restore_the_pen(cmd: str, args: str) -> None:
    """PCL5-II p. 21-18 (EA) and p. 21-39 (RA): a rectangle from the current location to
    the diagonally opposite corner (absolute for EA/RA, an increment for ER/RR); "when the
    command operation is complete, the original pen location and up/down status are
    restored". Edge or fill, the geometry is the one closed ring."""
    d = read(f"IN;SP1;PU100,100;{cmd}{args};PD150,100;")
    np.testing.assert_array_equal(pts(d, 0), [[100, 100], [300, 100], [300, 200], [100, 200],
                                              [100, 100]])
    assert d.paths[0].closed
    np.testing.assert_array_equal(pts(d, 1), [[100, 100], [150, 100]])


# ------------------------------------------------------------------ Table 1: Béziers
def _bezier(c: np.ndarray, t: np.ndarray) -> np.ndarray:
    t = t[:, None]
    return ((1 - t) ** 3 * c[0] + 3 * (1 - t) ** 2 * t * c[1] + 3 * (1 - t) * t**2 * c[2]
            + t**3 * c[3])


@pytest.mark.parametrize("cmd", ["BZ", "BA"])
def test_bz_cubic_from_the_current_point(cmd: str) -> None:
    """ch. 20, BZ: a cubic Bézier from the current location with the two control points
    and the end point given; the pen ends at the end point. The flattening stays within
    0.1 unit of the curve."""
    d = read(f"IN;SP1;PU0,0;PD;{cmd}0,100,100,100,100,0;")
    p = pts(d)
    np.testing.assert_allclose(p[0], [0, 0])
    np.testing.assert_allclose(p[-1], [100, 0])
    curve = _bezier(np.array([[0, 0], [0, 100], [100, 100], [100, 0]], float),
                    np.linspace(0, 1, 2001))
    # every curve point lies within the tolerance of the polyline
    a, b = p[:-1], p[1:]
    ab = b - a
    t = np.clip(((curve[:, None, :] - a) * ab).sum(-1) / (ab * ab).sum(-1), 0, 1)
    dist = np.hypot(*(a + t[..., None] * ab - curve[:, None, :]).transpose(2, 0, 1)).min(1)
    assert dist.max() <= 0.1 + 1e-9


def test_br_control_points_are_increments_from_the_start() -> None:
    """ch. 20, BR: the control and end points are increments from the curve's start."""
    a = read("IN;SP1;PU10,10;PD;BZ10,110,110,110,110,10;")
    r = read("IN;SP1;PU10,10;PD;BR0,100,100,100,100,0;")
    np.testing.assert_allclose(pts(r), pts(a))


# ------------------------------------------------------------------ Table 1: EP, FP
def test_ep_edges_the_polygon_buffer() -> None:
    """PCL5-II p. 21-36: EP draws the pen-down edges of the polygon in the buffer."""
    d = read("IN;SP1;PA0,0;PM0;PD100,0,100,100,0,100;PM2;EP;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [100, 0], [100, 100], [0, 100], [0, 0]])
    assert d.paths[0].closed


def test_fp_fills_the_polygon_buffer_as_closed_rings() -> None:
    """PCL5-II p. 21-36: FP fills between all vertices, pen up or down: each subpolygon is
    one closed region."""
    d = read("IN;SP1;PA0,0;PM0;PU100,0;PD100,100,0,100;PM2;FP;")
    assert all(p.closed for p in d.paths)


# ------------------------------------------------------------------ other HP-GL/2 commands
def test_ew_wg_wedge_is_centre_arc_centre() -> None:
    """PCL5-II p. 21-2 and ch. 21, EW/WG: a wedge (pie slice) around the current location:
    radius, start angle, sweep; one closed ring from the centre along the arc and back."""
    for cmd in ("EW", "WG"):
        d = read(f"IN;SP1;PU0,0;{cmd}100,0,90;")
        p = pts(d)
        np.testing.assert_allclose(p[0], [0, 0])
        np.testing.assert_allclose(p[1], [100, 0])
        np.testing.assert_allclose(p[-2], [0, 100], atol=1e-9)
        assert d.paths[0].closed


def test_in_lifts_the_pen_and_resets_absolute_mode() -> None:
    """ch. 19, IN: default conditions: pen up, absolute plotting, scaling off."""
    d = read("SP1;PR;SC0,10,0,10;PD;IN;PU5,5;PD6,6;")
    np.testing.assert_array_equal(pts(d, len(d.paths) - 1), [[5, 5], [6, 6]])


def test_df_turns_scaling_off() -> None:
    """ch. 19, DF: default values (scaling off, absolute) without moving P1/P2."""
    d = read("IN;SP1;IP0,0,1000,1000;SC0,10,0,10;DF;PU5,5;PD6,6;")
    np.testing.assert_array_equal(pts(d), [[5, 5], [6, 6]])


def test_ip_sc_map_user_units_onto_p1_p2() -> None:
    """ch. 19, IP and SC: SC xmin,xmax,ymin,ymax maps the user range onto P1..P2 (IP)."""
    d = read("IN;SP1;IP1000,1000,2000,3000;SC0,10,0,10;PU0,0;PD10,10;")
    np.testing.assert_allclose(pts(d), [[1000, 1000], [2000, 3000]])


def test_ir_gives_p1_p2_in_percent_of_the_page() -> None:
    """ch. 19, IR: P1 and P2 as percentages of the hard-clip limits (here the PS page)."""
    d = read("IN;SP1;PS1000,2000;IR10,20,60,70;SC0,100,0,100;PU0,0;PD100,100;")
    np.testing.assert_allclose(pts(d), [[100, 400], [600, 1400]])


def test_ro_rotates_the_coordinate_system() -> None:
    """ch. 19, RO: RO90 turns the coordinate system by 90 degrees counterclockwise."""
    d = read("IN;SP1;RO90;PU0,0;PD100,0;")
    np.testing.assert_allclose(pts(d), [[0, 0], [0, 100]])


def test_iw_clips_pen_down_lines_to_the_window() -> None:
    """ch. 19, IW: the soft-clip window; drawing outside it is clipped."""
    d = read("IN;SP1;IW0,0,100,100;PU50,50;PD150,50;")
    np.testing.assert_allclose(pts(d), [[50, 50], [100, 50]])


def test_ct_chord_tolerance_mode_1_uses_deviation() -> None:
    """ch. 20, CT: CT1 reads the chord argument of arcs and circles as the largest
    deviation (current units), not an angle: a smaller deviation gives more chords."""
    coarse = read("IN;SP1;PU0,0;CT1;CI1000,50;")
    fine = read("IN;SP1;PU0,0;CT1;CI1000,5;")
    assert len(pts(fine)) > len(pts(coarse)) > 4


def test_xt_yt_tick_marks() -> None:
    """ch. 22, XT/YT (TL): tick marks at the current location, 0.5 % of P2-P1 each way by
    default; the pen does not move."""
    d = read("IN;SP1;IP0,0,10000,10000;PU1000,1000;XT;")
    np.testing.assert_allclose(pts(d), [[1000, 950], [1000, 1050]])


def test_lt_is_recorded_and_lines_stay_solid() -> None:
    """ch. 22, LT: line types are a rendering attribute; the geometry is the solid line."""
    d = read("IN;SP1;LT2,4;PU0,0;PD100,0;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [100, 0]])
    assert any("line types" in w.message for w in d.warnings)


def test_pg_pages_are_overlaid() -> None:
    """ch. 19, PG: advances a page; a galvo has one field, so pages are overlaid (warned)."""
    d = read("IN;SP1;PU0,0;PD10,0;PG;PU0,0;PD10,0;PG;")
    assert len(d.paths) == 2
    assert any("pages" in w.message for w in d.warnings)


def test_dt_lb_label_text_is_not_read_as_commands() -> None:
    """ch. 23, DT and LB: the text up to the terminator (DT, ETX by default) is text."""
    d = read("IN;SP1;DT#;PU0,0;LBPD9,9#PU0,0;PD1,1;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [1, 1]])


def test_co_comment_is_ignored() -> None:
    """ch. 19, CO: a comment, "ignored by the device"."""
    d = read('IN;SP1;CO"PD9,9;";PU0,0;PD1,1;')
    np.testing.assert_array_equal(pts(d), [[0, 0], [1, 1]])


def test_sm_symbol_character_is_not_a_command() -> None:
    """ch. 22, SM: the next character is the symbol, not the start of a command."""
    d = read("IN;SP1;SMP;PU0,0;PD1,1;SM;")
    np.testing.assert_array_equal(pts(d), [[0, 0], [1, 1]])


def test_sp_selects_the_pen_of_later_paths() -> None:
    """PCL5-II p. 17-21: "the pen remains selected until a new SP command"."""
    d = read("IN;SP3;PU0,0;PD1,1;PU;SP2;PD2,2;")
    assert [p.pen for p in d.paths] == [3, 2]


def test_ps_page_size_is_the_hard_clip_for_iw_without_numbers() -> None:
    """ch. 19, PS and IW: IW without parameters is the hard-clip limits, the page PS gave."""
    d = read("IN;SP1;PS1000,1000;IW;PU500,500;PD2000,500;")
    np.testing.assert_allclose(pts(d), [[500, 500], [1000, 500]])


def test_arc_chords_follow_the_chord_angle() -> None:
    """ch. 20, AA: the fourth parameter is the chord angle; 30 degrees: 3 chords in 90."""
    d = read("IN;SP1;PU100,0;PD;AA0,0,90,30;")
    assert len(pts(d)) == 4
    np.testing.assert_allclose(pts(d)[1], [100 * math.cos(math.radians(30)),
                                           100 * math.sin(math.radians(30))])


# ------------------------------------------------------------------ LO with LB
CELL = 1.5 * 0.187 * 400  # the default character cell along the text (SI defaults)


@pytest.mark.parametrize("lo", ["", "LO;", "LO1;", "LO2;", "LO3;", "LO11;", "LO12;", "LO13;",
                                "LO21;"])
def test_lo_left_justified_labels_leave_the_pen_at_their_end(lo: str) -> None:
    """ch. 23, LO (PCL5-II 23-62: positions 1-9, 11-19, 21; none is LO1) and 23-65 (Table
    23-35): with text path DV0 the label origins 1, 2, 3, 11, 12, 13 and 21 concatenate:
    "the pen position is updated to give the normal delta X space" to the next label, so
    PD;PR after a 3-character label draws from 3 cells further on (LO11-13 only offset the
    letters from the pen, not where the next label starts)."""
    d = read(f"IN;SP1;PU0,0;{lo}LBABC\x03;PD;PR100,0;")
    np.testing.assert_allclose(pts(d), [[3 * CELL, 0], [3 * CELL + 100, 0]])


@pytest.mark.parametrize("lo", [4, 5, 6, 7, 8, 9, 14, 15, 16, 17, 18, 19])
def test_lo_centred_or_right_justified_labels_restore_the_pen(lo: int) -> None:
    """ch. 23, LO (PCL5-II 23-65, rule 2): "If a non-concatenation combination is
    specified, the pen position that existed immediately prior to the LB command is
    restored" -- also over CR/LF in the label."""
    d = read(f"IN;SP1;PU0,0;LO{lo};LBABC\r\nDE\x03;PD;PR100,0;")
    np.testing.assert_allclose(pts(d), [[0, 0], [100, 0]])


def test_lo_lasts_until_in_or_df_and_out_of_range_is_ignored() -> None:
    """ch. 23, LO (PCL5-II 23-63): "An LO command remains in effect until another LO
    command is executed, or the printer is initialized or set to default conditions"; a
    position outside 1-9, 11-19, 21 is not one (ignored, with a warning)."""
    # LO5 then LO10 (ignored): still LO5, the pen stays at 0,0 after both labels
    d = read("IN;SP1;PU0,0;LO5;LBAB\x03LO10;LBAB\x03PD;PR100,0;")
    np.testing.assert_allclose(pts(d), [[0, 0], [100, 0]])
    assert any("LO10" in w.message for w in d.warnings)
    for reset in ("IN;SP1;", "DF;"):
        d = read(f"IN;SP1;LO5;{reset}PU0,0;LBAB\x03;PD;PR100,0;")
        np.testing.assert_allclose(pts(d)[0], [2 * CELL, 0])
