"""An operator trusts the preview: a cached result must never differ from a fresh one.

A random walk over the controls (field size, magnification, tolerances, marking points,
kerf, fill, hatch, order) on the seal sample; after every change the cached pipeline's job
must equal a fresh pipeline's job mark for mark (and in its stats and warnings)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from galvo_core.drawing import Drawing
from galvo_core.errors import ParamError
from galvo_core.hpgl import read_file
from galvo_core.params import Params
from galvo_core.pipeline import Pipeline

SEAL = Path(__file__).resolve().parents[1] / "resources" / "samples" / "seal.plt"

#: values an operator moves between (repeats make the walk come back to cached settings)
CONTROLS: dict[str, tuple[object, ...]] = {
    "field_size_mm": (110.0, 220.0, 70.0),
    "magnification": (None, 6.0, 10.0, 14.0),
    "fit_field": (False, True),
    "eps_line": (0.02, 0.5, 1.0),
    "e_per": (0.02, 0.1, 0.75),
    "interpolation": ("adaptive", "fixed", "raw"),
    "chord_tol_bits": (0.5, 1.0, 4.0),
    "min_step_bits": (0.0, 2.0, 8.0),
    "kerf_mm": (0.0, 0.05, 0.2),
    "kerf_side": ("outside", "inside"),
    "fill": ("none", "scanline", "zigzag"),
    "hatch_spacing_mm": (0.15, 0.3, 1.0),
    "hatch_angle_deg": (0.0, 30.0),
    "hatch_passes": (1, 2),
    "scan_order": ("file", "greedy", "optimized"),
}

STEP = st.sampled_from(sorted(CONTROLS)).flatmap(
    lambda name: st.tuples(st.just(name), st.sampled_from(CONTROLS[name])))


def _outcome(pipe: Pipeline, d: Drawing, p: Params) -> object:
    try:
        job = pipe.run(d, p).job
    except ParamError as exc:  # e.g. the drawing leaves the field: both must say so
        return ("refused", str(exc))
    return job


def _same(a: object, b: object) -> bool:
    if isinstance(a, tuple) or isinstance(b, tuple):
        return a == b
    if len(a.strokes) != len(b.strokes):  # type: ignore[attr-defined]
        return False
    for s, t in zip(a.strokes, b.strokes, strict=True):  # type: ignore[attr-defined]
        if (s.kind, s.source_index, s.closed, s.pen) != (t.kind, t.source_index, t.closed,
                                                         t.pen):
            return False
        if not np.array_equal(s.marks, t.marks):
            return False
    return (a.stats == b.stats and a.warnings == b.warnings  # type: ignore[attr-defined]
            and a.field_map == b.field_map and a.params == b.params)  # type: ignore[attr-defined]


@pytest.fixture(scope="module")
def seal() -> Drawing:
    return read_file(SEAL)


@settings(max_examples=1, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture,
                                 HealthCheck.too_slow, HealthCheck.data_too_large])
@given(walk=st.lists(STEP, min_size=120, max_size=120))
def test_a_random_walk_of_control_changes_never_shows_a_stale_job(seal, walk):
    cached = Pipeline()
    params = Params(clamp=True)
    hits = 0
    for i, (name, value) in enumerate(walk):
        params = params.replace(**{name: value})
        res_stages: tuple[str, ...] = ()
        try:
            res = cached.run(seal, params)
            got: object = res.job
            res_stages = res.stages_run
        except ParamError as exc:
            got = ("refused", str(exc))
        hits += len(res_stages) < 2
        fresh = _outcome(Pipeline(), seal, params)
        assert _same(got, fresh), f"step {i}: {name} = {value!r} -> cached != fresh ({params})"
    assert hits > 0  # the walk did reuse cached stages


@pytest.mark.parametrize("base", [
    Params(clamp=True, magnification=10.0, fill="scanline", hatch_spacing_mm=0.3),
    Params(clamp=True, magnification=10.0, fill="zigzag", hatch_spacing_mm=0.3, kerf_mm=0.1),
], ids=["fill", "kerf+fill"])
def test_every_single_change_from_a_cached_state_equals_a_fresh_run(seal, base):
    """Systematically: from a cached state, each control moved alone (and back) gives the
    fresh pipeline's job. Catches a stage whose cache key misses a quantity it reads (the
    hatch and the kerf once converted millimetres through the field but were keyed by the
    magnification only: a field size change kept the old hatch)."""
    pipe = Pipeline()
    first = pipe.run(seal, base).job
    for name, values in CONTROLS.items():
        for value in values:
            if getattr(base, name) == value:
                continue
            p = base.replace(**{name: value})
            got = _outcome(pipe, seal, p)
            assert _same(got, _outcome(Pipeline(), seal, p)), f"{name} = {value!r}"
            assert _same(pipe.run(seal, base).job, first), f"back from {name} = {value!r}"
