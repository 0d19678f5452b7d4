"""``galvo-workstation [FILE] [--screenshot OUT.png [--size WxH]] [--set NAME=VALUE …]``.

Without ``--screenshot`` the window opens on FILE (if given). With ``--screenshot`` the
window is rendered offscreen (when there is no display) once the pipeline has finished,
written as a PNG and the program exits: 0 on success, 2 with one ``error: ...`` line on
stderr for bad arguments, a bad ``--set`` (unknown name or a value Params refuses) or a
refused file. Without FILE, ``--screenshot`` uses the first bundled sample
(``resources/samples/*.plt``). ``--set`` takes any Params field (``e_per=0.05``,
``magnification=36``, ``fit_field=true``, ``fill=zigzag``) or LaserParams field
(``mark_speed_mm_s=500``); screenshots ignore the saved settings.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections.abc import Sequence
from pathlib import Path as FsPath

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_USAGE = 2

DEFAULT_SIZE = (1400, 800)
MIN_SIZE = (480, 320)
MAX_SIZE = (8192, 8192)


class UsageError(Exception):
    """Bad command-line arguments: reported as one ``error:`` line, exit 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, no usage dump
        raise UsageError(message)


def parse_size(text: str) -> tuple[int, int]:
    """``"1400x800"`` -> (1400, 800); raises UsageError when malformed or out of range."""
    m = re.fullmatch(r"\s*(\d{1,5})\s*[xX×]\s*(\d{1,5})\s*", text)
    if not m:
        raise UsageError(f"--size must look like WIDTHxHEIGHT (e.g. 1400x800), got {text!r}")
    w, h = int(m.group(1)), int(m.group(2))
    if not (MIN_SIZE[0] <= w <= MAX_SIZE[0] and MIN_SIZE[1] <= h <= MAX_SIZE[1]):
        raise UsageError(
            f"--size {w}x{h} is out of range: width {MIN_SIZE[0]}..{MAX_SIZE[0]}, "
            f"height {MIN_SIZE[1]}..{MAX_SIZE[1]}"
        )
    return w, h


def params_from_sets(sets: Sequence[str]):
    """Params() with ``NAME=VALUE`` changes, each parsed and checked by its parameter's Spec
    (:mod:`galvo_core.params`); UsageError otherwise."""
    from galvo_core.errors import ParamError
    from galvo_core.params import Params, spec

    changes: dict[str, object] = {}
    for item in sets:
        if "=" not in item:
            raise UsageError(f"--set needs NAME=VALUE, got {item!r}")
        name, value = (x.strip() for x in item.split("=", 1))
        name = name.removeprefix("laser.")
        try:
            changes[name] = spec(name).parse(value)
        except ParamError as exc:
            raise UsageError(f"--set: {exc}") from None
    try:
        return Params(**changes)
    except ParamError as exc:
        raise UsageError(f"--set: {exc}") from None


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="galvo-workstation",
        description="Laser galvo marking workstation: view an HP-GL/PLT drawing.",
    )
    p.add_argument("file", nargs="?", metavar="FILE", help="HP-GL / PLT file to open")
    p.add_argument(
        "--screenshot",
        metavar="OUT.png",
        help="render the window (offscreen when there is no display), write a PNG and exit; "
        "without FILE a bundled sample is shown",
    )
    p.add_argument(
        "--set",
        dest="sets",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a processing parameter (any Params or LaserParams field), repeatable",
    )
    p.add_argument(
        "--size",
        metavar="WxH",
        default=None,
        help=f"window size for --screenshot (default {DEFAULT_SIZE[0]}x{DEFAULT_SIZE[1]})",
    )
    return p


def _has_display() -> bool:
    if sys.platform != "linux":
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def _err(message: str) -> None:
    print(f"error: {' '.join(str(message).split())}", file=sys.stderr)


