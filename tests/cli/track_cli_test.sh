#!/usr/bin/env bash
# `arco track` from the command line on a capture of opencv-doc's messi5.jpg (a real
# photo as a 1-frame video in two cameras 100 mm apart): what it prints and writes, and
# every bad input (labels in one view, names that match nothing, a label outside the
# image, a labelled frame outside the capture, a capture without videos or without an
# instrument, bad flags, a bow shorter than a bow) as one line "arco: error: ...", exit 1,
# nothing written. Then a rig in its own units (issue 24): the real SPD calibration
# (Metashape units, about 2 m per unit) with the real labels of four cameras and the bow
# labelled, where every length the trackers compare is mm through the calibration's scale.
# usage: track_cli_test.sh ARCO_BINARY [SHARED_DATA_DIR]
set -uo pipefail
arco=$(realpath "$1")
shared=${2:-}
photo=/usr/share/doc/opencv-doc/examples/data/messi5.jpg
if [ ! -f "$photo" ]; then echo "FAILED: $photo is needed (apt-get install opencv-doc)"; exit 1; fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
cd "$tmp" || exit 1

cat > cal.json <<'JSON'
{"format": "arco-calibration", "version": 1, "units": "mm", "cameras": [
 {"name": "front", "width": 548, "height": 342, "K": [600, 0, 273.5, 0, 600, 170.5, 0, 0, 1],
  "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [0, 0, 0]},
 {"name": "side", "width": 548, "height": 342, "K": [600, 0, 273.5, 0, 600, 170.5, 0, 0, 1],
  "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [100, 0, 0]}]}
JSON
"$arco" capture new --calibration cal.json --video "front=$photo" --video "side=$photo" \
  --fps 30 --instrument cello -o cap >/dev/null || { echo "FAILED: capture new"; exit 1; }
"$arco" capture new --calibration cal.json --video "front=$photo" --video "side=$photo" \
  --fps 30 -o nocello >/dev/null || { echo "FAILED: capture new"; exit 1; }

# labels FILE DX EXTRA: the cello's points 1 m in front of the cameras, shifted by DX px
# (the side camera sees them 60 px to the right), plus EXTRA shapes.
labels() {
  local file=$1 dx=$2 extra=${3:-}
  local shapes="" name x y
  while read -r name x y; do
    shapes+="{\"label\": \"$name\", \"points\": [[$((x + dx)), $y]], \"shape_type\": \"point\"},"
  done <<'PTS'
scroll_top 200 60
nut_l 190 100
nut_r 215 100
bridge_l 180 250
bridge_r 230 250
tail_gut 205 300
end_pin 205 330
PTS
  shapes+="{\"label\": \"cello\", \"points\": [[100, 40], [300, 340]], \"shape_type\": \"rectangle\"}"
  echo "{\"version\": \"5.3.1\", \"shapes\": [$shapes$extra], \"imageWidth\": 548, \"imageHeight\": 342}" > "$file"
}
labels front.json 0
labels side.json 60
labels chin.json 60 ', {"label": "chin", "points": [[10, 10]], "shape_type": "point"}'
labels far.json 60 ', {"label": "tip_plate", "points": [[10, 10]], "shape_type": "point"}'
labels bowfront.json 0 ', {"label": "frog", "points": [[150, 200]], "shape_type": "point"}, {"label": "tip_plate", "points": [[400, 120]], "shape_type": "point"}'
labels bowside.json 60 ', {"label": "frog", "points": [[210, 200]], "shape_type": "point"}, {"label": "tip_plate", "points": [[460, 120]], "shape_type": "point"}'
echo '{"version": "5.3.1", "shapes": [{"label": "foo", "points": [[10, 10]], "shape_type": "point"}]}' > foo.json
sed 's/\[\[260, 60\]\]/[[600, 60]]/' side.json > outside.json

bad "one view" "labels in 1 view(s): at least two views are needed" \
  track cap --labels front=front.json
bad "one view twice" "front.json: camera front frame 1 is labelled twice" \
  track cap --labels front=front.json --labels front@1=front.json
bad "names match nothing" "foo.json: no label names a point of the cello" \
  track cap --labels front=front.json --labels side=foo.json
bad "label outside" "outside.json: label scroll_top at (599.5" \
  track cap --labels front=front.json --labels side=outside.json
bad "labels frame outside" "--labels-frame 5 is outside the capture's frames 1:1" \
  track cap --labels front=front.json --labels side=side.json --labels-frame 5
bad "label file frame outside" "side.json: labelled frame 3 is outside the capture's frames 1:1" \
  track cap --labels front=front.json --labels side@3=side.json
bad "unknown camera" "side.json: camera back is not in" \
  track cap --labels front=front.json --labels back=side.json
bad "missing file" "nowhere.json" track cap --labels front=front.json --labels side=nowhere.json
bad "spec syntax" '--labels "front" must look like CAMERA=FILE or CAMERA@FRAME=FILE' \
  track cap --labels front
bad "no labels" "--labels is required" track cap
bad "threads range" "--threads: -1 is outside" track cap --labels front=front.json --threads -1
bad "no instrument" 'instrument is "none"' track nocello --labels front=front.json --labels side=side.json
bad "no capture" "nowhere/capture.json" track nowhere --labels front=front.json
labels shortfront.json 0 ', {"label": "frog", "points": [[150, 200]], "shape_type": "point"}, {"label": "tip_plate", "points": [[160, 200]], "shape_type": "point"}'
labels shortside.json 60 ', {"label": "frog", "points": [[210, 200]], "shape_type": "point"}, {"label": "tip_plate", "points": [[220, 200]], "shape_type": "point"}'
bad "bow too short" "shortfront.json, shortside.json: frog and tip are 16.67 mm apart in frame 1 (a bow is at least 50 mm long; scale 1 mm per mm unit of" \
  track cap --labels front=shortfront.json --labels side=shortside.json
"$arco" synth -o syn --duration-s 1 >/dev/null 2>&1 || { echo "FAILED: synth"; exit 1; }
bad "no video" "has no video" track syn --labels front=front.json --labels side=side.json
check '[ ! -e cap/keypoints2d.npy ] && [ ! -e cap/track.json ]' "a failed track wrote something"

# The real run: an unknown label is a warning, the bow's labels are not.
"$arco" track cap --labels front=front.json --labels side=chin.json --threads 2 >out.txt 2>err.txt
rc=$?
check '[ $rc -eq 0 ]' "track: exit $rc: $(cat err.txt)"
check 'grep -q "tracked frames 1:1 in 2 cameras from labels of frame 1 (layout spd_cello)" out.txt' \
  "track's summary: $(cat out.txt)"
check 'grep -q "warning: label \"chin\" is not a point of the cello" err.txt' "no warning: $(cat err.txt)"
check '[ -f cap/keypoints2d.npy ] && grep -q "arco-track-report" cap/track.json' "outputs missing"
check 'grep -q "keypoints2d.npy" cap/capture.json && grep -q "spd_cello" cap/capture.json' \
  "capture.json does not name the keypoints"
"$arco" track cap --labels front=front.json --labels side=far.json --no-bow >/dev/null 2>err.txt
check '! grep -q tip_plate err.txt && grep -q "the bow is not tracked (--no-bow)" err.txt' \
  "the bow's label was warned about: $(cat err.txt)"
check 'grep -A1 "\"tracked_points\"" cap/track.json | grep -q "\"scroll_top\""' \
  "track.json lacks the tracked points"
"$arco" track cap --labels front=front.json --labels side=far.json >/dev/null 2>err.txt
check 'grep -q "the bow is not tracked (its frog and tip need labels in two views of frame 1)" err.txt' \
  "no warning for a bow labelled in one view: $(cat err.txt)"
# The bow labelled in both views: tracked (the default) as its own thin body, no warning.
"$arco" track cap --labels front=bowfront.json --labels side=bowside.json >out.txt 2>err.txt
check '[ ! -s err.txt ] && grep -q "\"bow_tracked\": true" cap/track.json' \
  "the bow was not tracked: $(cat err.txt)"
check 'grep -q "of which the bow .* ms per view-frame; the right hand seen in 0 frames" out.txt' \
  "the bow's time is not printed: $(cat out.txt)"

# A calibration in metres: the same rig, the bow (437 mm) tracked, scale 1000 mm per unit.
sed 's/"units": "mm"/"units": "m"/; s/"t": \[100, 0, 0\]/"t": [0.1, 0, 0]/' cal.json > cal_m.json
"$arco" capture new --calibration cal_m.json --video "front=$photo" --video "side=$photo" \
  --fps 30 --instrument cello -o cap_m >/dev/null || { echo "FAILED: capture new (m)"; exit 1; }
"$arco" track cap_m --labels front=bowfront.json --labels side=bowside.json >out.txt 2>err.txt
rc=$?
check '[ $rc -eq 0 ] && grep -q "\"bow_tracked\": true" cap_m/track.json &&
       grep -q "\"mm_per_unit\": 1000.0" cap_m/track.json' \
  "track on a calibration in metres: exit $rc: $(cat err.txt)"

# The real SPD rig in Metashape units: four cameras of session cello_1113_scale with their
# real labels of frame 128 (the bow's frog and tip among them, 0.32 units apart), each
# camera's video the real frame example.jpg (one frame; the template comes from the labels).
if [ -n "$shared" ] && [ -d "$shared/spd" ]; then
  spd=$shared/spd
  videos=() labels=()
  for serial in 21334181 21334190 21334211 21334237; do
    videos+=(--video "$serial=$spd/example.jpg")
    labels+=(--labels "$serial=$spd/labels_frame128/cello_1113_scale_${serial}_128.json")
  done
  "$arco" capture new --calibration "$spd/cello_1113_scale_camera.xml" "${videos[@]}" --fps 30 \
    --instrument cello -o spdcap >/dev/null || { echo "FAILED: capture new (SPD)"; exit 1; }
  "$arco" track spdcap "${labels[@]}" --threads 2 >out.txt 2>err.txt
  rc=$?
  check '[ $rc -eq 0 ]' "track on the real SPD calibration: exit $rc: $(cat err.txt)"
  check 'grep -q "world in metashape units: 20[0-9][0-9] mm per unit" out.txt' \
    "the scale is not printed: $(cat out.txt)"
  check 'grep -q "\"bow_tracked\": true" spdcap/track.json && grep -q "\"units\": \"metashape\"" spdcap/track.json' \
    "the bow was not tracked on the SPD rig: $(grep -E "bow_tracked|units" spdcap/track.json)"
  # One unit is about 2.02 m in this session (spd/README.md): nut-bridge 0.344 units = 695 mm.
  mm=$(sed -n 's/.*"mm_per_unit": \([0-9.]*\).*/\1/p' spdcap/track.json)
  check 'awk -v s="$mm" "BEGIN { exit !(s > 1950 && s < 2100) }"' "SPD scale: $mm mm per unit"
  # Without the nut and bridge labelled there is no scale: one line naming the files.
  mkdir nonut
  for serial in 21334181 21334190 21334211 21334237; do
    python3 - "$spd/labels_frame128/cello_1113_scale_${serial}_128.json" "nonut/$serial.json" <<'PY'
import json, sys
a = json.load(open(sys.argv[1]))
a["shapes"] = [s for s in a["shapes"] if s["label"] != "nut_r"]
json.dump(a, open(sys.argv[2], "w"))
PY
  done
  bad "metashape without a scale" "nonut/21334237.json: the calibration spdcap/calibration.xml is in units 'metashape' (no metric scale): label nut_l, nut_r, bridge_l and bridge_r in two views" \
    track spdcap --labels 21334181=nonut/21334181.json --labels 21334190=nonut/21334190.json \
    --labels 21334211=nonut/21334211.json --labels 21334237=nonut/21334237.json
else
  echo "SKIPPED: the SPD rig part (no SHARED_DATA_DIR/spd)"
fi
exit $fail
