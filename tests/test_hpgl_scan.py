"""The compiled scanner (galvo_core.hpgl.scan) reads exactly what the command-by-command
reader reads: same points (bit for bit), pens, closed flags, positions, warnings and command
counts, also when its output chunks fill up in the middle of paths and commands."""

from __future__ import annotations

import random
from collections import Counter
from unittest import mock

import numpy as np
import pytest

import galvo_core.hpgl.reader as reader
from galvo_core.hpgl import read_bytes

pytest.importorskip("numba")


def _read(data: bytes, compiled: bool, chunk: int = reader._CHUNK_POINTS):
    with mock.patch.object(reader, "_use_compiled", lambda size: compiled), \
            mock.patch.object(reader, "_FAST_MIN_BYTES", 10**12), \
            mock.patch.object(reader, "_CHUNK_POINTS", chunk):
        return read_bytes(data, "scan.plt")


def assert_same(a, b) -> None:
    assert len(a.paths) == len(b.paths)
    for p, q in zip(a.paths, b.paths, strict=True):
        assert np.array_equal(p.points, q.points)
        assert (p.pen, p.closed, p.start) == (q.pen, q.closed, q.start)
        assert not p.points.flags.writeable
    assert a.warnings == b.warnings
    assert dict(a.commands) == dict(b.commands)


def _program(rng: random.Random, n: int) -> bytes:
    out = [b"IN;SP1;"]
    for _ in range(n):
        r = rng.random()
        if r < 0.3:
            out.append(b"PU%d,%d;" % (rng.randint(-999, 999), rng.randint(-999, 999)))
        elif r < 0.6:
            k = rng.randint(0, 40)
            nums = ",".join(f"{rng.uniform(-500, 500):.{rng.randint(0, 3)}f}" for _ in range(2 * k))
            out.append(b"PD" + nums.encode() + b";")
        elif r < 0.7:
            out.append(b"PR;" if rng.random() < 0.5 else b"PA;")
        elif r < 0.8:
            out.append(b"SP%d;" % rng.randint(0, 4))
        elif r < 0.85:
            out.append(rng.choice([b"LT;", b"CI5;", b"PD1:2;", b"PD1,2,3;", b"BP;", b"\n",
                                   b"SC0,100,0,100;", b"SC;", b"PD1.2.3,4;", b"LBab\x03",
                                   b"PW0.35;", b"PW0.5,2;", b"PW;", b"PW1,2,3;", b"PW.;"]))
        else:
            out.append(b"PD%d,%d" % (rng.randint(0, 99), rng.randint(0, 99)))  # no ';'
    return b"".join(out)


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("chunk", [8, 1 << 16])
def test_compiled_scanner_reads_what_the_general_reader_reads(seed: int, chunk: int) -> None:
    data = _program(random.Random(seed), 400)
    assert_same(_read(data, True, chunk), _read(data, False))


def test_one_long_command_across_many_chunks() -> None:
    """A single PD with 5000 pairs, chunks of 8 points: the chunk grows, the path is one."""
    body = ",".join(f"{k},{k % 7}" for k in range(5000)).encode()
    data = b"IN;SP1;PU0,0;PD" + body + b";PU;"
    a, b = _read(data, True, 8), _read(data, False)
    assert_same(a, b)
    assert len(a.paths) == 1 and len(a.paths[0].points) == 5001


def test_path_open_across_an_interruption_is_one_path() -> None:
    """A path the scanner leaves open goes on after a command it hands over (LT)."""
    data = b"IN;SP1;PU0,0;PD1,1;LT;PD2,2;LT;PD3,3;PU;"
    a = _read(data, True, 8)
    assert_same(a, _read(data, False))
    np.testing.assert_array_equal(a.paths[0].points, [[0, 0], [1, 1], [2, 2], [3, 3]])


