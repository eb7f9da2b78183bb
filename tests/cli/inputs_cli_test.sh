#!/usr/bin/env bash
# Fail early (docs/architecture.md, "Validation rules"): every defect of a capture's
# inputs is one line "arco: error: FILE: ..." naming the file and the field, a non-zero
# exit, no output (and no temporary) left behind, on every command that reads that input:
# arco run (before its first stage: no stage progress line), arco triangulate,
# arco calibrate check, arco calibrate refine,
# arco pitch --capture and arco sync --capture. Also: a truncated WAV is a warning naming
# the file; a capture whose audio starts late is still run.
# usage: inputs_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$(realpath "$1")
export ARCO_SHARED_DATA_DIR=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"

"$arco" synth --duration-s 1 --seed 5 -o "$tmp/good" >"$tmp/synth.log" 2>&1
rc=$?
check '[ $rc -eq 0 ]' "synth the good capture: $(tail -1 "$tmp/synth.log")"
rm -rf "$tmp/good/truth"

# defect NAME: a copy of the good capture in $tmp/NAME, edited by the commands that follow.
defect() { rm -rf "$tmp/$1"; cp -r "$tmp/good" "$tmp/$1"; }
# json NAME PYTHON: edits $tmp/NAME/capture.json as the dict `j` (text edits with sed).
json() {
  /usr/bin/python3 - "$tmp/$1/capture.json" "$2" <<'EOF'
import json, sys
path, code = sys.argv[1], sys.argv[2]
j = json.load(open(path))
exec(code)
json.dump(j, open(path, "w"), indent=2)
EOF
}
# npy NAME DESCR FRAMES: rewrites keypoints2d.npy with another dtype and/or frame count
# (0: the same).
npy() {
  /usr/bin/python3 - "$tmp/$1/keypoints2d.npy" "$2" "$3" <<'EOF'
import ast, math, struct, sys
path, descr, frames = sys.argv[1], sys.argv[2], int(sys.argv[3])
raw = open(path, "rb").read()
n = raw[8] | raw[9] << 8
header = ast.literal_eval(raw[10:10 + n].decode())
frames = frames if frames > 0 else header["shape"][0]
count = 1
for d in header["shape"]:
    count *= d
values = struct.unpack("<%df" % count, raw[10 + n:10 + n + 4 * count])
shape = (frames,) + tuple(header["shape"][1:])
keep = frames * count // header["shape"][0]
values = (values * 2)[:keep]
if descr == "<i4":
    data = struct.pack("<%di" % keep, *[0 if math.isnan(v) else int(v) for v in values])
else:
    data = struct.pack("<%df" % keep, *values)
d = "{'descr': '%s', 'fortran_order': False, 'shape': %r, }" % (descr, shape)
d += " " * ((64 - (10 + len(d) + 1) % 64) % 64) + "\n"
open(path, "wb").write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(d)) + d.encode() + data)
EOF
}

# bad NAME FILE WORDS ARGS...: exit non-zero, exactly one stderr line starting
# "arco: error: FILE" and holding WORDS, nothing new in $tmp/out (outputs go there).
bad() {
  local name=$1 file=$2 words=$3; shift 3
  rm -rf "$tmp/out"; mkdir -p "$tmp/out"
  "$arco" "$@" >"$tmp/stdout" 2>"$tmp/err"
  local rc=$?
  local line; line=$(cat "$tmp/err")
  check '[ $rc -ne 0 ]' "$name: exit $rc"
  check '[ "$(wc -l <"$tmp/err")" -eq 1 ]' "$name: not one stderr line: $line"
  check '[[ "$line" == "arco: error: $file"* ]]' "$name: does not start with $file: $line"
  check '[[ "$line" == *"$words"* ]]' "$name: does not say '$words': $line"
  check '[[ "$line" != *"--"* ]]' "$name: names a flag not given: $line"
  check '[ -z "$(ls -A "$tmp/out")" ]' "$name: left $(ls -A "$tmp/out" | head -3)"
}
# run_bad NAME FILE WORDS: `arco run` fails before its first stage.
run_bad() {
  bad "run: $1" "$2" "$3" run "$tmp/$1" -o "$tmp/out/result"
  check '! grep -q "triangulate" "$tmp/stdout" "$tmp/err"' "run: $1: a stage started"
}
# tri_bad / pitch_bad / sync_bad: the same input on the other commands that read it.
tri_bad() { bad "triangulate: $1" "$2" "$3" triangulate "$tmp/$1" -o "$tmp/out/tri"; }
pitch_bad() { bad "pitch: $1" "$2" "$3" pitch --capture "$tmp/$1" -o "$tmp/out/p.csv"; }
sync_bad() {
  bad "sync: $1" "$2" "$3" sync "$tmp/good/audio.wav" --video "$tmp/good/audio.wav" \
    --capture "$tmp/$1"
}
check_bad() { bad "calibrate check: $1" "$2" "$3" calibrate check "$tmp/$1"; }
refine_bad() { bad "calibrate refine: $1" "$2" "$3" calibrate refine "$tmp/$1" -o "$tmp/out/r.json"; }
# every NAME FILE WORDS: the manifest defect on every command reading capture.json.
every() {
  run_bad "$@"; tri_bad "$@"; pitch_bad "$@"; sync_bad "$@"; check_bad "$@"; refine_bad "$@"
}

