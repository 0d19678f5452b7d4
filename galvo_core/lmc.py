"""BJJCZ ("LMC", the boards EzCad2 drives) list commands: a job as 12-byte records.

A list is a flat sequence of records, each six little-endian 16-bit words: the command word
(0x8001 jump, 0x8005 mark, 0x800C mark speed, ...) and five parameter words. The words and
units are those of the open drivers (galvoplotter, MeerK40t's galvo driver), and the
encoder writes what galvoplotter's ``GalvoController`` sends for the same job, word for word
(tests/test_lmc.py checks it against galvoplotter itself):

* the list opens as galvoplotter's marking mode does: ready-mark (0x8051), for a fiber
  source a delay (0x8004) of the MO opening time in 10 µs units, the port word with the laser
  bit on (0x8011);
* each layer's settings before its strokes, in galvoplotter's ``set()`` order: jump speed,
  [fiber: pulse width if set, mark current, Q-switch period | CO2: frequency, power ratio],
  mark speed, laser-on delay, laser-off delay, polygon delay. Like the drivers, a word is
  written only when it changes (a layer with the same jump speed as the one before it writes
  no new jump speed);
* units: speeds in bits/ms, ``int(mm_s * bits_per_mm / 1000)``, with the job's own
  ``bits_per_mm = field bits / field size_mm``; fiber power as mark current
  ``round(% * 4095 / 100)``; fiber frequency as Q-switch period ``round(20000 / kHz)``; CO2
  frequency ``round(10000 / kHz)`` and power ratio ``round(200 * % / kHz)``; delays in µs
  (whole µs, as the drivers truncate them; a second word 0x8000 marks a delay <= 0);
* every stroke: the jump delay (short, or long past ``long_jump_mm``, when it changes), a
  jump (0x8001 X, Y, 0, distance) to its first mark — always, even of length 0, so that a
  reader finds every stroke — then a mark (0x8005 X, Y, 0, distance) to each further mark
  (a mark at the position the beam is already at is dropped, as the drivers do: it would
  only hold the beam still); a stroke of one mark fires one laser-on-point (0x8003) of
  ``point_period_us`` in 10 µs units;
* passes repeat a layer's strokes; disabled layers are left out; one end-of-list (0x8002)
  closes the list.

``mark_delay_us`` (the mark-end delay) has no list command in these drivers; it counts in
the time estimate only.

Orientation (swap x/y, then flip x, flip y) is applied here, at export. A mark outside
0..65535 after it is refused (:class:`~galvo_core.errors.InputError` naming the stroke and
the mark): the drivers silently drop such moves.

:func:`to_text` writes the same list as MeerK40t's readable dump (one record per line,
``8001:8000:8000:0000:0000:0000 listJumpTo``) for diffs. :func:`decode` is an independent
reader used by the tests (it shares no code with the encoder).
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from galvo_core.errors import InputError, ParamError
from galvo_core.job import Job, Stroke
from galvo_core.layers import LASER_KEYS, LayerSettings, PenTable, pen_table_from_layers
from galvo_core.params import LaserParams

RECORD = 12

JUMP_TO = 0x8001
END_OF_LIST = 0x8002
LASER_ON_POINT = 0x8003
DELAY_TIME = 0x8004
MARK_TO = 0x8005
JUMP_SPEED = 0x8006
LASER_ON_DELAY = 0x8007
LASER_OFF_DELAY = 0x8008
MARK_FREQ = 0x800A
MARK_POWER_RATIO = 0x800B
MARK_SPEED = 0x800C
JUMP_DELAY = 0x800D
POLYGON_DELAY = 0x800F
WRITE_PORT = 0x8011
MARK_CURRENT = 0x8012
QSWITCH_PERIOD = 0x801B
FIBER_PULSE_WIDTH = 0x8026
READY_MARK = 0x8051

NAMES = {
    JUMP_TO: "listJumpTo", END_OF_LIST: "listEndOfList", LASER_ON_POINT: "listLaserOnPoint",
    DELAY_TIME: "listDelayTime", MARK_TO: "listMarkTo", JUMP_SPEED: "listJumpSpeed",
    LASER_ON_DELAY: "listLaserOnDelay", LASER_OFF_DELAY: "listLaserOffDelay",
    MARK_FREQ: "listMarkFreq", MARK_POWER_RATIO: "listMarkPowerRatio",
    MARK_SPEED: "listMarkSpeed", JUMP_DELAY: "listJumpDelay",
    POLYGON_DELAY: "listPolygonDelay", WRITE_PORT: "listWritePort",
    MARK_CURRENT: "listMarkCurrent", QSWITCH_PERIOD: "listQSwitchPeriod",
    FIBER_PULSE_WIDTH: "listFiberYLPMPulseWidth", READY_MARK: "listReadyMark",
}

FIELD_MAX = 0xFFFF
CENTRE = 0x8000  # where the drivers assume the beam starts


@dataclass(frozen=True, slots=True)
class Orientation:
    """How the job's X/Y reach the galvos: swap X and Y first, then mirror X, then Y."""

    swap_xy: bool = False
    flip_x: bool = False
    flip_y: bool = False

    def apply(self, marks: np.ndarray, max_bit: int = FIELD_MAX) -> np.ndarray:
        m = np.asarray(marks, dtype=np.int64).reshape(-1, 2)
        if self.swap_xy:
            m = m[:, ::-1]
        if self.flip_x or self.flip_y:
            m = m.copy()
            if self.flip_x:
                m[:, 0] = max_bit - m[:, 0]
            if self.flip_y:
                m[:, 1] = max_bit - m[:, 1]
        return m

    @property
    def is_identity(self) -> bool:
        return not (self.swap_xy or self.flip_x or self.flip_y)


