// `arco view` in a real browser (docs/view.md): Debian's /usr/bin/chromium, headless,
// driven by playwright-core (scripts/fetch_view_tools). Checked against the result folder
// read here independently (the .npy and .wav files themselves, not the page's arrays):
//  - a second `arco view` on the same port fails with one line (the port is not shared);
//  - the served page loads with no console error, failed request or page error;
//  - the 3D canvas is not blank (pixel variance of a screenshot, decoded here);
//  - after seeking to two frames, the drawn left index fingertip sits where the points3d.npy
//    of the shown method projects through the camera the page reports (0.5 px), and so it
//    moves by the amount the data says;
//  - the audio element's duration equals the capture's audio.wav (from its RIFF header);
//  - the left hand's error against the synthetic truth (CAPTURE/truth/points3d.npy) as shown;
//  - the note of notes.csv is named in the pitch panel;
//  - the contact marker sits on contacts.csv's pressed point, and is hidden at rest;
//  - switching the method moves the hand to the other method's point;
//  - playing, the frame follows the audio clock;
//  - the speed control slows the audio without changing its pitch (preservesPitch);
//  - the --no-serve folder works from file:// with no server;
//  - a result missing a stage shows which in the page and in the terminal.
// usage: node view_browser_test.js ARCO RESULT BAD_RESULT WORK_DIR PLAYWRIGHT_CORE_DIR
'use strict';
const fs = require('fs');
const path = require('path');
const {execFileSync} = require('child_process');
const lib = require('./browser_test_lib.js');
const {decodePng, lumaVariance} = lib;

const [arco, result, badResult, work, playwrightDir] = process.argv.slice(2);
const tip = 'left_hand_index_tip';
const {check, failures} = lib.makeChecker();
const {readNpy, openPage, stopServer} = lib;

// ---- independent readers ------------------------------------------------------------------
function wavDurationS(file) {
  const b = fs.readFileSync(file);
  let rate = 0, blockAlign = 0, dataBytes = 0;
  for (let o = 12; o + 8 <= b.length;) {
    const id = b.toString('latin1', o, o + 4), size = b.readUInt32LE(o + 4);
    if (id === 'fmt ') {
      rate = b.readUInt32LE(o + 12);
      blockAlign = b.readUInt16LE(o + 20);
    }
    if (id === 'data') dataBytes = Math.min(size, b.length - o - 8);
    o += 8 + size + (size % 2);
  }
  return dataBytes / blockAlign / rate;
}

const resultJson = JSON.parse(fs.readFileSync(path.join(result, 'result.json'), 'utf8'));
function methodPoints(method) {
  const names = resultJson.stages[method].keypoint_names;
  return {names, points: readNpy(path.join(result, method, 'points3d.npy'))};
}
function pointAt(m, frame, name) {
  const p = m.names.indexOf(name), n = m.points.shape[1];
  const o = (frame * n + p) * 3;
  return [m.points.data[o], m.points.data[o + 1], m.points.data[o + 2]];
}
// Data mm -> CSS px through the matrix the page reports (column-major projection * view * root).
function project(clip, x) {
  const e = clip.matrix;
  const v = [0, 1, 2, 3].map((r) => e[r] * x[0] + e[4 + r] * x[1] + e[8 + r] * x[2] + e[12 + r]);
  return {x: (v[0] / v[3] + 1) / 2 * clip.width, y: (1 - v[1] / v[3]) / 2 * clip.height};
}
const dist = (a, b) => Math.hypot(a.x - b.x, a.y - b.y);

// `arco view` with its own TMPDIR, to see that the served folder is removed when it stops.
async function startServer(res) {
  const tmpdir = path.join(work, 'tmp_' + path.basename(res));
  fs.mkdirSync(tmpdir, {recursive: true});
  return {...(await lib.startServer(arco, res, [], {TMPDIR: tmpdir})), tmpdir};
}

