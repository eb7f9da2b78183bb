#!/usr/bin/env bash
# One camera (issue 26 part 4): SPD's real cellist (cello01, first 11 s, real audio)
# re-captured by `arco synth --motion` in ONE camera of the SPD rig, then `arco run` and
# `arco eval`. One view fixes no depth: the instrument is placed by a PnP of its nominal
# points, the left hand at the depth of the strings its fingertips pass closest to, the
# body at an assumed depth, the bow not at all (track/monocular_lift.h). Checks that the run
# completes, that every lifted point says where its depth came from
# (triangulation/depth_source.npy, result.json), and the accuracy reached today in the
# instrument's frame (regression bounds, not the issue's targets: docs/accuracy.md, "One
# camera"). Also: a one-camera capture without the instrument is one line naming the file.
# usage: one_camera_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$1
spd=$2/spd
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
take="$spd/cello01_first_half_results.npy"
wav="$spd/cello01_first_half.wav"
rig="$spd/cello_1113_scale_camera.xml"

ok "re-capture" synth --motion "$take" --audio "$wav" --calibration "$rig" \
  --error-model shared --cameras 1 --seed 1 -o "$tmp/cap"
ok "run" run "$tmp/cap" -o "$tmp/res"
check 'grep -q "one camera" "$tmp/err" "$tmp/out"' "the run says the hand's depth is the strings'"
ok "eval" eval "$tmp/res" --truth "$tmp/cap/truth" -o "$tmp/eval.json"
/usr/bin/python3 - "$tmp" "$(dirname "${BASH_SOURCE[0]}")/../../scripts" <<'PY' || fail=1
import json, sys
import numpy as np
tmp = sys.argv[1]
r = json.load(open(tmp + "/res/result.json"))
bad = []
tri = r["stages"]["triangulation"]
if tri.get("depth", {}).get("method") != "one_view": bad.append("result.json has no one_view depth")
if len(tri["depth"].get("camera_centre_in_world", [])) != 3: bad.append("no camera centre in result.json")
names = r["keypoint_names"]
d = np.load(tmp + "/res/triangulation/" + tri["files"]["depth_source"])
p = np.load(tmp + "/res/triangulation/points3d.npy")
col = lambda n: names.index(n)
lh = list(range(col("left_hand_wrist"), col("left_hand_wrist") + 21))
checks = [("instrument", [col("nut_l"), col("bridge_r")], 1), ("left hand", lh, 2),
          ("shoulders", [col("left_shoulder"), col("right_shoulder")], 3)]
for what, cols, code in checks:
    got = d[:, cols]
    lifted = got[got != 0]
    if lifted.size == 0 or not np.all(lifted == code):
        bad.append("%s: depth codes %s, expected %d" % (what, np.unique(got), code))
for n in ("frog", "tip"):
    if not (np.all(d[:, col(n)] == 0) and np.all(np.isnan(p[:, col(n)]))):
        bad.append("the bow's %s was lifted (one view cannot place it)" % n)
if not np.array_equal(np.isnan(p[..., 0]), d == 0): bad.append("a NaN point has a depth code")

# The left hand in the instrument's frame (scripts/hand_in_instrument.py).
sys.path.insert(0, sys.argv[2])
from hand_in_instrument import left_hand_in_instrument
res = {}
for m in ("vision", "paper", "arco"):
    res[m] = left_hand_in_instrument(tmp + "/res", tmp + "/cap/truth/points3d.npy", m)
    print("%-6s left hand in the instrument's frame: median %.1f mm, within 15 mm on %.3f of "
          "frames (a hand on %.3f)" % ((m,) + res[m]))
j = json.load(open(tmp + "/eval.json"))["methods"]
for m in ("paper", "arco"):
    print("%-6s string %.3f finger %.3f contact %.1f mm" % (m, j[m]["string_accuracy"],
          j[m]["finger_accuracy"], j[m]["contact_point_error_mm"]))
