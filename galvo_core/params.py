"""Every processing parameter, declared once, with its unit, range, default and help.

Parameters come in frozen groups, one per stage that reads them:

==========  ============================  ==============================================
group       class                         read by
==========  ============================  ==============================================
``field``   :class:`FieldParams`          the field map (magnification, offset, bits)
``fit``     :class:`FitParams`            thinning and Bézier fitting (paper 000 §2-3)
``sample``  :class:`SampleParams`         marking points (paper 000 §4, 004, 001)
``kerf``    :class:`KerfParams`           kerf compensation (paper 003)
``fill``    :class:`FillParams`           hatch fill (paper 002)
``order``   :class:`OrderParams`          stroke order
``laser``   :class:`LaserParams`          the time estimate, the job's ``laser`` table
==========  ============================  ==============================================

Each field is declared with :func:`param`: its default, unit, label, help text, range and
choices live in the field's metadata (:class:`Spec`) and nowhere else. From them come the
CLI's options (:mod:`galvo_core.cli`), the GUI's controls (``app/controls.py``), validation
with one clear message (:func:`validate`), the job's ``params`` and each stage's cache key
(the whole group a stage reads, see :mod:`galvo_core.pipeline`). A new parameter is one
:func:`param` line in one group.

:class:`Params` holds one instance of each group and reads flat: ``params.e_per`` is
``params.group("fit").e_per``; ``Params(e_per=0.1)`` and ``params.replace(e_per=0.1)`` take
any field of any group by name.

Units (see shared/spec/job-format.md): ``eps_line``, ``e_per``, ``eps_sum`` are input units
(HP-GL plotter units) as in paper 000; ``*_bits`` galvo bits; ``magnification`` galvo bits per
input unit; ``*_mm``, ``*_mm_s`` millimetres (per second) on the workpiece, after
magnification; ``*_us`` microseconds, ``*_khz`` kilohertz, ``*_deg`` degrees.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, fields
from typing import Any, ClassVar

from galvo_core.errors import ParamError

INTERPOLATIONS = ("adaptive", "fixed", "raw")
KERF_SIDES = ("outside", "inside")
KERF_METHODS = ("vector", "raster", "rectangle")
FILLS = ("none", "scanline", "zigzag")
SCAN_ORDERS = ("file", "greedy", "optimized")

#: galvo bits per axis of the usual 16-bit scanner interface (XY2-100)
DEFAULT_FIELD_BITS = 65536
#: field size of a typical F-theta lens, mm
DEFAULT_FIELD_SIZE_MM = 110.0
#: HP-GL plotter units per millimetre of the drawing
UNITS_PER_MM = 40.0


@dataclass(frozen=True, slots=True)
class Spec:
    """What one parameter is: the single source of its CLI option, GUI control, validation.

    ``kind``: "float", "int", "bool", "choice" or "pair" (two floats); ``optional``: None is
    allowed and means ``none_means``; ``lo``/``hi``: the valid range (``lo_open``: strictly
    above ``lo``); ``slider``: (lo, hi) of the GUI's slider when the field has a control
    (``log`` scale, ``zero``: the leftmost position means 0); ``decimals`` shown.
    """

    default: Any
    kind: str
    unit: str
    label: str
    help: str
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    choices: tuple[str, ...] = ()
    optional: bool = False
    none_means: str = ""
    slider: tuple[float, float] | None = None
    log: bool = True
    zero: bool = False
    decimals: int = 4
    control: bool = False  # a control in the GUI's processing panel (sliders, combos, checks)
    name: str = ""
    group: str = ""

    @property
    def option(self) -> str:
        """The CLI option: ``--eps-line``."""
        return "--" + self.name.replace("_", "-")

    def describe(self) -> str:
        """Help text with unit, range and default (the CLI's and the GUI's tooltip)."""
        parts = [self.help]
        if self.unit:
            parts.append(f"unit: {self.unit}")
        rng = self.range_text()
        if rng:
            parts.append(rng)
        if self.optional and self.default is None:
            parts.append(f"default: {self.none_means or 'none'}")
        else:
            parts.append(f"default: {format_value(self.default)}")
        return "; ".join(parts)

    def range_text(self) -> str:
        """``> 0``, ``>= 0 and <= 100``, ``one of a, b``; empty when any value goes."""
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        parts = []
        if self.lo is not None:
            parts.append(f"{'>' if self.lo_open else '>='} {format_value(self.lo)}")
        if self.hi is not None:
            parts.append(f"<= {format_value(self.hi)}")
        return " and ".join(parts)

    def check(self, v: Any) -> Any:
        """``v`` validated (ints accepted for floats, returned as float); ParamError says
        which parameter, what it got and what it takes."""
        if v is None:
            if self.optional:
                return None
            raise ParamError(f"{self.name} must be given ({self.range_text() or self.kind})")
        if self.kind == "bool":
            if not isinstance(v, bool):
                raise ParamError(f"{self.name} must be true or false, got {v!r}")
            return v
        if self.kind == "choice":
            if v not in self.choices:
                raise ParamError(f"{self.name} must be one of {', '.join(self.choices)}; "
                                 f"got {v!r}")
            return v
        if self.kind == "pair":
            if (not isinstance(v, (tuple, list)) or len(v) != 2
                    or not all(_is_number(x) and math.isfinite(x) for x in v)):
                raise ParamError(f"{self.name} must be two finite numbers, got {v!r}")
            return (float(v[0]), float(v[1]))
        if not _is_number(v):
            raise ParamError(f"{self.name} must be a number, got {v!r}")
        if self.kind == "int":
            if not isinstance(v, int) and not float(v).is_integer():
                raise ParamError(f"{self.name} must be a whole number, got {v!r}")
            v = int(v)
        else:
            v = float(v)
            if not math.isfinite(v):
                raise ParamError(f"{self.name} must be a finite number, got {v!r}")
        if self.lo is not None and (v <= self.lo if self.lo_open else v < self.lo) or (
                self.hi is not None and v > self.hi):
            raise ParamError(f"{self.name} must be {self.range_text()}, got {v!r}")
        return v

    def parse(self, text: str) -> Any:
        """A value typed by a user (CLI, ``--set``) -> checked value; ParamError otherwise."""
        t = text.strip()
        low = t.lower()
        if self.optional and low in ("none", "auto", ""):
            return None
        if self.kind == "bool":
            if low in ("1", "true", "yes", "on"):
                return True
            if low in ("0", "false", "no", "off"):
                return False
            raise ParamError(f"{self.name} must be true or false, got {text!r}")
        if self.kind == "choice":
            return self.check(t)
        if self.kind == "pair":
            parts = [p for p in re.split(r"[,\s]+", t) if p]
            try:
                return self.check(tuple(float(p) for p in parts))
            except ValueError:
                raise ParamError(f"{self.name} must be two numbers X,Y, got {text!r}") from None
        try:
            num = int(t) if self.kind == "int" else float(t)
        except ValueError:
            what = "a whole number" if self.kind == "int" else "a number"
            raise ParamError(f"{self.name} must be {what}, got {text!r}") from None
        return self.check(num)


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def format_value(v: Any) -> str:
    """A value as a user reads it: 0.02, 110, 65536, true, outside, 10,20."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return f"{v:g}" if abs(v) < 1e6 else f"{v:.0f}"
    if isinstance(v, tuple):
        return ",".join(format_value(x) for x in v)
    return str(v)


