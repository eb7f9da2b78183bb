#!/usr/bin/env bash
# The Snakemake workflow (workflow/Snakefile, docs/workflow.md) on three synthetic takes
# with 2 cores: results, eval and the summary of each; a re-run does nothing; a changed
# input redoes only its take; a broken take fails alone, named with its stage, while the
# others complete (--keep-going); a failed take is run again (never a finished target);
# `arco batch`; the command lines rendered for a video
# session and an SPD session, and an SPD session made from a synthetic take run for real;
# the Slurm profile's submissions (a mock sbatch that runs the job itself).
# Without snakemake it skips (exit 77) unless CI is set.
# With the detector models (MODELS_DIR/pose_detection.onnx) a video take of a real photo
# runs capture new -> detect -> run for real (run stops: the take names no instrument).
# usage: workflow_test.sh ARCO_BINARY [SHARED_DATA_DIR [MODELS_DIR]]
set -uo pipefail
arco=$(realpath "$1")
[ -n "${2:-}" ] && export ARCO_SHARED_DATA_DIR=$2
models=${3:-}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
snakefile=$here/Snakefile
if [ -x /usr/bin/snakemake ]; then
  snakemake=(/usr/bin/snakemake)
elif /usr/bin/python3 -c 'import snakemake' 2>/dev/null; then
  snakemake=(/usr/bin/python3 -m snakemake)
else
  echo "snakemake is missing: run scripts/setup (apt-get install snakemake)"
  [ -n "${CI:-}" ] && exit 1
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
fail=0
check() { if ! eval "$1"; then echo "FAILED: $2"; fail=1; fi; }
# wf OUT [ARGS...]: the workflow on takes/ into OUT with 2 cores.
wf() {
  local out=$1; shift
  "${snakemake[@]}" -s "$snakefile" --cores 2 --config takes=takes out="$out" arco="$arco" "$@"
}
# column TAKE NAME: a take's value in out/summary.tsv.
column() {
  awk -F'\t' -v take="$1" -v name="$2" \
    'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next } $1 == take { print $col[name] }' \
    out/summary.tsv
}

for k in 1 2 3; do
  "$arco" synth -o takes/take$k --duration-s 2 --seed $k --threads 1 >/dev/null 2>synth$k.txt &
done
wait
for k in 1 2 3; do
  check '[ -f takes/take$k/capture.json ]' "arco synth take$k: $(cat synth$k.txt)"
done

# End to end.
wf out --keep-going --printshellcmds > run1.txt 2>&1
rc=$?
check '[ $rc -eq 0 ]' "first run failed: $(tail -20 run1.txt)"
for k in 1 2 3; do
  check '[ -f out/take$k/result/result.json ] && [ -f out/take$k/eval.json ]' \
    "take$k: no result.json or eval.json"
  check '[ "$(column take$k status)" = ok ] && [ "$(column take$k frames)" = 75 ] &&
         [ "$(column take$k views)" = 20 ] && [ -n "$(column take$k hand_mpjpe_mm)" ] &&
         [ -n "$(column take$k voiced_pct)" ] && [ -n "$(column take$k corrected)" ]' \
    "take$k: summary row $(grep take$k out/summary.tsv)"
done
check '[ "$(wc -l < out/summary.tsv)" -eq 4 ] && [ "$(grep -c "^| take" out/summary.md)" -eq 4 ]' \
  "summary: $(cat out/summary.md)"
check '[ "$(grep -c "arco run .*/takes/take[123] -o .*/out/take[123]/result --threads 2" run1.txt)" -eq 3 ]' \
  "run jobs were not given 2 threads: $(grep "arco run" run1.txt)"

# A re-run executes nothing.
wf out -n > rerun.txt 2>&1
check 'grep -q "Nothing to be done" rerun.txt' "re-run is not empty: $(tail -20 rerun.txt)"

# `arco batch` runs the same workflow: nothing to do either; a clear line without snakemake.
"$arco" batch takes -o out --cores 2 --workflow "$here" -n > batch.txt 2>&1
rc=$?
check '[ $rc -eq 0 ] && grep -q "Nothing to be done" batch.txt' "arco batch -n: $(tail -5 batch.txt)"
line=$("$arco" batch takes -o out --cores 2 --keep-going --workflow "$here" --print-command)
check '[ "$line" = "snakemake -s $here/Snakefile --cores 2 --keep-going --config takes=$tmp/takes out=$tmp/out arco=$arco" ]' \
  "arco batch --print-command: $line"
