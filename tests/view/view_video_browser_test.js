// `arco view` with camera videos (docs/view.md, "Camera videos") in Debian's /usr/bin/chromium
// driven by playwright-core. The expected pixels come from the result and the calibration
// read here (arco/points3d.npy, calibration.json: pinhole + Brown-Conrady distortion,
// OpenCV's formulas written out), not from arco's overlay code. Checks:
//  - served with two --video-camera: the video panel, its camera selector, no console error;
//  - the video plays in chromium (readyState >= 2, no error), at the overlay's size, and its
//    duration is the capture's frames / fps within a frame;
//  - seeking the page to two frames puts video.currentTime inside each frame's interval
//    [k / fps, (k + 1) / fps), and the picture drawn to a canvas there is the overlay's
//    fingertip magenta at the projected left fingertips, and not at the other frame's tip
//    (the first camera, where the tips of the two frames are 15 px apart);
//  - playing, the video plays along the audio clock (within 3 frames);
//  - the selector switches to the second camera, whose fingertips are on their marks too;
//  - the --no-serve folder's video plays from file://.
// usage: node view_video_browser_test.js ARCO RESULT PAGE_DIR CAMERA WORK_DIR PLAYWRIGHT_CORE_DIR
'use strict';
const fs = require('fs');
const path = require('path');
const lib = require('./browser_test_lib.js');

const [arco, result, pageDir, camera, work, playwrightDir] = process.argv.slice(2);
const secondCamera = 'camera_21334209_1';  // no video: the overlay on black
const scale = 0.25;
const tipNames = ['thumb', 'index', 'middle', 'ring', 'little'].map((f) => `left_hand_${f}_tip`);
const {check, failures} = lib.makeChecker();
const {readNpy, openPage, stopServer} = lib;

const resultJson = JSON.parse(fs.readFileSync(path.join(result, 'result.json'), 'utf8'));
const capture = path.resolve(result, resultJson.capture);
const captureJson = JSON.parse(fs.readFileSync(path.join(capture, 'capture.json'), 'utf8'));
const fps = Number(captureJson.fps.value || captureJson.fps);
const calibration =
    JSON.parse(fs.readFileSync(path.resolve(capture, captureJson.calibration), 'utf8'));
const unitsPerMm = resultJson.stages.instrument.world_units_per_mm;
const names = resultJson.stages.arco.keypoint_names;
const points = readNpy(path.join(result, 'arco', 'points3d.npy'));
const frames = points.shape[0];

// The overlay's output pixel of a point (mm) seen by `cam`: the calibration pixel (u, v)
// covers [(u - 0.5) s, (u + 0.5) s] of the output scaled by s.
function projector(cam) {
  const c = calibration.cameras.find((x) => x.name === cam);
  const K = c.K.flat(), R = c.R.flat(), t = c.t, d = c.distortion;
  return (x) => {
    const w = x.map((v) => v * unitsPerMm);
    const xc =
        [0, 1, 2].map((r) => R[3 * r] * w[0] + R[3 * r + 1] * w[1] + R[3 * r + 2] * w[2] + t[r]);
    const a = xc[0] / xc[2], b = xc[1] / xc[2], r2 = a * a + b * b;
    const radial = 1 + d.k1 * r2 + d.k2 * r2 * r2 + d.k3 * r2 * r2 * r2;
    const xd = a * radial + 2 * d.p1 * a * b + d.p2 * (r2 + 2 * a * a);
    const yd = b * radial + d.p1 * (r2 + 2 * b * b) + 2 * d.p2 * a * b;
    const u = K[0] * xd + K[1] * yd + K[2], v = K[4] * yd + K[5];
    return {x: (u + 0.5) * scale - 0.5, y: (v + 0.5) * scale - 0.5};
  };
}
function tipsAt(project, f) {
  return tipNames.map((n) => {
    const p = names.indexOf(n), o = (f * points.shape[1] + p) * 3;
    return project([points.data[o], points.data[o + 1], points.data[o + 2]]);
  });
}
const magenta = (rgb) => rgb[0] > 190 && rgb[1] < 90 && rgb[2] > 190;
const dist = (a, b) => Math.hypot(a.x - b.x, a.y - b.y);

