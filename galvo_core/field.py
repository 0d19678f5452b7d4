"""The galvo field: magnification, offset and the input-unit -> bit mapping.

``X = round(x * magnification + ox)``, likewise Y (shared/spec/job-format.md). Marks are
integers in 0..field_bits-1; a drawing that does not fit is refused (:class:`ParamError`)
unless clamping is asked for, in which case out-of-field marks are clamped to the border and
counted in a warning. Never wrapped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from galvo_core.errors import ParamError

#: largest magnification that still fits a drawing leaves this many bits free on each side
FIT_MARGIN_BITS = 16


@dataclass(frozen=True, slots=True)
class FieldMap:
    """Mapping from input units to galvo bits.

    magnification: bits per input unit; offset_bits: (ox, oy) added after scaling;
    field_bits: number of addressable positions per axis (65536 -> 0..65535);
    field_size_mm: width of the field on the workpiece.
    """

    magnification: float
    offset_bits: tuple[float, float]
    field_bits: int = 65536
    field_size_mm: float = 110.0

    @property
    def mm_per_bit(self) -> float:
        return self.field_size_mm / self.field_bits

    @property
    def mm_per_unit(self) -> float:
        """Millimetres on the workpiece per input unit."""
        return self.magnification * self.mm_per_bit

    @property
    def max_bit(self) -> int:
        return self.field_bits - 1

    def to_bits_float(self, pts: np.ndarray) -> np.ndarray:
        """(N, 2) input units -> (N, 2) float bits (not rounded)."""
        p = np.asarray(pts, dtype=np.float64)
        return p * self.magnification + np.asarray(self.offset_bits)

    def to_bits(self, pts: np.ndarray) -> np.ndarray:
        """(N, 2) input units -> (N, 2) int64 bits, rounded half away from zero."""
        f = self.to_bits_float(pts)
        return np.where(f >= 0, np.floor(f + 0.5), np.ceil(f - 0.5)).astype(np.int64)

    def mm_to_units(self, mm: float) -> float:
        """A length on the workpiece (mm) in input units."""
        return mm / self.mm_per_unit

    def bits_to_units(self, bits: float) -> float:
        return bits / self.magnification

    def as_dict(self) -> dict[str, object]:
        return {
            "magnification": self.magnification,
            "offset_bits": [float(self.offset_bits[0]), float(self.offset_bits[1])],
            "field_bits": self.field_bits,
            "field_size_mm": self.field_size_mm,
        }


def make_field(
    bbox: tuple[float, float, float, float] | None,
    *,
    magnification: float | None,
    fit_field: bool = False,
    field_bits: int = 65536,
    field_size_mm: float = 110.0,
    offset_bits: tuple[float, float] | None = None,
    margin_bits: float = 0.0,
) -> FieldMap:
    """Choose the mapping for a drawing with bounding box ``bbox`` (input units).

    ``fit_field`` picks the largest magnification that fits the drawing in the field with
    :data:`FIT_MARGIN_BITS` plus ``margin_bits`` to spare on each side (``margin_bits``: room
    for what later stages add, e.g. an outward kerf; a given ``magnification`` is ignored).
    Without an offset the drawing's bounding box is centred in the field.
    """
    if bbox is None:
        bbox = (0.0, 0.0, 0.0, 0.0)
    xmin, ymin, xmax, ymax = bbox
    w, h = xmax - xmin, ymax - ymin
    usable = field_bits - 1 - 2 * (FIT_MARGIN_BITS + max(0.0, margin_bits))
    if fit_field or magnification is None:
        if not fit_field:
            raise ParamError("give a magnification (bits per input unit) or ask for fit-field")
        span = max(w, h)
        magnification = usable / span if span > 0 else 1.0
    if not (magnification > 0 and math.isfinite(magnification)):
        raise ParamError(f"magnification must be a positive finite number, got {magnification!r}")
    if offset_bits is None:
        centre = (field_bits - 1) / 2.0
        offset_bits = (
            centre - magnification * (xmin + xmax) / 2.0,
            centre - magnification * (ymin + ymax) / 2.0,
        )
    return FieldMap(float(magnification), (float(offset_bits[0]), float(offset_bits[1])),
                    field_bits, field_size_mm)


def check_in_field(
    fm: FieldMap, bbox: tuple[float, float, float, float] | None, *, clamp: bool, name: str = ""
) -> str | None:
    """Refuse a drawing that leaves the field (ParamError), or with ``clamp`` return a
    warning text. None when everything fits."""
    if bbox is None:
        return None
    lo = fm.to_bits_float(np.array([bbox[:2]]))[0]
    hi = fm.to_bits_float(np.array([bbox[2:]]))[0]
    if lo.min() >= -0.5 and hi.max() < fm.max_bit + 0.5:
        return None
    size_mm = (
        (bbox[2] - bbox[0]) * fm.mm_per_unit,
        (bbox[3] - bbox[1]) * fm.mm_per_unit,
    )
    msg = (
        f"the drawing ({size_mm[0]:.1f} x {size_mm[1]:.1f} mm at magnification "
        f"{fm.magnification:g}) leaves the {fm.field_size_mm:g} mm field "
        f"(bits {lo[0]:.0f}..{hi[0]:.0f} x {lo[1]:.0f}..{hi[1]:.0f}, field 0..{fm.max_bit})"
    )
    if not clamp:
        raise ParamError(msg + "; lower the magnification, use --fit-field, or --clamp")
    return msg + "; marks outside were clamped to the field border"