// ---- the browser ---------------------------------------------------------------------------
async function canvasVariance(page, file) {
  const png = await page.locator('#canvas3d').screenshot({path: file});
  return lumaVariance(decodePng(png));
}
// Frames where the arco fingertip moves most between two sampled frames.
function framePair(m) {
  const frames = m.points.shape[0];
  let best = [0, frames - 1], bestD = -1;
  for (let a = 0; a < frames; a += 7) {
    for (let b = a + 7; b < frames; b += 7) {
      const pa = pointAt(m, a, tip), pb = pointAt(m, b, tip);
      const d = Math.hypot(pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]);
      if (d > bestD) {
        bestD = d;
        best = [a, b];
      }
    }
  }
  return best;
}
async function checkSeek(page, label, m) {
  const [f1, f2] = framePair(m);
  const shown = [];
  for (const f of [f1, f2]) {
    const frame = await page.evaluate((f) => window.arcoView.seek(f), f);
    const drawn = await page.evaluate((n) => window.arcoView.projectKeypoint(n), tip);
    const clip = await page.evaluate(() => window.arcoView.dataToClip());
    const expected = project(clip, pointAt(m, f, tip));
    check(
        frame === f && dist(drawn, expected) < 0.5,
        `${label}: frame ${f}: fingertip drawn at (${drawn.x.toFixed(2)}, ${
            drawn.y.toFixed(2)}) px, ` +
            `data says (${expected.x.toFixed(2)}, ${expected.y.toFixed(2)})`);
    shown.push({drawn, expected});
  }
  const moved = dist(shown[0].drawn, shown[1].drawn),
        want = dist(shown[0].expected, shown[1].expected);
  check(
      want > 5 && Math.abs(moved - want) < 0.5,
      `${label}: frames ${f1} -> ${f2}: the fingertip moved ${moved.toFixed(2)} px, the data says ${
          want.toFixed(2)} px`);
}