M=capture.json
# capture.json fields: the file and the field, never a flag.
for v in NaN Infinity -Infinity; do
  defect fps_$v; sed -i "s/\"fps\": [0-9.]*/\"fps\": $v/" "$tmp/fps_$v/$M"
  every fps_$v "$tmp/fps_$v/$M" "\"fps\" is $v; must be a finite number"
done
defect fps_neg; json fps_neg 'j["fps"] = -30'
every fps_neg "$tmp/fps_neg/$M" '"fps" is -30; must be in (0, 10000]'
defect fps_zero; json fps_zero 'j["fps"] = 0'
every fps_zero "$tmp/fps_zero/$M" '"fps" is 0; must be in (0, 10000]'
defect fps_str; json fps_str 'j["fps"] = "30"'
every fps_str "$tmp/fps_str/$M" '"fps" is "30"; must be a number'
defect first_neg; json first_neg 'j["frames"]["first"] = -5'
every first_neg "$tmp/first_neg/$M" '"frames.first" is -5; must be in [0'
defect drops_neg; json drops_neg 'j["cameras"][0]["dropped_frames"] = [-3]'
every drops_neg "$tmp/drops_neg/$M" '"cameras[0].dropped_frames" holds frame -3'
defect drops_far; json drops_far 'j["cameras"][2]["dropped_frames"] = [99999]'
every drops_far "$tmp/drops_far/$M" '"cameras[2].dropped_frames" holds frame 99999'
defect drops_twice; json drops_twice 'j["cameras"][0]["dropped_frames"] = [3, 3]'
every drops_twice "$tmp/drops_twice/$M" '"cameras[0].dropped_frames" lists frame 3 twice'
defect offset_nan; sed -i 's/"offset_s": [0-9.]*/"offset_s": NaN/' "$tmp/offset_nan/$M"
every offset_nan "$tmp/offset_nan/$M" '"audio.offset_s" is NaN'
defect family; json family 'j["instrument"] = "violin"'
every family "$tmp/family/$M" '"keypoints2d.layout" is "spd_cello", but "instrument" is "violin"'

# The audio: run and pitch --capture (sync is given its audio on the command line).
defect offset_far; json offset_far 'j["audio"]["offset_s"] = 99'
run_bad offset_far "$tmp/offset_far/$M" "audio.offset_s = 99 s is outside the audio (0.."
pitch_bad offset_far "$tmp/offset_far/$M" "audio.offset_s = 99 s is outside the audio (0.."
defect offset_before; json offset_before 'j["audio"]["offset_s"] = -5000'
run_bad offset_before "$tmp/offset_before/$M" "audio.offset_s = -5000 s puts the last frame at"
pitch_bad offset_before "$tmp/offset_before/$M" "audio.offset_s = -5000 s puts the last frame at"
defect no_audio; rm "$tmp/no_audio/audio.wav"
run_bad no_audio "$tmp/no_audio/$M" "audio.file \"audio.wav\": $tmp/no_audio/audio.wav not found"
pitch_bad no_audio "$tmp/no_audio/$M" "audio.file \"audio.wav\": $tmp/no_audio/audio.wav not found"
defect bad_audio; head -c 5000 /dev/zero | tr '\0' 'x' >"$tmp/bad_audio/audio.wav"
run_bad bad_audio "$tmp/bad_audio/$M" "audio.file: $tmp/bad_audio/audio.wav: cannot decode"
pitch_bad bad_audio "$tmp/bad_audio/$M" "audio.file: $tmp/bad_audio/audio.wav: cannot decode"

