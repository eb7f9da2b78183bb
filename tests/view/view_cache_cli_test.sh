#!/usr/bin/env bash
# `arco view`'s video cache (docs/view.md, "Video cache") on a synthetic capture given a
# small video for one camera: a second start with the same inputs takes the cached WebM
# (the summary line counts 0 encoded, 1 from the cache; the bytes are the first's), served
# or --no-serve; a changed input that the overlay draws or encodes (points3d.npy,
# notes.csv, --video-scale, the source video) encodes again; a truncated entry or one
# without its sidecar is encoded again; --no-cache writes no cache; --cache-max-gb 0
# removes every entry but the one in use; a missing source video is the overlay's own
# error; the default folder is $XDG_CACHE_HOME/arco/view; the result folder is never
# written to. Bad cache options (also --no-cache with --cache-dir): one line
# "arco: error: ...", exit 1, nothing written. Skips (77) without ffmpeg unless CI is set.
# usage: view_cache_cli_test.sh ARCO_BINARY SOURCE_DIR
set -uo pipefail
arco=$1
src=$2
py=/usr/bin/python3
if ! command -v ffmpeg >/dev/null; then
  echo "ffmpeg not installed (scripts/setup installs it)"
  [ -n "${CI:-}" ] && exit 1
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$src/tests/cli/cli_test_lib.sh"
mkdir -p "$tmp/w"
SNAPSHOT_DIR=$tmp/w

synth_and_run "$tmp/cap" "$tmp/res" 1
cam=camera_21334181_1
give_turned_video "$tmp/cap" $cam "$frames" hue=s=0
# The capture changed: its result is made again (a result is tied to its capture's files).
"$arco" run "$tmp/cap" -o "$tmp/res" --overwrite >/dev/null 2>&1 ||
  { echo "FAILED: run again after editing capture.json"; exit 1; }
result_before=$(SNAPSHOT_DIR=$tmp/res snapshot)
cache=$tmp/cache
video=video_$("$py" -c "import json,sys; print([x['name'] for x in json.load(open(sys.argv[1]))['cameras']].index(sys.argv[2]))" \
  "$tmp/cap/capture.json" $cam).webm

n=0
# view_page EXPECT_ENCODED EXPECT_CACHED NAME ARGS...: a --no-serve page (into $tmp/p<n>,
# kept in $page) at --video-scale $scale (default 0.1) whose summary counts the videos
# encoded and taken from the cache.
view_page() {
  local enc=$1 hit=$2 name=$3; shift 3
  n=$((n + 1)); page=$tmp/p$n
  ok "$name" view "$tmp/res" --no-serve -o "$page" --video-scale "${scale:-0.1}" "$@"
  check 'grep -q "videos: $enc encoded, $hit from the cache" "$tmp/out"' \
    "$name: expected $enc encoded, $hit cached: $(grep videos: "$tmp/out")"
  check '[ -s "$page/$video" ]' "$name: no $video in the page"
}
entries() { ls "$cache" 2>/dev/null | grep -c '\.webm$'; }

view_page 1 0 "first start" --cache-dir "$cache"
first=$tmp/p$n/$video
check '[ "$(entries)" -eq 1 ]' "first start: $(entries) cache entries, not 1"
check 'grep -q "encoded in" "$tmp/out"' "first start: the video line does not say encoded"
view_page 0 1 "second start" --cache-dir "$cache"
check 'cmp -s "$first" "$page/$video"' "second start: the cached video's bytes differ"
check 'grep -q "taken from the cache in" "$tmp/out"' "second start: the video line"
# Served: the same cache.
ok "served start" view "$tmp/res" --port 0 --exit-after-s 0.5 --video-scale 0.1 --cache-dir "$cache"
check 'grep -q "videos: 0 encoded, 1 from the cache" "$tmp/out"' \
  "served start: $(grep videos: "$tmp/out")"
key=$(ls "$cache" | grep '\.webm$' | sed 's/\.webm$//')

# --no-cache: encoded, the cache untouched.
cache_before=$(SNAPSHOT_DIR=$cache snapshot)
XDG_CACHE_HOME=$cache view_page 1 0 "--no-cache" --no-cache
check 'grep -q "(no cache)" "$tmp/out"' "--no-cache: the summary names a cache"
check '[ "$(SNAPSHOT_DIR=$cache snapshot)" = "$cache_before" ]' "--no-cache: the cache changed"
# The default folder: $XDG_CACHE_HOME/arco/view.
XDG_CACHE_HOME=$tmp/xdg view_page 1 0 "XDG_CACHE_HOME"
check '[ -s "$tmp/xdg/arco/view/$key.webm" ] && [ -s "$tmp/xdg/arco/view/$key.json" ]' \
  "XDG_CACHE_HOME: no entry $key in $tmp/xdg/arco/view"

