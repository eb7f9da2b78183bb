#!/usr/bin/env bash
# End-to-end checks of `arco calibration show/convert` on the real SPD files:
# JSON shape and conventions, conversions, and bad input (one error line, exit 1,
# no output file); and `arco calibrate` on OpenCV's stereo pairs (opencv-doc): the
# calibration reads back, the report's figures, --origin board, --intrinsics with
# --fix-intrinsics. usage: calibration_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$1
spd=$2/spd
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"

"$arco" calibration show "$spd/cello_1113_scale_camera.xml" --json >"$tmp/show.json" 2>"$tmp/err"
check '[ $? -eq 0 ] && [ ! -s "$tmp/err" ]' "show --json exits 0 without warnings"
check '/usr/bin/python3 - "$tmp/show.json" "$spd/cello_1113_scale_camera.json" <<"PY"
import json, sys
show = json.load(open(sys.argv[1]))
spd = json.load(open(sys.argv[2]))
assert list(show) == ["cameras"], list(show)
cams = show["cameras"]
assert len(cams) == 20
serials = ["21334181","21334237","21334180","21334209","21334208","21334186","21293326",
           "21293325","21293324","21334206","21334220","21334183","21334207","21334191",
           "21334184","21334238","21334221","21334219","21334190","21334211"]
by_serial = {c["serial"]: c for c in cams}
for i, serial in enumerate(serials):
    c, s = by_serial[serial], spd["cam%d" % i]
    assert set(c) == {"name","serial","width","height","K","R","t","distortion"}, set(c)
    assert c["name"] == "camera_%s_1" % serial
    assert (c["width"], c["height"]) == (2300, 2656)
    assert max(abs(a - b) for a, b in zip(c["R"], s["R"])) < 1e-12
    assert max(abs(a - b) for a, b in zip(c["t"], s["T"])) < 1e-12
    # OpenCV pixel centre vs the SPD file, which keeps Metashape corner origin.
    assert abs(c["K"][2] - (s["K"][2] - 0.5)) < 1e-9 and abs(c["K"][5] - (s["K"][5] - 0.5)) < 1e-9
    assert c["K"][0] == s["K"][0] and c["K"][4] == s["K"][4]
    d = c["distortion"]
    assert (d["k1"], d["k2"], d["p1"], d["p2"], d["k3"]) == (s["distort"][0], s["distort"][1], s["distort"][3], s["distort"][2], s["distort"][4])
PY' "show --json agrees with the authors' JSON"

"$arco" calibration show "$spd/cello_1113_pgy_camera.xml" --json >"$tmp/pgy.json"
check '/usr/bin/python3 -c "import json,sys; c=json.load(open(sys.argv[1]))[\"cameras\"]; assert all(x[\"K\"][2]==1149.5 and x[\"K\"][5]==1327.5 for x in c)" "$tmp/pgy.json"' \
  "pgy principal point is the image centre"

check '"$arco" calibration show "$spd/camera.json" | grep -q "spd-json, 20 cameras, world units: metashape"' "table header"

for out in rig.yaml rig.xml rig.json; do
  "$arco" calibration convert "$spd/camera.xml" "$tmp/$out" >/dev/null
  check '[ $? -eq 0 ]' "convert to $out"
  "$arco" calibration show "$tmp/$out" --json >"$tmp/$out.show"
  "$arco" calibration show "$spd/camera.xml" --json >"$tmp/orig.show"
  check 'cmp -s "$tmp/$out.show" "$tmp/orig.show"' "$out round trip prints the same JSON"
done
"$arco" calibration convert "$spd/camera.xml" "$tmp/spd.json" --format spd >/dev/null
check '/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert sorted(d)==sorted(\"cam%d\"%i for i in range(20))" "$tmp/spd.json"' \
  "--format spd writes camN keys"

# Bad input: one line naming the file, exit 1, no output file.
printf '<document><chunk><sensors>' >"$tmp/truncated.xml"
for bad in "$tmp/missing.xml" "$tmp/truncated.xml"; do
  "$arco" calibration convert "$bad" "$tmp/out.yaml" >/dev/null 2>"$tmp/err"
  rc=$?
  check '[ $rc -eq 1 ] && [ $(wc -l <"$tmp/err") -eq 1 ] && grep -q "$bad" "$tmp/err"' "error line for $bad"
  check '[ ! -e "$tmp/out.yaml" ] && [ -z "$(ls "$tmp" | grep out.yaml)" ]' "no output for $bad"
