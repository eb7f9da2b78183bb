#!/usr/bin/env bash
# ctest's install_test: arco as a user installs it (docs/install.md).
#  1. `cmake --install` into a temporary prefix, which is then moved elsewhere (arco finds
#     its data from its own path: a relocatable prefix).
#  2. From a working folder outside the source tree, with a clean environment, under
#     `strace -f -e trace=open,openat`: `arco --version` (the version and this checkout's
#     revision), `arco info`, a short `arco synth` + `arco run`, `arco view --no-serve`,
#     `arco batch --print-command` (the installed workflow),
#     `man -l` on a page, the bash completion, `import arco` from the installed module with
#     /usr/bin/python3. Nothing under the source or the build folder may be opened (failed
#     attempts included): the installed arco uses none of the paths compiled in.
#  3. A missing data file is named, with ARCO_DATA_DIR and with --data-dir.
#  4. The Debian package (cpack -G DEB, what `make package` builds): its name, its files
#     (dpkg-deb -c; no test or benchmark binaries) and its Depends from dpkg-shlibdeps.
# usage: install_test.sh BUILD_DIR SOURCE_DIR SHARED_DATA_DIR MODELS_DIR VERSION PYTHON_DIR
# (PYTHON_DIR: where the module is installed relative to the prefix, "" when not built).
# Exit 77 (skipped) without strace, man, dpkg-deb or dpkg-shlibdeps, unless CI is set.
set -uo pipefail
build=$(cd "$1" && pwd -P)
src=$(cd "$2" && pwd -P)
spd="$3/spd"
models=$4
version=$5
python_dir=$6

for tool in strace man dpkg-deb dpkg-shlibdeps cpack; do
  if ! command -v "$tool" >/dev/null; then
    echo "install_test: $tool is not installed (scripts/setup installs it)" >&2
    if [ -n "${CI:-}" ]; then exit 1; fi
    exit 77
  fi
done

