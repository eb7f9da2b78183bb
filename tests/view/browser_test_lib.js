// What the browser tests of `arco view` share (view_browser_test.js,
// view_video_browser_test.js): the check tally, an independent .npy reader, Debian's
// chromium launched headless through playwright-core, a page opened until the viewer is
// ready (collecting its errors), and `arco view` started and stopped as a server.
'use strict';
const fs = require('fs');
const path = require('path');
const {spawn} = require('child_process');
const zlib = require('zlib');

// check(ok, what) prints one line per check; failures() counts the failed ones.
function makeChecker() {
  let failed = 0;
  return {
    check(ok, what) {
      console.log((ok ? 'ok      ' : 'FAILED  ') + what);
      if (!ok) failed += 1;
    },
    failures: () => failed,
  };
}

// A little-endian float64 C-order .npy file -> { shape, data: Float64Array }.
function readNpy(file) {
  const buf = fs.readFileSync(file);
  if (buf.toString('latin1', 1, 6) !== 'NUMPY') throw new Error(file + ': not .npy');
  const major = buf[6];
  const headerLen = major === 1 ? buf.readUInt16LE(8) : buf.readUInt32LE(8);
  const start = (major === 1 ? 10 : 12);
  const header = buf.toString('latin1', start, start + headerLen);
  if (!/'descr': '<f8'/.test(header) || /'fortran_order': True/.test(header)) {
    throw new Error(file + ': expected little-endian float64, C order: ' + header);
  }
  const shape =
      header.match(/'shape': \(([^)]*)\)/)[1].split(',').filter((s) => s.trim()).map(Number);
  const data = new Float64Array(
      buf.buffer.slice(buf.byteOffset + start + headerLen, buf.byteOffset + buf.length));
  return {shape, data};
}

// Debian's chromium (never a downloaded browser), software GL, audio allowed to play.
function launchChromium(playwrightDir) {
  const {chromium} = require(path.resolve(playwrightDir));
  return chromium.launch({
    executablePath: '/usr/bin/chromium',
    args: [
      '--no-sandbox',
      '--use-angle=swiftshader',
      '--enable-unsafe-swiftshader',
      '--autoplay-policy=no-user-gesture-required'
    ],
  });
}

// Opens `url` and waits until the viewer says it is ready; errors collects console
// errors, page errors and failed requests from the start.
async function openPage(browser, url) {
  const page = await browser.newPage({viewport: {width: 1280, height: 720}});
  const errors = [];
  page.on('console', (m) => {
    if (m.type() === 'error') errors.push('console: ' + m.text());
  });
  page.on('pageerror', (e) => errors.push('page error: ' + e.message));
  page.on('requestfailed', (r) => errors.push('request failed: ' + r.url()));
  const start = Date.now();
  await page.goto(url);
  await page.waitForFunction(
      () => window.arcoView && window.arcoView.ready, null, {timeout: 60000});
  return {page, errors, loadS: (Date.now() - start) / 1000};
}

// `arco view RESULT --port 0 ARGS...` (with `env` added to the environment), resolved
// once it prints its URL: { child, url, out(), stderr(), seconds }.
function startServer(arco, result, args = [], env = {}) {
  return new Promise((resolve, reject) => {
    const child = spawn(arco, ['view', result, '--port', '0', '--exit-after-s', '300', ...args], {
      env: {...process.env, ...env}
    });
    let out = '', err = '';
    const start = Date.now();
    child.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (m)
        resolve({
          child,
          url: m[0],
          out: () => out,
          stderr: () => err,
          seconds: (Date.now() - start) / 1000
        });
    });
    child.stderr.on('data', (d) => {
      err += d;
    });
    child.on('exit', (code) => reject(new Error('arco view exited ' + code + ': ' + err)));
  });
}

// Ctrl-C to the server: resolves { code, signal } when it has exited.
function stopServer(server) {
  return new Promise((resolve) => {
    server.child.removeAllListeners('exit');
    server.child.on('exit', (code, signal) => resolve({code, signal}));
    server.child.kill('SIGINT');
  });
}

// 8-bit RGB/RGBA, non-interlaced PNG (what Chromium's screenshots are) -> RGBA-less pixels.
function decodePng(buf) {
  let o = 8, width = 0, height = 0, type = 0;
  const idat = [];
  while (o < buf.length) {
    const len = buf.readUInt32BE(o), id = buf.toString('latin1', o + 4, o + 8);
    const body = buf.subarray(o + 8, o + 8 + len);
    if (id === 'IHDR') {
      width = body.readUInt32BE(0);
      height = body.readUInt32BE(4);
      type = body[9];
      if (body[8] !== 8 || body[12] !== 0 || (type !== 2 && type !== 6))
        throw new Error('unsupported PNG');
    }
    if (id === 'IDAT') idat.push(body);
    o += 12 + len;
  }
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const bpp = type === 6 ? 4 : 3, stride = width * bpp;
  const out = new Uint8Array(height * stride);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    for (let x = 0; x < stride; ++x) {
      const v = raw[y * (stride + 1) + 1 + x];
      const a = x >= bpp ? out[y * stride + x - bpp] : 0;
      const b = y > 0 ? out[(y - 1) * stride + x] : 0;
      const c = x >= bpp && y > 0 ? out[(y - 1) * stride + x - bpp] : 0;
      let p = 0;
      if (filter === 1)
        p = a;
      else if (filter === 2)
        p = b;
      else if (filter === 3)
        p = (a + b) >> 1;
      else if (filter === 4) {
        const pa = Math.abs(b - c), pb = Math.abs(a - c), pc = Math.abs(a + b - 2 * c);
        p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      out[y * stride + x] = (v + p) & 255;
    }
  }
  return {width, height, bpp, pixels: out};
}
// Over the columns [x0, x1) (default: all).
function lumaVariance(png, x0 = 0, x1 = png.width) {
  let s = 0, s2 = 0, n = 0;
  for (let y = 0; y < png.height; ++y) {
    for (let x = x0; x < x1; ++x, ++n) {
      const k = (y * png.width + x) * png.bpp;
      const l = 0.299 * png.pixels[k] + 0.587 * png.pixels[k + 1] + 0.114 * png.pixels[k + 2];
      s += l;
      s2 += l * l;
    }
  }
  return s2 / n - (s / n) * (s / n);
}

module.exports = {
  makeChecker,
  readNpy,
  decodePng,
  lumaVariance,
  launchChromium,
  openPage,
  startServer,
  stopServer
};
