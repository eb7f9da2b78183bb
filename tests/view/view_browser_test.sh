#!/usr/bin/env bash
# `arco view` in a real browser: view_browser_test.js on a synthetic result (arco synth +
# arco run) and on a copy missing its arco stage. Skips (77) only when Debian's
# /usr/bin/chromium is absent; a missing node or playwright-core (scripts/fetch_view_tools)
# is a failure. Screenshots stay in WORK_DIR as the test's artefacts.
# usage: view_browser_test.sh ARCO_BINARY SOURCE_DIR WORK_DIR
set -uo pipefail
arco=$1
src=$2
work=$3
rm -rf "$work"
# Bad input, without a browser: one line "arco: error: ...", exit 1, nothing written.
mkdir -p "$work"
source "$src/tests/cli/cli_test_lib.sh"
SNAPSHOT_DIR=$work
mkdir -p "$work/not_a_result"
expect_error "no result.json" "*not_a_result/result.json: not found (not an arco result folder)" \
  view "$work/not_a_result" --no-serve -o "$work/out"
expect_error "--no-serve without -o" "*--no-serve needs -o DIR*" view "$work/not_a_result" --no-serve
expect_error "-o without --no-serve" "*-o is for --no-serve*" view "$work/not_a_result" -o "$work/out"
expect_error "port out of range" "*--port*" view "$work/not_a_result" --port 70000
[ $fail -eq 0 ] || exit 1

require_browser "$src"
"$arco" synth -o "$work/cap" --duration-s 3 >/dev/null 2>&1 &&
  "$arco" run "$work/cap" -o "$work/res" >/dev/null 2>&1 ||
  { echo "FAILED: synth + run"; exit 1; }
# The same result without its arco stage (result.json's entry and the folder).
cp -r "$work/res" "$work/res_no_arco"
rm -rf "$work/res_no_arco/arco"
/usr/bin/python3 - "$work/res_no_arco/result.json" <<'PY' || { echo "FAILED: editing result.json"; exit 1; }
import json, sys
d = json.load(open(sys.argv[1]))
del d["stages"]["arco"]
json.dump(d, open(sys.argv[1], "w"), indent=1)
PY
node "$src/tests/view/view_browser_test.js" "$arco" "$work/res" "$work/res_no_arco" \
  "$work/shots" "$playwright"
