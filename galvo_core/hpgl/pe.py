"""HP-GL/2 PE (polyline encoded) decoding.

Format (HP-GL/2 reference, "PE, Polyline Encoded"): after the mnemonic comes a run of
flags and numbers, ended by ``;``.

* Flags: ``:`` select pen (next number), ``<`` the next coordinate pair is a pen-up move,
  ``>`` the next number is the count of fractional binary digits of later coordinates,
  ``=`` the next pair is absolute, ``7`` switch to 7-bit (base-32) numbers.
* Numbers are little-endian digit strings. 8-bit mode (base 64): digits 63..126 go on,
  191..254 end the number; 7-bit mode (base 32): 63..94 go on, 95..126 end it. The value's
  low bit is the sign (odd = negative), the rest is the magnitude.
* Every other byte (control characters, spaces, bytes 127..190 and 255 in 8-bit mode) is
  ignored.

Engineering decision (files in the wild): AutoCAD drivers write a PE run that is *not*
terminated by ``;`` and follow it directly by the next mnemonic (``...PUSP0;``). Upper-case
letters are valid digits, so a strict reader would swallow the rest of the file. We end the
run at a number boundary when what follows is not a complete number: a run of continuation
digits that reaches a byte which is neither a digit nor an ignorable byte (for instance ``0``
or ``;``) before it reaches a terminating digit cannot be a number, so the PE ends there and
the letters are read as commands.

Linear time: that look-ahead may scan far (``PEPEPE...`` is all continuation digits), so
the caller passes a cache (:class:`PECache`) remembering the stretch a failed look-ahead
crossed; a later look-ahead starting inside it fails at once, so each byte is scanned by
failed look-aheads at most once per mode.
"""

from __future__ import annotations

from dataclasses import dataclass, field

# byte classes
_IGNORABLE_8 = frozenset(list(range(0, 33)) + list(range(127, 191)) + [255])
_IGNORABLE_7 = frozenset(list(range(0, 33)) + list(range(127, 256)))
_FLAGS = frozenset(b":<>=7")
MAX_VALUE = 10**15  # larger numbers are clamped (as the reader clamps ASCII numbers)


@dataclass
class PEItem:
    """One decoded element: a pen select, a fraction change, or a coordinate pair."""

    kind: str  # "pen" | "pair"
    value: int = 0
    x: float = 0.0
    y: float = 0.0
    pen_up: bool = False
    absolute: bool = False


@dataclass
class PEResult:
    items: list[PEItem] = field(default_factory=list)
    end: int = 0  # offset just past the run (past its ';' when there is one)
    problems: list[tuple[int, str]] = field(default_factory=list)  # (offset, message)


def _is_cont(b: int, seven: bool) -> bool:
    return 63 <= b <= 94 if seven else 63 <= b <= 126


def _is_term(b: int, seven: bool) -> bool:
    return 95 <= b <= 126 if seven else 191 <= b <= 254


@dataclass
class PECache:
    """Stretches ``[start, end)`` (per mode) where no complete number can start."""

    fail: dict[bool, tuple[int, int]] = field(default_factory=dict)


def _looks_like_number(data: bytes, pos: int, seven: bool, cache: PECache | None = None) -> bool:
    """True when a complete number (continuations then a terminator) starts at ``pos``."""
    if cache is not None:
        span = cache.fail.get(seven)
        if span is not None and span[0] <= pos < span[1]:
            return False
    ign = _IGNORABLE_7 if seven else _IGNORABLE_8
    n = len(data)
    i = pos
    while i < n:
        b = data[i]
        if _is_term(b, seven):
            return True
        if _is_cont(b, seven) or b in ign:
            i += 1
            continue
        break
    if cache is not None:
        cache.fail[seven] = (pos, i)
    return False


def decode_pe(data: bytes, pos: int, cache: PECache | None = None) -> PEResult:
    """Decode a PE run starting at ``pos`` (just after the ``PE`` mnemonic).

    Pass the same ``cache`` for every PE of one file to keep the whole read linear.
    """
    res = PEResult()
    n = len(data)
    seven = False
    frac_bits = 0
    pending_flag: int | None = None  # ':' or '>' waiting for its number
    pen_up_next = False
    absolute_next = False
    coord: list[int] = []
    i = pos
    while i < n:
        b = data[i]
        if b == 0x3B:  # ';'
            i += 1
            break
        if b == 0x1B:  # ESC: a PCL escape ends the run
            break
        if b in _FLAGS:
            if b == 0x37:  # '7'
                seven = True
            elif b == 0x3C:  # '<'
                pen_up_next = True
            elif b == 0x3D:  # '='
                absolute_next = True
            else:
                pending_flag = b
            i += 1
            continue
        ign = _IGNORABLE_7 if seven else _IGNORABLE_8
        if b in ign:
            i += 1
            continue
        if _is_cont(b, seven) or _is_term(b, seven):
            if not _looks_like_number(data, i, seven, cache):
                # an unterminated PE run followed by ordinary commands
                break
            # read one number
            value = 0
            shift = 0
            base_bits = 5 if seven else 6
            while i < n:
                b = data[i]
                if _is_cont(b, seven):
                    value |= (b - 63) << shift
                    shift += base_bits
                    i += 1
                elif _is_term(b, seven):
                    value |= (b - (95 if seven else 191)) << shift
                    i += 1
                    break
                elif b in ign:
                    i += 1
                else:  # cannot happen after _looks_like_number
                    break
            num = -(value >> 1) if value & 1 else value >> 1
            if abs(num) > MAX_VALUE:
                res.problems.append((i, "PE number out of range; clamped"))
                num = MAX_VALUE if num > 0 else -MAX_VALUE
            if pending_flag == 0x3A:  # ':'
                res.items.append(PEItem("pen", value=num))
                pending_flag = None
            elif pending_flag == 0x3E:  # '>'
                if 0 <= num <= 26:
                    frac_bits = num
                else:
                    res.problems.append((i, f"PE fractional bits {num} out of range 0..26"))
                pending_flag = None
            else:
                coord.append(num)
                if len(coord) == 2:
                    scale = float(1 << frac_bits) if frac_bits else 1.0
                    res.items.append(
                        PEItem(
                            "pair",
                            x=coord[0] / scale,
                            y=coord[1] / scale,
                            pen_up=pen_up_next,
                            absolute=absolute_next,
                        )
                    )
                    coord = []
                    pen_up_next = False
                    absolute_next = False
            continue
        # any other byte (a digit '0'..'6', '8', '9', punctuation): not PE data
        break
    if coord:
        res.problems.append((i, "PE run ends with half a coordinate pair; it was dropped"))
    if pending_flag is not None:
        res.problems.append((i, "PE run ends with a flag that has no number"))
    res.end = i
    return res


def encode_number(value: int, *, seven: bool = False) -> bytes:
    """Encode one signed integer as PE digits (used by tests and the PLT writer)."""
    v = (-value << 1) | 1 if value < 0 else value << 1
    base_bits = 5 if seven else 6
    base = 1 << base_bits
    out = bytearray()
    while True:
        digit = v & (base - 1)
        v >>= base_bits
        if v == 0:
            out.append(digit + (95 if seven else 191))
            return bytes(out)
        out.append(digit + 63)
