#!/usr/bin/env bash
# Interrupts (docs/architecture.md, "Outputs"): SIGINT (Ctrl-C) or SIGTERM while a command
# writes removes what it was writing (its hidden .tmp-PID.* entries) and exits with 130,
# leaving the output's folder exactly as it was; a process killed outright (SIGKILL) leaves
# its temporary, which the next command writing into that folder removes.
# usage: interrupt_cli_test.sh ARCO_BINARY SHARED_DATA_DIR
set -uo pipefail
arco=$(realpath "$1")
export ARCO_SHARED_DATA_DIR=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"

# handles_sigint PID: the process has installed its SIGINT handler (SigCgt bit 2 in
# /proc/PID/status). Before that a background job of a script ignores SIGINT, as bash
# starts it with SIGINT ignored.
handles_sigint() {
  local caught; caught=$(awk '/^SigCgt:/ {print $2}' "/proc/$1/status" 2>/dev/null)
  [ -n "$caught" ] && (( (0x$caught & 2) != 0 ))
}

# start DIR ARGS...: runs `arco ARGS` in the background ($pid), waits until it handles
# SIGINT and has a temporary in DIR (at most 60 s), then a little longer, so that it is
# inside its work; with DIR "-", only 0.2 s after the handler (still computing).
start() {
  local dir=$1; shift
  "$arco" "$@" >"$tmp/out" 2>"$tmp/err" &
  pid=$!
  local waited=0
  until handles_sigint "$pid" || [ $waited -ge 1200 ]; do sleep 0.05; waited=$((waited + 1)); done
  if [ "$dir" = - ]; then sleep 0.2; return; fi
  until [ -n "$(find "$dir" -maxdepth 1 -name ".tmp-$pid.*" 2>/dev/null)" ] || [ $waited -ge 1200 ]; do
    sleep 0.05; waited=$((waited + 1))
  done
  check '[ $waited -lt 1200 ]' "$*: no temporary in $dir after 60 s"
  sleep 0.2
}

# interrupt NAME SIGNAL DIR WAIT ARGS...: the command, interrupted with SIGNAL once it has
# a temporary in DIR (WAIT "tmp") or while it computes (WAIT "-"), exits 130 with one line
# saying so, and DIR is as it was.
interrupt() {
  local name=$1 signal=$2 dir=$3 when=$4; shift 4
  mkdir -p "$dir"
  local before; before=$(SNAPSHOT_DIR=$dir snapshot)
  if [ "$when" = tmp ]; then start "$dir" "$@"; else start - "$@"; fi
  kill -"$signal" "$pid"
  wait "$pid"
  local rc=$?
  check '[ $rc -eq 130 ]' "$name: exit $rc, want 130: $(tail -1 "$tmp/err")"
  check 'grep -q "^arco: interrupted (SIG$signal)" "$tmp/err"' "$name: no 'interrupted' line: $(tail -1 "$tmp/err")"
  check '[ "$(SNAPSHOT_DIR=$dir snapshot)" = "$before" ]' "$name: $dir changed: $(ls -A "$dir" | tr '\n' ' ')"
}

"$arco" synth --duration-s 6 --seed 2 --no-audio -o "$tmp/cap" >"$tmp/log" 2>&1
check '[ $? -eq 0 ]' "synth the capture: $(tail -1 "$tmp/log")"

# While the result folder is being written (run writes it from its first stage on).
interrupt "run, SIGINT" INT "$tmp/b" tmp run "$tmp/cap" -o "$tmp/b/res" --threads 1
interrupt "run, SIGTERM" TERM "$tmp/b" tmp run "$tmp/cap" -o "$tmp/b/res" --threads 1
# An output being replaced (--overwrite): the old one stays whole.
"$arco" run "$tmp/cap" -o "$tmp/b/res" --threads 2 >"$tmp/log" 2>&1
check '[ $? -eq 0 ]' "run: $(tail -1 "$tmp/log")"
interrupt "run --overwrite, SIGINT" INT "$tmp/b" tmp run "$tmp/cap" -o "$tmp/b/res" --overwrite --threads 1
# synth computes before it writes (and writes in a moment): interrupted while computing.
interrupt "synth, SIGINT" INT "$tmp/a" - synth --no-audio -o "$tmp/a/cap"

# SIGKILL cannot be handled: the temporary stays until the next command writes there.
start "$tmp/c" run "$tmp/cap" -o "$tmp/c/res" --threads 1
kill -KILL "$pid"
wait "$pid" 2>/dev/null
check '[ -n "$(find "$tmp/c" -maxdepth 1 -name ".tmp-$pid.*")" ]' "SIGKILL leaves its temporary"
ok "a later command into the same folder" export "$tmp/b/res" --format csv --method vision -o "$tmp/c/x.csv"
check '[ -z "$(find "$tmp/c" -maxdepth 1 -name ".tmp-*")" ] && [ -s "$tmp/c/x.csv" ]' \
  "the next start removes the dead process's temporary: $(ls -A "$tmp/c" | tr '\n' ' ')"
exit $fail
