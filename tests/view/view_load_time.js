// Load time of `arco view` pages (docs/view.md, docs/performance.md): the time from
// navigation to the page's ready flag (data fetched or decoded, scene built, frame 0
// drawn), served and from disk, and the mean time of one frame update (seek + render) over
// 200 frames. Headless Chromium renders with SwiftShader (software GL), so the frame time
// is an upper bound of a laptop's.
// With camera videos, also the time from navigation until the first video shows a frame
// (readyState >= 2), and the time `arco view` takes until the URL is printed.
// usage: node view_load_time.js ARCO RESULT WORK_DIR PLAYWRIGHT_CORE_DIR [RUNS [ARCO_VIEW_ARGS]]
//   ARCO_VIEW_ARGS: more options of both `arco view` runs, space-separated (--no-videos).
'use strict';
const fs = require('fs');
const path = require('path');
const {spawn, execFileSync} = require('child_process');
const [arco, result, work, playwrightDir, runsText, extraText] = process.argv.slice(2);
const extra = (extraText || '').split(' ').filter((a) => a);
const runs = Number(runsText || 3);
const {chromium} = require(path.resolve(playwrightDir));

async function timeLoad(browser, url) {
  const page = await browser.newPage({viewport: {width: 1280, height: 720}});
  const start = Date.now();
  await page.goto(url);
  await page.waitForFunction(
      () => window.arcoView && window.arcoView.ready, null, {timeout: 120000, polling: 10});
  const loadS = (Date.now() - start) / 1000;
  const timings = await page.evaluate(() => window.arcoView.timings);
  let videoS = null;
  if (await page.evaluate(() => window.arcoView.video() !== null)) {
    await page.waitForFunction(
        () => window.arcoView.video().readyState >= 2, null, {timeout: 120000, polling: 10});
    videoS = (Date.now() - start) / 1000;
  }
  console.log(
      `  ${url.slice(0, 30)}: ${loadS.toFixed(2)} s; in the page: data ${
          timings.data_ms.toFixed(0)} ms, ready ${timings.ready_ms.toFixed(0)} ms` +
      (videoS === null ? '' : `; video frame shown at ${videoS.toFixed(2)} s`));
  await page.waitForTimeout(1000);  // the page's work after ready (audio metadata, GC)
  const frameMs = await page.evaluate(() => {
    const n = Math.min(200, window.arcoView.seek(1e9) + 1);
    const t0 = performance.now();
    for (let f = 0; f < n; ++f) window.arcoView.seek(f);
    return (performance.now() - t0) / n;
  });
  await page.close();
  return {loadS, frameMs};
}
const median = (v) => v.slice().sort((a, b) => a - b)[Math.floor(v.length / 2)];

(async () => {
  fs.mkdirSync(work, {recursive: true});
  const started = Date.now();
  const child = spawn(arco, ['view', result, '--port', '0', '--exit-after-s', '3600', ...extra]);
  const url = await new Promise((resolve) => {
    let out = '';
    child.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (m) resolve(m[0]);
    });
  });
  console.log(`arco view ${extra.join(' ')}: the URL printed after ${
      ((Date.now() - started) / 1000).toFixed(1)} s`);
  const folder = path.join(work, 'page');
  fs.rmSync(folder, {recursive: true, force: true});
  execFileSync(arco, ['view', result, '--no-serve', '-o', folder, ...extra], {stdio: 'pipe'});
  const browser = await chromium.launch({
    executablePath: '/usr/bin/chromium',
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader']
  });
  for (const [label, target] of [
           ['served', url],
           ['file://', 'file://' + path.join(folder, 'index.html')]]) {
    const loads = [], frames = [];
    for (let i = 0; i < runs; ++i) {
      const r = await timeLoad(browser, target);
      loads.push(r.loadS);
      frames.push(r.frameMs);
    }
    console.log(
        `${label}: load ${median(loads).toFixed(2)} s (median of ${runs}: ${
            loads.map((x) => x.toFixed(2)).join(', ')}), ` +
        `frame update ${median(frames).toFixed(2)} ms`);
  }
  await browser.close();
  child.kill('SIGINT');
})();