def test_pen_width_between_paths_stays_in_the_scanner_and_makes_the_file_hpgl2() -> None:
    """PW (pen width, recorded, not drawn) between paths, as plotting libraries write it
    before every path: read in the compiled run like the general reader reads it; PW is an
    HP-GL/2 command, so a later SP keeps the pen down (PCL5-II p. 17-21) in both readers."""
    data = (b"IN;SP1;" + b"".join(b"PW0.75;PU%d,0;PD%d,10,%d,20;" % (k, k, k + 1)
                                  for k in range(0, 300, 3))
            + b"PU0,0;PD5,5;SP2;PA9,9;PU;")
    calls = []
    run = reader._Reader._compiled_run
    with mock.patch.object(reader._Reader, "_compiled_run",
                           lambda self, i: calls.append(i) or run(self, i)):
        a = _read(data, True, 1 << 16)
    assert_same(a, _read(data, False))
    assert len(calls) <= 3  # one run over all 100 PW, not a hand-over at each one
    assert a.commands["PW"] == 100
    assert [p.pen for p in a.paths[-2:]] == [1, 2]  # SP2 kept the pen down: drawn with pen 2
    np.testing.assert_array_equal(a.paths[-1].points, [[5, 5], [9, 9]])


def _poly_program(rng: random.Random, n: int) -> bytes:
    """Random programs in and out of polygon mode (PM0/PM1/PM2, EP/FP, moves, odd counts,
    junk, scaling, figures inside PM): what the general reader warns about or reads itself
    must come out the same from the compiled one."""
    out = [b"IN;SP1;"]
    for _ in range(n):
        r = rng.random()
        if r < 0.1:
            out.append(rng.choice([b"PM0;", b"PM;", b"PM1;", b"PM2;", b"PM 0;", b"PM0.5;"]))
        elif r < 0.16:
            out.append(rng.choice([b"EP;", b"FP;", b"FP1;", b"EP", b"FP0,2;"]))
        elif r < 0.36:
            out.append(b"PU%d,%d;" % (rng.randint(-999, 999), rng.randint(-999, 999))
                       if rng.random() < 0.8 else b"PU;")
        elif r < 0.66:
            k = rng.randint(0, 12)
            nums = ",".join(f"{rng.uniform(-500, 500):.{rng.randint(0, 3)}f}" for _ in range(2 * k))
            out.append(rng.choice([b"PD", b"PA", b"PR", b"pd"]) + nums.encode() + b";")
        elif r < 0.72:
            out.append(rng.choice([b"PR;", b"PA;", b"PD;", b"PW0.3;", b"PW;"]))
        elif r < 0.76:
            out.append(b"SP%d;" % rng.randint(1, 3))
        elif r < 0.82:
            out.append(rng.choice([b"CI5;", b"PD1:2;", b"PD1,2,3;", b"PR1.2.3,4;", b"LBab\x03",
                                   b"SC0,100,0,100;", b"SC;", b"EA50,50;", b"AA0,0,90;",
                                   b"\n", b"LT;", b"PW1,2,3;", b"IN;SP1;", b"DF;"]))
        else:
            out.append(b"PD%d,%d" % (rng.randint(0, 99), rng.randint(0, 99)))  # no ';'
    return b"".join(out)


@pytest.mark.parametrize("seed", range(16))
def test_compiled_polygon_mode_reads_what_the_general_reader_reads(seed: int) -> None:
    """Moves inside polygon mode are read by the compiled scanner into its polygon buffer:
    same sub-polygons, EP/FP paths, warnings and counts."""
    data = _poly_program(random.Random(1000 + seed), 500)
    a = _read(data, True, 8)
    assert_same(a, _read(data, False))
    assert a.commands.get("PM", 0) > 0 and len(a.paths) > 0


def _nums(rng: random.Random, k: int) -> bytes:
    """``k`` random coordinate pairs (0-2 decimals) as one parameter list."""
    return ",".join(f"{rng.uniform(-500, 500):.{rng.randint(0, 2)}f}"
                    for _ in range(2 * k)).encode()


