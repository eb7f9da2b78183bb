#!/usr/bin/env bash
# Results are tied to what made them (docs/architecture.md, "Results are tied to their
# inputs"). Every command that reads a result with its capture (eval, export, plot, view,
# overlay, calibrate check, refine), given a result whose capture changed since it was
# made, in each way it can change (capture.json, the calibration, keypoints2d.npy, the
# audio, one of them gone, the whole capture replaced by `synth --overwrite`), is refused
# with one line "arco: error: FILE changed since the result RESULT was made (re-run `arco
# run`)", exit status 1, and nothing written or changed (cli_test_lib.sh's snapshot). A
# result of an older arco (no fingerprints) is read as before. Re-running a stage
# (`arco triangulate` into a full result) removes the later stages and names them;
# `arco run --overwrite` makes the result whole again.
# usage: results_tied_cli_test.sh ARCO_BINARY [SHARED_DATA_DIR]
set -uo pipefail
arco=$(realpath "$1")
[ -n "${2:-}" ] && export ARCO_SHARED_DATA_DIR=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
w=$tmp/w
SNAPSHOT_DIR=$w
mkdir -p "$tmp/pristine"

"$arco" synth --duration-s 1 --seed 3 -o "$tmp/pristine/cap" >"$tmp/log" 2>&1
check '[ $? -eq 0 ] && [ -f "$tmp/pristine/cap/audio.wav" ]' "synth: $(tail -1 "$tmp/log")"
# Given relative, the capture is recorded relative ("../cap"): copies of the pair stay a pair.
(cd "$tmp/pristine" && "$arco" run cap -o res --threads 2) >"$tmp/log" 2>&1
check '[ $? -eq 0 ] && [ -d "$tmp/pristine/res/arco" ]' "run: $(tail -1 "$tmp/log")"
check 'grep -q "\"capture\": \"../cap\"" "$tmp/pristine/res/result.json"' "the result names ../cap"
camera=$(/usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["cameras"][0]["name"])' \
  "$tmp/pristine/cap/capture.json")

# fresh: $w holds a copy of the capture and its result (the result names ../cap).
fresh() { rm -rf "$w"; cp -r "$tmp/pristine" "$w"; }

# The readers, each with its outputs inside $w (the snapshot sees anything written).
readers=(eval export plot view overlay "calibrate check" refine)
read_result() {
  case $1 in
    eval) "$arco" eval "$w/res" --truth "$w/cap/truth" -o "$w/e.json" ;;
    export) "$arco" export "$w/res" --format csv --method arco -o "$w/x.csv" ;;
    plot) "$arco" plot "$w/res" -o "$w/plots" ;;
    view) "$arco" view "$w/res" --no-serve -o "$w/page" --no-cache ;;
    overlay) "$arco" overlay "$w/res" --method arco --camera "$camera" --frames 1:3 --scale 0.1 \
      -o "$w/o.mkv" ;;
    "calibrate check") "$arco" calibrate check "$w/res" ;;
    refine) "$arco" refine "$w/res" --mode arco ;;
  esac
}

# refused NAME FILE: every reader refuses the result, naming FILE (under $w/cap).
refused() {
  local name=$1 file=$2 reader
  for reader in "${readers[@]}"; do
    local before; before=$(snapshot)
    local line; line=$(read_result "$reader" 2>&1 >/dev/null)
    local rc=$?
    local expected="arco: error: $w/cap/$file changed since the result $w/res was made (${3:-}re-run \`arco run\`)"
    check '[ $rc -eq 1 ] && [ "$line" = "$expected" ]' \
      "$reader, $name: exit $rc: $line (expected: $expected)"
    check '[ "$(snapshot)" = "$before" ]' "$reader, $name: the folder changed"
  done
}

# Each reader reads the untouched result (so that a refusal below is the change's).
fresh
for reader in "${readers[@]}"; do
  read_result "$reader" >"$tmp/out" 2>"$tmp/err"
  check '[ $? -eq 0 ]' "$reader on the untouched result: $(tail -1 "$tmp/err")"
done