def param(default: Any, *, unit: str, label: str, help: str, kind: str | None = None,
          **spec: Any) -> Any:
    """Declare one parameter of a group (a dataclass field whose metadata is its Spec)."""
    if kind is None:
        kind = ("bool" if isinstance(default, bool) else "int" if isinstance(default, int)
                else "choice" if "choices" in spec else "float")
    s = Spec(default, kind, unit, label, help, **spec)
    return dataclasses.field(default=default, metadata={"spec": s})


class ParamGroup:
    """Base of the frozen groups: validates every field through its Spec on creation."""

    __slots__ = ()
    STAGE: ClassVar[str] = ""
    TITLE: ClassVar[str] = ""
    _NAMED: ClassVar[dict[str, Spec]] = {}

    def __post_init__(self) -> None:
        for f in fields(self):  # type: ignore[arg-type]
            object.__setattr__(self, f.name, spec_of(type(self), f.name).check(
                getattr(self, f.name)))
        self._check_together()

    def _check_together(self) -> None:
        """Rules between fields of the group (override)."""

    @classmethod
    def specs(cls) -> tuple[Spec, ...]:
        return tuple(spec_of(cls, f.name) for f in fields(cls))  # type: ignore[arg-type]

    def as_dict(self) -> dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in fields(self)}  # type: ignore[arg-type]


