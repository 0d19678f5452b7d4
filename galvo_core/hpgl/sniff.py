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
    (b"\xfd7zXZ\x00", "an xz-compressed file, not HP-GL (decompress it first)"),
    (b"\x28\xb5\x2f\xfd", "a zstd-compressed file, not HP-GL (decompress it first)"),
    (b"\x1f\x9d", "a compress (.Z) file, not HP-GL (decompress it first)"),
]

_DXF_RE = re.compile(rb"\A\s*0\s*\r?\n\s*SECTION\b")
_BZIP2_RE = re.compile(rb"\ABZh[1-9]1AY&SY")
_CDR_RE = re.compile(rb"\ARIFF....CDR", re.S)
# Gerber (RS-274X: %FS / %MO parameters, G04 comments) and Excellon drill files (M48)
_GERBER_RE = re.compile(rb"\A\s*(?:G04[^\n]*\n\s*)*%(?:FS|MO|TF)")
_EXCELLON_RE = re.compile(rb"\A\s*(?:;[^\n]*\n\s*)*M48\s*\n")
_XML_RE = re.compile(rb"\A\s*<(\?xml|svg|!DOCTYPE|html)", re.I)
_DMPL_RE = re.compile(rb"\A[\s\x00]*(?:\x1b;@:|;:[A-Z ])|;:H ?A\b")
_GCODE_RE = re.compile(rb"\A(\s*(\(.*\)|;.*)?\s*\n)*\s*[GM]\d+\b[^\n]*\n\s*[GMXYZF]", re.M)
_PCL_HEAD_RE = re.compile(rb"[\x00-\x20]*(?:\x1b|@PJL)")
# control bytes that neither HP-GL text nor PE data contain (TAB LF FF CR ESC ETX excluded)
_CONTROL = bytes(b for b in range(32) if b not in (3, 9, 10, 12, 13, 27))


def _looks_binary(head: bytes) -> bool:
    """Random-looking binary: many control bytes *and* many high bytes.

    Real files have one or the other (labels with control bytes; 8-bit PE data with high
    bytes), never both in quantity. PCL/PJL jobs are left to the reader (raster data).
    """
    if len(head) < 256 or _PCL_HEAD_RE.match(head):
        return False
    n = len(head)
    controls = n - len(head.translate(None, _CONTROL))
    high = n - len(head.translate(None, bytes(range(128, 256))))
    return controls > 0.07 * n and high > 0.25 * n


def refusal_reason(head: bytes) -> str | None:
    """A reason to refuse the file, judged from its first bytes, or None to go on parsing.

    ``head`` is the start of the file with any leading NUL padding removed.
    """
    if not head.strip(b" \t\r\n\x00\x1a"):
        return "the file is empty"
    for sig, reason in _SIGNATURES:
        if head.startswith(sig):
            return reason
    if _BZIP2_RE.match(head):
        return "a bzip2-compressed file, not HP-GL (decompress it first)"
    if _CDR_RE.match(head):
        return "a CorelDRAW drawing, not HP-GL (export it as PLT/HP-GL first)"
    if _GERBER_RE.match(head):
        return "a Gerber (RS-274X) file, not HP-GL"
    if _EXCELLON_RE.match(head):
        return "an Excellon drill file, not HP-GL"
    if _XML_RE.match(head):
        return "an XML/SVG/HTML document, not HP-GL"
    if _DXF_RE.match(head):
        return "a DXF drawing, not HP-GL (export it as PLT/HP-GL first)"
    if _DMPL_RE.search(head[:4096]):
        return "a Summa DM/PL cutter file (';:' header): that dialect is not HP-GL"
    if _GCODE_RE.match(head):
        return "a G-code program, not HP-GL"
    if _looks_binary(head):
        return "binary data (not text): not an HP-GL/PLT file"
    return None
