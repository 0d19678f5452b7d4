#!/usr/bin/env bash
# Marking-point benchmark (issue 5): runs bench/bench_sample.py with the project's .venv and
# writes the "Marking points (issue 5)" section of bench/RESULTS.md. Extra arguments go to
# bench_sample.py (e.g. --quick, or no --write).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/.." && pwd)"
[ -x "$root/.venv/bin/python" ] || bash "$root/scripts/setup.sh"
args=("$@")
[ ${#args[@]} -eq 0 ] && args=(--write)
PYTHONPATH="$root${PYTHONPATH:+:$PYTHONPATH}" exec "$root/.venv/bin/python" "$here/bench_sample.py" "${args[@]}"
