"""Pen layers: each PLT pen (SP n) is a layer with its own laser settings and passes.

A :class:`PenTable` holds one laser *profile* (the defaults, a :class:`LaserParams` plus the
layer extras) and the settings of the pens that differ from it. It is frozen and hashable,
so a pipeline can cache by it and the GUI can pass it around as one value.

Pen tables are read from TOML (:func:`load_pen_table`)::

    source = "fiber"                 # or "co2" (optional, default fiber)

    [laser]                          # the profile: defaults of every pen (optional)
    mark_speed_mm_s = 500
    frequency_khz = 30

    [pen.1]
    power_percent = 40
    passes = 2

    [pen.2]
    mark_speed_mm_s = 200
    power_percent = 80
    enabled = true

Keys are named as the job's ``laser`` keys (``mark_speed_mm_s``, ``jump_speed_mm_s``,
``power_percent``, ``frequency_khz``, ``laser_on_delay_us``, ``laser_off_delay_us``,
``polygon_delay_us``, ``mark_delay_us``, ``jump_delay_us``, ``jump_delay_long_us``,
``long_jump_mm``, ``point_period_us``) plus ``passes``, ``enabled``, ``pulse_width_ns``
(fiber MOPA pulse width, optional) and ``colour`` (``"#rrggbb"``, for display). Anything
else, a negative speed, a power above 100 %, broken TOML: :class:`InputError` naming the
file and the place, before anything is written.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, fields
from typing import Any

from galvo_core.errors import InputError, ParamError, read_input_bytes
from galvo_core.params import LaserParams

SOURCES = ("fiber", "co2")
LASER_KEYS: tuple[str, ...] = tuple(f.name for f in fields(LaserParams))
EXTRA_KEYS = ("passes", "enabled", "pulse_width_ns", "colour")
MAX_PASSES = 1000

#: display colours of pens 1..8 when the table gives none (pen n uses n-1 modulo 8)
PEN_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
               "#17becf")
_COLOUR = re.compile(r"^#[0-9a-fA-F]{6}$")


def default_colour(pen: int) -> str:
    return PEN_COLOURS[(pen - 1) % len(PEN_COLOURS)]


@dataclass(frozen=True, slots=True)
class LayerSettings:
    """The settings of one pen layer. ``laser`` carries the speeds, power, frequency and
    delays (units in the names, :class:`LaserParams`); ``passes`` repeats the layer's strokes;
    a disabled layer is neither marked nor timed; ``pulse_width_ns`` (fiber MOPA) is written
    to the controller only when set; ``colour`` is for display only."""

    pen: int
    laser: LaserParams = dataclasses.field(default_factory=LaserParams)
    passes: int = 1
    enabled: bool = True
    pulse_width_ns: int | None = None
    colour: str = ""

    def __post_init__(self) -> None:
        if isinstance(self.pen, bool) or not isinstance(self.pen, int) or self.pen < 0:
            raise ParamError(f"pen must be an integer >= 0, got {self.pen!r}")
        if (isinstance(self.passes, bool) or not isinstance(self.passes, int)
                or not 1 <= self.passes <= MAX_PASSES):
            raise ParamError(f"passes must be an integer in 1..{MAX_PASSES}, got "
                             f"{self.passes!r}")
        if not isinstance(self.enabled, bool):
            raise ParamError(f"enabled must be true or false, got {self.enabled!r}")
        pw = self.pulse_width_ns
        if pw is not None and (isinstance(pw, bool) or not isinstance(pw, int)
                               or not 1 <= pw <= 0xFFFF):
            raise ParamError(f"pulse_width_ns must be an integer in 1..65535, got {pw!r}")
        if self.colour and not _COLOUR.match(self.colour):
            raise ParamError(f"colour must look like \"#rrggbb\", got {self.colour!r}")

    @property
    def display_colour(self) -> str:
        return self.colour or default_colour(self.pen)

    def as_dict(self) -> dict[str, Any]:
        """The job's ``layers`` entry: pen, enabled, passes, colour, pulse_width_ns and every
        laser key."""
        out: dict[str, Any] = {"pen": self.pen, "enabled": self.enabled, "passes": self.passes,
                               "colour": self.display_colour,
                               "pulse_width_ns": self.pulse_width_ns}
        out.update(self.laser.as_dict())
        return out

    def replace(self, **changes: Any) -> LayerSettings:
        """A copy with some settings changed: layer keys and laser keys alike (validated)."""
        laser_kw = {k: changes.pop(k) for k in list(changes) if k in LASER_KEYS}
        laser = dataclasses.replace(self.laser, **laser_kw) if laser_kw else self.laser
        return dataclasses.replace(self, laser=laser, **changes)


@dataclass(frozen=True, slots=True)
class PenTable:
    """The laser profile (``default``, its pen number unused) and the pens that differ from
    it, sorted by pen number. ``source``: ``"fiber"`` (power as mark current, frequency as
    Q-switch period) or ``"co2"`` (frequency and power ratio)."""

    default: LayerSettings = dataclasses.field(default_factory=lambda: LayerSettings(0))
    pens: tuple[LayerSettings, ...] = ()
    source: str = "fiber"

    def __post_init__(self) -> None:
        if self.source not in SOURCES:
            raise ParamError(f"source must be one of {', '.join(SOURCES)}; got {self.source!r}")
        nums = [p.pen for p in self.pens]
        if len(set(nums)) != len(nums):
            raise ParamError("a pen is listed twice")
        if nums != sorted(nums):
            object.__setattr__(self, "pens", tuple(sorted(self.pens, key=lambda p: p.pen)))

    @classmethod
    def from_laser(cls, laser: LaserParams, source: str = "fiber") -> PenTable:
        """A table where every pen uses one laser setting (a job without a pen table)."""
        return cls(LayerSettings(0, laser), (), source)

    def settings(self, pen: int) -> LayerSettings:
        """The settings pen ``pen`` marks with (its own, or the profile's)."""
        for p in self.pens:
            if p.pen == pen:
                return p
        return dataclasses.replace(self.default, pen=pen)

    def layers(self, pens_used: Iterable[int]) -> tuple[LayerSettings, ...]:
        """One layer per pen in ``pens_used``, in pen-number order (the export order)."""
        return tuple(self.settings(p) for p in sorted(set(int(x) for x in pens_used)))

    def with_pen(self, settings: LayerSettings) -> PenTable:
        """A copy with one pen's settings set (added or replaced)."""
        rest = tuple(p for p in self.pens if p.pen != settings.pen)
        return dataclasses.replace(self, pens=rest + (settings,))


# ---------------------------------------------------------------------------- TOML
def _number(v: Any, where: str, name: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InputError(name, f"{where} must be a finite number, not {v!r}")
    return float(v)


def _settings_kw(tab: Mapping[str, Any], where: str, name: str) -> tuple[dict[str, float],
                                                                         dict[str, Any]]:
    """Split a TOML table into LaserParams keywords and layer keywords, refusing unknown
    keys and values of the wrong type."""
    laser: dict[str, float] = {}
    extra: dict[str, Any] = {}
    for key, v in tab.items():
        here = f"{where}.{key}"
        if key in LASER_KEYS:
            laser[key] = _number(v, here, name)
        elif key == "passes":
            if isinstance(v, bool) or not isinstance(v, int):
                raise InputError(name, f"{here} must be a whole number, not {v!r}")
            extra[key] = v
        elif key == "enabled":
            if not isinstance(v, bool):
                raise InputError(name, f"{here} must be true or false, not {v!r}")
            extra[key] = v
        elif key == "pulse_width_ns":
            if isinstance(v, bool) or not isinstance(v, int):
                raise InputError(name, f"{here} must be a whole number of ns, not {v!r}")
            extra[key] = v
        elif key == "colour":
            if not isinstance(v, str):
                raise InputError(name, f"{here} must be a string \"#rrggbb\", not {v!r}")
            extra[key] = v
        else:
            raise InputError(name, f"{here}: unknown key (known: "
                                   f"{', '.join(LASER_KEYS + EXTRA_KEYS)})")
    return laser, extra


def _check(make: Any, where: str, name: str) -> Any:
    try:
        return make()
    except ParamError as exc:
        raise InputError(name, f"{where}: {exc}") from None


def pen_table_from_dict(doc: Mapping[str, Any], name: str = "<pens>",
                        base: LaserParams | None = None) -> PenTable:
    """Build and validate a pen table from parsed TOML (see the module docstring). ``base``:
    the laser profile the ``[laser]`` table starts from (the job's laser settings)."""
    for key in doc:
        if key not in ("source", "laser", "pen"):
            raise InputError(name, f"{key}: unknown key (known: source, [laser], [pen.N])")
    source = doc.get("source", "fiber")
    if source not in SOURCES:
        raise InputError(name, f"source must be one of {', '.join(SOURCES)}, not {source!r}")
    prof = doc.get("laser", {})
    if not isinstance(prof, dict):
        raise InputError(name, "laser must be a table [laser]")
    laser_kw, extra_kw = _settings_kw(prof, "laser", name)
    base_laser = base or LaserParams()
    default = _check(lambda: LayerSettings(
        0, dataclasses.replace(base_laser, **laser_kw), **extra_kw), "laser", name)
    pens_in = doc.get("pen", {})
    if not isinstance(pens_in, dict):
        raise InputError(name, "pen must be tables [pen.N]")
    pens: list[LayerSettings] = []
    for key, tab in pens_in.items():
        where = f"pen.{key}"
        if not re.fullmatch(r"\d{1,4}", str(key)):
            raise InputError(name, f"{where}: a pen number must be a whole number 0..9999")
        if not isinstance(tab, dict):
            raise InputError(name, f"{where} must be a table [{where}]")
        lk, ek = _settings_kw(tab, where, name)
        pens.append(_check(lambda lk=lk, ek=ek, key=key: default.replace(
            pen=int(key), **lk, **ek), where, name))
    if len({p.pen for p in pens}) != len(pens):
        raise InputError(name, "a pen is listed twice (e.g. [pen.1] and [pen.01])")
    return PenTable(default, tuple(pens), source)


def load_pen_table(path: str | os.PathLike[str], base: LaserParams | None = None) -> PenTable:
    """Read a pen table TOML file; InputError (``<file>: <reason>``) if it cannot be used."""
    name, raw = read_input_bytes(path)
    try:
        doc = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise InputError(name, f"not UTF-8 text (byte {exc.start})") from exc
    except tomllib.TOMLDecodeError as exc:
        raise InputError(name, f"not valid TOML: {exc}") from exc
    return pen_table_from_dict(doc, name, base)


def pen_table_from_layers(rows: Iterable[Mapping[str, Any]], source: str = "fiber",
                          name: str = "<job>") -> PenTable:
    """The inverse of the job's ``layers`` table (each row a :meth:`LayerSettings.as_dict`)."""
    pens: list[LayerSettings] = []
    for i, row in enumerate(rows):
        where = f"layers[{i}]"
        if not isinstance(row, Mapping) or "pen" not in row:
            raise InputError(name, f"{where} has no pen")
        r = dict(row)
        pen = r.pop("pen")
        if isinstance(pen, bool) or not isinstance(pen, int):
            raise InputError(name, f"{where}.pen must be a whole number, not {pen!r}")
        if r.get("pulse_width_ns") is None:
            r.pop("pulse_width_ns", None)
        lk, ek = _settings_kw(r, where, name)
        pens.append(_check(lambda lk=lk, ek=ek, pen=pen: LayerSettings(
            pen, LaserParams(**lk), **ek), where, name))
    return _check(lambda: PenTable(LayerSettings(0), tuple(pens), source), "layers", name)


def dump_pen_table(table: PenTable) -> str:
    """The table as TOML that :func:`load_pen_table` reads back to an equal table: the
    profile under ``[laser]``, each listed pen's settings that differ from it."""
    def lines(s: LayerSettings, ref: LayerSettings | None) -> list[str]:
        out = []
        for k in LASER_KEYS:
            v = getattr(s.laser, k)
            if ref is None or v != getattr(ref.laser, k):
                out.append(f"{k} = {float(v)!r}")
        for k in EXTRA_KEYS:
            v = getattr(s, k)
            if v is None or (k == "colour" and not v):
                continue
            if ref is None or v != getattr(ref, k):
                out.append(f"{k} = " + ("true" if v is True else "false" if v is False
                                         else f'"{v}"' if isinstance(v, str) else str(v)))
        return out

    text = [f'source = "{table.source}"', "", "[laser]"] + lines(table.default, None)
    for p in table.pens:
        text += ["", f"[pen.{p.pen}]"] + lines(p, table.default)
    return "\n".join(text) + "\n"


# ---------------------------------------------------------------------------- jobs
def apply_pens(job: Any, pens: PenTable) -> Any:
    """``job`` (a :class:`galvo_core.job.Job`) with its ``layers`` table (one row per pen
    its strokes use, in pen order), the laser source, and the time estimate redone layer by
    layer with each layer's settings and passes (disabled layers neither marked nor timed):
    ``stats["layers"]`` gives each layer's pen, strokes, passes and estimated_time_s; the
    job's time (estimated_time_s, mark_time_s, jump_time_s, delay_time_s) becomes the sum
    over the enabled layers; the counts and lengths of the job's strokes stay as they were."""
    from galvo_core.timing import estimate_layers

    by_pen: dict[int, list[Any]] = {}
    for s in job.strokes:
        by_pen.setdefault(int(s.pen), []).append(s.marks)
    layers = pens.layers(by_pen)
    enabled = [la for la in layers if la.enabled]
    total, per = estimate_layers([(by_pen[la.pen], la.laser, la.passes) for la in enabled],
                                 job.field_map.mm_per_bit)
    rows: list[dict[str, Any]] = []
    it = iter(per)
    for la in layers:
        t = next(it) if la.enabled else None
        rows.append({"pen": la.pen, "enabled": la.enabled, "strokes": len(by_pen[la.pen]),
                     "passes": la.passes,
                     "estimated_time_s": float(t["estimated_time_s"]) if t else 0.0,
                     "mark_length_mm": float(t["mark_length_mm"]) if t else 0.0})
    stats = dict(job.stats)
    for k in ("estimated_time_s", "mark_time_s", "jump_time_s", "delay_time_s"):
        stats[k] = float(total[k])
    stats["layers"] = rows
    return dataclasses.replace(job, layers=tuple(la.as_dict() for la in layers),
                               laser_source=pens.source, stats=stats)