# Another scale is another entry; the first is still taken.
scale=0.12 view_page 1 0 "--video-scale 0.12" --cache-dir "$cache"
check '[ "$(entries)" -eq 2 ]' "--video-scale 0.12: $(entries) cache entries, not 2"
view_page 0 1 "--video-scale 0.1 again" --cache-dir "$cache"

# A truncated entry, an entry without its sidecar: encoded again (VP8 from libvpx is
# deterministic: the same bytes as the first time).
truncate -s 1000 "$cache/$key.webm"
view_page 1 0 "truncated entry" --cache-dir "$cache"
check 'cmp -s "$first" "$cache/$key.webm"' "truncated entry: not encoded again whole"
check 'cmp -s "$first" "$page/$video"' "truncated entry: the page's video"
rm "$cache/$key.json"
view_page 1 0 "entry without sidecar" --cache-dir "$cache"
check '[ -s "$cache/$key.json" ]' "entry without sidecar: no sidecar written"
check '[ -z "$(ls -A "$cache" | grep "^\.")" ]' "temporaries left in the cache: $(ls -A "$cache")"

# The result folder was never written to.
check '[ "$(SNAPSHOT_DIR=$tmp/res snapshot)" = "$result_before" ]' "the result folder changed"

# Inputs that the overlay draws: the method's points, the notes; the source video.
"$py" -c "
import numpy as np, sys
p = np.load(sys.argv[1]); p[..., 0] += 5; np.save(sys.argv[1], p)" "$tmp/res/arco/points3d.npy" ||
  { echo "FAILED: editing points3d.npy"; fail=1; }
view_page 1 0 "points3d.npy changed" --cache-dir "$cache"
view_page 0 1 "points3d.npy changed, second start" --cache-dir "$cache"
printf '\n' >>"$tmp/res/notes.csv"
view_page 1 0 "notes.csv changed" --cache-dir "$cache"
ffmpeg -v error -y -f lavfi -i "testsrc2=size=2656x2300:rate=30" -frames:v "$frames" \
  -c:v mpeg4 -q:v 3 "$tmp/cap/$cam.mp4" || { echo "FAILED: making the second video"; fail=1; }
view_page 1 0 "source video changed" --cache-dir "$cache"

# --cache-max-gb 0: every entry but the one in use is removed, least recently used first.
before=$(entries)
view_page 0 1 "--cache-max-gb 0" --cache-dir "$cache" --cache-max-gb 0
check '[ "$(entries)" -eq 1 ] && [ "$before" -gt 1 ]' "--cache-max-gb 0: $before then $(entries) entries"
check 'grep -q "$((before - 1)) cache entries removed" "$tmp/out"' "--cache-max-gb 0: $(grep videos: "$tmp/out")"
view_page 0 1 "after eviction" --cache-dir "$cache"

# A missing source video: the overlay's own error, as without the cache, nothing cached.
mv "$tmp/cap/$cam.mp4" "$tmp/moved.mp4"
before=$(SNAPSHOT_DIR=$cache snapshot)
with=$("$arco" view "$tmp/res" --no-serve -o "$tmp/w/out" --cache-dir "$cache" 2>&1 >/dev/null)
without=$("$arco" view "$tmp/res" --no-serve -o "$tmp/w/out" --no-cache 2>&1 >/dev/null)
check '[[ "$with" == "arco: error: "*"$cam.mp4"* ]] && [ "$with" = "$without" ]' \
  "missing video: '$with' with the cache, '$without' without"
check '[ "$(SNAPSHOT_DIR=$cache snapshot)" = "$before" ] && [ ! -e "$tmp/w/out" ]' \
  "missing video: something was written"
mv "$tmp/moved.mp4" "$tmp/cap/$cam.mp4"

# Bad cache options: one error line, nothing written.
bad "--cache-max-gb negative" "--cache-max-gb" view "$tmp/res" --no-serve -o "$tmp/w/out" \
  --cache-max-gb -1
bad_at "unwritable cache" "/proc/arco-cache" view "$tmp/res" --no-serve -o "$tmp/w/out" \
  --cache-dir /proc/arco-cache
bad "--no-cache with --cache-dir" "--no-cache and --cache-dir contradict" view "$tmp/res" \
  --no-serve -o "$tmp/w/out" --no-cache --cache-dir "$tmp/w/cache"
HOME= XDG_CACHE_HOME= bad "no cache folder" "--cache-dir: no cache folder" view "$tmp/res" \
  --no-serve -o "$tmp/w/out"
exit $fail