(async () => {
  fs.mkdirSync(work, {recursive: true});
  const browser = await lib.launchChromium(playwrightDir);
  try {
    const arcoPts = methodPoints('arco'), visionPts = methodPoints('vision');

    // 1. Served.
    const server = await startServer(result);
    // A second server on the same port: one error line, exit 1 (no shared port).
    const port = server.url.match(/:(\d+)\//)[1];
    let busy = {status: 0, stderr: ''};
    try {
      execFileSync(arco, ['view', result, '--port', port, '--exit-after-s', '5'], {stdio: 'pipe'});
    } catch (e) {
      busy = {status: e.status, stderr: String(e.stderr), stdout: String(e.stdout)};
    }
    check(
        busy.status === 1 && busy.stdout === '' &&
            /^arco: error: 127\.0\.0\.1:\d+: cannot listen \(port in use\? --port 0 picks a free one\)\n$/
                .test(busy.stderr),
        'a busy port: ' + JSON.stringify(busy));
    const {page, errors, loadS} = await openPage(browser, server.url);
    console.log(`info    served page ready in ${loadS.toFixed(2)} s`);
    const methods = await page.evaluate(() => window.arcoView.methods());
    check(
        JSON.stringify(methods) === JSON.stringify(['arco', 'paper', 'vision']),
        'methods shown: ' + methods.join(', '));
    const variance = await canvasVariance(page, path.join(work, 'served_canvas.png'));
    check(variance > 20, `canvas not blank: luma variance ${variance.toFixed(1)}`);
    await checkSeek(page, 'served, arco', arcoPts);

    const capture = path.resolve(result, resultJson.capture);
    const captureJson = JSON.parse(fs.readFileSync(path.join(capture, 'capture.json'), 'utf8'));
    const wantS = wavDurationS(path.resolve(capture, captureJson.audio.file));
    await page.waitForFunction(
        () => Number.isFinite(window.arcoView.audioDuration()), null, {timeout: 30000});
    const gotS = await page.evaluate(() => window.arcoView.audioDuration());
    check(
        Math.abs(gotS - wantS) < 1e-3,
        `audio duration ${gotS.toFixed(4)} s, the take's ${wantS.toFixed(4)} s`);

    // Errors against the synthetic truth, as the quality panel prints them.
    const truthJson =
        JSON.parse(fs.readFileSync(path.join(capture, 'truth', 'truth.json'), 'utf8'));
    check(
        truthJson.truth_layout === resultJson.stages.arco.layout,
        'truth and arco share the layout ' + truthJson.truth_layout);
    const truth = {
      names: arcoPts.names,
      points: readNpy(path.join(capture, 'truth', 'points3d.npy'))
    };
    const errFrame = Math.floor(arcoPts.points.shape[0] / 2);
    let sum = 0, n = 0;
    for (const name of arcoPts.names.filter((k) => k.startsWith('left_hand_'))) {
      const a = pointAt(arcoPts, errFrame, name), t = pointAt(truth, errFrame, name);
      const d = Math.hypot(a[0] - t[0], a[1] - t[1], a[2] - t[2]);
      if (Number.isFinite(d)) {
        sum += d;
        ++n;
      }
    }
    await page.evaluate((f) => window.arcoView.seek(f), errFrame);
    const quality = await page.locator('#quality').innerText();
    const shownErr = Number((quality.match(/left hand ([0-9.]+) mm/) || [])[1]);
    check(
        n === 21 && Math.abs(shownErr - sum / n) <= 0.05 + 1e-9,
        `frame ${errFrame}: left hand error shown ${shownErr} mm, truth says ${
            (sum / n).toFixed(3)} mm`);

    // The note of notes.csv at the middle of one of its notes, named as notes.csv names it.
    const noteRows = fs.readFileSync(path.join(result, 'notes.csv'), 'utf8').trim().split('\n');
    const ncol = Object.fromEntries(noteRows[0].split(',').map((n, i) => [n, i]));
    const notes = noteRows.slice(1).map((r) => r.split(',')).filter((r) => r[ncol.kind] === 'note');
    const mid = notes[Math.floor(notes.length / 2)];
    const noteFrame =
        Math.floor(0.5 * (Number(mid[ncol.onset_s]) + Number(mid[ncol.offset_s])) * resultJson.fps);
    await page.evaluate((f) => window.arcoView.seek(f), noteFrame);
    const noteText = await page.locator('#note').innerText();
    const shownCents = Number((noteText.match(/note \S+ \(([+-]?\d+) cents median/) || [])[1]);
    check(
        notes.length > 2 && noteText.includes('note ' + mid[ncol.note_name] + ' (') &&
            Math.abs(shownCents - Number(mid[ncol.cents_from_et])) <= 0.55,
        `frame ${noteFrame}: notes.csv says ${mid[ncol.note_name]} ${
            mid[ncol.cents_from_et]} cents, the page: ${JSON.stringify(noteText)}`);

    // The contact marker where arco/contacts.csv puts the pressed contact, hidden at rest.
    const rows =
        fs.readFileSync(path.join(result, 'arco', 'contacts.csv'), 'utf8').trim().split('\n');
    const col = Object.fromEntries(rows[0].split(',').map((n, i) => [n, i]));
    const cells = rows.slice(1).map((r) => r.split(','));
    const pressedRow = cells[cells.map((c) => c[col.state]).lastIndexOf('pressed')];
    const restRow = cells.find((c) => c[col.state] === 'rest');
    const pf = Number(pressedRow[col.frame]);
    await page.evaluate((f) => window.arcoView.seek(f), pf);
    const marker = await page.evaluate(() => window.arcoView.projectContact());
    const markerWant = project(
        await page.evaluate(() => window.arcoView.dataToClip()),
        ['contact_x_mm', 'contact_y_mm', 'contact_z_mm'].map((k) => Number(pressedRow[col[k]])));
    check(
        marker !== null && dist(marker, markerWant) < 0.5,
        `frame ${pf}: contact marker at ${
            marker && dist(marker, markerWant).toFixed(3)} px of contacts.csv's point`);
    await page.evaluate((f) => window.arcoView.seek(f), Number(restRow[col.frame]));
    check(
        await page.evaluate(() => window.arcoView.projectContact()) === null,
        `frame ${restRow[col.frame]} (rest): no contact marker`);

    // Method switch: a frame where arco's and vision's fingertips differ most.
    let frame = 0, gap = -1;
    for (let f = 0; f < arcoPts.points.shape[0]; ++f) {
      const a = pointAt(arcoPts, f, tip), v = pointAt(visionPts, f, tip);
      const d = Math.hypot(a[0] - v[0], a[1] - v[1], a[2] - v[2]);
      if (d > gap) {
        gap = d;
        frame = f;
      }
    }
    await page.evaluate((f) => window.arcoView.seek(f), frame);
    const onArco = await page.evaluate((n) => window.arcoView.projectKeypoint(n), tip);
    await page.selectOption('#method', {label: 'vision'});
    const onVision = await page.evaluate((n) => window.arcoView.projectKeypoint(n), tip);
    const clip = await page.evaluate(() => window.arcoView.dataToClip());
    const wantVision = project(clip, pointAt(visionPts, frame, tip));
    check(
        dist(onArco, onVision) > 1 && dist(onVision, wantVision) < 0.5,
        `method arco -> vision at frame ${frame} (${gap.toFixed(1)} mm apart): the hand moved ` +
            `${dist(onArco, onVision).toFixed(2)} px, to ${
                dist(onVision, wantVision).toFixed(3)} px of vision's point`);
    // Playing: the frame follows the audio clock.
    await page.evaluate(() => window.arcoView.seek(0));
    await page.click('#play');
    // Wait on the audio clock itself (a loaded machine may start the sound late), then
    // read the frame right after the page's next animation frame, in the same task as
    // the clock: the frame drawn must be the clock's.
    await page.waitForFunction(
        () => document.getElementById('audio').currentTime > 0.4, null, {timeout: 30000});
    const played = await page.evaluate(
        () => new Promise((resolve) => requestAnimationFrame(() => {
                            const a = document.getElementById('audio');
                            resolve(
                                {frame: window.arcoView.frame, t: a.currentTime, paused: a.paused});
                          })));
    const frameOf = (t) => Math.floor((t - (captureJson.audio.offset_s || 0)) * resultJson.fps);
    check(
        !played.paused && played.frame >= 10 && Math.abs(played.frame - frameOf(played.t)) <= 1,
        `playing: frame ${played.frame}, audio clock ${played.t.toFixed(3)} s (frame ${
            frameOf(played.t)})`);
    await page.click('#play');
    const paused = await page.evaluate(() => {
      const a = document.getElementById('audio');
      return {frame: window.arcoView.frame, t: a.currentTime, paused: a.paused};
    });
    check(
        paused.paused && paused.frame === frameOf(paused.t),
        `paused: frame ${paused.frame}, audio clock ${paused.t.toFixed(3)} s (frame ${
            frameOf(paused.t)})`);
    // Side by side: the shown method (arco) in the left half, the ghost (vision) in the
    // right half, through one camera: each fingertip where its own data projects.
    await page.selectOption('#method', {label: 'arco'});
    await page.selectOption('#ghost', {label: 'vision'});
    await page.selectOption('#layout', 'side');
    await page.evaluate((f) => window.arcoView.seek(f), frame);
    const half = await page.evaluate(() => window.arcoView.dataToClip());
    const sideArco = await page.evaluate((n) => window.arcoView.projectKeypoint(n), tip);
    const sideVision = await page.evaluate((n) => window.arcoView.projectKeypoint(n, true), tip);
    const wantArco = project(half, pointAt(arcoPts, frame, tip));
    const wantSide = project(half, pointAt(visionPts, frame, tip));
    wantSide.x += half.width;
    check(
        half.width < 0.51 * clip.width && dist(sideArco, wantArco) < 0.5 &&
            dist(sideVision, wantSide) < 0.5 && sideArco.x < half.width &&
            sideVision.x >= half.width &&
            dist(sideArco, {x: sideVision.x - half.width, y: sideVision.y}) > 1,
        `side by side at frame ${frame}: arco's fingertip ${
            dist(sideArco, wantArco).toFixed(3)} px from its point in the ` +
            `left half (${half.width} px), vision's ${
                dist(sideVision, wantSide).toFixed(3)} px from its point in the right half, ` +
            `${dist(sideArco, {
                 x: sideVision.x - half.width,
                 y: sideVision.y
               }).toFixed(2)} px apart`);
    const sidePng = decodePng(
        await page.locator('#canvas3d').screenshot({path: path.join(work, 'side_by_side.png')}));
    const vl = lumaVariance(sidePng, 0, half.width),
          vr = lumaVariance(sidePng, half.width, sidePng.width);
    check(
        vl > 20 && vr > 20,
        `side by side: both halves drawn (luma variance ${vl.toFixed(1)}, ${vr.toFixed(1)})`);
    await page.screenshot({path: path.join(work, 'side_by_side_page.png')});
    await page.selectOption('#layout', 'ghost');
    // Without camera videos in the capture, no video panel.
    check(
        await page.evaluate(
            () => window.arcoView.video() === null && document.getElementById('videopanel').hidden),
        'a capture without videos: no video panel');
    await page.selectOption('#ghost', {label: 'arco'});
    await page.selectOption('#speed', '0.25');
    const rate = await page.evaluate(() => {
      const a = document.getElementById('audio');
      return [a.playbackRate, a.preservesPitch];
    });
    check(
        rate[0] === 0.25 && rate[1] === true,
        `speed 0.25x: playbackRate ${rate[0]}, preservesPitch ${rate[1]}`);
    await page.evaluate(() => window.arcoView.seek(Math.floor(window.arcoView.frame + 0)));
    await page.screenshot({path: path.join(work, 'served_page.png')});
    check(
        errors.length === 0,
        'served: no console errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
    const servedFiles = fs.readdirSync(server.tmpdir);
    const stopped = await stopServer(server);
    check(
        stopped.code === 0,
        `arco view stops on SIGINT with exit 0 (got ${stopped.code}, ${stopped.signal})`);
    check(
        servedFiles.length === 1 && fs.readdirSync(server.tmpdir).length === 0,
        `the served folder (${servedFiles.join(', ')}) is removed when the server stops`);

    // 2. --no-serve, from disk, with no server running.
    const folder = path.join(work, 'page');
    fs.rmSync(folder, {recursive: true, force: true});
    execFileSync(arco, ['view', result, '--no-serve', '-o', folder], {stdio: 'pipe'});
    // The folder's arrays: points_arco.bin is arco/points3d.npy in float32, and data.js
    // embeds the same bytes.
    const bin = fs.readFileSync(path.join(folder, 'points_arco.bin'));
    const f32 = new Float32Array(bin.buffer.slice(bin.byteOffset, bin.byteOffset + bin.length));
    let same = f32.length === arcoPts.points.data.length;
    for (let i = 0; same && i < f32.length; ++i) {
      const want = Math.fround(arcoPts.points.data[i]);
      same = Number.isNaN(want) ? Number.isNaN(f32[i]) : f32[i] === want;
    }
    check(same, `points_arco.bin is arco/points3d.npy in float32 (${f32.length} values)`);
    const dataJs = fs.readFileSync(path.join(folder, 'data.js'), 'utf8');
    const embedded = JSON.parse(dataJs.slice(dataJs.indexOf('{'), dataJs.lastIndexOf('}') + 1));
    check(
        Buffer.from(embedded.arrays['points_arco.bin'], 'base64').equals(bin) &&
            Object.keys(embedded.arrays).length ===
                fs.readdirSync(folder).filter((n) => n.endsWith('.bin')).length,
        'data.js embeds every .bin, byte for byte');
    const disk = await openPage(browser, 'file://' + path.join(folder, 'index.html'));
    const diskVariance = await canvasVariance(disk.page, path.join(work, 'file_canvas.png'));
    check(diskVariance > 20, `file://: canvas not blank: luma variance ${diskVariance.toFixed(1)}`);
    await checkSeek(disk.page, 'file://, arco', arcoPts);
    await disk.page.waitForFunction(
        () => Number.isFinite(window.arcoView.audioDuration()), null, {timeout: 30000});
    const diskS = await disk.page.evaluate(() => window.arcoView.audioDuration());
    check(Math.abs(diskS - wantS) < 1e-3, `file://: audio duration ${diskS.toFixed(4)} s`);
    // The documentation's picture: a frame with a pressed contact, vision ghosted.
    const pressed = JSON.parse(fs.readFileSync(path.join(folder, 'manifest.json'), 'utf8'));
    await disk.page.evaluate(() => window.arcoView.setGhost('vision'));
    await disk.page.evaluate((f) => window.arcoView.seek(f), Math.round(pressed.frames * 0.6));
    await disk.page.screenshot({path: path.join(work, 'view.png')});
    check(
        disk.errors.length === 0,
        'file://: no console errors' + (disk.errors.length ? ': ' + disk.errors.join(' | ') : ''));

    // 3. A result missing a stage: the terminal and the page say which.
    const bad = await startServer(badResult);
    const shown = await openPage(browser, bad.url);
    const text = await shown.page.locator('#missing').innerText();
    const visible = await shown.page.locator('#missing').isVisible();
    check(
        visible && /arco is missing: arco refine writes it/.test(text),
        'missing stage in the page: ' + JSON.stringify(text));
    check(
        /arco view: arco is missing: arco refine writes it/.test(bad.stderr()),
        'missing stage in the terminal: ' + JSON.stringify(bad.stderr()));
    const badVariance = await canvasVariance(shown.page, path.join(work, 'missing_canvas.png'));
    check(
        badVariance > 20,
        `missing stage: the page still draws (luma variance ${badVariance.toFixed(1)})`);
    await shown.page.screenshot({path: path.join(work, 'missing_page.png')});
    check(
        shown.errors.length === 0,
        'missing stage: no console errors' +
            (shown.errors.length ? ': ' + shown.errors.join(' | ') : ''));
    await stopServer(bad);
  } catch (err) {
    check(false, 'unexpected: ' + (err.stack || err));
  } finally {
    await browser.close();
  }
  console.log(
      failures() ? `${failures()} check(s) FAILED; screenshots in ${work}` :
                   `all checks passed; screenshots in ${work}`);
  process.exit(failures() ? 1 : 0);
})();