mkdir empty
PATH="$tmp/empty" "$arco" batch takes -o out --workflow "$here" > batch2.txt 2>&1
rc=$?
check '[ $rc -eq 1 ] && grep -q "^arco: error: snakemake: not found; .*apt-get install snakemake" batch2.txt' \
  "arco batch without snakemake: $(cat batch2.txt)"

# A workflow that cannot start is one line, not Snakemake's report of the Snakefile's stack.
mkdir notakes
"$arco" batch notakes -o out-none --workflow "$here" > batch3.txt 2>&1
rc=$?
check '[ $rc -eq 1 ] && grep -q "^arco workflow: error: no takes in .*notakes$" batch3.txt &&
       ! grep -qE "Traceback|File \"|SystemExit|WorkflowError" batch3.txt' \
  "arco batch without takes: exit $rc: $(cat batch3.txt)"

# A changed input redoes only its take (Snakemake compares contents: a touch alone is no change).
before1=$(stat -c %Y out/take1/eval.json)
echo " " >> takes/take2/capture.json
wf out > run2.txt 2>&1
rc=$?
check '[ $rc -eq 0 ]' "run after a change failed: $(tail -20 run2.txt)"
check '[ "$(grep -c "wildcards: take=take2" run2.txt)" -eq 2 ] && ! grep -q "take=take[13]" run2.txt' \
  "a change of take2 ran: $(grep wildcards run2.txt)"
check '[ "$(stat -c %Y out/take1/eval.json)" = "$before1" ]' "take1 was redone"

# A broken take fails alone (take1 is redone meanwhile), named with its stage.
echo '{"format": "arco-capture", "version": 1, "fps": ' > takes/take3/capture.json
echo " " >> takes/take1/capture.json
wf out --keep-going > run3.txt 2>&1
rc=$?
check '[ $rc -ne 0 ]' "a broken take did not fail the workflow"
check 'grep -q "arco workflow: take take3 failed at stage run: arco: error: .*take3/capture.json: malformed JSON" run3.txt' \
  "no line naming take3 and its stage: $(grep "arco workflow" run3.txt)"
check 'grep -q "arco workflow: 2 of 3 takes done" run3.txt' "count of takes done"
check '[ "$(column take3 status)" = failed ] && [ "$(column take3 stage)" = run ] &&
       [[ "$(column take3 message)" == *"malformed JSON"* ]]' \
  "take3 row: $(grep take3 out/summary.tsv)"
check '[ "$(column take1 status)" = ok ] && [ "$(column take2 status)" = ok ] &&
       [ "$(stat -c %Y out/take1/eval.json)" != "$before1" ]' \
  "take1/take2 rows: $(grep "take[12]" out/summary.tsv)"

# A failed take is never a finished target: the table `onerror` writes is no proof of
# work, so `arco batch` run again runs the take again and fails while it fails (it used
# to say "Nothing to be done" and exit 0 with the take's outputs missing), and once the
# take is fixed the re-run completes it.
mkdir -p ftakes && cp -r takes/take1 ftakes/late
cp ftakes/late/capture.json late-capture.json
echo '{"format": "arco-capture", "version": 1, "fps": ' > ftakes/late/capture.json
batch() { "$arco" batch ftakes -o fout --cores 2 --keep-going --workflow "$here" > "$1" 2>&1; }
batch fail1.txt
rc=$?
check '[ $rc -ne 0 ] && [ -f fout/summary.tsv ] && [ ! -e fout/late/result ]' \
  "the failed take: exit $rc, $(ls fout fout/late 2>&1 | tr '\n' ' ')"
batch fail2.txt
rc=$?
check '[ $rc -ne 0 ] && ! grep -q "Nothing to be done" fail2.txt &&
       grep -q "arco workflow: take late failed at stage run: " fail2.txt' \
  "arco batch after a failed take: exit $rc: $(tail -5 fail2.txt)"
cp late-capture.json ftakes/late/capture.json
batch fail3.txt
rc=$?
check '[ $rc -eq 0 ] && [ -f fout/late/result/result.json ] && [ -f fout/late/eval.json ] &&
       [ "$(tail -1 fout/summary.tsv | cut -f1-2)" = "$(printf "late\tok")" ]' \
  "the fixed take: exit $rc: $(tail -5 fail3.txt) $(cat fout/summary.tsv)"

