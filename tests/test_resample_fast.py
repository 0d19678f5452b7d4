"""The re-sample path without per-stroke Python (issue 18, round 3): the fast stroke
construction, the clamp over joined marks, the job's marks joined once, the compiled
bounding boxes. Each gives what the plain per-stroke code gives."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from galvo_core.drawing import Drawing, Path
from galvo_core.job import Segments, Stroke
from galvo_core.params import Params
from galvo_core.pipeline import Pipeline, _clamped, _new_strokes
from galvo_core.preview import bbox
from galvo_core.timing import estimate_with_dwell, joined_marks


def test_fast_strokes_equal_the_constructors_field_by_field():
    rng = np.random.default_rng(1)
    n = 50
    marks = [rng.integers(0, 100, size=(int(k), 2)) for k in rng.integers(1, 6, n)]
    segs = [Segments(np.array([False]), rng.random((2, 2))) for _ in range(n)]
    src, closed, pens = list(range(n)), [bool(i % 2) for i in range(n)], [1 + i % 3
                                                                          for i in range(n)]
    fast = _new_strokes("contour", src, closed, marks, segs, pens)
    for i, s in enumerate(fast):
        ref = Stroke("contour", src[i], closed[i], marks[i], segs[i], pens[i])
        assert type(s) is Stroke
        for f in dataclasses.fields(Stroke):
            assert getattr(s, f.name) is getattr(ref, f.name), f.name
        with pytest.raises(dataclasses.FrozenInstanceError):
            s.pen = 7  # still frozen


def test_clamp_over_joined_marks_equals_clipping_each_stroke():
    rng = np.random.default_rng(2)
    marks = [rng.integers(-50, 1100, size=(int(k), 2)) for k in rng.integers(0, 7, 200)]
    out, n = _clamped(marks, 1000)
    want = sum(int((np.clip(m, 0, 1000) != m).any(axis=1).sum()) for m in marks)
    assert n == want > 0
    for m, o in zip(marks, out, strict=True):
        assert np.array_equal(o, np.clip(m, 0, 1000))
        if ((m >= 0) & (m <= 1000)).all():
            assert o is m  # untouched strokes keep their array


def test_clamped_run_counts_and_clips_like_before():
    d = Drawing((Path.from_points([(0, 0), (100000, 0)]),
                 Path.from_points([(0, 10), (50, 10)])), name="wide.plt")
    job = Pipeline().run(d, Params(magnification=1.0, clamp=True)).job
    allm = np.concatenate([s.marks for s in job.strokes])
    assert allm.min() >= 0 and allm.max() <= job.field_map.max_bit
    assert any("clamped" in w.message for w in job.warnings)


def test_joined_marks_are_the_strokes_marks_in_order_and_shared():
    rng = np.random.default_rng(3)
    strokes = tuple(Stroke("hatch" if i % 5 == 0 else "contour", 10 + i, False,
                           rng.integers(0, 9, size=(int(k), 2)))
                    for i, k in enumerate(rng.integers(0, 5, 40)))
    j = joined_marks(strokes)
    assert np.array_equal(j.marks, np.concatenate([s.marks for s in strokes]))
    assert j.lens.tolist() == [len(s.marks) for s in strokes]
    assert j.source.tolist() == [s.source_index for s in strokes]
    assert j.hatch.tolist() == [s.kind == "hatch" for s in strokes]
    assert joined_marks(strokes) is j  # a tuple is joined once
    assert joined_marks(list(strokes)) is not j  # a list may change: joined again


def test_estimate_from_joined_marks_equals_the_per_stroke_form():
    rng = np.random.default_rng(4)
    strokes = tuple(Stroke("contour", i, False, rng.integers(0, 3000, size=(int(k), 2)))
                    for i, k in enumerate(rng.integers(0, 9, 300)))
    laser = Params().laser
    a = estimate_with_dwell([s.marks for s in strokes], laser, 0.0017)
    b = estimate_with_dwell(joined_marks(strokes), laser, 0.0017)
    assert a == b


def test_compiled_bbox_equals_numpy_on_finite_rows():
    rng = np.random.default_rng(5)
    xy = rng.normal(size=(1000, 2)) * 100
    xy[::7, 0] = np.nan
    xy[::11, 1] = np.inf
    f = xy[np.isfinite(xy).all(axis=1)]
    assert bbox(xy) == (f[:, 0].min(), f[:, 1].min(), f[:, 0].max(), f[:, 1].max())
    ints = rng.integers(-5, 70000, size=(999, 2))
    assert bbox(ints) == (ints[:, 0].min(), ints[:, 1].min(), ints[:, 0].max(),
                          ints[:, 1].max())
    assert bbox(np.full((3, 2), np.nan)) is None
    assert bbox(np.empty((0, 2), dtype=np.int64)) is None