# The calibration: run and triangulate.
defect no_calib; rm "$tmp/no_calib/calibration.json"
run_bad no_calib "$tmp/no_calib/$M" "calibration \"calibration.json\": $tmp/no_calib/calibration.json not found"
check_bad no_calib "$tmp/no_calib/$M" "calibration \"calibration.json\": $tmp/no_calib/calibration.json not found"
tri_bad no_calib "$tmp/no_calib/$M" "calibration: $tmp/no_calib/calibration.json"
defect bad_calib; echo '{"cameras": 3}' >"$tmp/bad_calib/calibration.json"
run_bad bad_calib "$tmp/bad_calib/$M" "calibration: $tmp/bad_calib/calibration.json"
check_bad bad_calib "$tmp/bad_calib/$M" "calibration: $tmp/bad_calib/calibration.json"
tri_bad bad_calib "$tmp/bad_calib/$M" "calibration: $tmp/bad_calib/calibration.json"
defect no_camera; json no_camera 'j["cameras"][1]["name"] = "cam_x"; j["cameras"][1]["serial"] = "x"'
run_bad no_camera "$tmp/no_camera/$M" "camera \"cam_x\" is not in $tmp/no_camera/calibration.json"
check_bad no_camera "$tmp/no_camera/$M" "camera \"cam_x\" is not in $tmp/no_camera/calibration.json"
tri_bad no_camera "$tmp/no_camera/$M" "camera \"cam_x\" is not in $tmp/no_camera/calibration.json"

# keypoints2d.npy: dtype and shape, from its header.
defect int32; npy int32 '<i4' 0
run_bad int32 "$tmp/int32/keypoints2d.npy" "dtype int32; keypoints2d must be float32 or float64"
check_bad int32 "$tmp/int32/keypoints2d.npy" "dtype int32; keypoints2d must be float32 or float64"
tri_bad int32 "$tmp/int32/keypoints2d.npy" "dtype int32; keypoints2d must be float32 or float64"
defect short; npy short '<f4' 30
run_bad short "$tmp/short/keypoints2d.npy" "shape (30, 20, 142, 3) does not match capture.json ("
check_bad short "$tmp/short/keypoints2d.npy" "shape (30, 20, 142, 3) does not match capture.json ("
tri_bad short "$tmp/short/keypoints2d.npy" "shape (30, 20, 142, 3) does not match capture.json ("
defect no_npy; rm "$tmp/no_npy/keypoints2d.npy"
run_bad no_npy "$tmp/no_npy/keypoints2d.npy" "not found"
check_bad no_npy "$tmp/no_npy/keypoints2d.npy" "not found"
tri_bad no_npy "$tmp/no_npy/keypoints2d.npy" "not found"

# The instrument's points: run (the instrument stage needs them).
defect no_points; json no_points 'j["keypoints2d"]["layout"] = "coco_wholebody_133"'
run_bad no_points "$tmp/no_points/$M" "layout coco_wholebody_133 has no instrument point"

# The output: under a regular file (tests run as root: chmod would not stop them).
echo file >"$tmp/out_file"
rm -rf "$tmp/out"; mkdir -p "$tmp/out"
"$arco" run "$tmp/good" -o "$tmp/out_file/result" >"$tmp/stdout" 2>"$tmp/err"
rc=$?
check '[ $rc -ne 0 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ]' "run under a file: one line, exit non-zero"
check 'grep -q "^arco: error: $tmp/out_file/result: cannot create folder" "$tmp/err"' \
  "run under a file names the output: $(cat "$tmp/err")"
check '! grep -q triangulate "$tmp/stdout" "$tmp/err"' "run under a file: a stage started"

