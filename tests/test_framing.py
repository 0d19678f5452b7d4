"""Framing: the outline (bbox, convex hull) and the light-only list, golden vs galvoplotter."""

from __future__ import annotations

import numpy as np
import pytest
from _lmc_util import make_job, rng_strokes

from galvo_core.framing import frame_records, outline
from galvo_core.lmc import (
    END_OF_LIST,
    JUMP_TO,
    LASER_ON_POINT,
    MARK_TO,
    WRITE_PORT,
    Orientation,
    bits_per_mm,
    decode,
    to_bytes,
)
from galvo_core.params import LaserParams


def test_bbox_and_hull_enclose_every_mark():
    job = make_job(rng_strokes(2, 20, (1, 2)))
    allm = np.concatenate([s.marks for s in job.strokes])
    box = outline(job, "bbox")
    assert box.min(axis=0).tolist() == allm.min(axis=0).tolist()
    assert box.max(axis=0).tolist() == allm.max(axis=0).tolist()
    hull = outline(job, "hull")
    assert len(hull) >= 3
    # every vertex is a mark; every mark is inside or on the hull (counter-clockwise)
    marks = {tuple(m) for m in allm.tolist()}
    assert all(tuple(v) in marks for v in hull.tolist())
    a = hull.astype(float)
    b = np.roll(a, -1, axis=0)
    cross = ((b[:, 0] - a[:, 0])[None] * (allm[:, 1:2] - a[:, 1][None])
             - (b[:, 1] - a[:, 1])[None] * (allm[:, 0:1] - a[:, 0][None]))
    assert (cross >= 0).all()


def test_frame_list_is_light_only_and_loops():
    job = make_job([(1, [(1000, 2000), (5000, 7000)])])
    rec = frame_records(outline(job), 3, job)
    cmds = set(rec[:, 0].tolist())
    assert MARK_TO not in cmds and LASER_ON_POINT not in cmds
    port = rec[rec[:, 0] == WRITE_PORT]
    assert port[:, 1].tolist() == [1 << 8]  # the light pin, laser pin off
    jumps = rec[rec[:, 0] == JUMP_TO][:, 1:3].tolist()
    assert jumps == [[1000, 2000]] + [[5000, 2000], [5000, 7000], [1000, 7000],
                                      [1000, 2000]] * 3
    assert rec[-1, 0] == END_OF_LIST and (rec[:-1, 0] != END_OF_LIST).all()
    assert decode(to_bytes(rec)).ended


def test_frame_orientation():
    job = make_job([(1, [(1000, 2000), (5000, 7000)])])
    box = outline(job, orientation=Orientation(swap_xy=True))
    assert box[0].tolist() == [2000, 1000]


@pytest.mark.parametrize("shape", ["bbox", "hull"])
def test_golden_frame_matches_galvoplotter_lighting(shape):
    galvo = pytest.importorskip("galvo")
    job = make_job(rng_strokes(4, 15, (1,)))
    las = LaserParams(jump_speed_mm_s=2500, jump_delay_us=30, jump_delay_long_us=150,
                      long_jump_mm=20)
    path = outline(job, shape)
    ours = frame_records(path, 4, job, las, light_speed_mm_s=1800)
    bpm = bits_per_mm(job)
    c = galvo.GalvoController(mock=True, galvos_per_mm=bpm, light_speed=1800)
    packets = []

    def send(data, read=True):  # noqa: ANN001
        if len(data) == 0xC00:
            packets.append(bytes(data))
        return (0, 0, 0, 0x20)

    c.send = send
    c.lighting_configuration()
    kw = {"long": las.jump_delay_long_us, "short": las.jump_delay_us,
          "distance_limit": las.long_jump_mm * bpm}
    c.light(int(path[0, 0]), int(path[0, 1]), **kw)
    for _ in range(4):
        for x, y in np.vstack([path[1:], path[:1]]):
            c.light(int(x), int(y), **kw)
    c.initial_configuration()
    rec = np.frombuffer(b"".join(packets), dtype="<u2").reshape(-1, 6)
    n = len(rec)
    while n and rec[n - 1, 0] == END_OF_LIST and not rec[n - 1, 1:].any():
        n -= 1
    theirs = np.vstack([rec[:n], [[END_OF_LIST, 0, 0, 0, 0, 0]]])
    np.testing.assert_array_equal(ours, theirs)
