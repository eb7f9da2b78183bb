#!/usr/bin/env bash
# Runs every benchmark binary of a build (Google Benchmark executables named
# *_bench in BUILD_DIR/bin) and keeps their JSON reports in BUILD_DIR/bench-results.
# usage: bench/run_all.sh BUILD_DIR [extra Google Benchmark flags]
set -euo pipefail
build=${1:-build}
shift || true
cd "$(dirname "$0")/.."
out="$build/bench-results"
mkdir -p "$out"
found=0
for bin in "$build"/bin/*_bench; do
  [ -x "$bin" ] || continue
  found=1
  name=$(basename "$bin")
  echo "== $name"
  "$bin" --benchmark_out="$out/$name.json" --benchmark_out_format=json "$@"
done
if [ "$found" = 0 ]; then
  echo "no benchmark binaries in $build/bin (configure with -DARCO_BUILD_BENCH=ON)" >&2
  exit 1
fi
echo "reports in $out/"
