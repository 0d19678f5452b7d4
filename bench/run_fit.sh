#!/usr/bin/env bash
# Thin and fit benchmark (issue 4): one command, creates what it needs.
#   bash bench/run_fit.sh          -> bench/out/thin.json, bench/out/fit.json, printed tables
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-.venv/bin/python}
[ -x "$PY" ] || PY=python3
mkdir -p bench/out
# peers (versions pinned in bench/js/package.json) into bench/node_modules (gitignored)
if [ ! -d bench/node_modules/fit-curve ] || [ ! -d bench/node_modules/paper ]; then
  npm install --prefix bench --no-save --no-audit --no-fund \
    "fit-curve@$(node -p "require('./bench/js/package.json').dependencies['fit-curve']")" \
    "paper@$(node -p "require('./bench/js/package.json').dependencies.paper")"
fi
echo "date: $(date -u +%F)  nproc: $(nproc)  cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
"$PY" -c "import sys, numpy, shapely; print('python', sys.version.split()[0], 'numpy', numpy.__version__, 'shapely', shapely.__version__)"
echo "node $(node --version)"
"$PY" bench/bench_thin.py --json bench/out/thin.json
"$PY" bench/bench_fit.py --json bench/out/fit.json
