"""Compiled reading of runs of plain pen commands (PU PD PA PR with numbers), for large files.

One pass over the bytes, no per-byte temporary arrays: the scanner reads the commands one
after the other, parses each number exactly (at most 15 digits: the integer mantissa is
exact, one correctly rounded division by a power of ten, the same value as Python's
``float``), applies the pen and mode state and writes the pen-down points straight into a
preallocated chunk of output. It stops, at a command boundary, at the first thing it does
not read itself (any other command, a number it cannot read exactly, a parameter the
general reader would warn about, an odd coordinate count, ESC) and hands over to the
command-by-command reader, which then calls it again after that command.

Output: *segments* -- runs of points of one path, contiguous in the chunk. The first
segment of a call may continue the path the caller has open (``CONT``); the last may be
left open when the pen is still down (``OPEN``).

The module imports numba (about 0.2 s the first time in a process); the reader uses it only
for large inputs or when numba is already loaded (see ``reader._use_compiled``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

# int state slots
(I_POS, I_PEN, I_ABS, I_OPEN, I_NPTS, I_NSEG, I_CONT, I_NU, I_ND, I_NA, I_NR, I_FULL,
 I_NEED) = range(13)
N_ISTATE = 13
# float state slots
F_X, F_Y, F_AX, F_BX, F_AY, F_BY, F_SC = range(7)
N_FSTATE = 7

_POW10 = 10.0 ** np.arange(0, 23)


@njit(cache=True, nogil=True, boundscheck=False)
def _is_sep(c: int) -> bool:
    # separators the general reader accepts in parameters without a warning:
    # NUL, TAB, LF, VT, FF, CR, space, comma
    return c == 44 or c == 32 or c == 0 or (9 <= c <= 13)


@njit(cache=True, nogil=True, boundscheck=False)
def _is_letter(c: int) -> bool:
    return (65 <= c <= 90) or (97 <= c <= 122)


@njit(cache=True, nogil=True, boundscheck=False)
def _check_params(b, j, n):
    """Validate the parameters starting at ``j``: returns (end, numbers) or (-1, 0) when
    the general reader must read them. ``end`` is the offset after the parameters (after
    the ';' when there is one)."""
    count = 0
    while j < n:
        c = b[j]
        if c == 59:  # ';'
            return j + 1, count
        if c == 27 or _is_letter(c):
            return j, count
        if _is_sep(c):
            j += 1
            continue
        # a number: [+-]? digits [. digits] | [+-]? . digits
        k = j
        if c == 43 or c == 45:
            k += 1
        nd = 0
        while k < n and 48 <= b[k] <= 57:
            k += 1
            nd += 1
        if k < n and b[k] == 46:
            k += 1
            while k < n and 48 <= b[k] <= 57:
                k += 1
                nd += 1
            if k < n and b[k] == 46:
                return -1, 0  # "1.2.3": read by the general reader
        if nd == 0 or nd > 15:
            return -1, 0
        count += 1
        j = k
        if j < n:
            c = b[j]
            # a number ends at a separator, a sign, ';', a letter or ESC
            if not (c == 59 or c == 27 or c == 43 or c == 45 or _is_sep(c) or _is_letter(c)):
                return -1, 0
    return j, count


@njit(cache=True, nogil=True, boundscheck=False)
def _parse_number(b, j, pow10):
    """(value, end) of the number at ``j`` (already validated)."""
    neg = False
    c = b[j]
    if c == 43 or c == 45:
        neg = c == 45
        j += 1
    mant = 0
    frac = 0
    seen_dot = False
    n = b.shape[0]
    while j < n:
        c = b[j]
        if 48 <= c <= 57:
            mant = mant * 10 + (c - 48)
            if seen_dot:
                frac += 1
        elif c == 46 and not seen_dot:
            seen_dot = True
        else:
            break
        j += 1
    v = float(mant)
    if frac:
        v = v / pow10[frac]
    if neg:
        v = -v
    return v, j


@njit(cache=True, nogil=True, boundscheck=False)
def scan_moves(b, ist, fst, pts, seg_start, seg_off, pow10):
    """Read PU/PD/PA/PR commands from ``ist[I_POS]`` on; see the module docstring.

    ``ist``/``fst`` hold the state in and out (position, pen down, absolute mode, path
    open, points and segments used in the chunk, counts per command); ``pts`` (cap, 2),
    ``seg_start``/``seg_off`` (segment capacity) are the chunk. Stops at the first command
    it does not read, or (``I_FULL`` = 1) before a command that would not fit the chunk.
    """
    n = b.shape[0]
    i = ist[I_POS]
    pen = ist[I_PEN]
    absm = ist[I_ABS]
    is_open = ist[I_OPEN]
    npts = ist[I_NPTS]
    nseg = ist[I_NSEG]
    cap = pts.shape[0]
    scap = seg_start.shape[0]
    x = fst[F_X]
    y = fst[F_Y]
    ax = fst[F_AX]
    bx = fst[F_BX]
    ay = fst[F_AY]
    by = fst[F_BY]
    has_sc = fst[F_SC] != 0.0
    ist[I_CONT] = 0
    ist[I_FULL] = 0
    if is_open:
        # the caller's open path goes on here (an empty segment if it ends at once)
        seg_start[nseg] = npts
        seg_off[nseg] = i
        nseg += 1
        ist[I_CONT] = 1
    while True:
        # separators before a command
        j = i
        while j < n:
            c = b[j]
            if c == 59 or c == 44 or (c <= 32 and c != 27):
                j += 1
            else:
                break
        if j + 1 >= n:
            i = j if j >= n else i
            break
        c0 = b[j] | 32
        c1 = b[j + 1] | 32
        if c0 != 112:  # 'p'
            break
        if c1 == 117:
            code = 0
        elif c1 == 100:
            code = 1
        elif c1 == 97:
            code = 2
        elif c1 == 114:
            code = 3
        else:
            break
        if not _is_letter(b[j]) or not _is_letter(b[j + 1]):
            break
        cmd_at = j
        end, count = _check_params(b, j + 2, n)
        if end < 0 or count % 2 == 1:
            break
        npairs = count // 2
        # room: the pairs, plus a path's start point, plus two segments
        if npts + npairs + 1 > cap or nseg + 2 > scap:
            ist[I_FULL] = 1
            ist[I_NEED] = npairs + 1
            break
        if code == 0:
            ist[I_NU] += 1
            if pen == 1:
                pen = 0
                is_open = 0
        elif code == 1:
            ist[I_ND] += 1
            if pen == 0:
                pen = 1
                seg_start[nseg] = npts
                seg_off[nseg] = cmd_at
                nseg += 1
                pts[npts, 0] = x
                pts[npts, 1] = y
                npts += 1
                is_open = 1
        elif code == 2:
            ist[I_NA] += 1
            absm = 1
        else:
            ist[I_NR] += 1
            absm = 0
        k = j + 2
        for _ in range(npairs):
            while _is_sep(b[k]):
                k += 1
            vx, k = _parse_number(b, k, pow10)
            while _is_sep(b[k]):
                k += 1
            vy, k = _parse_number(b, k, pow10)
            if absm == 1:
                if has_sc:
                    nx = ax * vx + bx
                    ny = ay * vy + by
                else:
                    nx = vx
                    ny = vy
            elif has_sc:
                nx = x + ax * vx
                ny = y + ay * vy
            else:
                nx = x + vx
                ny = y + vy
            if pen == 1:
                if is_open == 0:
                    # the pen is down but the path was ended (SP, CI, ...): a new path
                    # starts at the current point
                    seg_start[nseg] = npts
                    seg_off[nseg] = cmd_at
                    nseg += 1
                    pts[npts, 0] = x
                    pts[npts, 1] = y
                    npts += 1
                    is_open = 1
                pts[npts, 0] = nx
                pts[npts, 1] = ny
                npts += 1
            x = nx
            y = ny
        i = end
    ist[I_POS] = i
    ist[I_PEN] = pen
    ist[I_ABS] = absm
    ist[I_OPEN] = is_open
    ist[I_NPTS] = npts
    ist[I_NSEG] = nseg
    fst[F_X] = x
    fst[F_Y] = y
