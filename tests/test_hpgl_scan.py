"""The compiled scanner (galvo_core.hpgl.scan) reads exactly what the command-by-command
reader reads: same points (bit for bit), pens, closed flags, positions, warnings and command
counts, also when its output chunks fill up in the middle of paths and commands."""

from __future__ import annotations

import random
from unittest import mock

import numpy as np
import pytest

import galvo_core.hpgl.reader as reader
from galvo_core.hpgl import read_bytes

pytest.importorskip("numba")


def _read(data: bytes, compiled: bool, chunk: int = reader._CHUNK_POINTS):
    with mock.patch.object(reader, "_use_compiled", lambda size: compiled), \
            mock.patch.object(reader, "_FAST_MIN_BYTES", 10**12), \
            mock.patch.object(reader, "_CHUNK_POINTS", chunk):
        return read_bytes(data, "scan.plt")


def assert_same(a, b) -> None:
    assert len(a.paths) == len(b.paths)
    for p, q in zip(a.paths, b.paths, strict=True):
        assert np.array_equal(p.points, q.points)
        assert (p.pen, p.closed, p.start) == (q.pen, q.closed, q.start)
        assert not p.points.flags.writeable
    assert a.warnings == b.warnings
    assert dict(a.commands) == dict(b.commands)


def _program(rng: random.Random, n: int) -> bytes:
    out = [b"IN;SP1;"]
    for _ in range(n):
        r = rng.random()
        if r < 0.3:
            out.append(b"PU%d,%d;" % (rng.randint(-999, 999), rng.randint(-999, 999)))
        elif r < 0.6:
            k = rng.randint(0, 40)
            nums = ",".join(f"{rng.uniform(-500, 500):.{rng.randint(0, 3)}f}" for _ in range(2 * k))
            out.append(b"PD" + nums.encode() + b";")
        elif r < 0.7:
            out.append(b"PR;" if rng.random() < 0.5 else b"PA;")
        elif r < 0.8:
            out.append(b"SP%d;" % rng.randint(0, 4))
        elif r < 0.85:
            out.append(rng.choice([b"LT;", b"CI5;", b"PD1:2;", b"PD1,2,3;", b"BP;", b"\n",
                                   b"SC0,100,0,100;", b"SC;", b"PD1.2.3,4;", b"LBab\x03"]))
        else:
            out.append(b"PD%d,%d" % (rng.randint(0, 99), rng.randint(0, 99)))  # no ';'
    return b"".join(out)


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("chunk", [8, 1 << 16])
def test_compiled_scanner_reads_what_the_general_reader_reads(seed: int, chunk: int) -> None:
    data = _program(random.Random(seed), 400)
    assert_same(_read(data, True, chunk), _read(data, False))


def test_one_long_command_across_many_chunks() -> None:
    """A single PD with 5000 pairs, chunks of 8 points: the chunk grows, the path is one."""
    body = ",".join(f"{k},{k % 7}" for k in range(5000)).encode()
    data = b"IN;SP1;PU0,0;PD" + body + b";PU;"
    a, b = _read(data, True, 8), _read(data, False)
    assert_same(a, b)
    assert len(a.paths) == 1 and len(a.paths[0].points) == 5001


def test_path_open_across_an_interruption_is_one_path() -> None:
    """A path the scanner leaves open goes on after a command it hands over (LT)."""
    data = b"IN;SP1;PU0,0;PD1,1;LT;PD2,2;LT;PD3,3;PU;"
    a = _read(data, True, 8)
    assert_same(a, _read(data, False))
    np.testing.assert_array_equal(a.paths[0].points, [[0, 0], [1, 1], [2, 2], [3, 3]])