done
"$arco" calibration convert "$spd/camera.xml" "$tmp/out.txt" >/dev/null 2>"$tmp/err"
check '[ $? -eq 1 ] && grep -q "out.txt" "$tmp/err" && [ ! -e "$tmp/out.txt" ]' "unknown extension"
"$arco" calibration show "$tmp/truncated.xml" >/dev/null 2>"$tmp/err"
check '[ $? -eq 1 ] && grep -q "malformed XML" "$tmp/err"' "show on malformed XML"

# arco calibrate on OpenCV's stereo pairs.
data=/usr/share/doc/opencv-doc/examples/data
mkdir -p "$tmp/L" "$tmp/R"
for f in "$data"/left[0-9][0-9].jpg; do ln -s "$f" "$tmp/L/"; done
for f in "$data"/right[0-9][0-9].jpg; do ln -s "$f" "$tmp/R/"; done
K=(calibrate --board chessboard:9x6:25 --images left="$tmp/L" --images right="$tmp/R")
"$arco" "${K[@]}" -o "$tmp/rig.json" >"$tmp/cal.out" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ]' "calibrate: $(tail -1 "$tmp/err")"
check 'grep -q "calibrated 2 cameras from chessboard:9x6:25 boards; world: left, mm" "$tmp/cal.out"' \
  "calibrate prints its summary: $(head -1 "$tmp/cal.out")"
"$arco" calibration show "$tmp/rig.json" --json >"$tmp/rig.show"
check '/usr/bin/python3 - "$tmp/rig.show" "$tmp/rig.report.json" <<EOF
import json, sys
rig = json.load(open(sys.argv[1])); rep = json.load(open(sys.argv[2]))
cams = rig["cameras"]
assert [c["name"] for c in cams] == ["left", "right"], cams
assert cams[0]["R"] == [1, 0, 0, 0, 1, 0, 0, 0, 1] and cams[0]["t"] == [0, 0, 0], cams[0]
baseline = sum(x * x for x in cams[1]["t"]) ** 0.5
assert 80 < baseline < 87, baseline            # about 3.3 squares of 25 mm
assert rep["rms_px"] < 0.3 and rep["warnings"] == [], rep
assert rep["pairs"] == [{"cameras": ["left", "right"], "shared_frames": 13}], rep["pairs"]
assert rep["board_triangulation"]["rms_mm"] < 0.6, rep["board_triangulation"]
assert rep["bundle_adjustment"]["termination"] == "CONVERGENCE", rep["bundle_adjustment"]
EOF' "calibrate: the calibration and the report"
# Repeat runs write the same calibration bit for bit, with one thread or all: separate
# processes (calibrateCamera's result moved between them by 2e-9 px, which the former
# rounding split in half the runs on these pairs).
same=1
for i in 1 2 3 4; do
  "$arco" "${K[@]}" $([ $i -gt 2 ] && echo --threads 1) -o "$tmp/again$i.json" >/dev/null 2>&1
  cmp -s "$tmp/rig.json" "$tmp/again$i.json" || same=0
  cmp -s "$tmp/rig.report.json" "$tmp/again$i.report.json" || same=0
done
check '[ $same -eq 1 ]' "calibrate: four repeat runs (two with --threads 1) write the same file and report"
# The first camera given is the world, whichever flag gives it.
"$arco" calibrate --board chessboard:9x6:25 --images right="$tmp/R" --video left="$tmp/L" \
  -o "$tmp/order.json" >"$tmp/order.out" 2>"$tmp/err"
