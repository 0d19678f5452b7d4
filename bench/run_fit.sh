#!/usr/bin/env bash
# Thin, fit and precision benchmarks (issues 4 and 16): one command, creates what it needs.
#   bash bench/run_fit.sh          -> bench/out/{thin,fit,precision_em1000,precision_peers}.json
#                                     and the tables printed (thin, fit, precision, precision
#                                     speed, peers on the typefaces and the corpus)
#   FIT_STAGES="precision peers" bash bench/run_fit.sh   -> only those stages
#   FIT_STAGES=peers-ours bash bench/run_fit.sh   -> ours re-run beside the stored peer rows
#                                     (bench/precision_peers_s6.json; PEERS_JSON to name others)
# Stages: thin fit precision speed peers (peers-ours: only on request).
# Peers: fit-curve and paper (npm, versions pinned in bench/js/package.json, into
# bench/node_modules, gitignored); Debian packages potrace, python3-fontforge, inkscape and
# the DejaVu fonts (fonts-dejavu-core, fonts-dejavu-extra), installed with apt-get when
# missing and run as root (bench only: never project dependencies); fontTools (the project's
# "bench" extra) into the Python used here when it is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-.venv/bin/python}
[ -x "$PY" ] || PY=python3
STAGES=${FIT_STAGES:-thin fit precision speed peers}
has() { case " $STAGES " in *" $1 "*) return 0 ;; *) return 1 ;; esac; }
mkdir -p bench/out
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}"

if has thin || has fit || has peers; then
  if [ ! -d bench/node_modules/fit-curve ] || [ ! -d bench/node_modules/paper ]; then
    npm install --prefix bench --no-save --no-audit --no-fund \
      "fit-curve@$(node -p "require('./bench/js/package.json').dependencies['fit-curve']")" \
      "paper@$(node -p "require('./bench/js/package.json').dependencies.paper")"
  fi
fi
if has precision || has peers || has peers-ours; then
  "$PY" -c "import fontTools" 2>/dev/null || "$PY" -m pip install -q "fontTools>=4.40"
  need=()
  [ -f /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ] || need+=(fonts-dejavu-core)
  [ -f /usr/share/fonts/truetype/dejavu/DejaVuSans-ExtraLight.ttf ] || need+=(fonts-dejavu-extra)
  if has peers || has peers-ours; then  # the held-out typefaces of the stored peer rows
    [ -f /usr/share/fonts/truetype/inconsolata/Inconsolata.otf ] || need+=(fonts-inconsolata)
    [ -f /usr/share/fonts/opentype/cantarell/Cantarell-Regular.otf ] || need+=(fonts-cantarell)
  fi
  if has peers; then
    command -v potrace >/dev/null || need+=(potrace)
    /usr/bin/python3 -c "import fontforge" 2>/dev/null || need+=(python3-fontforge)
    command -v inkscape >/dev/null || need+=(inkscape)
  fi
  if [ ${#need[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ]; then
      apt-get update -qq
      DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${need[@]}"
    else
      echo "missing Debian packages (install as root): ${need[*]}" >&2
      exit 1
    fi
  fi
fi

echo "date: $(date -u '+%F %H:%M UTC')  nproc: $(nproc)  load: $(cut -d' ' -f1-3 /proc/loadavg)  cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
"$PY" -c "import sys, numpy, shapely; print('python', sys.version.split()[0], 'numpy', numpy.__version__, 'shapely', shapely.__version__)"
echo "node $(node --version)"
if has thin; then "$PY" bench/bench_thin.py --json bench/out/thin.json; fi
if has fit; then "$PY" bench/bench_fit.py --json bench/out/fit.json; fi
if has precision; then "$PY" bench/bench_precision.py --json bench/out/precision_em1000.json; fi
if has speed; then "$PY" bench/bench_precision_speed.py --reps 3; fi
if has peers; then
  echo "potrace $(potrace --version | head -1 | cut -d' ' -f2)  fontforge $(/usr/bin/python3 -c 'import fontforge; print(fontforge.version())' 2>/dev/null)  $(inkscape --version 2>/dev/null | head -1 | cut -d' ' -f1-2)"
  "$PY" bench/bench_precision_peers.py --corpus --json bench/out/precision_peers.json "$@"
fi
if has peers-ours; then
  # only ours re-run; the peers' rows (typefaces and corpus) read from the stored runs
  # shellcheck disable=SC2086
  "$PY" bench/bench_precision_peers.py --ours-only \
    --peers-json ${PEERS_JSON:-bench/precision_peers_s6.json} \
    --json bench/out/precision_peers_ours.json "$@"
fi
