#!/usr/bin/env bash
# `arco view` with the capture's camera videos (docs/view.md, "Camera videos"): a synthetic
# capture given a video for one camera (stored turned, rotate_deg 90, as SPD's), `arco run`,
# then view_video_browser_test.js in Debian's chromium. The --no-serve folder's WebM is also
# decoded by overlay_check.py (numpy and Debian's ffmpeg/ffprobe, nothing of arco's): frame
# count and rate the capture's, the fingertips on their marks, the background the source
# video turned. Bad video options: one line "arco: error: ...", exit 1, nothing written.
# Skips (77) only when /usr/bin/chromium or ffmpeg is absent; a missing node or
# playwright-core (scripts/fetch_view_tools) is a failure. Screenshots stay in WORK_DIR.
# usage: view_video_browser_test.sh ARCO_BINARY SOURCE_DIR WORK_DIR
set -uo pipefail
arco=$1
src=$2
work=$3
rm -rf "$work"
mkdir -p "$work"
# The video cache (docs/view.md, "Video cache") in the work folder, not the user's.
export XDG_CACHE_HOME=$work/cache
source "$src/tests/cli/cli_test_lib.sh"
require_browser "$src" ffmpeg ffprobe
synth_and_run "$work/cap" "$work/res" 3
cam=camera_21334181_1
# Grey (hue=s=0): no magenta in the picture but the overlay's fingertip marks.
give_turned_video "$work/cap" $cam "$frames" hue=s=0
# The capture changed: its result is made again (a result is tied to its capture's files).
"$arco" run "$work/cap" -o "$work/res" --overwrite >/dev/null 2>&1 ||
  { echo "FAILED: run again after editing capture.json"; exit 1; }

fail=0
bad() {  # bad NAME PATTERN ARGS...
  local name=$1 pattern=$2; shift 2
  "$arco" "$@" >/dev/null 2>"$work/err"
  local rc=$? line; line=$(cat "$work/err")
  if [ $rc -ne 1 ] || [ "$(wc -l <"$work/err")" -ne 1 ] || [[ "$line" != "arco: error: "$pattern ]]; then
    echo "FAILED: $name: exit $rc: $line"; fail=1
  fi
  if [ -e "$work/out" ]; then echo "FAILED: $name: $work/out was written"; fail=1; fi
}
bad "unknown video camera" "*cap/capture.json: no camera 'nosuch' (cameras: camera_21293324_1, *" \
  view "$work/res" --no-serve -o "$work/out" --video-camera nosuch
bad "--no-videos with --video-camera" "*--no-videos and --video-camera contradict*" \
  view "$work/res" --no-serve -o "$work/out" --no-videos --video-camera $cam
bad "video scale out of range" "*--video-scale*" view "$work/res" --no-serve -o "$work/out" --video-scale 2
bad "video scale zero" "*--video-scale*" view "$work/res" --no-serve -o "$work/out" --video-scale 0

# --no-serve: the video of the default camera (the first with a video), checked by ffmpeg.
"$arco" view "$work/res" --no-serve -o "$work/page" --video-scale 0.25 >"$work/out.txt" 2>&1 ||
  { echo "FAILED: arco view --no-serve: $(cat "$work/out.txt")"; exit 1; }
grep -q "video of $cam (576x664, $frames frames, arco overlay" "$work/out.txt" ||
  { echo "FAILED: the video line: $(cat "$work/out.txt")"; fail=1; }
video=$(/usr/bin/python3 -c "import json,sys; v=json.load(open(sys.argv[1]))['videos']; assert len(v)==1; print(v[0]['file'])" \
  "$work/page/manifest.json") || { echo "FAILED: manifest.json's videos"; exit 1; }
if /usr/bin/python3 -c "import numpy" 2>/dev/null; then
  /usr/bin/python3 "$src/tests/cli/overlay_check.py" "$work/page/$video" "$work/res" $cam 0.25 1 "$frames" \
    "$work/cap/$cam.mp4" 90 || { echo "FAILED: overlay_check.py on $video"; fail=1; }
else
  echo "FAILED: python3-numpy missing (scripts/setup)"; fail=1
fi
# --no-videos: no video written, none listed.
"$arco" view "$work/res" --no-serve -o "$work/page_novideo" --no-videos >/dev/null 2>&1 &&
  [ -z "$(ls "$work/page_novideo" | grep '\.webm$')" ] &&
  grep -q '"videos": \[\]' "$work/page_novideo/manifest.json" ||
  { echo "FAILED: --no-videos still writes a video"; fail=1; }
[ $fail -eq 0 ] || exit 1

node "$src/tests/view/view_video_browser_test.js" "$arco" "$work/res" "$work/page" $cam \
  "$work/shots" "$playwright"
