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
from collections.abc import Callable, Sequence
from typing import Any, NoReturn

from galvo_core import __version__, cli_lmc
from galvo_core.errors import GalvoError, ParamError
from galvo_core.hpgl import read_file
from galvo_core.params import GROUPS, Params, Spec, all_specs


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:
        sys.stderr.write(f"error: {self.prog}: {message}\n")
        sys.exit(2)


def _option_type(spec: Spec) -> Callable[[str], Any]:
    """argparse ``type`` for one parameter: its Spec parses and checks the text."""

    def convert(text: str) -> Any:
        try:
            return spec.parse(text)
        except ParamError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    convert.__name__ = spec.kind  # argparse names the type in its messages
    return convert


def _add_processing_args(p: argparse.ArgumentParser, *, report: bool = False) -> None:
    """One option per parameter of :mod:`galvo_core.params`, from its Spec alone (name,
    unit, range, default and help); only the options given end up in the namespace."""
    for group in GROUPS:
        g = p.add_argument_group(f"{group.TITLE.lower()} ({group.STAGE} stage)"
                                 if group.STAGE != "laser" else "laser (time estimate, job)")
        for spec in group.specs():
            kw: dict[str, Any] = {"dest": spec.name, "default": argparse.SUPPRESS,
                                  "help": spec.describe().replace("%", "%%")}
            if spec.name == "magnification" and report:
                g.add_argument(spec.option, type=_option_type(spec), nargs="+", metavar="M",
                               dest="magnifications", default=None,
                               help="magnifications to compare raw and adaptive marks at "
                                    "(e.g. 36 72)")
                continue
            if spec.kind == "bool":
                g.add_argument(spec.option, action=argparse.BooleanOptionalAction, **kw)
            elif spec.kind == "pair":
                g.add_argument(spec.option, type=float, nargs=2, metavar=("X", "Y"), **kw)
            elif spec.kind == "choice":
                g.add_argument(spec.option, choices=spec.choices, **kw)
            else:
                g.add_argument(spec.option, type=_option_type(spec), metavar=spec.kind.upper(),
                               **kw)


def _params_from_args(a: argparse.Namespace) -> Params:
    given = {s.name: getattr(a, s.name) for s in all_specs() if hasattr(a, s.name)}
    if "offset_bits" in given:
        given["offset_bits"] = tuple(given["offset_bits"])
    return Params(**given)


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
    t0 = time.perf_counter()
    d = read_file(a.file)
    t1 = time.perf_counter()
    res = Pipeline().run(d, params)
    job = cli_lmc.prepare_job(res.job, a)  # pens, field correction; LMC files checked
    t2 = time.perf_counter()
    write_job(job, a.output)
    # wall seconds per stage: the file read, each stage the pipeline ran, the job written
    timings = {"read": t1 - t0, **res.timings, "write": time.perf_counter() - t2}
    if a.plt:
        write_plt(job, a.plt, what=a.plt_what)
    if a.svg:
        write_svg(job, a.svg, marks=a.svg_marks)
    controller = cli_lmc.write_controller_outputs(job, a)
    _print_json({
        "file": d.name,
        "output": a.output,
        "magnification": job.field_map.magnification,
        "stats": job.stats,
        "warnings": [w.as_dict() for w in job.warnings],
        "timings_s": {k: round(v, 6) for k, v in timings.items()},
        **controller,
    })
    return 0


def cmd_report(a: argparse.Namespace) -> int:
    from galvo_core.fit import fit_report
    from galvo_core.pipeline import Pipeline

    params = _params_from_args(a)
    d = read_file(a.file)
    row = fit_report(d, eps_line=params.eps_line, e_per=params.e_per, eps_sum=params.eps_sum,
                     per_path=True)
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
            "quantum_units": row["quantum_units"],
            "e_per_in_effect": row["e_per_in_effect"],
        },
        # per path: segments (lines, cubics), the bound in effect and the worst true error
        "paths": row["paths"],
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
                job = pipe.run(d, p).job
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
        print(f"  coordinate grid        {t['quantum_units']:g} unit (bound from the points: "
              f"{t['e_per_in_effect']:.4g})")
        paths = out["paths"]
        worst = sorted(paths, key=lambda p: -p["max_error"] / max(p["bound"], 1e-300))[:10]
        if worst:
            print("  paths nearest their bound (index: segments lines/cubics, worst / bound):")
        for p in worst:
            print(f"    {p['index']:>6}: {p['segments']:>5} {p['lines']}/{p['cubics']}, "
                  f"{p['max_error']:.4f} / {p['bound']:.4f}")
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
    cli_lmc.add_controller_options(pp)
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
    cli_lmc.add_send_parser(sub)
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