# edit FILE PYTHON: rewrites $w/cap/FILE's bytes `b` (a bytearray) with PYTHON.
edit() {
  /usr/bin/python3 - "$w/cap/$1" "$2" <<'EOF'
import sys
path, code = sys.argv[1], sys.argv[2]
b = bytearray(open(path, "rb").read())
exec(code)
open(path, "wb").write(bytes(b))
EOF
}

# The manifest: the audio offset moved by a millisecond (what `arco sync --capture` does).
fresh
/usr/bin/python3 - "$w/cap/capture.json" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
j["audio"]["offset_s"] += 0.001
json.dump(j, open(sys.argv[1], "w"), indent=2)
EOF
refused "capture.json edited" capture.json
# The calibration: one digit of the first camera (same size).
fresh
edit calibration.json 'i = b.index(b"1"); b[i] = ord("2")'
refused "calibration edited" calibration.json
# The 2D keypoints: the last byte of the array (a re-detection).
fresh
edit keypoints2d.npy 'b[-1] ^= 1'
refused "keypoints2d.npy changed" keypoints2d.npy
# The audio: one sample byte in the middle (a re-recorded or re-cut take).
fresh
edit audio.wav 'b[len(b) // 2] ^= 1'
refused "audio changed" audio.wav
# A file gone.
fresh
rm "$w/cap/audio.wav"
refused "audio gone" audio.wav "it is gone; "
# The whole capture replaced (another seed): its manifest is named first.
fresh
"$arco" synth --duration-s 1 --seed 4 -o "$w/cap" --overwrite >"$tmp/log" 2>&1
check '[ $? -eq 0 ]' "synth --overwrite: $(tail -1 "$tmp/log")"
refused "capture replaced" capture.json
cp -r "$w/cap" "$tmp/replaced"  # the replaced capture, for the re-run below

# A result of an older arco (no "inputs" anywhere) is read as before, even over a changed
# capture: there is nothing to compare.
fresh
/usr/bin/python3 - "$w/res/result.json" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
j.pop("inputs")
for stage in j["stages"].values():
    stage.pop("inputs", None)
json.dump(j, open(sys.argv[1], "w"), indent=2)
EOF
edit calibration.json 'i = b.index(b"1"); b[i] = ord("2")'
ok "export of a result without fingerprints" export "$w/res" --format csv --method arco -o "$w/x.csv"

# Re-running the first stage into the full result, after the capture changed: it is the
# writer, so it runs; the stages made from the old triangulation go, and are named.
fresh
rm -rf "$w/cap" && cp -r "$tmp/replaced" "$w/cap"
"$arco" triangulate "$w/cap" -o "$w/res" >"$tmp/out" 2>"$tmp/err"
check '[ $? -eq 0 ]' "triangulate into the result: $(cat "$tmp/err")"
check 'grep -q "^removed the later stages made from the old triangulation: instrument, hand, pitch, arco, paper, vision (arco run redoes them)$" "$tmp/out"' \
  "triangulate names the removed stages: $(cat "$tmp/out")"
check '[ "$(ls "$w/res")" = "$(printf "result.json\ntriangulation")" ]' \
  "stale stages left: $(ls "$w/res")"
check '/usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
assert list(j[\"stages\"]) == [\"triangulation\"], j[\"stages\"].keys()
assert j[\"removed_stages\"] == [\"instrument\", \"hand\", \"pitch\", \"arco\", \"paper\", \"vision\"], j[\"removed_stages\"]
assert sorted(j[\"inputs\"]) == [\"calibration\", \"capture.json\", \"keypoints2d\"], j[\"inputs\"]
assert \"options\" not in j
" "$w/res/result.json"' "result.json after triangulate: $(head -c 600 "$w/res/result.json")"
# What needs the removed stages says so; the triangulation itself reads (the new capture).
expect_error "refine after the stages went" "$w/res/result.json: no hand stage*" refine "$w/res"
ok "calibrate check of the new triangulation" calibrate check "$w/res"
# `arco run --overwrite` makes it whole again, tied to the new capture.
ok "run --overwrite" run "$w/cap" -o "$w/res" --overwrite --threads 2
ok "export after run --overwrite" export "$w/res" --format csv --method arco -o "$w/x.csv"
check '! grep -q removed_stages "$w/res/result.json"' "run --overwrite left removed_stages"

[ $fail -eq 0 ] && echo "results_tied_cli_test: all passed"
exit $fail