def spec_of(cls: type, name: str) -> Spec:
    """The Spec of field ``name`` of group class ``cls`` (named after the field and group)."""
    return cls._NAMED[name]  # type: ignore[attr-defined,no-any-return]


def _named(cls: type[ParamGroup]) -> type[ParamGroup]:
    """Class decorator (after ``@dataclass``): each field's Spec with its name and group."""
    cls._NAMED = {  # type: ignore[attr-defined]
        f.name: dataclasses.replace(f.metadata["spec"], name=f.name, group=cls.STAGE)
        for f in fields(cls)}  # type: ignore[arg-type]
    return cls


@_named
@dataclass(frozen=True, slots=True, kw_only=True)
class FitParams(ParamGroup):
    """Thinning and fitting, input units (paper 000 §2-3)."""

    STAGE: ClassVar[str] = "fit"
    TITLE: ClassVar[str] = "Fit (paper 000)"

    eps_line: float = param(
        0.02, unit="units", label="ε_line  (line thinning)", lo=0.0, lo_open=True,
        help="line thinning tolerance: largest distance of a dropped point from the line "
             "that replaces it", slider=(0.001, 10.0), control=True)
    e_per: float = param(
        0.02, unit="units", label="e_per  (curve tolerance)", lo=0.0, lo_open=True,
        help="largest distance of an input point from its fitted cubic",
        slider=(0.001, 10.0), control=True)
    eps_sum: float = param(
        0.002, unit="units", label="ε_sum  (dichotomy stop)", lo=0.0, lo_open=True,
        help="the dichotomy stops when the signed error sum is below this")


@_named
@dataclass(frozen=True, slots=True, kw_only=True)
class FieldParams(ParamGroup):
    """How input units map to galvo bits."""

    STAGE: ClassVar[str] = "field"
    TITLE: ClassVar[str] = "Field"

    magnification: float | None = param(
        None, unit="bits/unit", label="Magnification", lo=0.0, lo_open=True, optional=True,
        none_means="true size (field bits / field mm / 40), or the largest that fits with "
                   "fit_field",
        help="galvo bits per input unit", slider=(0.005, 2000.0), decimals=4, control=True)
    fit_field: bool = param(
        False, unit="", label="Fit field (largest size that fits)", control=True,
        help="the largest magnification that fits the field (overrides magnification)")
    field_size_mm: float = param(
        DEFAULT_FIELD_SIZE_MM, unit="mm", label="Field size", lo=0.0, lo_open=True, hi=10000.0,
        help="width of the scanner's field on the workpiece")
    field_bits: int = param(
        DEFAULT_FIELD_BITS, unit="bits", label="Field bits", lo=2, hi=1 << 24,
        help="addressable positions per axis (65536: marks 0..65535)")
    offset_bits: tuple[float, float] | None = param(
        None, kind="pair", unit="bits", label="Offset", optional=True,
        none_means="the drawing centred in the field",
        help="offset added after scaling, X and Y")
    clamp: bool = param(
        False, unit="", label="Clamp to field",
        help="clamp marks that leave the field (with a warning) instead of refusing")