check 'grep -q "world: right, mm" "$tmp/order.out"' "calibrate: the first camera given is the origin: $(head -1 "$tmp/order.out") $(cat "$tmp/err")"
"$arco" "${K[@]}" --origin board --intrinsics "$tmp/rig.json" --fix-intrinsics -o "$tmp/rig2.yaml" >/dev/null 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ]' "calibrate --origin board --intrinsics --fix-intrinsics: $(tail -1 "$tmp/err")"
"$arco" calibration show "$tmp/rig2.yaml" --json >"$tmp/rig2.show"
check '/usr/bin/python3 - "$tmp/rig.show" "$tmp/rig2.show" "$tmp/rig2.report.json" <<EOF
import json, sys
a = json.load(open(sys.argv[1]))["cameras"]; b = json.load(open(sys.argv[2]))["cameras"]
rep = json.load(open(sys.argv[3]))
assert rep["origin"].startswith("board@"), rep["origin"]
assert all(c["intrinsics_given"] for c in rep["cameras"]), rep["cameras"]
for x, y in zip(a, b):
    assert all(abs(p - q) < 1e-9 * max(1, abs(p)) for p, q in zip(x["K"], y["K"])), (x["K"], y["K"])
    assert x["distortion"] == y["distortion"] or all(abs(x["distortion"][k] - y["distortion"][k]) < 1e-12 for k in x["distortion"])
assert b[0]["t"] != [0, 0, 0]                  # the world is the board now
EOF' "calibrate --origin board --fix-intrinsics keeps the given intrinsics"

# arco calibrate check: a synthetic capture against its own calibration (nothing flagged)
# and against a copy with one camera turned by 1 degree about its centre (flagged).
"$arco" synth --duration-s 1 --no-audio -o "$tmp/cap" >/dev/null 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ]' "synth for check: $(tail -1 "$tmp/err")"
"$arco" calibrate check "$tmp/cap" >"$tmp/check.out" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ] && grep -q "no camera flagged" "$tmp/check.out"' "check: $(tail -2 "$tmp/check.out") $(cat "$tmp/err")"
/usr/bin/python3 - "$tmp/cap/calibration.json" "$tmp/turned.json" <<EOF
import json, math, sys
d = json.load(open(sys.argv[1]))
a = math.radians(1)
ry = [[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]]
cam = d["cameras"][3]
R = [cam["R"][0:3], cam["R"][3:6], cam["R"][6:9]]
cam["R"] = [sum(ry[i][k] * R[k][j] for k in range(3)) for i in range(3) for j in range(3)]
cam["t"] = [sum(ry[i][k] * cam["t"][k] for k in range(3)) for i in range(3)]
json.dump(d, open(sys.argv[2], "w"))
EOF
name=$(/usr/bin/python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['cameras'][3]['name'])" "$tmp/cap/calibration.json")
# A flagged camera: exit 3 (checked, found problems), as a linter does; the warning on
# stderr, the table on stdout.
"$arco" calibrate check "$tmp/cap" --calibration "$tmp/turned.json" >"$tmp/check_turned.out" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 3 ] && grep -q "FLAGGED" "$tmp/check_turned.out" && ! grep -q "warning" "$tmp/check_turned.out" && grep -q "^warning: $name: residuals stand out" "$tmp/err"' \
  "check of a turned camera exits 3 with its warning on stderr: exit $rc: $(cat "$tmp/err")"
"$arco" calibrate check "$tmp/cap" --calibration "$tmp/turned.json" --json >"$tmp/check.json" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 3 ] && /usr/bin/python3 -c "import json, sys; d = json.load(open(sys.argv[1])); assert d[\"flagged\"] == [sys.argv[2]], d[\"flagged\"]" "$tmp/check.json" "$name"' \
  "check flags the turned camera $name: $(cat "$tmp/err")"
"$arco" calibrate check "$tmp/cap" --calibration "$tmp/missing.json" >/dev/null 2>"$tmp/err"
rc=$?
check '[ $rc -eq 1 ] && [ $(wc -l <"$tmp/err") -eq 1 ] && grep -q "^arco: error: $tmp/missing.json" "$tmp/err"' "check: missing calibration: $(cat "$tmp/err")"

# calibrate check on a result folder (arco triangulate's): its points against its capture.
"$arco" triangulate "$tmp/cap" -o "$tmp/res" >/dev/null 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ]' "triangulate for check: $(tail -1 "$tmp/err")"
"$arco" calibrate check "$tmp/res" >"$tmp/check_res.out" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ] && grep -q "no camera flagged" "$tmp/check_res.out"' "check on a result: $(tail -2 "$tmp/check_res.out") $(cat "$tmp/err")"
"$arco" calibrate check "$tmp/res" --calibration "$tmp/turned.json" --json >"$tmp/check_res.json" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 3 ] && /usr/bin/python3 -c "import json, sys; d = json.load(open(sys.argv[1])); assert d[\"flagged\"] == [sys.argv[2]] and d[\"result\"] == sys.argv[3], d" "$tmp/check_res.json" "$name" "$tmp/res"' \
  "check on a result flags the turned camera $name: $(cat "$tmp/err")"

