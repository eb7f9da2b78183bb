#!/usr/bin/env bash
# `arco capture new` and `arco capture import-keypoints` from the command line, on the real
# videos of Debian's opencv-doc (vtest.avi 768x576, Megamind.avi 720x528) and generated
# PNG frames: a capture that references the videos (relative paths kept relative to the
# capture), `arco run` / `arco triangulate` on it saying to run `arco detect`, and every
# bad input as one line "arco: error: FILE: ...", exit 1, nothing written.
# usage: capture_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$(realpath "$1")
spd=$2/spd
videos=/usr/share/doc/opencv-doc/examples/data
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
if [ ! -f "$videos/vtest.avi" ] || [ ! -f "$videos/Megamind.avi" ]; then
  echo "FAILED: $videos/vtest.avi and Megamind.avi are needed (apt-get install opencv-doc)"
  exit 1
fi
cd "$tmp" || exit 1
w=$tmp/w
SNAPSHOT_DIR=$w
mkdir -p "$w" videos

# A rig of three SPD cameras resized for the videos: cam A 768x576, cam B 576x768 (a
# portrait camera: vtest turned 90 degrees), cam C 720x528.
"$arco" calibration convert "$spd/cello_1113_scale_camera.xml" all.json >/dev/null
python3 - <<'EOF'
import json
j = json.load(open("all.json"))
j["cameras"] = j["cameras"][:3]
for cam, (wd, ht) in zip(j["cameras"], [(768, 576), (576, 768), (720, 528)]):
    cam["width"], cam["height"] = wd, ht
json.dump(j, open("rig.json", "w"))
EOF
A=21293324 B=21293325 C=21293326
ln -s "$videos/vtest.avi" videos/vtest.avi
# PNG frames (grey, 768x576) written with the standard library only.
png() {
  python3 - "$@" <<'EOF'
import struct, sys, zlib
path, width, height, grey = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
rows = b"".join(b"\0" + bytes([grey]) * width for _ in range(height))
open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)) +
                       chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
EOF
}
mkdir -p frames empty
for k in 1 2 10; do png "frames/f$k.png" 768 576 $((k * 20)); done

# A capture from videos: relative paths stay relative to the capture folder.
ok "capture new" capture new --calibration rig.json --video "$A=videos/vtest.avi" \
  --video "$B=videos/vtest.avi" --rotate "$B=90" -o caps/one/
check 'grep -q "capture of 2 cameras x 795 frames at 10 fps" "$tmp/out"' "capture new summary: $(cat "$tmp/out")"
python3 - caps/one/capture.json <<'EOF' || { echo "FAILED: capture.json"; fail=1; }
import json, sys
j = json.load(open(sys.argv[1]))
assert j["frames"] == {"first": 1, "count": 795}, j["frames"]
assert j["fps"] == 10, j["fps"]
assert "keypoints2d" not in j
c = j["cameras"]
assert [x["serial"] for x in c] == ["21293324", "21293325"], c
assert c[0]["video"] == "../../videos/vtest.avi" and "rotate_deg" not in c[0], c[0]
assert c[1]["rotate_deg"] == 90, c[1]
EOF
check '[ -f caps/one/calibration.json ]' "the calibration is copied"
for cmd in run triangulate; do
  "$arco" $cmd caps/one -o res >/dev/null 2>"$tmp/err"
  rc=$?
  check '[ $rc -eq 1 ] && [ "$(wc -l <"$tmp/err")" -eq 1 ] && grep -q "^arco: error: caps/one/capture.json: no 2D keypoints yet.*arco detect" "$tmp/err"' \
    "$cmd on a capture without keypoints: $(cat "$tmp/err")"
  check '[ ! -e res ]' "$cmd wrote nothing"
done
ok "capture new, images" capture new --calibration rig.json --images "$A=frames" --fps 25 -o caps/img
check 'grep -q "1 cameras x 3 frames at 25 fps" "$tmp/out"' "an image folder: $(cat "$tmp/out")"

