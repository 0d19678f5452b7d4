#!/usr/bin/env bash
# GUI latency benchmark (issue 8): slider release -> redrawn views on a 100,000-point file.
set -euo pipefail
cd "$(dirname "$0")/.."
export QT_QPA_PLATFORM=offscreen
exec .venv/bin/python bench/bench_gui.py "$@"
