"""Cross-check with an independent decoder: the ``ezhpgl`` package (Rust, written from the
HP-GL/2 reference), on every corpus file it reads in strict mode.

What is compared is what a user marks: the total pen-down length and the extent (bounding
box) of the pen-down geometry, within 1 %. ezhpgl's geometry is taken as it gives it
(millimetres, converted back at 40 units/mm): polylines and curves, and the pen-down edges of
polygon contours. Where the two readers differ on purpose the file is listed in
``DIFFERENT`` with the reason, and the test checks that the difference is that one.

Skipped when ezhpgl is not installed (it is in the ``test`` extra).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

ezhpgl = pytest.importorskip("ezhpgl")

from galvo_core.hpgl import read_file  # noqa: E402

PLT = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "plt"
if not PLT.is_dir():
    pytest.skip(f"corpus folder {PLT} not present", allow_module_level=True)

MM = 40.0  # plotter units per mm
LIMITS = ezhpgl.Limits(max_input_bytes=1 << 30, max_commands=1 << 26)
GEOMETRY = ezhpgl.GeometryLimits(max_operations=1 << 26, max_vertices=1 << 26)


def theirs(doc) -> tuple[float, tuple[float, float, float, float] | None]:
    """Pen-down length and extent of an ezhpgl document, in plotter units."""
    pieces: list[np.ndarray] = []
    for page in doc.pages:
        for op in page.operations:
            g = op.geometry
            if g.kind in ("polyline", "curve"):
                p = np.array([(q.x, q.y) for q in g.points], dtype=np.float64) * MM
                if len(p):
                    pieces.append(p)
            elif g.kind == "polygon":
                for c in g.contours:
                    p = np.array([(q.x, q.y) for q in c.points], dtype=np.float64) * MM
                    for e in c.edges:
                        if e.pen_down:
                            step = 1 if e.end >= e.start else -1
                            pieces.append(p[list(range(e.start, e.end + step, step))])
    length = float(sum(np.hypot(*np.diff(p, axis=0).T).sum() for p in pieces if len(p) > 1))
    if not pieces:
        return length, None
    allp = np.concatenate(pieces)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    return length, (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


def strict_files() -> list[str]:
    out = []
    for p in sorted(PLT.iterdir()):
        if not p.is_file() or "__expected" in p.name:
            continue
        try:
            ezhpgl.parse(p.read_bytes(), limits=LIMITS, geometry_limits=GEOMETRY)
        except Exception:  # noqa: BLE001 - ezhpgl refuses it: not cross-checked
            continue
        out.append(p.name)
    return out


# Files where the readers differ on purpose (checked to be that difference):
NO_PEN = "no SP (or SP0): ezhpgl draws nothing, as HP-GL/2 says; we draw with pen 1 or 0 and warn"
TWICE = "EP after FP / RA: ezhpgl gives the polygon once per command; we give one region"
CLIPPED = "IW: we clip to the window; ezhpgl keeps the whole line and attaches the window"
ROTATED = "RO: we rotate about the plotter origin; ezhpgl about the page corner"
DIFFERENT = {
    "dgtlrift__hp2xx__marr.pgl": NO_PEN,
    "drepetto__chiplotle__bird_by_brian_whitman_and_kelly_dobson.hpgl": NO_PEN,
    "dylanvanassche__java-hpgl2gcode__randomledcontroller_pen3.plt": NO_PEN,
    "orblivion__hpgl-coding-test__space-columbia.plt": NO_PEN,
    "straight-coding__gcode-hpgl-viewer__b_fabric_nesting.plt": NO_PEN,
    "cfriisha__hpgl2hitachi__v12v7a3-b_cu.plt": TWICE,
    "drepetto__chiplotle__hpgl_import_test_file.hpgl": TWICE,
    "temagrin__kicadhpgl2gcode__laser-b_cu.plt": TWICE,
    "dgtlrift__hp2xx__iw.hp": CLIPPED,
    "felixfischer__hpgl-viewer__input-window.hpgl": CLIPPED,
    "dgtlrift__hp2xx__286x192.5_qh2.hpg": ROTATED,
}
FILES = strict_files()


def test_ezhpgl_reads_a_good_part_of_the_corpus() -> None:
    assert len(FILES) >= 30, FILES


@pytest.mark.parametrize("name", FILES)
def test_pen_down_length_and_extent_agree_with_ezhpgl(name: str) -> None:
    doc = ezhpgl.parse((PLT / name).read_bytes(), limits=LIMITS, geometry_limits=GEOMETRY)
    their_len, their_box = theirs(doc)
    d = read_file(PLT / name)
    our_len = sum(p.length for p in d.paths)
    our_box = d.bbox()
    msgs = " ".join(w.message for w in d.warnings)
    why = DIFFERENT.get(name)
    if why is None:
        assert our_len == pytest.approx(their_len, rel=0.01, abs=1e-6)
        if their_box is None:
            assert our_box is None
        else:
            assert our_box is not None
            size = max(their_box[2] - their_box[0], their_box[3] - their_box[1], 1.0)
            assert max(abs(a - b) for a, b in zip(our_box, their_box, strict=True)) \
                <= 0.01 * size, (our_box, their_box)
    elif why is NO_PEN:
        assert their_len == 0 and our_len > 0
        assert "before any pen was selected" in msgs or "pen 0" in msgs
    elif why is TWICE:
        # ezhpgl = ours + our polygon-mode rings once more (they start at their PM0)
        lines = (PLT / name).read_bytes().split(b"\n")
        poly = sum(p.length for p in d.paths
                   if lines[p.start.line - 1][p.start.col - 1 :].upper().startswith(b"PM"))
        assert poly > 0 and {"EP", "FP"} <= set(d.commands)
        assert their_len == pytest.approx(our_len + poly, rel=0.01)
    elif why is CLIPPED:
        assert our_len < their_len and "clipped by the input window" in msgs
    elif why is ROTATED:
        assert our_len == pytest.approx(their_len, rel=0.01) and "RO" in d.commands
