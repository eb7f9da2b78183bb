#!/usr/bin/env bash
# Bad content (issue 24, docs/architecture.md "Validation rules"): files that parse but say
# something impossible are one error line naming the file, exit 1, nothing written, on
# every command that reads them: a CSV row cut short (notes.csv, pitch.csv: refine), a
# NaN audio sample (pitch, sync, run), a coordinate of 1e300 (export, every format), an
# export whose extension is another format's, --fps against a video's own rate (sync), the
# same images for two cameras and --intrinsics naming none of them (calibrate), and a
# stage error prefixed once ("instrument fit:", run).
# usage: bad_content_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$(realpath "$1")
export ARCO_SHARED_DATA_DIR=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
cd "$tmp" || exit 1

"$arco" synth --duration-s 1.5 --seed 5 -o cap >log 2>&1
check '[ $? -eq 0 ]' "synth: $(tail -1 log)"
"$arco" run cap -o res >log 2>&1
check '[ $? -eq 0 ]' "run: $(tail -1 log)"
mkdir -p w
SNAPSHOT_DIR=$tmp/w

# CSV rows cut short: notes.csv (accepted before) and pitch.csv, read by refine.
cp -r res cut_notes
sed -i '2s/^\(note,[^,]*,[^,]*,[^,]*\),.*/\1/' cut_notes/notes.csv
bad_at "refine: notes.csv row cut short" "cut_notes/notes.csv:2" refine cut_notes
check 'grep -q "expected 11 fields (as the header), found 4" <<<"$error_line"' \
  "refine names the cut notes.csv row's fields"
cp -r res cut_pitch
sed -i '3s/,[^,]*$//' cut_pitch/pitch.csv
bad_at "refine: pitch.csv row cut short" "cut_pitch/pitch.csv:3" refine cut_pitch

# A NaN sample in a float WAV: refused (not read as 0) on every command that decodes it.
/usr/bin/python3 - <<'PY'
import numpy as np, struct
rate = 48000
x = (0.3 * np.sin(2 * np.pi * 220 * np.arange(rate) / rate)).astype("<f4")
x[1000] = np.nan
data = x.tobytes()
fmt = struct.pack("<IHHIIHH", 16, 3, 1, rate, rate * 4, 4, 32)
open("nan.wav", "wb").write(b"RIFF" + struct.pack("<I", 36 + len(data)) + b"WAVEfmt " + fmt
                            + b"data" + struct.pack("<I", len(data)) + data)
PY
nan_msg="nan.wav: sample 1000 (0.0208 s) is nan; audio samples must be finite"
bad "pitch: a NaN sample" "$nan_msg" pitch nan.wav -o w/p.csv
bad "sync: a NaN sample" "$nan_msg" sync nan.wav --video nan.wav
cp -r cap nan_cap && cp nan.wav nan_cap/audio.wav
nan_msg="nan_cap/audio.wav: sample 1000 (0.0208 s) is nan; audio samples must be finite"
bad "run: a NaN sample" "$nan_msg" run nan_cap -o w/r
bad "pitch --capture: a NaN sample" "$nan_msg" pitch --capture nan_cap -o w/p.csv

# Export: the extension is the format's; a coordinate of 1e300 is refused in every format.
bad_at "export --format bvh -o x.glb" "w/x.glb" export res --format bvh -o w/x.glb
bad_at "export --format gltf -o x.gltf" "w/x.gltf" export res --format gltf -o w/x.gltf
cp -r res big
/usr/bin/python3 -c "
import numpy as np
a = np.load('big/arco/points3d.npy'); a[3, 5, 1] = 1e300; np.save('big/arco/points3d.npy', a)"
for ext in csv trc c3d glb bvh; do
  format=${ext/glb/gltf}
  bad_at "export --format $format: a point at 1e300" "big/arco/points3d.npy" \
    export big --format "$format" -o "w/x.$ext"
  check 'grep -q "frame 4 keypoint .*: coordinate 1e+300 mm is not finite or beyond 1e9 mm" <<<"$error_line"' \
    "export --format $format names the frame and keypoint of the huge coordinate"
done

# sync --fps against a 30 fps video (arco overlay's): an error naming the video and the
# flag; the video's own rate (or none given) is accepted as far as the event search.
# A tenth of the camera's size: the rate is the same, and each sync decodes it in 0.1 s
# instead of 4 s (the full-size overlay alone took 11 s).
"$arco" overlay res --camera "$(/usr/bin/python3 -c "import json; print(json.load(open('cap/capture.json'))['cameras'][0]['name'])")" --scale 0.1 -o v.mkv >log 2>&1
if [ -f v.mkv ]; then
  bad_at "sync --fps 15 on a 30 fps video" "v.mkv" sync cap/audio.wav --video v.mkv --fps 15
  check 'grep -q "30 fps in the container, but --fps = 15" <<<"$error_line"' \
    "sync names the container's rate and the flag"
  line=$("$arco" sync cap/audio.wav --video v.mkv --fps 30 2>&1)
  check '[[ "$line" != *"in the container"* ]]' "sync --fps 30 on a 30 fps video: $line"
else
  echo "FAILED: overlay made no video: $(tail -1 log)"; fail=1
fi

# calibrate: one image folder for two cameras; --intrinsics naming none of the cameras.
data=/usr/share/doc/opencv-doc/examples/data
mkdir -p L R
for f in "$data"/left0[1-4].jpg; do ln -s "$f" L/; done
for f in "$data"/right0[1-4].jpg; do ln -s "$f" R/; done
B=(calibrate --board chessboard:9x6:25)
bad "calibrate: the same folder twice" "cameras 'a' and 'b' are given the same video or image folder" \
  "${B[@]}" --images a=L --images b=./L/ -o w/rig.json
cp -rL L L2
bad "calibrate: a copy of one folder" "are 0 mm apart: a rig needs a baseline" \
  "${B[@]}" --images a=L --images b=L2 -o w/rig.json
"$arco" "${B[@]}" --images left=L --images right=R -o lr.json >log 2>&1
check '[ $? -eq 0 ]' "calibrate left/right: $(tail -1 log)"
bad_at "calibrate --intrinsics naming none of the cameras" "lr.json" \
  "${B[@]}" --images a=L --images b=R --intrinsics lr.json -o w/rig.json

# A stage's error carries its prefix once: the instrument fit of a capture whose bridge
# is drawn on its nut names the file it fitted.
cp -r cap noinst
/usr/bin/python3 -c "
import json, numpy as np
names = json.load(open('res/result.json'))['keypoint_names']
k = np.load('noinst/keypoints2d.npy')
for side in 'lr':
    k[:, :, names.index('bridge_' + side)] = k[:, :, names.index('nut_' + side)]
np.save('noinst/keypoints2d.npy', k)"
"$arco" run noinst -o w/noinst >log 2>err
rc=$?
check '[ $rc -eq 1 ] && grep -q "^arco: error: w/noinst/triangulation/points3d.npy: instrument fit: " err && ! grep -q "instrument fit: instrument fit" err' \
  "run: the instrument fit's error names the file, its prefix once: exit $rc: $(cat err)"
rm -rf w/noinst

[ $fail -eq 0 ] && echo "bad content CLI: all checks passed"
exit $fail
