"""Synthetic PLT (HP-GL) files for parser benchmarks.

``generate_plt(n_points, seed=0)`` returns the bytes of a deterministic file with
exactly ``n_points`` coordinate pairs in PU/PD commands, mixing the shapes real
CAD exports take:

* long multi-point ``PD`` lists (AutoCAD style, a whole contour in one command)
* one point per command, ``PU x,y;`` then ``PD x,y;`` lines (CorelDRAW style)
* relative segments: ``PR;`` then ``PD dx,dy,...;`` and back with ``PA;``
* float coordinates (``PD 1234.5,678.25,...``)
* line ends CR/LF, LF only, or none (commands run together on one line)

Coordinates are plotter units (40 per mm) within 0..16000 (400 mm); the file
starts with ``IN;SP1;`` and ends with ``PU;SP0;``.

CLI::

    python bench/gen_plt.py 1000000 /tmp/big.plt
"""

from __future__ import annotations

import sys

import numpy as np

SIZE = 16000  # coordinate range in plotter units


def _walk(rng: np.random.Generator, n: int, step: float) -> np.ndarray:
    """A smooth random curve of ``n`` points (float), kept inside the field."""
    start = rng.uniform(0.1 * SIZE, 0.9 * SIZE, 2)
    heading = rng.uniform(0, 2 * np.pi)
    turn = np.cumsum(rng.normal(0.0, 0.08, n))
    ang = heading + turn
    steps = np.stack([np.cos(ang), np.sin(ang)], axis=1) * step
    pts = start + np.cumsum(steps, axis=0)
    # fold back into the field (reflect at the edges)
    pts = np.abs(pts) % (2 * SIZE)
    pts = np.where(pts > SIZE, 2 * SIZE - pts, pts)
    return pts


def _ints(a: np.ndarray) -> list[str]:
    return [str(v) for v in np.rint(a).astype(np.int64).ravel().tolist()]


def generate_plt(n_points: int, seed: int = 0) -> bytes:
    """A synthetic PLT of exactly ``n_points`` coordinate pairs, same bytes per seed."""
    if n_points < 1:
        raise ValueError("n_points must be at least 1")
    rng = np.random.default_rng(seed)
    out: list[str] = ["IN;SP1;\r\n"]
    left = n_points
    eols = (";\r\n", ";\n", ";")
    while left > 0:
        kind = rng.choice(4, p=(0.55, 0.2, 0.15, 0.1))
        eol = eols[int(rng.choice(3, p=(0.6, 0.3, 0.1)))]
        if kind == 0:  # long multi-point PD list, integer coordinates
            n = int(min(left, rng.integers(20, 2000)))
            pts = _walk(rng, n, rng.uniform(1.0, 4.0))
            s = _ints(pts)
            out.append(f"PU{s[0]},{s[1]}{eol}")
            if n > 1:
                out.append("PD" + ",".join(s[2:]) + eol)
        elif kind == 1:  # one point per PU/PD command
            n = int(min(left, rng.integers(5, 200)))
            pts = _walk(rng, n, rng.uniform(2.0, 20.0))
            s = _ints(pts)
            out.append(f"PU{s[0]},{s[1]}{eol}")
            out.extend(f"PD{s[i]},{s[i + 1]}{eol}" for i in range(2, len(s), 2))
        elif kind == 2:  # relative segments
            n = int(min(left, rng.integers(10, 500)))
            pts = np.rint(_walk(rng, n, rng.uniform(1.0, 6.0))).astype(np.int64)
            d = np.diff(pts, axis=0)
            out.append(f"PA;PU{pts[0, 0]},{pts[0, 1]}{eol}")
            if n > 1:
                out.append("PR;PD" + ",".join(map(str, d.ravel().tolist())) + eol)
            out.append("PA" + eol)
        else:  # float coordinates
            n = int(min(left, rng.integers(10, 800)))
            pts = _walk(rng, n, rng.uniform(0.5, 3.0))
            s = [f"{v:.2f}".rstrip("0").rstrip(".") for v in pts.ravel().tolist()]
            out.append(f"PU{s[0]},{s[1]}{eol}")
            if n > 1:
                out.append("PD" + ",".join(s[2:]) + eol)
        left -= n
    out.append("PU;SP0;\r\n")
    return "".join(out).encode("ascii")


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) not in (2, 3):
        print("usage: python bench/gen_plt.py N_POINTS OUT.plt [SEED]", file=sys.stderr)
        return 2
    n = int(argv[0])
    seed = int(argv[2]) if len(argv) == 3 else 0
    data = generate_plt(n, seed)
    with open(argv[1], "wb") as f:
        f.write(data)
    print(f"{argv[1]}: {n} points, {len(data)} bytes")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
