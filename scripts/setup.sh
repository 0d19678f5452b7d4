#!/usr/bin/env bash
# Create (or refresh) the project-local virtual environment .venv with everything the
# workstation, its tests and its checks need. Safe to run again: it only reinstalls when
# pyproject.toml changed.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
if ! "$PY" -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; then
  echo "error: Python >= 3.11 is needed (found: $("$PY" --version 2>&1))" >&2
  exit 2
fi
if [ ! -x .venv/bin/python ]; then
  echo "setting up .venv ..." >&2
  "$PY" -m venv .venv
fi
stamp=.venv/.installed-$(sha256sum pyproject.toml | cut -c1-16)
if [ ! -f "$stamp" ]; then
  .venv/bin/python -m pip install --quiet --upgrade pip >&2
  .venv/bin/python -m pip install --quiet -e ".[test,dev]" >&2
  rm -f .venv/.installed-*
  touch "$stamp"
fi
# build the compiled kernels (numba, cached in galvo_core/__pycache__) now rather than on the
# first fit; a no-op when the cache is current
.venv/bin/python -c "from galvo_core.fit import warm_up; warm_up()" >&2
