#!/usr/bin/env bash
# End-to-end checks of the front end itself: an unknown command is named; `arco run` on a
# capture without audio says it wrote vision/ only (and did); `arco --check-args` parses
# and checks a command line without running it; errors name the flag the user typed, not
# an options struct's field.
# usage: commands_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$1
export ARCO_SHARED_DATA_DIR=$2
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

out=$("$arco" frobnicate 2>&1); rc=$?
check '[ $rc -eq 1 ] && [ "$(wc -l <<<"$out")" -eq 1 ]' "unknown command: one line, exit 1"
check 'grep -q "^arco: error: unknown command .frobnicate. (commands: .*run.*)" <<<"$out"' \
  "unknown command is named, with the commands"
out=$("$arco" 2>&1); rc=$?
check '[ $rc -eq 1 ]' "no command: exit 1"

"$arco" synth --no-audio --duration-s 1.5 --seed 4 -o "$tmp/cap" > "$tmp/synth.log" 2>&1
check '[ $? -eq 0 ]' "synth without audio"
out=$("$arco" run "$tmp/cap" -o "$tmp/res" 2>&1); rc=$?
check '[ $rc -eq 0 ]' "run without audio exits 0"
check 'grep -q "^total .* (vision/: points3d.npy" <<<"$out"' "run without audio names vision/ only"
check '! grep -q "paper/" <<<"$out"' "run without audio does not claim paper/"
check '[ -d "$tmp/res/vision" ] && [ ! -e "$tmp/res/paper" ] && [ ! -e "$tmp/res/arco" ]' \
  "only vision/ exists"

# `arco --check-args COMMAND ...`: exit 0 and silence for a valid command line, the parse
# error otherwise; nothing read or written either way (the workflow checks a take's
# options so, docs/workflow.md).
out=$("$arco" --check-args run "$tmp/nowhere" -o "$tmp/res2" --min-confidence 0.7 2>&1); rc=$?
check '[ $rc -eq 0 ] && [ -z "$out" ] && [ ! -e "$tmp/res2" ]' "--check-args, valid: exit $rc: $out"
out=$("$arco" --check-args run "$tmp/cap" -o "$tmp/res2" --min-confidence 7 2>&1); rc=$?
check '[ $rc -eq 1 ] && [[ "$out" == "arco: error: --min-confidence: 7 is outside [0.2, 1]"* ]] &&
       [ ! -e "$tmp/res2" ]' "--check-args, out of range: exit $rc: $out"
out=$("$arco" --check-args track "$tmp/cap" --labels a=b.json --no-such-flag 2>&1); rc=$?
check '[ $rc -eq 1 ] && [ "$(wc -l <<<"$out")" -eq 1 ] && grep -q -- "--no-such-flag" <<<"$out"' \
  "--check-args, unknown flag: exit $rc: $out"

# Messages name the flag typed ("last_frame 2 is before first_frame 5" before).
SNAPSHOT_DIR=$tmp
bad "detect --frames reversed" '--frames "5:2": LAST is before FIRST' detect "$tmp/cap" --frames 5:2
bad "overlay --frames reversed" '--frames "9:3": LAST is before FIRST' \
  overlay "$tmp/res" --camera x --frames 9:3 -o "$tmp/x.mp4"
mkdir -p "$tmp/human"
bad "import-spd without a frame range" "give the frame range (--first, --last) or a summary" \
  import-spd --calibration "$tmp/cap/calibration.json" --human "$tmp/human" -o "$tmp/spd"
exit $fail
