#!/usr/bin/env bash
# Run every benchmark in turn (each rewrites its own section of bench/RESULTS.md).
# Run it on a quiet machine: the timings are wall-clock.
set -euo pipefail
cd "$(dirname "$0")/.."
for b in parse fit sample kerf fill gui; do
  echo "=== bench/run_$b.sh"
  bash "bench/run_$b.sh"
done
