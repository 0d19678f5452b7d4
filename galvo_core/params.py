"""One frozen parameter set for the whole pipeline, units in the names.

Units (see shared/spec/job-format.md):
* ``eps_line``, ``e_per``, ``eps_sum`` are input units (HP-GL plotter units), as in paper 000;
* ``*_bits`` are galvo bits; ``magnification`` is galvo bits per input unit;
* ``*_mm``, ``*_mm_s`` are millimetres (per second) on the workpiece, after magnification;
* ``*_us`` microseconds, ``*_khz`` kilohertz, ``*_deg`` degrees.

Every stage reads only the fields it needs (see :data:`STAGE_FIELDS`), so the pipeline can
cache a stage's result by those fields: moving ``e_per`` refits but does not re-read the file;
moving the magnification re-samples but does not refit.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, fields
from typing import Any

from galvo_core.errors import ParamError

INTERPOLATIONS = ("adaptive", "fixed", "raw")
KERF_SIDES = ("outside", "inside")
KERF_METHODS = ("vector", "raster", "rectangle")
FILLS = ("none", "scanline", "zigzag")
SCAN_ORDERS = ("file", "greedy", "optimized")


@dataclass(frozen=True, slots=True)
class LaserParams:
    """The laser and scanner settings of a job (defaults: a typical fibre-laser galvo)."""

    mark_speed_mm_s: float = 100.0
    jump_speed_mm_s: float = 2000.0
    frequency_khz: float = 30.0
    power_percent: float = 50.0
    laser_on_delay_us: float = 100.0
    laser_off_delay_us: float = 100.0
    polygon_delay_us: float = 100.0
    mark_delay_us: float = 300.0  # mark end delay
    jump_delay_us: float = 8.0  # short jumps
    jump_delay_long_us: float = 200.0  # jumps longer than long_jump_mm
    long_jump_mm: float = 10.0
    point_period_us: float = 10.0  # XY2-100: one point per 10 µs at best

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ParamError(f"{f.name} must be a finite number >= 0, got {v!r}")
        for name in ("mark_speed_mm_s", "jump_speed_mm_s", "frequency_khz", "point_period_us"):
            if getattr(self, name) <= 0:
                raise ParamError(f"{name} must be > 0, got {getattr(self, name)!r}")
        if self.power_percent > 100:
            raise ParamError(f"power_percent must be <= 100, got {self.power_percent!r}")

    def as_dict(self) -> dict[str, float]:
        return {f.name: float(getattr(self, f.name)) for f in fields(self)}


@dataclass(frozen=True, slots=True)
class Params:
    """Every processing parameter; keyword-only construction, validated on creation."""

    # paper 000 §2-3: thinning and fitting, input units
    eps_line: float = 0.02
    e_per: float = 0.02
    eps_sum: float = 0.002
    # field mapping
    magnification: float | None = None  # bits per input unit; None with fit_field
    fit_field: bool = False
    field_size_mm: float = 110.0
    field_bits: int = 65536
    offset_bits: tuple[float, float] | None = None  # None: drawing centred in the field
    clamp: bool = False
    # marking points (paper 000 §4, paper 004, paper 001 baseline)
    interpolation: str = "adaptive"
    chord_tol_bits: float = 1.0
    min_step_bits: float = 2.0
    max_step_bits: float | None = None
    fixed_step_bits: float = 16.0  # paper 001 baseline: step along x
    fixed_slope_tol: float = 0.05  # paper 001 baseline: slope threshold k0
    # kerf (paper 003)
    kerf_mm: float = 0.0
    kerf_side: str = "outside"
    kerf_method: str = "vector"
    arc_tol_bits: float = 1.0
    # fill and order (paper 002)
    fill: str = "none"
    hatch_spacing_mm: float = 0.05
    hatch_angle_deg: float = 0.0
    hatch_passes: int = 1
    hatch_angle_step_deg: float = 90.0
    hatch_inset_mm: float = 0.0
    scan_order: str = "file"
    order_time_budget_s: float = 1.0
    laser: LaserParams = field(default_factory=LaserParams)

    def __post_init__(self) -> None:
        def positive(name: str) -> None:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ParamError(f"{name} must be a number, got {v!r}")
            if not math.isfinite(v) or v <= 0:
                raise ParamError(f"{name} must be a positive finite number, got {v!r}")

        def non_negative(name: str) -> None:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ParamError(f"{name} must be a finite number, got {v!r}")
            if v < 0:
                raise ParamError(f"{name} must be >= 0, got {v!r}")

        for name in ("eps_line", "e_per", "eps_sum", "field_size_mm", "chord_tol_bits",
                     "fixed_step_bits", "fixed_slope_tol", "arc_tol_bits", "hatch_spacing_mm",
                     "order_time_budget_s"):
            positive(name)
        for name in ("min_step_bits", "kerf_mm", "hatch_inset_mm"):
            non_negative(name)
        if self.magnification is not None:
            positive("magnification")
        if self.max_step_bits is not None:
            positive("max_step_bits")
            if self.max_step_bits < self.min_step_bits:
                raise ParamError("max_step_bits must be >= min_step_bits")
        if not isinstance(self.field_bits, int) or not 2 <= self.field_bits <= 1 << 24:
            raise ParamError(
                f"field_bits must be an integer in 2..16777216, got {self.field_bits!r}"
            )
        if not math.isfinite(self.hatch_angle_deg):
            raise ParamError("hatch_angle_deg must be finite")
        if not isinstance(self.hatch_passes, int) or not 1 <= self.hatch_passes <= 16:
            raise ParamError(f"hatch_passes must be an integer in 1..16, got {self.hatch_passes!r}")
        for name, allowed in (("interpolation", INTERPOLATIONS), ("kerf_side", KERF_SIDES),
                              ("kerf_method", KERF_METHODS), ("fill", FILLS),
                              ("scan_order", SCAN_ORDERS)):
            if getattr(self, name) not in allowed:
                raise ParamError(
                    f"{name} must be one of {', '.join(allowed)}; got {getattr(self, name)!r}"
                )
        if self.offset_bits is not None:
            ox, oy = self.offset_bits
            if not (math.isfinite(ox) and math.isfinite(oy)):
                raise ParamError("offset_bits must be finite")

    @property
    def mm_per_bit(self) -> float:
        return self.field_size_mm / self.field_bits

    def replace(self, **changes: Any) -> Params:
        """A copy with some fields changed (validated)."""
        return dataclasses.replace(self, **changes)

    def processing_dict(self) -> dict[str, Any]:
        """Every processing parameter by name (what a job's ``params`` records)."""
        out: dict[str, Any] = {}
        for f in fields(self):
            if f.name == "laser":
                continue
            v = getattr(self, f.name)
            out[f.name] = list(v) if isinstance(v, tuple) else v
        return out


#: which Params fields each stage depends on (the cache key of that stage)
STAGE_FIELDS: dict[str, tuple[str, ...]] = {
    "kerf": ("kerf_mm", "kerf_side", "kerf_method", "arc_tol_bits", "magnification",
             "fit_field", "field_size_mm", "field_bits"),
    "fit": ("eps_line", "e_per", "eps_sum"),
    "field": ("magnification", "fit_field", "field_size_mm", "field_bits", "offset_bits",
              "clamp"),
    "sample": ("interpolation", "chord_tol_bits", "min_step_bits", "max_step_bits",
               "fixed_step_bits", "fixed_slope_tol"),
    "fill": ("fill", "hatch_spacing_mm", "hatch_angle_deg", "hatch_passes",
             "hatch_angle_step_deg", "hatch_inset_mm"),
    "order": ("scan_order", "order_time_budget_s"),
}
