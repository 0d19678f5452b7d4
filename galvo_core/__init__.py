"""galvo_core: all computation of the laser galvo marking workstation (no Qt, ever)."""

from __future__ import annotations

import os as _os

# One BLAS thread unless the user says otherwise (before numpy is first imported). The work
# here is element-wise or small solves (3x3), which OpenBLAS runs on one thread anyway; its
# thread pool costs 0.1-0.3 s of wall time at every start of the CLI on a busy 2-core machine
# (`galvo-core info seal.plt`: 0.33-0.52 s wall with the pool, 0.15 s without) and its
# spinning threads compete with the window's GUI thread. Has no effect once numpy is loaded.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")

from galvo_core.drawing import UNITS_PER_MM, Drawing, Path, SourcePos, Warning  # noqa: E402
from galvo_core.errors import GalvoError, InputError, ParamError  # noqa: E402

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
