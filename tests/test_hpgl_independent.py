"""Issue 20: every HP-GL file of the corpus loads with its pen-down length and extent within
1 % of an independent decoder written here from the HP-GL/2 reference.

The decoder below shares no code with :mod:`galvo_core.hpgl` (not its tokenizer, number
reader, arcs, PE decoder nor PCL skipper). It follows HP's "PCL 5 Printer Language Technical
Reference Manual, Part II" (PCL5-II; HP-GL/2 chapters 17-23) instruction by instruction, and
the HP 7475A manual for HP-GL/1 (SP lifts the pen; the character cell of LB). Where the
reference leaves a choice to the device, it takes the importer's documented decision (the
reader's module docstring), each marked ``decision:`` below: no SP draws with pen 1, RO
rotates about the plotter origin, IW without numbers is PS's page, a pen-up move inside
polygon mode ends a sub-polygon, FP after EP is one region, an unterminated label ends at
its line's end.

It computes only what a user marks: the total pen-down length and the extent (bounding box
of every pen-down point, dots included) in plotter units, after IW clipping and RO. Arcs are
drawn as the chords the reference describes (CT0: chord angle, default 5 degrees; CT1:
chord deviation).

Compared on every corpus file the importer loads (the others are refused as not HP-GL:
tests/test_corpus.py); ezhpgl (tests/test_hpgl_ezhpgl.py) checks the strictly readable part
of the same files against a third reader.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from galvo_core.errors import InputError
from galvo_core.hpgl import read_file

PLT = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "plt"
if not PLT.is_dir():
    pytest.skip(f"corpus folder {PLT} not present", allow_module_level=True)

# HP-GL/2-only instructions (PCL5-II ch. 17-23; absent from the 7475A's HP-GL): a file that
# uses one is HP-GL/2 from there on (SP then keeps the pen down, PCL5-II 17-21)
HPGL2_ONLY = set("BP BR BZ CR FR LA MC MG NP PC PE PP PS PW QL RF SV TR WU".split())
NUM = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)")
LETTER = re.compile(rb"[A-Za-z]")


class Extent:
    """Pen-down length and bounding box."""

    def __init__(self) -> None:
        self.length = 0.0
        self.box = [math.inf, math.inf, -math.inf, -math.inf]

    def point(self, x: float, y: float) -> None:
        b = self.box
        b[0], b[1], b[2], b[3] = min(b[0], x), min(b[1], y), max(b[2], x), max(b[3], y)

    def result(self) -> tuple[float, tuple[float, ...] | None]:
        return self.length, (tuple(self.box) if self.box[0] <= self.box[2] else None)


def clip(a: tuple[float, float], b: tuple[float, float],
         win: tuple[float, float, float, float] | None):
    """The part of segment a-b inside the window (Liang-Barsky), or None."""
    if win is None:
        return a, b
    t0, t1 = 0.0, 1.0
    dx, dy = b[0] - a[0], b[1] - a[1]
    for p, q in ((-dx, a[0] - win[0]), (dx, win[2] - a[0]), (-dy, a[1] - win[1]),
                 (dy, win[3] - a[1])):
        if p == 0:
            if q < 0:
                return None
        else:
            t = q / p
            if p < 0:
                t0 = max(t0, t)
            else:
                t1 = min(t1, t)
    if t0 > t1:
        return None
    return (a[0] + t0 * dx, a[1] + t0 * dy), (a[0] + t1 * dx, a[1] + t1 * dy)


class Decoder:
    def __init__(self, data: bytes) -> None:
        self.data = data
        self.out = Extent()
        self.pen_no = 1
        self.hpgl2 = False
        self.initialize()

    # ---------------------------------------------------------------- state (IN, DF)
    def initialize(self) -> None:
        """IN (PCL5-II ch. 19): defaults, P1/P2, pen up at the origin, no rotation."""
        self.x = self.y = 0.0
        self.down = False
        self.p1, self.p2 = (250.0, 596.0), (10250.0, 7796.0)  # decision: 7475A, ANSI A
        self.page: tuple[float, float] | None = None
        self.rot = 0
        self.defaults()

    def defaults(self) -> None:
        """DF: relative/absolute, scaling, window, polygon, label state to defaults."""
        self.absolute = True
        self.scale: tuple[float, float, float, float] | None = None  # ax, bx, ay, by
        self.sc_args: list[float] | None = None
        self.window: tuple[float, float, float, float] | None = None
        self.chord_tol = False
        self.term = 3
        self.poly: list[tuple[list[tuple[float, float]], list[bool]]] | None = None
        self.buffer: list[tuple[list[tuple[float, float]], list[bool]]] = []
        self.edged: list[tuple[float, tuple[float, ...] | None]] | None = None
        self.filled = True
        self.char = (0.187 * 400, 0.269 * 400)  # SI defaults, cm -> plotter units
        self.char_rel: tuple[float, float] | None = None
        self.direction = (1.0, 0.0)
        self.origin = 1
        self.tick = (0.5, 0.5)

    def user_to_plotter(self, x: float, y: float) -> tuple[float, float]:
        if self.scale is None:
            return x, y
        ax, bx, ay, by = self.scale
        return ax * x + bx, ay * y + by

    def plotter_to_user(self, x: float, y: float) -> tuple[float, float]:
        if self.scale is None:
            return x, y
        ax, bx, ay, by = self.scale
        return (x - bx) / ax, (y - by) / ay

    def set_scale(self) -> None:
        """SC xmin,xmax,ymin,ymax[,type[,left,bottom]] (PCL5-II ch. 19, SC): type 0
        anisotropic, 1 isotropic (centred by left/bottom %), 2 point factor."""
        v = self.sc_args
        if not v or len(v) < 4:
            self.scale = None
            return
        (p1x, p1y), (p2x, p2y) = self.p1, self.p2
        kind = int(v[4]) if len(v) > 4 else 0
        if kind == 2:
            self.scale = (v[1], p1x - v[0] * v[1], v[3], p1y - v[2] * v[3])
            return
        if v[1] == v[0] or v[3] == v[2]:
            self.scale = None
            return
        ax = (p2x - p1x) / (v[1] - v[0])
        ay = (p2y - p1y) / (v[3] - v[2])
        if kind == 1:
            s = min(abs(ax), abs(ay))
            sx, sy = math.copysign(s, ax), math.copysign(s, ay)
            left = v[5] if len(v) > 5 else 50.0
            bottom = v[6] if len(v) > 6 else 50.0
            ox = ((p2x - p1x) - sx * (v[1] - v[0])) * left / 100.0
            oy = ((p2y - p1y) - sy * (v[3] - v[2])) * bottom / 100.0
            self.scale = (sx, p1x - v[0] * sx + ox, sy, p1y - v[2] * sy + oy)
        else:
            self.scale = (ax, p1x - v[0] * ax, ay, p1y - v[2] * ay)
        if ax == 0 or ay == 0:
            self.scale = None

    # ---------------------------------------------------------------- drawing
    def orient(self, x: float, y: float) -> tuple[float, float]:
        """decision: RO rotates the output about the plotter origin."""
        r = self.rot
        if r == 90:
            return -y, x
        if r == 180:
            return -x, -y
        if r == 270:
            return y, -x
        return x, y

    def polyline(self, pts: list[tuple[float, float]]) -> None:
        """A pen-down polyline (plotter units): its clipped length and points."""
        out = self.out
        if len(pts) == 1:
            if clip(pts[0], pts[0], self.window) is not None:
                out.point(*self.orient(*pts[0]))
            return
        for a, b in zip(pts, pts[1:], strict=False):
            seg = clip(a, b, self.window)
            if seg is None:
                continue
            (ax, ay), (bx, by) = seg
            out.length += math.hypot(bx - ax, by - ay)
            out.point(*self.orient(ax, ay))
            out.point(*self.orient(bx, by))

    def move(self, x: float, y: float) -> None:
        """To plotter point (x, y) with the current pen state."""
        if self.poly is not None:
            ring, downs = self.poly[-1]
            if self.fresh:  # PM1: the next point starts a sub-polygon, pen up
                self.fresh = False
                self.poly[-1] = ([(x, y)], [])
            elif self.down:
                ring.append((x, y))
                downs.append(True)
            else:  # decision: a pen-up move ends the sub-polygon
                self.poly.append(([(x, y)], []))
        elif self.down:
            self.polyline([(self.x, self.y), (x, y)])
        self.x, self.y = x, y

    def pen(self, down: bool) -> None:
        if down and not self.down and self.poly is None:
            self.polyline([(self.x, self.y)])  # the pen touches the paper: a dot at least
        self.down = down

    def figure(self, ring: list[tuple[float, float]]) -> None:
        """A closed figure (CI, EA, ER, RA, RR, EW, WG): drawn whatever the pen state; in
        polygon mode a sub-polygon of the buffer (PCL5-II 21-2)."""
        if ring[0] != ring[-1]:
            ring = ring + [ring[0]]
        if self.poly is not None:
            self.poly.append((ring, [True] * (len(ring) - 1)))
            self.poly.append(([(self.x, self.y)], []))
        else:
            self.polyline(ring)

    def chords(self, r: float, sweep: float, chord: float | None) -> int:
        """Number of chords of an arc (PCL5-II ch. 20, AA and CT): the chord angle
        (default 5 degrees, at least 0.5, at most 180) or, in CT1 mode, the largest
        distance from chord to arc."""
        if self.chord_tol and chord is not None and r > 0:
            dev = min(abs(chord), r)
            step = math.degrees(2 * math.acos(1 - dev / r)) if dev > 0 else 0.5
        else:
            step = 5.0 if chord is None else abs(chord)
        step = min(max(step, 0.5), 180.0)
        return max(1, math.ceil(abs(sweep) / step - 1e-9))

    def arc_points(self, cx: float, cy: float, ux: float, uy: float, sweep: float,
                   chord: float | None) -> list[tuple[float, float]]:
        """Points of an arc around user point (cx, cy) from user point (ux, uy), in plotter
        units; chords of equal angle."""
        r = math.hypot(ux - cx, uy - cy)
        a0 = math.atan2(uy - cy, ux - cx)
        sweep = max(min(sweep, 360.0), -360.0)
        n = self.chords(r, sweep, chord)
        return [self.user_to_plotter(cx + r * math.cos(a0 + math.radians(sweep) * k / n),
                                     cy + r * math.sin(a0 + math.radians(sweep) * k / n))
                for k in range(1, n + 1)]

    def follow(self, pts: list[tuple[float, float]]) -> None:
        for x, y in pts:
            self.move(x, y)

    def edge_fill(self, mn: str) -> None:
        """EP: the pen-down edges of the buffer; FP: every sub-polygon as a closed ring
        (decision: edged and filled it is one region, FP after EP replaces EP's edges)."""
        if self.poly is not None:
            return
        if mn == "EP":
            if self.edged is not None or self.filled:
                return
            before = self.out.length, tuple(self.out.box)
            for ring, downs in self.buffer:
                pts = ring + ([ring[0]] if ring[0] != ring[-1] else [])
                flags = downs + [False] * (len(pts) - 1 - len(downs))
                run: list[tuple[float, float]] = []
                for k, d in enumerate(flags[: len(pts) - 1]):
                    if d:
                        run = run or [pts[k]]
                        run.append(pts[k + 1])
                    elif run:
                        self.polyline(run)
                        run = []
                if run:
                    self.polyline(run)
            self.edged = [before]
            return
        if self.filled and self.edged is None:
            return
        if self.edged is not None:  # undo EP's edges: FP's rings replace them
            (length, box), = self.edged
            # EP's edges lie on FP's rings: the rings' extent covers them
            self.out.length = length
            self.out.box = list(box)
        for ring, _ in self.buffer:
            if len(ring) > 1:
                self.polyline(ring + ([ring[0]] if ring[0] != ring[-1] else []))
        self.filled = True
        self.edged = None

    # ---------------------------------------------------------------- labels
    def cell(self) -> tuple[float, float]:
        """(advance, line spacing): 1.5 x the character width, 2 x its height (7475A, SI);
        SR gives width and height in % of P2 - P1."""
        if self.char_rel is not None:
            (p1x, p1y), (p2x, p2y) = self.p1, self.p2
            w = self.char_rel[0] / 100 * abs(p2x - p1x)
            h = self.char_rel[1] / 100 * abs(p2y - p1y)
        else:
            w, h = self.char
        return 1.5 * w, 2.0 * h

    def label(self, text: bytes) -> None:
        """LB moves the pen over the text (PCL5-II 23-65: after a concatenating label
        origin, LO 1-3, 11-13, 21 with text path right, the pen is left where the next
        label goes on; after the others the position before LB is restored)."""
        if self.origin not in (1, 2, 3, 11, 12, 13, 21):
            return
        adv, line = self.cell()
        ux, uy = self.direction
        col = row = 0.0
        for c in text:
            if c == 13:
                col = 0.0
            elif c == 10:
                row += 1.0
            elif c == 8:
                col -= 1.0
            elif c >= 32:
                col += 1.0
        if col or row:
            x = self.x + col * adv * ux + row * line * uy
            y = self.y + col * adv * uy - row * line * ux
            if self.poly is not None:
                self.move(x, y)
            self.x, self.y = x, y

    # ---------------------------------------------------------------- instructions
    def run(self) -> None:
        data = self.data
        n = len(data)
        i = 0
        hpgl = not re.match(rb"[\x00-\x20]*(\x1bE|\x1b%-12345X|@PJL|\x1b[&*(])", data)
        while i < n:
            c = data[i]
            if c == 27:
                i = self.escape(i)
                continue
            if not hpgl and not self.in_hpgl:
                j = data.find(b"\x1b", i)
                m = re.compile(rb"@PJL[ \t]+ENTER[ \t]+LANGUAGE[ \t]*=[ \t]*\"?HPGL2", re.I)\
                    .search(data, i, n if j < 0 else j)
                if m:
                    self.in_hpgl = True
                    self.hpgl2 = True
                    i = m.end()
                    continue
                i = n if j < 0 else j
                continue
            if not (65 <= c <= 90 or 97 <= c <= 122) or i + 1 >= n or \
                    not (65 <= data[i + 1] <= 90 or 97 <= data[i + 1] <= 122):
                i += 1
                continue
            mn = data[i : i + 2].decode().upper()
            i += 2
            i = self.instruction(mn, i)

    in_hpgl = False

    def escape(self, i: int) -> int:
        """PCL escapes (PCL5 Technical Reference, Part I): ESC%#B enters HP-GL/2, ESC%#A
        and ESC E leave it; parameterised escapes ending in W carry # bytes of data, as
        does ESC&p#X (transparent print data). HP 7475A device control ESC.x...: skipped."""
        data = self.data
        m = re.compile(rb"\x1b%-?(\d*)([AB])").match(data, i)
        if m:
            self.in_hpgl = m.group(2) == b"B"
            self.hpgl2 = self.hpgl2 or self.in_hpgl
            return m.end()
        m = re.compile(rb"\x1b\.(?:[@-Z(){}][0-9;.\s]*:?)").match(data, i)
        if m:
            return m.end()
        m = re.compile(rb"\x1b([!-/])([`-~]?)((?:[+-]?[0-9.]*[`-~])*)([+-]?[0-9.]*)([@-^])")\
            .match(data, i)
        if m:
            end = m.end()
            last = m.group(5)
            if last == b"W" or (m.group(1) + m.group(2) == b"&p" and last == b"X"):
                try:
                    end += int(float(m.group(4) or b"0"))
                except ValueError:
                    pass
            return end
        if data[i + 1 : i + 2] == b"E":
            self.in_hpgl = False
        return i + 2

    def params(self, i: int) -> tuple[list[float], int]:
        """Numbers up to ';', the next letter or ESC."""
        data = self.data
        j = i
        n = len(data)
        while j < n and data[j] != 59 and data[j] != 27 and not \
                (65 <= data[j] <= 90 or 97 <= data[j] <= 122):
            j += 1
        v = [min(max(float(t), -1e15), 1e15) for t in NUM.findall(data, i, j)]
        return v, (j + 1 if j < n and data[j] == 59 else j)

    def instruction(self, mn: str, i: int) -> int:
        data = self.data
        if mn in HPGL2_ONLY:
            self.hpgl2 = True
        if mn in ("LB", "BL", "WD"):
            j = data.find(bytes((self.term,)), i)
            eol = data.find(b"\n", i)
            if j < 0:  # decision: an unterminated label ends at its line's end
                j = n1 = (len(data) if eol < 0 else eol)
            else:
                n1 = j + 1
            if mn == "LB":
                self.label(data[i:j])
            return n1
        if mn == "PE":
            return self.pe(i)
        if mn == "DT":
            j = i
            while j < len(data) and data[j] in b" ":
                j += 1
            if j < len(data) and data[j] != 59:
                self.term = data[j]
                j += 1
            else:
                self.term = 3
            if j < len(data) and data[j] == 44:  # DT t,mode
                _, j = self.params(j)
            elif j < len(data) and data[j] == 59:
                j += 1
            return j
        if mn == "SM":
            return i + 1 if i < len(data) and data[i] != 59 else i + 1
        if mn == "CO":
            j = i
            while j < len(data) and data[j] in b" \t":
                j += 1
            if j < len(data) and data[j] == 34:
                k = data.find(b'"', j + 1)
                if k < 0:
                    k = data.find(b"\n", j)
                return len(data) if k < 0 else k + 1
            m = re.compile(rb"[^;\r\n" + re.escape(bytes((self.term,))) + rb"]*").match(data, i)
            return min(m.end() + 1, len(data))
        v, i = self.params(i)
        getattr(self, "do_" + mn, self.nothing)(v, mn)
        return i

    def nothing(self, v: list[float], mn: str) -> None:
        pass

    # moves (PCL5-II ch. 20)
    def pairs(self, v: list[float], relative: bool) -> None:
        for k in range(0, len(v) - 1, 2):
            if relative:
                dx, dy = v[k], v[k + 1]
                if self.scale is not None:
                    dx, dy = self.scale[0] * dx, self.scale[2] * dy
                self.move(self.x + dx, self.y + dy)
            else:
                self.move(*self.user_to_plotter(v[k], v[k + 1]))

    def do_PU(self, v: list[float], mn: str) -> None:
        self.pen(False)
        self.pairs(v, not self.absolute)

    def do_PD(self, v: list[float], mn: str) -> None:
        self.pen(True)
        self.pairs(v, not self.absolute)

    def do_PA(self, v: list[float], mn: str) -> None:
        self.absolute = True
        self.pairs(v, False)

    def do_PR(self, v: list[float], mn: str) -> None:
        self.absolute = False
        self.pairs(v, True)

    def do_SP(self, v: list[float], mn: str) -> None:
        """PCL5-II 17-21: the pen stays down in HP-GL/2; a 7475A stores the pen (up)."""
        if not self.hpgl2:
            self.down = False

    def do_IN(self, v: list[float], mn: str) -> None:
        self.initialize()

    def do_DF(self, v: list[float], mn: str) -> None:
        self.defaults()

    def do_IP(self, v: list[float], mn: str) -> None:
        if len(v) >= 4:
            self.p1, self.p2 = (v[0], v[1]), (v[2], v[3])
        elif len(v) >= 2:
            dx, dy = self.p2[0] - self.p1[0], self.p2[1] - self.p1[1]
            self.p1, self.p2 = (v[0], v[1]), (v[0] + dx, v[1] + dy)
        else:
            self.p1, self.p2 = ((0.0, 0.0), self.page) if self.page else \
                ((250.0, 596.0), (10250.0, 7796.0))
        self.set_scale()

    def do_IR(self, v: list[float], mn: str) -> None:
        """IR: P1 (and P2) in % of the hard-clip limits; with two numbers P2 keeps its
        distance to P1."""
        lo, hi = ((0.0, 0.0), self.page) if self.page else ((250.0, 596.0), (10250.0, 7796.0))
        w, h = hi[0] - lo[0], hi[1] - lo[1]
        if len(v) >= 4:
            self.p1 = (lo[0] + v[0] / 100 * w, lo[1] + v[1] / 100 * h)
            self.p2 = (lo[0] + v[2] / 100 * w, lo[1] + v[3] / 100 * h)
        elif len(v) >= 2:
            dx, dy = self.p2[0] - self.p1[0], self.p2[1] - self.p1[1]
            self.p1 = (lo[0] + v[0] / 100 * w, lo[1] + v[1] / 100 * h)
            self.p2 = (self.p1[0] + dx, self.p1[1] + dy)
        else:
            self.p1, self.p2 = lo, hi
        self.set_scale()

    def do_SC(self, v: list[float], mn: str) -> None:
        self.sc_args = v if len(v) >= 4 else None
        self.set_scale()

    def do_PS(self, v: list[float], mn: str) -> None:
        """PS length[,width] (PCL5-II ch. 19): a length <= 0 is ignored; decision: P1/P2
        become the page corners."""
        if not v or v[0] <= 0:
            return
        w = v[0]
        h = v[1] if len(v) > 1 and v[1] > 0 else w
        self.page = (w, h)
        self.p1, self.p2 = (0.0, 0.0), (w, h)
        self.set_scale()

    def do_RO(self, v: list[float], mn: str) -> None:
        r = int(v[0]) if v else 0
        if r in (0, 90, 180, 270):
            self.rot = r

    def do_IW(self, v: list[float], mn: str) -> None:
        """IW xll,yll,xur,yur in current units; none: the hard-clip limits (decision: the
        PS page, none without PS or under RO)."""
        if len(v) >= 4:
            a = self.user_to_plotter(v[0], v[1])
            b = self.user_to_plotter(v[2], v[3])
            self.window = (min(a[0], b[0]), min(a[1], b[1]), max(a[0], b[0]), max(a[1], b[1]))
        elif self.page and self.rot == 0:
            self.window = (0.0, 0.0, self.page[0], self.page[1])
        else:
            self.window = None

    def do_CT(self, v: list[float], mn: str) -> None:
        self.chord_tol = bool(v and int(v[0]) == 1)

    def do_SI(self, v: list[float], mn: str) -> None:
        self.char_rel = None
        self.char = (v[0] * 400, v[1] * 400) if len(v) >= 2 else (0.187 * 400, 0.269 * 400)

    def do_SR(self, v: list[float], mn: str) -> None:
        self.char_rel = (v[0], v[1]) if len(v) >= 2 else (0.75, 1.5)

    def do_DI(self, v: list[float], mn: str) -> None:
        run, rise = (v[0], v[1]) if len(v) >= 2 else (1.0, 0.0)
        if mn == "DR":
            run *= (self.p2[0] - self.p1[0]) / 100
            rise *= (self.p2[1] - self.p1[1]) / 100
        r = math.hypot(run, rise)
        self.direction = (run / r, rise / r) if r > 0 else (1.0, 0.0)

    do_DR = do_DI

    def do_LO(self, v: list[float], mn: str) -> None:
        pos = int(v[0]) if v else 1
        if pos in (*range(1, 10), *range(11, 20), 21):
            self.origin = pos

    # figures and arcs (PCL5-II ch. 20, 21)
    def here_user(self) -> tuple[float, float]:
        return self.plotter_to_user(self.x, self.y)

    def do_CI(self, v: list[float], mn: str) -> None:
        if not v:
            return
        cx, cy = self.here_user()
        r = v[0]
        pts = self.arc_points(cx, cy, cx + r, cy, 360.0, v[1] if len(v) > 1 else None)
        self.figure([self.user_to_plotter(cx + r, cy)] + pts)

    def do_AA(self, v: list[float], mn: str) -> None:
        if len(v) < 3:
            return
        cx, cy = v[0], v[1]
        if mn == "AR":
            ux, uy = self.here_user()
            cx, cy = ux + v[0], uy + v[1]
        self.follow(self.arc_points(cx, cy, *self.here_user(), v[2],
                                    v[3] if len(v) > 3 else None))

    do_AR = do_AA

    def do_AT(self, v: list[float], mn: str) -> None:
        """AT/RT: the arc from here through (x1, y1) to (x2, y2); on a line: a line."""
        if len(v) < 4:
            return
        x0, y0 = self.here_user()
        (x1, y1), (x2, y2) = (v[0], v[1]), (v[2], v[3])
        if mn == "RT":
            x1, y1, x2, y2 = x0 + x1, y0 + y1, x0 + x2, y0 + y2
        d = 2 * (x0 * (y1 - y2) + x1 * (y2 - y0) + x2 * (y0 - y1))
        if d == 0:
            self.follow([self.user_to_plotter(x2, y2)])
            return
        s0, s1, s2 = x0 * x0 + y0 * y0, x1 * x1 + y1 * y1, x2 * x2 + y2 * y2
        cx = (s0 * (y1 - y2) + s1 * (y2 - y0) + s2 * (y0 - y1)) / d
        cy = (s0 * (x2 - x1) + s1 * (x0 - x2) + s2 * (x1 - x0)) / d
        a0 = math.atan2(y0 - cy, x0 - cx)
        a1 = math.atan2(y1 - cy, x1 - cx)
        a2 = math.atan2(y2 - cy, x2 - cx)
        sweep = (a2 - a0) % (2 * math.pi)
        if (a1 - a0) % (2 * math.pi) > sweep:  # through (x1, y1): the other way round
            sweep -= 2 * math.pi
        self.follow(self.arc_points(cx, cy, x0, y0, math.degrees(sweep),
                                    v[4] if len(v) > 4 else None))

    do_RT = do_AT

    def do_EA(self, v: list[float], mn: str) -> None:
        if len(v) < 2:
            return
        x0, y0 = self.here_user()
        x1, y1 = (x0 + v[0], y0 + v[1]) if mn in ("ER", "RR") else (v[0], v[1])
        self.figure([self.user_to_plotter(*p)
                     for p in ((x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0))])

    do_ER = do_RA = do_RR = do_EA

    def do_EW(self, v: list[float], mn: str) -> None:
        """EW/WG r,start,sweep[,chord]: radius from here at the start angle, the arc, the
        radius back; a 360-degree sweep is a circle."""
        if len(v) < 3:
            return
        cx, cy = self.here_user()
        r, a0, sweep = v[0], math.radians(v[1]), max(min(v[2], 360.0), -360.0)
        sx, sy = cx + r * math.cos(a0), cy + r * math.sin(a0)
        arc = self.arc_points(cx, cy, sx, sy, sweep, v[3] if len(v) > 3 else None)
        start = self.user_to_plotter(sx, sy)
        if abs(sweep) >= 360:
            self.figure([start] + arc)
        else:
            c = self.user_to_plotter(cx, cy)
            self.figure([c, start] + arc + [c])

    do_WG = do_EW

    def do_BZ(self, v: list[float], mn: str) -> None:
        """BZ/BR: cubic Béziers from here, three control points each."""
        for k in range(0, len(v) - 5, 6):
            p0 = self.here_user()
            c = [(v[k + 2 * j], v[k + 2 * j + 1]) for j in range(3)]
            if mn == "BR":
                c = [(p0[0] + a, p0[1] + b) for a, b in c]
            pts = []
            for s in range(1, 65):
                t = s / 64
                u = 1 - t
                pts.append(self.user_to_plotter(
                    u**3 * p0[0] + 3 * u * u * t * c[0][0] + 3 * u * t * t * c[1][0]
                    + t**3 * c[2][0],
                    u**3 * p0[1] + 3 * u * u * t * c[0][1] + 3 * u * t * t * c[1][1]
                    + t**3 * c[2][1]))
            self.follow(pts)

    do_BR = do_BA = do_BZ

    def do_XT(self, v: list[float], mn: str) -> None:
        """XT/YT: a tick through the current point, tp/tn % of P2 - P1 (TL, 0.5 %)."""
        (p1x, p1y), (p2x, p2y) = self.p1, self.p2
        tp, tn = self.tick
        if mn == "XT":
            h = abs(p2y - p1y) / 100
            pts = [(self.x, self.y + tp * h), (self.x, self.y - tn * h)]
        else:
            w = abs(p2x - p1x) / 100
            pts = [(self.x + tp * w, self.y), (self.x - tn * w, self.y)]
        if self.poly is None:
            self.polyline(pts)

    do_YT = do_XT

    def do_TL(self, v: list[float], mn: str) -> None:
        self.tick = (v[0], v[1] if len(v) > 1 else 0.0) if v else (0.5, 0.5)

    # polygon mode (PCL5-II 21-34 to 21-37)
    def do_PM(self, v: list[float], mn: str) -> None:
        mode = int(v[0]) if v else 0
        if mode == 0:
            self.poly = [([(self.x, self.y)], [])]
            self.fresh = False
            self.edged = None
            self.filled = False
        elif self.poly is not None:
            ring, downs = self.poly[-1]
            downs.append(self.down)  # PM1/PM2 close with the current pen state
            if mode == 1:
                self.fresh = True
                self.poly.append(([(self.x, self.y)], []))
            elif mode == 2:
                self.buffer = [(r, d) for r, d in self.poly if len(r) > 1]
                self.poly = None

    def do_EP(self, v: list[float], mn: str) -> None:
        self.edge_fill(mn)

    do_FP = do_EP

    # PE (PCL5-II ch. 20, PE)
    def pe(self, i: int) -> int:
        """Polyline encoded: flags ':' pen select, '<' pen up, '>' fractional bits, '='
        absolute, '7' seven-bit mode; numbers base 64 (bytes 63-126 then a terminator
        191-254) or base 32 in seven-bit mode (63-94, terminator 95-126), sign in the
        lowest bit. Pairs without '<' are drawn; decision: a PE that ends with a pen-up
        move leaves the pen up."""
        data = self.data
        n = len(data)
        seven = False
        frac = 0
        flag = None
        up = absolute = False
        nums: list[float] = []
        while i < n:
            c = data[i]
            if c == 59:
                i += 1
                break
            if c == 27:
                break
            if c in (55, 58, 60, 61, 62):  # 7 : < = >
                if c == 55:
                    seven = True
                elif c == 60:
                    up = True
                elif c == 61:
                    absolute = True
                else:
                    flag = c
                i += 1
                continue
            lo, hi, base, tlo, thi = (63, 94, 32, 95, 126) if seven else (63, 126, 64, 191, 254)
            if lo <= c <= hi or tlo <= c <= thi:
                value, mult = 0, 1
                while i < n:
                    c = data[i]
                    if lo <= c <= hi:
                        value += (c - lo) * mult
                        mult *= base
                        i += 1
                    elif tlo <= c <= thi:
                        value += (c - tlo) * mult
                        i += 1
                        break
                    else:
                        i += 1  # ignored bytes inside a number
                num = -(value >> 1) if value & 1 else value >> 1
                num = max(min(num, 10**15), -(10**15))
                if flag == 58:  # ':' pen
                    flag = None
                    nums = []
                elif flag == 62:  # '>' fractional bits
                    flag = None
                    if 0 <= num <= 26:
                        frac = num
                else:
                    nums.append(num / 2**frac)
                    if len(nums) == 2:
                        x, y = nums
                        nums = []
                        if up:
                            self.pen(False)
                        elif not self.down:
                            self.pen(True)
                        if absolute:
                            self.move(*self.user_to_plotter(x, y))
                        else:
                            if self.scale is not None:
                                x, y = self.scale[0] * x, self.scale[2] * y
                            self.move(self.x + x, self.y + y)
                        up = absolute = False
                continue
            i += 1
        return i


def decode(data: bytes) -> tuple[float, tuple[float, ...] | None]:
    dec = Decoder(data)
    dec.run()
    return dec.out.result()


def files() -> list[str]:
    return sorted(p.name for p in PLT.iterdir() if p.is_file() and "__expected" not in p.name)


@pytest.mark.parametrize("name", files())
def test_pen_down_length_and_extent_agree_with_the_independent_decoder(name: str) -> None:
    try:
        d = read_file(PLT / name)
    except InputError:
        pytest.skip("not HP-GL: refused (tests/test_corpus.py checks which)")
    their_len, their_box = decode((PLT / name).read_bytes())
    our_len = sum(p.length for p in d.paths)
    our_box = d.bbox()
    assert our_len == pytest.approx(their_len, rel=0.01, abs=1e-6)
    if their_box is None:
        assert our_box is None
        return
    assert our_box is not None
    size = max(their_box[2] - their_box[0], their_box[3] - their_box[1], 1.0)
    assert max(abs(a - b) for a, b in zip(our_box, their_box, strict=True)) <= 0.01 * size, \
        (our_box, their_box)


# the minimal reproducers and a few more constructs real files use
SNIPPETS = [
    b"IN;SP1;PA0,0;PM0;PD;PA100,0,100,100;PU;PM2;EP;",  # plotutils: open polyline in PM
    b"IN;PS0;IW;SP1;PU100,100;PD1000,1000;",  # PS <= 0 ignored
    b"\x1bE\x1b*p300X\x1b%1BIN;SP1;PU0,0;PD1000,0;",  # ESC*p#X carries no data
    b"IN;SP1;PU0,0;LBABC\x03;PD;PR100,0;",  # LB moves the pen
    b"BP;IN;SP1;PU0,0;PD100,0;SP2;PA200,0;",  # HP-GL/2: SP keeps the pen down
    b"IN;SP1;PU0,0;PD100,0;SP2;PA200,0;",  # HP-GL/1: SP stores the pen
    b"IN;PU0,0;PD100,0;",  # no SP
    b"IN;SP1;PU0,0;LO16;LBABC\x03;PD;PR100,0;LO13;LBAB\x03PD;PR0,50;",
    b"IN;SP1;SC0,100,0,100;PU10,10;PD50,10;CI20;AA10,10,90,10;EA90,90;",
    b"IN;SP1;IW100,100,500,500;PU0,0;PD600,600;RO90;PU0,0;PD-300,200;",
    b"IN;SP1;PA0,0;PM0;PD100,0,100,100,0,100;PM1;PA20,20;PD40,20,40,40;PM2;FP;EP;",
    b"IN;SP1;PU0,0;PE7<=__Ge_Ge_;",  # PE, seven-bit: up to 0,0, then +100,0 twice
    b"IN;SP1;PE<=\xbf\xbfG\xc2\xbf;",  # PE, eight-bit: the same first side
    b"IN;SP1;PU0,0;PD;BZ0,100,100,100,100,0;",
    b"IN;SP1;PU500,500;EW200,0,270;WG100,90,90;",
    b"IN;SP1;PU0,0;PD;AT100,100,200,0;",
]


@pytest.mark.parametrize("data", SNIPPETS)
def test_snippets_agree_with_the_independent_decoder(data: bytes) -> None:
    from galvo_core.hpgl import read_bytes

    d = read_bytes(data, "snippet.plt")
    their_len, their_box = decode(data)
    assert sum(p.length for p in d.paths) == pytest.approx(their_len, rel=0.01, abs=1e-6)
    assert their_len > 0
    size = max(their_box[2] - their_box[0], their_box[3] - their_box[1], 1.0)
    assert max(abs(a - b) for a, b in zip(d.bbox(), their_box, strict=True)) <= 0.01 * size
