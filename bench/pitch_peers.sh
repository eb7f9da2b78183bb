#!/usr/bin/env bash
# Pitch accuracy and speed against Praat and aubiopitch on fluidsynth-rendered
# cello/violin/viola/contrabass music with known truth (see pitch_peers.py).
# usage: bench/pitch_peers.sh [BUILD_DIR] [NOTES] [RUNS] [SEEDS]
set -euo pipefail
build=${1:-build}
cd "$(dirname "$0")/.."
cmake --build "$build" --target arco render_test_music >/dev/null
exec /usr/bin/python3 bench/pitch_peers.py "$build" "${2:-60}" "${3:-3}" "${4:-11,12,13,14,15,16,17,18}"
