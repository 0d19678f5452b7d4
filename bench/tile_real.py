"""Real drawings side by side (issue 21): copies of the bundled samples and of corpus
drawings with closed paths, in a grid of rows of ``per_row`` tiles, until the drawing has at
least ``n_points`` points. Input units; each tile keeps its true size."""

from __future__ import annotations

from pathlib import Path as FsPath

import numpy as np

from galvo_core.drawing import Drawing, Path
from galvo_core.hpgl import read_file

ROOT = FsPath(__file__).resolve().parents[1]
CORPUS = ROOT.parent / "shared" / "corpus" / "plt"
if not CORPUS.is_dir():
    CORPUS = FsPath("/work/shared/corpus/plt")
#: drawings with closed paths (regions to fill): samples first, then corpus files
SOURCES = (
    "resources/samples/seal.plt",
    "resources/samples/text_outline.plt",
    "resources/samples/dense_logo.plt",
    "resources/samples/arcs_circles.plt",
    "corpus:cfriisha__hpgl2hitachi__v12v7a3-b_cu.plt",
    "corpus:drepetto__chiplotle__bird_by_brian_whitman_and_kelly_dobson.hpgl",
    "corpus:dylanvanassche__java-hpgl2gcode__randomledcontroller_pen3.plt",
    "corpus:drepetto__chiplotle__foal_release-0.1.hpgl",
    "corpus:temagrin__kicadhpgl2gcode__laser-b_cu.plt",
    "corpus:bblanchon__hpglviewer__gl-c-f.plt",
)


def source_path(name: str) -> FsPath:
    if name.startswith("corpus:"):
        return CORPUS / name.split(":", 1)[1]
    return ROOT / name


def load_sources() -> list[Drawing]:
    out = []
    for name in SOURCES:
        p = source_path(name)
        if p.exists():
            out.append(read_file(p))
    return out


def tiled(n_points: int, per_row: int = 20, sources: list[Drawing] | None = None
          ) -> Drawing:
    """Copies of the sources in turn, side by side (rows of ``per_row``), >= n_points."""
    srcs = sources if sources is not None else load_sources()
    paths: list[Path] = []
    total = 0
    k = 0
    x = y = 0.0
    row_h = 0.0
    while total < n_points:
        d = srcs[k % len(srcs)]
        pts = [p.points for p in d.paths]
        allp = np.concatenate(pts)
        lo = allp.min(axis=0)
        w, h = allp.max(axis=0) - lo
        gap = 0.05 * max(w, h) + 40.0
        for p in d.paths:
            paths.append(Path(p.points - lo + (x, y), pen=p.pen, closed=p.closed,
                              start=p.start))
            total += len(p.points)
        x += w + gap
        row_h = max(row_h, h + gap)
        k += 1
        if k % per_row == 0:
            x, y, row_h = 0.0, y + row_h, 0.0
    return Drawing(tuple(paths), name=f"tiled_{n_points}.plt")
