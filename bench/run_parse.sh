#!/usr/bin/env bash
# Importer benchmark (issue 3 §6): speed of galvo_core.hpgl.read_bytes on a 1,000,000-point
# PLT, and a path-by-path comparison with the ezhpgl package on /work/shared/corpus/plt.
#
#   bash bench/run_parse.sh                 # run everything, rewrite "## Import (issue 3)"
#                                           # in bench/RESULTS.md
#   bash bench/run_parse.sh --corpus-only --examples 3 --no-write   # look at differences
#   bash bench/run_parse.sh --ratios        # issue 20: time and memory ratio to ezhpgl per
#                                           # file, its own section of bench/RESULTS.md
#
# ezhpgl and numpy go into the bench's own environment bench/.venv-peers (gitignored), never
# into the project's .venv; the project is imported from this checkout (sys.path), so both
# parsers run in the same process. EZHPGL_SPEC pins the peer (the explanation in RESULTS.md
# was written against 0.1.0a2). GALVO_PLT_CORPUS overrides the corpus folder.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv-peers"
spec="${EZHPGL_SPEC:-ezhpgl==0.1.0a2}"
py="${PYTHON:-python3}"

if [ ! -x "$venv/bin/python" ]; then
    "$py" -m venv "$venv"
fi
if ! "$venv/bin/python" - "$spec" <<'EOF' 2>/dev/null
import sys
from importlib.metadata import version
import numpy  # noqa: F401
import numba  # noqa: F401  (the importer's compiled scanner)
want = sys.argv[1].partition("==")[2]
sys.exit(0 if (not want or version("ezhpgl") == want) else 1)
EOF
then
    "$venv/bin/pip" install --quiet --disable-pip-version-check --pre "$spec" numpy numba
fi

write=(--write "$here/RESULTS.md")
args=()
for a in "$@"; do
    if [ "$a" = "--no-write" ]; then write=(); else args+=("$a"); fi
done
exec "$venv/bin/python" "$here/bench_parse.py" "${write[@]}" "${args[@]}"