def _pm_program(rng: random.Random, n: int) -> bytes:
    """Random programs dense in polygon mode as files write it (GNU plotutils' open
    polylines, per-point PD closed by FP, PM1 sub-polygons) mixed with PU/PD/PA/PR/PW, pen
    changes (SP inside PM too, no SP at all), FP after EP (with and without paths drawn
    between), EP after FP, and what the compiled scanner hands back to the general reader
    at that command (PE, CI, EA, LB inside PM, IW, RO, IN, DF, PM0 inside PM, PM1/PM2/EP/FP
    where they are warned about, junk parameters)."""
    from galvo_core.hpgl.pe import encode_number

    def nums(k: int) -> bytes:
        return _nums(rng, k)
    out = [rng.choice([b"IN;SP1;", b"IN;", b"", b"SP2;", b"IN;PW0.5;SP1;"])]
    for _ in range(n):
        r = rng.random()
        if r < 0.12:
            out.append(rng.choice([b"PM0;", b"PM;", b"PM1;", b"PM2;", b"PM 2;", b"PM0.5;",
                                   b"PM1,5;", b"PM3;", b"pm2", b"PM-0;", b"PM2\n"]))
        elif r < 0.22:
            out.append(rng.choice([b"EP;", b"FP;", b"FP1;", b"EP", b"FP0,2;", b"EP;FP;",
                                   b"FP;EP;", b"EP;PD1,1;FP;", b"EP;PU;FP;", b"EP;LT;FP;",
                                   b"EP;PU5,5;FP;", b"ep;fp;", b"EP;SP2;FP;", b"FP:;"]))
        elif r < 0.30:  # GNU plotutils: an open polyline (PM2 with the pen up)
            out.append(b"PA%d,%d;PM0;PD;PA%s;PU;PM2;EP;" % (
                rng.randint(-999, 999), rng.randint(-999, 999), nums(rng.randint(1, 6))))
        elif r < 0.36:  # per-point PD, closed by FP (and PM1 sub-polygons)
            body = b"".join((b"PD%s;" % nums(1)) if rng.random() < 0.85 else
                            rng.choice([b"PM1;", b"PU%s;" % nums(1), b"PU;", b"PD;"])
                            for _ in range(rng.randint(0, 8)))
            out.append(b"PU%s;PM0;%sPM2;%s" % (nums(1), body,
                                               rng.choice([b"FP;", b"EP;", b"FP;EP;", b""])))
        elif r < 0.48:
            out.append(b"PU%s;" % nums(rng.randint(0, 2)))
        elif r < 0.66:
            out.append(rng.choice([b"PD", b"PA", b"PR", b"pd", b"PD ", b"PA\n"])
                       + nums(rng.randint(0, 6)) + b";")
        elif r < 0.74:
            out.append(rng.choice([b"SP0;", b"SP1;", b"SP2;", b"SP3;", b"PW0.3;", b"PW;",
                                   b"PR;", b"PA;", b"PD;", b"PU;"]))
        elif r < 0.82:
            pe = b"PE" + b"".join(encode_number(rng.randint(-300, 300)) for _ in range(4))
            out.append(rng.choice([b"CI5;", b"EA50,50;", pe + b";", b"<" + pe[2:] + b";",
                                   b"LBab\x03", b"IW-400,-400,400,400;", b"IW;", b"RO90;",
                                   b"RO;", b"SC0,100,0,100;", b"SC;", b"IN;", b"DF;", b"LT;",
                                   b"PD1:2;", b"PR1.2.3,4;", b"PD1,2,3;"]))
        elif r < 0.84:  # fill type (recorded, not drawn), as files write it before PM0
            out.append(rng.choice([b"FT1;", b"FT;", b"FT10,30,45;", b"FT:;", b"ft 3,5",
                                   b"FT1,2,3,4,5,6;", b"FT1.2.3;"]))
        elif r < 0.87:
            out.append(b"\n")
        else:
            out.append(b"PD%d,%d" % (rng.randint(0, 99), rng.randint(0, 99)))  # no ';'
    return b"".join(out)


