"""The HP-GL / HP-GL/2 reader: bytes in, :class:`~galvo_core.drawing.Drawing` out.

What it reads
-------------
* Pen moves: PA PR PU PD (with and without coordinates; ``PD;`` then ``PU`` is a dot),
  PE (polyline encoded, see :mod:`.pe`).
* Rectangles EA ER RA RR and wedges EW WG as closed rings; arcs and circles AA AR CI AT RT
  flattened by the HP-GL chord rule (:mod:`.arcs`), CT chord-tolerance mode honoured;
  Béziers BZ BR (and BA, the name paper 001 uses for BZ) flattened within 0.1 unit; XT/YT
  tick marks.
* Polygon mode: PM0/PM1/PM2 fill a polygon buffer, each edge with its pen state; PM1/PM2
  close a sub-polygon with the pen state of the moment, the point after PM1 starts the next
  one with a pen-up move. EP gives the runs of pen-down edges (an open polyline stays open),
  FP each sub-polygon as a closed ring; a buffer edged *and* filled is one region (FP after
  EP replaces EP's edges). A pen-up move inside PM0 also ends a sub-polygon (its ring is
  its own region), where the reference would join the pieces by pen-up edges into one
  ring; files use it for separate pieces.
* Geometry state: IN DF IP IR SC (types 0, 1, 2) RO IW PS SP; user units are converted to
  plotter units, RO rotates about the plotter origin (x, y) -> (-y, x) for 90 degrees,
  IW clips pen-down lines to the window (one warning says how many paths were clipped).
  IR with two numbers moves P1 and keeps the P1-P2 distance (P2 moves along).
* Recorded, not drawn: LT VS FS PW LA PT FT and the like; labels LB/BL/WD (skipped to their
  terminator, DT honoured; LB moves the pen over the text: SI/SR/default cell, CR/LF/BS,
  DI/DR; after a centred or right-justified label, LO4-9 and LO14-19, the pen stays where
  it was, as the reference restores it; DV, the text path, is taken as DV0), CO comments,
  SM symbols, vendor ``!XX`` commands.
* Wrappers: PCL (ESC E, ESC%#A / ESC%#B, parameterised escapes with binary data: ESC...#W
  and ESC&p#X; ESC*p#X is cursor positioning, no data), PJL
  (``@PJL ENTER LANGUAGE=HPGL2``), UEL, HP 7475A device control ESC.( ESC.I…: (also with
  the ESC byte lost), NUL padding.

Syntax decisions (where the standard is ambiguous or files break it)
--------------------------------------------------------------------
* A command is two letters (any case); its parameters end at ``;``, at the next letter or at
  ESC. Numbers are separated by commas, white space, or a sign; a trailing comma is fine.
  Anything else among the parameters (``PD:``) is skipped with a warning.
* Numbers are clamped to +-1e15 (MAX_NUMBER); a path that still ends up with a non-finite
  coordinate is dropped with a warning. AA/AR sweeps beyond +-360 degrees draw a circle.
* Relative moves add up pair by pair, left to right (``x = x + dx``): the vectorised fast
  path and the command-by-command path give bit-identical points, so a relative figure that
  returns to its start is ``closed`` on both.
* A command with an odd coordinate count drops the last number with a warning.
* A label without its terminator ends at the end of its line (warning), so that one broken
  label does not swallow the rest of the file.
* An unquoted CO comment ends at ``;``, at the label terminator or at the end of the line.
* Default P1/P2 (for SC without IP, and IR) are those of an HP 7475A on ANSI A paper:
  (250, 596) and (10250, 7796); after PS w,h they are (0, 0) and (w, h).
* IN lifts the pen. SP ends the current path; it keeps the pen down in HP-GL/2 ("the pen
  remains down ... until a PU or IN") and lifts it in HP-GL/1 (a plotter stores the pen):
  a file is HP-GL/2 once it shows it (PCL/PJL entry, BP PS PE PW BZ ... see HPGL2_ONLY).
  Without any SP the paths are drawn with pen 1 and one warning says so. RO and IW end the
  current path (the pen stays down, the next pen-down move starts a new path); IP and SC
  only change later coordinates. PS with a length <= 0 is ignored.
* IW without numbers is the hard-clip window: the page PS gave, (0, 0)-(w, h), when RO is
  0; without PS (a galvo has no paper) or under RO there is no window.
* PE: a pair without ``<`` puts the pen down; a PE that ends with a pen-up move leaves the
  pen up and draws no dot there.
* SM takes the next character as its symbol (``SMY;``), not as a command letter.
* Pages (PG) are overlaid: a galvo has one field; a warning says how many pages there were.
* Warnings about the whole file (labels not drawn, pages, line types...) have line 0,
  column 0; every other warning points at its line and column (both from 1).
* A path is ``closed`` when its last point equals its first and it has at least 4 points.

Errors
------
A file that is not HP-GL (empty, binary, SVG, DXF, Summa DM/PL, G-code, a PCL job without
HP-GL/2 -- escapes alone do not count as HP-GL --, mostly unreadable) raises
:class:`~galvo_core.errors.InputError`. A malformed or unknown command inside a good file is
skipped with a warning naming line and column. Time and memory are linear in the file size
(also for ``PEPEPE...``: see :mod:`.pe`).

Speed
-----
Large inputs (from ``_COMPILED_MIN_BYTES``), or any input once numba is loaded, are read by
the compiled scanner (:mod:`.scan`) wherever a PU/PD/PA/PR/SP/PW command starts, and PE by
its compiled decoder. Once running, the scanner reads FT and polygon mode too (PM0/PM1/PM2
into its own polygon buffer, EP's and FP's paths written as its segments); it hands the
buffer back to the general reader (``_poly_from_scanner``) at anything else (PE, CI, LB...
inside PM; IW or RO in force; FP after an EP it did not write). The general reader takes
every other command. Smaller inputs in a fresh process use the numpy runs of
:mod:`.fastrun` (outside polygon mode). All three read the same geometry bit for bit
(tests/test_hpgl_scan.py, tests/test_hpgl_fuzz.py).
"""

from __future__ import annotations

import gc
import math
import os
import re
import sys
from collections import Counter
from collections.abc import Callable
from typing import Any

import numpy as np

from galvo_core.drawing import Drawing, Path, Warning, paths_from_store, sha256_hex
from galvo_core.errors import InputError
from galvo_core.hpgl.arcs import arc_points, bezier_points, chord_angle, circle_through
from galvo_core.hpgl.fastrun import (
    CODE_A,
    CODE_D,
    CODE_R,
    CODE_U,
    ffill_state,
    segmented_cumsum,
    tokenize_run,
)
from galvo_core.hpgl.pe import PECache, decode_pe
from galvo_core.hpgl.sniff import refusal_reason

#: largest file the reader accepts (bytes); larger files are refused, not half-read.
MAX_FILE_BYTES = 512 * 1024 * 1024

DEFAULT_P1 = (250.0, 596.0)
DEFAULT_P2 = (10250.0, 7796.0)
BEZIER_TOL = 0.1  # plotter units
ETX = 0x03

KNOWN = frozenset(
    (
        "AA AC AD AF AH AP AR AS AT BA BF BL BP BR BZ CA CC CF CI CM CO CP CR CS CT CV DC DF"
        " DI DL DP DR DS DT DV EA EC EP ER ES EW FI FN FP FR FS FT GC GM GP IM IN IP IR IV IW"
        " KY LA LB LM LO LT MC MG MT NP NR OA OC OD OE OF OG OH OI OL OO OP OS OT OW PA PB PC"
        " PD PE PG PM PP PR PS PT PU PW QL RA RF RO RP RR RT SA SB SC SD SG SI SL SM SP SR SS"
        " ST SV TD TL TR UC UF UL VS WD WG WU XT YT"
    ).split()
)

#: commands that only HP-GL/2 (and PCL's HP-GL/2) has: a file using one is read as HP-GL/2
HPGL2_ONLY = frozenset("BP BR BZ CR FR LA MC MG NP PC PE PP PS PW QL RF SV TR WU".split())

# one ordinary command with its leading separators: mnemonic, parameters, optional ';'
_CMD_RE = re.compile(rb"[\x00-\x1a\x1c-\x20;,]*([A-Za-z]{2})([^A-Za-z;\x1b]*)(;?)")
# possessive (Python 3.11): the same runs, but re keeps no backtracking state per command
# (the plain ``(...)+`` held about 25 bytes per byte of a run while matching it)
_RUN_RE = re.compile(
    rb"(?:[\x00-\x1a\x1c-\x20;,]*+[Pp][UuDdAaRr][-+0-9.,;\x00-\x1a\x1c-\x20]*+)++"
)
_FAST_MIN_BYTES = 256  # shorter runs go command by command
_FAST_PIECE_BYTES = 1 << 13  # longer runs are read in pieces of at most this size
#: inputs from this size on are read with the compiled scanner (:mod:`.scan`, numba); smaller
#: ones with the numpy runs of :mod:`.fastrun` -- unless numba is loaded already (the GUI,
#: ``process``), so that ``galvo-core info small.plt`` does not pay numba's import
_COMPILED_MIN_BYTES = 1 << 20
_CHUNK_POINTS = 1 << 16  # points per output chunk of the compiled scanner
_POLY_POINTS = 1 << 10  # points of the compiled scanner's first polygon buffer
_BLOCK_POINTS = 1 << 12  # the general reader's paths are gathered into blocks of about
_BLOCK_PATHS = 1 << 9  # this many points or paths
_PE_MESSAGES = {  # scan.PE_* problem codes -> the messages of pe.decode_pe
    1: "PE number out of range; clamped",
    2: "PE fractional bits {} out of range 0..26",
    3: "PE run ends with half a coordinate pair; it was dropped",
    4: "PE run ends with a flag that has no number",
}
#: LO positions (PCL5-II 23-62); those after which a label leaves the pen where the next
#: label goes on, for text path DV0 (PCL5-II 23-65, Table 23-35): after the others LB
#: restores the pen position it found
_LABEL_ORIGINS = frozenset((*range(1, 10), *range(11, 20), 21))
_LO_CONCATENATE = frozenset((1, 2, 3, 11, 12, 13, 21))
#: where the compiled scanner is started (it reads PM, EP, FP and FT too once it runs)
_SCAN_CMDS = frozenset((b"PU", b"PD", b"PA", b"PR", b"SP", b"PW", b"PE"))


def _is_letter_or_esc(c: int) -> bool:
    return 65 <= c <= 90 or 97 <= c <= 122 or c == 0x1B


def _use_compiled(size: int) -> bool:
    return size >= _COMPILED_MIN_BYTES or "numba" in sys.modules


