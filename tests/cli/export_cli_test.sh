#!/usr/bin/env bash
# `arco export` (docs/export.md) on a synthetic result with gaps: every format read back by
# an independent reader (export_check.py: Python with numpy and struct only) against
# points3d.npy (within 1e-3 mm; frame counts, rates, names, gaps; BVH forward kinematics
# within the residuals the file reports), the .glb by the Khronos glTF-Validator with 0
# errors; bad input (unknown format or method, a method the result lacks, no result, an
# unwritable output, a damaged points3d.npy or result.json) is one line "arco: error: ...",
# exit 1, and nothing written.
# The validator comes from scripts/fetch_gltf_validator; without it (or node) the test
# skips (exit 77) unless CI is set, where it fails.
# usage: export_cli_test.sh ARCO_BINARY SOURCE_DIR
set -uo pipefail
arco=$1
src=$2
py=/usr/bin/python3
check_py=$src/tests/cli/export_check.py
validator=$src/tools/gltf_validate
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"

synth_and_run "$tmp/cap" "$tmp/res" 2
# Gaps: a fingertip for three frames, the nose for one (the contact point has its own).
"$py" - "$tmp/res" <<'PY' || { echo "FAILED: making gaps"; exit 1; }
import json, sys
import numpy as np
d = sys.argv[1]
names = json.load(open(d + "/result.json"))["stages"]["arco"]["keypoint_names"]
x = np.load(d + "/arco/points3d.npy")
x[5:8, names.index("left_hand_index_tip")] = np.nan
x[10, names.index("nose")] = np.nan
np.save(d + "/arco/points3d.npy", x)
PY

mkdir -p "$tmp/w"
SNAPSHOT_DIR=$tmp/w
for format in csv trc c3d gltf bvh; do
  out=$tmp/w/take.${format/gltf/glb}
  if ! "$arco" export "$tmp/res" --format $format -o "$out" >"$tmp/out" 2>"$tmp/err"; then
    echo "FAILED: export --format $format: $(cat "$tmp/err")"; fail=1; continue
  fi
  check '"$py" "$check_py" $format "$out" "$tmp/res" arco' "read back $format"
done
"$arco" export "$tmp/res" --format bvh --method paper -o "$tmp/w/paper.bvh" >/dev/null &&
  check '"$py" "$check_py" bvh "$tmp/w/paper.bvh" "$tmp/res" paper' "read back paper's bvh"
grep -q "BVH fit residual, median: body" "$tmp/out" || { echo "FAILED: BVH residual line"; fail=1; }

# Bad input: nothing written.
cp -r "$tmp/res" "$tmp/nopaper"
"$py" -c "
import json, sys
p = sys.argv[1] + '/result.json'; r = json.load(open(p)); del r['stages']['paper']
json.dump(r, open(p, 'w'))" "$tmp/nopaper"
expect_error "unknown format" "--format: 'fbx' is not csv, trc, c3d, gltf (glb) or bvh" \
  export "$tmp/res" --format fbx -o "$tmp/w/x.fbx"
expect_error "unknown method" "--method: 'truth' is not arco, paper or vision" \
  export "$tmp/res" --format csv --method truth -o "$tmp/w/x.csv"
expect_error "method not in the result" "$tmp/nopaper/result.json: the result has no 'paper' points*" \
  export "$tmp/nopaper" --format csv --method paper -o "$tmp/w/x.csv"
expect_error "no result folder" "$tmp/none/result.json: *" \
  export "$tmp/none" --format csv -o "$tmp/w/x.csv"
expect_error "output in a missing folder" "$tmp/w/missing/x.csv: *" \
  export "$tmp/res" --format csv -o "$tmp/w/missing/x.csv"
expect_error "output under a file" "$tmp/w/take.csv/x.csv: *" \
  export "$tmp/res" --format csv -o "$tmp/w/take.csv/x.csv"
# Damaged results: one line naming the file.
cp -r "$tmp/res" "$tmp/garbage" && echo "not an npy" >"$tmp/garbage/arco/points3d.npy"
expect_error "points3d.npy not an npy" "$tmp/garbage/arco/points3d.npy: *" \
  export "$tmp/garbage" --format bvh -o "$tmp/w/x.bvh"
cp -r "$tmp/res" "$tmp/shape"
"$py" -c "import numpy as np, sys; np.save(sys.argv[1], np.zeros((4, 10, 3)))" \
  "$tmp/shape/arco/points3d.npy"
expect_error "points3d.npy of another layout" "$tmp/shape/arco/points3d.npy: shape is not (frames >= 1, 155, 3)" \
  export "$tmp/shape" --format gltf -o "$tmp/w/x.glb"
cp -r "$tmp/res" "$tmp/json" && echo "{" >"$tmp/json/result.json"
expect_error "result.json not JSON" "$tmp/json/result.json: *" export "$tmp/json" --format trc -o "$tmp/w/x.trc"
mkdir -p "$tmp/w/dir.trc"
expect_error "output is a folder" "$tmp/w/dir.trc: *" export "$tmp/res" --format trc -o "$tmp/w/dir.trc"

# The Khronos validator: 0 errors.
if command -v node >/dev/null && [ -d "$validator/node_modules/gltf-validator" ]; then
  check 'NODE_PATH="$validator/node_modules" node "$validator/validate.js" "$tmp/w/take.glb"' \
    "gltf-validator on the .glb"
elif [ -n "${CI:-}" ]; then
  echo "FAILED: gltf-validator missing (scripts/fetch_gltf_validator)"; fail=1
else
  [ $fail -eq 0 ] && { echo "SKIPPED: gltf-validator missing (scripts/fetch_gltf_validator)"; exit 77; }
fi
exit $fail
