#!/usr/bin/env bash
# Runs every benchmark executable of a build folder (default: build).
set -euo pipefail
build="${1:-build}"
status=0
for exe in "$build"/bench/*; do
  [ -f "$exe" ] && [ -x "$exe" ] || continue
  echo "== $(basename "$exe")"
  "$exe" --benchmark_min_time=0.5 || status=1
done
exit $status