@_named
@dataclass(frozen=True, slots=True, kw_only=True)
class SampleParams(ParamGroup):
    """Marking points (paper 000 §4, paper 004, paper 001's fixed step as a baseline)."""

    STAGE: ClassVar[str] = "sample"
    TITLE: ClassVar[str] = "Marking points"

    interpolation: str = param(
        "adaptive", unit="", label="Method", choices=INTERPOLATIONS, control=True,
        help="adaptive: step from the curvature with a chord-height bound; fixed: paper 001's "
             "fixed step; raw: the input points as they are")
    chord_tol_bits: float = param(
        1.0, unit="bits", label="Chord tolerance", lo=0.0, lo_open=True,
        help="largest chord height between marks on a curve", slider=(0.02, 512.0),
        control=True)
    min_step_bits: float = param(
        2.0, unit="bits", label="Minimum step", lo=0.0,
        help="marks closer than this are merged (0: keep all)", slider=(0.1, 512.0),
        zero=True, control=True)
    max_step_bits: float | None = param(
        None, unit="bits", label="Maximum step", lo=0.0, lo_open=True, optional=True,
        none_means="no limit", help="longest step between marks on a curve")
    fixed_step_bits: float = param(
        16.0, unit="bits", label="Fixed step", lo=0.0, lo_open=True,
        help="paper 001 baseline (interpolation fixed): step along the curve's main axis")
    fixed_slope_tol: float = param(
        0.05, unit="", label="Fixed slope threshold", lo=0.0, lo_open=True,
        help="paper 001 baseline: slope threshold k0")

    def _check_together(self) -> None:
        if self.max_step_bits is not None and self.max_step_bits < self.min_step_bits:
            raise ParamError("max_step_bits must be >= min_step_bits")


@_named
@dataclass(frozen=True, slots=True, kw_only=True)
class KerfParams(ParamGroup):
    """Kerf compensation (paper 003)."""

    STAGE: ClassVar[str] = "kerf"
    TITLE: ClassVar[str] = "Kerf compensation"

    kerf_mm: float = param(
        0.0, unit="mm", label="Kerf width", lo=0.0, hi=1000.0,
        help="width of the laser trough on the workpiece (0: no compensation)",
        slider=(0.001, 5.0), zero=True, control=True)
    kerf_side: str = param(
        "outside", unit="", label="Side", choices=KERF_SIDES, control=True,
        help="outside grows the design's regions, inside shrinks them")
    kerf_method: str = param(
        "vector", unit="", label="Method", choices=KERF_METHODS, control=True,
        help="vector: polygon offset (GEOS); raster and rectangle: paper 003's alternatives")
    arc_tol_bits: float = param(
        1.0, unit="bits", label="Arc tolerance", lo=0.0, lo_open=True,
        help="largest deviation of the offset's round corners from true arcs")


@_named
@dataclass(frozen=True, slots=True, kw_only=True)
class FillParams(ParamGroup):
    """Hatch fill (paper 002)."""

    STAGE: ClassVar[str] = "fill"
    TITLE: ClassVar[str] = "Fill"

    fill: str = param(
        "none", unit="", label="Fill", choices=FILLS, control=True,
        help="none; scanline: one line per scan row; zigzag: joined rows over monotone cells "
             "(fewer laser switches)")
    hatch_spacing_mm: float = param(
        0.05, unit="mm", label="Hatch spacing", lo=0.0, lo_open=True,
        help="distance between fill lines on the workpiece", slider=(0.005, 10.0),
        control=True)
    hatch_angle_deg: float = param(
        0.0, unit="deg", label="Hatch angle", lo=-360.0, hi=360.0,
        help="direction of the fill lines", slider=(-90.0, 90.0), log=False, decimals=1,
        control=True)
    hatch_passes: int = param(
        1, unit="", label="Hatch passes", lo=1, hi=16,
        help="fill passes, each turned by hatch_angle_step_deg", slider=(1.0, 16.0), log=False,
        decimals=0, control=True)
    hatch_angle_step_deg: float = param(
        90.0, unit="deg", label="Hatch angle step", lo=-360.0, hi=360.0,
        help="turn between hatch passes", slider=(-180.0, 180.0), log=False, decimals=1,
        control=True)
    hatch_inset_mm: float = param(
        0.0, unit="mm", label="Hatch inset", lo=0.0, hi=1000.0,
        help="distance kept between the fill lines and the outline")


