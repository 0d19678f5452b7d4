"""The HP-GL semantics that real files rely on (issue 20), one minimal reproducer each.

Each test is the smallest file that showed the rule on a real file, and asserts the geometry
a user would mark. References: HP's "PCL 5 Printer Language Technical Reference Manual,
Part II" (the HP-GL/2 chapters; cited as PCL5-II with the page number printed on the page,
e.g. 21-36), the "HP-GL/2 Reference Guide" (Addison-Wesley 1990; cited as HP-GL/2 RG with
the instruction, where no page was at hand) and the HP 7475A "Interfacing and Programming
Manual" (HP-GL/1; cited as 7475A with the instruction).
"""

from __future__ import annotations

import bz2
import gzip
import lzma

import numpy as np
import pytest

from galvo_core.errors import InputError
from galvo_core.hpgl import read_bytes


def read(text: str | bytes):
    return read_bytes(text.encode("latin-1") if isinstance(text, str) else text, "rule.plt")


def pen_down_length(d) -> float:
    return sum(p.length for p in d.paths)


def messages(d) -> list[str]:
    return [w.message for w in d.warnings]


# ------------------------------------------------------------------- 1. polygon mode
def test_plotutils_open_polyline_in_polygon_mode_stays_open() -> None:
    """GNU plotutils writes each open polyline as ``PM0;PD;PA...;PU;PM2;EP;``.

    PCL5-II p. 21-36/21-37 (PM): EP "only draws between points that are defined when the
    pen is down"; PM2 closes the polygon by adding a point, an edge with the pen state of
    the moment (p. 21-37 refers to "Pen Status", p. 17-21). The pen is up at PM2, so the
    closing edge is not drawn: the polyline stays open, 2 segments, 200 units.
    """
    d = read("IN;SP1;PA0,0;PM0;PD;PA100,0;PA100,100;PU;PM2;EP;")
    assert len(d.paths) == 1
    np.testing.assert_array_equal(d.paths[0].points, [[0, 0], [100, 0], [100, 100]])
    assert not d.paths[0].closed
    assert pen_down_length(d) == pytest.approx(200.0)


def test_pm2_with_the_pen_down_draws_the_closing_edge() -> None:
    """PCL5-II p. 21-37: with the pen down at PM2 the closure is a pen-down edge."""
    d = read("IN;SP1;PA0,0;PM0;PD;PA100,0;PA100,100;PM2;EP;")
    assert len(d.paths) == 1 and d.paths[0].closed
    np.testing.assert_array_equal(d.paths[0].points,
                                  [[0, 0], [100, 0], [100, 100], [0, 0]])


def test_ep_skips_pen_up_edges_but_fp_fills_the_whole_ring() -> None:
    """PCL5-II p. 21-36: EP draws only pen-down edges; "FP fills the area(s) between all
    vertices, regardless of whether the pen is up or down": the fill ring is closed."""
    ep = read("IN;SP1;PA0,0;PM0;PD;PA100,0,100,100;PU;PM2;EP;")
    fp = read("IN;SP1;PA0,0;PM0;PD;PA100,0,100,100;PU;PM2;FP;")
    assert len(ep.paths) == 1 and not ep.paths[0].closed
    assert len(fp.paths) == 1 and fp.paths[0].closed
    np.testing.assert_array_equal(fp.paths[0].points,
                                  [[0, 0], [100, 0], [100, 100], [0, 0]])
    # edged and filled: one region (FP replaces EP's open edges by the ring)
    both = read("IN;SP1;PA0,0;PM0;PD;PA100,0,100,100;PU;PM2;EP;FP;")
    assert len(both.paths) == 1 and both.paths[0].closed


def test_the_point_after_pm1_starts_a_subpolygon_with_a_pen_up_move() -> None:
    """PCL5-II p. 21-36: "the point after (PM1) becomes the first point of the next
    subpolygon ... the pen always moves to this point in the up position, regardless of
    the current pen status": no edge joins the two."""
    d = read("IN;SP1;PA0,0;PM0;PD100,0,100,100,0,100,0,0;PM1;PD20,20,80,20;PU;PM2;EP;")
    assert len(d.paths) == 2
    np.testing.assert_array_equal(d.paths[1].points, [[20, 20], [80, 20]])
    assert d.paths[0].closed and not d.paths[1].closed


