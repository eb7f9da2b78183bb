# Shared helpers of the command-line tests (tests/cli/*_cli_test.sh), sourced after the
# test has set `arco` (the binary) and made `tmp` (its scratch folder):
#   source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
# A bad input must give exactly one stderr line "arco: error: ...", exit status 1 and
# leave the watched folder (SNAPSHOT_DIR, default: the current folder) exactly as it was:
# no partial output, old outputs intact, no temporaries (docs/architecture.md, "Outputs").
fail=0

# check CONDITION MESSAGE: evaluates CONDITION; prints "FAILED: MESSAGE" when it is false.
check() { if ! eval "$1"; then echo "FAILED: $2"; fail=1; fi; }

# snapshot: every path and every file's checksum below SNAPSHOT_DIR.
snapshot() {
  (cd "${SNAPSHOT_DIR:-.}" && find . | sort && find . -type f -exec md5sum {} + | sort)
}

# ok NAME ARGS...: `arco ARGS` exits 0 (its output in $tmp/out and $tmp/err).
ok() {
  local name=$1; shift
  "$arco" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  check '[ $rc -eq 0 ]' "$name: exit $rc: $(tail -1 "$tmp/err")"
}

# expect_error NAME PATTERN ARGS...: `arco ARGS` exits 1 with one stderr line matching
# "arco: error: PATTERN" (a shell glob: quote literal parts) and changes nothing. The
# line stays in $error_line, for further checks of its words without running arco again.
expect_error() {
  local name=$1 pattern=$2; shift 2
  local before; before=$(snapshot)
  local line; line=$("$arco" "$@" 2>&1 >/dev/null)
  local rc=$?
  error_line=$line
  local one_line=0
  if [ -n "$line" ] && [[ "$line" != *$'\n'* ]]; then one_line=1; fi
  check '[ $rc -eq 1 ] && [ $one_line -eq 1 ] && [[ "$line" == "arco: error: "$pattern ]]' \
    "$name: exit $rc: $line"
  check '[ "$(snapshot)" = "$before" ]' "$name: the folder changed"
}

# glob_literal TEXT: TEXT with the glob characters escaped, to match it literally.
glob_literal() { printf '%s' "$1" | sed 's/[][*?\\]/\\&/g'; }

# bad NAME TEXT ARGS...: expect_error with a line that says TEXT (literally) anywhere.
bad() {
  local name=$1 text; text=$(glob_literal "$2"); shift 2
  expect_error "$name" "*$text*" "$@"
}

# bad_at NAME PATH ARGS...: expect_error with a line that starts "arco: error: PATH: ".
bad_at() {
  local name=$1 path; path=$(glob_literal "$2"); shift 2
  expect_error "$name" "$path: *" "$@"
}

# require_browser SRC [COMMAND...]: the browser tests' prerequisites. Debian's chromium
# (and each COMMAND) absent: the test is skipped (exit 77); node or the npm playwright-core
# that drives chromium (scripts/fetch_view_tools) absent: it fails (exit 1). Sets
# `playwright` to playwright-core's folder.
require_browser() {
  local src=$1 c
  shift
  if [ ! -x /usr/bin/chromium ]; then
    echo "SKIPPED: /usr/bin/chromium is not installed (scripts/setup)"
    exit 77
  fi
  for c in "$@"; do
    if ! command -v "$c" >/dev/null; then
      echo "SKIPPED: $c is not installed (scripts/setup)"
      exit 77
    fi
  done
  playwright=$src/tools/view/node_modules/playwright-core
  if ! command -v node >/dev/null || [ ! -f "$playwright/package.json" ]; then
    echo "FAILED: node or $playwright missing (run scripts/fetch_view_tools)"
    exit 1
  fi
}

# synth_and_run CAP RES DURATION_S: a synthetic capture (`arco synth`) and its result
# (`arco run`); exits the test on failure. Sets `frames`, the result's frame count.
synth_and_run() {
  "$arco" synth -o "$1" --duration-s "$3" >/dev/null 2>&1 &&
    "$arco" run "$1" -o "$2" >/dev/null 2>&1 ||
    { echo "FAILED: synth + run"; exit 1; }
  frames=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['frames']['count'])" \
    "$2/result.json")
}

# give_turned_video CAP CAM FRAMES [FILTER]: camera CAM of capture CAP gets a video of
# FRAMES frames (ffmpeg's testsrc2 at 30 fps, through the ffmpeg filter FILTER if given),
# stored turned as SPD's: the calibration's image is 2300x2656, the file 2656x2300, and
# capture.json's rotate_deg 90 turns it back. Exits the test on failure.
give_turned_video() {
  local cap=$1 cam=$2 count=$3 filter=(); [ $# -ge 4 ] && filter=(-vf "$4")
  ffmpeg -v error -f lavfi -i "testsrc2=size=2656x2300:rate=30" "${filter[@]}" -frames:v "$count" \
    -c:v mpeg4 -q:v 3 "$cap/$cam.mp4" || { echo "FAILED: making the test video"; exit 1; }
  /usr/bin/python3 - "$cap/capture.json" "$cam" <<'PY' || { echo "FAILED: editing capture.json"; exit 1; }
import json, sys
path, cam = sys.argv[1:3]
c = json.load(open(path))
for x in c["cameras"]:
    if x["name"] == cam:
        x["video"] = cam + ".mp4"
        x["rotate_deg"] = 90
json.dump(c, open(path, "w"), indent=1)
PY
}
