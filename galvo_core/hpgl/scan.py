"""Compiled reading of runs of plain pen commands (PU PD PA PR with numbers, SP, PW).

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
 I_NEED, I_PENNO, I_HPGL2, I_NSP, I_SPOK, I_LINE, I_LASTNL, I_NPW) = range(20)
N_ISTATE = 20
# float state slots
F_X, F_Y, F_AX, F_BX, F_AY, F_BY, F_SC = range(7)
N_FSTATE = 7

_POW10 = 10.0 ** np.arange(0, 23)

# byte classes (one table look-up per byte in the loops)
C_OTHER, C_SEP, C_LETTER, C_DIGIT, C_SIGN, C_DOT, C_SEMI, C_ESC, C_CTRL = range(9)
CLASS = np.full(256, C_OTHER, dtype=np.uint8)
CLASS[list(range(1, 9)) + list(range(14, 27)) + list(range(28, 32))] = C_CTRL
CLASS[[0, 9, 10, 11, 12, 13, 32, 44]] = C_SEP
CLASS[65:91] = C_LETTER
CLASS[97:123] = C_LETTER
CLASS[48:58] = C_DIGIT
CLASS[[43, 45]] = C_SIGN
CLASS[46] = C_DOT
CLASS[59] = C_SEMI
CLASS[27] = C_ESC


@njit(cache=True, nogil=True, boundscheck=False)
def _read_number(b, j, n, pow10, cls):
    """The number at ``j``: (value, end), end = -1 when the general reader must read it
    ("1.2.3", a sign or point without digits, more than 15 digits, junk right after)."""
    neg = False
    c = b[j]
    if c == 43 or c == 45:
        neg = c == 45
        j += 1
    mant = 0
    nd = 0
    frac = 0
    while j < n and cls[b[j]] == C_DIGIT:
        mant = mant * 10 + (b[j] - 48)
        nd += 1
        j += 1
    if j < n and b[j] == 46:
        j += 1
        while j < n and cls[b[j]] == C_DIGIT:
            mant = mant * 10 + (b[j] - 48)
            nd += 1
            frac += 1
            j += 1
        if j < n and b[j] == 46:
            return 0.0, -1
    if nd == 0 or nd > 15:
        return 0.0, -1
    if j < n:
        k = cls[b[j]]
        # a number ends at a separator, a sign, ';', a letter or ESC
        if not (k == C_SEP or k == C_SIGN or k == C_SEMI or k == C_LETTER or k == C_ESC):
            return 0.0, -1
    v = float(mant)
    if frac:
        v = v / pow10[frac]
    return (-v if neg else v), j


@njit(cache=True, nogil=True, boundscheck=False)
def scan_moves(b, ist, fst, pts, seg_start, seg_off, seg_pen, seg_line, seg_col, pow10, cls):
    """Read PU/PD/PA/PR (and SP) commands from ``ist[I_POS]`` on; see the module docstring.

    ``ist``/``fst`` hold the state in and out (position, pen down, absolute mode, path
    open, points and segments used in the chunk, counts per command, pen number, dialect);
    ``pts`` (cap, 2) and the segment arrays are the chunk. One pass: a command is applied as
    it is read and rolled back (state restored, nothing kept) when it turns out to need
    the general reader. Stops at the first command it does not read, or (``I_FULL`` = 1)
    before a command that does not fit the chunk (``I_NEED`` points asked for).
    """
    n = b.shape[0]
    i = ist[I_POS]
    # line number at i and offset of the last newline before i (committed with i); tl, tn:
    # the same, tentatively, over bytes not yet consumed
    line = ist[I_LINE]
    last_nl = ist[I_LASTNL]
    pen = ist[I_PEN]
    absm = ist[I_ABS]
    is_open = ist[I_OPEN]
    npts = ist[I_NPTS]
    nseg = ist[I_NSEG]
    pen_no = ist[I_PENNO]
    hpgl2 = ist[I_HPGL2] != 0
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
        seg_pen[nseg] = pen_no
        nseg += 1
        ist[I_CONT] = 1
    nu = 0
    nd_ = 0
    na = 0
    nr = 0
    nsp = 0
    npw = 0
    while True:
        # separators before a command
        j = i
        tl = line
        tn = last_nl
        while j < n:
            k = cls[b[j]]
            if k == C_SEP or k == C_SEMI or k == C_CTRL:
                if b[j] == 10:
                    tl += 1
                    tn = j
                j += 1
            else:
                break
        if j + 1 >= n:
            if j >= n:
                i = n
                line = tl
                last_nl = tn
            break
        c0 = b[j] | 32
        c1 = b[j + 1] | 32
        if cls[b[j]] != C_LETTER or cls[b[j + 1]] != C_LETTER:
            break
        if c0 == 112:  # 'p'
            if c1 == 117:
                code = 0
            elif c1 == 100:
                code = 1
            elif c1 == 97:
                code = 2
            elif c1 == 114:
                code = 3
            elif c1 == 119:  # 'pw': pen width, recorded, not drawn (an HP-GL/2 command)
                code = 5
            else:
                break
        elif c0 == 115 and c1 == 112 and ist[I_SPOK] != 0:  # 'sp' (once a pen was selected)
            code = 4
        else:
            break
        cmd_at = j
        cmd_line = tl
        cmd_col = j - tn
        # state at the command's start, to roll back to
        r_pen, r_absm, r_open, r_npts, r_nseg, r_x, r_y = pen, absm, is_open, npts, nseg, x, y
        r_pen_no = pen_no
        k = j + 2
        if code == 5:
            # PW [width[,pen]]: no geometry; the file is HP-GL/2 from here on (as the
            # general reader says); anything but up to two numbers: the general reader's
            count = 0
            ok = True
            while k < n:
                t = cls[b[k]]
                if t == C_SEMI:
                    k += 1
                    break
                if t == C_ESC or t == C_LETTER:
                    break
                if t == C_SEP:
                    if b[k] == 10:
                        tl += 1
                        tn = k
                    k += 1
                    continue
                v, e = _read_number(b, k, n, pow10, cls)
                if e < 0 or count == 2:
                    ok = False
                    break
                count += 1
                k = e
            if not ok:
                break
            hpgl2 = True
            npw += 1
            i = k
            line = tl
            last_nl = tn
            continue
        if code == 4:
            # SP [n]: ends the path; HP-GL/2 keeps the pen down, HP-GL/1 lifts it
            count = 0
            val = 0.0
            ok = True
            while k < n:
                t = cls[b[k]]
                if t == C_SEMI:
                    k += 1
                    break
                if t == C_ESC or t == C_LETTER:
                    break
                if t == C_SEP:
                    if b[k] == 10:
                        tl += 1
                        tn = k
                    k += 1
                    continue
                v, e = _read_number(b, k, n, pow10, cls)
                if e < 0 or count == 1:
                    ok = False
                    break
                val = v
                count += 1
                k = e
            if not ok:
                break
            pen_no = int(val) if count else 0
            is_open = 0
            if not hpgl2:
                pen = 0
            nsp += 1
            i = k
            line = tl
            last_nl = tn
            continue
        if code == 0:
            if pen == 1:
                pen = 0
                is_open = 0
        elif code == 1:
            if pen == 0:
                pen = 1
                if npts + 1 > cap or nseg + 2 > scap:
                    ist[I_FULL] = 1
                    ist[I_NEED] = 2
                    pen, is_open = r_pen, r_open
                    break
                seg_start[nseg] = npts
                seg_off[nseg] = cmd_at
                seg_line[nseg] = cmd_line
                seg_col[nseg] = cmd_col
                seg_pen[nseg] = pen_no
                nseg += 1
                pts[npts, 0] = x
                pts[npts, 1] = y
                npts += 1
                is_open = 1
        elif code == 2:
            absm = 1
        else:
            absm = 0
        # the pairs, applied as read
        ok = True
        full = False
        half = False
        vx = 0.0
        while k < n:
            t = cls[b[k]]
            if t == C_SEMI:
                k += 1
                break
            if t == C_ESC or t == C_LETTER:
                break
            if t == C_SEP:
                if b[k] == 10:
                    tl += 1
                    tn = k
                k += 1
                continue
            # the number at k, read in place (a call per number costs more than the
            # number: the arrays' reference counts)
            neg = False
            if t == C_SIGN:
                neg = b[k] == 45
                k += 1
            mant = 0
            nd = 0
            frac = 0
            while k < n:
                c = b[k]
                if 48 <= c <= 57:
                    mant = mant * 10 + (c - 48)
                    nd += 1
                    k += 1
                else:
                    break
            if k < n and b[k] == 46:
                k += 1
                while k < n:
                    c = b[k]
                    if 48 <= c <= 57:
                        mant = mant * 10 + (c - 48)
                        nd += 1
                        frac += 1
                        k += 1
                    else:
                        break
                if k < n and b[k] == 46:
                    ok = False
                    break
            if nd == 0 or nd > 15:
                ok = False
                break
            if k < n:
                t = cls[b[k]]
                # a number ends at a separator, a sign, ';', a letter or ESC
                if not (t == C_SEP or t == C_SIGN or t == C_SEMI or t == C_LETTER
                        or t == C_ESC):
                    ok = False
                    break
            v = float(mant)
            if frac:
                v = v / pow10[frac]
            if neg:
                v = -v
            if not half:
                vx = v
                half = True
                continue
            half = False
            if absm == 1:
                if has_sc:
                    nx = ax * vx + bx
                    ny = ay * v + by
                else:
                    nx = vx
                    ny = v
            elif has_sc:
                nx = x + ax * vx
                ny = y + ay * v
            else:
                nx = x + vx
                ny = y + v
            if pen == 1:
                if npts + 2 > cap or nseg + 2 > scap:
                    full = True
                    break
                if is_open == 0:
                    # the pen is down but the path was ended (SP, CI, ...): a new path
                    # starts at the current point
                    seg_start[nseg] = npts
                    seg_off[nseg] = cmd_at
                    seg_line[nseg] = cmd_line
                    seg_col[nseg] = cmd_col
                    seg_pen[nseg] = pen_no
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
        if full or not ok or half:
            # roll back: the general reader reads this command (or a larger chunk is made)
            pen, absm, is_open, npts, nseg, x, y = r_pen, r_absm, r_open, r_npts, r_nseg, r_x, r_y
            pen_no = r_pen_no
            if full:
                ist[I_FULL] = 1
                ist[I_NEED] = 2 * cap
            break
        if code == 0:
            nu += 1
        elif code == 1:
            nd_ += 1
        elif code == 2:
            na += 1
        else:
            nr += 1
        i = k
        line = tl
        last_nl = tn
    ist[I_POS] = i
    ist[I_LINE] = line
    ist[I_LASTNL] = last_nl
    ist[I_PEN] = pen
    ist[I_ABS] = absm
    ist[I_OPEN] = is_open
    ist[I_NPTS] = npts
    ist[I_NSEG] = nseg
    ist[I_PENNO] = pen_no
    ist[I_NU] = nu
    ist[I_ND] = nd_
    ist[I_NA] = na
    ist[I_NR] = nr
    ist[I_NSP] = nsp
    ist[I_NPW] = npw
    ist[I_HPGL2] = 1 if hpgl2 else 0
    fst[F_X] = x
    fst[F_Y] = y



@njit(cache=True, nogil=True, boundscheck=False)
def scan_poly_moves(b, ist, fst, mx, my, mdown, pow10, cls):
    """Polygon mode: read PU/PD/PA/PR (and PW) commands from ``ist[I_POS]`` on, as
    :func:`scan_moves` reads them, but record every move instead of drawing: the point
    (``mx``, ``my``, plotter units) and the pen state it was made with (``mdown``); the
    reader adds them to its polygon buffer. ``ist[I_NPTS]`` counts the moves. Stops at the
    first command it does not read (rolled back: nothing of it kept), or (``I_FULL`` = 1)
    before a command whose moves do not fit.
    """
    n = b.shape[0]
    i = ist[I_POS]
    line = ist[I_LINE]
    last_nl = ist[I_LASTNL]
    pen = ist[I_PEN]
    absm = ist[I_ABS]
    nm = ist[I_NPTS]
    hpgl2 = ist[I_HPGL2] != 0
    cap = mx.shape[0]
    x = fst[F_X]
    y = fst[F_Y]
    ax = fst[F_AX]
    bx = fst[F_BX]
    ay = fst[F_AY]
    by = fst[F_BY]
    has_sc = fst[F_SC] != 0.0
    ist[I_FULL] = 0
    nu = 0
    nd_ = 0
    na = 0
    nr = 0
    npw = 0
    while True:
        j = i
        tl = line
        tn = last_nl
        while j < n:
            k = cls[b[j]]
            if k == C_SEP or k == C_SEMI or k == C_CTRL:
                if b[j] == 10:
                    tl += 1
                    tn = j
                j += 1
            else:
                break
        if j + 1 >= n:
            if j >= n:
                i = n
                line = tl
                last_nl = tn
            break
        if cls[b[j]] != C_LETTER or cls[b[j + 1]] != C_LETTER:
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
        elif c1 == 119:
            code = 5
        else:
            break
        r_pen, r_absm, r_nm, r_x, r_y = pen, absm, nm, x, y
        k = j + 2
        if code == 5:
            count = 0
            ok = True
            while k < n:
                t = cls[b[k]]
                if t == C_SEMI:
                    k += 1
                    break
                if t == C_ESC or t == C_LETTER:
                    break
                if t == C_SEP:
                    if b[k] == 10:
                        tl += 1
                        tn = k
                    k += 1
                    continue
                v, e = _read_number(b, k, n, pow10, cls)
                if e < 0 or count == 2:
                    ok = False
                    break
                count += 1
                k = e
            if not ok:
                break
            hpgl2 = True
            npw += 1
            i = k
            line = tl
            last_nl = tn
            continue
        if code == 0:
            pen = 0
        elif code == 1:
            pen = 1
        elif code == 2:
            absm = 1
        else:
            absm = 0
        ok = True
        full = False
        half = False
        vx = 0.0
        while k < n:
            t = cls[b[k]]
            if t == C_SEMI:
                k += 1
                break
            if t == C_ESC or t == C_LETTER:
                break
            if t == C_SEP:
                if b[k] == 10:
                    tl += 1
                    tn = k
                k += 1
                continue
            v, e = _read_number(b, k, n, pow10, cls)
            if e < 0:
                ok = False
                break
            k = e
            if not half:
                vx = v
                half = True
                continue
            half = False
            if absm == 1:
                if has_sc:
                    nx = ax * vx + bx
                    ny = ay * v + by
                else:
                    nx = vx
                    ny = v
            elif has_sc:
                nx = x + ax * vx
                ny = y + ay * v
            else:
                nx = x + vx
                ny = y + v
            if nm >= cap:
                full = True
                break
            mx[nm] = nx
            my[nm] = ny
            mdown[nm] = pen
            nm += 1
            x = nx
            y = ny
        if full or not ok or half:
            pen, absm, nm, x, y = r_pen, r_absm, r_nm, r_x, r_y
            if full:
                ist[I_FULL] = 1
                ist[I_NEED] = 2 * cap
            break
        if code == 0:
            nu += 1
        elif code == 1:
            nd_ += 1
        elif code == 2:
            na += 1
        else:
            nr += 1
        i = k
        line = tl
        last_nl = tn
    ist[I_POS] = i
    ist[I_LINE] = line
    ist[I_LASTNL] = last_nl
    ist[I_PEN] = pen
    ist[I_ABS] = absm
    ist[I_NPTS] = nm
    ist[I_NU] = nu
    ist[I_ND] = nd_
    ist[I_NA] = na
    ist[I_NR] = nr
    ist[I_NPW] = npw
    ist[I_HPGL2] = 1 if hpgl2 else 0
    fst[F_X] = x
    fst[F_Y] = y


# ------------------------------------------------------------------ PE (polyline encoded)
# item kinds and problem codes of decode_pe (the same decoding as pe.decode_pe)
PE_PEN, PE_PAIR = 0, 1
PE_CLAMPED, PE_FRACTION, PE_HALF_PAIR, PE_FLAG = 1, 2, 3, 4
_PE_MAX = 10**15


@njit(cache=True, nogil=True, boundscheck=False)
def _pe_cont(c, seven):
    return (63 <= c <= 94) if seven else (63 <= c <= 126)


@njit(cache=True, nogil=True, boundscheck=False)
def _pe_term(c, seven):
    return (95 <= c <= 126) if seven else (191 <= c <= 254)


@njit(cache=True, nogil=True, boundscheck=False)
def _pe_ign(c, seven):
    if c <= 32:
        return True
    if seven:
        return c >= 127
    return (127 <= c <= 190) or c == 255


@njit(cache=True, nogil=True, boundscheck=False)
def _pe_looks_like_number(b, pos, seven, cache):
    """As pe._looks_like_number; ``cache`` = [start8, end8, start7, end7] of the stretch a
    failed look-ahead crossed (per mode), so each byte is crossed at most once per mode."""
    s = 2 if seven else 0
    if cache[s] <= pos < cache[s + 1]:
        return False
    n = b.shape[0]
    i = pos
    while i < n:
        c = b[i]
        if _pe_term(c, seven):
            return True
        if _pe_cont(c, seven) or _pe_ign(c, seven):
            i += 1
            continue
        break
    cache[s] = pos
    cache[s + 1] = i
    return False


@njit(cache=True, nogil=True, boundscheck=False)
def decode_pe(b, pos, cache):
    """Decode a PE run from ``pos`` (just after the mnemonic), exactly as pe.decode_pe.

    Returns (end, kinds, xs, ys, flags, n_items, prob_off, prob_code, prob_val, n_probs):
    item k is a pen select (kinds PE_PEN, the pen in xs) or a pair (xs, ys; flags bit 0 pen
    up, bit 1 absolute); problems are (offset, code, value).
    """
    n = b.shape[0]
    cap = 16
    kinds = np.empty(cap, np.int8)
    xs = np.empty(cap, np.float64)
    ys = np.empty(cap, np.float64)
    flags = np.empty(cap, np.int8)
    pcap = 4
    p_off = np.empty(pcap, np.int64)
    p_code = np.empty(pcap, np.int8)
    p_val = np.empty(pcap, np.int64)
    ni = 0
    npb = 0
    seven = False
    frac_bits = 0
    pending = 0  # ':' or '>' waiting for its number
    pen_up_next = False
    abs_next = False
    have_x = False
    cx = 0
    i = pos
    while i < n:
        c = b[i]
        if c == 59:
            i += 1
            break
        if c == 27:
            break
        if c == 58 or c == 60 or c == 62 or c == 61 or c == 55:  # : < > = 7
            if c == 55:
                seven = True
            elif c == 60:
                pen_up_next = True
            elif c == 61:
                abs_next = True
            else:
                pending = c
            i += 1
            continue
        if _pe_ign(c, seven):
            i += 1
            continue
        if _pe_cont(c, seven) or _pe_term(c, seven):
            if not _pe_looks_like_number(b, i, seven, cache):
                break
            value = 0
            shift = 0
            bits = 5 if seven else 6
            big = False
            while i < n:
                c = b[i]
                if _pe_cont(c, seven):
                    if shift < 60:
                        value |= (c - 63) << shift
                    elif c != 63:
                        big = True
                    shift += bits
                    i += 1
                elif _pe_term(c, seven):
                    d = c - (95 if seven else 191)
                    if shift < 60:
                        if shift > 0 and (d >> (62 - shift)) != 0:
                            big = True
                        else:
                            value |= d << shift
                    elif d != 0:
                        big = True
                    i += 1
                    break
                elif _pe_ign(c, seven):
                    i += 1
                else:
                    break
            if big or value > 2 * _PE_MAX + 1:
                num = _PE_MAX if (value & 1) == 0 else -_PE_MAX
                clamped = True
            else:
                num = -(value >> 1) if value & 1 else value >> 1
                clamped = num > _PE_MAX or num < -_PE_MAX
                if clamped:
                    num = _PE_MAX if num > 0 else -_PE_MAX
            if clamped:
                if npb == pcap:
                    pcap *= 2
                    p_off = _grow_i64(p_off, pcap)
                    p_code = _grow_i8(p_code, pcap)
                    p_val = _grow_i64(p_val, pcap)
                p_off[npb] = i
                p_code[npb] = PE_CLAMPED
                p_val[npb] = 0
                npb += 1
            if pending == 58:
                if ni == cap:
                    cap *= 2
                    kinds = _grow_i8(kinds, cap)
                    xs = _grow_f64(xs, cap)
                    ys = _grow_f64(ys, cap)
                    flags = _grow_i8(flags, cap)
                kinds[ni] = PE_PEN
                xs[ni] = num
                ys[ni] = 0.0
                flags[ni] = 0
                ni += 1
                pending = 0
            elif pending == 62:
                if 0 <= num <= 26:
                    frac_bits = num
                else:
                    if npb == pcap:
                        pcap *= 2
                        p_off = _grow_i64(p_off, pcap)
                        p_code = _grow_i8(p_code, pcap)
                        p_val = _grow_i64(p_val, pcap)
                    p_off[npb] = i
                    p_code[npb] = PE_FRACTION
                    p_val[npb] = num
                    npb += 1
                pending = 0
            elif not have_x:
                cx = num
                have_x = True
            else:
                have_x = False
                scale = float(1 << frac_bits) if frac_bits else 1.0
                if ni == cap:
                    cap *= 2
                    kinds = _grow_i8(kinds, cap)
                    xs = _grow_f64(xs, cap)
                    ys = _grow_f64(ys, cap)
                    flags = _grow_i8(flags, cap)
                kinds[ni] = PE_PAIR
                xs[ni] = cx / scale
                ys[ni] = num / scale
                flags[ni] = (1 if pen_up_next else 0) | (2 if abs_next else 0)
                ni += 1
                pen_up_next = False
                abs_next = False
            continue
        break
    for code in (PE_HALF_PAIR, PE_FLAG):
        if (code == PE_HALF_PAIR and have_x) or (code == PE_FLAG and pending != 0):
            if npb == pcap:
                pcap *= 2
                p_off = _grow_i64(p_off, pcap)
                p_code = _grow_i8(p_code, pcap)
                p_val = _grow_i64(p_val, pcap)
            p_off[npb] = i
            p_code[npb] = code
            p_val[npb] = 0
            npb += 1
    return i, kinds, xs, ys, flags, ni, p_off, p_code, p_val, npb


@njit(cache=True, nogil=True)
def _grow_i8(a, cap):
    out = np.empty(cap, np.int8)
    out[: a.shape[0]] = a
    return out


@njit(cache=True, nogil=True)
def _grow_i64(a, cap):
    out = np.empty(cap, np.int64)
    out[: a.shape[0]] = a
    return out


@njit(cache=True, nogil=True)
def _grow_f64(a, cap):
    out = np.empty(cap, np.float64)
    out[: a.shape[0]] = a
    return out
