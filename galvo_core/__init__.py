"""galvo_core: all computation of the laser galvo marking workstation (no Qt, ever)."""

from __future__ import annotations

from galvo_core.drawing import UNITS_PER_MM, Drawing, Path, SourcePos, Warning
from galvo_core.errors import GalvoError, InputError, ParamError

__version__ = "0.1.0"

__all__ = [
    "UNITS_PER_MM",
    "Drawing",
    "GalvoError",
    "InputError",
    "ParamError",
    "Path",
    "SourcePos",
    "Warning",
    "__version__",
]
