"""Field correction: .cor layouts, bilinear shifts, straight lines stay straight, 3x3 grids,
applied once."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from galvo_core.correction import (
    CELL,
    GRID,
    FieldCorrection,
    apply_to_job,
    from_3x3,
    load_3x3,
    read_cor,
    write_cor,
)
from galvo_core.errors import InputError
from galvo_core.field import FieldMap
from galvo_core.job import Job, Stroke
from galvo_core.params import LaserParams


def pincushion(p: np.ndarray, k: float = 4e-9) -> np.ndarray:
    """A lens-like error field (bits): radial, cubic in the distance from the centre."""
    q = np.asarray(p, dtype=np.float64) - 32768.0
    r2 = (q ** 2).sum(axis=1, keepdims=True)
    return k * r2 * q * 1e-4 + np.array([[3.0, -2.0]])


def grid_of(fn) -> FieldCorrection:
    g = np.arange(GRID) * CELL
    gx, gy = np.meshgrid(g, g)
    p = np.stack([gx.ravel(), gy.ravel()], axis=1)
    v = fn(p)
    return FieldCorrection(v[:, 0].reshape(GRID, GRID), v[:, 1].reshape(GRID, GRID), "t")


def test_bilinear_is_exact_at_nodes_and_linear_along_grid_lines():
    corr = grid_of(lambda p: -pincushion(p))
    nodes = np.array([[0, 0], [1024, 5 * 1024], [65536, 65536], [32768, 1024]])
    np.testing.assert_allclose(corr.shift(nodes), -pincushion(nodes), atol=1e-9)
    mid = np.array([[512.0, 5 * 1024]])
    np.testing.assert_allclose(corr.shift(mid), (corr.shift(nodes[:1] * 0 + [[0, 5120]])
                                                 + corr.shift([[1024, 5120]])) / 2)


@pytest.mark.parametrize("tol", [0.25, 1.0])
def test_long_lines_are_subdivided_so_they_stay_straight(tol):
    corr = grid_of(lambda p: -pincushion(p, 4e-8))  # up to ~90 bits of shift
    line = np.array([[2000, 3000], [63000, 9000], [5000, 61000]])
    out = corr.apply(line, tol_bits=tol)
    # the true corrected curve: each point of the straight line moved by the table
    t = np.linspace(0, 1, 4001)[:, None]
    dense = np.vstack([line[0] + t * (line[1] - line[0]), line[1] + t * (line[2] - line[1])])
    want = dense + corr.shift(dense)
    # every point of the true curve is within tol (+ rounding to whole bits) of the marks
    seg_a, seg_b = out[:-1].astype(float), out[1:].astype(float)
    d = seg_b - seg_a
    w = want[:, None, :] - seg_a[None]
    s = np.clip((w * d).sum(-1) / np.maximum((d * d).sum(-1), 1e-12), 0, 1)
    dist = np.hypot(*(w - s[..., None] * d).transpose(2, 0, 1)).min(axis=1)
    assert dist.max() <= tol + 0.75
    # and without the subdivision, the corrected chord misses the curve by far more
    a, b = line[:2] + corr.shift(line[:2])
    w = want[:4001] - a
    off = np.abs((b - a)[0] * w[:, 1] - (b - a)[1] * w[:, 0]) / np.hypot(*(b - a))
    assert off.max() > 5 * (tol + 0.75)
    assert out[0].tolist() == np.floor(line[0] + corr.shift(line[:1])[0] + 0.5).tolist()


def test_affine_tables_add_no_points():
    corr = grid_of(lambda p: np.tile([[5.0, -7.0]], (len(p), 1)))  # a pure offset
    m = np.array([[100, 100], [900, 800], [60000, 61000]])
    np.testing.assert_array_equal(corr.apply(m), m + [5, -7])
    scale = grid_of(lambda p: (p - 32768.0) * 1e-3)  # 0.1 % too small a field
    out = scale.apply(m)
    assert len(out) == 3
    np.testing.assert_array_equal(out, np.floor(m + (m - 32768.0) * 1e-3 + 0.5))


def write_v1(path, table):  # (65, 65, 2) [iy, ix]
    label = "LMC1COR_1.0".encode("utf-16-le")
    head = label + b"\0" * 2 + struct.pack("<63d", *([0.0] * 43 + [595.0] + [0.0] * 19))
    path.write_bytes(head + table.astype("<f8").tobytes())


def test_cor_layouts(tmp_path):
    rng = np.random.default_rng(3)
    table = rng.integers(-300, 300, size=(GRID, GRID, 2)).astype(float)
    write_v1(tmp_path / "a.cor", table)
    c1 = read_cor(tmp_path / "a.cor")
    np.testing.assert_array_equal(c1.dx, table[:, :, 0])
    np.testing.assert_array_equal(c1.dy, table[:, :, 1])
    write_cor(tmp_path / "b.cor", c1)
    c2 = read_cor(tmp_path / "b.cor")
    np.testing.assert_array_equal(c2.dx, c1.dx)
    assert (tmp_path / "b.cor").stat().st_size == 0x24 + 65 * 65 * 8
    # galvoplotter reads the same integer table (its sign-magnitude words)
    galvo = pytest.importorskip("galvo")
    def sign_magnitude(v):
        v = int(v)
        return v if v >= 0 else -v + 0x8000

    want = [[sign_magnitude(dx), sign_magnitude(dy)] for dx, dy in table.reshape(-1, 2)]
    reader = galvo.GalvoController(mock=True)
    assert reader._read_correction_file(str(tmp_path / "b.cor")) == want  # integer layout
    assert reader._read_correction_file(str(tmp_path / "a.cor")) == want  # LMC1COR_1.0
    (tmp_path / "c.cor").write_bytes(b"short")
    with pytest.raises(InputError, match="c.cor: not a .cor"):
        read_cor(tmp_path / "c.cor")


def test_from_3x3_inverts_a_measured_distortion():
    # the lens moves a mark aimed at p to p + e(p); measure e at the 3x3 pattern
    def e(p):
        q = (np.asarray(p, dtype=float) - 32768.0) / 32768.0
        return np.stack([60 * q[:, 0] * q[:, 1] ** 2 + 20 * q[:, 0] ** 2,
                         -45 * q[:, 1] * q[:, 0] ** 2 + 10], axis=1)

    span = 60000.0
    c = 32768.0
    pts = np.array([[c + (ix - 1) * span / 2, c + (iy - 1) * span / 2]
                    for iy in range(3) for ix in range(3)])
    corr = from_3x3(e(pts).reshape(3, 3, 2), span)
    rng = np.random.default_rng(0)
    p = rng.uniform(4000, 61000, size=(500, 2))
    landed = p + corr.shift(p)
    landed = landed + e(landed)
    err = np.hypot(*(landed - p).T)
    before = np.hypot(*e(p).T)
    assert before.max() > 40
    assert err.max() < 2.0  # biquadratic error field, bilinear grid of 1024-bit cells


def test_load_3x3_toml(tmp_path):
    p = tmp_path / "m.toml"
    p.write_text("span_mm = 100\ndx_mm = [[0.1, 0, -0.1], [0.05, 0, -0.05], [0.1, 0, -0.1]]\n"
                 "dy_mm = [[0, 0, 0], [0, 0, 0], [0, 0, 0]]\n")
    corr = load_3x3(p)
    bpm = 65536 / 110
    # the left column landed 0.1 mm too far right: correct by -0.1 mm there
    assert corr.shift(np.array([[32768 - 50 * bpm, 32768 - 50 * bpm]]))[0, 0] == \
        pytest.approx(-0.1 * bpm, rel=0.05)
    p.write_text("span_mm = 100\ndx_mm = [[0.1, 0]]\ndy_mm = 1\n")
    with pytest.raises(InputError, match="m.toml: "):
        load_3x3(p)


def test_job_is_corrected_once():
    fm = FieldMap(1.0, (0.0, 0.0), 65536, 110.0)
    job = Job("t.plt", "", fm, {}, LaserParams().as_dict(),
              (Stroke("contour", 0, False, np.array([[1000, 1000], [60000, 50000]]), (), 1),))
    corr = grid_of(lambda p: -pincushion(p, 4e-8))
    done = apply_to_job(job, corr)
    assert done.field_correction["applied"] is True
    assert len(done.strokes[0].marks) > 2
    with pytest.raises(InputError, match="already field-corrected"):
        apply_to_job(done, corr)
    far = grid_of(lambda p: np.tile([[-2000.0, 0.0]], (len(p), 1)))
    with pytest.raises(InputError, match=r"strokes\[0\].*outside 0\.\.65535"):
        apply_to_job(job, far)


def test_many_strokes_at_once_equal_one_by_one():
    corr = grid_of(lambda p: -pincushion(p, 4e-8))
    rng = np.random.default_rng(5)
    strokes = [rng.integers(2000, 63000, size=(int(k), 2)) for k in rng.integers(0, 9, 40)]
    strokes[3] = np.array([[5000, 5000], [5000, 5000], [5000, 5000]])  # collapses to one
    many = corr.apply_many(strokes)
    assert len(many) == len(strokes)
    for m, got in zip(strokes, many, strict=True):
        np.testing.assert_array_equal(got, corr.apply(m))
