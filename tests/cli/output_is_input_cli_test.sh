#!/usr/bin/env bash
# An output is never an input (docs/architecture.md, "Outputs"): on every command that
# writes, an output path that is one of the command's inputs (the same file through `./`,
# `..` or a symbolic link), lies inside an input folder (also the capture a result folder
# names) or contains an input is refused before any work: one line "arco: error: PATH:
# FLAG is the input ... / is inside the input folder ... / contains the input ...", exit
# status 1, and every file under the working folder byte-identical (md5) with nothing
# added (cli_test_lib.sh's snapshot). Also: the leftovers of a dead process beside an
# output go on the next start.
# usage: output_is_input_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$(realpath "$1")
spd=$2/spd
export ARCO_SHARED_DATA_DIR=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
w=$tmp/w
SNAPSHOT_DIR=$w
mkdir -p "$w"

# refused NAME ARGS...: refused with a line naming the conflict; nothing under $w changes.
refused() {
  local name=$1; shift
  expect_error "$name" "*: *@(is the input|is inside the input folder|contains the input)*" "$@"
}
shopt -s extglob

# The inputs, all inside $w: a recording, a calibration, a capture with audio and its
# result, labelled views, board images, SPD keypoint folders, a folder of takes.
cp "$spd/pgy.wav" "$w/m.wav"
ln -s m.wav "$w/link.wav"
cp "$spd/cello_1113_scale_camera.xml" "$w/c.xml"
"$arco" synth --calibration "$w/c.xml" --duration-s 1.5 --seed 3 -o "$w/cap" >"$tmp/log" 2>&1
check '[ $? -eq 0 ] && [ -f "$w/cap/audio.wav" ]' "synth the capture: $(tail -1 "$tmp/log")"
"$arco" run "$w/cap" -o "$w/res" --threads 2 >"$tmp/log" 2>&1
check '[ $? -eq 0 ] && [ -f "$w/res/result.json" ]' "run the capture: $(tail -1 "$tmp/log")"
"$arco" calibration convert "$w/c.xml" "$w/c.json" >"$tmp/log" 2>&1
check '[ $? -eq 0 ]' "calibration convert: $(tail -1 "$tmp/log")"
mkdir -p "$w/labels" "$w/L" "$w/R" "$w/h/21334181" "$w/h/21334237" "$w/takes/t1"
for serial in 21334181 21334190 21334211 21334237; do
  cp "$spd/labels_frame128/cello_1113_scale_${serial}_128.json" "$w/labels/$serial.json"
done
data=/usr/share/doc/opencv-doc/examples/data
for n in 01 02 03; do cp "$data/left$n.jpg" "$w/L/"; cp "$data/right$n.jpg" "$w/R/"; done

# pitch: the recording, through -o, --fine, --notes, --midi, ./, a link, ..; the capture's
# audio and folder.
refused "pitch -o the input" pitch "$w/m.wav" -o "$w/m.wav"
refused "pitch --notes the input" pitch "$w/m.wav" --notes "$w/m.wav"
refused "pitch --midi ./the input" pitch "$w/m.wav" --midi "$w/./m.wav"
refused "pitch --fine the input via .." pitch "$w/m.wav" --fine "$w/cap/../m.wav"
refused "pitch -o a link to the input" pitch "$w/m.wav" -o "$w/link.wav"
pushd "$w" >/dev/null
refused "pitch -o the input, relative paths" pitch m.wav -o ./m.wav
refused "calibration convert in place, relative paths" calibration convert c.json L/../c.json
popd >/dev/null
refused "pitch --capture -o its audio" pitch --capture "$w/cap" -o "$w/cap/audio.wav"
refused "pitch --capture -o into the capture" pitch --capture "$w/cap" -o "$w/cap/pitch.csv"

# export, eval, overlay, plot, view: the result folder and the capture it names.
# (export's output is named by its format's extension: .csv files of the result.)
refused "export -o a result file" export "$w/res" --format csv -o "$w/res/arco/contacts.csv"
refused "export -o the result's notes.csv" export "$w/res" --format csv --method vision -o "$w/res/notes.csv"
refused "export -o into the result's capture" export "$w/res" --format csv --method vision -o "$w/cap/x.csv"
refused "eval -o result.json" eval "$w/res" --truth "$w/cap/truth" -o "$w/res/result.json"
refused "eval -o into --truth" eval "$w/res" --truth "$w/cap/truth" -o "$w/cap/truth/eval.json"
refused "eval --plot into the result" eval "$w/res" --truth "$w/cap/truth" -o "$w/e.json" --plot "$w/res/e.svg"
O=(overlay "$w/res" --method vision --camera camera_21334181_1 --frames 1:3 --scale 0.1)
refused "overlay -o into the result" "${O[@]}" -o "$w/res/o.mkv"
refused "overlay -o into the capture" "${O[@]}" -o "$w/cap/o.mkv"
refused "plot -o the result folder" plot "$w/res" -o "$w/res" --overwrite
refused "plot -o into the result" plot "$w/res" -o "$w/res/plots"
refused "view -o into the result" view "$w/res" --no-serve -o "$w/res/page"
refused "view -o the capture" view "$w/res" --no-serve -o "$w/cap" --overwrite

