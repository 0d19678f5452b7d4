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