@pytest.mark.parametrize("seed", range(24))
@pytest.mark.parametrize("small", [True, False])
def test_compiled_polygon_commands_read_what_the_general_reader_reads(seed: int,
                                                                     small: bool) -> None:
    """PM0/PM1/PM2, EP and FP read by the compiled scanner (EP's and FP's paths written as
    its segments, FP after EP replacing them) give the same paths, pens, closed flags,
    positions, warnings (the pen-selected count too) and command counts as the general
    reader; with tiny output chunks and polygon buffers (``small``) they fill up in the
    middle of commands, polygons, EP and FP."""
    from galvo_core.hpgl import scan

    data = _pm_program(random.Random(2000 + seed), 400)
    read_by_scanner = Counter()
    orig = scan.scan_moves

    def spy(*args):  # type: ignore[no-untyped-def]
        orig(*args)
        ist = args[1]
        read_by_scanner.update(PM=int(ist[scan.I_NPM]), EP=int(ist[scan.I_NEP]),
                               FP=int(ist[scan.I_NFP]))

    with mock.patch.object(scan, "scan_moves", spy), \
            mock.patch.object(reader, "_POLY_POINTS", 4 if small else reader._POLY_POINTS):
        a = _read(data, True, 8 if small else 1 << 16)
    assert_same(a, _read(data, False))
    assert read_by_scanner["PM"] > 0 and read_by_scanner["EP"] + read_by_scanner["FP"] > 0


@pytest.mark.parametrize("data", [
    b"IN;SP1;PU0,0;LT;PM0;\nCI3;\nPD10,0,10,10;PM2;EP;FP;PU;PD3,3;",
    b"IN;SP1;PU0,0;LT;PM0;\nLT;PD10,0,10,10;\nPM2;FP;\nEP;PU;PD3,3;",
    b"IN;SP1;PU0,0;LT;PM0;PD10,0;\nPD10,10;PM1;PD20,20,30,30;PM2;FP;EP;PA0,0;",
    b"IN;SP1;PU1,1;PM0;PD5,5;CI3;PD9,9;PM2;EP;LT;FP;PU;PD1,2;",
])
def test_polygon_begun_by_the_general_reader_is_finished_by_the_scanner(data: bytes) -> None:
    """A polygon the general reader began (PM0 after a command the scanner does not read)
    or added to (CI inside PM) is handed to the scanner with the moves that follow; FP after
    an EP the scanner wrote is the general reader's when something came between. EP's and
    FP's paths start at PM0 (line 1) also when the scanner took the polygon over on a later
    line."""
    a = _read(data, True)
    assert_same(a, _read(data, False))
    at_pm0 = [p for p in a.paths
              if (p.start.line, p.start.col) == (1, data.index(b"PM0") + 1)]
    assert at_pm0 and any(len(p.points) >= 3 for p in at_pm0)