# calibration convert, calibrate, calibrate refine: a calibration onto itself.
refused "calibration convert in place" calibration convert "$w/c.json" "$w/c.json" --format spd
refused "calibration convert in place via .." calibration convert "$w/c.json" "$w/L/../c.json"
K=(calibrate --board chessboard:9x6:25 --images left="$w/L" --images right="$w/R")
refused "calibrate -o into --images" "${K[@]}" -o "$w/L/rig.json"
refused "calibrate -o --intrinsics" "${K[@]}" --intrinsics "$w/c.json" -o "$w/c.json"
refused "calibrate -o whose report is an input" "${K[@]}" --intrinsics "$w/c.report.json" -o "$w/c.yaml"
refused "calibrate refine -o the capture's calibration" calibrate refine "$w/cap" -o "$w/cap/calibration.json" --overwrite
refused "calibrate refine -o --calibration" calibrate refine "$w/cap" --calibration "$w/c.json" -o "$w/c.json" --overwrite

# Commands that make a capture or a result folder: -o an input, inside one, around one.
refused "synth -o around --calibration" synth --calibration "$w/cap/calibration.json" -o "$w/cap" --overwrite --no-audio
refused "synth -o the calibration" synth --calibration "$w/c.json" -o "$w/c.json" --no-audio
refused "import-spd -o --human" import-spd --calibration "$w/c.xml" --human "$w/h" --serials 21334181 --first 1 --last 2 -o "$w/h" --overwrite
refused "import-spd -o into --human" import-spd --calibration "$w/c.xml" --human "$w/h" --serials 21334181 --first 1 --last 2 -o "$w/h/cap"
refused "capture new -o into --images" capture new --calibration "$w/c.xml" --images "21334181=$w/L" --fps 30 -o "$w/L/cap"
refused "capture new -o --calibration" capture new --calibration "$w/c.xml" --images "21334181=$w/L" --fps 30 -o "$w/c.xml"
refused "capture import-keypoints --camera the manifest" capture import-keypoints --format mmpose --camera "21334181=$w/cap/capture.json" "$w/cap"
refused "triangulate views -o a --view" triangulate --calibration "$w/c.xml" --view "21334181=$w/labels/21334181.json" --view "21334237=$w/labels/21334237.json" -o "$w/labels/21334181.json"
refused "triangulate -o the capture" triangulate "$w/cap" -o "$w/cap"
refused "triangulate -o into the capture" triangulate "$w/cap" -o "$w/cap/tri"
refused "run -o into the capture" run "$w/cap" -o "$w/cap/res"
refused "run -o the capture" run "$w/cap" -o "$w/cap/" --overwrite
refused "run -o around the capture" run "$w/cap" -o "$w" --overwrite
refused "batch -o into TAKES" batch "$w/takes" -o "$w/takes/out"

# Not an input: still fine.
ok "pitch -o beside the input" pitch "$w/m.wav" --frames 30 -o "$tmp/p.csv"
ok "calibration convert beside" calibration convert "$w/c.json" "$tmp/c2.json"

# The leftovers of dead processes beside an output go when a command starts (a pid above
# any pid_max); a live one's stay.
mkdir -p "$tmp/o/.tmp-999999999.cap/truth"
echo partial >"$tmp/o/.tmp-999999998.p.csv"
echo mine >"$tmp/o/.tmp-$$.x"
ok "export beside leftovers" export "$w/res" --format csv --method vision -o "$tmp/o/x.csv"
check '[ ! -e "$tmp/o/.tmp-999999999.cap" ] && [ ! -e "$tmp/o/.tmp-999999998.p.csv" ]' "dead processes' temporaries removed"
check '[ -f "$tmp/o/.tmp-$$.x" ] && [ -s "$tmp/o/x.csv" ]' "a live process's temporary and the output stay"

check '[ -z "$(find "$w" -name ".tmp-*" -o -name ".old-*")" ]' "no temporaries left"
exit $fail
