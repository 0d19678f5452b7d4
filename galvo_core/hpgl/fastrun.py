"""Vectorised reading of runs of plain pen commands (PU PD PA PR with numbers).

Almost every byte of a real PLT file is such a run: ``PU x,y;PD x,y,x,y,...``. Reading
them one command at a time in Python costs microseconds per point; here a whole run is
tokenised in one compiled pass over its bytes (:func:`_scan`, numba; numbers read exactly
for up to 15 digits) and the pen/mode state machine is evaluated with numpy prefix scans.
The caller falls back to the command-by-command reader when a run holds anything unusual
(see :func:`tokenize_run`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

CODE_U, CODE_D, CODE_A, CODE_R = 0, 1, 2, 3
_LETTER_CODE = np.full(256, -1, dtype=np.int8)
for _ch, _code in ((b"U", CODE_U), (b"D", CODE_D), (b"A", CODE_A), (b"R", CODE_R)):
    _LETTER_CODE[_ch[0]] = _code
    _LETTER_CODE[_ch[0] | 0x20] = _code
_POW10 = 10.0 ** np.arange(0, 23)
_LETTER_READ_ONLY = _LETTER_CODE.copy()
_LETTER_READ_ONLY.setflags(write=False)


@dataclass
class RunTokens:
    cmd_pos: np.ndarray  # (C,) offsets of the mnemonics within the run
    cmd_code: np.ndarray  # (C,) CODE_U/D/A/R
    num_cmd: np.ndarray  # (K,) index of the command each number belongs to
    num_val: np.ndarray  # (K,) float64 values


#: bytes tokenised at once: the output buffers sized for the worst case (16 bytes per
#: input byte) stay small however large the file
CHUNK_BYTES = 1 << 20


def tokenize_run(buf: bytes | memoryview) -> RunTokens | None:
    """Tokenise a run; None when it holds a number this fast path does not read exactly
    (more than 15 digits, two decimal points, a sign or point without digits).

    A long run is tokenised in pieces of about :data:`CHUNK_BYTES` cut just after a ``;``
    (a command boundary), with the same result as in one piece."""
    b = np.frombuffer(buf, dtype=np.uint8)
    if len(b) <= 2 * CHUNK_BYTES:
        return _tokenize(b)
    cuts = [0]
    while len(b) - cuts[-1] > 2 * CHUNK_BYTES:
        semi = np.flatnonzero(b[cuts[-1] + CHUNK_BYTES:cuts[-1] + 2 * CHUNK_BYTES] == 59)
        if len(semi) == 0:
            break
        cuts.append(cuts[-1] + CHUNK_BYTES + int(semi[0]) + 1)
    cuts.append(len(b))
    parts = []
    n_cmd = 0
    for a, e in zip(cuts[:-1], cuts[1:], strict=True):
        t = _tokenize(b[a:e])
        if t is None:
            return None
        t.cmd_pos += a
        t.num_cmd += n_cmd
        n_cmd += len(t.cmd_pos)
        parts.append(t)
    return RunTokens(*(np.concatenate([getattr(t, f) for t in parts])
                       for f in ("cmd_pos", "cmd_code", "num_cmd", "num_val")))


_nt = numba.types
#: compiled when this module is imported (from the cache after the first time on a
#: machine), not on the first file read: the bytes are a read-only uint8 array
_SCAN_SIGNATURE = _nt.Tuple((_nt.int64, _nt.int64, _nt.boolean))(
    _nt.Array(_nt.uint8, 1, "C", readonly=True), _nt.Array(_nt.int8, 1, "C", readonly=True),
    _nt.int64[::1], _nt.int8[::1], _nt.int64[::1], _nt.float64[::1])


@numba.njit(_SCAN_SIGNATURE, cache=True, nogil=True)
def _scan(b: np.ndarray, letter_code: np.ndarray, cmd_pos: np.ndarray, cmd_code: np.ndarray,
          num_cmd: np.ndarray, num_val: np.ndarray) -> tuple[int, int, bool]:  # pragma: no cover
    """One pass over the bytes: (commands, numbers, ok). A mnemonic is two letters (not
    necessarily adjacent: letters pair up in order), its position that of its first
    letter; a number is a run of digits and at most one point, a sign only at its start
    (a sign always starts a new number), read exactly as digits -> integer mantissa (up to
    15 digits, exact in float64) divided by a power of ten. ok False where the vectorised
    rules say None."""
    n = len(b)
    nc = 0
    nn = 0
    half = False  # the first letter of a mnemonic seen, not its second
    i = 0
    while i < n:
        c = b[i]
        if (65 <= c <= 90) or (97 <= c <= 122):
            if half:
                code = letter_code[c]
                if code < 0:
                    return nc, nn, False
                cmd_code[nc - 1] = code
                half = False
            else:
                cmd_pos[nc] = i
                nc += 1
                half = True
            i += 1
            continue
        if (48 <= c <= 57) or c == 46 or c == 43 or c == 45:
            neg = c == 45
            if c == 43 or c == 45:
                i += 1
            mant = 0.0
            nd = 0
            ndots = 0
            frac = 0
            while i < n:
                c = b[i]
                if 48 <= c <= 57:
                    mant = mant * 10.0 + (c - 48)
                    nd += 1
                    if ndots:
                        frac += 1
                elif c == 46:
                    ndots += 1
                else:
                    break
                i += 1
            if nd == 0 or nd > 15 or ndots > 1 or nc == 0:
                return nc, nn, False
            val = mant / _POW10[frac]
            num_val[nn] = -val if neg else val
            num_cmd[nn] = nc - 1
            nn += 1
            continue
        i += 1
    return nc, nn, not half


def _tokenize(b: np.ndarray) -> RunTokens | None:
    """:func:`tokenize_run` of one piece (compiled single pass, :func:`_scan`)."""
    cap = len(b) // 2 + 1
    cmd_pos = np.empty(cap, dtype=np.int64)
    cmd_code = np.empty(cap, dtype=np.int8)
    num_cmd = np.empty(cap, dtype=np.int64)
    num_val = np.empty(cap, dtype=np.float64)
    nc, nn, ok = _scan(b, _LETTER_READ_ONLY, cmd_pos, cmd_code, num_cmd, num_val)
    if not ok:
        return None
    return RunTokens(cmd_pos[:nc].copy(), cmd_code[:nc].copy(), num_cmd[:nn].copy(),
                     num_val[:nn].copy())


def segmented_cumsum(values: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Running sums of ``values`` that restart at each index in ``starts`` (``starts[0]``
    must be 0), added left to right exactly as a loop would (the same float rounding as the
    command-by-command reader: ``x = x + dx`` per pair).

    Segments are padded to the next power of two and summed as rows of a 2-D block per
    width, so the work stays linear and vectorised however many segments there are.
    """
    n = len(values)
    out = values.astype(np.float64, copy=True)
    lengths = np.diff(np.append(starts, n))
    multi = lengths > 1
    if not multi.any():
        return out
    seg_start = starts[multi]
    seg_len = lengths[multi]
    width_exp = np.ceil(np.log2(seg_len)).astype(np.int64)
    for e in np.unique(width_exp).tolist():
        sel = width_exp == e
        s0 = seg_start[sel]
        ln = seg_len[sel]
        cols = np.arange(1 << e)
        idx = s0[:, None] + cols[None, :]
        valid = cols[None, :] < ln[:, None]
        block = np.where(valid, out[np.minimum(idx, n - 1)], 0.0)
        np.cumsum(block, axis=1, out=block)
        out[idx[valid]] = block[valid]
    return out


def ffill_state(setter: np.ndarray, initial: int) -> np.ndarray:
    """Forward-fill: ``setter`` holds the new state or -1 (keep); returns the state per slot."""
    idx = np.where(setter >= 0, np.arange(len(setter)), -1)
    np.maximum.accumulate(idx, out=idx)
    out = np.where(idx >= 0, setter[np.maximum(idx, 0)], initial)
    return out.astype(np.int8)
