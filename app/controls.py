"""The processing controls: sliders with spin boxes (log scale across decades), each showing
its value also in µm and galvo bits at the current magnification; the laser dialog.

Defaults come from :class:`galvo_core.params.Params` / :class:`LaserParams`; only controls
for fields that Params has are built. The panel emits ``changed(changes, final)``: a dict
of Params fields, ``final`` False while a slider is being dragged, True on release, on a
typed value and on combo/checkbox changes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QLabel,
    QPushButton,
    QSizePolicy,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from galvo_core import params as params_mod
from galvo_core.field import FieldMap
from galvo_core.params import LaserParams, Params, Spec

SLIDER_STEPS = 1000


@dataclass(frozen=True)
class SliderSpec:
    """One numeric Params field on a slider.

    ``unit``: "units" (input units), "bits", "mm", "deg" or "mag" (bits per unit) — decides
    the conversions shown; ``log``: logarithmic slider between ``lo`` and ``hi``;
    ``zero``: the leftmost slider position means 0 (e.g. no kerf).
    """

    name: str
    label: str
    unit: str
    lo: float
    hi: float
    log: bool = True
    zero: bool = False
    decimals: int = 4
    tip: str = ""


SUFFIX = {"units": " u", "bits": " bits", "mm": " mm", "deg": " °", "mag": " bits/u", "": ""}


class ParamSlider(QWidget):
    """A slider, a spin box and a line of conversions, for one float field."""

    moved = Signal(float)  # while dragging
    committed = Signal(float)  # release, typed value, keyboard step

    def __init__(self, spec: SliderSpec, value: float, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.spec = spec
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(0, SLIDER_STEPS)
        self.slider.setSingleStep(5)
        self.slider.setPageStep(50)
        self.slider.setObjectName(f"slider_{spec.name}")
        self.slider.setMinimumWidth(110)
        self.spin = QDoubleSpinBox()
        self.spin.setObjectName(f"spin_{spec.name}")
        self.spin.setDecimals(spec.decimals)
        self.spin.setRange(0.0 if spec.zero else spec.lo, spec.hi)
        self.spin.setSuffix(SUFFIX.get(spec.unit, ""))
        self.spin.setKeyboardTracking(False)
        self.spin.setAccelerated(True)
        if spec.log:
            self.spin.setStepType(QAbstractSpinBox.StepType.AdaptiveDecimalStepType)
        self.spin.setMinimumWidth(108)
        self.spin.setAlignment(Qt.AlignmentFlag.AlignRight)
        self.info = QLabel("")
        self.info.setObjectName(f"info_{spec.name}")
        self.info.setStyleSheet("color: #5f6b7a; font-size: 8pt;")
        self.info.setWordWrap(True)
        self.name_label = QLabel(spec.label)
        self.name_label.setToolTip(spec.tip or spec.name)
        self.slider.setToolTip(f"{spec.tip}\n({spec.name})" if spec.tip else spec.name)

        grid = QGridLayout(self)
        grid.setContentsMargins(0, 1, 0, 1)
        grid.setHorizontalSpacing(6)
        grid.setVerticalSpacing(0)
        grid.addWidget(self.name_label, 0, 0)
        grid.addWidget(self.spin, 0, 1, alignment=Qt.AlignmentFlag.AlignRight)
        grid.addWidget(self.slider, 1, 0, 1, 2)
        grid.addWidget(self.info, 2, 0, 1, 2)
        grid.setColumnStretch(0, 1)

        self._value = float(value)
        self.set_value(value)
        self.slider.valueChanged.connect(self._on_slider)
        self.slider.sliderReleased.connect(self._on_released)
        self.spin.valueChanged.connect(self._on_spin)

    # --- mapping -------------------------------------------------------------------------
    def to_position(self, v: float) -> int:
        s = self.spec
        if s.zero and v <= 0.0:
            return 0
        first = 1 if s.zero else 0
        span = SLIDER_STEPS - first
        if s.log:
            v = min(max(v, s.lo), s.hi)
            f = math.log(v / s.lo) / math.log(s.hi / s.lo)
        else:
            f = (min(max(v, s.lo), s.hi) - s.lo) / (s.hi - s.lo)
        return first + int(round(f * span))

    def from_position(self, pos: int) -> float:
        s = self.spec
        if s.zero and pos <= 0:
            return 0.0
        first = 1 if s.zero else 0
        f = (pos - first) / (SLIDER_STEPS - first)
        if s.log:
            v = s.lo * (s.hi / s.lo) ** f
        else:
            v = s.lo + f * (s.hi - s.lo)
        # round to the spin box's precision (3 significant digits on a log scale)
        if s.log and v > 0:
            digits = max(0, 2 - int(math.floor(math.log10(v))))
            v = round(v, min(digits, s.decimals))
        return round(v, s.decimals)

    # --- value ---------------------------------------------------------------------------
    def value(self) -> float:
        return self._value

    def set_value(self, v: float) -> None:
        """Set without emitting."""
        self._value = float(v)
        for w in (self.slider, self.spin):
            w.blockSignals(True)
        self.slider.setValue(self.to_position(self._value))
        self.spin.setValue(self._value)
        for w in (self.slider, self.spin):
            w.blockSignals(False)

    def set_info(self, text: str) -> None:
        self.info.setText(text)

    def set_position(self, pos: int, final: bool = True) -> None:
        """Move the slider as a user drags it (tests, benchmark): pressed, moved to ``pos``
        (emits moved), and with ``final`` released there (emits committed once)."""
        self.slider.setSliderDown(True)
        self.slider.setValue(pos)
        if final:
            self.slider.setSliderDown(False)  # sliderReleased -> committed

    def _on_slider(self, pos: int) -> None:
        v = self.from_position(pos)
        self._value = v
        self.spin.blockSignals(True)
        self.spin.setValue(v)
        self.spin.blockSignals(False)
        if self.slider.isSliderDown():
            self.moved.emit(v)
        else:  # keyboard, wheel, click on the groove
            self.committed.emit(v)

    def _on_released(self) -> None:
        self.committed.emit(self._value)

    def _on_spin(self, v: float) -> None:
        self._value = float(v)
        self.slider.blockSignals(True)
        self.slider.setValue(self.to_position(v))
        self.slider.blockSignals(False)
        self.committed.emit(self._value)


def _fmt(v: float, digits: int = 3) -> str:
    if v == 0 or not math.isfinite(v):
        return "0"
    if abs(v) >= 10 ** digits:
        return f"{v:,.0f}".replace(",", "\u2009")
    return f"{v:.{digits}g}"


def conversion_text(unit: str, value: float, fm: FieldMap, drawing_size_units: tuple[float,
                    float] | None = None) -> str:
    """The value in µm and galvo bits (and input units) at the field map ``fm``."""
    if unit == "units":
        return (f"= {_fmt(value * fm.mm_per_unit * 1000)} µm · "
                f"{_fmt(value * fm.magnification)} bits")
    if unit == "bits":
        return (f"= {_fmt(value * fm.mm_per_bit * 1000)} µm · "
                f"{_fmt(value / fm.magnification)} u")
    if unit == "mm":
        return f"= {_fmt(value * 1000)} µm · {_fmt(value / fm.mm_per_bit)} bits"
    if unit == "mag":
        text = f"1 u = {_fmt(value * fm.mm_per_bit * 1000)} µm"
        if drawing_size_units is not None:
            w, h = (s * value * fm.mm_per_bit for s in drawing_size_units)
            text += f" · drawing {w:.1f} × {h:.1f} mm on the workpiece"
        return text
    return ""


#: how a parameter's unit (galvo_core.params.Spec.unit) shows its conversions in the panel
GUI_UNIT = {"units": "units", "bits": "bits", "mm": "mm", "deg": "deg", "bits/unit": "mag"}


def slider_spec(spec: Spec) -> SliderSpec:
    """The slider of a numeric parameter, from its Spec (label, unit, range, tooltip)."""
    assert spec.slider is not None, spec.name
    lo, hi = spec.slider
    return SliderSpec(spec.name, spec.label, GUI_UNIT.get(spec.unit, ""), lo, hi, log=spec.log,
                      zero=spec.zero, decimals=spec.decimals, tip=spec.describe())


def _control(spec: Spec) -> SliderSpec | str:
    return slider_spec(spec) if spec.slider is not None else spec.name


#: The controls, in panel order, grouped: every parameter whose Spec says ``control``;
#: sliders for numbers, combo boxes for choices, check boxes for switches.
GROUPS: tuple[tuple[str, tuple[SliderSpec | str, ...]], ...] = tuple(
    (g.TITLE, tuple(_control(s) for s in g.specs() if s.control))
    for g in params_mod.GROUPS if any(s.control for s in g.specs()))

CHOICES: dict[str, tuple[str, tuple[str, ...]]] = {
    s.name: (s.label, s.choices) for s in params_mod.all_specs() if s.kind == "choice"}


def _param_names() -> set[str]:
    return {s.name for s in params_mod.all_specs()}


class ControlsPanel(QWidget):
    """Every processing control, built from :data:`GROUPS` for the fields Params has."""

    changed = Signal(dict, bool)  # Params changes, final
    laser_requested = Signal()

    def __init__(self, params: Params | None = None, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        params = params or Params()
        names = _param_names()
        self.sliders: dict[str, ParamSlider] = {}
        self.combos: dict[str, QComboBox] = {}
        self.fit_field: QCheckBox | None = None
        self._fm: FieldMap | None = None
        self._drawing_size: tuple[float, float] | None = None
        self._effective_mag = 1.0

        outer = QVBoxLayout(self)
        outer.setContentsMargins(6, 4, 6, 4)
        outer.setSpacing(6)
        for title, items in GROUPS:
            present = [i for i in items if (i.name if isinstance(i, SliderSpec) else i) in names]
            if not present:
                continue
            box = QGroupBox(title)
            lay = QVBoxLayout(box)
            lay.setContentsMargins(8, 4, 8, 6)
            lay.setSpacing(3)
            for item in present:
                if isinstance(item, SliderSpec):
                    value = getattr(params, item.name)
                    w = ParamSlider(item, value if value is not None else 1.0)
                    w.moved.connect(lambda v, n=item.name: self._emit(n, v, False))
                    w.committed.connect(lambda v, n=item.name: self._emit(n, v, True))
                    self.sliders[item.name] = w
                    lay.addWidget(w)
                elif item == "fit_field":
                    cb = QCheckBox(params_mod.spec("fit_field").label)
                    cb.setToolTip(params_mod.spec("fit_field").describe())
                    cb.setObjectName("check_fit_field")
                    cb.setChecked(bool(params.fit_field))
                    cb.toggled.connect(self._on_fit_field)
                    self.fit_field = cb
                    lay.addWidget(cb)
                else:
                    label, options = CHOICES[item]
                    combo = QComboBox()
                    combo.setObjectName(f"combo_{item}")
                    combo.addItems(list(options))
                    combo.setCurrentText(str(getattr(params, item)))
                    combo.currentTextChanged.connect(
                        lambda text, n=item: self._emit(n, text, True))
                    self.combos[item] = combo
                    row = QWidget()
                    form = QFormLayout(row)
                    form.setContentsMargins(0, 0, 0, 0)
                    form.addRow(label, combo)
                    lay.addWidget(row)
            outer.addWidget(box)
        self.laser_button = QPushButton("Laser parameters…")
        self.laser_button.setToolTip("speeds, delays and frequency used by the time estimate")
        self.laser_button.clicked.connect(self.laser_requested)
        self.defaults_button = QPushButton("Restore defaults")
        self.defaults_button.setToolTip("every processing parameter back to galvo_core's default")
        outer.addWidget(self.laser_button)
        outer.addWidget(self.defaults_button)
        outer.addStretch(1)
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Maximum)
        self._sync_fit_field()

    # --- state ---------------------------------------------------------------------------
    def set_params(self, params: Params, fm: FieldMap | None = None) -> None:
        """Show ``params`` (no signals); ``fm`` the effective field map (magnification)."""
        for name, w in self.sliders.items():
            v = getattr(params, name)
            if name == "magnification" and v is None:
                v = fm.magnification if fm is not None else w.value()
            w.set_value(float(v))
        for name, combo in self.combos.items():
            combo.blockSignals(True)
            combo.setCurrentText(str(getattr(params, name)))
            combo.blockSignals(False)
        if self.fit_field is not None:
            self.fit_field.blockSignals(True)
            self.fit_field.setChecked(bool(params.fit_field))
            self.fit_field.blockSignals(False)
        self._sync_fit_field()
        if fm is not None:
            self.set_field_map(fm)

    def set_field_map(self, fm: FieldMap, drawing_size_units: tuple[float, float] | None = None
                      ) -> None:
        """Update the conversions (and the magnification shown under fit-field)."""
        self._fm = fm
        if drawing_size_units is not None:
            self._drawing_size = drawing_size_units
        mag = self.sliders.get("magnification")
        if mag is not None and self.fit_field is not None and self.fit_field.isChecked():
            mag.set_value(fm.magnification)
        self.refresh_info()

    def refresh_info(self) -> None:
        fm = self._fm
        if fm is None:
            return
        for name, w in self.sliders.items():
            if name == "magnification":
                local = FieldMap(w.value(), fm.offset_bits, fm.field_bits, fm.field_size_mm)
                w.set_info(conversion_text("mag", w.value(), local, self._drawing_size))
            else:
                w.set_info(conversion_text(w.spec.unit, w.value(), fm))

    def _sync_fit_field(self) -> None:
        mag = self.sliders.get("magnification")
        if mag is not None and self.fit_field is not None:
            on = self.fit_field.isChecked()
            mag.slider.setEnabled(not on)
            mag.spin.setEnabled(not on)

    def _on_fit_field(self, on: bool) -> None:
        self._sync_fit_field()
        changes: dict[str, Any] = {"fit_field": on}
        mag = self.sliders.get("magnification")
        if not on and mag is not None:
            changes["magnification"] = mag.value()
        self.changed.emit(changes, True)

    def _emit(self, name: str, value: Any, final: bool) -> None:
        if params_mod.spec(name).kind == "int":
            value = int(round(value))
        if name in self.sliders:
            fm = self._fm
            if fm is not None:
                self.refresh_info()
        self.changed.emit({name: value}, final)


class LaserDialog(QDialog):
    """Every LaserParams field as a spin box; OK validates through LaserParams."""

    def __init__(self, laser: LaserParams, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Laser parameters")
        self.spins: dict[str, QDoubleSpinBox] = {}
        form = QFormLayout()
        for spec in LaserParams.specs():
            spin = QDoubleSpinBox()
            spin.setObjectName(f"laser_{spec.name}")
            spin.setDecimals(2)
            spin.setRange(spec.lo or 0.0, spec.hi if spec.hi is not None else 1e7)
            spin.setSuffix(f" {spec.unit}" if spec.unit else "")
            spin.setValue(float(getattr(laser, spec.name)))
            spin.setToolTip(f"{spec.describe()}\n({spec.name})")
            self.spins[spec.name] = spin
            form.addRow(spec.label, spin)
        self.error = QLabel("")
        self.error.setStyleSheet("color: #b00020;")
        self.error.setWordWrap(True)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                                   | QDialogButtonBox.StandardButton.Cancel
                                   | QDialogButtonBox.StandardButton.RestoreDefaults)
        buttons.accepted.connect(self._accept)
        buttons.rejected.connect(self.reject)
        buttons.button(QDialogButtonBox.StandardButton.RestoreDefaults).clicked.connect(
            self.restore_defaults)
        lay = QVBoxLayout(self)
        lay.addLayout(form)
        lay.addWidget(self.error)
        lay.addWidget(buttons)
        self.result_laser: LaserParams | None = None

    def values(self) -> dict[str, float]:
        return {n: float(s.value()) for n, s in self.spins.items()}

    def restore_defaults(self) -> None:
        d = LaserParams()
        for n, s in self.spins.items():
            s.setValue(float(getattr(d, n)))

    def _accept(self) -> None:
        try:
            self.result_laser = LaserParams(**self.values())
        except (ValueError, TypeError) as exc:
            self.error.setText(str(exc))
            return
        self.accept()


__all__ = ["ControlsPanel", "GROUPS", "LaserDialog", "ParamSlider", "SliderSpec",
           "conversion_text"]
