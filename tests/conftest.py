"""Shared test setup: Qt always runs offscreen (no display needed, same pixels everywhere),
and the workstation keeps its settings in a throw-away INI file, never the user's.

Both must be chosen before anything imports Qt, hence at import time here.
"""

import os
import tempfile

os.environ["QT_QPA_PLATFORM"] = "offscreen"
os.environ["GALVO_WORKSTATION_SETTINGS"] = os.path.join(
    tempfile.mkdtemp(prefix="galvo-test-settings-"), "settings.ini"
)

# Property tests explore new random cases on a developer's machine; on CI they replay the
# same derandomized cases every run, so a run's verdict depends on the code alone (a case
# found once is kept as an @example in the test).
from hypothesis import settings  # noqa: E402

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


import pytest  # noqa: E402


@pytest.fixture(autouse=True)
def _own_settings_file(tmp_path_factory, monkeypatch):
    """Each test starts from no saved settings: what one test leaves in the workstation's
    settings (a hidden layer, a parameter) must not reach the next one."""
    path = tmp_path_factory.mktemp("settings") / "settings.ini"
    monkeypatch.setenv("GALVO_WORKSTATION_SETTINGS", str(path))


@pytest.fixture
def dialogs(monkeypatch):
    """The message boxes a GUI test's window opens, answered OK at once (Qt's modal exec
    would block an offscreen test): the list of boxes shown, for the test to read."""
    from PySide6.QtWidgets import QMessageBox

    boxes: list = []

    def fake_exec(box):
        boxes.append(box)
        return int(QMessageBox.StandardButton.Ok)

    monkeypatch.setattr(QMessageBox, "exec", fake_exec)
    return boxes
