"""One parameter model: every parameter is declared once (galvo_core.params) and the CLI, the
GUI's controls, validation and the job's ``params`` all come from that declaration."""

from __future__ import annotations

import argparse
import math

import pytest

from galvo_core import cli
from galvo_core.errors import ParamError
from galvo_core.params import (
    GROUPS,
    FitParams,
    LaserParams,
    Params,
    all_specs,
    format_value,
    spec,
)


def _process_parser() -> argparse.ArgumentParser:
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices["process"]


def test_every_parameter_has_one_cli_option_with_its_unit_and_default():
    p = _process_parser()
    options = {a.dest: a for a in p._actions}
    for s in all_specs():
        a = options[s.name]
        assert s.option in a.option_strings
        text = a.help.replace("%%", "%")
        assert s.help in text
        if s.unit:
            assert f"unit: {s.unit}" in text
        if not (s.optional and s.default is None):
            assert f"default: {format_value(s.default)}" in text
        if s.kind == "choice":
            assert tuple(a.choices) == s.choices
    # the parameter groups hold exactly the model's parameters, in the model's groups
    titles = {g.TITLE.lower(): g for g in GROUPS}
    seen = set()
    for ag in p._action_groups:
        group = next((g for t, g in titles.items() if ag.title and ag.title.startswith(t)),
                     None)
        if group is None:
            continue
        assert {a.dest for a in ag._group_actions} == {s.name for s in group.specs()}
        seen.add(group)
    assert seen == set(GROUPS)


def test_cli_parses_every_option_into_the_same_params():
    p = cli.build_parser()
    args = p.parse_args(["process", "x.plt", "-o", "j.json", "--e-per", "0.5",
                         "--hatch-passes", "3", "--fill", "zigzag", "--fit-field",
                         "--offset-bits", "10", "20", "--mark-speed-mm-s", "500"])
    params = cli._params_from_args(args)
    assert params == Params(e_per=0.5, hatch_passes=3, fill="zigzag", fit_field=True,
                            offset_bits=(10.0, 20.0), mark_speed_mm_s=500.0)
    # options not given keep the model's defaults
    assert params.eps_line == spec("eps_line").default


@pytest.mark.parametrize("argv, fragment", [
    (["--e-per", "-1"], "e_per must be > 0"),
    (["--power-percent", "120"], "power_percent must be >= 0 and <= 100"),
    (["--hatch-passes", "1.5"], "hatch_passes must be a whole number"),
    (["--fill", "wavy"], "invalid choice"),
])
def test_a_bad_option_is_one_clear_line(argv, fragment, capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["process", "x.plt", "-o", "j.json", *argv])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "\n" not in err and fragment in err


def test_job_params_and_laser_are_the_model_names_and_defaults():
    params = Params()
    job_params = params.processing_dict()
    laser = params.laser.as_dict()
    expected = {s.name: s.default for g in GROUPS if g is not LaserParams for s in g.specs()}
    assert job_params == expected
    assert laser == {s.name: float(s.default) for s in LaserParams.specs()}


def test_validation_comes_from_the_specs():
    for s in all_specs():
        if s.kind in ("float", "int"):
            if s.lo is not None:
                bad = s.lo if s.lo_open else s.lo - 1
                with pytest.raises(ParamError, match=s.name):
                    Params(**{s.name: bad})
            if s.hi is not None:
                with pytest.raises(ParamError, match=s.name):
                    Params(**{s.name: s.hi * 2 + 1})
            if s.kind == "float":
                with pytest.raises(ParamError, match=s.name):
                    Params(**{s.name: math.nan})
        if s.kind == "choice":
            with pytest.raises(ParamError, match=s.name):
                Params(**{s.name: "no-such-choice"})
    with pytest.raises(ParamError, match="unknown parameter"):
        Params(no_such_parameter=1)
    with pytest.raises(ParamError, match="max_step_bits must be >= min_step_bits"):
        Params(min_step_bits=4.0, max_step_bits=2.0)


def test_params_read_flat_and_by_group_and_are_values():
    p = Params(e_per=0.1, mark_speed_mm_s=250.0)
    assert p.e_per == 0.1 and p.laser.mark_speed_mm_s == 250.0
    assert p.group("fit") == FitParams(e_per=0.1)
    assert p == Params(e_per=0.1, mark_speed_mm_s=250.0) and hash(p) == hash(
        Params(e_per=0.1, mark_speed_mm_s=250.0))
    q = p.replace(magnification=36.0)
    assert q.magnification == 36.0 and p.magnification is None  # p unchanged
    assert q.group("fit") is p.group("fit")  # untouched groups are shared
    with pytest.raises(AttributeError):
        p.e_per = 1.0  # type: ignore[misc]
    assert Params.from_mapping(p.as_dict()) == p


@pytest.mark.gui
def test_gui_controls_are_the_model_controls(qtbot):
    from app.controls import ControlsPanel, LaserDialog

    panel = ControlsPanel(Params())
    qtbot.addWidget(panel)
    shown = set(panel.sliders) | set(panel.combos) | ({"fit_field"} if panel.fit_field else set())
    assert shown == {s.name for s in all_specs() if s.control}
    for name, w in panel.sliders.items():
        s = spec(name)
        assert w.name_label.text() == s.label
        assert s.help in w.name_label.toolTip()
        lo, hi = s.slider  # type: ignore[misc]
        # the slider's ends are values the model accepts
        s.check(lo if s.kind != "int" else int(lo))
        s.check(hi if s.kind != "int" else int(hi))
        assert math.isclose(w.value(), s.default if s.default is not None else w.value())
    for name, combo in panel.combos.items():
        assert tuple(combo.itemText(i) for i in range(combo.count())) == spec(name).choices
        assert combo.currentText() == spec(name).default
    dlg = LaserDialog(LaserParams())
    qtbot.addWidget(dlg)
    assert set(dlg.spins) == {s.name for s in LaserParams.specs()}
    for name, spin in dlg.spins.items():
        assert spin.value() == pytest.approx(spec(name).default)


@pytest.mark.gui
def test_an_int_slider_sends_an_int(qtbot):
    from app.controls import ControlsPanel

    panel = ControlsPanel(Params())
    qtbot.addWidget(panel)
    got: list[dict] = []
    panel.changed.connect(lambda changes, final: got.append(changes))
    panel.sliders["hatch_passes"].set_position(700)
    value = got[-1]["hatch_passes"]
    assert isinstance(value, int) and 1 <= value <= 16
    Params(hatch_passes=value)  # accepted as it is