tmp=$(mktemp -d "${TMPDIR:-/tmp}/arco_install_test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
case "$tmp/" in
  "$src"/* | "$build"/*) echo "install_test: the scratch folder $tmp is inside the source tree" >&2; exit 1 ;;
esac
fail=0
check() { if ! eval "$1"; then echo "FAILED: $2"; fail=1; fi; }
seconds() { date +%s.%N; }
t0=$(seconds)

# 1. Install, then move the prefix.
if ! cmake --install "$build" --prefix "$tmp/staged" >"$tmp/install.log" 2>&1; then
  cat "$tmp/install.log"
  echo "FAILED: cmake --install"
  exit 1
fi
mv "$tmp/staged" "$tmp/prefix"
p=$tmp/prefix
for f in bin/arco share/arco/view/web/index.html share/arco/view/web/viewer.js \
         share/arco/view/web/viewer.css share/arco/view/three.min.js \
         share/arco/workflow/Snakefile share/man/man1/arco.1.gz share/man/man1/arco-run.1.gz \
         share/man/man1/arco-capture-new.1.gz share/bash-completion/completions/arco \
         share/doc/arco/README.md; do
  check '[ -s "$p/$f" ]' "installed: $f"
done
# The models when the build had them (make build's scripts/setup fetches them).
if compgen -G "$models/*.onnx" >/dev/null; then
  for m in "$models"/*.onnx; do
    check 'cmp -s "$m" "$p/share/arco/models/$(basename "$m")"' "installed model $(basename "$m")"
  done
fi
module=""
if [ -n "$python_dir" ]; then
  module=$(compgen -G "$p/$python_dir/arco.cpython-*.so" | head -1)
  check '[ -n "$module" ]' "installed: the Python module in $python_dir"
fi
check '[ -z "$(find "$p" -name "*_test*" -o -name "*_bench*" -o -name "*_fuzz*")" ]' \
  "no test or benchmark files installed: $(find "$p" -name "*_test*" -o -name "*_bench*" | head -3)"
t_install=$(seconds)

# 2. The installed arco under strace, from a folder outside the source tree.
mkdir -p "$tmp/work" "$tmp/home"
cat >"$tmp/session.sh" <<'SESSION'
# Each step's failure is written to failures (the script goes on, to trace every step).
step() { local name=$1; shift; "$@" >"$name.out" 2>"$name.err" || echo "$name: exit $?" >>failures; }
cd "$WORK"
: >failures
step version "$P/bin/arco" --version
step info "$P/bin/arco" info
step synth "$P/bin/arco" synth --calibration "$SPD/cello_1113_scale_camera.xml" --duration-s 2 \
  --seed 1 -o capture
step run "$P/bin/arco" run capture -o result
step view "$P/bin/arco" view result --no-serve -o page --no-videos
mkdir -p takes
step batch "$P/bin/arco" batch takes -o batch_out --print-command
MANWIDTH=80 step man man --warnings -l "$P/share/man/man1/arco-run.1.gz"
step completion bash -c 'source "$1"; COMP_WORDS=(arco sy); COMP_CWORD=1; _arco
  echo "${COMPREPLY[*]}"; COMP_WORDS=(arco capture new --instrument vi); COMP_CWORD=4; _arco
  echo "${COMPREPLY[*]}"' bash "$P/share/bash-completion/completions/arco"
if [ -n "$PYDIR" ]; then
  PYTHONPATH="$P/$PYDIR" PYTHONDONTWRITEBYTECODE=1 step python /usr/bin/python3 -c \
    'import arco; print(arco.__file__); print(arco.__version__)'
fi
SESSION
env -i HOME="$tmp/home" PATH=/usr/local/bin:/usr/bin:/bin LANG=C.UTF-8 WORK="$tmp/work" P="$p" \
  SPD="$spd" PYDIR="$python_dir" \
  strace -f -qq --seccomp-bpf -e trace=open,openat -o "$tmp/trace" bash "$tmp/session.sh"
t_session=$(seconds)
w=$tmp/work
check '[ ! -s "$w/failures" ]' "installed arco: $(cat "$w/failures" 2>/dev/null | tr '\n' ' ')
$(for f in "$w"/*.err; do [ -s "$f" ] && { echo "--- $(basename "$f")"; tail -5 "$f"; }; done)"
revision=$(git -C "$src" rev-parse --short=12 HEAD 2>/dev/null || echo unknown)
check 'grep -Eq "^arco $version \(git $revision(-dirty)?\)$" "$w/version.out"' \
  "arco --version: '$(cat "$w/version.out")', expected arco $version (git $revision...)"
check 'grep -qx "data: $p/share/arco" "$w/info.out"' "arco info: the data folder: $(tail -1 "$w/info.out")"
check '[ -f "$w/result/result.json" ]' "arco run wrote result/result.json"
check '[ -s "$w/page/index.html" ] && [ -s "$w/page/three.min.js" ] && [ -s "$w/page/data.js" ]' \
  "arco view --no-serve wrote the page with three.js"
check 'grep -q -- "-s $p/share/arco/workflow/Snakefile " "$w/batch.out"' \
  "arco batch runs the installed workflow: $(cat "$w/batch.out")"
check 'grep -q "arco run" "$w/man.out" && grep -q -- "--output" "$w/man.out"' \
  "man -l arco-run.1.gz: $(head -3 "$w/man.out")"
check '[ ! -s "$w/man.err" ]' "man --warnings: $(head -3 "$w/man.err")"
check '[ "$(sed -n 1p "$w/completion.out")" = "synth sync" ]' \
  "bash completion of 'arco sy': $(sed -n 1p "$w/completion.out")"
check '[ "$(sed -n 2p "$w/completion.out")" = "violin viola" ]' \
  "bash completion of 'arco capture new --instrument vi': $(sed -n 2p "$w/completion.out")"
if [ -n "$python_dir" ]; then
  check '[ "$(sed -n 1p "$w/python.out")" = "$module" ] && [ "$(sed -n 2p "$w/python.out")" = "$version" ]' \
    "import arco from the installed module: $(cat "$w/python.out")"
fi
# Every file opened, the failed attempts too: none in the source or the build tree.
opened=$(grep -oE "open(at)?\([^\"]*\"[^\"]*\"" "$tmp/trace" | sed 's/.*"\(.*\)"/\1/' | sort -u)
check 'grep -qx "$p/share/arco/view/web/index.html" <<<"$opened"' \
  "strace saw the installed arco read its data folder"
leaked=$(grep -E "^($src|$build)(/|$)" <<<"$opened" | head -5)
check '[ -z "$leaked" ]' "the installed arco opened files of the source or build tree: $leaked"

# 3. A missing data file is named, whichever way the data folder is given.
mkdir -p "$tmp/empty"
line=$(cd "$w" && ARCO_DATA_DIR="$tmp/empty" "$p/bin/arco" view result --no-serve -o page2 --no-videos 2>&1)
check '[ "$line" = "arco: error: $tmp/empty/view/web/index.html: the viewer'"'"'s page is missing (the data folder is \$ARCO_DATA_DIR (or --data-dir))" ]' \
  "ARCO_DATA_DIR without the page: $line"
line=$(cd "$w" && "$p/bin/arco" --data-dir "$tmp/empty" view result --no-serve -o page2 --no-videos 2>&1)
check '[[ "$line" == "arco: error: $tmp/empty/view/web/index.html: the viewer"* ]]' \
  "--data-dir without the page: $line"
line=$(cd "$w" && "$p/bin/arco" --data-dir "$tmp/none" info 2>&1)
check '[ "$line" = "arco: error: $tmp/none: no such folder (--data-dir)" ]' "--data-dir of no folder: $line"
rm "$p/share/arco/view/three.min.js"
line=$(cd "$w" && "$p/bin/arco" view result --no-serve -o page2 --no-videos 2>&1)
check '[[ "$line" == "arco: error: $p/share/arco/view/three.min.js: three.js not found"* ]]' \
  "a missing three.js is named: $line"

# The installed tree is checked: its space is freed before the package is staged (the
# staging folder and the uncompressed package are two more copies of the install).
rm -rf "$p" "$tmp/work" "$tmp/home" "$tmp/trace" "$tmp/empty"

# 4. The Debian package of the same install rules (uncompressed here: gzip of the models
# takes 30 s; the files and the control fields are those of `make package`'s).
if ! (cd "$tmp" && cpack -G DEB -D CPACK_DEBIAN_COMPRESSION_TYPE=none \
        --config "$build/CPackConfig.cmake" -B "$tmp/package") \
     >"$tmp/cpack.log" 2>&1; then
  tail -20 "$tmp/cpack.log"
  echo "FAILED: cpack -G DEB"
  exit 1
fi
deb=$tmp/package/arco_${version}_amd64.deb
check '[ -s "$deb" ]' "the package is arco_${version}_amd64.deb: $(ls "$tmp/package")"
if [ -s "$deb" ]; then
  dpkg-deb -c "$deb" | awk '{print $NF}' | sed 's|^\./|/|' >"$tmp/contents"
  for f in /usr/bin/arco /usr/share/arco/view/web/index.html /usr/share/arco/view/three.min.js \
           /usr/share/arco/workflow/Snakefile /usr/share/man/man1/arco.1.gz \
           /usr/share/man/man1/arco-run.1.gz /usr/share/bash-completion/completions/arco; do
    check 'grep -qx "$f" "$tmp/contents"' "the package holds $f"
  done
  if [ -n "$module" ]; then
    check 'grep -qx "/usr/$python_dir/$(basename "$module")" "$tmp/contents"' "the package holds the Python module"
  fi
  bad=$(grep -E "(_test|_bench|_fuzz)[^/]*$|/tests?/|/bench/|gtest|benchmark" "$tmp/contents" | head -3)
  check '[ -z "$bad" ]' "no test or benchmark files in the package: $bad"
  check '[ "$(dpkg-deb -f "$deb" Package)" = arco ] && [ "$(dpkg-deb -f "$deb" Architecture)" = amd64 ]' \
    "package arco, architecture amd64"
  depends=$(dpkg-deb -f "$deb" Depends)
  for lib in libc6 libstdc++6 libopencv-dnn libxnnpack0 libavcodec libsndfile1 libfftw3 libcpp-httplib; do
    check 'grep -q "$lib" <<<"$depends"' "Depends (dpkg-shlibdeps) names $lib: $depends"
  done
fi
t_end=$(seconds)
awk -v a="$t0" -v b="$t_install" -v c="$t_session" -v d="$t_end" 'BEGIN {
  printf "install_test: install %.1f s, installed arco under strace %.1f s, the rest %.1f s\n",
         b - a, c - b, d - c }'
[ $fail -eq 0 ] && echo "install test: all checks passed"
exit $fail
