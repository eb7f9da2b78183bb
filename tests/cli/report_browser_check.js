// `arco report`'s page in Debian's chromium (report_cli_test.sh): it loads without errors,
// shows one table row per note of fingering.csv (each with its note name), every passage,
// the two figures, and a screenshot that is not blank.
// usage: node report_browser_check.js PLAYWRIGHT_DIR REPORT_HTML FINGERING_CSV WORK_DIR
'use strict';
const fs = require('fs');
const path = require('path');
const lib = require('../view/browser_test_lib.js');

async function main() {
  const [playwright, report, fingeringCsv, work] = process.argv.slice(2);
  const { check, failures } = lib.makeChecker();
  const lines = fs.readFileSync(fingeringCsv, 'utf8').trim().split('\n');
  const header = lines[0].split(',');
  const noteCol = header.indexOf('note'), nameCol = header.indexOf('note_name');
  const notes = lines.slice(1).map((l) => l.split(','));
  const browser = await lib.launchChromium(playwright);
  try {
    const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
    const errors = [];
    page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto('file://' + path.resolve(report));
    check(errors.length === 0, 'no page errors: ' + errors.join('; '));
    const rows = await page.$$eval('tr.note', (trs) => trs.map((tr) => ({
      note: tr.dataset.note, name: tr.children[2].textContent })));
    check(rows.length === notes.length, `one row per note: ${rows.length} rows, ${notes.length} notes`);
    let missing = 0;
    for (const n of notes) {
      const row = rows.find((r) => r.note === n[noteCol]);
      if (!row || row.name !== n[nameCol]) missing += 1;
    }
    check(missing === 0, `every note present with its name (${missing} missing)`);
    const passages = await page.$$eval('section.passage', (s) => s.length);
    check(passages >= 1, `passages: ${passages}`);
    const plots = await page.$$eval('figure.plot svg', (s) => s.map((x) => x.getBoundingClientRect().width));
    check(plots.length === 2 && plots.every((w) => w > 300), `two figures drawn: widths ${plots}`);
    const png = lib.decodePng(await page.screenshot({ path: path.join(work, 'report.png'), fullPage: true }));
    const variance = lib.lumaVariance(png);
    check(variance > 100, `screenshot not blank: luma variance ${variance.toFixed(1)}`);
  } finally {
    await browser.close();
  }
  process.exit(failures() ? 1 : 0);
}
main().catch((e) => { console.log('FAILED  ' + e.stack); process.exit(1); });