def test_polygon_mode_is_read_by_the_scanner_in_one_call() -> None:
    """Issue 20, reproducer 1 in polygon mode (GNU plotutils' open polylines,
    ``PA x0,y0;PM0;PD;PA x1,y1,...;PU;PM2;EP;``) and per-point PD in PM closed by FP (FT
    before it): the whole file is one compiled call (PM0/PM2/EP/FP/FT and the moves), the
    polylines stay open
    (PM2 closes them with the pen up: EP does not draw that edge), FP's rings are closed,
    as the general reader reads them; a single command with more moves than the polygon
    buffer holds (4,999 pairs) too."""
    lines = [[(k, 0), (k + 100, 50), (k + 200, 0)] for k in range(0, 3000, 300)]
    body = b"".join(b"PA%d,%d;PM0;PD;PA%s;PU;PM2;EP;\n" % (
        *ln[0], ",".join(f"{x},{y}" for x, y in ln[1:]).encode()) for ln in lines)
    rings = b"".join(b"PU%d,0;FT1;PM0;PD%d,9;PD%d,0;PM2;FP;\n" % (k, k + 5, k + 9)
                     for k in range(0, 100, 10))
    big = ",".join(f"{k},{k % 7}" for k in range(1, 5000)).encode()
    data = b"IN;SP1;" + body + rings + b"PU;PA0,0;PM0;PD;PA" + big + b";PM2;EP;"
    calls = []
    run = reader._Reader._compiled_run
    with mock.patch.object(reader._Reader, "_compiled_run",
                           lambda self, i: calls.append(i) or run(self, i)):
        a = _read(data, True)
    assert_same(a, _read(data, False))
    assert [c for c in calls if c >= len(b"IN;SP1;")] == [len(b"IN;SP1;")]  # (SP1 first:
    # the general reader's, no pen was selected)
    assert a.commands["PM"] == 2 * (len(lines) + 11) and a.commands["EP"] == len(lines) + 1
    assert a.commands["FT"] == 10
    assert len(a.paths) == len(lines) + 10 + 1
    for p, ln in zip(a.paths, lines, strict=False):
        np.testing.assert_array_equal(p.points, ln)  # open: no closing edge added
        assert not p.closed
    for p, k in zip(a.paths[len(lines):], range(0, 100, 10), strict=False):
        np.testing.assert_array_equal(p.points, [(k, 0), (k + 5, 9), (k + 9, 0), (k, 0)])
        assert p.closed and p.start.line == len(lines) + 1 + k // 10
    # the last one ends with the pen down: PM2 closes it with a pen-down edge
    assert len(a.paths[-1].points) == 5001 and a.paths[-1].closed


# ------------------------------------------------------------------ PE
def _pe_both(data: bytes, pos: int = 0):
    from galvo_core.hpgl import scan
    from galvo_core.hpgl.pe import PECache, decode_pe

    ref = decode_pe(data, pos, PECache())
    end, kinds, xs, ys, flags, ni, p_off, p_code, p_val, npb = scan.decode_pe(
        np.frombuffer(data, np.uint8), pos, np.array([-1, -1, -1, -1], np.int64))
    got = [("pen", int(x), 0.0, 0.0, False, False) if k == 0 else
           ("pair", 0, x, y, bool(f & 1), bool(f & 2))
           for k, x, y, f in zip(kinds[:ni].tolist(), xs[:ni].tolist(), ys[:ni].tolist(),
                                 flags[:ni].tolist(), strict=True)]
    want = [(it.kind, it.value if it.kind == "pen" else 0, it.x if it.kind == "pair" else 0.0,
             it.y if it.kind == "pair" else 0.0, it.pen_up, it.absolute) for it in ref.items]
    msgs = [reader._PE_MESSAGES[c].format(v) for c, v in zip(p_code[:npb].tolist(),
                                                            p_val[:npb].tolist(), strict=True)]
    return (end, got, list(zip(p_off[:npb].tolist(), msgs, strict=True))), \
        (ref.end, want, ref.problems)


@pytest.mark.parametrize("seed", range(40))
def test_compiled_pe_decoder_matches_the_python_one(seed: int) -> None:
    from galvo_core.hpgl.pe import encode_number

    rng = random.Random(seed)
    parts = []
    for _ in range(rng.randint(0, 60)):
        r = rng.random()
        seven = False
        if r < 0.05:
            parts.append(b"7")
            seven = True
        elif r < 0.15:
            parts.append(rng.choice([b":", b"<", b">", b"=", b" ", b"\n", b"\x80"]))
        elif r < 0.2:
            parts.append(bytes([rng.randrange(256)]))  # noise, maybe the end of the run
        else:
            v = rng.choice([rng.randint(-100, 100), rng.randint(-10**6, 10**6),
                            rng.randint(-10**17, 10**17), rng.randint(0, 30)])
            parts.append(encode_number(v, seven=seven))
    data = b"".join(parts) + rng.choice([b";", b"", b"PU;", b"\x1b%0A"])
    got, want = _pe_both(data)
    assert got == want


