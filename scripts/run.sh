#!/usr/bin/env bash
# Set up and open the workstation on a bundled sample. Where there is no display, render
# the window offscreen to a PNG instead and say where it is.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
sample=${1:-resources/samples/seal.plt}
if [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ] && [ "${QT_QPA_PLATFORM:-}" != "offscreen" ]; then
  out=${SCREENSHOT:-screenshot.png}
  QT_QPA_PLATFORM=offscreen .venv/bin/galvo-workstation "$sample" --screenshot "$out" --size 1400x800
  echo "no display: rendered the workstation on $sample offscreen to $(pwd)/$out"
else
  exec .venv/bin/galvo-workstation "$sample"
fi