# Video and SPD sessions: what would run (inputs as empty stand-ins).
mkdir -p sessions/video1/videos sessions/video1/labels sessions/spd1/human/21334181 \
  sessions/spd1/instrument/21334181 sessions/notatake
cp takes/take1/calibration.json sessions/video1/
touch sessions/video1/videos/cam0.mp4 sessions/video1/videos/cam1.mp4 \
  sessions/video1/audio.wav sessions/video1/labels/cam0.json sessions/video1/labels/cam1.json
cat > sessions/video1/take.yaml <<'YAML'
calibration: calibration.json
instrument: cello
audio: audio.wav
cameras:
  cam0: videos/cam0.mp4
  cam1: videos/cam1.mp4
rotate:
  cam1: 90
labels:
  cam0: labels/cam0.json
  cam1: labels/cam1.json
sync: clap
options:
  track: {no-bow: true, inlier-px: 2.5}
  run: {min-confidence: 0.6}
YAML
cp takes/take1/calibration.json sessions/spd1/spd1_camera.json
echo '{"StartFrame": 1, "EndFrame": 10}' > sessions/spd1/spd1_summary.json
echo '{"instrument": "violin"}' > sessions/spd1/take.json
"${snakemake[@]}" -s "$snakefile" --cores 2 -n -p --config takes=sessions out=out-s \
  arco="$arco" > sessions.txt 2>&1
rc=$?
check '[ $rc -eq 0 ]' "dry run of the sessions: $(tail -20 sessions.txt)"
check 'grep -q "capture new --calibration .*video1/calibration.json --instrument cello --video cam0=.*videos/cam0.mp4 --video cam1=.*--rotate cam1=90 --audio .*audio.wav --name video1 -o .*out-s/video1/capture" sessions.txt' \
  "video1: capture new: $(grep "capture new" sessions.txt)"
check 'grep -q "detect .*out-s/video1/detect --threads" sessions.txt' "video1: detect"
check 'grep -q "sync .*audio.wav --capture .*out-s/video1/sync --event clap" sessions.txt' "video1: sync"
check 'grep -q "run .*out-s/video1/sync -o .*out-s/video1/result" sessions.txt' "video1: run"
check 'grep -q "run .*out-s/video1/result --threads [0-9]*  *--min-confidence 0.6 " sessions.txt' \
  "video1: run without the take's options: $(grep " run " sessions.txt)"
if "$arco" --help | grep -qE '^\s+track\s'; then
  check 'grep -q "track .*out-s/video1/track --labels cam0=" sessions.txt' "video1: track"
  check 'grep -q "track .*out-s/video1/track .*--no-bow --inlier-px 2.5 " sessions.txt' \
    "video1: track without the take's options: $(grep " track " sessions.txt)"
else
  check '! grep -q "rule track" sessions.txt' "video1: track without arco track"
fi
check 'grep -q "import-spd --calibration .*spd1_camera.json --human .*spd1/human --instrument violin --instrument-points .*spd1/instrument --summary .*spd1_summary.json --name spd1 -o .*out-s/spd1/capture" sessions.txt' \
  "spd1: import-spd: $(grep "import-spd" sessions.txt)"
check 'grep -q "notatake: not a take" sessions.txt' "notatake was not skipped with a message"

# A take's options are checked by arco when the takes are planned: each defect is one
# line naming the take file and the key, and fails that take alone; a take file that is
# not text is such a line too, never a Python traceback.
mkdir -p badopts
for t in unknown range stage workflow notmap list binary; do
  mkdir -p badopts/$t/videos
  cp takes/take1/calibration.json badopts/$t/
  touch badopts/$t/videos/cam0.mp4
  printf 'calibration: calibration.json\ncameras:\n  cam0: videos/cam0.mp4\n' > badopts/$t/take.yaml
done
echo 'options: {run: {no-such-flag: 1}}' >> badopts/unknown/take.yaml
echo 'options: {run: {min-confidence: 7}}' >> badopts/range/take.yaml
echo 'options: {track: {no-bow: true}}' >> badopts/stage/take.yaml
echo 'options: {run: {threads: 3}}' >> badopts/workflow/take.yaml
echo 'options: [run]' >> badopts/notmap/take.yaml
echo 'options: {detect: {chunk-frames: {a: 1}}}' >> badopts/list/take.yaml
printf '\xff\xfe\x00 not text' > badopts/binary/take.yaml
"${snakemake[@]}" -s "$snakefile" --cores 2 -n --config takes=badopts out=out-b \
  arco="$arco" > badopts.txt 2>&1