# Bad inputs: one line naming the file, nothing written.
N=(capture new --calibration rig.json)
echo "not a video" >"$w/text.avi"
head -c 3000000 "$videos/vtest.avi" >"$w/cut.avi"
bad_at "unreadable video" "$w/text.avi" "${N[@]}" --video "$A=$w/text.avi" -o "$w/cap"
bad_at "missing video" "$w/none.avi" "${N[@]}" --video "$A=$w/none.avi" -o "$w/cap"
bad_at "truncated video" "$w/cut.avi" "${N[@]}" --video "$A=$w/cut.avi" -o "$w/cap"
bad_at "camera not in the calibration" rig.json "${N[@]}" --video "cam9=videos/vtest.avi" -o "$w/cap"
bad_at "size mismatch" "$videos/Megamind.avi" "${N[@]}" --video "$A=$videos/Megamind.avi" -o "$w/cap"
bad_at "size mismatch: no rotation" videos/vtest.avi "${N[@]}" --video "$B=videos/vtest.avi" -o "$w/cap"
bad_at "frame-count mismatch" frames "${N[@]}" --video "$A=videos/vtest.avi" \
  --images "$B=frames" --rotate "$B=90" -o "$w/cap"
bad_at "empty image folder" empty "${N[@]}" --images "$A=empty" --fps 25 -o "$w/cap"
bad_at "images without a frame rate" frames "${N[@]}" --images "$A=frames" -o "$w/cap"
bad_at "a video at another rate" videos/vtest.avi "${N[@]}" --video "$A=videos/vtest.avi" --images "$B=frames" \
  --rotate "$B=90" --fps 25 --dropped-frames "$B=$(seq -s, 4 795)" -o "$w/cap"
bad_at "rotate of an unknown camera" --rotate "${N[@]}" --video "$A=videos/vtest.avi" \
  --rotate "$C=90" -o "$w/cap"
bad_at "rotate by 45 degrees" --rotate "${N[@]}" --video "$A=videos/vtest.avi" --rotate "$A=45" \
  -o "$w/cap"
bad_at "dropped frames not a list" --dropped-frames "${N[@]}" --video "$A=videos/vtest.avi" \
  --dropped-frames "$A=1,x" -o "$w/cap"
# Dropped frames put the counts right: 3 images + 792 dropped = 795.
ok "capture new with dropped frames" "${N[@]}" --video "$A=videos/vtest.avi" \
  --images "$B=frames" --rotate "$B=90" --dropped-frames "$B=$(seq -s, 4 795)" -o caps/drops
check 'grep -q "795 frames at 10 fps" "$tmp/out"' "dropped frames: $(cat "$tmp/out")"

# Unknown subcommand.
"$arco" capture frobnicate >/dev/null 2>"$tmp/err"
rc=$?
check '[ $rc -eq 1 ] && grep -q "^arco: error: unknown command .capture frobnicate. (capture commands: new, import-keypoints" "$tmp/err"' \
  "unknown capture command: $(cat "$tmp/err")"

# import-keypoints: OpenPose files of the image capture's 3 frames.
mkdir -p op
for k in 0 1 2; do
  python3 - "op/v_${k}_keypoints.json" <<'EOF'
import json, sys
pose = [0.0] * 75
pose[15:18] = [100.0, 200.0, 0.9]  # BODY_25 5 = left shoulder
json.dump({"version": 1.3, "people": [{"pose_keypoints_2d": pose}]}, open(sys.argv[1], "w"))
EOF
done
ok "import-keypoints" capture import-keypoints caps/img --format openpose --camera "$A=op"
check 'grep -q "\"layout\": \"coco_wholebody_133\"" caps/img/capture.json && [ -f caps/img/keypoints2d.npy ]' \
  "import-keypoints names keypoints2d.npy: $(cat "$tmp/out")"
cp -r caps/img "$w/img"
bad_at "import-keypoints again" "$w/img/capture.json" capture import-keypoints "$w/img" \
  --format openpose --camera "$A=op"
ok "import-keypoints --overwrite" capture import-keypoints "$w/img" --format openpose \
  --camera "$A=op" --overwrite
rm op/v_2_keypoints.json
bad_at "import-keypoints: too few frames" op capture import-keypoints "$w/img" --format openpose \
  --camera "$A=op" --overwrite
echo '{"people": [{"pose_keypoints_2d": [1, 2]}]}' >op/v_2_keypoints.json
bad_at "import-keypoints: a malformed file" op/v_2_keypoints.json capture import-keypoints "$w/img" \
  --format openpose --camera "$A=op" --overwrite

check '[ -z "$(find "$tmp" -name ".tmp-*" -o -name ".old-*")" ]' "no temporaries left"
exit $fail
