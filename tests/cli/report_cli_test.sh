#!/usr/bin/env bash
# `arco report` (docs/report.md): a teacher's page of a synthetic result (arco synth + arco
# run): one row per note with the truth's strings and fingers, intonation and bowing, the
# bad inputs (one line, nothing written), and the page in Debian's chromium
# (report_browser_check.js; skipped, 77, only when /usr/bin/chromium is absent).
# usage: report_cli_test.sh ARCO_BINARY SOURCE_DIR
set -uo pipefail
arco=$(realpath "$1")
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source "$src/tests/cli/cli_test_lib.sh"

"$arco" synth --duration-s 12 --piece slow-melody --seed 2 -o "$tmp/cap" >/dev/null 2>&1 &&
  "$arco" run "$tmp/cap" -o "$tmp/res" >/dev/null 2>&1 ||
  { echo "FAILED: synth + run"; exit 1; }
ok "report" report "$tmp/res" -o "$tmp/report.html"
check 'grep -q "with bowing" "$tmp/out"' "the summary line says the bowing is in: $(cat "$tmp/out")"
/usr/bin/python3 - "$tmp/report.html" "$tmp/res/arco/fingering.csv" "$tmp/res/arco/bowing_notes.csv" \
  "$tmp/cap/truth/notes.csv" <<'PY' || fail=1
import csv, html.parser, sys
page, fingering, bowing, truth = sys.argv[1:]
class Rows(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(); self.rows = []; self.cell = None; self.in_row = False
    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "tr" and "note" in a.get("class", "").split():
            self.rows.append({"note": a["data-note"], "cells": []}); self.in_row = True
        elif tag == "td" and self.in_row:
            self.cell = ""
    def handle_endtag(self, tag):
        if tag == "td" and self.cell is not None:
            self.rows[-1]["cells"].append(self.cell.strip()); self.cell = None
        if tag == "tr": self.in_row = False
    def handle_data(self, data):
        if self.cell is not None: self.cell += data
p = Rows(); p.feed(open(page).read())
notes = list(csv.DictReader(open(fingering)))
bows = {b["note"]: b for b in csv.DictReader(open(bowing))}
bad = []
if len(p.rows) != len(notes): bad.append("%d rows for %d notes" % (len(p.rows), len(notes)))
by_note = {r["note"]: r["cells"] for r in p.rows}
for n in notes:
    cells = by_note.get(n["note"])
    if cells is None: bad.append("note %s missing" % n["note"]); continue
    # columns: #, time, note, string, finger, position, cents, vibrato, bow, sounding point, bow on
    if cells[2] != n["note_name"]: bad.append("note %s: name %s vs %s" % (n["note"], cells[2], n["note_name"]))
    cents = round(float(n["cents_off"]))
    if cells[6].replace("+", "") != str(cents) and not (cents == 0 and cells[6] in ("+0", "-0", "0")):
        bad.append("note %s: cents %s vs %s" % (n["note"], cells[6], n["cents_off"]))
    b = bows.get(n["note"])
    if b is None or cells[8] != b["direction"]: bad.append("note %s: bow %s vs %s" % (n["note"], cells[8], b and b["direction"]))
# The strings shown are arco's; on this clean synthetic take they are the truth's (by onset).
truth = list(csv.DictReader(open(truth)))
agree = 0
for n in notes:
    t = min(truth, key=lambda t: abs(float(t["onset_s"]) - float(n["onset_s"])))
    agree += t["string"] == n["string"]
if agree < 0.9 * len(notes): bad.append("only %d of %d notes on the truth's string" % (agree, len(notes)))
print("%d notes, %d rows, %d truth notes, %d on the truth's string" % (len(notes), len(p.rows), len(truth), agree))
for b in bad[:10]: print("FAILED: " + b)
sys.exit(1 if bad else 0)
PY

# Double stops: a row holds both notes where arco's fingering_2.csv has a second voice.
"$arco" synth --duration-s 6 --piece double-stops --instrument violin -o "$tmp/ds" >/dev/null 2>&1 &&
  "$arco" run "$tmp/ds" -o "$tmp/ds_res" --double-stops >/dev/null 2>&1 ||
  { echo "FAILED: synth + run --double-stops"; exit 1; }
ok "report of double stops" report "$tmp/ds_res" -o "$tmp/ds_report.html"
/usr/bin/python3 - "$tmp/ds_report.html" "$tmp/ds_res/arco/fingering.csv" \
  "$tmp/ds_res/arco/fingering_2.csv" <<'PY' || fail=1
import csv, re, sys
page, fingering, second = sys.argv[1:]
text = open(page).read()
rows = dict(re.findall(r'<tr class="note[^"]*" data-note="(\d+)">(.*?)</tr>', text))
upper = {u["note"]: u for u in csv.DictReader(open(second)) if u["state"] in ("pressed", "open")}
bad = []
if not upper: bad.append("no second voice in fingering_2.csv")
for n in csv.DictReader(open(fingering)):
    cells = re.findall(r"<td[^>]*>(.*?)</td>", rows.get(n["note"], ""))
    if not cells: bad.append("note %s missing" % n["note"]); continue
    u = upper.get(n["note"])
    want = n["note_name"] + (" + " + u["note_name"] if u else "")
    if cells[2] != want: bad.append("note %s: %r, want %r" % (n["note"], cells[2], want))
    if u and u["state"] == "pressed" and not cells[4].endswith(" + " + u["finger"]):
        bad.append("note %s: fingers %r, second %s" % (n["note"], cells[4], u["finger"]))
m = re.search(r"<b>(\d+)</b>double stops", text)
if not m or int(m.group(1)) != len(upper):
    bad.append("summary %s double stops for %d" % (m and m.group(1), len(upper)))
print("%d double stops in the report" % len(upper))
for b in bad[:10]: print("FAILED: " + b)
sys.exit(1 if bad else 0)
PY

# Bad input: one line, nothing written.
SNAPSHOT_DIR=$tmp
mkdir -p "$tmp/empty"
expect_error "not a result" "*empty/result.json*" report "$tmp/empty" -o "$tmp/r.html"
expect_error "not .html" "*-o*html*" report "$tmp/res" -o "$tmp/report.pdf"
expect_error "vision has no fingering" "*--method*" report "$tmp/res" --method vision -o "$tmp/r.html"
expect_error "passage gap out of range" "*--passage-gap-s*" report "$tmp/res" --passage-gap-s 0 -o "$tmp/r.html"
expect_error "output inside the result" "*-o*" report "$tmp/res" -o "$tmp/res/report.html"
cp -r "$tmp/res" "$tmp/res_no_fingering"
rm "$tmp/res_no_fingering/arco/fingering.csv"
expect_error "no fingering" "*fingering.csv*" report "$tmp/res_no_fingering" -o "$tmp/r.html"
[ $fail -eq 0 ] || exit 1

require_browser "$src"
node "$src/tests/cli/report_browser_check.js" "$playwright" "$tmp/report.html" \
  "$tmp/res/arco/fingering.csv" "$tmp" || fail=1
[ $fail -eq 0 ] && echo "report_cli_test: passed"
exit $fail
