"""The controller side of ``galvo-core``: pen tables, LMC list export, framing, field
correction (``process``), and the ``send`` subcommand.

Hooks for :mod:`galvo_core.cli` (``process``)::

    add_controller_options(parser)        # the options below, in their own groups
    job = prepare_job(job, args)          # pens + field correction; encodes and checks the
                                          # LMC outputs before anything is written
    write_job(job, args.output)
    summary.update(write_controller_outputs(job, args))

and ``add_send_parser(subparsers)`` for ``galvo-core send JOB.json``. Every refusal is a
:class:`~galvo_core.errors.GalvoError` / ``InputError`` (``<file>: <reason>``), raised before
any file is written.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

import numpy as np

from galvo_core.correction import FieldCorrection, apply_to_job, load_3x3, read_cor
from galvo_core.errors import GalvoError
from galvo_core.framing import SHAPES, frame_records, outline
from galvo_core.job import Job, atomic_write_bytes, load_job
from galvo_core.layers import PenTable, apply_pens, load_pen_table
from galvo_core.lmc import (
    Orientation,
    encode_job,
    job_pen_table,
    to_bytes,
    to_text,
)
from galvo_core.params import LaserParams

DEFAULT_FRAME_LOOPS = 20
FRAME_LOOPS_PER_LIST = 10  # send: loops per list sent to the board while framing


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1: {text!r}")
    return v


def _positive(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (v > 0 and v != float("inf")):
        raise argparse.ArgumentTypeError(f"must be a positive number: {text!r}")
    return v


def _add_common(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("pen layers and controller (BJJCZ / LMC)")
    g.add_argument("--pens", metavar="PENS.toml",
                   help="pen table: [pen.N] tables with the laser keys, passes, enabled")
    g.add_argument("--swap-xy", action="store_true", help="swap the galvos' X and Y")
    g.add_argument("--flip-x", action="store_true", help="mirror X (after --swap-xy)")
    g.add_argument("--flip-y", action="store_true", help="mirror Y (after --swap-xy)")
    c = g.add_mutually_exclusive_group()
    c.add_argument("--field-correction", metavar="FILE.cor",
                   help="correct the marks with a BJJCZ .cor table (software, bilinear)")
    c.add_argument("--field-correction-3x3", metavar="GRID.toml",
                   help="correct the marks from a measured 3x3 grid (span_mm, dx_mm, dy_mm)")
    g.add_argument("--correction-tol-bits", type=_positive, default=0.25,
                   help="largest bend of a corrected straight line, bits (default 0.25)")
    g.add_argument("--frame-shape", choices=SHAPES, default="bbox",
                   help="framing outline: bounding box (default) or convex hull")
    g.add_argument("--light-speed-mm-s", type=_positive, default=None,
                   help="framing speed (default: the jump speed)")


def add_controller_options(p: argparse.ArgumentParser) -> None:
    """The ``process`` options: --pens, --lmc, --lmc-text, --frame-lmc, orientation, field
    correction."""
    _add_common(p)
    g = p.add_argument_group("controller files")
    g.add_argument("--lmc", metavar="JOB.lmc", help="also write the job as BJJCZ list records")
    g.add_argument("--lmc-text", metavar="JOB.txt",
                   help="also write the list as text, one record per line (for diffs)")
    g.add_argument("--frame-lmc", metavar="FRAME.lmc",
                   help="also write a framing list (red pointer around the job)")
    g.add_argument("--frame-loops", type=_positive_int, default=DEFAULT_FRAME_LOOPS,
                   help=f"times around the outline in --frame-lmc (default "
                        f"{DEFAULT_FRAME_LOOPS})")


def _orientation(a: argparse.Namespace) -> Orientation:
    return Orientation(bool(a.swap_xy), bool(a.flip_x), bool(a.flip_y))


def _correction(a: argparse.Namespace, job: Job) -> FieldCorrection | None:
    if getattr(a, "field_correction", None):
        return read_cor(a.field_correction)
    if getattr(a, "field_correction_3x3", None):
        fm = job.field_map
        return load_3x3(a.field_correction_3x3, fm.field_bits, fm.field_size_mm)
    return None


def _pens(a: argparse.Namespace, job: Job) -> PenTable | None:
    if not getattr(a, "pens", None):
        return None
    base = LaserParams(**{k: v for k, v in job.laser.items()
                          if k in LaserParams.__dataclass_fields__})
    return load_pen_table(a.pens, base)


def apply_controller_options(job: Job, a: argparse.Namespace) -> Job:
    """Field correction and pens (layers table, time per layer on the marks as sent), as
    asked; both files are read before either is applied."""
    pens = _pens(a, job)
    corr = _correction(a, job)
    if corr is not None:
        job = apply_to_job(job, corr, a.correction_tol_bits)
    if pens is not None:
        job = apply_pens(job, pens)
    return job


def controller_outputs(job: Job, a: argparse.Namespace) -> list[tuple[str, bytes, str]]:
    """The files asked for, encoded (path, bytes, kind); raises before anything is written."""
    out: list[tuple[str, bytes, str]] = []
    orient = _orientation(a)
    if getattr(a, "lmc", None) or getattr(a, "lmc_text", None):
        rec = encode_job(job, orientation=orient)
        if a.lmc:
            out.append((a.lmc, to_bytes(rec), "lmc"))
        if a.lmc_text:
            out.append((a.lmc_text, to_text(rec).encode("ascii"), "lmc_text"))
    if getattr(a, "frame_lmc", None):
        table = job_pen_table(job)
        first = table.layers({s.pen for s in job.strokes} or {1})[0].laser
        rec = frame_records(outline(job, a.frame_shape, orient), a.frame_loops, job, first,
                            a.light_speed_mm_s)
        out.append((a.frame_lmc, to_bytes(rec), "frame_lmc"))
    return out


def prepare_job(job: Job, a: argparse.Namespace) -> Job:
    """``process``: apply pens and correction, then encode every controller file now (kept
    on ``a``) so that a refusal comes before the job file is written."""
    job = apply_controller_options(job, a)
    a._controller_outputs = (job, controller_outputs(job, a))
    return job


def write_controller_outputs(job: Job, a: argparse.Namespace) -> dict[str, Any]:
    """Write the controller files (atomically); return what to add to the summary."""
    held = getattr(a, "_controller_outputs", None)
    outs = held[1] if held is not None and held[0] is job else controller_outputs(job, a)
    summary: dict[str, Any] = {}
    for path, data, kind in outs:
        atomic_write_bytes(path, data)
        summary[kind] = path
        if kind in ("lmc", "frame_lmc"):
            summary[kind + "_records"] = len(data) // 12
    if "layers" in job.stats:
        summary["layers"] = job.stats["layers"]
    if job.field_correction is not None:
        summary["field_correction"] = job.field_correction
    return summary


# ---------------------------------------------------------------------------- send
def _controller(mock: bool, bits_per_mm: float, machine_index: int) -> Any:
    try:
        from galvo import GalvoController
        from galvo.mock_connection import MockConnection
    except ImportError:
        raise GalvoError("send needs galvoplotter: pip install 'galvo-workstation[lmc]'") \
            from None
    c = GalvoController(mock=mock, galvos_per_mm=bits_per_mm, machine_index=machine_index)
    if mock:
        c.connection = MockConnection()  # silent: its default prints every packet
    return c


def _board_present() -> str | None:
    """None when a BJJCZ board is on the USB bus, else why not (asked once, quickly:
    galvoplotter itself retries for about 6 s before giving up)."""
    try:
        import usb.core

        found = usb.core.find(idVendor=0x9588, idProduct=0x9899)
    except Exception as exc:  # noqa: BLE001 - no libusb backend, no permission
        return str(exc) or type(exc).__name__
    return None if found is not None else "no device"


def _connect(c: Any) -> None:
    if not c.mock:
        why = _board_present()
        if why is not None:
            raise GalvoError(f"no BJJCZ (LMC) board answered on USB 9588:9899 ({why}); "
                             "connect it, check permissions, or use --dry-run")
    try:
        c.connect_if_needed()
    except Exception as exc:  # noqa: BLE001 - no board, no libusb, no permission: one line
        why = str(exc) or type(exc).__name__
        raise GalvoError(f"no BJJCZ (LMC) board answered on USB 9588:9899 ({why}); connect "
                         "it, check permissions, or use --dry-run") from None
    if not c.is_connected:
        raise GalvoError("no BJJCZ (LMC) board answered on USB; use --dry-run to try")


def _run_list(c: Any, rec: np.ndarray, *, light: bool, fiber: bool) -> int:
    """Send one list of records (ending with its end-of-list) and run it; packets sent."""
    packets = [0]
    write = c.connection.write

    def counted(index: int = 0, packet: bytes | None = None) -> Any:
        if packet is not None and len(packet) == 0xC00:
            packets[0] += 1
        return write(index, packet)

    c.connection.write = counted
    try:
        c.reset_list()
        if light:
            c.port_off(c.laser_pin)
            c.port_on(c.light_pin)
            c.laser_configuration = "lighting"
        else:
            c.port_on(c.laser_pin)
            c.write_port()
            if fiber:
                c.set_fiber_mo(1)
            c.laser_configuration = "marking"
        for r in rec[:-1]:  # initial_configuration() writes the end-of-list
            c._list_write(*(int(w) for w in r))
        c.initial_configuration()
    finally:
        c.connection.write = write
    return packets[0]


def cmd_send(a: argparse.Namespace) -> int:
    job = load_job(a.job)
    if job.field_correction is not None and (a.field_correction or a.field_correction_3x3):
        raise GalvoError(f"{a.job}: the job's marks are already field-corrected "
                         f"({job.field_correction.get('source', '?')}); not applying a "
                         "correction twice")
    job_pen_table(job, name=a.job)  # the job's own layers table, checked naming the file
    job = apply_controller_options(job, a)
    orient = _orientation(a)
    table = job_pen_table(job, name=a.job)
    bpm = job.field_map.field_bits / job.field_map.field_size_mm
    if a.frame:
        first = table.layers({s.pen for s in job.strokes} or {1})[0].laser
        path = outline(job, a.frame_shape, orient)
        per_list = 1 if a.dry_run else FRAME_LOOPS_PER_LIST  # a dry run counts loops
        rec = frame_records(path, per_list, job, first, a.light_speed_mm_s)
    else:
        rec = encode_job(job, orientation=orient)
    c = _controller(a.dry_run, bpm, a.machine_index)
    _connect(c)
    sent = 0
    loops = 0
    t0 = time.perf_counter()
    try:
        if a.frame:
            # lists of a few loops each, until Ctrl-C (a dry run stops after --frame-loops)
            while not a.dry_run or loops < a.frame_loops:
                sent += _run_list(c, rec, light=True, fiber=table.source == "fiber")
                loops += per_list
        else:
            sent += _run_list(c, rec, light=False, fiber=table.source == "fiber")
    except KeyboardInterrupt:
        c.abort()
        if not a.frame:
            raise GalvoError(f"{a.job}: marking stopped (Ctrl-C)") from None
    finally:
        if a.frame:  # the pointer off again
            c.port_off(c.light_pin)
            c.write_port()
        c.shutdown()
    out = {"job": a.job, "dry_run": bool(a.dry_run), "what": "frame" if a.frame else "mark",
           "records": int(len(rec)), "packets": sent, "seconds": time.perf_counter() - t0}
    if a.frame:
        out["loops"] = loops
    sys.stdout.write(json.dumps(out, indent=2) + "\n")
    return 0


def add_send_parser(sub: Any) -> argparse.ArgumentParser:
    """Register ``send`` on the ``galvo-core`` subparsers."""
    ps = sub.add_parser(
        "send", help="mark a job on a connected BJJCZ (LMC) board (needs the [lmc] extra)",
        description="Send a job file to a BJJCZ (LMC) controller through galvoplotter: "
                    "the same list as --lmc, layer by layer. --frame traces the outline "
                    "with the red pointer until Ctrl-C instead. --dry-run uses "
                    "galvoplotter's mock connection (no board needed).")
    ps.add_argument("job", help="job file (JSON) written by process")
    ps.add_argument("--dry-run", action="store_true", help="mock connection, nothing moves")
    ps.add_argument("--frame", action="store_true",
                    help="trace the outline with the pointer until Ctrl-C")
    ps.add_argument("--frame-loops", type=_positive_int, default=DEFAULT_FRAME_LOOPS,
                    help="with --dry-run --frame: loops to simulate")
    ps.add_argument("--machine-index", type=int, default=0, help="which board (default 0)")
    _add_common(ps)
    ps.set_defaults(func=cmd_send)
    return ps
