#!/usr/bin/env bash
# End-to-end checks of `arco instrument`: the model table, the octave half way, and bad
# input (one error line, exit 1). usage: instrument_cli_test.sh ARCO_BINARY
set -uo pipefail
arco=$1
source "$(dirname "${BASH_SOURCE[0]}")/cli_test_lib.sh"

out=$("$arco" instrument cello --f0-hz 440 2>&1); rc=$?
check '[ $rc -eq 0 ]' "cello --f0-hz 440 exits 0"
check 'grep -Eq "^1 +A3 +220.00 +880.00" <<<"$out"' "string 1 is A3 220 Hz up to 880 Hz"
check 'grep -Eq "^4 +C2 +65.41" <<<"$out"' "string 4 is C2"
check 'grep -Eq "^1 +stopped .* 347.5 mm +0.5000" <<<"$out"' "A4 on the A string is half way"
check 'grep -Eq "^4 +above_range" <<<"$out"' "A4 is above the C string range"

out=$("$arco" instrument violin --a4-hz 442 --offset-cents 0,0,0,-200 2>&1); rc=$?
check '[ $rc -eq 0 ] && grep -Eq "^4 +G3 +175.41" <<<"$out"' "violin scordatura G3 -> F3 at A4=442"

out=$("$arco" instrument ukulele 2>&1); rc=$?
check '[ $rc -eq 1 ] && [ "$(wc -l <<<"$out")" -eq 1 ] && grep -q "^arco: error: unknown instrument .ukulele." <<<"$out"' \
  "unknown instrument: one error line, exit 1"
out=$("$arco" instrument cello --offset-cents 0,0 2>&1); rc=$?
check '[ $rc -eq 1 ] && grep -q "^arco: error: .*offset_cents" <<<"$out"' "wrong offset count: error"
out=$("$arco" instrument cello --a4-hz nan 2>&1); rc=$?
check '[ $rc -ne 0 ]' "NaN A4: error"
exit $fail