# arco calibrate: the board videos/images, the board spec, the camera graph and the given
# intrinsics; one line, nothing written (OpenCV's stereo pairs from opencv-doc).
data=/usr/share/doc/opencv-doc/examples/data
blank=$tmp/blank.pgm  # a 640x480 frame without a board
{ printf 'P5\n640 480\n255\n'; head -c 307200 /dev/zero | tr '\0' '\200'; } >"$blank"
mkdir -p "$tmp/cal/L" "$tmp/cal/R" "$tmp/cal/A" "$tmp/cal/B"
for n in 01 02 03 04 05 06; do
  ln -s "$data/left$n.jpg" "$tmp/cal/L/$n.jpg"; ln -s "$data/right$n.jpg" "$tmp/cal/R/$n.jpg"
  # A sees the board in frames 1-3 only, B in frames 4-6 only: no shared frame.
  if [ "$n" -le 03 ]; then ln -s "$data/left$n.jpg" "$tmp/cal/A/$n.jpg"; ln -s "$blank" "$tmp/cal/B/$n.pgm"
  else ln -s "$blank" "$tmp/cal/A/$n.pgm"; ln -s "$data/right$n.jpg" "$tmp/cal/B/$n.jpg"; fi
done
echo '{"cameras": 3}' >"$tmp/cal/bad_intrinsics.json"
C=(calibrate --board chessboard:9x6:25)
bad "calibrate: no board found" "$blank" "no board (chessboard:9x6:25) found in 1 frames" \
  "${C[@]}" --images left="$tmp/cal/L" --images blank="$blank" -o "$tmp/out/rig.json"
bad "calibrate: missing video" "$tmp/cal/missing.mp4" "" \
  "${C[@]}" --images left="$tmp/cal/L" --video right="$tmp/cal/missing.mp4" -o "$tmp/out/rig.json"
bad "calibrate: bad intrinsics" "$tmp/cal/bad_intrinsics.json" "" \
  "${C[@]}" --images left="$tmp/cal/L" --images right="$tmp/cal/R" \
  --intrinsics "$tmp/cal/bad_intrinsics.json" -o "$tmp/out/rig.json"
# cal_bad NAME WORDS ARGS...: one line "arco: error: " holding WORDS, nothing written.
cal_bad() {
  local name=$1 words=$2; shift 2
  rm -rf "$tmp/out"; mkdir -p "$tmp/out"
  "$arco" "$@" >"$tmp/stdout" 2>"$tmp/err"
  local rc=$?
  local line; line=$(cat "$tmp/err")
  check '[ $rc -ne 0 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ]' "$name: exit $rc, not one line: $line"
  check '[[ "$line" == "arco: error: "*"$words"* ]]' "$name: does not say '$words': $line"
  check '[ -z "$(ls -A "$tmp/out")" ]' "$name: left $(ls -A "$tmp/out" | head -3)"
}
cal_bad "calibrate: one camera" "at least two cameras, got 1 (left)" \
  "${C[@]}" --images left="$tmp/cal/L" -o "$tmp/out/rig.json"
cal_bad "calibrate: disconnected" "disconnected camera graph: b shares no board frame with a's group" \
  "${C[@]}" --images a="$tmp/cal/A" --images b="$tmp/cal/B" -o "$tmp/out/rig.json"
cal_bad "calibrate: wrong board spec" "board 'chessboard:9x6': expected chessboard:COLSxROWS:SQUARE_MM" \
  calibrate --board chessboard:9x6 --images left="$tmp/cal/L" --images right="$tmp/cal/R" -o "$tmp/out/rig.json"
# (A and B hold a 9x6 board in half their frames; L and R, with one in every frame, take
# twice as long to say the same: the search for a board that is not there is slow.)
cal_bad "calibrate: wrong board size" "no board (chessboard:7x7:25) found" \
  calibrate --board chessboard:7x7:25 --images a="$tmp/cal/A" --images b="$tmp/cal/B" -o "$tmp/out/rig.json"
cal_bad "calibrate: not CAMERA=PATH" "--images: 'left' is not CAMERA=PATH" \
  "${C[@]}" --images left --images right="$tmp/cal/R" -o "$tmp/out/rig.json"
