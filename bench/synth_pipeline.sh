#!/usr/bin/env bash
# Synthesis + pipeline time per minute of performance, stage by stage, through the
# CLI: arco synth (with fluidsynth audio and sample tuning), arco triangulate (or
# arco run once it exists), arco pitch, arco eval. Prints wall and CPU seconds per
# stage, scaled to one minute of performance.
#   bench/synth_pipeline.sh [BUILD_DIR] [THREADS]
set -euo pipefail
build=${1:-build}
threads=${2:-0}
cd "$(dirname "$0")/.."
arco="$build/bin/arco"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tempo=$(/usr/bin/python3 -c "print(60.0 / 16.27)")  # the 16.27 s scale stretched to 60 s
stage() {  # name, command...
  local name=$1; shift
  /usr/bin/time -f "%e %U %S" -o "$work/time" "$@" >"$work/$name.log" 2>&1 || { cat "$work/$name.log"; exit 1; }
  read -r wall user sys <"$work/time"
  printf "| %s | %.2f | %.2f |\n" "$name" "$wall" "$(echo "$user + $sys" | bc)"
}
echo "| stage | wall s per minute | CPU s per minute |"
echo "|---|---|---|"
stage synth "$arco" synth -o "$work/capture" --tempo-scale "$tempo" --threads "$threads"
if "$arco" --help | grep -qE "^  run "; then
  stage run "$arco" run "$work/capture" -o "$work/result"
else
  stage triangulate "$arco" triangulate "$work/capture" -o "$work/result" --threads "$threads"
fi
[ -f "$work/result/pitch.csv" ] || stage pitch "$arco" pitch "$work/capture/audio.wav" --instrument cello --fps 30 -o "$work/result/pitch.csv"
stage eval "$arco" eval "$work/result" --truth "$work/capture/truth" -o "$work/eval.json"
grep -m1 "performance" "$work/synth.log" | sed 's/^ */synth: /'
