#!/usr/bin/env bash
# docs/phones.md end to end: a lesson filmed with two phones, from their videos to the
# fingering table, the report, the viewer and the exports, with the guide's commands in its
# order. The phones: two H.264/AAC MP4s
# made here from a real photo of a cellist (SPD's example.jpg, scaled to 460x528, with its
# real labelme labels; the right phone's picture the left's shifted by 96 px, as a second
# camera beside the first sees a flat picture) and a real cello scale (SPD's
# background.wav) heard from 0.30 s by the left phone and from 0.95 s by the right one,
# whose clock runs 40 ppm fast and whose video has a variable frame rate (timestamps
# jittered by up to 0.3 frame). Checks: the right phone's start 0.65 s within 1 ms, every
# command exits 0, the notes of fingering.csv are the recording's, the report, exports
# (read back by export_check.py) and viewer files, and the guide's failure lines.
# Needs the models (scripts/setup); without them it skips (exit 77) unless CI is set.
# usage: phones_cli_test.sh ARCO_BINARY SHARED_DATA_DIR MODELS_DIR SOURCE_DIR
set -uo pipefail
arco=$(realpath "$1")
spd=$2/spd
models=$3
src=$4
if [ ! -f "$models/pose_detection.onnx" ]; then
  echo "$models/pose_detection.onnx is missing: run scripts/setup"
  [ -n "${CI:-}" ] && exit 1
  exit 77
fi
for tool in ffmpeg ffprobe; do
  command -v $tool >/dev/null || { echo "FAILED: $tool is needed"; exit 1; }
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$src/tests/cli/cli_test_lib.sh"
cd "$tmp" || exit 1
start=$SECONDS

# The two phones' pictures and labels (labelme 5, pixel centres scaled with the picture).
ffmpeg -v error -y -i "$spd/example.jpg" -vf "crop=2300:2640:0:0,scale=460:528" left.png &&
  ffmpeg -v error -y -i left.png -vf "crop=364:528:96:0,pad=460:528:0:0:gray" right.png ||
  { echo "FAILED: pictures"; exit 1; }
/usr/bin/python3 - "$spd/example.json" <<'PY' || { echo "FAILED: labels"; exit 1; }
import json, sys
d = json.load(open(sys.argv[1]))
for name, dx in (("left", 0), ("right", -96)):
    shapes = [{"label": s["label"], "shape_type": "point",
               "points": [[(s["points"][0][0] + 0.5) * 0.2 - 0.5 + dx, (s["points"][0][1] + 0.5) * 0.2 - 0.5]]}
              for s in d["shapes"] if s["shape_type"] == "point"
              and not s["label"].startswith("neck_bottom")]  # SPD's, not the guide's names
    json.dump({"version": "5.3.1", "shapes": shapes, "imageWidth": 460, "imageHeight": 528},
              open(name + ".json", "w"))
PY
# phone OUT.wav START_S DRIFT_PPM SEED: the recording as a phone that started START_S into
# it and whose clock runs DRIFT_PPM fast heard it (sample n: the sound at START_S + (1 +
# DRIFT_PPM 1e-6) n / rate), 8 s, mono, with its own microphone noise.
phone() {
  /usr/bin/python3 - "$spd/background.wav" "$@" <<'PY'
import sys, wave
import numpy as np
src, out, start, drift, seed = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
with wave.open(src) as w:
    rate, channels = w.getframerate(), w.getnchannels()
    x = np.frombuffer(w.readframes(w.getnframes()), "<i2").reshape(-1, channels).mean(axis=1) / 32768
t = start + (1 + drift * 1e-6) * np.arange(8 * rate) / rate
y = np.interp(t * rate, np.arange(len(x)), x) + np.random.default_rng(seed).normal(0, 0.002, 8 * rate)
with wave.open(out, "wb") as w:
    w.setnchannels(1); w.setsampwidth(2); w.setframerate(rate)
    w.writeframes((np.clip(y, -1, 1) * 32767).astype("<i2").tobytes())
PY
}
phone left.wav 0.30 0 1 && phone right.wav 0.95 40 2 || { echo "FAILED: sound"; exit 1; }
# video OUT.mp4 PICTURE AUDIO FPS [FILTER ARGS...]: 8 s of PICTURE at FPS with AUDIO as AAC.
video() {
  local out=$1 picture=$2 audio=$3 fps=$4; shift 4
  ffmpeg -v error -y -loop 1 -framerate "$fps" -i "$picture" -i "$audio" -map 0:v -map 1:a -t 8 \
    "$@" -c:v libx264 -preset ultrafast -pix_fmt yuv420p -c:a aac -b:a 128k "$out"
}
video left.mp4 left.png left.wav 30 &&
  video right.mp4 right.png right.wav 30 -vf "settb=1/90000,setpts='N/30/TB+0.3*sin(N)/30/TB'" \
    -fps_mode vfr -enc_time_base 1/90000 -video_track_timescale 90000 ||
  { echo "FAILED: videos"; exit 1; }