def test_compiled_pe_reads_files_as_the_python_decoder() -> None:
    """A PE-heavy HP-GL/2 job (PCL-wrapped, polygons), read both ways: the same drawing."""
    from pathlib import Path

    f = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "plt" / \
        "artifexsoftware__ghostpdl__grashopp.pcl"
    if not f.is_file():
        pytest.skip("corpus file not present")
    data = f.read_bytes()
    assert_same(_read(data, True), _read(data, False))


def _pe_run(rng: random.Random) -> bytes:
    """One PE command as files and encoders write it, and as they should not: random numbers
    (8-bit and 7-bit after ``7``), pen-up ``<``, absolute ``=``, pen select ``:``, fractional
    bits ``>`` (in and out of 0..26), numbers beyond the clamp, half pairs, flags without
    their number, newlines and ignored bytes inside, no ``;`` (ended by the next command or
    a byte that is no PE data), ESC."""
    from galvo_core.hpgl.pe import encode_number

    out = [rng.choice([b"PE", b"PE", b"PE", b"pe", b"PE\n"])]
    seven = False
    for _ in range(rng.randint(0, 16)):
        r = rng.random()
        if r < 0.04 and not seven:
            out.append(b"7")
            seven = True
        elif r < 0.14:
            out.append(b"<")
        elif r < 0.20:
            out.append(b"=")
        elif r < 0.23:
            pen = rng.choice([1, 2, 3, 0, -1, 1, 2, 3, 0, 2**40])
            out.append(b":" + encode_number(pen, seven=seven))
        elif r < 0.27:
            bits = rng.choice([0, 1, 3, 8, 26, 0, 1, 3, 8, 26, 27, -1])
            out.append(b">" + encode_number(bits, seven=seven))
        elif r < 0.30:
            out.append(rng.choice([b"\n", b" ", b"\x80", b"\xff", b"\r\n"]))
        elif r < 0.305:
            out.append(rng.choice([b":", b">", b"1"]))  # a flag without its number, junk
        else:
            v = rng.choice([rng.randint(-300, 300)] * 12 + [rng.randint(-10**6, 10**6)] * 4
                           + [rng.randint(-10**16, 10**16)])
            out.append(encode_number(v, seven=seven))
    out.append(rng.choice([b";"] * 12 + [b"", b"\x1b%0A\x1b%0B", b";\n"]))
    return b"".join(out)


def _pe_program(rng: random.Random, n: int) -> bytes:
    """Random programs with PE in and out of polygon mode, mixed with moves, PM0/PM1/PM2,
    EP/FP, pen selects, scaling, RF/FT and what the scanner hands back (IW, RO, CI, LB)."""
    def nums(k: int) -> bytes:
        return _nums(rng, k)
    out = [rng.choice([b"IN;SP1;", b"IN;", b"", b"SP2;", b"IN;SC0,100,0,100;SP1;"])]
    for _ in range(n):
        r = rng.random()
        if r < 0.35:
            out.append(_pe_run(rng))
        elif r < 0.45:  # grashopp.pcl: PE=<x,y;PM0PE...;PM2FP (PM1PE...; between too)
            out.append(b"PE=<%s;PM0%s%sPM2%s" % (
                _pe_run(rng)[2:-1] or b"?\xbf?\xbf", _pe_run(rng),
                rng.choice([b"", b"", b"PM1" + _pe_run(rng), b"PM1PE;" + _pe_run(rng)]),
                rng.choice([b"FP", b"EP", b"FP;EP;", b""])))
        elif r < 0.55:
            out.append(rng.choice([b"PM0;", b"PM1;", b"PM2;", b"EP;", b"FP;", b"PM1"]))
        elif r < 0.70:
            out.append(rng.choice([b"PU", b"PD", b"PA", b"PR"]) + nums(rng.randint(0, 3))
                       + b";")
        elif r < 0.78:
            out.append(rng.choice([b"SP1;", b"SP2;", b"PA;", b"PR;", b"PU;", b"PD;",
                                   b"RF1,2,2,0,1,1,0;", b"FT11,2", b"RF;", b"RF1,2.2.2;",
                                   b"FT1;"]))
        elif r < 0.84:
            out.append(rng.choice([b"IW-400,-400,400,400;", b"IW;", b"RO90;", b"RO;",
                                   b"SC0,100,0,100;", b"SC;", b"SC0,300,0,50;", b"CI5;",
                                   b"LBab\x03", b"IN;", b"MC1,90", b"LT;"]))
        else:
            out.append(b"\n")
    return b"".join(out)


