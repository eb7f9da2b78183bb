#!/usr/bin/env bash
# `arco run` opens its capture once and never reads back what it wrote (docs/architecture.md,
# "The pipeline"): traced with strace (openat), each capture file the run reads (capture.json,
# the calibration, keypoints2d.npy) is opened for reading exactly once and the audio at most
# twice (a file too large to hold is streamed by each reader), and no file under the result
# folder, its hidden temporary included (result.json, the stages' arrays), is opened for
# reading at all. On a cello capture and on a violin one with --double-stops. And `arco
# calibrate refine` and `arco calibrate from-instrument` read capture.json and
# keypoints2d.npy once each (the CLI reads the manifest to check the paths and hands it on).
# Needs strace (scripts/setup installs it): without it the test skips (exit 77), and fails
# when CI is set; where ptrace is not allowed (a container without it) it skips.
# usage: run_opens_once_cli_test.sh ARCO_BINARY [SHARED_DATA_DIR]
set -uo pipefail
arco=$(realpath "$1")
[ -n "${2:-}" ] && export ARCO_SHARED_DATA_DIR=$2
if ! command -v strace >/dev/null; then
  echo "strace is missing: run scripts/setup"
  [ -n "${CI:-}" ] && exit 1
  exit 77
fi
if ! strace -f -qq -e trace=openat -o /dev/null true 2>/dev/null; then
  echo "SKIPPED: strace cannot trace here (ptrace not allowed)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
tmp=$(realpath "$tmp")
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
mkdir -p "$tmp/in" "$tmp/out"

# opens TRACE: one line per successful openat for reading of a file (not a folder):
# "PATH" normalised, the calls split by threads (<unfinished ...> / <... resumed>) joined.
opens() {
  /usr/bin/python3 - "$1" <<'PY'
import os, re, sys
pending = {}
for line in open(sys.argv[1]):
    # "PID  call": strace pads the pid to five columns.
    m = re.match(r"(\d+)\s+(.*)", line.rstrip("\n"))
    if not m:
        continue
    pid, rest = m.group(1), m.group(2)
    if rest.endswith("<unfinished ...>"):
        pending[pid] = rest[: -len("<unfinished ...>")]
        continue
    m = re.match(r"<\.\.\. openat resumed>(.*)", rest)
    if m:
        rest = pending.pop(pid, "") + m.group(1)
    m = re.match(r'openat\(AT_FDCWD, "((?:[^"\\]|\\.)*)", ([A-Z_|]+)(?:, \d+)?\)\s*= (-?\d+)', rest)
    if not m:
        continue
    path, flags, rc = m.group(1), m.group(2).split("|"), int(m.group(3))
    if rc < 0 or "O_DIRECTORY" in flags or "O_WRONLY" in flags or "O_RDWR" in flags:
        continue
    print(os.path.normpath(path))
PY
}

# traced_run NAME CAPTURE ARGS...: `arco run CAPTURE -o $tmp/out/NAME ARGS` under strace;
# checks what it opened for reading.
traced_run() {
  local name=$1 cap=$2; shift 2
  local res=$tmp/out/$name trace=$tmp/$name.trace
  strace -f -qq -e trace=openat -o "$trace" "$arco" run "$cap" -o "$res" "$@" \
    >"$tmp/log" 2>&1
  check '[ $? -eq 0 ] && [ -f "$res/arco/points3d.npy" ]' "$name: run: $(tail -1 "$tmp/log")"
  opens "$trace" >"$tmp/$name.opens"
  local f n most
  for f in capture.json calibration.json keypoints2d.npy audio.wav; do
    n=$(grep -cxF "$cap/$f" "$tmp/$name.opens")
    most=1
    [ $f = audio.wav ] && most=2
    check '[ "$n" -ge 1 ] && [ "$n" -le $most ]' \
      "$name: $cap/$f opened for reading $n times (1 to $most expected)"
  done
  # Everything under out/: the result folder and its hidden temporary sibling.
  local read_back
  read_back=$(grep -F "$tmp/out/" "$tmp/$name.opens" | sort | uniq -c)
  check '[ -z "$read_back" ]' "$name: the run read back what it wrote:
$read_back"
}

"$arco" synth --duration-s 2 --seed 3 -o "$tmp/in/cello" >"$tmp/log" 2>&1
check '[ $? -eq 0 ] && [ -f "$tmp/in/cello/audio.wav" ]' "synth cello: $(tail -1 "$tmp/log")"
traced_run cello "$tmp/in/cello" --threads 2

"$arco" synth --piece double-stops --instrument violin --duration-s 2 --seed 3 \
  -o "$tmp/in/violin" >"$tmp/log" 2>&1
check '[ $? -eq 0 ] && [ -f "$tmp/in/violin/audio.wav" ]' "synth violin: $(tail -1 "$tmp/log")"
traced_run violin "$tmp/in/violin" --threads 2 --double-stops
check '[ -f "$tmp/out/violin/double_stops.csv" ]' "violin: no double_stops.csv"

# traced_calibrate NAME CAPTURE FILES ARGS...: `arco calibrate ARGS` under strace; each of
# FILES (names in CAPTURE, space-separated) opened for reading exactly once.
traced_calibrate() {
  local name=$1 cap=$2 files=$3; shift 3
  local trace=$tmp/$name.trace f n
  strace -f -qq -e trace=openat -o "$trace" "$arco" calibrate "$@" >"$tmp/log" 2>&1
  check '[ $? -eq 0 ]' "$name: $(tail -1 "$tmp/log")"
  opens "$trace" >"$tmp/$name.opens"
  for f in $files; do
    n=$(grep -cxF "$cap/$f" "$tmp/$name.opens")
    check '[ "$n" -eq 1 ]' "$name: $cap/$f opened for reading $n times (once expected)"
  done
}
traced_calibrate refine "$tmp/in/cello" "capture.json calibration.json keypoints2d.npy" \
  refine "$tmp/in/cello" -o "$tmp/out/refined.json"
# Two of the SPD rig's cameras without distortion, as calibration_cli_test.sh's from-instrument.
"$arco" calibration show "${ARCO_SHARED_DATA_DIR:-}/spd/cello_1113_scale_camera.xml" --json |
  /usr/bin/python3 -c "
import json, sys
d = json.load(sys.stdin)
d['cameras'] = [d['cameras'][0], d['cameras'][18]]
for c in d['cameras']:
    c['distortion'] = {k: 0 for k in c['distortion']}
json.dump(d, open(sys.argv[1], 'w'))" "$tmp/two.json"
"$arco" synth --calibration "$tmp/two.json" --duration-s 4 -o "$tmp/in/two" >"$tmp/log" 2>&1
check '[ $? -eq 0 ]' "synth two cameras: $(tail -1 "$tmp/log")"
traced_calibrate from-instrument "$tmp/in/two" "capture.json keypoints2d.npy" \
  from-instrument "$tmp/in/two" --image-size 2300x2656 --focal-px 2261.66 --fix-focal \
  --max-frames 30 -o "$tmp/out/fi.json"

exit $fail
