"""PLT / HP-GL / HP-GL/2 import: :func:`read_file` and :func:`read_bytes`."""

from __future__ import annotations

from galvo_core.hpgl.reader import read_bytes, read_file

__all__ = ["read_bytes", "read_file"]
