#!/usr/bin/env bash
# Kerf compensation benchmark (issue 6): makes bench/.venv-kerf (numpy, shapely, numba, hypothesis,
# clipper2-py: the Clipper2 peer, bench-only) and writes the "Kerf (issue 6)" section of
# bench/RESULTS.md. Extra arguments go to bench_kerf.py (e.g. --quick, or no --write).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/.venv-kerf"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check \
    "numpy>=1.26" "shapely>=2.0" "numba>=0.60" "hypothesis>=6.100" "clipper2-py>=0.1.1"
args=("$@")
[ ${#args[@]} -eq 0 ] && args=(--write)
PYTHONPATH="$here/..${PYTHONPATH:+:$PYTHONPATH}" exec "$venv/bin/python" "$here/bench_kerf.py" "${args[@]}"
