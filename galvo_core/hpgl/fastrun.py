"""Vectorised reading of runs of plain pen commands (PU PD PA PR with numbers).

Almost every byte of a real PLT file is such a run: ``PU x,y;PD x,y,x,y,...``. Reading
them one command at a time in Python costs microseconds per point; here a whole run is
tokenised with numpy in one go (numbers parsed digit-wise, exactly for up to 15 digits)
and the pen/mode state machine is evaluated with prefix scans. The caller falls back to the
command-by-command reader when a run holds anything unusual (see :func:`tokenize_run`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

CODE_U, CODE_D, CODE_A, CODE_R = 0, 1, 2, 3
_LETTER_CODE = np.full(256, -1, dtype=np.int8)
for _ch, _code in ((b"U", CODE_U), (b"D", CODE_D), (b"A", CODE_A), (b"R", CODE_R)):
    _LETTER_CODE[_ch[0]] = _code
    _LETTER_CODE[_ch[0] | 0x20] = _code
_POW10 = 10.0 ** np.arange(0, 23)


@dataclass
class RunTokens:
    cmd_pos: np.ndarray  # (C,) offsets of the mnemonics within the run
    cmd_code: np.ndarray  # (C,) CODE_U/D/A/R
    num_cmd: np.ndarray  # (K,) index of the command each number belongs to
    num_val: np.ndarray  # (K,) float64 values


def tokenize_run(buf: bytes | memoryview) -> RunTokens | None:
    """Tokenise a run; None when it holds a number this fast path does not read exactly
    (more than 15 digits, two decimal points, a sign or point without digits)."""
    b = np.frombuffer(buf, dtype=np.uint8)
    is_letter = ((b >= 65) & (b <= 90)) | ((b >= 97) & (b <= 122))
    letters = np.flatnonzero(is_letter)
    cmd_pos = letters[0::2]
    cmd_code = _LETTER_CODE[b[letters[1::2]]]
    if len(cmd_pos) != len(letters[1::2]) or (cmd_code < 0).any():
        return None
    is_dig = (b >= 48) & (b <= 57)
    is_dot = b == 46
    is_sign = (b == 43) | (b == 45)
    numch = is_dig | is_dot | is_sign
    prev = np.empty_like(numch)
    prev[0] = False
    prev[1:] = numch[:-1]
    starts = numch & (~prev | is_sign)
    ntok = int(starts.sum())
    if ntok == 0:
        return RunTokens(cmd_pos, cmd_code.astype(np.int8), np.empty(0, np.int64), np.empty(0))
    tok_id = np.cumsum(starts) - 1  # valid where numch
    tok_start = np.flatnonzero(starts)
    dpos = np.flatnonzero(is_dig)
    dtok = tok_id[dpos]
    nd = np.bincount(dtok, minlength=ntok)
    ndots = np.bincount(tok_id[is_dot], minlength=ntok) if is_dot.any() else np.zeros(ntok, int)
    if (nd == 0).any() or (nd > 15).any() or (ndots > 1).any():
        return None
    first_digit = np.cumsum(nd) - nd  # index into dpos of each token's first digit
    i_in_tok = np.arange(len(dpos)) - first_digit[dtok]
    power = nd[dtok] - 1 - i_in_tok
    digits = (b[dpos] - 48).astype(np.float64)
    mant = np.bincount(dtok, weights=digits * _POW10[power], minlength=ntok)
    val = mant
    if ndots.any():
        dot_pos = np.full(ntok, np.iinfo(np.int64).max, dtype=np.int64)
        dot_pos[tok_id[is_dot]] = np.flatnonzero(is_dot)
        frac = np.bincount(dtok, weights=(dpos > dot_pos[dtok]), minlength=ntok).astype(np.int64)
        val = mant / _POW10[frac]
    neg = b[tok_start] == 45
    val = np.where(neg, -val, val)
    num_cmd = np.searchsorted(cmd_pos, tok_start, side="right") - 1
    if len(num_cmd) and num_cmd[0] < 0:
        return None
    return RunTokens(cmd_pos, cmd_code.astype(np.int8), num_cmd.astype(np.int64), val)


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
