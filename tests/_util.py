"""Small shared helpers for tests (no fixtures with side effects)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "resources" / "samples"


def run_cli(*args: str, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    """Run ``galvo-core`` in this process (its ``main(argv)``), as a user would see it: the
    exit code, stdout and stderr. ``timeout`` is kept for :func:`run_cli_subprocess`'s
    signature and not used here."""
    import contextlib
    import io

    from galvo_core import cli

    out, err = io.StringIO(), io.StringIO()
    with contextlib.chdir(ROOT), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = cli.main(list(args))
        except SystemExit as exc:  # argparse: --help (0), usage errors (2)
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    return subprocess.CompletedProcess(["galvo-core", *args], code, out.getvalue(),
                                       err.getvalue())


def run_cli_subprocess(*args: str, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    """Run ``galvo-core`` in a subprocess, end to end (the one test that does so)."""
    env = dict(os.environ)
    return subprocess.run(
        [sys.executable, "-m", "galvo_core.cli", *args],
        capture_output=True, text=True, timeout=timeout, cwd=ROOT, env=env,
    )


def circle_plt(r: float = 400.0, n: int = 720, *, decimals: int = 3, cx: float = 1000.0,
               cy: float = 1000.0) -> bytes:
    """A closed circle written as a dense PD run, like a CAD export."""
    import numpy as np

    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    pts = [(round(cx + r * np.cos(a), decimals), round(cy + r * np.sin(a), decimals)) for a in t]
    pts.append(pts[0])
    body = ",".join(f"{x},{y}" for x, y in pts[1:])
    return f"IN;SP1;PU{pts[0][0]},{pts[0][1]};PD{body};PU;SP0;".encode()


def waved_ellipse(seed: int, k: int, n: int = 20000):
    """The k-th smooth closed outline of a seed (an ellipse with a three-fold wave, 60-400
    units across, at most 1000 units from the origin): ``n`` exact (float) points."""
    import numpy as np

    rng = np.random.default_rng(seed)
    for _ in range(k + 1):
        a, b = rng.uniform(60, 400, 2)
        cx, cy = rng.uniform(0, 1000, 2)
        rot = rng.uniform(0, np.pi)
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 1.0 + 0.15 * np.cos(3 * t)
    x, y = a * r * np.cos(t), b * r * np.sin(t)
    c, s = np.cos(rot), np.sin(rot)
    return np.stack([cx + c * x - s * y, cy + s * x + c * y], axis=1)


def whole_units(points, *, closed: bool = True):
    """``points`` as a PLT file writes them: rounded to whole units, repeated points dropped
    (and, ``closed``, a last point equal to the first)."""
    import numpy as np

    w = np.round(np.asarray(points, dtype=np.float64))
    w = w[np.r_[True, (w[1:] != w[:-1]).any(axis=1)]]
    return w[:-1] if closed and len(w) > 1 and (w[-1] == w[0]).all() else w


def flattened_cubic(p0, c1, c2, p3, chord: float = 0.002):
    """The cubic p0 c1 c2 p3 flattened to chord height ``chord`` (equal parameter steps,
    as many as its second difference needs), float points from p0 to p3."""
    import math

    import numpy as np

    p0, c1, c2, p3 = (np.asarray(v, dtype=float) for v in (p0, c1, c2, p3))
    acc = 6.0 * max(np.hypot(*(p0 - 2 * c1 + c2)), np.hypot(*(c1 - 2 * c2 + p3)))
    n = max(1, math.ceil(math.sqrt(acc / (8 * chord))))
    t = np.linspace(0.0, 1.0, n + 1)[:, None]
    s = 1.0 - t
    return s**3 * p0 + 3 * s * s * t * c1 + 3 * s * t * t * c2 + t**3 * p3


def design_distance(fp, true) -> float:
    """Both-ways distance between a fitted path (its cubics flattened at 0.002 unit chords,
    its lines as they are) and the true design polyline ``true``: the issue's measure."""
    import numpy as np

    from galvo_core.geometry import flatten_cubic, point_polyline_distance

    fitted = np.vstack([flatten_cubic(s.points, 0.002) if s.kind == "cubic"
                        else np.asarray(s.points) for s in fp.segments])
    return max(float(point_polyline_distance(fitted, true).max()),
               float(point_polyline_distance(true, fitted).max()))


def resampled(poly, step: float):
    """The polyline ``poly`` with its points at most ``step`` apart (each edge divided
    evenly; the last point kept), so a distance measured from it sees the edges' insides."""
    import numpy as np

    poly = np.asarray(poly, dtype=np.float64)
    out = [poly[:1]]
    for a, b in zip(poly[:-1], poly[1:], strict=True):
        n = max(1, int(np.ceil(np.hypot(*(b - a)) / step)))
        out.append(a + np.linspace(0.0, 1.0, n + 1)[1:, None] * (b - a))
    return np.vstack(out)