@dataclass(frozen=True, slots=True)
class Board:
    """The controller's wiring and the list preamble (galvoplotter's defaults)."""

    laser_pin: int = 0
    light_pin: int = 8
    open_mo_delay_ms: float = 8.0  # fiber: wait after opening the master oscillator


AS_IS = Orientation()
DEFAULT_BOARD = Board()


# ---------------------------------------------------------------------------- units
def speed_word(mm_s: float, bits_per_mm: float) -> int:
    """Speed in bits per ms, as the drivers convert it (truncated, at most 0xFFFF)."""
    return min(int(mm_s * abs(bits_per_mm) / 1000.0), FIELD_MAX)


def current_word(power_percent: float) -> int:
    """Fiber power (0..100 %) as the mark current word, 0..4095."""
    return int(round(power_percent * 0xFFF / 100.0))


def period_word(frequency_khz: float, base: float) -> int:
    """Frequency as a period word: ``round(base / kHz)`` (20000 fiber Q-switch, 10000 CO2)."""
    return int(round(base / frequency_khz)) & 0xFFFF


def delay_words(delay_us: float, what: str) -> tuple[int, int]:
    """A delay in whole µs and its sign word (0x8000 for <= 0, as the drivers write it)."""
    v = int(abs(delay_us))
    if v > FIELD_MAX:
        raise ParamError(f"{what} {delay_us:g} µs is longer than the controller's "
                         f"{FIELD_MAX} µs")
    return v, (0x0000 if delay_us > 0 else 0x8000)


def bits_per_mm(job: Job) -> float:
    return job.field_map.field_bits / job.field_map.field_size_mm