y=".*badopts/[a-z]*/take.yaml"
for expected in \
  "take unknown: $y: options.run.no-such-flag: .*--no-such-flag" \
  "take range: $y: options.run.min-confidence: --min-confidence: 7 is outside \[0.2, 1\]" \
  "take stage: $y: options.track: not a stage of this take (its stages: capture, detect, run)" \
  "take workflow: $y: options.run.threads: set by the workflow, not by a take" \
  "take notmap: $y: options must map stages to their flags" \
  "take list: $y: options.detect.chunk-frames: give a value, true/false or a list of values" \
  "take binary: $y: not UTF-8 text (byte 0)"; do
  check 'grep -q "^arco workflow: $expected.*; its capture stage fails$" badopts.txt' \
    "no line \"$expected\": $(grep "arco workflow" badopts.txt)"
done
# A flag in both the config's args and a take's options: arco's own line, naming the key.
mkdir -p clashtakes && cp -r badopts/range clashtakes/clash
sed -i 's/min-confidence: 7/min-confidence: 0.7/' clashtakes/clash/take.yaml
"${snakemake[@]}" -s "$snakefile" --cores 2 -n --config takes=clashtakes out=out-c \
  arco="$arco" args="{run: '--min-confidence 0.6'}" > clash.txt 2>&1
check 'grep -q "^arco workflow: take clash: .*take.yaml: options.run.min-confidence: --min-confidence: At Most 1 required but received 2" clash.txt' \
  "a flag in args and options: $(grep "arco workflow" clash.txt)"
check '! grep -qE "Traceback|^  File \"|Error in file" badopts.txt' \
  "a Python traceback: $(grep -B2 -A8 -E "Traceback|File \"" badopts.txt | head -20)"

# An SPD session for real: take1's capture written out in SPD's layout (per camera and
# frame JSON, a summary, the calibration, the audio), then import-spd -> run.
if /usr/bin/python3 -c 'import numpy' 2>/dev/null; then
  mkdir -p spdtakes/spd1
  /usr/bin/python3 - takes/take1 spdtakes/spd1 <<'PY'
import json, os, shutil, sys
import numpy as np
capture, session = sys.argv[1], sys.argv[2]
m = json.load(open(os.path.join(capture, "capture.json")))
k = np.load(os.path.join(capture, "keypoints2d.npy"))
for v, cam in enumerate(m["cameras"]):
    for sub, points in (("human", k[:, v, :133]), ("instrument", k[:, v, 133:])):
        os.makedirs(os.path.join(session, sub, cam["serial"]))
        for f in range(k.shape[0]):
            with open(os.path.join(session, sub, cam["serial"], f"{f + 1}.json"), "w") as out:
                json.dump(points[f].tolist(), out)  # NaN as bare NaN, as SPD writes it
first, count = m["frames"]["first"], m["frames"]["count"]
with open(os.path.join(session, "session_summary.json"), "w") as out:
    json.dump({"StartFrame": first, "EndFrame": first + count - 1, "FrameDropIDLog": {}}, out)
shutil.copy(os.path.join(capture, m["calibration"]), os.path.join(session, "session_camera.json"))
shutil.copy(os.path.join(capture, "audio.wav"), os.path.join(session, "audio.wav"))
PY
  # Its take file passes an option to `arco run` (recorded with the result's options).
  echo 'options: {run: {min-confidence: 0.7}}' > spdtakes/spd1/take.yaml
  # Beside it a video session whose take file names a missing calibration: it fails alone.
  mkdir -p spdtakes/missing
  printf 'calibration: cal.json\ncameras:\n  cam0: cam0.mp4\n' > spdtakes/missing/take.yaml
  "${snakemake[@]}" -s "$snakefile" --cores 2 --keep-going --config takes=spdtakes \
    out=out-spd arco="$arco" > spd.txt 2>&1
  rc=$?
  check '[ $rc -ne 0 ] && grep -q "arco workflow: take missing failed at stage capture: arco: error: .*spdtakes/missing/cal.json: not found" spd.txt' \
    "missing calibration: $(grep "arco workflow" spd.txt)"
  check 'grep -q "imported 75 frames x 20 views x 142 points" out-spd/spd1/logs/capture.log &&
         [ "$(tail -1 out-spd/summary.tsv | cut -f1-5)" = "$(printf "spd1\tok\t\t75\t20")" ]' \
    "SPD session: $(tail -5 spd.txt) $(cat out-spd/summary.tsv)"
  check 'grep -q "\"min_confidence\": 0.7" out-spd/spd1/result/result.json' \
    "the take's option did not reach arco run: $(grep -o "\"min_confidence\": [0-9.]*" out-spd/spd1/result/result.json)"