cal_bad "calibrate: a camera twice" "camera 'left' is given twice" \
  "${C[@]}" --images left="$tmp/cal/L" --images left="$tmp/cal/R" -o "$tmp/out/rig.json"
cal_bad "calibrate: unknown origin" "origin 'cam9' is neither 'board' nor one of the cameras" \
  "${C[@]}" --images left="$tmp/cal/L" --images right="$tmp/cal/R" --origin cam9 -o "$tmp/out/rig.json"

# No temporaries next to any output after all of the above.
check '[ -z "$(find "$tmp" -name ".tmp-*" -o -name ".old-*")" ]' "temporaries left behind"

# A good capture still runs; its audio starting after the video starts is a warning.
defect late; json late 'j["audio"]["offset_s"] = -0.5'
(cd "$tmp" && "$arco" run late -o late_result >"$tmp/stdout" 2>"$tmp/err")
rc=$?
check '[ $rc -eq 0 ] && [ -f "$tmp/late_result/result.json" ]' "run with a late audio start: $(tail -1 "$tmp/err")"
check 'grep -q "\"capture\": \"../late\"" "$tmp/late_result/result.json"' \
  "result.json's capture (given relative) is relative to the result folder"

# A flag's error names the flag, not a file it did not come from.
for v in -1 nan; do
  "$arco" synth --duration-s $v -o "$tmp/out/cap" >/dev/null 2>"$tmp/err"
  rc=$?
  check '[ $rc -ne 0 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] && grep -q "^arco: error: --duration-s: $v " "$tmp/err" && ! grep -qi "calibration" "$tmp/err" && [ ! -e "$tmp/out/cap" ]' \
    "synth --duration-s $v: $(cat "$tmp/err")"
done

# import-spd: a keypoint folder of a camera the calibration lacks is named, not dropped.
mkdir -p "$tmp/spd/h/21334181" "$tmp/spd/h/21334237" "$tmp/spd/h/99999999"
"$arco" import-spd --calibration "$ARCO_SHARED_DATA_DIR/spd/cello_1113_scale_camera.xml" \
  --human "$tmp/spd/h" --first 1 --last 2 -o "$tmp/spd/cap" >"$tmp/stdout" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ]' "import-spd with an uncalibrated camera folder: $(cat "$tmp/err")"
check 'grep -q "^warning: $tmp/spd/h/99999999: camera 99999999 is not in .*cello_1113_scale_camera.xml; its keypoints are not imported$" "$tmp/err"' \
  "import-spd names the camera it leaves out (on stderr): $(cat "$tmp/err")"

# What a killed run left beside its result folder goes with the next run on that folder.
dead=$(bash -c 'echo $$')
mkdir -p "$tmp/.tmp-$dead.late_result/triangulation"
"$arco" run "$tmp/late" -o "$tmp/late_result" --overwrite >"$tmp/stdout" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ] && [ ! -e "$tmp/.tmp-$dead.late_result" ]' "a dead run's temporary stays"

# A truncated WAV: a warning naming the file and how much is missing, on pitch and run.
defect trunc
size=$(stat -c %s "$tmp/trunc/audio.wav")
truncate -s $((size / 2)) "$tmp/trunc/audio.wav"
"$arco" pitch "$tmp/trunc/audio.wav" -o "$tmp/trunc.csv" >"$tmp/stdout" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ]' "pitch of a truncated WAV: $(cat "$tmp/err")"
check 'grep -q "^warning: $tmp/trunc/audio.wav: truncated: .* s missing" "$tmp/err" && ! grep -q warning "$tmp/stdout"' \
  "pitch warns of the truncated WAV: $(cat "$tmp/stdout" "$tmp/err" | grep -i warn)"
"$arco" run "$tmp/trunc" -o "$tmp/trunc_result" >"$tmp/stdout" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ]' "run with a truncated WAV: $(tail -1 "$tmp/err")"
check 'grep -q "^warning: pitch: $tmp/trunc/audio.wav: truncated: .* s missing" "$tmp/err" && ! grep -q warning "$tmp/stdout"' \
  "run warns of the truncated WAV on stderr"
exit $fail
