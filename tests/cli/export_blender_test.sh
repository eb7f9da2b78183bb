#!/usr/bin/env bash
# The consumer test of `arco export` (docs/export.md): Debian's Blender, headless, imports
# the BVH and the .glb of a synthetic result with its own importers, and
# export_blender.py checks the frame count, the bone/object count and the left
# fingertips' world positions at several frames against points3d.npy (within 1 mm).
# Without blender (scripts/setup installs it for the tests) the test skips (exit 77)
# unless CI is set, where it fails.
# usage: export_blender_test.sh ARCO_BINARY SOURCE_DIR
set -uo pipefail
arco=$1
src=$2
if ! command -v blender >/dev/null; then
  if [ -n "${CI:-}" ]; then echo "FAILED: blender is not installed (scripts/setup)"; exit 1; fi
  echo "SKIPPED: blender is not installed (scripts/setup)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$arco" synth -o "$tmp/cap" --duration-s 2 >/dev/null 2>&1 &&
  "$arco" run "$tmp/cap" -o "$tmp/res" >/dev/null 2>&1 &&
  "$arco" export "$tmp/res" --format bvh -o "$tmp/take.bvh" >/dev/null &&
  "$arco" export "$tmp/res" --format gltf -o "$tmp/take.glb" >/dev/null ||
  { echo "FAILED: synth, run or export"; exit 1; }
blender -b --factory-startup --python-exit-code 1 \
  --python "$src/tests/cli/export_blender.py" -- "$tmp/take.bvh" "$tmp/take.glb" "$tmp/res" arco \
  >"$tmp/blender.log" 2>&1
rc=$?
grep -E "^(FAIL|blender (bvh|glb))" "$tmp/blender.log"
if [ $rc -ne 0 ] || [ "$(grep -c '^blender \(bvh\|glb\):' "$tmp/blender.log")" -ne 2 ]; then
  echo "FAILED: blender exit $rc"; tail -20 "$tmp/blender.log"; exit 1
fi
