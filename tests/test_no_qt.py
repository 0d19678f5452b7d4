"""galvo_core is the computation: importing every one of its modules loads no Qt."""

import subprocess
import sys

CODE = r"""
import importlib, pkgutil, sys
import galvo_core
names = ['galvo_core'] + [m.name for m in pkgutil.walk_packages(galvo_core.__path__, 'galvo_core.')]
for n in names:
    importlib.import_module(n)
QT = ('PySide6', 'PyQt5', 'PyQt6', 'PySide2', 'pyqtgraph', 'shiboken6')
bad = sorted(m for m in sys.modules if m.split('.')[0] in QT)
print(len(names), 'modules')
assert not bad, bad
"""


def test_importing_every_galvo_core_module_loads_no_qt():
    r = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    n = int(r.stdout.split()[0])
    assert n >= 15  # the walk really found the package's modules
