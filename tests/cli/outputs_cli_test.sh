#!/usr/bin/env bash
# Output paths of every command that writes (docs/architecture.md, "Outputs"): a trailing
# slash names the same folder; an existing output folder is replaced only with --overwrite
# (and only when it is the command's own kind), an existing file path that is a folder, a
# missing or uncreatable parent (a path under a regular file: tests run as root, so
# chmod would not stop them) and a second output in a missing folder are each one line
# "arco: error: PATH: ...", a non-zero exit, and no change at all in the working folder.
# usage: outputs_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$1
spd=$2/spd
calib=$spd/cello_1113_scale_camera.xml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
w=$tmp/w
SNAPSHOT_DIR=$w
mkdir -p "$w" "$tmp/in/h/21334181" "$tmp/in/h/21334237"

echo "not a folder" >"$w/file"
mkdir -p "$w/photos" "$w/dir"
echo "precious" >"$w/photos/a.jpg"

# synth: a capture folder.
S=(synth --calibration "$calib" --duration-s 1 --no-audio)
ok "synth -o cap/" "${S[@]}" -o "$w/cap/"
check '[ -f "$w/cap/capture.json" ] && [ -f "$w/cap/truth/points3d.npy" ]' "synth -o cap/ writes cap"
bad_at "synth over a capture" "$w/cap" "${S[@]}" -o "$w/cap/"
echo old >"$w/cap/old.txt"
ok "synth --overwrite" "${S[@]}" --seed 1 -o "$w/cap/" --overwrite
check '[ -f "$w/cap/capture.json" ] && [ ! -e "$w/cap/old.txt" ]' "synth --overwrite replaces the capture"
bad_at "synth --overwrite over another folder" "$w/photos" "${S[@]}" -o "$w/photos" --overwrite
bad_at "synth over a file" "$w/file" "${S[@]}" -o "$w/file" --overwrite
bad_at "synth under a file" "$w/file/sub/cap" "${S[@]}" -o "$w/file/sub/cap"
ok "synth into a missing parent" "${S[@]}" -o "$w/new/parent/cap"
rm -rf "$w/new"

# import-spd: a capture folder.
I=(import-spd --calibration "$calib" --human "$tmp/in/h" --serials 21334181 --serials 21334237
   --first 1 --last 2)
ok "import-spd -o imp/" "${I[@]}" -o "$w/imp/"
check '[ -f "$w/imp/capture.json" ] && grep -q "\"name\": \"imp\"" "$w/imp/capture.json"' "import-spd -o imp/ names the capture imp"
bad_at "import-spd over a capture" "$w/imp" "${I[@]}" -o "$w/imp"
ok "import-spd --overwrite" "${I[@]}" -o "$w/imp/" --overwrite
bad_at "import-spd --overwrite over another folder" "$w/photos" "${I[@]}" -o "$w/photos/" --overwrite
bad_at "import-spd under a file" "$w/file/imp" "${I[@]}" -o "$w/file/imp"

