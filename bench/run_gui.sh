#!/usr/bin/env bash
# GUI benchmark (issue 18): control change -> redrawn views on a generated 150k-point file and
# the three largest corpus files; GUI-thread stalls while a 1M-point file opens, processes,
# exports and loads back; memory over ten big files opened in a row. Prints the tables of
# bench/RESULTS.md, "GUI (issue 18)".
set -euo pipefail
cd "$(dirname "$0")/.."
export QT_QPA_PLATFORM=offscreen
C=../shared/corpus/plt
FILES=()
for f in schwittlick__hpgl-viewer__composition100_mutoh_xp500_a1.hpgl \
         straight-coding__gcode-hpgl-viewer__s_fabric_nesting.plt \
         straight-coding__gcode-hpgl-viewer__b_fabric_nesting.plt; do
  [ -f "$C/$f" ] && FILES+=("$C/$f")
done
TMP=$(mktemp -d)
.venv/bin/python bench/gen_plt.py 150000 "$TMP/gen_150k.plt"
.venv/bin/python bench/bench_gui.py latency "$TMP/gen_150k.plt" "${FILES[@]}" "$@"
.venv/bin/python bench/bench_gui.py stalls --points 1000000 --opens 5
for f in "${FILES[@]}"; do .venv/bin/python bench/bench_gui.py stalls --file "$f" --opens 5; done
B="$C/straight-coding__gcode-hpgl-viewer__b_fabric_nesting.plt"
for s in 1 2 3; do .venv/bin/python bench/gen_plt.py 400000 "$TMP/g400k_$s.plt" "$s"; done
.venv/bin/python bench/gen_plt.py 1000000 "$TMP/g1m.plt"
MEM=("$TMP/g400k_1.plt" "$TMP/g400k_2.plt" "$TMP/g400k_3.plt")
[ -f "$B" ] && MEM+=("$B")
.venv/bin/python bench/bench_gui.py memory "${MEM[@]}" "$TMP/g1m.plt" --opens 10
rm -rf "$TMP"
