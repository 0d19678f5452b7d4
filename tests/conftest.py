"""Shared test setup: Qt always runs offscreen (no display needed, same pixels everywhere).

The platform must be chosen before anything imports Qt, hence at import time here.
"""

import os

os.environ["QT_QPA_PLATFORM"] = "offscreen"