else
  echo "no numpy for Debian's python3: the SPD session is only dry-run"
fi

# A video take for real: a photo as a 1-frame video in two cameras.
photo=/usr/share/doc/opencv-doc/examples/data/messi5.jpg
if [ -n "$models" ] && [ -f "$models/pose_detection.onnx" ] && [ -f "$photo" ]; then
  mkdir -p videotakes/photo
  cat > videotakes/photo/cal.json <<'JSON'
{"format": "arco-calibration", "version": 1, "units": "mm", "cameras": [
 {"name": "front", "width": 548, "height": 342, "K": [600, 0, 273.5, 0, 600, 170.5, 0, 0, 1],
  "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [0, 0, 0]},
 {"name": "side", "width": 548, "height": 342, "K": [600, 0, 273.5, 0, 600, 170.5, 0, 0, 1],
  "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [100, 0, 0]}]}
JSON
  printf '{"calibration": "cal.json", "fps": 30, "cameras": {"front": "%s", "side": "%s"}}\n' \
    "$photo" "$photo" > videotakes/photo/take.json
  "${snakemake[@]}" -s "$snakefile" --cores 2 --keep-going --config takes=videotakes \
    out=out-v arco="$arco" args="{detect: '--models-dir $models'}" > video.txt 2>&1
  check '[ -f out-v/photo/capture/capture.json ] && [ -f out-v/photo/detect/keypoints2d.npy ] &&
         [ ! -f out-v/photo/capture/keypoints2d.npy ]' "video take: capture and detect: $(tail video.txt)"
  check 'grep -q "arco workflow: take photo failed at stage run: arco: error: .*detect/capture.json: the capture names no instrument" video.txt' \
    "video take: $(grep "arco workflow" video.txt)"
else
  echo "no detector models in '$models': the video take is only dry-run"
fi

# Slurm: the dry run lists the jobs with their threads and memory; a mock sbatch records
# the submissions and runs each job itself (CI=true: Snakemake polls every second).
mkdir -p mock
printf '#!/bin/bash\necho "sbatch $*" >> "%s/sbatch.log"\nbash "${@: -1}" >/dev/null 2>&1\necho 4242\n' \
  "$tmp" > mock/sbatch
chmod +x mock/sbatch
cp -r takes/take1 takes-slurm
mkdir takes-one && mv takes-slurm takes-one/take1
"${snakemake[@]}" -s "$snakefile" -n --profile "$here/profiles/slurm" \
  --config takes=takes-one out=out-slurm arco="$arco" > slurm-n.txt 2>&1
rc=$?
check '[ $rc -eq 0 ] && grep -q "^rule run:" slurm-n.txt && grep -q "mem_mb=4000" slurm-n.txt' \
  "slurm dry run: $(tail -20 slurm-n.txt)"
"${snakemake[@]}" -s "$snakefile" -n --profile "$here/profiles/cluster" \
  --config takes=takes-one out=out-slurm arco="$arco" > cluster-n.txt 2>&1
rc=$?
check '[ $rc -eq 0 ] && grep -q "^rule eval:" cluster-n.txt' "cluster dry run: $(tail -20 cluster-n.txt)"
CI=true PATH="$tmp/mock:$PATH" "${snakemake[@]}" -s "$snakefile" --profile "$here/profiles/slurm" \
  --config takes=takes-one out=out-slurm arco="$arco" > slurm.txt 2>&1
rc=$?
check '[ $rc -eq 0 ] && [ -f out-slurm/take1/eval.json ] && [ -f out-slurm/summary.md ]' \
  "slurm run with a mock sbatch: $(tail -20 slurm.txt)"
check 'grep -q "^sbatch --parsable --job-name=arco-run-take1 --cpus-per-task=2 --mem=4000 --time=120 --output=logs/slurm/arco-run-take1-%j.out .*snakejob.run" sbatch.log &&
       grep -q "^sbatch --parsable --job-name=arco-eval-take1 --cpus-per-task=1 --mem=2000 " sbatch.log &&
       [ "$(wc -l < sbatch.log)" -eq 2 ]' "sbatch submissions: $(cat sbatch.log)"

[ $fail -eq 0 ] && echo "workflow_test: all passed"
exit $fail
