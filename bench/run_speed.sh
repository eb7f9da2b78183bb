#!/usr/bin/env bash
# `arco run` speed on the one-minute 20-camera synthetic take (docs/performance.md,
# "Whole pipeline"): the take is 58.0 s of music (`arco synth --tempo-scale 3.688`,
# 1738 frames, 142 keypoints). Each build in turn, --threads 1 and 2, REPEATS times
# alternately; the fastest wall time of each is kept. Prints x real time, peak RSS, and
# per stage: wall s per minute of performance, us per view-frame, scaling 1 -> 2 threads.
# Results must not depend on the thread count: every output file is compared.
#   bench/run_speed.sh BUILD_DIR [BASELINE_BUILD_DIR] [REPEATS]
set -euo pipefail
build=$(realpath "${1:-build}")
baseline=${2:-}
repeats=${3:-2}
[ -n "$baseline" ] && baseline=$(realpath "$baseline")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$build/bin/arco" synth -o "$work/cap" --tempo-scale 3.688 > /dev/null
read -r music_s views frames < <(/usr/bin/python3 -c "
import json, numpy as np
k = np.load('$work/cap/keypoints2d.npy', mmap_mode='r')
print(k.shape[0] / json.load(open('$work/cap/capture.json'))['fps'], k.shape[1], k.shape[0])")
run() {  # label build threads repeat
  local out="$work/$1-t$3-r$4"
  /usr/bin/time -f "%e %U %S %M" -o "$out.time" "$2/bin/arco" run "$work/cap" -o "$out" \
    --threads "$3" > "$out.log" 2>&1
}
labels="new"
[ -n "$baseline" ] && labels="baseline new"
for r in $(seq 1 "$repeats"); do
  for label in $labels; do
    b=$build
    [ "$label" = baseline ] && b=$baseline
    for t in 1 2; do run "$label" "$b" "$t" "$r"; done
  done
done
/usr/bin/python3 - "$work" "$music_s" "$views" "$repeats" "$frames" $labels <<'PY'
import glob, os, re, sys
work, music_s, views, repeats = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
frames = int(sys.argv[5])
labels = sys.argv[6:]
def best(label, t):
    runs = []
    for r in range(1, repeats + 1):
        base = f"{work}/{label}-t{t}-r{r}"
        wall, user, sys_, rss = open(base + ".time").read().split()[:4]
        stages = {}
        for line in open(base + ".log"):
            m = re.match(r"^(\w+)\s+([0-9.]+) s\s", line)
            if m: stages[m.group(1)] = float(m.group(2))
        runs.append((float(wall), float(user) + float(sys_), int(rss) / 1024, stages))
    return min(runs, key=lambda x: x[0])
def same(label):  # outputs of 1 and 2 threads, bit for bit (result.json records the threads)
    a, b = f"{work}/{label}-t1-r1", f"{work}/{label}-t2-r1"
    for root, _, files in os.walk(a):
        for f in files:
            p = os.path.join(root, f)
            if f == "result.json": continue
            q = os.path.join(b, os.path.relpath(p, a))
            if open(p, "rb").read() != open(q, "rb").read(): return "differ: " + os.path.relpath(p, a)
    return "identical"
print(f"take: {music_s:.1f} s of music, {frames} frames, {views} views")
print()
print("| build | threads | wall s | CPU s | x real time | peak RSS MB | outputs 1 vs 2 threads |")
print("|---|---|---|---|---|---|---|")
for label in labels:
    for t in (1, 2):
        wall, cpu, rss, _ = best(label, t)
        print(f"| {label} | {t} | {wall:.2f} | {cpu:.1f} | {music_s / wall:.2f}x | {rss:.0f} | {same(label) if t == 2 else ''} |")
for label in labels:
    print()
    print(f"{label}, per stage (fastest run's own stage times):")
    print()
    print("| stage | s per minute, 1 thread | s per minute, 2 threads | us per view-frame, 2 threads | scaling 1 -> 2 |")
    print("|---|---|---|---|---|")
    s1, s2 = best(label, 1)[3], best(label, 2)[3]
    for k in s2:
        a, b = s1.get(k, float("nan")), s2[k]
        vf = f"{1e6 * b / (frames * views):.0f}" if k in ("triangulate", "hands") else ""
        print(f"| {k} | {60 * a / music_s:.2f} | {60 * b / music_s:.2f} | {vf} | {a / b:.2f}x |")
PY
