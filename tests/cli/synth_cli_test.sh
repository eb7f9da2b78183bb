#!/usr/bin/env bash
# End-to-end checks of `arco synth` and `arco eval`: a short capture is written
# whole and identically for the same seed; eval of truth against itself; bad input
# gives one error line, exit 1 and no output folder.
# usage: synth_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$1
spd=$2/spd
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
# bad_input NAME ARGS...: exit 1, exactly one stderr line starting "arco: error:", no $tmp/bad
bad_input() {
  local name=$1; shift
  "$arco" synth "$@" -o "$tmp/bad" >/dev/null 2>"$tmp/err"
  local rc=$?
  check '[ $rc -eq 1 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] && grep -q "^arco: error:" "$tmp/err" && [ ! -e "$tmp/bad" ]' "$name: $(cat "$tmp/err")"
}

"$arco" synth --calibration "$spd/cello_1113_scale_camera.xml" --duration-s 1.5 --no-audio -o "$tmp/a" >/dev/null 2>&1
check '[ $? -eq 0 ] && [ -f "$tmp/a/capture.json" ] && [ -f "$tmp/a/truth/points3d.npy" ] && [ -f "$tmp/a/truth/contact.csv" ]' "synth writes a capture with truth"
"$arco" synth --calibration "$spd/cello_1113_scale_camera.xml" --duration-s 1.5 --no-audio -o "$tmp/b" --threads 1 >/dev/null 2>&1
check 'cmp -s "$tmp/a/keypoints2d.npy" "$tmp/b/keypoints2d.npy" && cmp -s "$tmp/a/truth/points3d.npy" "$tmp/b/truth/points3d.npy" && cmp -s "$tmp/a/truth/contact.csv" "$tmp/b/truth/contact.csv"' "same seed, same files (any thread count)"
"$arco" synth --calibration "$spd/cello_1113_scale_camera.xml" --duration-s 1.5 --no-audio --seed 3 -o "$tmp/c" >/dev/null 2>&1
check '! cmp -s "$tmp/a/keypoints2d.npy" "$tmp/c/keypoints2d.npy"' "another seed, other detections"
"$arco" synth --calibration "$spd/cello_1113_scale_camera.xml" --duration-s 1.5 --no-audio -o "$tmp/a" >/dev/null 2>"$tmp/err"
check '[ $? -eq 1 ] && grep -q "overwrite" "$tmp/err"' "an existing capture is not replaced without --overwrite"

# Eval of the truth against itself (a result stage holding the truth points).
mkdir -p "$tmp/r/arco"
cp "$tmp/a/truth/points3d.npy" "$tmp/r/arco/points3d.npy"
cp "$tmp/a/truth/contact.csv" "$tmp/r/arco/contact.csv"
echo '{"format": "arco-result", "units": "mm", "stages": {"arco": {"dir": "arco", "files": {"points3d": "points3d.npy", "contact": "contact.csv"}}}}' >"$tmp/r/result.json"
"$arco" eval "$tmp/r" --truth "$tmp/a/truth" -o "$tmp/eval.json" >"$tmp/table"
check '[ $? -eq 0 ] && grep -q "| arco | 0.00 | 0.00 | 0.00 |" "$tmp/table"' "eval of truth against itself gives zeros"
check '/usr/bin/python3 -c "import json,sys; m=json.load(open(sys.argv[1]))[\"methods\"][\"arco\"]; assert m[\"mpjpe_hand_mm\"]==0 and m[\"string_accuracy\"]==1 and m[\"joint_limit_violations\"]==0, m" "$tmp/eval.json"' "eval.json keys"

# Bad input.
bad_input "unknown piece" --piece bolero --calibration "$spd/cello_1113_scale_camera.xml"
check 'grep -q "^arco: error: --piece '"'"'bolero'"'"' is unknown (built-in pieces: scale-2oct, " "$tmp/err"' \
  "unknown piece: the flag is named, not the calibration: $(cat "$tmp/err")"
bad_input "unknown instrument" --instrument lute --calibration "$spd/cello_1113_scale_camera.xml"
check 'grep -qx "arco: error: --instrument '"'"'lute'"'"' is unknown (violin, viola, cello, double_bass)" "$tmp/err"' \
  "unknown instrument: the flag is named, not the calibration: $(cat "$tmp/err")"
bad_input "missing calibration" --calibration "$tmp/none.xml"
/usr/bin/python3 - "$spd/cello_1113_scale_camera.xml" "$tmp/one.xml" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
cams = re.findall(r"<camera [^>]*>.*?</camera>", text, flags=re.S)
for c in cams[1:]:
    text = text.replace(c, "")
open(sys.argv[2], "w").write(text)
PY
bad_input "one-camera calibration" --calibration "$tmp/one.xml"
check 'grep -q "at least 2" "$tmp/err"' "one camera: the error says a capture needs two"
# A MIDI file with F#1 (30), below the cello's C2.
printf 'MThd\x00\x00\x00\x06\x00\x00\x00\x01\x01\xe0MTrk\x00\x00\x00\x16\x00\x90\x30\x50\x83\x60\x80\x30\x00\x00\x90\x1e\x50\x83\x60\x80\x1e\x00\x00\xff\x2f\x00' >"$tmp/low.mid"
bad_input "note below the range" --midi "$tmp/low.mid" --calibration "$spd/cello_1113_scale_camera.xml"
check 'grep -q "note 30 (F#1) at 0.500 s is outside the cello" "$tmp/err"' "the error names the note: $(cat "$tmp/err")"
bad_input "bad option value" --noise-px -1 --calibration "$spd/cello_1113_scale_camera.xml"
"$arco" eval "$tmp/none" --truth "$tmp/a/truth" >/dev/null 2>"$tmp/err"
check '[ $? -eq 1 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ]' "eval of a missing result: one error line"

[ $fail -eq 0 ] && echo "synth CLI: all checks passed"
exit $fail
