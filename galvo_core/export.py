"""Exporting a job: HP-GL (what the laser marks) and SVG (the fitted geometry, in mm).

:func:`write_plt` writes the **marks** by default: one ``PU x,y;PD x,y,...;`` per stroke,
coordinates the integer galvo bits themselves (1 plotter unit = 1 bit). That is exactly what
the controller is sent, it reads back with :func:`galvo_core.hpgl.read_file` point for point
(one path per stroke, identical integers), and any HP-GL viewer shows the marking points and
their facets. The scale is the field's, not 40 units per mm: a header comment says so
(``CO``, skipped by readers). ``what="segments"`` writes the fitted geometry instead, in
input units (the original drawing's scale): lines as ``PD``, cubics as HP-GL/2 ``BZ``
(readers flatten those; ours within 0.1 unit); hatch strokes without segments as their marks
converted back to input units.

:func:`write_svg` writes the fitted geometry as SVG paths with cubic ``C`` commands, in
millimetres on the workpiece (the field's lower-left corner at the origin, y upwards as in
the field, so the document flips y); hatch strokes and, optionally, the marks as small
dots. One ``<g>`` per layer.

Both write atomically (:func:`galvo_core.job.atomic_write_bytes`): a failed write leaves the
old file as it was.
"""

from __future__ import annotations

import os
from collections.abc import Iterable

import numpy as np

from galvo_core.errors import ParamError
from galvo_core.job import Job, atomic_write_bytes

__all__ = ["plt_bytes", "svg_bytes", "write_plt", "write_svg"]


def _num(v: float) -> str:
    """Shortest exact-enough decimal: integers without a point, else up to 6 decimals."""
    if float(v).is_integer():
        return str(int(v))
    s = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _pairs(pts: Iterable[Iterable[float]]) -> str:
    return ",".join(f"{_num(x)},{_num(y)}" for x, y in pts)


def plt_bytes(job: Job, *, what: str = "marks") -> bytes:
    """The HP-GL text of :func:`write_plt`."""
    if what not in ("marks", "segments"):
        raise ParamError(f"what must be 'marks' or 'segments', got {what!r}")
    fm = job.field_map
    out = ["IN;"]
    if what == "marks":
        out.append(f'CO"galvo marks of {_clean(job.source_name)}: 1 unit = 1 galvo bit = '
                   f'{fm.mm_per_bit * 1000.0:.4f} um; magnification {fm.magnification:g}";')
    else:
        out.append(f'CO"fitted geometry of {_clean(job.source_name)}, input units '
                   '(40 per mm of the drawing)";')
    pen = None
    for s in job.strokes:
        if pen != s.pen:
            pen = s.pen
            out.append(f"SP{max(1, int(pen))};")
        if what == "marks" or not s.segments:
            m = np.asarray(s.marks)
            if what == "segments":  # hatch strokes: marks back to input units
                m = (m - np.asarray(fm.offset_bits)) / fm.magnification
            if len(m) == 0:
                continue
            out.append(f"PU{_pairs(m[:1])};")
            rest = m[1:] if len(m) > 1 else m[:1]  # a dot: pen down on the spot
            out.append(f"PD{_pairs(rest)};")
            continue
        first = s.segments[0][1][0]
        out.append(f"PU{_pairs([first])};")
        for kind, pts in s.segments:
            p = np.asarray(pts, dtype=np.float64)
            if kind == "cubic":
                out.append(f"PD;BZ{_pairs(p[1:])};")
            else:
                out.append(f"PD{_pairs(p[1:])};")
    out.append("PU;SP0;")
    return ("\n".join(out) + "\n").encode("ascii")


def write_plt(job: Job, path: str | os.PathLike[str], *, what: str = "marks") -> None:
    """Write the job as an HP-GL file, atomically (see the module docstring)."""
    atomic_write_bytes(path, plt_bytes(job, what=what))


def _clean(text: str) -> str:
    return "".join(ch for ch in text if ch.isprintable() and ch not in '"<>&').encode(
        "ascii", "replace").decode("ascii")


def svg_bytes(job: Job, *, marks: bool = False, mark_radius_mm: float = 0.02) -> bytes:
    """The SVG text of :func:`write_svg`."""
    fm = job.field_map
    size = fm.field_size_mm
    k = fm.mm_per_bit
    ox, oy = fm.offset_bits

    def mm_units(p: np.ndarray) -> np.ndarray:  # input units -> (x mm, y mm down)
        b = np.asarray(p, dtype=np.float64) * fm.magnification + (ox, oy)
        return np.column_stack((b[:, 0] * k, size - b[:, 1] * k))

    def mm_bits(m: np.ndarray) -> np.ndarray:
        b = np.asarray(m, dtype=np.float64).reshape(-1, 2)
        return np.column_stack((b[:, 0] * k, size - b[:, 1] * k))

    def pt(p: np.ndarray) -> str:
        return f"{p[0]:.5f},{p[1]:.5f}"

    contour: list[str] = []
    hatch: list[str] = []
    for s in job.strokes:
        if s.segments:
            first = mm_units(s.segments[0][1][:1])[0]
            d = [f"M{pt(first)}"]
            for kind, pts in s.segments:
                q = mm_units(pts)
                if kind == "cubic":
                    d.append("C" + " ".join(pt(x) for x in q[1:]))
                else:
                    d.append("L" + pt(q[1]))
            if s.closed:
                d.append("Z")
            contour.append(f'<path d="{" ".join(d)}"/>')
        elif len(s.marks):
            q = mm_bits(s.marks)
            hatch.append(f'<polyline points="{" ".join(pt(x) for x in q)}"/>')
    parts = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{size:g}mm" height="{size:g}mm" '
        f'viewBox="0 0 {size:g} {size:g}">',
        f"<title>{_clean(job.source_name)}: fitted geometry, mm on the workpiece "
        f"(magnification {fm.magnification:g})</title>",
        '<g id="contours" fill="none" stroke="black" stroke-width="0.02">',
        *contour,
        "</g>",
    ]
    if hatch:
        parts += ['<g id="hatch" fill="none" stroke="blue" stroke-width="0.01">', *hatch,
                  "</g>"]
    if marks:
        r = f"{mark_radius_mm:g}"
        dots = []
        for s in job.strokes:
            for x in mm_bits(s.marks):
                dots.append(f'<circle cx="{x[0]:.5f}" cy="{x[1]:.5f}" r="{r}"/>')
        parts += ['<g id="marks" fill="red" stroke="none">', *dots, "</g>"]
    parts.append("</svg>")
    return ("\n".join(parts) + "\n").encode("utf-8")


def write_svg(job: Job, path: str | os.PathLike[str], *, marks: bool = False,
              mark_radius_mm: float = 0.02) -> None:
    """Write the fitted geometry as SVG (mm), optionally with the marks, atomically."""
    atomic_write_bytes(path, svg_bytes(job, marks=marks, mark_radius_mm=mark_radius_mm))
