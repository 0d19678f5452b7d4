"""The PySide6 6.12.0 trap: on Python 3.11 it aborts the interpreter after a few hundred
signal disconnects (pyqtgraph connects and disconnects all the time). pyproject pins
PySide6 < 6.12; these tests catch a regression of the pin or of PySide6 itself.

The cycles run in a subprocess: an abort there fails the test instead of killing pytest.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

CYCLES = 1000
MARKER = "QT-DISCONNECT-CYCLES-DONE"

CHILD = textwrap.dedent(
    f"""
    import os, sys
    os.environ["QT_QPA_PLATFORM"] = "offscreen"
    from PySide6.QtCore import QObject, QTimer, Signal
    from PySide6.QtWidgets import QApplication

    app = QApplication([])

    class Emitter(QObject):
        with_arg = Signal(object)
        bare = Signal()

    class QtReceiver(QObject):
        def __init__(self):
            super().__init__()
            self.n = 0
        def slot(self, *args):
            self.n += 1

    class PlainReceiver:
        def __init__(self):
            self.n = 0
        def slot(self, *args):
            self.n += 1

    hits = [0]
    def function_slot(*args):
        hits[0] += 1

    emitter, qt_rx, plain_rx, timer = Emitter(), QtReceiver(), PlainReceiver(), QTimer()
    for i in range({CYCLES}):
        emitter.with_arg.connect(qt_rx.slot)           # bound method of a QObject
        emitter.with_arg.emit(i)
        emitter.with_arg.disconnect(qt_rx.slot)

        emitter.with_arg.connect(plain_rx.slot)        # bound method of a plain object
        emitter.with_arg.emit(i)
        emitter.with_arg.disconnect(plain_rx.slot)

        lam = lambda *a: hits.__setitem__(0, hits[0] + 1)
        emitter.bare.connect(lam)                      # lambda
        emitter.bare.emit()
        emitter.bare.disconnect(lam)

        emitter.bare.connect(function_slot)            # plain function
        emitter.bare.disconnect(function_slot)

        conn = emitter.with_arg.connect(qt_rx.slot)    # by connection handle
        QObject.disconnect(conn)

        timer.timeout.connect(plain_rx.slot)           # pyqtgraph-like: QTimer.timeout
        timer.timeout.disconnect(plain_rx.slot)

        emitter.with_arg.connect(plain_rx.slot)        # disconnect everything
        emitter.with_arg.disconnect()

    emitter.with_arg.emit(-1)                          # nothing connected any more
    assert qt_rx.n == {CYCLES} and plain_rx.n == {CYCLES} and hits[0] == {CYCLES}, (
        qt_rx.n, plain_rx.n, hits[0])

    # what pyqtgraph itself does: linking views and replacing data connect/disconnect
    import numpy as np
    import pyqtgraph as pg
    a, b = pg.PlotWidget(), pg.PlotWidget()
    item = a.plot([0, 1], [0, 1])
    for i in range({CYCLES} // 4):
        b.setXLink(a)
        b.setYLink(a)
        b.setXLink(None)
        b.setYLink(None)
        item.setData(np.arange(3) + i, np.arange(3))
        app.processEvents()
    print("{MARKER}", flush=True)
    """
)


def test_pyside6_is_not_the_broken_release():
    import PySide6

    assert PySide6.__version__ != "6.12.0", "PySide6 6.12.0 aborts after many disconnects"
    major, minor = (int(v) for v in PySide6.__version__.split(".")[:2])
    assert (major, minor) < (6, 12), f"pyproject pins PySide6 < 6.12, got {PySide6.__version__}"
    assert (major, minor) >= (6, 11)


@pytest.mark.gui
def test_thousand_connect_disconnect_cycles_do_not_abort():
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    r = subprocess.run(
        [sys.executable, "-c", CHILD],
        capture_output=True,
        text=True,
        timeout=180,
        env=env,
    )
    assert r.returncode == 0, f"exit {r.returncode}\nstdout:\n{r.stdout}\nstderr:\n{r.stderr}"
    assert MARKER in r.stdout, r.stdout + r.stderr