async function videoReady(page) {
  await page.waitForFunction(() => {
    const v = window.arcoView.video();
    return v && (v.error !== null || (v.readyState >= 2 && !v.seeking));
  }, null, {timeout: 30000});
  return page.evaluate(() => window.arcoView.video());
}
// Two frames whose index fingertips are each farthest from every fingertip of the other
// (sampled), so that a video one frame off the page would show no mark there.
function framePair(project) {
  let best = [0, frames - 1], bestD = -1;
  const apart = (a, b) =>
      Math.min(...tipsAt(project, a).map((p) => dist(p, tipsAt(project, b)[1])));
  for (let a = 0; a < frames; a += 3) {
    for (let b = a + 3; b < frames; b += 3) {
      const d = Math.min(apart(a, b), apart(b, a));
      if (d > bestD) {
        bestD = d;
        best = [a, b];
      }
    }
  }
  console.log(
      `info    ${bestD.toFixed(1)} px between frame ${best[0]}'s and ${best[1]}'s fingertips`);
  return best;
}
// With `apart`: also that the other frame's index fingertip, away from this frame's tips, is
// not a mark (the video shows this frame, not a neighbour).
async function checkFrames(page, label, cam, apart) {
  const project = projector(cam);
  const [f1, f2] = framePair(project);
  for (const [f, other] of [[f1, f2], [f2, f1]]) {
    await page.evaluate((k) => window.arcoView.seek(k), f);
    const v = await videoReady(page);
    check(
        v.error === null && v.currentTime >= f / fps && v.currentTime < (f + 1) / fps,
        `${label}: page frame ${f}: video.currentTime ${v.currentTime.toFixed(4)} s in [${
            (f / fps).toFixed(4)}, ${((f + 1) / fps).toFixed(4)})`);
    const tips = tipsAt(project, f);
    let on = 0, inside = 0;
    for (const p of tips) {
      const x = Math.round(p.x), y = Math.round(p.y);
      if (x < 0 || y < 0 || x >= v.width || y >= v.height) continue;
      ++inside;
      const rgb = await page.evaluate(([a, b]) => window.arcoView.videoPixel(a, b), [x, y]);
      if (magenta(rgb))
        ++on;
      else
        console.log(`info    ${label}: frame ${f}: tip at (${p.x.toFixed(1)}, ${
            p.y.toFixed(1)}) is ${rgb}`);
    }
    check(
        inside >= 3 && on === inside,
        `${label}: frame ${f}: ${on} of ${inside} projected fingertips on the magenta marks`);
    if (!apart) continue;
    const away = tipsAt(project, other)[1];
    // The mark's radius is 7 px.
    if (tips.every((p) => dist(p, away) > 10)) {
      const rgb = await page.evaluate(
          ([a, b]) => window.arcoView.videoPixel(a, b), [Math.round(away.x), Math.round(away.y)]);
      check(
          !magenta(rgb),
          `${label}: frame ${f}: frame ${other}'s fingertip position is not a mark (${rgb})`);
    } else {
      check(
          false,
          `${label}: frames ${f1} and ${
              f2}: the fingertips do not move apart (the check cannot tell the frames)`);
    }
  }
}

const startServer = (args) => lib.startServer(arco, result, args);

(async () => {
  fs.mkdirSync(work, {recursive: true});
  const browser = await lib.launchChromium(playwrightDir);
  try {
    const server = await startServer(
        ['--video-camera', camera, '--video-camera', secondCamera, '--video-scale', String(scale)]);
    console.log(
        `info    arco view wrote the page and two videos in ${server.seconds.toFixed(1)} s`);
    const {page, errors} = await openPage(browser, server.url);
    check(await page.locator('#videopanel').isVisible(), 'the video panel is shown');
    const options = await page.locator('#videocam option').allTextContents();
    check(
        JSON.stringify(options) === JSON.stringify([camera, secondCamera]) &&
            await page.locator('#videocam').isVisible(),
        'camera selector: ' + options.join(', '));
    let v = await videoReady(page);
    check(
        v.error === null && v.readyState >= 2 && v.camera === camera && v.width === 576 &&
            v.height === 664,
        `the video plays in chromium: ${JSON.stringify(v)}`);
    check(
        Math.abs(v.duration - frames / fps) <= 1 / fps,
        `video duration ${v.duration.toFixed(4)} s, the capture's ${frames} frames / ${fps} fps = ${
            (frames / fps).toFixed(4)} s`);
    await checkFrames(page, camera, camera, true);
    await page.screenshot({path: path.join(work, 'video_page.png')});

    // Playing: the video plays along the audio clock.
    await page.evaluate(() => window.arcoView.seek(0));
    await page.click('#play');
    await page.waitForTimeout(1000);
    const played = await page.evaluate(() => {
      const a = document.getElementById('audio'), w = document.getElementById('video');
      return {audio: a.currentTime, video: w.currentTime, paused: w.paused};
    });
    await page.click('#play');
    const clock = played.audio - (captureJson.audio.offset_s || 0);
    check(
        !played.paused && played.video > 0.3 && Math.abs(played.video - clock) < 3 / fps,
        `playing 1 s: video at ${played.video.toFixed(3)} s, audio clock ${clock.toFixed(3)} s`);
    const paused = await page.evaluate(() => document.getElementById('video').paused);
    check(paused, 'pause pauses the video');

    // The second camera, through the selector.
    await page.selectOption('#videocam', {label: secondCamera});
    await page.waitForFunction((c) => window.arcoView.video().camera === c, secondCamera);
    v = await videoReady(page);
    check(
        v.error === null && v.readyState >= 2 && /video_\d+\.webm$/.test(v.src),
        `second camera: ${JSON.stringify(v)}`);
    await checkFrames(page, secondCamera, secondCamera, false);
    check(
        errors.length === 0,
        'served: no console errors' + (errors.length ? ': ' + errors.join(' | ') : ''));
    await stopServer(server);

    // From disk, the --no-serve folder: the video plays with no server.
    const disk = await openPage(browser, 'file://' + path.join(pageDir, 'index.html'));
    v = await videoReady(disk.page);
    check(
        v.error === null && v.readyState >= 2 && Math.abs(v.duration - frames / fps) <= 1 / fps,
        `file://: the video plays: ${JSON.stringify(v)}`);
    check(!(await disk.page.locator('#videocam').isVisible()), 'file://: one camera, no selector');
    await disk.page.evaluate((k) => window.arcoView.seek(k), Math.round(frames * 0.6));
    await videoReady(disk.page);
    await disk.page.screenshot({path: path.join(work, 'view_video.png')});
    check(
        disk.errors.length === 0,
        'file://: no console errors' + (disk.errors.length ? ': ' + disk.errors.join(' | ') : ''));
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
