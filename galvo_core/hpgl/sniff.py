"""Recognise files that are not HP-GL at all, to refuse them with a clear reason."""

from __future__ import annotations

import re

_SIGNATURES: list[tuple[bytes, str]] = [
    (b"%PDF", "a PDF document, not HP-GL"),
    (b"%!PS", "a PostScript document, not HP-GL"),
    (b"\x89PNG", "a PNG image, not HP-GL"),
    (b"GIF8", "a GIF image, not HP-GL"),
    (b"\xff\xd8\xff", "a JPEG image, not HP-GL"),
    (b"PK\x03\x04", "a ZIP archive, not HP-GL (unpack it first)"),
    (b"\x1f\x8b", "a gzip-compressed file, not HP-GL (decompress it first)"),
    (b"7z\xbc\xaf", "a 7-Zip archive, not HP-GL"),
    (b"Rar!", "a RAR archive, not HP-GL"),
    (b"\x7fELF", "a program (ELF binary), not HP-GL"),
    (b"MZ", "a Windows program, not HP-GL"),
    (b"AC10", "an AutoCAD DWG drawing, not HP-GL (plot it to PLT first)"),
    (b"\xef\xbb\xbf<", "an XML/SVG document, not HP-GL"),
]

_DXF_RE = re.compile(rb"\A\s*0\s*\r?\n\s*SECTION\b")
_XML_RE = re.compile(rb"\A\s*<(\?xml|svg|!DOCTYPE|html)", re.I)
_DMPL_RE = re.compile(rb"\A[\s\x00]*(?:\x1b;@:|;:[A-Z ])|;:H ?A\b")
_GCODE_RE = re.compile(rb"\A(\s*(\(.*\)|;.*)?\s*\n)*\s*[GM]\d+\b[^\n]*\n\s*[GMXYZF]", re.M)


def refusal_reason(head: bytes) -> str | None:
    """A reason to refuse the file, judged from its first bytes, or None to go on parsing.

    ``head`` is the start of the file with any leading NUL padding removed.
    """
    if not head.strip(b" \t\r\n\x00\x1a"):
        return "the file is empty"
    for sig, reason in _SIGNATURES:
        if head.startswith(sig):
            return reason
    if _XML_RE.match(head):
        return "an XML/SVG/HTML document, not HP-GL"
    if _DXF_RE.match(head):
        return "a DXF drawing, not HP-GL (export it as PLT/HP-GL first)"
    if _DMPL_RE.search(head[:4096]):
        return "a Summa DM/PL cutter file (';:' header): that dialect is not HP-GL"
    if _GCODE_RE.match(head):
        return "a G-code program, not HP-GL"
    return None