# capture new: a capture folder referencing its videos (here one 2300x2656 image, SPD's
# rotated frame size); capture import-keypoints: keypoints2d.npy and capture.json together.
/usr/bin/python3 - "$tmp/in/frame.png" <<'PY'
import struct, sys, zlib
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
rows = b"".join(b"\0" + b"\x80" * 2300 for _ in range(2656))
header = struct.pack(">IIBBBBB", 2300, 2656, 8, 0, 0, 0, 0)
open(sys.argv[1], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
                              chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
PY
C=(capture new --calibration "$calib" --video "21334181=$tmp/in/frame.png" --fps 30)
ok "capture new -o new/" "${C[@]}" -o "$w/new/"
check '[ -f "$w/new/capture.json" ] && grep -q "\"name\": \"new\"" "$w/new/capture.json"' "capture new -o new/ writes new"
bad_at "capture new over a capture" "$w/new" "${C[@]}" -o "$w/new"
ok "capture new --overwrite" "${C[@]}" -o "$w/new/" --overwrite
bad_at "capture new --overwrite over another folder" "$w/photos" "${C[@]}" -o "$w/photos/" --overwrite
bad_at "capture new under a file" "$w/file/new" "${C[@]}" -o "$w/file/new"
echo '[{"frame_id": 0, "instances": []}]' >"$tmp/in/mm.json"
K=(capture import-keypoints --format mmpose --camera "21334181=$tmp/in/mm.json")
mkdir "$w/new/keypoints2d.npy"
bad_at "capture import-keypoints onto a folder" "$w/new/keypoints2d.npy" "${K[@]}" "$w/new"
rmdir "$w/new/keypoints2d.npy"
ok "capture import-keypoints" "${K[@]}" "$w/new/"
check '[ -f "$w/new/keypoints2d.npy" ] && grep -q "keypoints2d.npy" "$w/new/capture.json"' "capture import-keypoints writes both"

# run: a result folder.
ok "run -o res/" run "$w/cap" -o "$w/res/" --threads 2
check '[ -f "$w/res/result.json" ] && [ -f "$w/res/vision/points3d.npy" ]' "run -o res/ writes res"
bad_at "run over a result" "$w/res" run "$w/cap" -o "$w/res"
echo old >"$w/res/old.txt"
ok "run --overwrite" run "$w/cap" -o "$w/res/" --overwrite --threads 2
check '[ -f "$w/res/result.json" ] && [ ! -e "$w/res/old.txt" ]' "run --overwrite replaces the result"
bad_at "run --overwrite over another folder" "$w/photos" run "$w/cap" -o "$w/photos" --overwrite
bad_at "run under a file" "$w/file/res" run "$w/cap" -o "$w/file/res"

# refine: updates a result folder in place.
ok "refine res/" refine "$w/res/" --mode vision

# triangulate: a capture into a result folder; labelled views into a JSON file.
ok "triangulate -o tri/" triangulate "$w/cap" -o "$w/tri/"
check '[ -f "$w/tri/result.json" ] && [ -f "$w/tri/triangulation/points3d.npy" ]' "triangulate -o tri/ writes tri"
bad_at "triangulate into another folder" "$w/photos" triangulate "$w/cap" -o "$w/photos"
bad_at "triangulate under a file" "$w/file/tri" triangulate "$w/cap" -o "$w/file/tri"
V=(triangulate --calibration "$spd/camera.xml")
for serial in 21334181 21334190 21334211 21334237; do
  V+=(--view "$serial=$spd/labels_frame128/cello_1113_scale_${serial}_128.json")
done
V=(triangulate --calibration "$calib" "${V[@]:3}")
ok "triangulate views" "${V[@]}" -o "$w/points.json"
bad_at "triangulate views into a folder" "$w/dir" "${V[@]}" -o "$w/dir"
bad_at "triangulate views into a missing folder" "$w/nodir/p.json" "${V[@]}" -o "$w/nodir/p.json"
bad_at "triangulate views under a file" "$w/file/p.json" "${V[@]}" -o "$w/file/p.json"

# eval: metrics JSON and plot, both or neither.
E=(eval "$w/res" --truth "$w/cap/truth")
ok "eval -o --plot" "${E[@]}" -o "$w/e.json" --plot "$w/e.svg"
check '[ -s "$w/e.json" ] && [ -s "$w/e.svg" ]' "eval writes both outputs"
rm "$w/e.json" "$w/e.svg"
bad_at "eval plot in a missing folder" "$w/nodir/e.svg" "${E[@]}" -o "$w/e.json" --plot "$w/nodir/e.svg"
bad_at "eval -o a folder" "$w/dir" "${E[@]}" -o "$w/dir"
bad_at "eval plot under a file" "$w/file/e.svg" "${E[@]}" -o "$w/e.json" --plot "$w/file/e.svg"

# export: one file.
X=(export "$w/res" --format c3d --method vision)
ok "export -o" "${X[@]}" -o "$w/x.c3d"
check '[ -s "$w/x.c3d" ]' "export writes its file"
rm "$w/x.c3d"
bad_at "export in a missing folder" "$w/nodir/x.c3d" "${X[@]}" -o "$w/nodir/x.c3d"
mkdir -p "$w/dir.c3d"
bad_at "export -o a folder" "$w/dir.c3d" "${X[@]}" -o "$w/dir.c3d"
bad_at "export under a file" "$w/file/x.c3d" "${X[@]}" -o "$w/file/x.c3d"

# overlay: one video file.
O=(overlay "$w/res" --method vision --camera camera_21334181_1 --frames 1:3 --scale 0.1)
ok "overlay -o" "${O[@]}" -o "$w/o.mkv"
check '[ -s "$w/o.mkv" ]' "overlay writes its video"
rm "$w/o.mkv"
bad_at "overlay in a missing folder" "$w/nodir/o.mkv" "${O[@]}" -o "$w/nodir/o.mkv"
bad_at "overlay -o a folder" "$w/dir" "${O[@]}" -o "$w/dir"
bad_at "overlay under a file" "$w/file/o.mkv" "${O[@]}" -o "$w/file/o.mkv"

# plot: one folder, replaced only with --overwrite and only when it is a plot folder (the
# paths are checked before the work; this result has no fingering to plot, so the written
# and replaced folders are in plot_cli_test).
bad_at "plot over another folder" "$w/photos" plot "$w/res" -o "$w/photos/"
bad_at "plot --overwrite over another folder" "$w/photos" plot "$w/res" -o "$w/photos/" --overwrite
bad_at "plot over a file" "$w/file" plot "$w/res" -o "$w/file" --overwrite
bad_at "plot under a file" "$w/file/plots" plot "$w/res" -o "$w/file/plots"

# view --no-serve: a viewer folder (its marker: manifest.json).
V=(view "$w/res" --no-serve)
ok "view -o page/" "${V[@]}" -o "$w/page/"
check '[ -f "$w/page/index.html" ] && [ -f "$w/page/data.js" ] && [ -f "$w/page/manifest.json" ]' "view -o writes the page"
bad_at "view over a viewer folder" "$w/page" "${V[@]}" -o "$w/page"
echo old >"$w/page/old.txt"
ok "view --overwrite" "${V[@]}" -o "$w/page" --overwrite
check '[ -f "$w/page/index.html" ] && [ ! -e "$w/page/old.txt" ]' "view --overwrite replaces the page"
bad_at "view --overwrite over another folder" "$w/photos" "${V[@]}" -o "$w/photos" --overwrite
bad_at "view over a file" "$w/file" "${V[@]}" -o "$w/file" --overwrite
bad_at "view under a file" "$w/file/sub/page" "${V[@]}" -o "$w/file/sub/page"
rm -rf "$w/page"

# pitch: pitch.csv, --fine, --notes, --midi, all or none.
P=(pitch "$spd/pgy.wav" --frames 60)
ok "pitch every output" "${P[@]}" -o "$w/p.csv" --fine "$w/f.csv" --notes "$w/n.csv" --midi "$w/m.mid"
check '[ -s "$w/p.csv" ] && [ -s "$w/f.csv" ] && [ -s "$w/n.csv" ] && [ -s "$w/m.mid" ]' "pitch writes every output"
rm "$w/p.csv" "$w/f.csv" "$w/n.csv" "$w/m.mid"
bad_at "pitch notes in a missing folder" "$w/nodir/n.csv" "${P[@]}" -o "$w/p.csv" --notes "$w/nodir/n.csv"
bad_at "pitch -o a folder" "$w/dir" "${P[@]}" -o "$w/dir"
bad_at "pitch -o a folder path" "$w/p.csv/" "${P[@]}" -o "$w/p.csv/"
bad_at "pitch midi under a file" "$w/file/m.mid" "${P[@]}" -o "$w/p.csv" --midi "$w/file/m.mid"
echo old >"$w/p.csv"
bad_at "pitch fine in a missing folder keeps the old pitch.csv" "$w/nodir/f.csv" "${P[@]}" -o "$w/p.csv" --fine "$w/nodir/f.csv"
rm "$w/p.csv"

# calibration convert: one file.
ok "calibration convert" calibration convert "$calib" "$w/c.json"
bad_at "calibration convert into a folder" "$w/dir" calibration convert "$calib" "$w/dir"
bad_at "calibration convert into a missing folder" "$w/nodir/c.json" calibration convert "$calib" "$w/nodir/c.json"

# calibrate: the calibration and its report, both or neither.
data=/usr/share/doc/opencv-doc/examples/data
mkdir -p "$tmp/in/L" "$tmp/in/R"
for n in 01 02 03 04 05 06 07 08; do
  ln -s "$data/left$n.jpg" "$tmp/in/L/"; ln -s "$data/right$n.jpg" "$tmp/in/R/"
done
K=(calibrate --board chessboard:9x6:25 --images left="$tmp/in/L" --images right="$tmp/in/R")
ok "calibrate -o rig.json" "${K[@]}" -o "$w/rig.json"
check '[ -f "$w/rig.json" ] && [ -f "$w/rig.report.json" ]' "calibrate writes rig.json and rig.report.json"
ok "calibrate -o rig.yaml over an old report" "${K[@]}" -o "$w/rig.yaml"
check 'grep -q "%YAML" "$w/rig.yaml"' "calibrate -o rig.yaml writes OpenCV YAML"
rm "$w/rig.yaml" "$w/rig.json"
bad_at "calibrate into a folder" "$w/dir" "${K[@]}" -o "$w/dir"
bad_at "calibrate into a missing folder" "$w/nodir/rig.json" "${K[@]}" -o "$w/nodir/rig.json"
bad_at "calibrate under a file" "$w/file/rig.json" "${K[@]}" -o "$w/file/rig.json"
mkdir "$w/r2.report.json"
bad_at "calibrate: the report's path is a folder" "$w/r2.report.json" "${K[@]}" -o "$w/r2.json"
rmdir "$w/r2.report.json"
rm "$w/rig.report.json"

# calibrate refine: the same for its calibration and report; an existing file only with
# --overwrite (on synth's capture from above, which it only reads).
R=(calibrate refine "$w/cap" --max-frames 5)
bad_at "calibrate refine into a folder" "$w/dir" "${R[@]}" -o "$w/dir"
bad_at "calibrate refine into a missing folder" "$w/nodir/r.json" "${R[@]}" -o "$w/nodir/r.json"
bad_at "calibrate refine under a file" "$w/file/r.json" "${R[@]}" -o "$w/file/r.json"
mkdir "$w/r3.report.json"
bad_at "calibrate refine: the report's path is a folder" "$w/r3.report.json" "${R[@]}" -o "$w/r3.json"
rmdir "$w/r3.report.json"
echo "old" >"$w/r4.json"
bad_at "calibrate refine over an existing file without --overwrite" "$w/r4.json" "${R[@]}" -o "$w/r4.json"
rm "$w/r4.json"

check '[ -z "$(find "$w" -name ".tmp-*" -o -name ".old-*")" ]' "no temporaries left"
exit $fail