class _Chunk:
    """Output of the compiled scanner: points and the segments (paths) found in them."""

    __slots__ = ("pts", "seg_start", "seg_off", "seg_pen", "seg_line", "seg_col", "npts",
                 "nseg")

    def __init__(self, cap: int) -> None:
        self.pts = np.empty((cap, 2), dtype=np.float64)
        self.seg_start = np.empty(cap // 2 + 4, dtype=np.int32)
        self.seg_off = np.empty(cap // 2 + 4, dtype=np.int32)
        self.seg_pen = np.empty(cap // 2 + 4, dtype=np.int32)
        self.seg_line = np.empty(cap // 2 + 4, dtype=np.int32)
        self.seg_col = np.empty(cap // 2 + 4, dtype=np.int32)
        self.npts = 0
        self.nseg = 0


class _Batch:
    """Paths the compiled scanner read: ``pts[starts[k]:ends[k]]`` drawn with ``pens[k]``,
    starting at line ``lines[k]``, column ``cols[k]`` of the file."""

    __slots__ = ("chunk", "starts", "ends", "lines", "cols", "pens")

    def __init__(self, chunk: _Chunk, starts: np.ndarray, ends: np.ndarray, lines: np.ndarray,
                 cols: np.ndarray, pens: np.ndarray) -> None:
        self.chunk = chunk
        self.starts = starts
        self.ends = ends
        self.lines = lines
        self.cols = cols
        self.pens = pens
class _Block:
    """General-reader paths gathered: ``pts[starts[k]:ends[k]]`` (read-only), drawn with
    ``pens[k]``, ``closed[k]``, begun at line ``lines[k]``, column ``cols[k]``."""

    __slots__ = ("pts", "starts", "ends", "pens", "closed", "lines", "cols")

    def __init__(self, part: list[tuple[np.ndarray, int, bool, int]],
                 where: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]) -> None:
        pieces = [np.asarray(it[0], dtype=np.float64).reshape(-1, 2) for it in part]
        lens = np.fromiter(map(len, pieces), dtype=np.int64, count=len(pieces))
        self.ends = np.cumsum(lens).astype(np.int32)
        self.starts = self.ends - lens.astype(np.int32)
        self.pts = np.concatenate(pieces) if len(pieces) > 1 else pieces[0].copy()
        self.pts.setflags(write=False)
        del pieces
        self.pens = np.fromiter((it[1] for it in part), dtype=np.int64, count=len(part))
        self.closed = np.fromiter((it[2] for it in part), dtype=np.bool_, count=len(part))
        self.lines, self.cols = where(
            np.fromiter((it[3] for it in part), dtype=np.int64, count=len(part)))


_SEP_RE = re.compile(rb"[\x00-\x1a\x1c-\x20;,]*")
_NUM_RE = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)")
_JUNK_PARAM_RE = re.compile(rb"[^\s,0-9.+\-\x00]+")
_DEVCTL_RE = re.compile(rb"\x1b?\.(?:[()YZBEJKLORU]|[@HIMNPQST][0-9;.\s]{0,80}:?)")
_PCL_ESC_RE = re.compile(
    rb"\x1b(?:%-12345X"
    rb"|([!-/])([`-~]?)((?:[+-]?\d*(?:\.\d*)?[`-~]){0,64})([+-]?\d*(?:\.\d*)?)([@-^])"
    rb"|([0-~]))"
)
_PCL_SCAN_RE = re.compile(
    rb"\x1b|@PJL[ \t]+ENTER[ \t]+LANGUAGE[ \t]*=[ \t]*\"?([A-Za-z0-9\-/]+)[^\n]*\n?", re.I
)
_VENDOR_RE = re.compile(rb"!([A-Za-z]{2})([^;\x1b\n]*);?")
_PCL_START_RE = re.compile(rb"[\x00-\x20]*(?:\x1bE|\x1b%-12345X|@PJL|\x1b[&*(]|\x1b%-?\d*A)")

_POW10 = 10.0 ** np.arange(0, 23)
_EMPTY_I32 = np.empty(0, dtype=np.int32)
_WARN_CAP = 20  # warnings of one kind kept verbatim; the rest are counted


#: numbers are clamped to +-MAX_NUMBER (HP-GL's own ranges are far smaller); the fast path
#: reads at most 15 digits, so it never sees a larger number and both paths agree
MAX_NUMBER = 1e15


def _nums(params: bytes) -> list[float]:
    out = [float(t) for t in _NUM_RE.findall(params)]
    if any(abs(v) > MAX_NUMBER for v in out):
        out = [min(max(v, -MAX_NUMBER), MAX_NUMBER) for v in out]
    return out


class _Reader:
    """One pass over the bytes of one file. Not reusable."""

    def __init__(self, data: bytes, name: str) -> None:
        self.data = data
        self.name = name
        self.n = len(data)
        # outputs
        # the paths in file order: a _Batch (the scanner's) or None (the next general path)
        self.paths: list[_Batch | None] = []
        # the general reader's paths: (points, pen, closed, offset) not yet gathered into a
        # _Block (the first is general path number gen_base), and the blocks before them
        self.gen: list[tuple[np.ndarray, int, bool, int]] = []
        self.gen_base = 0
        self.gen_points = 0
        self.blocks: list[_Block] = []
        self.commands: Counter[str] = Counter()
        self._warn: list[tuple[int, str]] = []
        self._warn_count: Counter[str] = Counter()
        self.recognised = 0  # HP-GL commands read (escapes and PCL do not count)
        self.clipped = 0  # paths changed by the IW window
        self.first_clip = -1
        self.junk_bytes = 0
        self.pages = 0
        self.labels = 0
        self.line_types = 0
        self.text_symbols = 0
        # lexer state
        self.term = ETX
        self._no_term_after: dict[int, int] = {}
        self._pe_cache = PECache()
        self.compiled = _use_compiled(self.n)
        self._chunk: _Chunk | None = None
        self._scan: Any = None  # the compiled scanner's module, imported at its first use
        self._lc = (0, 1, -1)  # scanner position: offset, its line, the newline before it
        self._blc = (0, 1, -1)  # the same for lines_cols
        self.chunks: list[_Chunk] = []
        self._next_cap = _CHUNK_POINTS // 16
        self.batched = 0  # paths in _Batch items of self.paths
        self.hpgl_mode = True
        # dialect: HP-GL/2 once the file shows it (PCL/PJL entry, an HP-GL/2-only command)
        self.hpgl2 = False
        self.pen_selected = False  # no SP yet: drawn with pen 1 (warned)
        self.unselected_paths = 0
        # geometry state
        self.reset()
        self.pen = 1

    # ------------------------------------------------------------------ warnings
    def warn(self, offset: int, message: str, key: str | None = None) -> None:
        k = key or message
        self._warn_count[k] += 1
        if self._warn_count[k] <= _WARN_CAP:
            self._warn.append((offset, message))

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """IN: everything to power-on defaults (pen number is kept)."""
        self.flush()
        self.x = 0.0
        self.y = 0.0
        self.pen_down = False
        self.absolute = True
        self.p1 = DEFAULT_P1
        self.p2 = DEFAULT_P2
        self.hard = (DEFAULT_P1, DEFAULT_P2)
        self.page_known = False  # PS gave the page (hard-clip limits)
        self.sc: tuple[float, float, float, float] | None = None  # ax, bx, ay, by
        self.sc_params: list[float] | None = None
        self.rot = 0
        self.window: tuple[float, float, float, float] | None = None
        self.ct_tol = False
        self.term = ETX
        self.poly: list[list[tuple[float, float]]] | None = None  # rings while in PM
        # the sub-polygon being drawn (its edges are pen-down: a pen-up move ends it)
        self.poly_ring: list[tuple[float, float]] = []
        # sub-polygons: points and the pen state of the closing edge (back to the first
        # point); every other edge is pen-down
        self.poly_buffer: list[tuple[list[tuple[float, float]], bool]] = []
        self.poly_emitted = True
        # EP's paths: self.paths range and general path numbers (FP may replace them)
        self.poly_edged: tuple[int, int, int, int] | None = None
        self.poly_fresh = False
        self.poly_offset = 0
        self.poly_lc: tuple[int, int, int] | None = None  # offset, line, column of PM0
        # an edged polygon whose points are still only in the scanner's buffer (points,
        # rings): read back when an FP needs them (see _poly_from_scanner)
        self.poly_lazy: tuple[int, int] | None = None
        self.tick = (0.5, 0.5)
        self.char_size: tuple[float, float] | None = None  # SI: width, height (plotter units)
        self.char_rel: tuple[float, float] | None = None  # SR: % of P2-P1
        self.label_dir = (1.0, 0.0)  # DI/DR: unit vector of the text direction
        self.label_origin = 1  # LO
        self.cur: list[float] = []  # current pen-down path, flat x, y (plotter units)
        self.cur_parts: list[np.ndarray] = []  # its earlier points, read by the scanner
        self.cur_offset = 0

    def defaults(self) -> None:
        """DF: defaults that do not touch P1/P2 or rotation."""
        self.flush()
        self.absolute = True
        self.sc = None
        self.sc_params = None
        self.window = None
        self.ct_tol = False
        self.term = ETX
        self.poly = None
        self.tick = (0.5, 0.5)
        self.char_size = None
        self.char_rel = None
        self.label_dir = (1.0, 0.0)
        self.label_origin = 1

    # ------------------------------------------------------------------ units
    def to_plotter(self, x: float, y: float) -> tuple[float, float]:
        sc = self.sc
        if sc is None:
            return x, y
        return sc[0] * x + sc[1], sc[2] * y + sc[3]

    def delta_to_plotter(self, dx: float, dy: float) -> tuple[float, float]:
        sc = self.sc
        if sc is None:
            return dx, dy
        return sc[0] * dx, sc[2] * dy

    def to_user(self, x: float, y: float) -> tuple[float, float]:
        sc = self.sc
        if sc is None:
            return x, y
        return (x - sc[1]) / sc[0], (y - sc[3]) / sc[2]

    def update_scaling(self, offset: int) -> None:
        p = self.sc_params
        if p is None:
            self.sc = None
            return
        (p1x, p1y), (p2x, p2y) = self.p1, self.p2
        kind = int(p[4]) if len(p) >= 5 else 0
        try:
            if kind == 2:
                xmin, xf, ymin, yf = p[:4]
                if xf == 0 or yf == 0:
                    raise ZeroDivisionError
                self.sc = (xf, p1x - xmin * xf, yf, p1y - ymin * yf)
                return
            xmin, xmax, ymin, ymax = p[:4]
            ax = (p2x - p1x) / (xmax - xmin)
            ay = (p2y - p1y) / (ymax - ymin)
            if ax == 0 or ay == 0:
                raise ZeroDivisionError
            if kind == 1:
                s = min(abs(ax), abs(ay))
                left = p[5] if len(p) >= 6 else 50.0
                bottom = p[6] if len(p) >= 7 else 50.0
                sx = math.copysign(s, ax)
                sy = math.copysign(s, ay)
                spare_x = (p2x - p1x) - sx * (xmax - xmin)
                spare_y = (p2y - p1y) - sy * (ymax - ymin)
                self.sc = (
                    sx,
                    p1x - xmin * sx + spare_x * left / 100.0,
                    sy,
                    p1y - ymin * sy + spare_y * bottom / 100.0,
                )
            else:
                self.sc = (ax, p1x - xmin * ax, ay, p1y - ymin * ay)
        except ZeroDivisionError:
            self.warn(offset, "SC with an empty range (or P1 = P2) ignored: scaling off")
            self.sc = None
            self.sc_params = None

    # ------------------------------------------------------------------ output
    def _orient(self, pts: np.ndarray) -> np.ndarray:
        r = self.rot
        if r == 0:
            return pts
        x = pts[:, 0].copy()
        y = pts[:, 1].copy()
        if r == 90:
            return np.column_stack((-y, x)) + 0.0  # + 0.0: no -0.0 coordinates
        if r == 180:
            return np.column_stack((-x, -y)) + 0.0
        return np.column_stack((y, -x)) + 0.0

    def emit(self, pts: np.ndarray, offset: int, *, closed: bool | None = None) -> None:
        """Add a finished path (plotter units, before rotation and clipping)."""
        if not np.isfinite(pts).all():
            self.warn(offset, "path with coordinates out of range dropped", key="non-finite")
            return
        if self.window is not None:
            if self._scan is not None and len(pts) > 1:
                # (numba loaded: the compiled clipping, the same pieces)
                cp, cs, cn = self._scan.clip_polyline(pts, *self.window)
                cs = cs.tolist()
                pieces = [cp[cs[k] : cs[k + 1]] for k in range(cn)]
            else:
                pieces = _clip_polyline(pts, self.window)
            if len(pieces) != 1 or len(pieces[0]) != len(pts) or not np.array_equal(pieces[0], pts):
                self.clipped += 1
                if self.first_clip < 0:
                    self.first_clip = offset
                closed = False
            if not pieces:
                return
        else:
            pieces = [pts]
        for piece in pieces:
            piece = self._orient(piece)
            is_closed = (
                closed
                if closed is not None
                else len(piece) >= 4 and piece[0, 0] == piece[-1, 0] and piece[0, 1] == piece[-1, 1]
            )
            self.paths.append(None)
            self.gen.append((piece, self.pen, bool(is_closed), offset))
            self.gen_points += len(piece)
            if self.gen_points >= _BLOCK_POINTS or len(self.gen) >= _BLOCK_PATHS:
                self.gather()
            if not self.pen_selected:
                self.unselected_paths += 1

    def flush(self) -> None:
        cur = getattr(self, "cur", None)
        parts = getattr(self, "cur_parts", None)
        if parts:
            if cur:
                parts.append(np.array(cur, dtype=np.float64).reshape(-1, 2))
            pts = parts[0].copy() if len(parts) == 1 else np.concatenate(parts)
            self.cur = []
            self.cur_parts = []
            self.emit(pts, self.cur_offset)
        elif cur:
            self.emit(np.array(cur, dtype=np.float64).reshape(-1, 2), self.cur_offset)
            self.cur = []

    def gather(self, final: bool = False) -> None:
        """Move the general paths read so far into a _Block (one shared points array), but
        not EP's paths that a later FP may replace."""
        limit = len(self.gen)
        if self.poly_edged is not None and not final:
            limit = min(limit, self.poly_edged[2] - self.gen_base)
        if limit <= 0:
            return
        part = self.gen[:limit]
        del self.gen[:limit]
        self.gen_base += limit
        self.gen_points = sum(len(g[0]) for g in self.gen)
        self.blocks.append(_Block(part, self.lines_cols))

    def lines_cols(self, offs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """1-based line and column (int32) of the byte offsets ``offs`` (>= 0), counted from
        the last call's place (the paths of a block are near each other in the file): no
        pass over the whole file, no temporary larger than the stretch they span."""
        data = self.data
        lo = int(offs.min())
        hi = int(offs.max())
        pos, line, last_nl = self._blc  # line at pos, the last newline before pos
        if lo >= pos:
            cnt = data.count(b"\n", pos, lo)
            if cnt:
                line += cnt
                last_nl = data.rfind(b"\n", pos, lo)
        else:
            line -= data.count(b"\n", lo, pos)
            if last_nl >= lo:
                last_nl = data.rfind(b"\n", 0, lo)
        self._blc = (lo, line, last_nl)
        nl = np.flatnonzero(np.frombuffer(data, dtype=np.uint8, count=hi - lo, offset=lo) == 10)
        idx = np.searchsorted(nl, offs - lo, side="left")  # newlines in [lo, offset)
        prev = np.where(idx > 0, nl[np.maximum(idx - 1, 0)] + lo, last_nl) if len(nl) else \
            np.full(len(offs), last_nl, dtype=np.int64)
        return (idx + line).astype(np.int32), (offs - prev).astype(np.int32)

    def emit_ring(self, ring_pts: np.ndarray, offset: int) -> None:
        """A closed figure (rectangle, circle, wedge): into the polygon buffer in PM."""
        if len(ring_pts) and not _near(ring_pts[0], ring_pts[-1]):
            ring_pts = np.vstack((ring_pts, ring_pts[:1]))
        elif len(ring_pts):
            ring_pts = ring_pts.copy()
            ring_pts[-1] = ring_pts[0]
        if self.poly is not None:
            self._poly_close_ring(self.pen_down)
            ring = [tuple(p) for p in ring_pts.tolist()]
            self.poly_buffer.append((ring, True))
            self.poly_ring = [(self.x, self.y)]
            return
        self.emit(ring_pts, offset, closed=len(ring_pts) >= 4)

    # ------------------------------------------------------------------ moves
    def pen_to(self, x: float, y: float, offset: int) -> None:
        """Move to plotter point (x, y) with the current pen state."""
        if self.poly is not None:
            self._poly_move(x, y)
        elif self.pen_down:
            if not self.cur and not self.cur_parts:
                self.cur = [self.x, self.y]
                self.cur_offset = offset
            self.cur.append(x)
            self.cur.append(y)
        self.x, self.y = x, y

    def draw_polyline(self, pts: np.ndarray, offset: int) -> None:
        """Pen-down (or pen-up) through an (N, 2) array of plotter points."""
        if len(pts) == 0:
            return
        if self.poly is not None:
            if self.pen_down and not self.poly_fresh:
                # pen-down moves only append (what _poly_move does point by point)
                self.poly_ring.extend(zip(pts[:, 0].tolist(), pts[:, 1].tolist(), strict=True))
            else:
                for px, py in pts.tolist():
                    self._poly_move(px, py)
        elif self.pen_down:
            if not self.cur and not self.cur_parts:
                self.cur = [self.x, self.y]
                self.cur_offset = offset
            self.cur.extend(pts.ravel().tolist())
        self.x, self.y = float(pts[-1, 0]), float(pts[-1, 1])

    def points_from_params(self, v: list[float], offset: int, mn: str) -> np.ndarray | None:
        if len(v) % 2:
            self.warn(offset, f"{mn} has an odd number of coordinates; the last was ignored",
                      key=f"odd-{mn}")
            v = v[:-1]
        if not v:
            return None
        arr = np.array(v, dtype=np.float64).reshape(-1, 2)
        if self.absolute:
            if self.sc is not None:
                sc = self.sc
                arr[:, 0] = sc[0] * arr[:, 0] + sc[1]
                arr[:, 1] = sc[2] * arr[:, 1] + sc[3]
        else:
            if self.sc is not None:
                arr[:, 0] *= self.sc[0]
                arr[:, 1] *= self.sc[2]
            # x = x + dx pair by pair (the same rounding as one-pair commands)
            arr = np.cumsum(np.vstack(([(self.x, self.y)], arr)), axis=0)[1:]
        return arr

    def move_params(self, params: bytes, offset: int, mn: str) -> None:
        v = _nums(params)
        if len(v) == 2:  # the common one-point command, no numpy
            x, y = v
            if self.absolute:
                if self.sc is not None:
                    x, y = self.to_plotter(x, y)
            else:
                dx, dy = self.delta_to_plotter(x, y)
                x, y = self.x + dx, self.y + dy
            self.pen_to(x, y, offset)
            return
        pts = self.points_from_params(v, offset, mn)
        if pts is not None:
            if self.pen_down or self.poly is not None:
                self.draw_polyline(pts, offset)
            else:
                self.x, self.y = float(pts[-1, 0]), float(pts[-1, 1])

    def set_pen_down(self, down: bool, offset: int) -> None:
        if down and not self.pen_down:
            self.pen_down = True
            if self.poly is None:
                self.flush()
                self.cur = [self.x, self.y]
                self.cur_offset = offset
        elif not down and self.pen_down:
            self.pen_down = False
            if self.poly is None:
                self.flush()

    # ------------------------------------------------------------------ polygon mode
    def _poly_move(self, x: float, y: float) -> None:
        if self.poly_fresh:
            # the first move after PM1 starts the next sub-polygon: it is a pen-up move
            # whatever the pen state (HP-GL/2 PM; hp2xx and ezhpgl read it so too)
            self.poly_fresh = False
            self.poly_ring = [(x, y)]
            return
        if self.pen_down:
            self.poly_ring.append((x, y))
        else:
            # a pen-up move ends the sub-polygon (its closing edge is a pen-up edge); the
            # fill region of each piece is its own ring, not one ring joined by pen-up edges
            if len(self.poly_ring) > 1:
                self._poly_close_ring(False)
            self.poly_ring = [(x, y)]

    def _poly_close_ring(self, down: bool) -> None:
        """End the current sub-polygon; its closing edge has pen state ``down`` (PM1/PM2
        close with the current pen state: a pen-up closure is part of the fill region's
        boundary but EP does not draw it)."""
        ring = self.poly_ring
        if len(ring) > 1:
            self.poly_buffer.append((ring, down))
        self.poly_ring = [(self.x, self.y)]

    def do_pm(self, v: list[float], offset: int) -> None:
        mode = int(v[0]) if v else 0
        if mode == 0:
            self.flush()
            if self.poly is not None:
                self.warn(offset, "PM0 inside polygon mode: the earlier polygon was discarded")
            self.poly = []
            self.poly_buffer = []
            self.poly_ring = [(self.x, self.y)]
            self.poly_fresh = False
            self.poly_emitted = False
            self.poly_edged = None
            self.poly_offset = offset
            self.poly_lc = None
            self.poly_lazy = None
        elif mode == 1:
            if self.poly is None:
                self.warn(offset, "PM1 outside polygon mode ignored")
                return
            self._poly_close_ring(self.pen_down)
            self.poly_fresh = True
        elif mode == 2:
            if self.poly is None:
                self.warn(offset, "PM2 outside polygon mode ignored")
                return
            self._poly_close_ring(self.pen_down)
            self.poly = None
        else:
            self.warn(offset, f"PM{mode}: unknown polygon mode ignored")

    def do_edge_fill(self, mn: str, offset: int) -> None:
        """EP draws the pen-down edges of the polygon buffer; FP fills it: every sub-polygon
        is one closed ring (its region). A buffer is geometry, not paint: edged and filled
        it is one region (FP after EP replaces EP's edges by the rings, EP after FP adds
        nothing: its edges lie on the rings)."""
        if self.poly is not None:
            self.warn(offset, f"{mn} inside polygon mode ignored")
            return
        if mn == "EP":
            if self.poly_emitted:
                return
            self.poly_emitted = True
            first = len(self.paths)
            gfirst = self.gen_base + len(self.gen)
            self.poly_edged = (first, first, gfirst, gfirst)  # (not gathered from gfirst)
            for ring, closing in self.poly_buffer:
                if len(ring) >= 2:  # its pen-down edges: all but maybe the closing one
                    run = [*ring, ring[0]] if closing and ring[0] != ring[-1] else ring
                    self.emit(np.array(run, dtype=np.float64), self.poly_offset)
            self.poly_edged = (first, len(self.paths), gfirst, self.gen_base + len(self.gen))
            return
        if self.poly_emitted and self.poly_edged is None:
            return  # filled already
        if self.poly_lazy is not None:
            self._poly_buffer_from_scanner(*self.poly_lazy)
        rings = []
        for ring, _closing in self.poly_buffer:
            closed_ring = ring if ring[0] == ring[-1] else ring + [ring[0]]
            rings.append(np.array(closed_ring, dtype=np.float64))
        if self.poly_edged is not None:
            a, b, ga, gb = self.poly_edged
            self.poly_edged = None
            tail = self.paths[b:]
            # EP's paths, the compiled scanner's batches among them, are replaced
            self.batched -= sum(len(p.starts) for p in self.paths[a:b] if p is not None)
            del self.paths[a:]
            gtail = self.gen[gb - self.gen_base :]
            del self.gen[ga - self.gen_base :]
            self.gen_points = sum(len(g[0]) for g in self.gen)
            for arr in rings:
                self.emit(arr, self.poly_offset, closed=len(arr) >= 4)
            self.paths.extend(tail)
            self.gen.extend(gtail)
            self.gen_points += sum(len(g[0]) for g in gtail)
        else:
            for arr in rings:
                self.emit(arr, self.poly_offset, closed=len(arr) >= 4)
        self.poly_emitted = True
        self.poly_edged = None

    # ------------------------------------------------------------------ commands
    def do_arc(self, cx: float, cy: float, sweep: float, chord_arg: float | None,
               offset: int) -> None:
        """Arc around user-unit centre (cx, cy) starting at the current position."""
        ux, uy = self.to_user(self.x, self.y)
        r = math.hypot(ux - cx, uy - cy)
        if r == 0 or sweep == 0 or not math.isfinite(r):
            return
        sweep = max(-360.0, min(360.0, sweep))  # more than a full turn draws a circle
        start = math.degrees(math.atan2(uy - cy, ux - cx))
        ca = chord_angle(chord_arg, r, tolerance_mode=self.ct_tol)
        pts = arc_points(cx, cy, r, start, sweep, ca)[1:]
        self._draw_user_pts(pts, offset)

    def _draw_user_pts(self, pts: np.ndarray, offset: int) -> None:
        if self.sc is not None:
            sc = self.sc
            pts = np.column_stack((sc[0] * pts[:, 0] + sc[1], sc[2] * pts[:, 1] + sc[3]))
        if self.pen_down or self.poly is not None:
            self.draw_polyline(pts, offset)
        else:
            self.x, self.y = float(pts[-1, 0]), float(pts[-1, 1])

    def user_ring_to_plotter(self, pts: np.ndarray) -> np.ndarray:
        if self.sc is None:
            return pts
        sc = self.sc
        return np.column_stack((sc[0] * pts[:, 0] + sc[1], sc[2] * pts[:, 1] + sc[3]))

    def do_rect(self, v: list[float], relative: bool, offset: int, mn: str) -> None:
        if len(v) < 2:
            self.warn(offset, f"{mn} needs two coordinates; ignored", key=f"args-{mn}")
            return
        ux, uy = self.to_user(self.x, self.y)
        ex, ey = (ux + v[0], uy + v[1]) if relative else (v[0], v[1])
        ring = np.array([(ux, uy), (ex, uy), (ex, ey), (ux, ey), (ux, uy)], dtype=np.float64)
        pts = self.user_ring_to_plotter(ring)
        self.flush_if_drawing()
        self.emit_ring(pts, offset)

    def flush_if_drawing(self) -> None:
        if self.poly is None and (self.cur or self.cur_parts):
            self.flush()
            if self.pen_down:
                self.cur = []

    def do_wedge(self, v: list[float], offset: int, mn: str) -> None:
        if len(v) < 3:
            self.warn(offset, f"{mn} needs radius, start and sweep; ignored", key=f"args-{mn}")
            return
        r, start, sweep = v[0], v[1], v[2]
        if r < 0:
            r, start = -r, start + 180.0
        cx, cy = self.to_user(self.x, self.y)
        ca = chord_angle(v[3] if len(v) > 3 else None, r, tolerance_mode=self.ct_tol)
        arc = arc_points(cx, cy, r, start, max(-360.0, min(360.0, sweep)), ca)
        if abs(sweep) >= 360.0 or r == 0:
            ring = arc
            ring[-1] = ring[0]
        else:
            ring = np.vstack(([(cx, cy)], arc, [(cx, cy)]))
        self.flush_if_drawing()
        self.emit_ring(self.user_ring_to_plotter(ring), offset)

    def do_circle(self, v: list[float], offset: int) -> None:
        if not v:
            self.warn(offset, "CI without a radius ignored", key="args-CI")
            return
        r = v[0]
        start = 0.0
        if r < 0:
            r, start = -r, 180.0
        if r == 0:
            return
        cx, cy = self.to_user(self.x, self.y)
        ca = chord_angle(v[1] if len(v) > 1 else None, r, tolerance_mode=self.ct_tol)
        ring = arc_points(cx, cy, r, start, 360.0, ca)
        ring[-1] = ring[0]
        self.flush_if_drawing()
        self.emit_ring(self.user_ring_to_plotter(ring), offset)

    def do_three_point(self, v: list[float], relative: bool, offset: int, mn: str) -> None:
        if len(v) < 4:
            self.warn(offset, f"{mn} needs four coordinates; ignored", key=f"args-{mn}")
            return
        ux, uy = self.to_user(self.x, self.y)
        if relative:
            mid = (ux + v[0], uy + v[1])
            end = (ux + v[2], uy + v[3])
        else:
            mid, end = (v[0], v[1]), (v[2], v[3])
        circ = circle_through((ux, uy), mid, end)
        if circ is None:
            pts = np.array([mid, end], dtype=np.float64)
            if mid == (ux, uy) or mid == end:
                pts = pts[1:]
        else:
            cx, cy, r, start, sweep = circ
            ca = chord_angle(v[4] if len(v) > 4 else None, r, tolerance_mode=self.ct_tol)
            pts = arc_points(cx, cy, r, start, sweep, ca)[1:]
            pts[-1] = end
        self._draw_user_pts(pts, offset)

    def do_bezier(self, v: list[float], relative: bool, offset: int, mn: str) -> None:
        if len(v) % 6:
            self.warn(offset, f"{mn} needs coordinates in groups of six; the rest was ignored",
                      key=f"args-{mn}")
            v = v[: len(v) - len(v) % 6]
        for k in range(0, len(v), 6):
            ux, uy = self.to_user(self.x, self.y)
            c = np.array(v[k : k + 6], dtype=np.float64).reshape(3, 2)
            if relative:
                c += (ux, uy)
            ctrl = np.vstack(([(ux, uy)], c))
            ctrl_p = self.user_ring_to_plotter(ctrl)
            pts = bezier_points(ctrl_p, BEZIER_TOL)[1:]
            if self.pen_down or self.poly is not None:
                self.draw_polyline(pts, offset)
            else:
                self.x, self.y = float(pts[-1, 0]), float(pts[-1, 1])

    def do_tick(self, vertical: bool, offset: int) -> None:
        tp, tn = self.tick
        (p1x, p1y), (p2x, p2y) = self.p1, self.p2
        span = abs(p2y - p1y) if vertical else abs(p2x - p1x)
        up, down = span * tp / 100.0, span * tn / 100.0
        x, y = self.x, self.y
        if vertical:
            pts = np.array([(x, y - down), (x, y + up)])
        else:
            pts = np.array([(x - down, y), (x + up, y)])
        if self.poly is None:
            self.flush_if_drawing()
            self.emit(pts, offset, closed=False)

    def do_ip(self, v: list[float], offset: int) -> None:
        if not v:
            self.p1, self.p2 = self.hard
        elif len(v) >= 4:
            self.p1, self.p2 = (v[0], v[1]), (v[2], v[3])
        elif len(v) == 2:
            dx, dy = self.p2[0] - self.p1[0], self.p2[1] - self.p1[1]
            self.p1 = (v[0], v[1])
            self.p2 = (v[0] + dx, v[1] + dy)
        else:
            self.warn(offset, "IP needs 0, 2 or 4 numbers; ignored", key="args-IP")
            return
        self.update_scaling(offset)

    def do_ir(self, v: list[float], offset: int) -> None:
        (hx1, hy1), (hx2, hy2) = self.hard
        w, h = hx2 - hx1, hy2 - hy1
        if not v:
            self.p1, self.p2 = self.hard
        elif len(v) >= 2:
            dx, dy = self.p2[0] - self.p1[0], self.p2[1] - self.p1[1]
            self.p1 = (hx1 + w * v[0] / 100.0, hy1 + h * v[1] / 100.0)
            if len(v) >= 4:
                self.p2 = (hx1 + w * v[2] / 100.0, hy1 + h * v[3] / 100.0)
            else:  # P2 follows P1 (the P1-P2 distance is kept)
                self.p2 = (self.p1[0] + dx, self.p1[1] + dy)
        self.update_scaling(offset)

    def do_sc(self, v: list[float], offset: int) -> None:
        if not v:
            self.sc_params = None
            self.sc = None
            return
        if len(v) < 4:
            self.warn(offset, "SC needs at least four numbers; ignored", key="args-SC")
            return
        self.sc_params = v
        self.update_scaling(offset)

    def do_iw(self, v: list[float], offset: int) -> None:
        self.flush()
        if not v:
            # the hard-clip limits: the page PS gave (unknown without PS, and not
            # meaningful in this reader's rotate-about-the-origin frame under RO)
            if self.page_known and self.rot == 0:
                (x1, y1), (x2, y2) = self.hard
                self.window = (min(x1, x2), min(y1, y2), max(x1, x2), max(y1, y2))
            else:
                self.window = None
            return
        if len(v) < 4:
            self.warn(offset, "IW needs four numbers; ignored", key="args-IW")
            return
        x1, y1 = self.to_plotter(v[0], v[1])
        x2, y2 = self.to_plotter(v[2], v[3])
        self.window = (min(x1, x2), min(y1, y2), max(x1, x2), max(y1, y2))

    # ------------------------------------------------------------------ main loop
    def run(self) -> None:
        data = self.data
        n = self.n
        if _PCL_START_RE.match(data):
            self.hpgl_mode = False
        i = 0
        cmd_match = _CMD_RE.match
        handlers = self._handlers()
        commands = self.commands
        run_match = _RUN_RE.match
        slow_until = 0
        while i < n:
            if not self.hpgl_mode:
                i = self._pcl(i)
                continue
            m = None
            if self.compiled:
                m = cmd_match(data, i)
                if m is not None:
                    j = self._compiled_run(i) if m.group(1).upper() in _SCAN_CMDS else i
                    if j != i:
                        i = j
                        continue
            elif self.poly is None and i >= slow_until:
                rm = run_match(data, i)
                if rm is not None:
                    end = rm.end()
                    if end < n and not _is_letter_or_esc(data[end]):
                        # the run stops inside a command's parameters (``PD1:2``): that
                        # command is read by the general reader, which warns
                        k = end - 1
                        while k > i and not _is_letter_or_esc(data[k]):
                            k -= 1
                        end = k - 1
                    if end > i and end - i >= _FAST_MIN_BYTES:
                        j = self._fast_pieces(i, end)
                        if j > i:
                            i = j
                            continue
                    slow_until = rm.end()  # read this run command by command
            if m is None:
                m = cmd_match(data, i)
            if m is not None:
                mn = m.group(1).upper().decode()
                start = m.start(1)
                if mn in _SPECIAL:
                    if mn == "PE":
                        self.hpgl2 = True
                    commands[mn] += 1
                    self.recognised += 1
                    i = _SPECIAL[mn](self, start + 2)
                    continue
                commands[mn] += 1
                if mn in HPGL2_ONLY:
                    self.hpgl2 = True
                h = handlers.get(mn)
                if h is not None:
                    self.recognised += 1
                    params = m.group(2)
                    jm = _JUNK_PARAM_RE.search(params)
                    if jm is not None:
                        bad = jm.group(0)[:8]
                        self.warn(start + 2 + jm.start(),
                                  f"{mn}: unexpected {bad!r} in the parameters ignored",
                                  key=f"param-junk-{mn}")
                    h(params, start, mn)
                elif mn in KNOWN:
                    self.recognised += 1
                else:
                    self.junk_bytes += m.end() - start
                    self.warn(start, f"unknown command {mn} skipped", key=f"unknown-{mn}")
                i = m.end()
                continue
            # not an ordinary command: separators then something else
            sep = _SEP_RE.match(data, i)  # always matches (possibly empty)
            i = sep.end() if sep is not None else i
            if i >= n:
                break
            c = data[i]
            if c == 0x1B:
                i = self._escape_in_hpgl(i)
            elif c == 0x2E and (dm := _DEVCTL_RE.match(data, i)) is not None:  # '.'
                i = dm.end()
            elif c == 0x21 and (vm := _VENDOR_RE.match(data, i)) is not None:  # '!'
                name = "!" + vm.group(1).upper().decode()
                commands[name] += 1
                self.warn(i, f"vendor command {name} ignored", key=f"vendor-{name}")
                i = vm.end()
            else:
                j = i + 1
                while j < n and not (
                    (65 <= data[j] <= 90 or 97 <= data[j] <= 122) or data[j] in (0x1B, 0x3B)
                ):
                    j += 1
                self.junk_bytes += j - i
                snippet = data[i : min(j, i + 12)]
                self.warn(i, f"unreadable text {snippet!r} skipped", key="junk")
                i = j
        self.flush()
        if self.poly is not None:
            self.warn(n, "file ends in polygon mode (PM0 without PM2): polygon not drawn")
        elif not self.poly_emitted and self.poly_buffer:
            self.warn(self.poly_offset,
                      "polygon defined with PM but never edged or filled (EP/FP): not drawn")
        self.gather(final=True)

    # ------------------------------------------------------------------ compiled runs
    def _new_chunk(self, need: int, at: int = 0) -> _Chunk:
        # about one point per 16 bytes still to read (real files: 10-50 bytes per point), at
        # most _CHUNK_POINTS, and twice the last chunk: a small file, or one the scanner reads
        # little of, does not get a large chunk; more come as needed
        cap = max(need + 2, min(self._next_cap, (self.n - at) // 16 + 64))
        self._next_cap = min(2 * cap, _CHUNK_POINTS)
        ch = _Chunk(cap)
        self._chunk = ch
        self.chunks.append(ch)
        return ch

    def _scanner(self):  # type: ignore[no-untyped-def]
        """The compiled scanner module (:mod:`.scan`, imported at the first use: it loads
        numba) with this reader's byte view and state arrays made for it."""
        if self._scan is None:
            from galvo_core.hpgl import scan as scan_module

            self._scan = scan_module
            self._u8 = np.frombuffer(self.data, dtype=np.uint8)
            self._ist = np.zeros(scan_module.N_ISTATE, dtype=np.int64)
            self._fst = np.zeros(scan_module.N_FSTATE, dtype=np.float64)
            # PE's look-ahead cache (scan._pe_looks_like_number), the scanner's and
            # _pe_compiled's
            self._pe_span = np.array([-1, -1, -1, -1], dtype=np.int64)
        return self._scan

    def _line_at(self, i: int) -> tuple[int, int]:
        """(line, offset of the last newline) at ``i``, counted on from where the compiled
        scanner last stopped over the general reader's bytes since."""
        pos, line, last_nl = self._lc
        if i != pos:
            cnt = self.data.count(b"\n", pos, i)
            if cnt:
                line += cnt
                last_nl = self.data.rfind(b"\n", pos, i)
        return line, last_nl

    def _compiled_run(self, i: int) -> int:
        """Read the PU/PD/PA/PR/SP/PW/PE commands (and PM/EP/FP/FT/RF/MC) from ``i`` on with the
        compiled scanner; returns the offset where it stopped (``i`` when the next command
        is not one it reads)."""
        if not -(1 << 31) <= self.pen < 1 << 31:
            return i  # the scanner's segments hold the pen number as int32
        scan = self._scanner()
        ist, fst = self._ist, self._fst
        line, last_nl = self._line_at(i)
        # the scanner's polygon buffer holds the reader's (or one PM0 made in this run)
        buffered = self._poly_to_scanner(i, line, last_nl)
        nmove = scan.N_MOVE_STATE
        while True:
            ch = self._chunk
            if ch is None or len(ch.pts) - ch.npts < 2 or len(ch.seg_start) - ch.nseg < 3:
                ch = self._new_chunk(0, i)
            was_open = self.pen_down and bool(self.cur or self.cur_parts)
            # the move state in slot order (see scan.I_*); the polygon slots stay
            ist[:nmove] = (i, self.pen_down, self.absolute, was_open, ch.npts, ch.nseg,
                           0, 0, 0, 0, 0, 0, 0, self.pen, self.hpgl2, 0, self.pen_selected,
                           line, last_nl, 0)
            sc = self.sc
            fst[:] = (self.x, self.y, 0.0, 0.0, 0.0, 0.0, 0.0) if sc is None else \
                (self.x, self.y, sc[0], sc[1], sc[2], sc[3], 1.0)
            pb, rs, rcl = self._pbuf
            scan.scan_moves(self._u8, ist, fst, ch.pts, ch.seg_start, ch.seg_off, ch.seg_pen,
                            ch.seg_line, ch.seg_col, pb, rs, rcl, _POW10, scan.CLASS,
                            self._pe_span)
            out = ist.tolist()
            buffered = buffered or out[scan.I_NPM] > 0
            self._take_segments(ch, out)
            if out[scan.I_EDGED] == 1:
                ist[scan.I_EDGED] = 2  # EP's paths are in self.paths now (poly_edged)
            self.x, self.y = fst[0].item(), fst[1].item()
            self.pen_down = bool(out[scan.I_PEN])
            self.absolute = bool(out[scan.I_ABS])
            self.pen = out[scan.I_PENNO]
            counts = out[scan.I_NU : scan.I_NR + 1] + [out[scan.I_NSP], out[scan.I_NPW]] + \
                out[scan.I_NPM : scan.I_NFP + 1] + out[scan.I_NFT : scan.I_NMC + 1]
            self.hpgl2 = bool(out[scan.I_HPGL2])
            if any(counts):
                for name, c in zip(("PU", "PD", "PA", "PR", "SP", "PW", "PM", "EP", "FP", "FT",
                                    "PE", "RF", "MC"), counts, strict=True):
                    if c:
                        self.commands[name] += c
                self.recognised += sum(counts)
            if out[scan.I_DROP] and not self.pen_selected:
                self.unselected_paths += out[scan.I_DROP]  # as when FP replaces EP's paths
            i = out[scan.I_POS]
            self._lc = (i, out[scan.I_LINE], out[scan.I_LASTNL])
            full = out[scan.I_FULL]
            if not full:
                self._poly_from_scanner(out, buffered)
                return i
            line, last_nl = out[scan.I_LINE], out[scan.I_LASTNL]
            if full == scan.FULL_POLY:
                self._grow_poly_buffer(out[scan.I_NEED])
            else:
                self._new_chunk(out[scan.I_NEED], i)

    def _grow_poly_buffer(self, need: int) -> None:
        """The scanner's polygon buffer (points, ring starts, closing flags), made to hold
        at least ``need`` points, keeping what it holds."""
        old = getattr(self, "_pbuf", None)
        cap = max(need, 2 * len(old[0]) if old is not None else _POLY_POINTS)
        pb = np.empty((cap, 2), dtype=np.float64)
        rs = np.zeros(cap // 2 + 2, dtype=np.int64)  # (a ring has two points but the
        rcl = np.zeros(cap // 2 + 2, dtype=np.int8)  # reader's one-point figures; checked)
        if old is not None:
            pb[: len(old[0])] = old[0]
            rs[: len(old[1])] = old[1]
            rcl[: len(old[2])] = old[2]
        self._pbuf = (pb, rs, rcl)

    def _poly_to_scanner(self, i: int, line: int, last_nl: int) -> bool:
        """Polygon-mode state into the scanner's slots and buffer (see scan.scan_moves);
        False when the buffer is not handed over (no polygon, or one edged or filled: the
        scanner needs its points only for FP after EP, which it leaves to the reader when
        EP was not its own)."""
        scan = self._scan
        if not hasattr(self, "_pbuf"):
            self._grow_poly_buffer(0)
        ok = self.window is None and self.rot == 0
        edged = 0 if self.poly_edged is None else 2
        # slots I_POLY .. I_POLYOK in one assignment (see scan.I_*)
        if self.poly is None and self.poly_emitted:
            self._ist[scan.I_POLY : scan.I_POLYOK + 1] = (
                0, 0, 1, edged, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, ok)
            return False
        rings = self.poly_buffer
        ring = self.poly_ring
        npb = sum(len(r) for r, _c in rings) + len(ring)
        if npb + 1 > len(self._pbuf[0]) or len(rings) + 2 > len(self._pbuf[1]):
            self._grow_poly_buffer(2 * (npb + len(rings)) + 2)
        pb, rs, rcl = self._pbuf
        if rings:
            pb[:npb] = [p for r, _c in rings for p in r] + ring
            rs[1 : len(rings) + 1] = np.cumsum([len(r) for r, _c in rings])
            rcl[: len(rings)] = [c for _r, c in rings]
        elif len(ring) == 1:
            pb[0] = ring[0]
        elif ring:
            pb[:npb] = ring
        rs[0] = 0
        off = self.poly_offset
        lc = self.poly_lc
        if lc is None and off <= i and self.data.count(b"\n", off, i) == 0:
            lc = self.poly_lc = (off, line, off - last_nl)  # PM0 on the line of i
        # without PM0's line and column the general reader writes EP's and FP's paths
        plc = lc is not None and lc[0] == off
        pline, pcol = (lc[1], lc[2]) if lc is not None and plc else (0, 0)
        self._ist[scan.I_POLY : scan.I_POLYOK + 1] = (
            self.poly is not None, self.poly_fresh, self.poly_emitted, edged, 0, 0, 0, 0, off,
            pline, pcol, plc, npb, len(rings), ok)
        return True

    def _poly_from_scanner(self, out: list[int], buffered: bool) -> None:
        """Polygon-mode state back from the scanner's slots and buffer (``buffered``: the
        scanner's buffer is the polygon's, see :meth:`_poly_to_scanner`)."""
        scan = self._scan
        self.poly_fresh = bool(out[scan.I_FRESH])
        self.poly_emitted = bool(out[scan.I_EMITTED])
        if out[scan.I_EDGED] == 0:
            self.poly_edged = None
        in_poly = out[scan.I_POLY]
        self.poly = [] if in_poly else None
        if not in_poly and self.poly_emitted and self.poly_edged is None:
            # no polygon, or one filled: its points no longer matter
            self.poly_buffer = []
            self.poly_ring = [(self.x, self.y)]
            self.poly_lazy = None
            return
        if not buffered:
            return  # the reader's edged polygon, untouched
        off = self.poly_offset = out[scan.I_POFF]
        if out[scan.I_PLC]:
            self.poly_lc = (off, out[scan.I_PLINE], out[scan.I_PCOL])
        npb, nr = out[scan.I_NPB], out[scan.I_NRING]
        if not in_poly and self.poly_emitted:
            # edged: its points matter only to an FP the general reader reads (it replaces
            # EP's paths); until then they stay in the scanner's buffer, which only a new
            # polygon overwrites
            self.poly_buffer = []
            self.poly_lazy = (npb, nr)
            return
        self._poly_buffer_from_scanner(npb, nr)

    def _poly_buffer_from_scanner(self, npb: int, nr: int) -> None:
        """The polygon buffer as lists from the scanner's arrays (``npb`` points, ``nr``
        completed rings)."""
        pb, rs, rcl = self._pbuf
        xs = pb[:npb, 0].tolist()
        ys = pb[:npb, 1].tolist()
        bounds = rs[: nr + 1].tolist()
        flags = rcl[:nr].tolist()
        self.poly_buffer = [(list(zip(xs[a:e], ys[a:e], strict=True)), bool(c))
                            for a, e, c in zip(bounds, bounds[1:], flags, strict=False)]
        a = bounds[nr]
        self.poly_ring = list(zip(xs[a:], ys[a:], strict=True))
        self.poly_lazy = None

    def _take_segments(self, ch: _Chunk, ist: list[int]) -> None:
        scan = self._scan
        s0, s1 = ch.nseg, ist[scan.I_NSEG]
        p1 = ist[scan.I_NPTS]
        ch.nseg, ch.npts = s1, p1
        edged = ist[scan.I_EDGED] == 1
        if s1 == s0 and not edged:
            return
        starts = ch.seg_start[s0:s1].astype(np.int64)
        ends = np.empty_like(starts)
        ends[:-1] = starts[1:]
        if s1 > s0:
            ends[-1] = p1
        offs = ch.seg_off[s0:s1]
        pens = ch.seg_pen[s0:s1]
        lines = ch.seg_line[s0:s1]
        cols = ch.seg_col[s0:s1]
        a, b = 0, s1 - s0
        still_open = bool(ist[scan.I_OPEN])
        if ist[scan.I_CONT]:
            st, en = int(starts[0]), int(ends[0])
            if en > st:
                if self.cur:
                    self.cur_parts.append(np.array(self.cur, dtype=np.float64).reshape(-1, 2))
                    self.cur = []
                self.cur_parts.append(ch.pts[st:en])
            if b > 1 or not still_open:
                self.flush()
            a = 1
        open_last = still_open and b > a
        if open_last:
            b -= 1
        # EP's segments (when EP was read in this call): a batch of their own, so that a
        # later FP read by the general reader can replace them (poly_edged)
        cuts = [a, b]
        if edged:
            e0, e1 = ist[scan.I_EDGE_S0] - s0, ist[scan.I_EDGE_S1] - s0
            cuts = [a, e0, e1, b]
        for k in range(len(cuts) - 1):
            if edged and k == 1:
                g = self.gen_base + len(self.gen)
                first = len(self.paths)
            u, v = cuts[k], cuts[k + 1]
            if v > u:
                self._add_batch(ch, starts[u:v], ends[u:v], offs[u:v], pens[u:v], lines[u:v],
                                cols[u:v])
            if edged and k == 1:
                self.poly_edged = (first, len(self.paths), g, g)
        if open_last:
            self.cur = []
            self.cur_parts = [ch.pts[int(starts[b]) : int(ends[b])]]
            self.cur_offset = int(offs[b])

    def _add_batch(self, ch: _Chunk, starts: np.ndarray, ends: np.ndarray,
                   offs: np.ndarray, pens: np.ndarray, lines: np.ndarray,
                   cols: np.ndarray) -> None:
        span = ch.pts[int(starts[0]) : int(ends[-1])]
        if self.window is None and self.rot == 0 and np.isfinite(span).all():
            self.paths.append(_Batch(ch, starts.copy(), ends.copy(),  # type: ignore[arg-type]
                                     lines.copy(), cols.copy(), pens.copy()))
            self.batched += len(starts)
            if not self.pen_selected:  # (the scanner reads SP only once a pen was selected)
                self.unselected_paths += len(starts)
            return
        pen = self.pen
        for s, e, off, p in zip(starts.tolist(), ends.tolist(), offs.tolist(), pens.tolist(),
                                strict=True):
            self.pen = p
            self.emit(ch.pts[s:e].copy(), off)
        self.pen = pen

    def _fast_pieces(self, start: int, end: int) -> int:
        """Read a run with :meth:`_fast_run` in pieces of at most _FAST_PIECE_BYTES, cut
        before a command (the numpy tokenizer's temporaries take about 60 bytes per byte of
        what it reads at once); returns where it stopped (``start``: nothing read)."""
        data = self.data
        j = start
        while j < end:
            cut = end
            if end - j > _FAST_PIECE_BYTES:
                # inside a run the only letters are the P of PU/PD/PA/PR and their second
                cut = max(data.rfind(b"P", j + 1, j + _FAST_PIECE_BYTES),
                          data.rfind(b"p", j + 1, j + _FAST_PIECE_BYTES))
                if cut <= j:
                    cut = end
            if not self._fast_run(j, cut):
                break
            j = cut
        return j

    def _fast_run(self, start: int, end: int) -> bool:
        """Read a run of PU/PD/PA/PR commands in one vectorised step (see fastrun).

        Returns False (having changed nothing) when the run needs the general reader.
        """
        tok = tokenize_run(memoryview(self.data)[start:end])
        if tok is None:
            return False
        code = tok.cmd_code
        ncmd = len(code)
        counts = np.bincount(tok.num_cmd, minlength=ncmd)
        odd = np.flatnonzero(counts % 2)
        keep = np.ones(len(tok.num_val), dtype=bool)
        for c in odd.tolist():  # rare: drop the last number of such commands
            mn = "P" + "UDAR"[code[c]]
            self.warn(start + int(tok.cmd_pos[c]),
                      f"{mn} has an odd number of coordinates; the last was ignored",
                      key=f"odd-{mn}")
            last = np.flatnonzero(tok.num_cmd == c)[-1]
            keep[last] = False
        vals = tok.num_val[keep]
        ncmd_of = tok.num_cmd[keep]
        xs, ys = vals[0::2], vals[1::2]
        pair_cmd = ncmd_of[0::2]
        pen_set = np.where(code == CODE_U, 0, np.where(code == CODE_D, 1, -1)).astype(np.int8)
        mode_set = np.where(code == CODE_A, 1, np.where(code == CODE_R, 0, -1)).astype(np.int8)
        pen_after = ffill_state(pen_set, int(self.pen_down))
        mode_after = ffill_state(mode_set, int(self.absolute))
        pen_before = np.empty_like(pen_after)
        pen_before[0] = int(self.pen_down)
        pen_before[1:] = pen_after[:-1]
        # positions of every pair, in plotter units
        absolute = mode_after[pair_cmd].astype(bool)
        if self.sc is not None:
            ax, bx, ay, by = self.sc
            xs = np.where(absolute, ax * xs + bx, ax * xs)
            ys = np.where(absolute, ay * ys + by, ay * ys)
        K = len(xs)
        q = np.empty((K + 1, 2))
        q[0] = (self.x, self.y)
        if K:
            # positions: an absolute pair starts a segment, relative pairs add up after it
            # (left to right, the rounding of the command-by-command reader)
            starts = np.flatnonzero(np.concatenate(([True], absolute)))
            q[:, 0] = segmented_cumsum(np.concatenate(([self.x], xs)), starts)
            q[:, 1] = segmented_cumsum(np.concatenate(([self.y], ys)), starts)
        # paths: one per up->down transition; pairs drawn where the pen is down
        trans = np.flatnonzero((pen_before == 0) & (pen_after == 1))
        drawn = pen_after[pair_cmd] == 1 if K else np.zeros(0, dtype=bool)
        # index of the last pair before each transition command -> the path's start point
        pairs_before = np.searchsorted(pair_cmd, trans, side="left")  # pairs of earlier cmds
        path_of_pair = np.searchsorted(trans, pair_cmd, side="right") - 1  # -1: open path
        d_idx = np.flatnonzero(drawn)
        d_path = path_of_pair[d_idx]
        # continuation of a path open before the run
        cont = d_idx[d_path < 0]
        if len(cont):
            if not self.cur and not self.cur_parts:  # pen down, path ended (CI, SP, IW..)
                self.cur = [self.x, self.y]
                self.cur_offset = start + int(tok.cmd_pos[pair_cmd[cont[0]]])
            self.cur.extend(q[cont + 1].ravel().tolist())
        if (self.cur or self.cur_parts) and (len(trans) or not bool(pen_after[-1])):
            self.flush()
        npaths = len(trans)
        if npaths:
            sel = d_path >= 0
            d_idx = d_idx[sel]
            d_path = d_path[sel]
            per = np.bincount(d_path, minlength=npaths) + 1
            out_start = np.cumsum(per) - per
            out = np.empty((int(per.sum()), 2))
            out[out_start] = q[pairs_before]
            first_of_path = np.searchsorted(d_path, np.arange(npaths), side="left")
            rank = np.arange(len(d_idx)) - first_of_path[d_path]
            out[out_start[d_path] + 1 + rank] = q[d_idx + 1]
            offsets = (start + tok.cmd_pos[trans]).tolist()
            pieces = np.split(out, out_start[1:])
            open_last = bool(pen_after[-1])
            last = npaths - 1
            for k, (piece, off) in enumerate(zip(pieces, offsets, strict=True)):
                if k == last and open_last:
                    self.cur = piece.ravel().tolist()
                    self.cur_offset = off
                else:
                    self.emit(piece, off)
        self.x, self.y = float(q[-1, 0]), float(q[-1, 1])
        self.pen_down = bool(pen_after[-1])
        self.absolute = bool(mode_after[-1])
        cc = np.bincount(code, minlength=4)
        for k, name in enumerate(("PU", "PD", "PA", "PR")):
            if cc[k]:
                self.commands[name] += int(cc[k])
        self.recognised += ncmd
        return True

    def _handlers(self) -> dict[str, Callable[[bytes, int, str], None]]:
        """The command table: mnemonic -> handler(params, offset, mnemonic)."""
        return {
            "PA": self._move(True, None),
            "PR": self._move(False, None),
            "PU": self._move(None, False),
            "PD": self._move(None, True),
            "AA": self._arc(False),
            "AR": self._arc(True),
            "AT": self._nums_mn_of(lambda v, o, mn: self.do_three_point(v, False, o, mn)),
            "RT": self._nums_mn_of(lambda v, o, mn: self.do_three_point(v, True, o, mn)),
            "CI": self._nums_of(self.do_circle),
            "EA": self._nums_mn_of(lambda v, o, mn: self.do_rect(v, False, o, mn)),
            "RA": self._nums_mn_of(lambda v, o, mn: self.do_rect(v, False, o, mn)),
            "ER": self._nums_mn_of(lambda v, o, mn: self.do_rect(v, True, o, mn)),
            "RR": self._nums_mn_of(lambda v, o, mn: self.do_rect(v, True, o, mn)),
            "EW": self._nums_mn_of(self.do_wedge),
            "WG": self._nums_mn_of(self.do_wedge),
            "BZ": self._nums_mn_of(lambda v, o, mn: self.do_bezier(v, False, o, mn)),
            "BA": self._nums_mn_of(lambda v, o, mn: self.do_bezier(v, False, o, mn)),
            "BR": self._nums_mn_of(lambda v, o, mn: self.do_bezier(v, True, o, mn)),
            "PM": self._nums_of(self.do_pm),
            "EP": self.cmd_edge_fill,
            "FP": self.cmd_edge_fill,
            "XT": lambda p, o, mn: self.do_tick(True, o),
            "YT": lambda p, o, mn: self.do_tick(False, o),
            "TL": self.cmd_tl,
            "SP": self.cmd_sp,
            "RO": self.cmd_ro,
            "PS": self.cmd_ps,
            "IP": self._nums_of(self.do_ip),
            "IR": self._nums_of(self.do_ir),
            "SC": self._nums_of(self.do_sc),
            "IW": self._nums_of(self.do_iw),
            "CT": self.cmd_ct,
            "IN": self.cmd_in,
            "DF": self.cmd_df,
            "PG": self.cmd_pg,
            "LT": self.cmd_lt,
            "SI": self.cmd_si,
            "SR": self.cmd_sr,
            "DI": self.cmd_di,
            "DR": self.cmd_di,
            "LO": self.cmd_lo,
        }

    def _move(self, mode: bool | None, down: bool | None) -> Callable[[bytes, int, str], None]:
        def h(params: bytes, off: int, mn: str) -> None:
            if mode is not None:
                self.absolute = mode
            if down is not None:
                self.set_pen_down(down, off)
            if params:
                self.move_params(params, off, mn)
        return h

    def _nums_of(self, fn: Callable[[list[float], int], None]) -> Callable[[bytes, int, str], None]:
        return lambda params, off, mn: fn(_nums(params), off)

    def _nums_mn_of(self, fn: Callable[[list[float], int, str], None]) -> Callable[..., None]:
        return lambda params, off, mn: fn(_nums(params), off, mn)

    def _arc(self, relative: bool) -> Callable[[bytes, int, str], None]:
        def h(params: bytes, off: int, mn: str) -> None:
            v = _nums(params)
            if len(v) < 3:
                self.warn(off, f"{mn} needs centre and sweep; ignored", key=f"args-{mn}")
                return
            cx, cy = v[0], v[1]
            if relative:
                ux, uy = self.to_user(self.x, self.y)
                cx, cy = ux + cx, uy + cy
            self.do_arc(cx, cy, v[2], v[3] if len(v) > 3 else None, off)
        return h

    def cmd_sp(self, params: bytes, off: int, mn: str) -> None:
        # HP-GL/2: "the pen remains down ... until a PU or IN" (SP ends the path: the
        # next move starts a new one with the new pen); an HP-GL/1 plotter puts the
        # pen back in its stall, so there SP lifts it (see self.hpgl2)
        v = _nums(params)
        self.flush()
        if not self.hpgl2:
            self.pen_down = False
        self.pen = int(v[0]) if v else 0
        self.pen_selected = True

    def cmd_ro(self, params: bytes, off: int, mn: str) -> None:
        v = _nums(params)
        self.flush()
        ang = int(v[0]) % 360 if v else 0
        if ang not in (0, 90, 180, 270):
            self.warn(off, f"RO{ang}: only 0, 90, 180, 270 exist; treated as 0")
            ang = 0
        self.rot = ang

    def cmd_ps(self, params: bytes, off: int, mn: str) -> None:
        v = _nums(params)
        if any(x <= 0 for x in v[:2]):
            # "if a length is <= 0 the device ignores the instruction"
            self.warn(off, "PS with a length <= 0 ignored", key="args-PS")
            return
        if len(v) >= 2:
            w, h = abs(v[0]), abs(v[1])
        elif len(v) == 1:
            w = h = abs(v[0])
        else:
            w, h = DEFAULT_P2[0] - DEFAULT_P1[0], DEFAULT_P2[1] - DEFAULT_P1[1]
        self.hard = ((0.0, 0.0), (w, h))
        self.page_known = bool(v)
        self.p1, self.p2 = self.hard
        self.update_scaling(off)

    def cmd_ct(self, params: bytes, off: int, mn: str) -> None:
        v = _nums(params)
        self.ct_tol = bool(v and int(v[0]) == 1)

    def cmd_tl(self, params: bytes, off: int, mn: str) -> None:
        v = _nums(params)
        self.tick = (v[0] if v else 0.5, v[1] if len(v) > 1 else (0.0 if v else 0.5))

    def cmd_si(self, params: bytes, off: int, mn: str) -> None:
        v = _nums(params)
        if len(v) >= 2:
            self.char_size = (abs(v[0]) * 400.0, abs(v[1]) * 400.0)  # cm -> units
        else:
            self.char_size = None
        self.char_rel = None

    def cmd_sr(self, params: bytes, off: int, mn: str) -> None:
        v = _nums(params)
        self.char_rel = (abs(v[0]), abs(v[1])) if len(v) >= 2 else (0.75, 1.5)
        self.char_size = None

    def cmd_di(self, params: bytes, off: int, mn: str) -> None:
        v = _nums(params)
        run, rise = (v[0], v[1]) if len(v) >= 2 else (1.0, 0.0)
        if mn == "DR":
            (p1x, p1y), (p2x, p2y) = self.p1, self.p2
            run, rise = run * (p2x - p1x) / 100.0, rise * (p2y - p1y) / 100.0
        r = math.hypot(run, rise)
        self.label_dir = (run / r, rise / r) if r > 0 and math.isfinite(r) else (1.0, 0.0)

    def cmd_lo(self, params: bytes, off: int, mn: str) -> None:
        """LO [position]: the label origin, 1-9, 11-19 or 21; none is LO1."""
        v = _nums(params)
        pos = int(v[0]) if v and math.isfinite(v[0]) else 1
        if pos not in _LABEL_ORIGINS:
            self.warn(off, f"LO{pos}: label origin out of range (1-9, 11-19, 21) ignored",
                      key="lo-range")
            return
        self.label_origin = pos

    def cmd_pg(self, params: bytes, off: int, mn: str) -> None:
        self.flush()
        self.pages += 1

    def cmd_lt(self, params: bytes, off: int, mn: str) -> None:
        if _nums(params):
            self.line_types += 1

    def cmd_in(self, params: bytes, off: int, mn: str) -> None:
        self.reset()

    def cmd_df(self, params: bytes, off: int, mn: str) -> None:
        self.defaults()

    def cmd_edge_fill(self, params: bytes, off: int, mn: str) -> None:
        self.do_edge_fill(mn, off)

    # ------------------------------------------------------------------ text-like commands
    def _find_term(self, start: int, term: int) -> int:
        """Offset of ``term`` at or after ``start``, or -1 (cached to stay linear)."""
        none_after = self._no_term_after.get(term)
        if none_after is not None and start >= none_after:
            return -1
        j = self.data.find(bytes((term,)), start)
        if j < 0:
            self._no_term_after[term] = start
        return j

    def _end_of_line(self, start: int) -> int:
        j = self.data.find(b"\n", start)
        return self.n if j < 0 else j + 1

    def label(self, pos: int) -> int:
        """LB/BL/WD: skip text to the terminator; returns the offset after it.

        The letters are not drawn, but LB moves the pen as the plotter would: one character
        cell per character along the label direction, CR back to the line's start, LF one
        line down, BS one cell back (see :meth:`label_advance`). BL (buffer) and WD (a
        display) do not move it.
        """
        self.labels += 1
        mn = self.data[pos - 2 : pos].upper()
        j = self._find_term(pos, self.term)
        if j < 0:
            end = self._end_of_line(pos)
            self.warn(pos - 2, "label without its terminator: ended at the end of the line",
                      key="label-unterminated")
            text_end = end
        else:
            text_end, end = j, j + 1
        if mn == b"LB":
            self.label_advance(self.data[pos:text_end])
        return end

    def char_cell(self) -> tuple[float, float]:
        """(advance along the text, line spacing) in plotter units.

        The character cell of the HP stick font: 1.5 x the character width along the line,
        2 x the character height between lines (HP 7475A manual, SI; the HP-GL/2 default
        font, 9 characters per inch, is within 1 % of the same 0.187 cm x 1.5). Width and
        height come from SI (cm), from SR (% of P2 - P1) or are SI's defaults, 0.187 x
        0.269 cm.
        """
        if self.char_rel is not None:
            (p1x, p1y), (p2x, p2y) = self.p1, self.p2
            w = self.char_rel[0] / 100.0 * abs(p2x - p1x)
            h = self.char_rel[1] / 100.0 * abs(p2y - p1y)
        elif self.char_size is not None:
            w, h = self.char_size
        else:
            w, h = 0.187 * 400.0, 0.269 * 400.0
        return 1.5 * w, 2.0 * h

    def label_advance(self, text: bytes) -> None:
        """Move the current position over ``text`` as LB does (the pen state is kept: the
        path being drawn ends at the label, the next pen-down move starts at its end)."""
        if not text or self.label_origin not in _LO_CONCATENATE:
            # LO4-9, 14-19 (centred or right-justified labels): the pen position that
            # existed before LB is restored
            return
        adv, line = self.char_cell()
        ux, uy = self.label_dir
        nx, ny = uy, -ux  # one line down: to the right of the direction of the text
        col = 0.0
        row = 0.0
        for c in text:
            if c == 0x0D:
                col = 0.0
            elif c == 0x0A:
                row += 1.0
            elif c == 0x08:
                col -= 1.0
            elif c >= 0x20:
                col += 1.0
        if col == 0.0 and row == 0.0:
            return
        self.flush_if_drawing()
        x = self.x + col * adv * ux + row * line * nx
        y = self.y + col * adv * uy + row * line * ny
        if self.poly is not None:
            self._poly_move(x, y)  # pen-up (or pen-down) move in the polygon buffer
        self.x, self.y = x, y

    def dt(self, pos: int) -> int:
        data, n = self.data, self.n
        if pos >= n or data[pos] == 0x3B:  # 'DT;' -> default ETX
            self.term = ETX
            return min(pos + 1, n)
        t = data[pos]
        if t in (0x00, 0x0A, 0x0D, 0x1B) or t == 0x3B:
            self.warn(pos, f"DT with terminator {bytes((t,))!r} refused; ETX kept")
            self.term = ETX
        else:
            self.term = t
        m = re.compile(rb"(?:,\s*\d*)?;?").match(data, pos + 1)
        return m.end() if m else pos + 1

    def sm(self, pos: int) -> int:
        data, n = self.data, self.n
        if pos >= n or data[pos] in b";\r\n":
            return min(pos + 1, n) if pos < n and data[pos] == 0x3B else pos
        self.text_symbols += 1
        end = pos + 1
        if end < n and data[end] == 0x3B:
            end += 1
        return end

    def co(self, pos: int) -> int:
        data, n = self.data, self.n
        m = _SEP_RE.match(data, pos)
        j = m.end() if m else pos
        if j < n and data[j] == 0x22:  # '"'
            k = self._find_term(j + 1, 0x22)
            if k < 0:
                self.warn(pos - 2, "CO comment without its closing quote: ended at end of line")
                return self._end_of_line(j + 1)
            k += 1
            if k < n and data[k] == 0x3B:
                k += 1
            return k
        stop = re.compile(rb"[^;\r\n" + re.escape(bytes((self.term,))) + rb"]*").match(data, pos)
        k = stop.end() if stop else pos
        return min(k + 1, n)

    def pe(self, pos: int) -> int:
        if self.compiled:
            return self._pe_compiled(pos)
        res = decode_pe(self.data, pos, self._pe_cache)
        for off, msg in res.problems:
            self.warn(off, msg, key="pe")
        items = [(item.kind == "pen", item.value if item.kind == "pen" else 0, item.x, item.y,
                  item.pen_up, item.absolute) for item in res.items]
        self._pe_apply(items, pos)
        return res.end

    def _pe_compiled(self, pos: int) -> int:
        """PE decoded by the compiled decoder (scan.decode_pe, the same decoding)."""
        scan = self._scanner()
        end, kinds, xs, ys, flags, ni, p_off, p_code, p_val, npb = scan.decode_pe(
            self._u8, pos, self._pe_span)
        for off, code, val in zip(p_off[:npb].tolist(), p_code[:npb].tolist(),
                                  p_val[:npb].tolist(), strict=True):
            self.warn(off, _PE_MESSAGES[code].format(val), key="pe")
        if ni:
            xl = xs[:ni].tolist()
            fl = flags[:ni].tolist()
            items = [(k == 0, int(x) if k == 0 else 0, x, y, bool(f & 1), bool(f & 2))
                     for k, x, y, f in zip(kinds[:ni].tolist(), xl, ys[:ni].tolist(), fl,
                                           strict=True)]
            self._pe_apply(items, pos)
        return int(end)

    def _pe_apply(self, items: list[tuple[bool, int, float, float, bool, bool]],
                  pos: int) -> None:
        """Apply decoded PE items: (is pen select, pen, x, y, pen up, absolute)."""
        saved_abs = self.absolute
        for is_pen, pen, ix, iy, pen_up, absolute in items:
            if is_pen:
                self.flush()
                self.pen = pen
                self.pen_selected = True
                continue
            if pen_up:
                self.set_pen_down(False, pos)
            elif not self.pen_down:
                self.set_pen_down(True, pos)
            if absolute:
                x, y = self.to_plotter(ix, iy)
            else:
                dx, dy = self.delta_to_plotter(ix, iy)
                x, y = self.x + dx, self.y + dy
            self.pen_to(x, y, pos)
            # after a pen-up move the next pair (without '<') puts the pen down again; a
            # PE that ends with a pen-up move leaves the pen up (and draws no dot there)
        self.absolute = saved_abs

    # ------------------------------------------------------------------ escapes and PCL
    def _escape_in_hpgl(self, i: int) -> int:
        data = self.data
        dm = _DEVCTL_RE.match(data, i)
        if dm is not None:
            return dm.end()
        m = _PCL_ESC_RE.match(data, i)
        if m is None:
            self.junk_bytes += 1
            return i + 1
        if m.group(0) == b"\x1b%-12345X" or m.group(6) == b"E":
            self.flush()
            self.hpgl_mode = False
            return m.end()
        if m.group(1) == b"%" and m.group(5) == b"A":
            self.flush()
            self.hpgl_mode = False
            return m.end()
        return self._skip_pcl_data(m)

    def _skip_pcl_data(self, m: re.Match[bytes]) -> int:
        end = m.end()
        term = m.group(5)
        # ESC ... #W (raster, font, pattern data) and ESC&p#X (transparent print data)
        # carry # bytes of data; ESC*p#X is cursor positioning and carries none
        if term == b"W" or (term == b"X" and m.group(1) == b"&" and m.group(2) == b"p"):
            try:
                count = int(float(m.group(4) or b"0"))
            except ValueError:
                count = 0
            end = min(self.n, end + max(0, count))
        return end

    def _pcl(self, i: int) -> int:
        """In PCL/PJL mode: skip to the next way back into HP-GL/2."""
        data = self.data
        m = _PCL_SCAN_RE.search(data, i)
        if m is None:
            return self.n
        if m.group(0) != b"\x1b":
            lang = m.group(1).upper().replace(b"-", b"")
            if lang.startswith(b"HPGL"):
                self.hpgl_mode = True
                self.hpgl2 = True
            return m.end()
        e = _PCL_ESC_RE.match(data, m.start())
        if e is None:
            return m.start() + 1
        if e.group(1) == b"%" and e.group(5) == b"B":
            self.hpgl_mode = True
            self.hpgl2 = True
            return e.end()
        return self._skip_pcl_data(e)


_SPECIAL: dict[str, Callable[[_Reader, int], int]] = {
    "LB": _Reader.label,
    "BL": _Reader.label,
    "WD": _Reader.label,
    "DT": _Reader.dt,
    "CO": _Reader.co,
    "PE": _Reader.pe,
    "SM": _Reader.sm,
}


def _near(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal up to floating-point noise (a ring's end computed by trigonometry)."""
    scale = max(1.0, float(np.abs(a).max()), float(np.abs(b).max()))
    return bool(np.abs(a - b).max() <= 1e-9 * scale)


def _clip_polyline(pts: np.ndarray, win: tuple[float, float, float, float]) -> list[np.ndarray]:
    """Clip a polyline to an axis-aligned window (Liang–Barsky per segment)."""
    xmin, ymin, xmax, ymax = win
    if len(pts) == 1:
        x, y = pts[0]
        return [pts] if xmin <= x <= xmax and ymin <= y <= ymax else []
    a = pts[:-1]
    d = pts[1:] - a
    t0 = np.zeros(len(a))
    t1 = np.ones(len(a))
    visible = np.ones(len(a), dtype=bool)
    for p, q in (
        (-d[:, 0], a[:, 0] - xmin),
        (d[:, 0], xmax - a[:, 0]),
        (-d[:, 1], a[:, 1] - ymin),
        (d[:, 1], ymax - a[:, 1]),
    ):
        zero = p == 0
        visible &= ~(zero & (q < 0))
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(zero, 0.0, q / np.where(zero, 1.0, p))
        neg = (p < 0) & ~zero
        pos_ = (p > 0) & ~zero
        t0 = np.where(neg, np.maximum(t0, r), t0)
        t1 = np.where(pos_, np.minimum(t1, r), t1)
    visible &= t0 <= t1
    ks = np.flatnonzero(visible)
    if not len(ks):
        return []
    # the visible part of segment k runs from s to e; segment k goes on from segment k-1
    # when that one was visible up to its end and this one is visible from its start
    s = a[ks] + t0[ks, None] * d[ks]
    e = a[ks] + t1[ks, None] * d[ks]
    kp = np.maximum(ks - 1, 0)
    new = ~((ks > 0) & visible[kp] & (t1[kp] == 1.0) & (t0[ks] == 0.0))
    at_e = np.arange(len(ks)) + np.cumsum(new)  # where each e goes; s before it when new
    out_pts = np.empty((len(ks) + int(new.sum()), 2))
    out_pts[at_e] = e
    out_pts[at_e[new] - 1] = s[new]
    return np.split(out_pts, at_e[new][1:] - 1)


def _line_cols_arrays(data: bytes, offs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """1-based line and column of each byte offset (one pass over the newlines)."""
    if not len(offs):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    u8 = np.frombuffer(data, dtype=np.uint8)
    step = 1 << 16  # newlines found 64 kB at a time: no temporary the size of the file
    nl = np.concatenate([np.flatnonzero(u8[i : i + step] == 10) + i
                         for i in range(0, len(u8), step)] or [np.zeros(0, np.int64)])
    idx = np.searchsorted(nl, offs, side="left")  # newlines strictly before offset
    if len(nl):
        line_start = np.where(idx > 0, nl[np.maximum(idx - 1, 0)] + 1, 0)
    else:
        line_start = np.zeros_like(offs)
    return idx + 1, offs - line_start + 1


def _line_cols(rd: _Reader, offs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """1-based line and column of each offset: counted between the sorted offsets (bytes
    counts newlines in C) when there are few, else in one pass over the bytes."""
    if len(offs) > 2000:
        return _line_cols_arrays(rd.data, offs)
    data = rd.data
    order = np.argsort(offs, kind="stable").tolist()
    lines = np.empty(len(offs), dtype=np.int64)
    cols = np.empty(len(offs), dtype=np.int64)
    pos, line, last_nl = 0, 1, -1
    offs_l = offs.tolist()
    for k in order:
        o = max(offs_l[k], 0)
        if o > pos:
            cnt = data.count(b"\n", pos, o)
            if cnt:
                line += cnt
                last_nl = data.rfind(b"\n", pos, o)
            pos = o
        lines[k] = line
        cols[k] = offs_l[k] - last_nl
    return lines, cols




def _scanner_paths(rd: _Reader) -> list[Path]:
    """The paths of the scanner's batches, in order: one vectorised step per chunk, each
    path a view (made when first read) of the chunk's frozen points."""
    out: list[Path] = []
    batches = [p for p in rd.paths if p is not None]
    k = 0
    while k < len(batches):
        ch = batches[k].chunk
        j = k
        while j < len(batches) and batches[j].chunk is ch:
            j += 1
        group = batches[k:j]
        k = j
        if len(group) == 1:
            b = group[0]
            starts, ends, lines, cols, pens = b.starts, b.ends, b.lines, b.cols, b.pens
        else:
            starts, ends, lines, cols, pens = (
                np.concatenate([getattr(b, f) for b in group])
                for f in ("starts", "ends", "lines", "cols", "pens"))
        pts = ch.pts
        first = pts[starts]
        last = pts[ends - 1]
        closed = ((ends - starts >= 4) & (first[:, 0] == last[:, 0])
                  & (first[:, 1] == last[:, 1]))
        out.extend(paths_from_store(pts, starts, ends, pens.tolist(), closed.tolist(),
                                    lines, cols))
    return out


def _general_paths(blocks: list[_Block]) -> list[Path]:
    """The general reader's paths, in order, each a view of its block's points."""
    out: list[Path] = []
    for bl in blocks:
        out.extend(paths_from_store(bl.pts, bl.starts, bl.ends, bl.pens.tolist(),
                                    bl.closed.tolist(), bl.lines, bl.cols))
    return out


def read_bytes(data: bytes, name: str = "<bytes>") -> Drawing:
    """Read HP-GL / HP-GL/2 from bytes. Raises InputError when it is not HP-GL."""
    if len(data) > MAX_FILE_BYTES:
        raise InputError(name, f"file is larger than {MAX_FILE_BYTES // 2**20} MiB")
    head = data[: 1 << 16].lstrip(b"\x00") if data[:1] == b"\x00" else data[: 1 << 16]
    if data[:1] == b"\x00" and not head:
        head = data.lstrip(b"\x00")[: 1 << 16]
    reason = refusal_reason(head)
    del head
    if reason is not None:
        raise InputError(name, reason)
    # the reader makes tens of thousands of objects that all live on (paths, positions):
    # the cyclic garbage collector would walk them again and again for nothing
    gc_was_on = gc.isenabled()
    gc.disable()
    try:
        return _read(data, name)
    finally:
        if gc_was_on:
            gc.enable()


def _read(data: bytes, name: str) -> Drawing:
    rd = _Reader(data, name)
    try:
        with np.errstate(all="ignore"):  # out-of-range numbers are dropped, not warned twice
            rd.run()
    except RecursionError as exc:  # pragma: no cover - defensive
        raise InputError(name, "file too deeply nested to read") from exc
    # bytes that are not NUL padding (counted only when some bytes were not HP-GL)
    body = len(data) - data.count(b"\x00") if rd.junk_bytes else len(data)
    if rd.recognised == 0:
        if not rd.hpgl_mode or _PCL_START_RE.match(data.lstrip(b"\x00")):
            raise InputError(name, "a PCL/PJL print job without HP-GL/2 graphics")
        raise InputError(name, "no HP-GL commands found: not an HP-GL/PLT file")
    if rd.junk_bytes > 0.5 * max(body, 1):
        share = 100.0 * rd.junk_bytes / max(body, 1)
        raise InputError(name, f"not HP-GL: {share:.0f}% of the file is not HP-GL commands")
    # warnings about the whole file have no position (offset -1 -> line 0, column 0)
    if rd.clipped:
        rd.warn(rd.first_clip, f"{rd.clipped} path(s) clipped by the input window (IW)")
    if rd.pages > 1:
        rd.warn(-1, f"the file has {rd.pages} pages (PG); they are overlaid in one field")
    if rd.labels:
        rd.warn(-1, f"{rd.labels} text label(s) (LB) are not drawn: convert text to curves")
    if rd.line_types:
        rd.warn(-1, "line types (LT) are not applied: every line is imported solid")
    if rd.text_symbols:
        rd.warn(-1, "symbol mode (SM) characters are not drawn")
    if rd.unselected_paths:
        rd.warn(-1, f"{rd.unselected_paths} path(s) drawn before any pen was selected (SP): "
                   "imported with pen 1 (an HP-GL/2 device would not draw them)")
    pen0 = sum(int((p.pens == 0).sum()) for p in rd.paths if p is not None)
    pen0 += sum(int((bl.pens == 0).sum()) for bl in rd.blocks)
    if pen0:
        rd.warn(-1, f"{pen0} path(s) drawn with pen 0 (SP0 puts the pen away: a pen plotter "
                   "would not draw them); imported anyway")
    if not rd.paths:
        rd.warn(-1, "the file has no pen-down geometry")
    for key, count in rd._warn_count.items():
        if count > _WARN_CAP:
            rd._warn.append((-1, f"... and {count - _WARN_CAP} more warnings like: {key}"))
    # positions: the scanner's paths carry theirs; the others' and the warnings' from offsets
    offs = np.array([w[0] for w in rd._warn], dtype=np.int64)
    lines, cols = _line_cols(rd, offs)
    for ch in rd.chunks:
        ch.seg_start = ch.seg_off = ch.seg_pen = ch.seg_line = ch.seg_col = _EMPTY_I32
        if len(ch.pts) - ch.npts > max(ch.npts // 4, 4096):
            ch.pts = ch.pts[: ch.npts].copy()  # the drawing keeps only what was used
        ch.pts.setflags(write=False)
    scanned = _scanner_paths(rd) if rd.batched else []
    gen_paths = _general_paths(rd.blocks)
    rd.blocks = []
    if not scanned:
        paths = gen_paths
    elif not gen_paths:
        paths = scanned
    else:  # in file order
        paths = []
        bi = gi = 0
        for item in rd.paths:
            if item is None:
                paths.append(gen_paths[gi])
                gi += 1
            else:
                m = len(item.starts)
                paths.extend(scanned[bi : bi + m])
                bi += m
    rd.paths = []
    lc = list(zip(lines.tolist(), cols.tolist(), strict=True))
    warnings = []
    for (off, msg), (line, col) in zip(rd._warn, lc, strict=True):
        if off < 0:
            line, col = 0, 0
        warnings.append(Warning(line, col, msg))
    warnings.sort(key=lambda w: (w.line == 0, w.line, w.col))
    return Drawing(
        paths=tuple(paths),
        name=name,
        sha256=sha256_hex(data),
        commands=dict(rd.commands),
        warnings=tuple(warnings),
    )


def read_file(path: str | os.PathLike[str]) -> Drawing:
    """Read a PLT/HP-GL file. Raises InputError (naming the file) when it cannot be used."""
    name = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            size = os.fstat(fh.fileno()).st_size
            if size > MAX_FILE_BYTES:
                raise InputError(name, f"file is larger than {MAX_FILE_BYTES // 2**20} MiB")
            data = fh.read()
    except IsADirectoryError as exc:
        raise InputError(name, "is a folder, not a file") from exc
    except FileNotFoundError as exc:
        raise InputError(name, "no such file") from exc
    except PermissionError as exc:
        raise InputError(name, "permission denied") from exc
    except OSError as exc:
        raise InputError(name, f"cannot be read ({exc.strerror or exc})") from exc
    drawing = read_bytes(data, os.path.basename(name))
    return drawing