# ---------------------------------------------------------------------------- the list
class ListWriter:
    """Records (N, 6) uint16 under construction, with the settings already on the board
    (a word is written only when it changes) and the beam's position."""

    def __init__(self, bits_per_mm: float, source: str = "fiber", board: Board = DEFAULT_BOARD):
        if source not in ("fiber", "co2"):
            raise ParamError(f"source must be fiber or co2, not {source!r}")
        self.bits_per_mm = bits_per_mm
        self.source = source
        self.board = board
        self.chunks: list[np.ndarray] = []
        self.state: dict[int, tuple[int, ...]] = {}
        self.x, self.y = CENTRE, CENTRE

    # -- raw
    def write(self, cmd: int, *words: int) -> None:
        row = np.zeros((1, 6), dtype=np.uint16)
        row[0, 0] = cmd
        row[0, 1:1 + len(words)] = words
        self.chunks.append(row)

    def _set(self, cmd: int, *words: int) -> None:
        if self.state.get(cmd) != words:
            self.state[cmd] = words
            self.write(cmd, *words)

    # -- list preamble
    def begin_marking(self) -> None:
        self.write(READY_MARK)
        if self.source == "fiber" and self.board.open_mo_delay_ms:
            self.write(DELAY_TIME, int(self.board.open_mo_delay_ms * 100))
        self.write(WRITE_PORT, 1 << self.board.laser_pin)

    def begin_lighting(self) -> None:
        self.write(READY_MARK)
        self.write(WRITE_PORT, 1 << self.board.light_pin)

    # -- settings
    def jump_speed(self, mm_s: float) -> None:
        if mm_s:
            self._set(JUMP_SPEED, speed_word(mm_s, self.bits_per_mm))

    def settings(self, layer: LayerSettings) -> None:
        """A layer's laser settings (only the words that change)."""
        las = layer.laser
        self.jump_speed(las.jump_speed_mm_s)
        if self.source == "co2":
            self._set(MARK_FREQ, period_word(las.frequency_khz, 10000.0))
            self._set(MARK_POWER_RATIO, int(round(200 * las.power_percent / las.frequency_khz)))
        else:
            if layer.pulse_width_ns is not None:
                self._set(FIBER_PULSE_WIDTH, int(layer.pulse_width_ns))
            self._set(MARK_CURRENT, current_word(las.power_percent))
            self._set(QSWITCH_PERIOD, period_word(las.frequency_khz, 20000.0))
        self._set(MARK_SPEED, speed_word(las.mark_speed_mm_s, self.bits_per_mm))
        self._set(LASER_ON_DELAY, *delay_words(las.laser_on_delay_us, "laser_on_delay_us"))
        self._set(LASER_OFF_DELAY, *delay_words(las.laser_off_delay_us, "laser_off_delay_us"))
        self._set(POLYGON_DELAY, *delay_words(las.polygon_delay_us, "polygon_delay_us"))

    # -- moves
    def jump(self, x: int, y: int, laser: LaserParams) -> None:
        """A jump with the jump delay the drivers choose (long past ``long_jump_mm``)."""
        dist = int(abs(complex(x, y) - complex(self.x, self.y)))
        limit = laser.long_jump_mm * self.bits_per_mm
        delay = laser.jump_delay_long_us if limit and dist > limit else laser.jump_delay_us
        if delay:
            self._set(JUMP_DELAY, *delay_words(delay, "jump delay"))
        self.write(JUMP_TO, x, y, 0, min(dist, FIELD_MAX))
        self.x, self.y = int(x), int(y)

    def marks(self, pts: np.ndarray) -> None:
        """Marks from the current position through ``pts`` (K, 2), repeated points dropped."""
        p = np.asarray(pts, dtype=np.int64).reshape(-1, 2)
        full = np.vstack([[self.x, self.y], p])
        d = np.diff(full, axis=0)
        keep = (d != 0).any(axis=1)
        if not keep.any():
            return
        full = np.vstack([[self.x, self.y], p[keep]])
        d = np.diff(full, axis=0).astype(np.float64)
        dist = np.minimum(np.hypot(d[:, 0], d[:, 1]).astype(np.int64), FIELD_MAX)
        rows = np.zeros((len(dist), 6), dtype=np.uint16)
        rows[:, 0] = MARK_TO
        rows[:, 1] = full[1:, 0]
        rows[:, 2] = full[1:, 1]
        rows[:, 4] = dist
        self.chunks.append(rows)
        self.x, self.y = int(full[-1, 0]), int(full[-1, 1])

    def strokes(self, allm: np.ndarray, sizes: np.ndarray, laser: LaserParams) -> None:
        """Many strokes at once, the same records as :meth:`jump` to each stroke's first
        mark then :meth:`marks` (or :meth:`dot`) for each, in whole arrays: ``allm`` (N, 2)
        their marks concatenated, ``sizes`` (K,) their lengths (each >= 1)."""
        sizes = np.asarray(sizes, dtype=np.int64)
        n = len(sizes)
        if n == 0:
            return
        allm = np.asarray(allm, dtype=np.int64).reshape(-1, 2)
        sid = np.repeat(np.arange(n), sizes)
        first = np.zeros(len(allm), dtype=bool)
        first[np.cumsum(sizes) - sizes] = True
        keep = np.ones(len(allm), dtype=bool)
        keep[1:] = ~((allm[1:] == allm[:-1]).all(axis=1) & ~first[1:])
        m, first, sid = allm[keep], first[keep], sid[keep]
        prev = np.empty_like(m)
        prev[0] = (self.x, self.y)
        prev[1:] = m[:-1]
        d = (m - prev).astype(np.float64)
        dist = np.hypot(d[:, 0], d[:, 1]).astype(np.int64)
        rows = np.zeros((len(m), 6), dtype=np.uint16)
        rows[:, 0] = np.where(first, JUMP_TO, MARK_TO)
        rows[:, 1:3] = m
        rows[:, 4] = np.minimum(dist, FIELD_MAX)
        keys = [2 * np.arange(len(m))]
        parts = [rows]
        fi = np.flatnonzero(first)
        # strokes left with one mark: a laser-on point after their jump
        dots = fi[np.bincount(sid, minlength=n) == 1]
        if len(dots):
            drow = np.zeros((len(dots), 6), dtype=np.uint16)
            drow[:, 0] = LASER_ON_POINT
            drow[:, 1] = max(1, int(round(laser.point_period_us / 10.0)))
            keys.append(2 * dots + 1)
            parts.append(drow)
        # jump delays: short or long by the (uncapped) distance; written when they change
        limit = laser.long_jump_mm * self.bits_per_mm
        words: list[tuple[int, int]] = []
        code = np.full(len(fi), -1, dtype=np.int64)
        far = (dist[fi] > limit) if limit else np.zeros(len(fi), dtype=bool)
        for sel, delay in ((~far, laser.jump_delay_us), (far, laser.jump_delay_long_us)):
            if not delay:
                continue  # no delay word for these jumps (the drivers write none)
            wd = delay_words(delay, "jump delay")
            if wd not in words:
                words.append(wd)
            code[sel] = words.index(wd)
        init = self.state.get(JUMP_DELAY)
        init_code = words.index(init) if init in words else -2
        last = np.where(code >= 0, np.arange(len(fi)), -1)
        np.maximum.accumulate(last, out=last)
        after = np.where(last >= 0, code[np.maximum(last, 0)], init_code)
        before = np.concatenate([[init_code], after[:-1]])
        emit = (code >= 0) & (code != before)
        if emit.any():
            jrow = np.zeros((int(emit.sum()), 6), dtype=np.uint16)
            jrow[:, 0] = JUMP_DELAY
            jrow[:, 1:3] = np.array(words, dtype=np.uint16)[code[emit]]
            keys.append(2 * fi[emit] - 1)
            parts.append(jrow)
        if after[-1] >= 0:
            self.state[JUMP_DELAY] = words[int(after[-1])]
        order = np.argsort(np.concatenate(keys), kind="stable")
        self.chunks.append(np.concatenate(parts)[order])
        self.x, self.y = int(m[-1, 0]), int(m[-1, 1])

    def dot(self, laser: LaserParams) -> None:
        self.write(LASER_ON_POINT, max(1, int(round(laser.point_period_us / 10.0))))

    def end(self) -> np.ndarray:
        self.write(END_OF_LIST)
        return np.concatenate(self.chunks) if self.chunks else np.zeros((0, 6), np.uint16)