@_named
@dataclass(frozen=True, slots=True, kw_only=True)
class OrderParams(ParamGroup):
    """The order strokes are marked in."""

    STAGE: ClassVar[str] = "order"
    TITLE: ClassVar[str] = "Order"

    scan_order: str = param(
        "file", unit="", label="Scan order", choices=SCAN_ORDERS, control=True,
        help="file: as drawn; greedy: nearest next stroke; optimized: greedy then improved "
             "(shorter jumps)")
    order_time_budget_s: float = param(
        30.0, unit="s", label="Order time cap", lo=0.0, lo_open=True, hi=3600.0,
        help="safety cap on the optimized order's search, which stops by itself when it "
             "stops improving (then the order depends on the job alone); only a job that "
             "reaches the cap gets an order that depends on the machine's speed")


@_named
@dataclass(frozen=True, slots=True, kw_only=True)
class LaserParams(ParamGroup):
    """The laser and scanner settings of a job (defaults: a typical fibre-laser galvo)."""

    STAGE: ClassVar[str] = "laser"
    TITLE: ClassVar[str] = "Laser"

    mark_speed_mm_s: float = param(100.0, unit="mm/s", label="Mark speed", lo=0.0,
                                   lo_open=True, hi=1e5, help="beam speed while marking")
    jump_speed_mm_s: float = param(2000.0, unit="mm/s", label="Jump speed", lo=0.0,
                                   lo_open=True, hi=1e5, help="beam speed between strokes")
    frequency_khz: float = param(30.0, unit="kHz", label="Frequency", lo=0.0, lo_open=True,
                                 hi=1e4, help="pulse repetition frequency")
    power_percent: float = param(50.0, unit="%", label="Power", lo=0.0, hi=100.0,
                                 help="laser power")
    laser_on_delay_us: float = param(100.0, unit="µs", label="Laser on delay", lo=0.0, hi=1e6,
                                     help="wait after a jump before the laser turns on")
    laser_off_delay_us: float = param(100.0, unit="µs", label="Laser off delay", lo=0.0,
                                      hi=1e6, help="wait before the laser turns off")
    polygon_delay_us: float = param(100.0, unit="µs", label="Polygon delay", lo=0.0, hi=1e6,
                                    help="wait at each corner of a stroke")
    mark_delay_us: float = param(300.0, unit="µs", label="Mark delay", lo=0.0, hi=1e6,
                                 help="wait at the end of a stroke")
    jump_delay_us: float = param(8.0, unit="µs", label="Jump delay", lo=0.0, hi=1e6,
                                 help="wait after a short jump")
    jump_delay_long_us: float = param(200.0, unit="µs", label="Long jump delay", lo=0.0,
                                      hi=1e6, help="wait after a jump longer than long_jump_mm")
    long_jump_mm: float = param(10.0, unit="mm", label="Long jump", lo=0.0, hi=1e4,
                                help="jumps longer than this wait jump_delay_long_us")
    point_period_us: float = param(10.0, unit="µs", label="Point period", lo=0.0,
                                   lo_open=True, hi=1e6,
                                   help="time per mark point (XY2-100: 10 µs at best)")

    def as_dict(self) -> dict[str, float]:  # type: ignore[override]
        return {f.name: float(getattr(self, f.name)) for f in fields(self)}


#: every group in the order of the pipeline (and of the GUI's panel, the CLI's help)
GROUPS: tuple[type[ParamGroup], ...] = (FitParams, FieldParams, SampleParams, KerfParams,
                                         FillParams, OrderParams, LaserParams)
GROUP_NAMES: tuple[str, ...] = tuple(g.STAGE for g in GROUPS)
#: field name -> its group's name
WHERE: dict[str, str] = {f.name: g.STAGE for g in GROUPS for f in fields(g)}  # type: ignore[arg-type]


def all_specs() -> Iterator[Spec]:
    """Every parameter's Spec, group by group."""
    for g in GROUPS:
        yield from g.specs()


def spec(name: str) -> Spec:
    """The Spec of parameter ``name`` (any group); ParamError for an unknown name."""
    g = WHERE.get(name)
    if g is None:
        raise ParamError(f"unknown parameter {name!r}")
    return spec_of(GROUPS[GROUP_NAMES.index(g)], name)


