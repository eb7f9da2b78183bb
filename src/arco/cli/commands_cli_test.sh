#!/usr/bin/env bash
# End-to-end checks of the front end itself: an unknown command is named; `arco run` on a
# capture without audio says it wrote vision/ only (and did).
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
exit $fail