@pytest.mark.parametrize("seed", range(24))
@pytest.mark.parametrize("small", [True, False])
def test_compiled_pe_reads_what_the_general_reader_reads(seed: int, small: bool) -> None:
    """PE decoded and applied by the compiled scanner, in and out of polygon mode (issue
    20, grashopp.pcl's ``PE=<..;PM0PE..;PM2FP``), gives the same paths (bit for bit), pens,
    closed flags, positions (PE's paths start just after the mnemonic), warnings (the PE
    problems the general reader reports: the scanner hands those PE back) and command
    counts as the general reader with the Python decoder (pe.decode_pe); with tiny chunks
    and polygon buffers (``small``) they fill up in the middle of a PE."""
    from galvo_core.hpgl import scan

    data = _pe_program(random.Random(3000 + seed), 300)
    read_by_scanner = Counter()
    orig = scan.scan_moves

    def spy(*args):  # type: ignore[no-untyped-def]
        orig(*args)
        read_by_scanner.update(PE=int(args[1][scan.I_NPE]))

    with mock.patch.object(scan, "scan_moves", spy), \
            mock.patch.object(reader, "_POLY_POINTS", 4 if small else reader._POLY_POINTS):
        a = _read(data, True, 8 if small else 1 << 16)
    b = _read(data, False)
    assert_same(a, b)
    assert read_by_scanner["PE"] >= 10  # (the rest: problems, handed back, no SP yet)


def test_pe_polygons_are_read_by_the_scanner_in_one_call() -> None:
    """grashopp.pcl's polygons (``PE=<x,y;PM0PE<pairs>;PM2FP`` with RF/FT between, HP-GL/2
    reference, PE p. 20-... and PM): one compiled call reads them all; each is a closed ring
    starting at the absolute pen-up point (relative pairs after it, pen down)."""
    from galvo_core.hpgl.pe import encode_number as enc

    polys = []
    for k in range(50):
        x0, y0 = 10 * k, -3 * k
        d = [(5, 0), (0, 5), (-2, -1)]
        body = b"".join(enc(dx) + enc(dy) for dx, dy in d)
        rf = b"RF1,2,2,0,1,1,0;FT11,1" if k % 7 == 0 else b""
        polys.append(b"PE=<%s%s;PM0PE%s;PM2%sFP" % (enc(x0), enc(y0), body, rf))
    data = b"\x1bE\x1b%0BIN;SP1;PU0,0;" + b"".join(polys) + b"\x1b%0A"
    calls = []
    run = reader._Reader._compiled_run
    with mock.patch.object(reader._Reader, "_compiled_run",
                           lambda self, i: calls.append(i) or run(self, i)):
        a = _read(data, True)
    assert_same(a, _read(data, False))
    assert [c for c in calls if c >= data.index(b"PU0,0")] == [data.index(b"PU0,0")]
    assert a.commands["PE"] == 100 and a.commands["FP"] == 50 and len(a.paths) == 50
    for k, p in enumerate(a.paths):
        x0, y0 = 10 * k, -3 * k
        np.testing.assert_array_equal(p.points, [(x0, y0), (x0 + 5, y0), (x0 + 5, y0 + 5),
                                                 (x0 + 3, y0 + 4), (x0, y0)])
        assert p.closed