class Params:
    """Every processing parameter: one frozen instance of each group, read flat.

    ``Params(e_per=0.1, mark_speed_mm_s=500)`` builds the groups from flat keywords (and
    accepts whole groups: ``Params(laser=LaserParams(...))``); ``params.e_per`` reads a field
    of any group; ``params.group("fit")`` is the whole group (a stage's cache key).
    Immutable, hashable, compared by value.
    """

    __slots__ = ("_groups",)

    def __init__(self, **values: Any) -> None:
        per: dict[str, dict[str, Any]] = {g: {} for g in GROUP_NAMES}
        given: dict[str, ParamGroup] = {}
        for name, v in values.items():
            if name in per and isinstance(v, ParamGroup):
                given[name] = v
            elif name in WHERE:
                per[WHERE[name]][name] = v
            else:
                raise ParamError(f"unknown parameter {name!r}")
        groups = []
        for cls in GROUPS:
            g = cls.STAGE
            base = given.get(g)
            if base is None:
                groups.append(cls(**per[g]))
            else:
                groups.append(dataclasses.replace(base, **per[g]) if per[g] else base)  # type: ignore[type-var]
        object.__setattr__(self, "_groups", tuple(groups))

    def __getattr__(self, name: str) -> Any:
        g = WHERE.get(name)
        if g is None:
            if name == "laser":
                return self._groups[-1]
            raise AttributeError(name)
        return getattr(self._groups[GROUP_NAMES.index(g)], name)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("Params is immutable: use replace()")

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Params) and self._groups == other._groups

    def __hash__(self) -> int:
        return hash(self._groups)

    def __repr__(self) -> str:
        changed = {k: v for k, v in self.as_dict().items() if v != spec(k).default}
        return "Params(" + ", ".join(f"{k}={v!r}" for k, v in changed.items()) + ")"

    def __reduce__(self) -> tuple[Any, ...]:
        return (_rebuild, (self.as_dict(),))

    def group(self, name: str) -> ParamGroup:
        """The frozen group ``name`` ("field", "fit", "sample", "kerf", "fill", "order",
        "laser")."""
        return self._groups[GROUP_NAMES.index(name)]

    def replace(self, **changes: Any) -> Params:
        """A copy with some fields (or whole groups) changed, validated."""
        if not changes:
            return self
        out = Params.__new__(Params)
        per: dict[str, dict[str, Any]] = {}
        groups = list(self._groups)
        for name, v in changes.items():
            if name in GROUP_NAMES and isinstance(v, ParamGroup):
                groups[GROUP_NAMES.index(name)] = v
            elif name in WHERE:
                per.setdefault(WHERE[name], {})[name] = v
            else:
                raise ParamError(f"unknown parameter {name!r}")
        for g, ch in per.items():
            i = GROUP_NAMES.index(g)
            groups[i] = dataclasses.replace(groups[i], **ch)  # type: ignore[type-var]
        object.__setattr__(out, "_groups", tuple(groups))
        return out

    def as_dict(self) -> dict[str, Any]:
        """Every parameter by name, every group."""
        out: dict[str, Any] = {}
        for g in self._groups:
            out.update(g.as_dict())
        return out

    def processing_dict(self) -> dict[str, Any]:
        """Every processing parameter by name (what a job's ``params`` records: all groups
        but the laser, which the job keeps in its own ``laser`` table)."""
        out: dict[str, Any] = {}
        for g in self._groups:
            if g.STAGE == "laser":
                continue
            for k, v in g.as_dict().items():
                out[k] = list(v) if isinstance(v, tuple) else v
        return out

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any], *, base: Params | None = None,
                     ignore_unknown: bool = False) -> Params:
        """Params from a flat mapping (a job's ``params`` and ``laser``, saved settings):
        ``base`` with those values; lists become pairs; unknown names are refused unless
        ``ignore_unknown``."""
        changes = {k: tuple(v) if isinstance(v, list) else v for k, v in values.items()
                   if not ignore_unknown or k in WHERE}
        return (base or cls()).replace(**changes)


def _rebuild(values: dict[str, Any]) -> Params:
    return Params(**values)