# The right video's timestamps really are irregular (else the test tests nothing).
check 'ffprobe -v error -select_streams v -show_entries packet=pts_time -of csv=p=0 right.mp4 | sort -g |
       awk "NR > 1 { d = \$1 - p; if (d < 0.030 || d > 0.0367) irregular++ } { p = \$1 } END { exit !(irregular > 100) }"' \
  "right.mp4 has no variable frame rate"

# 1. The starting calibration: the guide's phones.json at these videos' size.
cat > phones.json <<'JSON'
{"format": "arco-calibration", "version": 1, "units": "mm", "cameras": [
 {"name": "left", "width": 460, "height": 528, "K": [345, 0, 229.5, 0, 345, 263.5, 0, 0, 1],
  "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [0, 0, 0]},
 {"name": "right", "width": 460, "height": 528, "K": [345, 0, 229.5, 0, 345, 263.5, 0, 0, 1],
  "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [-1000, 0, 0]}]}
JSON

# 2. The capture, synced by sound.
ok "capture new" capture new --calibration phones.json --video left=left.mp4 --video right=right.mp4 \
  --sync audio --instrument cello -o capture
check 'grep -q "synced by sound" "$tmp/out" && grep -q "capture of 2 cameras x 240 frames at 30 fps" "$tmp/out"' \
  "capture's summary: $(cat "$tmp/out")"
check '[ ! -s "$tmp/err" ]' "a jitter below a frame is not a timestamps jump: $(cat "$tmp/err")"
cat "$tmp/out"
/usr/bin/python3 - capture/capture.json <<'PY' || { echo "FAILED: offsets: $(cat "$tmp/out")"; fail=1; }
import json, sys
cams = {c["name"]: c for c in json.load(open(sys.argv[1]))["cameras"]}
got = [cams["left"].get("offset_s", 0.0), cams["right"].get("offset_s", 0.0)]
print("offsets", got, "errors (ms)", [round(1000 * (g - w), 3) for g, w in zip(got, [0, 0.65])])
assert abs(got[0]) < 0.001 and abs(got[1] - 0.65) < 0.001, got
# 8 s is below the 20 s over which a drift is measured: the start alone.
assert all(abs(c.get("drift_ppm", 0.0)) < 1 for c in cams.values()), cams
PY

# 3. The performer.
ok "detect" detect capture
check 'grep -Eq "left +240 frames  person 100.0%  left hand 100.0%" "$tmp/out" &&
       grep -Eq "right +240 frames  person 100.0%  left hand 100.0%" "$tmp/out"' \
  "detect found the cellist and her left hand in every frame: $(cat "$tmp/out")"

# Calibrating before the labels are in: the guide's line.
SNAPSHOT_DIR=$tmp/capture
bad "calibrate before the labels" "capture/keypoints2d.npy: camera left never shows 5 of the cello's points with a score of at least 0.6 that a PnP pose agrees with" \
  calibrate from-instrument capture -o rig.json
check '[ ! -e rig.json ] && [ ! -e rig.report.json ]' "a failed calibration wrote its files"

# 4. The first calibration from the labels of the capture's frame 31 (the right phone
# started 0.65 s later: the capture's first 20 frames are not in its video). 30 frames for
# the bundle adjustment instead of 300: the same still picture in every frame.
check 'grep -q "^arco calibrate from-instrument capture --labels left=left.json --labels right=right.json" "$src/docs/phones.md"' \
  "the guide's from-instrument line with --labels was not found"
echo '{"shapes": [{"label": "bridge", "points": [[10, 10]], "shape_type": "point"}]}' >bad_labels.json
bad "a label that is not a point" "bad_labels.json: 0 of the cello's points are labelled (not its points: bridge), a camera's pose needs 5 (scroll_top, nut_l, nut_r, bridge_l, bridge_r, tail_gut, end_pin)" \
  calibrate from-instrument capture --labels left=left.json --labels right=bad_labels.json --labels-frame 31 -o rig.json
bad "labels of a frame the right phone did not record" "right.json: camera right did not record frame 3 of the capture (--labels-frame)" \
  calibrate from-instrument capture --labels left=left.json --labels right=right.json --labels-frame 3 -o rig.json
check '[ ! -e rig.json ] && [ ! -e rig.report.json ]' "a failed calibration wrote its files"
F=(--focal-px 452 --fix-focal --max-frames 30)
L=(--labels left=left.json --labels right=right.json --labels-frame 31)
ok "from-instrument (labels)" calibrate from-instrument capture "${L[@]}" "${F[@]}" -o rig.json
check 'grep -q "wrote rig.json and its .report.json" "$tmp/out" && [ -f rig.report.json ]' \
  "from-instrument's output: $(cat "$tmp/out")"
cat "$tmp/out"
cp rig.json capture/calibration.json

# 5. The instrument tracked from the labels.
ok "track" track capture "${L[@]}"
check 'grep -q "tracked frames 1:240 in 2 cameras from labels of frame 31 (layout spd_cello)" "$tmp/out" &&
       grep -q "labels agree to 0\.[0-9]* px" "$tmp/out"' "track's summary: $(cat "$tmp/out")"

# 6. Calibrated again from the tracked instrument: the string length through the rig.
ok "from-instrument (tracked)" calibrate from-instrument capture "${F[@]}" -o rig.json --overwrite
/usr/bin/python3 - rig.json rig.report.json <<'PY' || { echo "FAILED: the rig: $(cat "$tmp/out")"; fail=1; }
import json, sys
rig, report = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert [c["name"] for c in rig["cameras"]] == ["left", "right"], rig["cameras"]
assert [c["K"][0] for c in rig["cameras"]] == [452.0, 452.0], "--fix-focal kept the focal length"
measured = report["string_length_measured"]
print("string length", measured, "rms", report["rms_px"])
assert abs(measured["error_mm"]) < 3 and report["rms_px"] < 3, report
PY
cp rig.json capture/calibration.json

# 7. Everything else.
ok "run" run capture -o result
check 'grep -q "total .* -> result (vision/, paper/, arco/: points3d.npy, contacts.csv, fingering.csv)" "$tmp/out"' \
  "run's summary: $(tail -3 "$tmp/out")"
tail -4 "$tmp/out"

# 8. The fingering table: the recorded scale's notes, its open strings on their strings.
/usr/bin/python3 - result/arco/fingering.csv <<'PY' || { echo "FAILED: fingering.csv"; fail=1; }
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
names = [r["note_name"] for r in rows]
print("notes", names, "strings", [r["string"] for r in rows], "fingers", [r["finger"] for r in rows])
assert names[:9] == ["C2", "D2", "E2", "F2", "G2", "A2", "B2", "C3", "D3"], names
for r in rows:
    assert r["state"] in ("open", "pressed", "uncertain", "rest"), r
    assert 1 <= int(r["string"]) <= 4 and 0 <= int(r["finger"]) <= 4, r
    assert math.isfinite(float(r["cents_off"])) and float(r["duration_s"]) > 0, r
    assert (r["state"] == "open") == (int(r["finger"]) == 0), r
open_strings = {r["note_name"]: r["string"] for r in rows if r["state"] == "open"}
assert open_strings == {"C2": "4", "G2": "3", "D3": "2"}, open_strings
PY
ok "report" report result -o report.html
check 'grep -q "notes in 1 passages" "$tmp/out" && [ "$(grep -o "data-note=" report.html | wc -l)" -eq "$(($(wc -l < result/arco/fingering.csv) - 1))" ]' \
  "the report has one row per note of fingering.csv: $(cat "$tmp/out")"
for format in csv trc c3d gltf; do
  out=take.${format/gltf/glb}
  ok "export $format" export result --format "$format" -o "$out"
  /usr/bin/python3 "$src/tests/cli/export_check.py" "$format" "$out" result arco >check.txt ||
    { echo "FAILED: export $format: $(tail -1 check.txt)"; fail=1; }
done
bad "export bvh" "BVH: no frame has every body and hand joint" export result --format bvh -o take.bvh
if [ -f "$src/tools/view/node_modules/three/build/three.min.js" ]; then
  ok "view" view result --no-serve -o viewer --cache-dir "$tmp/cache"
  check '[ -f viewer/index.html ] && [ -f viewer/data.js ] && [ -f viewer/video_0.webm ] &&
         grep -q "\"frames\": 240" viewer/manifest.json' "the viewer's files: $(ls viewer)"
else
  echo "note: the viewer is not checked: three.js is not installed (scripts/fetch_view_tools)"
fi
ok "overlay" overlay result --camera left -o left_overlay.mp4
check '[ "$(ffprobe -v error -count_frames -select_streams v -show_entries stream=nb_read_frames -of csv=p=0 left_overlay.mp4)" = 240 ]' \
  "the overlay video has every frame: $(cat "$tmp/out")"

# When a step fails: the guide's lines.
SNAPSHOT_DIR=$tmp/w
mkdir -p w
N=(capture new --calibration phones.json --sync audio --instrument cello -o w/cap)
ffmpeg -v error -y -loop 1 -framerate 30 -i right.png -t 8 -c:v libx264 -preset ultrafast \
  -pix_fmt yuv420p mute.mp4
bad_at "a muted phone" "mute.mp4" "${N[@]}" --video left=left.mp4 --video right=mute.mp4
check '[[ "$error_line" == *"no audio stream"* ]]' "a muted phone: $error_line"
video fast.mp4 right.png right.wav 60
bad "two frame rates" "fast.mp4: 60 fps, but left.mp4 has 30 fps" "${N[@]}" \
  --video left=left.mp4 --video right=fast.mp4
ffmpeg -v error -y -i "$spd/pgy.wav" -t 8 other.wav && video other.mp4 right.png other.wav 30
bad "another performance" "other.mp4 against left.mp4: ambiguous alignment" "${N[@]}" \
  --video left=left.mp4 --video right=other.mp4
bad "a camera the calibration lacks" 'phones.json: no camera "back" (given for right.mp4; cameras: left, right)' \
  "${N[@]}" --video left=left.mp4 --video back=right.mp4
SNAPSHOT_DIR=$tmp/capture
bad "labels in one view of two" "left.json: labels in 1 view(s): at least two views are needed" \
  track capture --labels left=left.json
"$arco" capture new --calibration phones.json --video left=left.mp4 --video right=right.mp4 \
  --sync audio --instrument cello -o undetected >/dev/null || { echo "FAILED: capture new"; fail=1; }
/usr/bin/python3 - <<'PY'
import json
d = json.load(open("right.json"))
for shape in d["shapes"]:
    shape["points"][0][1] += 30
json.dump(d, open("right_bad.json", "w"))
PY
SNAPSHOT_DIR=$tmp/undetected
bad "labels that disagree" "left.json, right_bad.json: label scroll_top: the views do not agree (rays miss by more than" \
  track undetected --labels left=left.json --labels right=right_bad.json --labels-frame 31
SNAPSHOT_DIR=$tmp/w
bad "run before detect" "undetected/capture.json: no 2D keypoints yet" run undetected -o w/res

# One phone, the guide's commands for it: the left phone alone, from its video to the
# fingering table without a calibration file (capture new, detect, track, run); then its
# focal length given.
SNAPSHOT_DIR=$tmp/w
bad "two phones without a calibration" "--calibration is missing: 2 cameras need one that names them" \
  capture new --video left=left.mp4 --video right=right.mp4 --sync audio --instrument cello -o w/two
ok "one phone: capture new" capture new --video left=left.mp4 --sync audio --instrument cello -o one
check 'grep -q "calibration.json made: camera left from its video: 460x528, focal 398.9 px (a phone.s default, 67 deg across the longer side), no distortion, its frame the world" "$tmp/out"' \
  "one phone's capture: $(cat "$tmp/out")"
ok "one phone: detect" detect one
bad "one phone: run before track" "one/keypoints2d.npy: no frame shows the cello's nut_l, nut_r, bridge_l and bridge_r in its view" \
  run one -o w/res
check '[ ! -e w/res ]' "a failed run wrote its folder"
SNAPSHOT_DIR=
/usr/bin/python3 - <<'PY'
import json
d = json.load(open("left.json"))
for shape in d["shapes"]:
    if shape["label"] == "nut_r":
        shape["points"][0][0] += 40
json.dump(d, open("left_slip.json", "w"))
PY
SNAPSHOT_DIR=$tmp/one
bad "one phone: a label that slipped" "left_slip.json: label nut_r: the labels do not fit the instrument's shape in one view (it is 45 px from where the others put it; 10 px at most)" \
  track one --labels left=left_slip.json --labels-frame 31
SNAPSHOT_DIR=
ok "one phone: track" track one --labels left=left.json --labels-frame 31
check 'grep -q "tracked frames 1:240 in 1 cameras from labels of frame 31 (layout spd_cello)" "$tmp/out" &&
       grep -q "the bow is not tracked from one view" "$tmp/err"' "one phone's track: $(cat "$tmp/out" "$tmp/err")"
# The still picture's instrument stays on its labels in every frame (the model posed by
# them fits them to the PnP's residual, 1-2 px on this real cello).
/usr/bin/python3 - one left.json <<'PY' || { echo "FAILED: one phone's tracked points"; fail=1; }
import json, sys
import numpy as np
names = ["scroll_top", "nut_l", "nut_r", "bridge_l", "bridge_r", "tail_gut"]
labels = {s["label"]: s["points"][0] for s in json.load(open(sys.argv[2]))["shapes"]}
k = np.load(sys.argv[1] + "/keypoints2d.npy")
first = 133  # spd_cello: the instrument after COCO-WholeBody's 133
worst = max(np.linalg.norm(k[:, 0, first + i, :2] - labels[n], axis=1).max() for i, n in enumerate(names))
print("one phone: tracked points at most %.2f px from the labels over %d frames" % (worst, len(k)))
assert worst < 3, worst
PY
ok "one phone: run" run one -o one_result
/usr/bin/python3 - one_result <<'PY' || { echo "FAILED: one phone's result"; fail=1; }
import csv, sys
import numpy as np
rows = list(csv.DictReader(open(sys.argv[1] + "/arco/fingering.csv")))
names = [r["note_name"] for r in rows]
print("one phone: notes", names, "strings", [r["string"] for r in rows], "fingers", [r["finger"] for r in rows])
assert names[:9] == ["C2", "D2", "E2", "F2", "G2", "A2", "B2", "C3", "D3"], names
open_strings = {r["note_name"]: r["string"] for r in rows if r["state"] == "open"}
assert open_strings == {"C2": "4", "G2": "3", "D3": "2"}, open_strings
# Every point says where its depth came from: the instrument's from its pose.
source = np.load(sys.argv[1] + "/triangulation/depth_source.npy")
assert (source[:, 133:139] == 1).all(), np.unique(source[:, 133:139])
PY
# The phone's focal length known: its calibration from the labels, then run again.
ok "one phone: calibrate" calibrate from-instrument one --labels left=left.json --labels-frame 31 \
  --focal-px 452 -o one_rig.json
check 'grep -q "calibrated 1 camera of one: 460x528 (video), focal 452.0 px from --focal-px; world: camera left.s frame, mm" "$tmp/out" &&
       grep -q "the cello.s model fits its points in 240 frames" "$tmp/out"' \
  "one phone's calibration: $(cat "$tmp/out")"
cp one_rig.json one/calibration.json
ok "one phone: run with the focal length" run one -o one_result_focal
check 'cmp -s <(cut -d, -f8 one_result/arco/fingering.csv) <(cut -d, -f8 one_result_focal/arco/fingering.csv)' \
  "the focal length changed the notes: $(cut -d, -f8 one_result_focal/arco/fingering.csv | tr '\n' ' ')"
check '[ -z "$(find "$tmp" -name ".tmp-*" -o -name ".old-*")" ]' "no temporaries left"
echo "phones: $((SECONDS - start)) s"
[ $fail -eq 0 ] && echo "phones CLI: all checks passed"
exit $fail
