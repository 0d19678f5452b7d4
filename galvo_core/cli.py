"""``galvo-core``: the headless workstation.

Subcommands: ``info`` (what a file holds), ``process`` (file -> job), ``report`` (paper
000's Table 1 for a file). Exit codes: 0 done, 2 refused input or bad option (one line
``error: ...`` on stderr), 1 an internal error (still one line, no traceback).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from dataclasses import fields
from typing import Any, NoReturn

from galvo_core import __version__
from galvo_core.errors import GalvoError, ParamError
from galvo_core.hpgl import read_file
from galvo_core.params import (
    FILLS,
    INTERPOLATIONS,
    KERF_METHODS,
    KERF_SIDES,
    SCAN_ORDERS,
    LaserParams,
    Params,
)


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:
        sys.stderr.write(f"error: {self.prog}: {message}\n")
        sys.exit(2)


def _finite(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if v != v or v in (float("inf"), float("-inf")):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return v


def _add_processing_args(p: argparse.ArgumentParser, *, report: bool = False) -> None:
    d = Params()
    g = p.add_argument_group("thinning and fitting (input units, paper 000)")
    g.add_argument("--eps-line", type=_finite, default=d.eps_line,
                   help=f"line thinning tolerance (default {d.eps_line})")
    g.add_argument("--e-per", type=_finite, default=d.e_per,
                   help=f"largest distance of an input point to its cubic (default {d.e_per})")
    g.add_argument("--eps-sum", type=_finite, default=d.eps_sum,
                   help=f"dichotomy stop on the signed error sum (default {d.eps_sum})")
    f = p.add_argument_group("field")
    m = f.add_mutually_exclusive_group()
    if report:
        m.add_argument("--magnification", type=_finite, nargs="+", metavar="M",
                       dest="magnifications",
                       help="magnifications to compare raw and adaptive marks at (e.g. 36 72)")
    else:
        m.add_argument("--magnification", type=_finite,
                       help="galvo bits per input unit (default: true size, "
                            "field bits / field mm / 40)")
    m.add_argument("--fit-field", action="store_true",
                   help="the largest magnification that fits the field")
    f.add_argument("--field-size-mm", type=_finite, default=d.field_size_mm)
    f.add_argument("--field-bits", type=int, default=d.field_bits)
    f.add_argument("--offset-bits", type=_finite, nargs=2, metavar=("OX", "OY"),
                   help="offset added after scaling (default: drawing centred)")
    f.add_argument("--clamp", action="store_true",
                   help="clamp marks that leave the field (with a warning) instead of refusing")
    s = p.add_argument_group("marking points")
    s.add_argument("--interpolation", choices=INTERPOLATIONS, default=d.interpolation)
    s.add_argument("--chord-tol-bits", type=_finite, default=d.chord_tol_bits)
    s.add_argument("--min-step-bits", type=_finite, default=d.min_step_bits)
    s.add_argument("--max-step-bits", type=_finite, default=None)
    s.add_argument("--fixed-step-bits", type=_finite, default=d.fixed_step_bits,
                   help="paper 001 baseline (--interpolation fixed): step along the curve's "
                        "main axis")
    s.add_argument("--fixed-slope-tol", type=_finite, default=d.fixed_slope_tol,
                   help="paper 001 baseline: slope threshold k0")
    k = p.add_argument_group("kerf compensation (paper 003)")
    k.add_argument("--kerf-mm", type=_finite, default=d.kerf_mm,
                   help="width of the laser trough on the workpiece; 0 = none (default)")
    k.add_argument("--kerf-side", choices=KERF_SIDES, default=d.kerf_side,
                   help="outside grows the design's regions, inside shrinks them")
    k.add_argument("--kerf-method", choices=KERF_METHODS, default=d.kerf_method)
    k.add_argument("--arc-tol-bits", type=_finite, default=d.arc_tol_bits,
                   help="largest deviation of the round corners' arcs (galvo bits)")
    h = p.add_argument_group("fill and order (paper 002)")
    h.add_argument("--fill", choices=FILLS, default=d.fill)
    h.add_argument("--hatch-spacing-mm", type=_finite, default=d.hatch_spacing_mm)
    h.add_argument("--hatch-angle-deg", type=_finite, default=d.hatch_angle_deg)
    h.add_argument("--hatch-passes", type=int, default=d.hatch_passes)
    h.add_argument("--hatch-angle-step-deg", type=_finite, default=d.hatch_angle_step_deg)
    h.add_argument("--hatch-inset-mm", type=_finite, default=d.hatch_inset_mm)
    h.add_argument("--scan-order", choices=SCAN_ORDERS, default=d.scan_order)
    h.add_argument("--order-time-budget-s", type=_finite, default=d.order_time_budget_s)
    las = p.add_argument_group("laser")
    for fld in fields(LaserParams):
        las.add_argument("--" + fld.name.replace("_", "-"), type=_finite, default=None,
                         dest="laser_" + fld.name, help=f"default {fld.default}")


def _params_from_args(a: argparse.Namespace) -> Params:
    laser_kw = {
        fld.name: getattr(a, "laser_" + fld.name)
        for fld in fields(LaserParams)
        if getattr(a, "laser_" + fld.name) is not None
    }
    return Params(
        eps_line=a.eps_line, e_per=a.e_per, eps_sum=a.eps_sum,
        magnification=getattr(a, "magnification", None), fit_field=a.fit_field,
        field_size_mm=a.field_size_mm, field_bits=a.field_bits,
        offset_bits=tuple(a.offset_bits) if a.offset_bits else None, clamp=a.clamp,
        interpolation=a.interpolation, chord_tol_bits=a.chord_tol_bits,
        min_step_bits=a.min_step_bits, max_step_bits=a.max_step_bits,
        fixed_step_bits=a.fixed_step_bits, fixed_slope_tol=a.fixed_slope_tol,
        kerf_mm=a.kerf_mm, kerf_side=a.kerf_side, kerf_method=a.kerf_method,
        arc_tol_bits=a.arc_tol_bits, fill=a.fill, hatch_spacing_mm=a.hatch_spacing_mm,
        hatch_angle_deg=a.hatch_angle_deg, hatch_passes=a.hatch_passes,
        hatch_angle_step_deg=a.hatch_angle_step_deg, hatch_inset_mm=a.hatch_inset_mm,
        scan_order=a.scan_order, order_time_budget_s=a.order_time_budget_s,
        laser=LaserParams(**laser_kw),
    )


def _print_json(obj: Any) -> None:
    sys.stdout.write(json.dumps(obj, indent=2) + "\n")


def cmd_info(a: argparse.Namespace) -> int:
    d = read_file(a.file)
    _print_json(d.info())
    return 0


def cmd_process(a: argparse.Namespace) -> int:
    # imported here: info and --help need none of the pipeline (numba, scipy, shapely)
    from galvo_core.export import write_plt, write_svg
    from galvo_core.job import write_job
    from galvo_core.pipeline import Pipeline

    params = _params_from_args(a)
    d = read_file(a.file)
    job = Pipeline().run(d, params)
    write_job(job, a.output)
    if a.plt:
        write_plt(job, a.plt, what=a.plt_what)
    if a.svg:
        write_svg(job, a.svg, marks=a.svg_marks)
    _print_json({
        "file": d.name,
        "output": a.output,
        "magnification": job.field_map.magnification,
        "stats": job.stats,
        "warnings": [w.as_dict() for w in job.warnings],
    })
    return 0


def cmd_report(a: argparse.Namespace) -> int:
    from galvo_core.fit import fit_report
    from galvo_core.pipeline import Pipeline

    params = _params_from_args(a)
    d = read_file(a.file)
    row = fit_report(d, eps_line=params.eps_line, e_per=params.e_per, eps_sum=params.eps_sum)
    out: dict[str, Any] = {
        "file": d.name,
        "eps_line": params.eps_line,
        "e_per": params.e_per,
        "table1": {
            "input_points": row["input_points"],
            "points_after_thinning": row["thinned_points"],
            "control_points": row["control_points"],
            "lines": row["lines"],
            "cubics": row["cubics"],
            "max_true_error": row["max_error"],
            "time_ms": 1000.0 * float(row["seconds"]),  # type: ignore[arg-type]
        },
    }
    mags = a.magnifications or []
    if mags:
        pipe = Pipeline()
        rows = []
        for mag in mags:
            r: dict[str, Any] = {"magnification": mag}
            for interp in ("raw", "adaptive"):
                p = params.replace(magnification=mag, fit_field=False, interpolation=interp)
                t0 = time.perf_counter()
                job = pipe.run(d, p)
                r[interp] = {
                    "mark_points": job.stats["mark_points"],
                    "estimated_time_s": job.stats["estimated_time_s"],
                    "dwell_points": job.stats["dwell_points"],
                    "seconds": time.perf_counter() - t0,
                }
            r["max_fit_error_um"] = job.stats["max_fit_error_um"]
            rows.append(r)
        out["magnifications"] = rows
    if a.json:
        _print_json(out)
    else:
        t = out["table1"]
        print(f"{d.name}: paper 000 Table 1 (eps_line={params.eps_line:g}, "
              f"e_per={params.e_per:g} input units)")
        print(f"  input points           {t['input_points']}")
        print(f"  points after thinning  {t['points_after_thinning']}")
        print(f"  control points         {t['control_points']}")
        print(f"  lines / cubics         {t['lines']} / {t['cubics']}")
        print(f"  largest true error     {t['max_true_error']:.4f} input units")
        print(f"  time                   {t['time_ms']:.1f} ms")
        for r in out.get("magnifications", []):
            print(f"  at {r['magnification']:g}x: raw {r['raw']['mark_points']} marks "
                  f"({r['raw']['estimated_time_s']:.4f} s), adaptive "
                  f"{r['adaptive']['mark_points']} marks "
                  f"({r['adaptive']['estimated_time_s']:.4f} s), "
                  f"fit error {r['max_fit_error_um']:.2f} µm")
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="galvo-core", description=__doc__.splitlines()[0] if __doc__ else None)
    p.add_argument("--version", action="version", version=f"galvo-core {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    pi = sub.add_parser("info", help="what a PLT/HP-GL file holds, as JSON",
                        description="Print JSON: paths, points, closed_paths, bbox (input "
                                    "units), size_mm, commands, warnings.")
    pi.add_argument("file")
    pi.set_defaults(func=cmd_info)
    pp = sub.add_parser("process", help="process a file into a job file",
                        description="Read, thin and fit, generate marking points, write the "
                                    "job (shared/spec/job-format.md) atomically; print a JSON "
                                    "summary with stats.")
    pp.add_argument("file")
    pp.add_argument("-o", "--output", required=True, help="job file to write (JSON)")
    ex = pp.add_argument_group("export")
    ex.add_argument("--plt", metavar="OUT.plt", help="also write the job as HP-GL")
    ex.add_argument("--plt-what", choices=("marks", "segments"), default="marks",
                    help="marks: the marks in galvo bits (default); segments: the fitted "
                         "lines and Béziers (BZ) in input units")
    ex.add_argument("--svg", metavar="OUT.svg", help="also write the fitted geometry as SVG (mm)")
    ex.add_argument("--svg-marks", action="store_true", help="draw the marks in the SVG too")
    _add_processing_args(pp)
    pp.set_defaults(func=cmd_process)
    pr = sub.add_parser("report", help="paper 000's Table 1 for a file",
                        description="Input points, points after thinning, control points, "
                                    "lines and cubics, largest true error, time; with "
                                    "--magnification M [M ...], raw vs adaptive marks per "
                                    "magnification.")
    pr.add_argument("file")
    pr.add_argument("--json", action="store_true", help="print JSON instead of a table")
    _add_processing_args(pr, report=True)
    pr.set_defaults(func=cmd_report)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (GalvoError, ParamError) as exc:
        sys.stderr.write(f"error: {exc}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("error: interrupted\n")
        return 130
    except MemoryError:
        sys.stderr.write("error: out of memory\n")
        return 1
    except Exception as exc:  # noqa: BLE001 - the user gets one line, never a traceback
        sys.stderr.write(f"error: internal error: {type(exc).__name__}: {exc}\n")
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