def job_pen_table(job: Job, pens: PenTable | None = None, name: str | None = None
                  ) -> PenTable:
    """The pen table a job is marked with: ``pens`` if given, else the job's own ``layers``
    table, else its one ``laser`` setting for every pen. A table the job holds that cannot
    be used raises InputError naming ``name`` (default: the job's source)."""
    if pens is not None:
        return pens
    where = name or job.source_name
    if job.layers:
        return pen_table_from_layers(job.layers, job.laser_source, where)
    try:
        return PenTable.from_laser(LaserParams(**{k: float(v) for k, v in job.laser.items()
                                                  if k in LASER_KEYS}))
    except (ParamError, TypeError, ValueError) as exc:
        raise InputError(where, f"laser: {exc}") from None


def write_lmc(job: Job, path: str, pens: PenTable | None = None,
              orientation: Orientation = AS_IS, text: bool = False) -> int:
    """Encode ``job`` and write it atomically (the GUI's File > Export): the records, or with
    ``text`` MeerK40t's readable dump. Returns the number of records."""
    from galvo_core.job import atomic_write_bytes

    rec = encode_job(job, pens, orientation)
    atomic_write_bytes(path, to_text(rec).encode("ascii") if text else to_bytes(rec))
    return len(rec)


def layer_order(job: Job, pens: PenTable) -> list[tuple[LayerSettings, list[int]]]:
    """The export order: layers by pen number, each with its strokes' indices in job order
    (disabled layers included, for the caller to skip)."""
    by_pen: dict[int, list[int]] = {}
    for i, s in enumerate(job.strokes):
        by_pen.setdefault(int(s.pen), []).append(i)
    return [(pens.settings(p), by_pen[p]) for p in sorted(by_pen)]


