#!/usr/bin/env bash
# `arco detect` from the command line on a capture of opencv-doc's messi5.jpg (a real
# photo, as a 1-frame video in two cameras, one stored turned): what it prints and
# writes, and every bad input as one line "arco: error: ...", exit 1, nothing written.
# Needs the models (scripts/setup); without them it skips (exit 77) unless CI is set.
# usage: detect_cli_test.sh ARCO_BINARY MODELS_DIR
set -uo pipefail
arco=$(realpath "$1")
models=$2
photo=/usr/share/doc/opencv-doc/examples/data/messi5.jpg
if [ ! -f "$models/pose_detection.onnx" ]; then
  echo "$models/pose_detection.onnx is missing: run scripts/setup"
  [ -n "${CI:-}" ] && exit 1
  exit 77
fi
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
  --fps 30 -o cap >/dev/null || { echo "FAILED: capture new"; exit 1; }

# Bad input first (the capture has no keypoints yet).
bad "frames syntax" '--frames "5" must look like FIRST:LAST' detect cap --frames 5
bad "frames outside" "outside the capture's frames 1:1" detect cap --frames 1:4
bad "threads range" "--threads: -1 is outside" detect cap --threads -1
bad "hand gate range" "--hand-gate: 3 is outside" detect cap --hand-gate 3
bad "score range" "--min-hand-presence: nan is not a finite number" detect cap --min-hand-presence nan
bad "unknown model" "--model" detect cap --model tiny
bad "no capture" "nowhere/capture.json" detect nowhere
bad "missing models" "nomodels/pose_detection.onnx: model file not found; run scripts/setup" \
  detect cap --models-dir nomodels
# A capture made from keypoints (no videos) says how to make one from videos.
"$arco" synth -o syn --duration-s 1 >/dev/null 2>&1 || { echo "FAILED: synth"; exit 1; }
bad "no video" "has no video" detect syn
check '[ ! -e cap/keypoints2d.npy ]' "a failed detect wrote keypoints"

# The real run.
"$arco" detect cap --threads 2 >out.txt 2>err.txt
rc=$?
check '[ $rc -eq 0 ]' "detect: exit $rc: $(tail -1 err.txt)"
check 'grep -q "detected frames 1:1 in 2 cameras (layout coco_wholebody_133)" out.txt' "summary: $(cat out.txt)"
check 'grep -Eq "front +1 frames  person 100.0%" out.txt' "front camera line: $(cat out.txt)"
check 'grep -q "wrote cap/keypoints2d.npy, detect.json and capture.json" out.txt' "wrote line"
check 'grep -q "hands across views: not checked (fewer cameras than hands.min_views)" out.txt' "hands line: $(cat out.txt)"
/usr/bin/python3 - <<'PY' || { echo "FAILED: keypoints2d.npy"; fail=1; }
import json
import numpy as np
k = np.load("cap/keypoints2d.npy")
assert k.shape == (1, 2, 133, 3) and k.dtype == np.float32, (k.shape, k.dtype)
assert np.array_equal(k[0, 0], k[0, 1], equal_nan=True), "same picture, same keypoints"
body = k[0, 0, :17]
assert np.all(body[:, 2] > 0.5), body[:, 2]
assert np.all((body[:, 0] > 0) & (body[:, 0] < 548) & (body[:, 1] > 0) & (body[:, 1] < 342))
assert np.all(np.isnan(k[0, 0, 23:91])), "face points stay NaN"
j = json.load(open("cap/capture.json"))
assert j["keypoints2d"] == {"file": "keypoints2d.npy", "layout": "coco_wholebody_133"}, j
PY
ls -a cap | grep -q '^\.tmp' && { echo "FAILED: temporaries left in cap/"; fail=1; }
exit $fail
