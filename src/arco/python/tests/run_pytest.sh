#!/usr/bin/env bash
# ctest's python_test: pytest on the module with Debian's python3 (/usr/bin/python3 sees
# Debian's numpy and pytest). Exit 77 (skipped) when the module was not built because
# pybind11 was absent at configure time, or in a sanitizer build; a failure instead when
# CI or ARCO_REQUIRE_PYTHON_MODULE is set (`make test`, whose README promises the module).
#   run_pytest.sh TESTS_DIR   (PYTHONPATH, ARCO_BIN, ARCO_PYTHON_MODULE from ctest)
set -euo pipefail
if [ "${ARCO_PYTHON_MODULE:-ON}" = SANITIZED ]; then
  echo "python_test: sanitizer build, no Python module" >&2
  exit 77
fi
if [ "${ARCO_PYTHON_MODULE:-ON}" != ON ]; then
  echo "python_test: the module was not built (pybind11 absent at configure time)" >&2
  if [ -n "${CI:-}" ] || [ -n "${ARCO_REQUIRE_PYTHON_MODULE:-}" ]; then
    echo "python_test: required here: scripts/setup installs pybind11-dev and python3-dev," \
      "then configure the build again" >&2
    exit 1
  fi
  exit 77
fi
# No __pycache__ or .pytest_cache in the source tree.
export PYTHONDONTWRITEBYTECODE=1
# pytest's own temporary folders in one scratch folder removed on exit (its default, under
# /tmp/pytest-of-USER, keeps the last three runs: 28 MB each here).
base=$(mktemp -d "${TMPDIR:-/tmp}/arco_pytest.XXXXXX")
trap 'rm -rf "$base"' EXIT
/usr/bin/python3 -m pytest -q -p no:cacheprovider --basetemp="$base/tmp" "$1"