def _qapp(argv: Sequence[str]):
    from PySide6.QtWidgets import QApplication

    existing = QApplication.instance()
    if isinstance(existing, QApplication):
        app = existing
    else:
        app = QApplication([sys.argv[0] if sys.argv else "galvo-workstation", *argv])
    app.setApplicationName("Galvo Workstation")
    app.setOrganizationName("galvo-workstation")
    app.setApplicationDisplayName("Galvo Workstation")
    return app


def render_screenshot(window, out: FsPath, size: tuple[int, int]) -> None:
    """Lay ``window`` out at ``size``, wait for the pipeline, fit the views, and write it to
    ``out`` as PNG."""
    from PySide6.QtWidgets import QApplication

    window.resize(*size)
    window.show()
    for _ in range(3):
        QApplication.processEvents()
    window.wait_for_result(120.0)
    for _ in range(3):
        QApplication.processEvents()
    window.fit()  # after the final layout: the views know their real size now
    for _ in range(3):
        QApplication.processEvents()
    image = window.grab().toImage()
    if (image.width(), image.height()) != size:  # e.g. a display with a size limit
        from PySide6.QtCore import Qt

        image = image.scaled(
            size[0],
            size[1],
            Qt.AspectRatioMode.IgnoreAspectRatio,
            Qt.TransformationMode.SmoothTransformation,
        )
    if not image.save(str(out), "PNG"):
        raise OSError(f"cannot write {out}")


def _screenshot(args: argparse.Namespace, size: tuple[int, int]) -> int:
    out = FsPath(args.screenshot)
    if out.parent and not out.parent.is_dir():
        raise UsageError(f"cannot write {out}: folder {out.parent} does not exist")

    from galvo_core.errors import GalvoError

    from .window import bundled_sample, describe_load_error, load_drawing

    params = params_from_sets(args.sets)
    path = FsPath(args.file) if args.file else bundled_sample()
    drawing = None
    if path is not None:
        try:
            drawing = load_drawing(path)
        except (GalvoError, OSError) as exc:
            _err(describe_load_error(path, exc))
            return EXIT_USAGE

    if not _has_display() and not os.environ.get("QT_QPA_PLATFORM"):
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
    _qapp([])
    from .window import MainWindow

    window = MainWindow(restore=False)
    window.set_params(params, run=False)
    if drawing is not None:
        window.set_drawing(drawing, path)
    try:
        render_screenshot(window, out, size)
    except OSError as exc:
        _err(str(exc))
        return EXIT_USAGE
    finally:
        window.close()
    return EXIT_OK


def _gui(args: argparse.Namespace) -> int:
    if not _has_display() and not os.environ.get("QT_QPA_PLATFORM") and sys.platform == "linux":
        _err("no display (DISPLAY/WAYLAND_DISPLAY unset): use --screenshot OUT.png")
        return EXIT_USAGE
    app = _qapp([])
    from PySide6.QtCore import QTimer

    from .window import MainWindow

    window = MainWindow()
    if args.sets:
        window.set_params(params_from_sets(args.sets), run=False)
    if not window.settings.value("window/geometry"):
        window.resize(*DEFAULT_SIZE)
    window.show()
    if args.file:
        # after the event loop starts, so an error dialog appears over the window
        QTimer.singleShot(0, lambda: window.load_file(args.file))
    return app.exec()


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = build_parser().parse_args(argv)
        if args.size is not None and not args.screenshot:
            raise UsageError("--size needs --screenshot")
        if args.sets and not args.screenshot:
            params_from_sets(args.sets)  # validate before opening a window
        size = parse_size(args.size) if args.size is not None else DEFAULT_SIZE
        if args.screenshot:
            return _screenshot(args, size)
    except UsageError as exc:
        _err(str(exc))
        return EXIT_USAGE
    except Exception as exc:  # noqa: BLE001 - one line, never a traceback
        _err(f"internal error: {type(exc).__name__}: {exc}")
        return EXIT_INTERNAL
    return _gui(args)


if __name__ == "__main__":  # python -m app.main
    sys.exit(main())