# ------------------------------------------------------------------------------ 2. PS
@pytest.mark.parametrize("ps", ["PS0;", "PS-100;", "PS0,1000;", "PS1000,0;"])
def test_ps_with_a_length_of_zero_or_less_is_ignored(ps: str) -> None:
    """HP-GL/2 RG, PS: a length <= 0 makes the device ignore the instruction.
    An ignored PS leaves no page, so IW; has no window to clip to."""
    d = read(f"IN;{ps}IW;SP1;PU100,100;PD1000,1000;")
    assert len(d.paths) == 1
    np.testing.assert_array_equal(d.paths[0].points, [[100, 100], [1000, 1000]])
    assert any("PS with a length <= 0 ignored" in m for m in messages(d))


# ------------------------------------------------------------------------- 3. ESC*p#X
def test_pcl_cursor_position_escape_carries_no_data() -> None:
    """ESC*p#X is PCL's horizontal cursor position (no data follows, PCL 5 Technical
    Reference, Part I, cursor positioning); only ESC&p#X (transparent print data) is
    followed by # bytes of data. The HP-GL/2 after ESC%1B is read."""
    d = read(b"\x1bE\x1b*p300X\x1b%1BIN;SP1;PU0,0;PD1000,0;")
    assert len(d.paths) == 1
    np.testing.assert_array_equal(d.paths[0].points, [[0, 0], [1000, 0]])


def test_transparent_print_data_is_skipped_as_data() -> None:
    """ESC&p#X: the # bytes after it are data, even when they look like HP-GL."""
    d = read(b"\x1bE\x1b&p8XPD9,9,9;\x1b%1BIN;SP1;PU0,0;PD1000,0;")
    assert len(d.paths) == 1
    np.testing.assert_array_equal(d.paths[0].points, [[0, 0], [1000, 0]])


# ------------------------------------------------------------------------------ 4. LB
CELL = 1.5 * 0.187 * 400  # default advance: 1.5 x the default width 0.187 cm (7475A, SI)
LINE = 2.0 * 0.269 * 400  # default line spacing: 2 x the default height 0.269 cm


def test_label_moves_the_pen_to_its_end() -> None:
    """HP-GL/2 RG and 7475A, LB: the pen moves one character cell per character and is
    left at the end of the text (CR/LF move to the carriage-return point's next line).
    A following PD;PR draws from there."""
    d = read("IN;SP1;PU0,0;LBABC\x03;PD;PR100,0;")
    assert len(d.paths) == 1
    np.testing.assert_allclose(d.paths[0].points, [[3 * CELL, 0], [3 * CELL + 100, 0]])


def test_label_cell_follows_si_and_direction_follows_di() -> None:
    """SI w,h in cm sets the cell (7475A: 1.5 w along the text); DI 0,1 writes upwards."""
    d = read("IN;SP1;SI0.4,0.6;DI0,1;PU0,0;LBAB\x03;PD;PR0,100;")
    np.testing.assert_allclose(d.paths[0].points[0], [0, 2 * 1.5 * 0.4 * 400])


def test_label_cell_follows_sr() -> None:
    """SR w,h: percentages of P2x-P1x and P2y-P1y (7475A and HP-GL/2 RG, SR)."""
    d = read("IN;SP1;IP0,0,10000,10000;SR1,2;PU0,0;LBAB\x03;PD;PR0,100;")
    np.testing.assert_allclose(d.paths[0].points[0], [2 * 1.5 * 100, 0])


def test_label_cr_lf_goes_to_the_next_line_start() -> None:
    """CR returns to the label's start column, LF moves one line down (7475A, LB)."""
    d = read("IN;SP1;PU1000,1000;LBABCD\r\nX\x03;PD;PR10,0;")
    np.testing.assert_allclose(d.paths[0].points[0], [1000 + CELL, 1000 - LINE])


def test_label_ends_the_path_drawn_before_it() -> None:
    """With the pen down, the line drawn before the label ends there; the next pen-down
    move starts at the label's end (no line across the text)."""
    d = read("IN;SP1;PU0,0;PD100,0;LBA\x03;PR0,100;")
    assert len(d.paths) == 2
    np.testing.assert_allclose(d.paths[1].points, [[100 + CELL, 0], [100 + CELL, 100]])