# arco calibrate refine: the turned copy refined with the capture's keypoints and the
# instrument (camera 0 held fixed): the turned camera turns back by about 1 degree
# (8 frames of the 1-second capture: 0.99 degrees; 15 frames: 1.02, twice the time).
"$arco" calibrate refine "$tmp/cap" --calibration "$tmp/turned.json" --max-frames 8 -o "$tmp/refined.json" >"$tmp/refine.out" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ] && [ -f "$tmp/refined.json" ] && /usr/bin/python3 -c "
import json, sys
r = json.load(open(sys.argv[1]))
c = r[\"cameras\"][3]
assert 0.9 < c[\"rotation_change_deg\"] < 1.1, c
assert c[\"rms_after_px\"] < 0.2 * c[\"rms_before_px\"], c
assert r[\"cameras\"][0][\"reference\"] and r[\"cameras\"][0][\"rotation_change_deg\"] == 0, r[\"cameras\"][0]
" "$tmp/refined.report.json"' "refine turns camera 3 back: $(tail -3 "$tmp/refine.out") $(cat "$tmp/err")"
"$arco" calibrate refine "$tmp/cap" --calibration "$tmp/turned.json" --max-frames 8 -o "$tmp/refined.json" >/dev/null 2>"$tmp/err"
rc=$?
check '[ $rc -eq 1 ] && [ $(wc -l <"$tmp/err") -eq 1 ] && grep -q "exists; give --overwrite" "$tmp/err"' "refine: existing output: $(cat "$tmp/err")"
"$arco" calibrate refine "$tmp/cap" --min-score 1 -o "$tmp/none.json" >/dev/null 2>"$tmp/err"
rc=$?
check '[ $rc -eq 1 ] && [ $(wc -l <"$tmp/err") -eq 1 ] && grep -q "keypoints2d.npy: only" "$tmp/err" && [ ! -e "$tmp/none.json" ] && [ ! -e "$tmp/none.report.json" ]' "refine: too few keypoints: $(cat "$tmp/err")"

# arco calibrate from-instrument: two of the SPD rig's cameras (distortion removed), a
# 4-second synthetic take, the true focal length held (with it free, two views fix it
# poorly: docs/calibration.md): the camera pair against the truth within 1 degree and
# 20 mm; then bad input. PnP poses come from every frame; the bundle adjustment uses 30
# frames spread over the take (the default, all 135, takes five times as long for the same
# pair: 0.39 degrees and 14 mm either way).
"$arco" calibration show "$spd/cello_1113_scale_camera.xml" --json | /usr/bin/python3 -c "
import json, sys
d = json.load(sys.stdin)
d['cameras'] = [d['cameras'][0], d['cameras'][18]]
for c in d['cameras']:
    c['distortion'] = {k: 0 for k in c['distortion']}
json.dump(d, open(sys.argv[1], 'w'))" "$tmp/two.json"
"$arco" synth --calibration "$tmp/two.json" --duration-s 4 -o "$tmp/two" >/dev/null 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ]' "synth two cameras: $(tail -1 "$tmp/err")"
"$arco" calibrate from-instrument "$tmp/two" --image-size 2300x2656 --focal-px 2261.66 --fix-focal --max-frames 30 -o "$tmp/fi.json" >"$tmp/fi.out" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ] && [ -f "$tmp/fi.report.json" ] && grep -q "focal from --focal-px" "$tmp/fi.out" && /usr/bin/python3 - "$tmp/two/calibration.json" "$tmp/fi.json" "$tmp/fi.report.json" <<"PY"
import json, math, sys
def mat(v): return [v[0:3], v[3:6], v[6:9]]
def mul(A, B): return [[sum(A[i][k] * B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
def tr(A): return [list(r) for r in zip(*A)]
def app(A, x): return [sum(A[i][k] * x[k] for k in range(3)) for i in range(3)]
def rel(path):
    c = json.load(open(path))["cameras"]
    R0, t0, R1, t1 = mat(c[0]["R"]), c[0]["t"], mat(c[1]["R"]), c[1]["t"]
    centre1 = [-x for x in app(tr(R1), t1)]
    return mul(R1, tr(R0)), [a + b for a, b in zip(app(R0, centre1), t0)]
(Rt, ct), (Re, ce) = rel(sys.argv[1]), rel(sys.argv[2])
D = mul(tr(Rt), Re)
deg = math.degrees(math.acos(max(-1, min(1, (D[0][0] + D[1][1] + D[2][2] - 1) / 2))))
mm = math.dist(ct, ce)
assert deg < 1 and mm < 20, (deg, mm)
r = json.load(open(sys.argv[3]))
assert r["world"].startswith("the first camera") and r["rms_px"] < 3, r
assert abs(r["string_length_mm"] - 695) < 1e-9 and r["cameras"][0]["pnp_frames"] > 0, r
assert abs(r["string_length_measured"]["error_mm"]) < 3, r["string_length_measured"]
PY' "from-instrument recovers the pair: $(tail -2 "$tmp/fi.out") $(cat "$tmp/err")"
# --labels: labelme files of one frame (as `arco track --labels`); bad ones are one line
# naming the file.
cam0=$(/usr/bin/python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['cameras'][0]['name'])" "$tmp/two/capture.json")
echo '{"shapes": [{"label": "fingerboard", "points": [[10, 10]], "shape_type": "point"}]}' >"$tmp/odd.json"
for bad in "--labels nosuch=$tmp/odd.json:odd.json: camera nosuch is not in .*capture.json (cameras: " \
           "--labels $cam0=$tmp/odd.json:odd.json: 0 of the cello's points are labelled (not its points: fingerboard), a camera's pose needs 5 (scroll_top, " \
           "--labels justtext:--labels .justtext. must look like CAMERA=LABELME.json" \
           "--labels $cam0@3=$tmp/odd.json:must look like CAMERA=LABELME.json (the labels of --labels-frame)" \
           "--labels $cam0=$tmp/odd.json --labels-frame -2:--labels-frame" \
           "--min-score 1:keypoints2d.npy: camera .* never shows 5 of the cello" \
           ":capture.json: camera .* has no video to read its image size from" \
           "--image-size 12by4:--image-size: .12by4. is not WIDTHxHEIGHT" \
           "--focal-px 1000 --fov-deg 60:give one of them, not both"; do
  args=${bad%%:*} want=${bad#*:}
  [ "$args" = "${args#--image-size}" ] && [ -n "$args" ] && args="$args --image-size 2300x2656"
  "$arco" calibrate from-instrument "$tmp/two" $args -o "$tmp/bad.json" >/dev/null 2>"$tmp/err"
  rc=$?
  check '[ $rc -ne 0 ] && [ $(wc -l <"$tmp/err") -eq 1 ] && grep -q -- "$want" "$tmp/err" && [ ! -e "$tmp/bad.json" ] && [ ! -e "$tmp/bad.report.json" ]' \
    "from-instrument bad input ($args): exit $rc: $(cat "$tmp/err")"
done

# calibrate check on the real SPD labelled views of frame 128: nothing flagged with the
# session's calibration.
V=()
for s in 21334181 21334190 21334211 21334237; do
  V+=(--view "$s=$spd/labels_frame128/cello_1113_scale_${s}_128.json")
done
"$arco" calibrate check --calibration "$spd/cello_1113_scale_camera.xml" "${V[@]}" >"$tmp/spd.out" 2>"$tmp/err"
rc=$?
check '[ $rc -eq 0 ] && grep -q "no camera flagged" "$tmp/spd.out"' "check on the SPD labels: $(cat "$tmp/spd.out" "$tmp/err")"
"$arco" calibrate check "${V[@]}" >/dev/null 2>"$tmp/err"
rc=$?
check '[ $rc -eq 1 ] && grep -q "^arco: error: --view needs --calibration" "$tmp/err"' "check --view without --calibration: $(cat "$tmp/err")"

[ $fail -eq 0 ] && echo "calibration CLI: all checks passed"
exit $fail
