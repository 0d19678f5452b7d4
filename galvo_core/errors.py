"""Errors that reach the user as one clear line, never as a traceback."""

from __future__ import annotations

import os


class GalvoError(Exception):
    """Base of every error galvo_core raises on purpose.

    ``str(err)`` is the message shown to the user after ``error: ``.
    """


class InputError(GalvoError):
    """A file is refused: not HP-GL, unreadable, empty, truncated beyond use.

    ``file`` names the file, ``reason`` says why in words an operator understands;
    ``str(err)`` is ``"<file>: <reason>"``.
    """

    def __init__(self, file: str, reason: str) -> None:
        super().__init__(f"{file}: {reason}")
        self.file = file
        self.reason = reason


class ParamError(GalvoError, ValueError):
    """A processing parameter is out of its allowed range (zero, negative, NaN, absurd)."""


class Cancelled(Exception):
    """Raised inside a run (fit, sampling, preview) when its ``cancel`` callback says stop."""


def read_input_bytes(path: str | os.PathLike[str]) -> tuple[str, bytes]:
    """The file's name (as given) and bytes; InputError ``<file>: cannot be read (...)``
    when the system refuses (missing, a folder, no permission)."""
    name = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            return name, fh.read()
    except OSError as exc:
        raise InputError(name, f"cannot be read ({exc.strerror or exc})") from exc
