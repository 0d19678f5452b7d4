"""Compiled reading of runs of plain pen commands (PU PD PA PR with numbers, SP, PW) and of
polygon mode (PM0 PM1 PM2 EP FP).

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
left open when the pen is still down (``OPEN``). In polygon mode the moves go to a polygon
buffer instead; EP and FP write its rings as segments (see :func:`scan_moves`).

The module imports numba (about 0.2 s the first time in a process); the reader uses it only
for large inputs or when numba is already loaded (see ``reader._use_compiled``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

# int state slots
(I_POS, I_PEN, I_ABS, I_OPEN, I_NPTS, I_NSEG, I_CONT, I_NU, I_ND, I_NA, I_NR, I_FULL,
 I_NEED, I_PENNO, I_HPGL2, I_NSP, I_SPOK, I_LINE, I_LASTNL, I_NPW,
 # polygon mode: in PM, after PM1, buffer edged or filled, EP's segments (0: none, 1: in
 # this call, [I_EDGE_S0, I_EDGE_S1) and points [I_EDGE_P0, I_EDGE_P1) of the chunk, 2: the
 # caller's), PM0's offset, line, column (I_PLC: known), buffer points and completed rings,
 # EP/FP allowed (no IW window, no RO), PM/EP/FP counts, EP segments FP replaced; FT count
 I_POLY, I_FRESH, I_EMITTED, I_EDGED, I_EDGE_S0, I_EDGE_S1, I_EDGE_P0, I_EDGE_P1,
 I_POFF, I_PLINE, I_PCOL, I_PLC, I_NPB, I_NRING, I_POLYOK, I_NPM, I_NEP, I_NFP,
 I_DROP, I_NFT) = range(40)
N_ISTATE = 40
N_MOVE_STATE = 20  # slots I_POS..I_NPW: the move state the caller sets at every call
# I_FULL values: the output chunk is full / the polygon buffer is full
FULL_CHUNK, FULL_POLY = 1, 2
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

_MANY = 1 << 62  # "any number of parameters"


@njit(cache=True, nogil=True, boundscheck=False)
def _rings_fit(pb, rs, nr):
    """EP/FP may be read here: every completed ring has a point, every point is finite
    (the general reader drops a non-finite path with a warning)."""
    for r in range(nr):
        if rs[r + 1] <= rs[r]:
            return False
    for q in range(rs[nr]):
        if not (np.isfinite(pb[q, 0]) and np.isfinite(pb[q, 1])):
            return False
    return True


@njit(cache=True, nogil=True, boundscheck=False)
def _write_rings(pts, seg_start, seg_off, seg_pen, seg_line, seg_col, npts, nseg, pb, rs, rcl,
                 nr, fill, off, line, col, pen_no):
    """EP (``fill`` False): each ring's pen-down edges as a segment, closed when its closing
    edge is pen-down (a ring of one point has no edge); FP: each ring closed. Returns the
    points and segments used."""
    for r in range(nr):
        a = rs[r]
        e = rs[r + 1]
        if not fill and e - a < 2:
            continue
        seg_start[nseg] = npts
        seg_off[nseg] = off
        seg_line[nseg] = line
        seg_col[nseg] = col
        seg_pen[nseg] = pen_no
        nseg += 1
        for q in range(a, e):
            pts[npts, 0] = pb[q, 0]
            pts[npts, 1] = pb[q, 1]
            npts += 1
        if (fill or rcl[r]) and not (pb[a, 0] == pb[e - 1, 0] and pb[a, 1] == pb[e - 1, 1]):
            pts[npts, 0] = pb[a, 0]
            pts[npts, 1] = pb[a, 1]
            npts += 1
    return npts, nseg


@njit(cache=True, nogil=True, boundscheck=False)
def scan_moves(b, ist, fst, pts, seg_start, seg_off, seg_pen, seg_line, seg_col, pb, rs, rcl,
               pow10, cls):
    """Read PU/PD/PA/PR (and SP, PW, and in polygon mode PM, EP, FP) commands from
    ``ist[I_POS]`` on; see the module docstring.

    ``ist``/``fst`` hold the state in and out (position, pen down, absolute mode, path
    open, points and segments used in the chunk, counts per command, pen number, dialect,
    polygon mode); ``pts`` (cap, 2) and the segment arrays are the chunk. One pass: a
    command is applied as it is read and rolled back (state restored, nothing kept) when it
    turns out to need the general reader. Stops at the first command it does not read, or
    (``I_FULL`` = FULL_CHUNK) before a command that does not fit the chunk (``I_NEED``
    points asked for), or (FULL_POLY) one whose moves do not fit the polygon buffer.

    Polygon mode (as the general reader's ``_Reader._poly_move``, ``do_pm``,
    ``do_edge_fill``): the buffer is ``pb`` (points), ``rs`` (ring k is
    ``pb[rs[k]:rs[k + 1]]``, the ring being drawn ``pb[rs[nr]:npb]``) and ``rcl`` (the pen
    state of each completed ring's closing edge; its other edges are pen-down). A pen-down
    move adds a point; a pen-up move ends the ring (when it has an edge) and starts the next
    at the new point; PM1/PM2 close the ring with the current pen state; the move after
    PM1 starts the next ring. EP writes each ring's pen-down edges as a segment (closed
    when the closing edge is pen-down), FP each ring closed; FP right after EP (nothing
    drawn between) replaces EP's segments.
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
    # polygon mode
    in_poly = ist[I_POLY]
    fresh = ist[I_FRESH]
    emitted = ist[I_EMITTED]
    edged = ist[I_EDGED]
    e_s0 = ist[I_EDGE_S0]
    e_s1 = ist[I_EDGE_S1]
    e_p0 = ist[I_EDGE_P0]
    e_p1 = ist[I_EDGE_P1]
    poff = ist[I_POFF]
    pline = ist[I_PLINE]
    pcol = ist[I_PCOL]
    plc = ist[I_PLC]
    npb = ist[I_NPB]
    nr = ist[I_NRING]
    poly_ok = ist[I_POLYOK] != 0
    pcap = pb.shape[0]
    rcap = rs.shape[0]
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
    nr_ = 0
    nsp = 0
    npw = 0
    npm = 0
    nep = 0
    nfp = 0
    nft = 0
    drop = 0
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
            elif c1 == 109:  # 'pm'
                code = 6
            else:
                break
        elif c1 == 112:
            if c0 == 115 and ist[I_SPOK] != 0:  # 'sp' (once a pen was selected)
                code = 4
            elif c0 == 101:  # 'ep'
                code = 7
            elif c0 == 102:  # 'fp'
                code = 8
            else:
                break
        elif c0 == 102 and c1 == 116:  # 'ft': fill type, recorded, not drawn
            code = 9
        else:
            break
        cmd_at = j
        cmd_line = tl
        cmd_col = j - tn
        k = j + 2
        # state at the command's start, to roll back to
        r_pen, r_absm, r_open, r_npts, r_nseg, r_x, r_y = pen, absm, is_open, npts, nseg, x, y
        r_npb, r_nr, r_fresh = npb, nr, fresh
        r_q0 = -1
        r_p0x = r_p0y = 0.0
        if in_poly:
            # the ring being drawn: its first point is overwritten when a move replaces it
            r_q0 = rs[nr]
            r_p0x = pb[r_q0, 0]
            r_p0y = pb[r_q0, 1]
        if code == 0:
            if pen == 1:
                pen = 0
                is_open = 0
        elif code == 1:
            if pen == 0:
                pen = 1
                if not in_poly:
                    if npts + 1 > cap or nseg + 2 > scap:
                        ist[I_FULL] = FULL_CHUNK
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
        elif code == 3:
            absm = 0
        # the parameters: pairs applied as read; the numbers of the commands without
        # geometry of their own (SP, PW, PM, EP, FP) counted (at most ``most``; PM with
        # more than one number is the general reader's), the command applied after
        most = 1 if code == 4 or code == 6 else (2 if code == 5 else _MANY)
        count = 0
        ok = True
        full = 0
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
            # the number at k, read in place: the only copy of the number syntax (a helper
            # function per number costs 2-4 times the whole scan: the arrays' reference
            # counts, even inlined); at most 15 digits, "1.2.3", a sign or point without
            # digits, junk right after: the general reader's
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
                # (a command without geometry never completes a pair: its numbers are
                # counted, the last kept, without a test per number in the moves' loop)
                vx = v
                half = code < 4
                count += 1
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
            if in_poly:
                if npb + 1 > pcap or nr + 2 > rcap:
                    full = FULL_POLY
                    break
                if fresh:
                    # the first move after PM1 starts the next ring: a pen-up move
                    # whatever the pen state
                    fresh = 0
                    npb = rs[nr]
                elif pen == 0:
                    # a pen-up move ends the ring (when it has an edge; its closing edge
                    # is pen-up), the next starts at the new point
                    if npb - rs[nr] > 1:
                        rcl[nr] = 0
                        nr += 1
                        rs[nr] = npb
                    npb = rs[nr]
                pb[npb, 0] = nx
                pb[npb, 1] = ny
                npb += 1
            elif pen == 1:
                if npts + 2 > cap or nseg + 2 > scap:
                    full = FULL_CHUNK
                    break
                if is_open == 0:
                    # the pen is down but the path was ended (SP, CI, PM, ...): a new
                    # path starts at the current point
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
        if code >= 4 and count > most:
            ok = False
        if full or not ok or half:
            # roll back: the general reader reads this command (or a larger chunk or
            # buffer is made)
            pen, absm, is_open, npts, nseg, x, y = r_pen, r_absm, r_open, r_npts, r_nseg, r_x, r_y
            npb, nr, fresh = r_npb, r_nr, r_fresh
            if r_q0 >= 0:
                pb[r_q0, 0] = r_p0x
                pb[r_q0, 1] = r_p0y
            if full:
                ist[I_FULL] = full
                ist[I_NEED] = 2 * (pcap if full == FULL_POLY else cap)
            break
        if code == 4:
            # SP [n]: ends the path; HP-GL/2 keeps the pen down, HP-GL/1 lifts it
            pen_no = int(vx) if count else 0
            is_open = 0
            if not hpgl2:
                pen = 0
            nsp += 1
        elif code == 5:
            # PW [width[,pen]]: no geometry; the file is HP-GL/2 from here on (as the
            # general reader says)
            hpgl2 = True
            npw += 1
        elif code == 6:
            mode = int(vx) if count else 0
            if mode == 0:
                if in_poly:
                    break  # PM0 inside PM: the general reader warns
                # PM0: the path ends, a new buffer starts at the current point
                is_open = 0
                in_poly = 1
                nr = 0
                rs[0] = 0
                pb[0, 0] = x
                pb[0, 1] = y
                npb = 1
                fresh = 0
                emitted = 0
                edged = 0
                poff = cmd_at
                pline = cmd_line
                pcol = cmd_col
                plc = 1
            elif mode == 1 or mode == 2:
                if not in_poly:
                    break  # PM1/PM2 outside PM: the general reader warns
                if npb + 1 > pcap or nr + 2 > rcap:
                    ist[I_FULL] = FULL_POLY
                    ist[I_NEED] = 2 * pcap
                    break
                # close the ring with the current pen state, the next starts here
                if npb - rs[nr] > 1:
                    rcl[nr] = pen
                    nr += 1
                    rs[nr] = npb
                npb = rs[nr]
                pb[npb, 0] = x
                pb[npb, 1] = y
                npb += 1
                if mode == 1:
                    fresh = 1
                else:
                    in_poly = 0
            else:
                break  # unknown mode: the general reader warns
            npm += 1
        elif code == 7:
            if in_poly:
                break  # EP inside PM: the general reader warns
            if not emitted:
                # (a path still open is written after EP's in the general reader)
                if is_open or not poly_ok or not plc or not _rings_fit(pb, rs, nr):
                    break
                need = rs[nr] + nr
                if npts + need > cap or nseg + nr + 2 > scap:
                    ist[I_FULL] = FULL_CHUNK
                    ist[I_NEED] = need
                    break
                e_s0 = nseg
                e_p0 = npts
                npts, nseg = _write_rings(pts, seg_start, seg_off, seg_pen, seg_line, seg_col,
                                          npts, nseg, pb, rs, rcl, nr, False, poff, pline,
                                          pcol, pen_no)
                e_s1 = nseg
                e_p1 = npts
                emitted = 1
                edged = 1
            nep += 1
        elif code == 8:
            if in_poly:
                break  # FP inside PM: the general reader warns
            if edged == 2:
                break  # EP's paths are the caller's: it replaces them
            if edged == 1 and (nseg != e_s1 or npts != e_p1):
                break  # something was drawn after EP's paths
            if not emitted or edged == 1:
                if is_open or not poly_ok or not plc or not _rings_fit(pb, rs, nr):
                    break
                s_at = e_s0 if edged == 1 else nseg
                p_at = e_p0 if edged == 1 else npts
                need = rs[nr] + nr
                if p_at + need > cap or s_at + nr + 2 > scap:
                    ist[I_FULL] = FULL_CHUNK
                    ist[I_NEED] = need
                    break
                if edged == 1:
                    # a buffer edged and filled is one region: the rings replace EP's
                    # segments
                    drop += e_s1 - e_s0
                npts, nseg = _write_rings(pts, seg_start, seg_off, seg_pen, seg_line, seg_col,
                                          p_at, s_at, pb, rs, rcl, nr, True, poff, pline,
                                          pcol, pen_no)
                emitted = 1
                edged = 0
            nfp += 1
        elif code == 9:
            nft += 1  # FT [type[,option...]]: nothing to apply (the general reader's too)
        elif code == 0:
            nu += 1
        elif code == 1:
            nd_ += 1
        elif code == 2:
            na += 1
        else:
            nr_ += 1
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
    ist[I_NR] = nr_
    ist[I_NSP] = nsp
    ist[I_NPW] = npw
    ist[I_HPGL2] = 1 if hpgl2 else 0
    ist[I_POLY] = in_poly
    ist[I_FRESH] = fresh
    ist[I_EMITTED] = emitted
    ist[I_EDGED] = edged
    ist[I_EDGE_S0] = e_s0
    ist[I_EDGE_S1] = e_s1
    ist[I_EDGE_P0] = e_p0
    ist[I_EDGE_P1] = e_p1
    ist[I_POFF] = poff
    ist[I_PLINE] = pline
    ist[I_PCOL] = pcol
    ist[I_PLC] = plc
    ist[I_NPB] = npb
    ist[I_NRING] = nr
    ist[I_NPM] = npm
    ist[I_NEP] = nep
    ist[I_NFP] = nfp
    ist[I_NFT] = nft
    ist[I_DROP] = drop
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
