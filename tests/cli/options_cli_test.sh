#!/usr/bin/env bash
# Every option used is recorded: result.json "options" (arco run) and the method entry's
# "options" (arco refine) hold the values given on the command line, as applied; a bad
# value fails with one line naming the flag before anything is written.
# usage: options_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$1
export ARCO_SHARED_DATA_DIR=$2
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# json FILE EXPR: the value of a Python expression over the parsed file `d`.
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(json.dumps($2))" "$1"; }

"$arco" synth --duration-s 2 --seed 4 -o "$tmp/cap" > "$tmp/synth.log" 2>&1
check '[ $? -eq 0 ]' "synth"

# A bad value: one line naming the flag and the value, exit 1, no result folder.
out=$("$arco" run "$tmp/cap" -o "$tmp/bad" --min-confidence nan 2>&1); rc=$?
check '[ $rc -eq 1 ] && [ "$(wc -l <<<"$out")" -eq 1 ]' "run --min-confidence nan: one line, exit 1"
check 'grep -q -- "--min-confidence: nan" <<<"$out"' "run --min-confidence nan names flag and value"
check '[ ! -e "$tmp/bad" ]' "run --min-confidence nan writes nothing"

"$arco" run "$tmp/cap" -o "$tmp/res" --min-confidence 0.6 --threads 2 > "$tmp/run.log" 2>&1
check '[ $? -eq 0 ]' "run"
r=$tmp/res/result.json
check '[ "$(json "$r" "d[\"options\"][\"refine\"][\"pitch\"][\"min_confidence\"]")" = 0.6 ]' \
  "result.json options.refine.pitch.min_confidence = --min-confidence"
check '[ "$(json "$r" "d[\"options\"][\"num_threads\"]")" = 2 ]' \
  "result.json options.num_threads = --threads"
check '[ "$(json "$r" "d[\"stages\"][\"arco\"][\"options\"][\"min_confidence\"]")" = 0.6 ]' \
  "arco method entry records --min-confidence"
for key in triangulate instrument hands refine; do
  check '[ "$(json "$r" "\"$key\" in d[\"options\"]")" = true ]' "result.json options.$key"
done

out=$("$arco" refine "$tmp/res" --shift-cost -100 2>&1); rc=$?
check '[ $rc -eq 1 ] && grep -q -- "--shift-cost: -100 is outside" <<<"$out"' \
  "refine --shift-cost -100 rejected with the flag"
"$arco" refine "$tmp/res" --mode arco --shift-cost 2.5 --temporal-weight 3 --normal-weight 0.5 \
  --straddle-s 0.02 --neighbour-shift-frames 1 --no-audio-onsets --joints pip_dip \
  --binding-cents 25 --threads 1 > "$tmp/refine.log" 2>&1
check '[ $? -eq 0 ]' "refine"
o='d["stages"]["arco"]["options"]'
expect() {  # expect EXPR VALUE FLAG
  local got want=$2
  got=$(json "$r" "$o$1")
  check '[ "$got" = "$want" ]' "refine $3 recorded as $want (got $got)"
}
expect '["decode"]["shift_cost_per_semitone"]' 2.5 --shift-cost
expect '["ik"]["temporal_weight_mm_per_rad"]' 3.0 --temporal-weight
expect '["decode"]["normal_weight"]' 0.5 --normal-weight
expect '["decode"]["boundaries"]["straddle_s"]' 0.02 --straddle-s
expect '["ik"]["neighbour_shift_frames"]' 1 --neighbour-shift-frames
expect '["decode"]["audio_onsets"]' false --no-audio-onsets
expect '["ik"]["joints"]' '"pip_dip"' --joints
expect '["paper"]["binding_cents"]' 25.0 --binding-cents
expect '["num_threads"]' 1 --threads
expect '["pitch"]["min_confidence"]' 0.5 "(default --min-confidence)"

# eval.json records its options too.
"$arco" eval "$tmp/res" --truth "$tmp/cap/truth" --pck-mm 7 15 --limit-tolerance-deg 4 \
  -o "$tmp/eval.json" > "$tmp/eval.log" 2>&1
check '[ $? -eq 0 ]' "eval"
check '[ "$(json "$tmp/eval.json" "d[\"options\"][\"pck_thresholds_mm\"]")" = "[7.0, 15.0]" ]' \
  "eval.json options.pck_thresholds_mm = --pck-mm"
check '[ "$(json "$tmp/eval.json" "d[\"options\"][\"joint_limit_tolerance_deg\"]")" = 4.0 ]' \
  "eval.json options.joint_limit_tolerance_deg = --limit-tolerance-deg"
exit $fail