# Today's figures with a margin (median 25 mm, paper's string agreement 0.90); before the
# one-camera lift `arco run` stopped, and with the hand lifted to the strings' plane and
# its bones measured from the lift the median was 680 mm.
if not res["vision"][0] <= 35: bad.append("vision's left hand median %.1f mm > 35" % res["vision"][0])
if not res["vision"][2] >= 0.9: bad.append("hand fitted on %.3f of frames" % res["vision"][2])
if not j["paper"]["string_accuracy"] >= 0.8: bad.append("paper's strings %.3f" % j["paper"]["string_accuracy"])
# arco's own decisions and hand (this capture, `shared` seed 1: strings 0.996, fingers
# 0.874, median 17.4 mm, within 15 mm on 0.324 of frames (vision 0.264), its contact 4.4 mm
# (mean) and 2.2 mm (median) from SPD's in the instrument's frame, 53.8 mm in the world; the
# clang sanitizer build: 1.000, 0.905, 20.2 mm, 0.267 (vision 0.182), 4.2 / 2.2 mm, 31.6 mm;
# docs/accuracy.md, "One camera: the instrument's real shape and the image across the
# string" and the sections after it). The capture is not the one the former bounds
# (strings 0.9, fingers 0.65, within 15 mm 0.33) were set on: `arco synth --motion` places
# the take by the instrument's nominal shape, which is now the real cello's, and this camera
# sees the bridge on 35 % of the frames instead of 97 %; the former code gives strings 0.179,
# fingers 0.130, within 15 mm 0.024 on it (a frame's own PnP held on 17 of its 330 frames).
# The sound must keep the hand ahead of vision in the instrument's frame.
if not j["arco"]["string_accuracy"] >= 0.95: bad.append("arco's strings %.3f" % j["arco"]["string_accuracy"])
if not j["arco"]["finger_accuracy"] >= 0.8: bad.append("arco's fingers %.3f" % j["arco"]["finger_accuracy"])
# (0.512 in the gcc Release build with the hand blended with its other times on the same
# note, RefineOptions::one_view_same_note_weight, 0.488 without it; 0.252 in the clang
# sanitizer build (vision 0.182) before it; with the refined hand held over +-0.2 s,
# RefineOptions::one_view_smoothing_s, 0.430 without it and with the palm as one piece,
# HandStageOptions::one_view_palm_as_one, 0.376 without it and with the other fingertips at
# their places in the hand frame, RefineOptions::one_view_hand_frame, 0.324 without either; 0.267 without in the clang
# sanitizer build: the one-view PnP and the hand fit stop elsewhere within their
# tolerances. Before a cello's depth was held over +-250 frames,
# MonocularLiftOptions::end_pin_depth_window_frames: 0.230 and 0.191.)
if not res["arco"][1] >= 0.24: bad.append("arco's hand within 15 mm on %.3f of frames" % res["arco"][1])
# The contact in the world: the instrument's distance from the one camera, held over the
# take for a cello on its end pin (82.2 mm with +-90 frames).
if not j["arco"]["contact_point_error_mm"] <= 70:
    bad.append("arco's contact %.1f mm from SPD's in the world" % j["arco"]["contact_point_error_mm"])
if not res["arco"][1] >= res["vision"][1] + 0.05:
    bad.append("arco's hand within 15 mm on %.3f of frames, vision's %.3f" % (res["arco"][1], res["vision"][1]))
from hand_in_instrument import contact_in_instrument
contact = contact_in_instrument(tmp + "/res", tmp + "/cap/truth/points3d.npy", "arco")
print("arco   contact in the instrument's frame: mean %.2f mm, median %.2f mm, within 5 mm on "
      "%.3f of %d frames" % contact)
if not contact[1] <= 3.5: bad.append("arco's contact %.2f mm from SPD's (median)" % contact[1])
if not contact[0] <= 7: bad.append("arco's contact %.2f mm from SPD's (mean)" % contact[0])
if not res["arco"][0] < res["vision"][0]:
    bad.append("arco's left hand %.1f mm, not below vision's %.1f" % (res["arco"][0], res["vision"][0]))
for b in bad: print("FAILED: " + b)
sys.exit(1 if bad else 0)
PY

# `arco refine` refines from the folder what `arco run` refined (the camera's centre is in
# result.json): the same bytes.
cp "$tmp/res/arco/points3d.npy" "$tmp/arco_run.npy"
cp "$tmp/res/arco/contacts.csv" "$tmp/arco_run.csv"
ok "refine" refine "$tmp/res" --mode arco
check 'cmp -s "$tmp/arco_run.npy" "$tmp/res/arco/points3d.npy" && cmp -s "$tmp/arco_run.csv" "$tmp/res/arco/contacts.csv"' \
  "arco refine differs from arco run on a one-camera result"

# A one-camera capture whose view never shows the instrument: one line naming the file.
cp -r "$tmp/cap" "$tmp/blind"
/usr/bin/python3 - "$tmp/blind/keypoints2d.npy" <<'PY'
import numpy as np, sys
k = np.load(sys.argv[1]); k[:, :, 133:140, 2] = 0; np.save(sys.argv[1], k)
PY
SNAPSHOT_DIR=$tmp
bad_at "no instrument in the view" "$tmp/blind/keypoints2d.npy" run "$tmp/blind" -o "$tmp/res2"
exit $fail
