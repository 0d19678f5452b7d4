#!/usr/bin/env bash
# Fill and order benchmarks (issue 7): makes bench/.venv-fill (numpy, shapely, numba, vpype, elkai,
# meerk40t if installable) and runs bench/bench_fill.py and bench/bench_order.py.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=bench/.venv-fill
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install -q numpy "shapely>=2.0" "numba>=0.60" vpype elkai
"$VENV/bin/pip" install -q meerk40t || echo "meerk40t is not installable here; compared without it"
echo "## fill"
"$VENV/bin/python" bench/bench_fill.py
echo
echo "## order"
"$VENV/bin/python" bench/bench_order.py
echo
echo "## zig-zag strokes per file (issue 21; compare with --root OLD_CHECKOUT, see the script)"
"$VENV/bin/python" bench/bench_zigzag.py --out bench/out/zigzag.json
echo
echo "## order that stops by itself (issue 21)"
"$VENV/bin/python" bench/bench_order_stop.py
echo
echo "## fill / kerf / order growth on real drawings side by side (issue 21)"
"$VENV/bin/python" bench/bench_scale.py --sizes 100000 1000000
"$VENV/bin/python" bench/bench_scale.py --crossings-only --per-row 1000000 --sizes 100000 1000000
