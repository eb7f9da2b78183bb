#!/usr/bin/env bash
# `arco plot` (docs/export.md, "Plots") on a synthetic result, checked by an independent
# reader (plot_check.py: xml.etree, numpy and Debian's ffmpeg CLI): every figure as SVG and
# PNG, the PNG of the asked size and not blank, the SVG valid XML with one mark per note
# carrying its name, each mark at its note's time and pitch (and its place on the
# fingerboard) within a pixel; the error figure only when the capture has a truth folder.
# Bad input (a method without fingering, an unknown method, an existing folder that is
# not a plot folder, a plot folder without --overwrite, an output under a file): one line
# "arco: error: ...", exit 1, nothing written.
# Without ffmpeg the test skips (exit 77) unless CI is set, where it fails.
# usage: plot_cli_test.sh ARCO_BINARY SOURCE_DIR
set -uo pipefail
arco=$1
src=$2
py=/usr/bin/python3
check_py=$src/tests/cli/plot_check.py
if ! command -v ffmpeg >/dev/null; then
  echo "ffmpeg not installed (scripts/setup installs it)"
  [ -n "${CI:-}" ] && exit 1
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
SNAPSHOT_DIR=$tmp/w

synth_and_run "$tmp/cap" "$tmp/res" 3
mkdir -p "$tmp/w"

check '"$arco" plot "$tmp/res" -o "$tmp/w/plots" >"$tmp/out"' "plot: $(cat "$tmp/out" 2>/dev/null)"
grep -q "errors against the truth" "$tmp/out" || { echo "FAILED: no error figure"; fail=1; }
check '"$py" "$check_py" "$tmp/w/plots" "$tmp/res" arco 1200 600 1' "arco's figures"
check '"$arco" plot "$tmp/res" -o "$tmp/again" >/dev/null && diff -r "$tmp/w/plots" "$tmp/again" >/dev/null' \
  "a second run gives the same files"
check '"$arco" plot "$tmp/res" --method paper --width 900 --height 500 -o "$tmp/w/paper" >/dev/null' \
  "plot paper"
check '"$py" "$check_py" "$tmp/w/paper" "$tmp/res" paper 900 500 1' "paper's figures, 900x500"
check '"$arco" plot "$tmp/res" --overwrite -o "$tmp/w/paper" >/dev/null' "plot --overwrite"
check '"$py" "$check_py" "$tmp/w/paper" "$tmp/res" arco 1200 600 1' "replaced figures"
# Without the truth folder: no error figure.
mv "$tmp/cap/truth" "$tmp/truth"
check '"$arco" plot "$tmp/res" -o "$tmp/w/notruth" >/dev/null' "plot without truth"
check '"$py" "$check_py" "$tmp/w/notruth" "$tmp/res" arco 1200 600 0' "figures without truth"
mv "$tmp/truth" "$tmp/cap/truth"

mkdir -p "$tmp/w/mine" && echo "keep" >"$tmp/w/mine/notes.txt"
expect_error "a method without fingering" "$tmp/res/vision/fingering.csv: no notes *" \
  plot "$tmp/res" --method vision -o "$tmp/w/x"
expect_error "unknown method" "--method: 'truth' is not arco, paper or vision" \
  plot "$tmp/res" --method truth -o "$tmp/w/x"
expect_error "an existing plot folder" "*--overwrite*" plot "$tmp/res" -o "$tmp/w/plots"
expect_error "a folder that is not a plot folder" "*" plot "$tmp/res" --overwrite -o "$tmp/w/mine"
expect_error "output under a file" "*" plot "$tmp/res" -o "$tmp/w/mine/notes.txt/x"
expect_error "no result folder" "$tmp/none/result.json: *" plot "$tmp/none" -o "$tmp/w/x"

[ $fail -eq 0 ] && echo "plot_cli_test: ok"
exit $fail