def check_field(marks: np.ndarray, where: str, name: str) -> None:
    bad = np.flatnonzero(((marks < 0) | (marks > FIELD_MAX)).any(axis=1))
    if len(bad):
        k = int(bad[0])
        x, y = (int(v) for v in marks[k])
        raise InputError(name, f"{where} mark {k} ({x}, {y}) is outside the controller's "
                               f"field 0..{FIELD_MAX}; nothing was written")


def oriented_marks(job: Job, orientation: Orientation = AS_IS
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Every stroke's marks as the galvos get them, concatenated (N, 2), and the strokes'
    start offsets (K + 1,), checked against 0..65535 (InputError naming the stroke and the
    mark otherwise)."""
    if job.field_map.field_bits > FIELD_MAX + 1:
        raise InputError(job.source_name, f"the job's field has {job.field_map.field_bits} "
                                          f"bits; the controller takes at most {FIELD_MAX + 1}")
    sizes = np.fromiter((len(s.marks) for s in job.strokes), dtype=np.int64,
                        count=len(job.strokes))
    off = np.concatenate([[0], np.cumsum(sizes)])
    if not off[-1]:
        return np.zeros((0, 2), dtype=np.int64), off
    allm = orientation.apply(np.concatenate([np.asarray(s.marks).reshape(-1, 2)
                                             for s in job.strokes]), job.field_map.max_bit)
    bad = np.flatnonzero(((allm < 0) | (allm > FIELD_MAX)).any(axis=1))
    if len(bad):
        k = int(np.searchsorted(off, bad[0], side="right") - 1)
        check_field(allm[off[k]:off[k + 1]], f"strokes[{k}]", job.source_name)
    return allm, off


def oriented_strokes(job: Job, orientation: Orientation = AS_IS) -> list[np.ndarray]:
    """Each stroke's marks as the galvos get them, checked against 0..65535."""
    allm, off = oriented_marks(job, orientation)
    return [allm[off[i]:off[i + 1]] for i in range(len(off) - 1)]


def encode_job(job: Job, pens: PenTable | None = None,
               orientation: Orientation = AS_IS, board: Board = DEFAULT_BOARD) -> np.ndarray:
    """The job as list records (N, 6) uint16 in marking order (see the module docstring)."""
    table = job_pen_table(job, pens)
    allm, off = oriented_marks(job, orientation)
    w = ListWriter(bits_per_mm(job), table.source, board)
    w.begin_marking()
    for layer, idx in layer_order(job, table):
        if not layer.enabled:
            continue
        ids = np.asarray(idx, dtype=np.int64)
        ids = ids[off[ids + 1] > off[ids]]  # strokes with marks
        if not len(ids):
            continue
        sizes = off[ids + 1] - off[ids]
        if len(ids) == len(off) - 1:
            marks = allm  # every stroke of the job, in job order
        else:
            marks = np.concatenate([allm[off[i]:off[i + 1]] for i in ids.tolist()])
        w.settings(layer)
        for _ in range(layer.passes):
            w.strokes(marks, sizes, layer.laser)
    return w.end()


def to_bytes(records: np.ndarray) -> bytes:
    return np.ascontiguousarray(records, dtype="<u2").tobytes()


def to_text(records: np.ndarray) -> str:
    """MeerK40t's readable list dump: ``cmd:p1:p2:p3:p4:p5 name``, one record per line."""
    lines = [":".join(f"{int(w):04x}" for w in r) + " " + NAMES.get(int(r[0]), "Unknown")
             for r in np.asarray(records)]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------- decoder
@dataclass
class DecodedStroke:
    marks: np.ndarray  # (M, 2) int: the jump target, then every mark
    settings: dict[str, Any]  # the settings words in force while it was marked
    dots: int = 0


@dataclass
class Decoded:
    strokes: list[DecodedStroke]
    records: int
    ended: bool  # exactly one end-of-list, as the last record
    preamble: list[tuple[str, tuple[int, ...]]]


def decode(data: bytes) -> Decoded:
    """Replay a list (raw bytes) independently of the encoder: the strokes it marks (a jump
    starts a stroke; marks and laser-on-points extend it), the settings words in force for
    each, and whether it ends with exactly one end-of-list. Raises ValueError on a record
    this reader does not know, or bytes that are not whole records."""
    if len(data) % 12:
        raise ValueError(f"{len(data)} bytes is not a whole number of 12-byte records")
    n = len(data) // 12
    words = struct.unpack(f"<{6 * n}H", data)
    state: dict[str, Any] = {}
    strokes: list[DecodedStroke] = []
    pre: list[tuple[str, tuple[int, ...]]] = []
    cur: list[tuple[int, int]] | None = None
    cur_dots = 0
    ends = []
    x, y = 0x8000, 0x8000  # the drivers' start: the field's centre

    def close() -> None:
        nonlocal cur, cur_dots
        if cur is not None and (len(cur) > 1 or cur_dots):
            strokes.append(DecodedStroke(np.array(cur, dtype=np.int64), dict(state), cur_dots))
        cur, cur_dots = None, 0

    setting_names = {0x8006: "jump_speed", 0x800C: "mark_speed", 0x8012: "mark_current",
                     0x801B: "q_switch_period", 0x800A: "co2_frequency",
                     0x800B: "co2_power_ratio", 0x8026: "pulse_width",
                     0x8007: "laser_on_delay", 0x8008: "laser_off_delay",
                     0x800F: "polygon_delay", 0x800D: "jump_delay"}
    for i in range(n):
        c, a, b, _, d, _ = words[6 * i: 6 * i + 6]
        if c == 0x8002:
            ends.append(i)
            continue
        if c == 0x8001:
            close()
            if d != min(int(abs(complex(a - x, b - y))), 0xFFFF):
                raise ValueError(f"record {i}: jump distance {d} is wrong")
            x, y = a, b
            cur = [(a, b)]
        elif c == 0x8005:
            if cur is None:
                raise ValueError(f"record {i}: a mark with no jump before it")
            if d != min(int(abs(complex(a - x, b - y))), 0xFFFF):
                raise ValueError(f"record {i}: mark distance {d} is wrong")
            x, y = a, b
            cur.append((a, b))
        elif c == 0x8003:
            if cur is None:
                raise ValueError(f"record {i}: a laser-on point with no jump before it")
            cur_dots += 1
        elif c in setting_names:
            close()
            nm = setting_names[c]
            val = a if nm.endswith("speed") or nm in ("mark_current", "q_switch_period",
                                                       "co2_frequency", "co2_power_ratio",
                                                       "pulse_width") else (a, b)
            state[nm] = val
        elif c in (0x8051, 0x8004, 0x8011):
            close()
            pre.append(({0x8051: "ready", 0x8004: "delay", 0x8011: "port"}[c],
                        words[6 * i + 1: 6 * i + 6]))
        else:
            raise ValueError(f"record {i}: unknown command 0x{c:04x}")
        if ends:
            raise ValueError(f"record {i}: records after the end-of-list")
    close()
    return Decoded(strokes, n, len(ends) == 1 and ends[0] == n - 1, pre)


def expected_strokes(job: Job, pens: PenTable | None = None,
                     orientation: Orientation = AS_IS
                     ) -> list[tuple[LayerSettings, np.ndarray]]:
    """What a list of ``job`` must mark, stroke by stroke (each pass), with repeated marks
    dropped: for tests and for checking a written file."""
    table = job_pen_table(job, pens)
    out = []
    for layer, idx in layer_order(job, table):
        if not layer.enabled:
            continue
        for _ in range(layer.passes):
            for i in idx:
                m = orientation.apply(job.strokes[i].marks, job.field_map.max_bit)
                if len(m) > 1:
                    keep = np.concatenate([[True], (np.diff(m, axis=0) != 0).any(axis=1)])
                    m = m[keep]
                out.append((layer, m))
    return [(la, m) for la, m in out if len(m)]


def stroke_count(strokes: Sequence[Stroke]) -> int:
    return sum(1 for s in strokes if len(s.marks))