# ------------------------------------------------------------------------------ 5. SP
def test_sp_keeps_the_pen_down_in_hpgl2() -> None:
    """PCL5-II p. 17-21: "Once lowered with a PD command, the pen remains down ... until a
    PU or IN" (SP only changes the pen). HP-GL/2 file (BP): 200 units, the second part with
    pen 2."""
    d = read("BP;IN;SP1;PU0,0;PD100,0;SP2;PA200,0;")
    assert [p.pen for p in d.paths] == [1, 2]
    assert pen_down_length(d) == pytest.approx(200.0)
    np.testing.assert_array_equal(d.paths[1].points, [[100, 0], [200, 0]])


def test_sp_lifts_the_pen_in_hpgl1() -> None:
    """An HP-GL/1 plotter (7475A, SP) puts the pen in its stall and takes the new one: the
    pen comes back up. A file with no HP-GL/2-only command is read as HP-GL/1."""
    d = read("IN;SP1;PU0,0;PD100,0;SP2;PA200,0;")
    assert [p.pen for p in d.paths] == [1]
    assert pen_down_length(d) == pytest.approx(100.0)


def test_pcl_wrapped_hpgl2_keeps_the_pen_down_over_sp() -> None:
    """Entered through PCL (ESC%1B) the language is HP-GL/2."""
    d = read(b"\x1bE\x1b%1BIN;SP1;PU0,0;PD100,0;SP2;PA200,0;")
    assert pen_down_length(d) == pytest.approx(200.0)


# ------------------------------------------------------------------------- 6. no SP
def test_no_sp_draws_with_pen_1_and_says_so() -> None:
    """PCL5-II p. 17-21: without SP "no lines are drawn"; CAD files rely on pen 1, so the
    reader draws with pen 1 and warns once."""
    d = read("IN;PU0,0;PD100,0;PU;PD0,100;")
    assert [p.pen for p in d.paths] == [1, 1]
    assert any("drawn before any pen was selected (SP)" in m and m.startswith("2 path")
               for m in messages(d))


def test_sp_first_gives_no_pen_warning() -> None:
    d = read("IN;SP1;PU0,0;PD100,0;")
    assert not any("pen was selected" in m for m in messages(d))


# ------------------------------------------------------------- not HP-GL: refused
NOT_HPGL = {
    "gzip": (gzip.compress(b"IN;SP1;PD100,100;" * 40), "gzip"),
    "bzip2": (bz2.compress(b"IN;SP1;PD100,100;" * 40), "bzip2"),
    "xz": (lzma.compress(b"IN;SP1;PD100,100;" * 40), "xz"),
    "zip": (b"PK\x03\x04" + bytes(300), "ZIP"),
    "gerber": (b"G04 board*\n%FSLAX24Y24*%\n%MOIN*%\nD10*\nX0Y0D02*\nX1000Y0D01*\nM02*\n",
               "Gerber"),
    "excellon": (b"M48\nINCH,LZ\nT1C0.035\n%\nT1\nX001Y001\nM30\n", "Excellon"),
    "dmpl": (b";: EC5 U 0,0 D 100,0 100,100 @", "DM/PL"),
    "gcode": (b"G21\nG90\nG1 X10 Y10 F100\nG1 X20 Y10\n", "G-code"),
    "coreldraw": (b"RIFF\x10\x00\x00\x00CDRvvers" + bytes(300), "CorelDRAW"),
    "pcl-raster": (b"\x1bE\x1b*t300R\x1b*r1A\x1b*b4W\x00\x01\x02\x03\x1b*rB\x1bE",
                   "PCL/PJL print job without HP-GL/2"),
}


@pytest.mark.parametrize("kind", sorted(NOT_HPGL))
def test_non_hpgl_is_refused_with_one_line(kind: str, tmp_path, capsys) -> None:
    """Compressed files, other plot and CAD languages and PCL raster-only jobs are refused
    with one line naming the file and what it is (the CLI exits 2, no traceback)."""
    from galvo_core.cli import main

    data, words = NOT_HPGL[kind]
    with pytest.raises(InputError, match=words) as ei:
        read(data)
    assert "\n" not in str(ei.value) and str(ei.value).startswith("rule.plt: ")
    f = tmp_path / f"{kind}.plt"
    f.write_bytes(data)
    assert main(["info", str(f)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"error: {kind}.plt: ") and words in err
