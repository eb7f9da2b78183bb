// arco view: the page of a result folder (docs/view.md). Reads manifest.json and its
// float32 arrays (fetched, or embedded in data.js for pages opened from disk), draws every
// method's points with three.js, and keeps the 3D, the panels and the audio on one frame.
// Time: frame k (from 0) is shown at k / fps; its audio time is audio.offset_s + k / fps,
// and its camera videos' time k / fps (one video frame per result frame).
// World: the arrays are mm in arco's world axes; the scene root scales them to metres and
// turns the body's up direction (ankles -> shoulders) to three.js's +Y.
(function () {
  'use strict';

  const $ = (id) => document.getElementById(id);
  const kColors = { arco: 0xe8743b, paper: 0x3b8be8, vision: 0x59b36b, triangulation: 0xaaaaaa };
  const kNoteNames = ['C', 'C#', 'D', 'D#', 'E', 'F', 'F#', 'G', 'G#', 'A', 'A#', 'B'];
  const kFingers = ['open', 'index', 'middle', 'ring', 'little'];
  const kStates = ['rest', 'open string', 'pressed', 'uncertain'];

  const view = { ready: false, frame: 0, method: 0, ghost: -1, side: false, playing: false };
  window.arcoView = view;  // the test hooks (see the end of this file)

  // ---- data ----------------------------------------------------------------------------
  function arrayEntries(node, out) {
    if (Array.isArray(node)) node.forEach((n) => arrayEntries(n, out));
    else if (node && typeof node === 'object') {
      if (typeof node.file === 'string' && node.file.endsWith('.bin') && node.shape) out.push(node);
      else Object.values(node).forEach((n) => arrayEntries(n, out));
    }
    return out;
  }
  function decodeBase64(text) {
    const bin = atob(text);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
    return bytes.buffer;
  }
  async function loadData() {
    const embedded = window.ARCO_VIEW_DATA;
    const manifest = embedded ? embedded.manifest : await (await fetch('manifest.json')).json();
    const entries = arrayEntries(manifest, []);
    await Promise.all(entries.map(async (e) => {
      const buffer = embedded ? decodeBase64(embedded.arrays[e.file])
                              : await (await fetch(e.file)).arrayBuffer();
      e.data = new Float32Array(buffer);
      const want = e.shape.reduce((a, b) => a * b, 1);
      if (e.data.length !== want) throw new Error(e.file + ': ' + e.data.length + ' values, shape says ' + want);
    }));
    window.ARCO_VIEW_DATA = null;  // the base64 text is decoded: let it go
    return manifest;
  }

  // ---- geometry helpers ------------------------------------------------------------------
  function point(arr, frame, index) {
    const p = arr.shape[1];
    const o = (frame * p + index) * 3;
    return [arr.data[o], arr.data[o + 1], arr.data[o + 2]];
  }
  const finite3 = (v) => Number.isFinite(v[0]) && Number.isFinite(v[1]) && Number.isFinite(v[2]);

  // Bones by name: body, both hands (every finger joint), instrument outline, bow.
  function boneNames() {
    const bones = [['left_shoulder', 'right_shoulder'], ['left_hip', 'right_hip'],
      ['left_shoulder', 'left_hip'], ['right_shoulder', 'right_hip'],
      ['left_shoulder', 'left_elbow'], ['left_elbow', 'left_wrist'],
      ['right_shoulder', 'right_elbow'], ['right_elbow', 'right_wrist'],
      ['left_hip', 'left_knee'], ['left_knee', 'left_ankle'],
      ['right_hip', 'right_knee'], ['right_knee', 'right_ankle'],
      ['nose', 'left_eye'], ['nose', 'right_eye'], ['left_eye', 'left_ear'], ['right_eye', 'right_ear'],
      ['scroll_top', 'nut_l'], ['scroll_top', 'nut_r'], ['nut_l', 'bridge_l'], ['nut_r', 'bridge_r'],
      ['bridge_l', 'tail_gut'], ['bridge_r', 'tail_gut'], ['tail_gut', 'end_pin'], ['frog', 'tip'],
      ['finger_mcp', 'finger_pip'], ['finger_pip', 'finger_dip'], ['finger_dip', 'finger_tip']];
    for (const side of ['left', 'right']) {
      const h = side + '_hand_';
      bones.push([side + '_wrist', h + 'wrist']);
      const chains = { thumb: ['cmc', 'mcp', 'ip', 'tip'], index: ['mcp', 'pip', 'dip', 'tip'],
        middle: ['mcp', 'pip', 'dip', 'tip'], ring: ['mcp', 'pip', 'dip', 'tip'], little: ['mcp', 'pip', 'dip', 'tip'] };
      for (const [finger, joints] of Object.entries(chains)) {
        let prev = h + 'wrist';
        for (const j of joints) { bones.push([prev, h + finger + '_' + j]); prev = h + finger + '_' + j; }
      }
    }
    return bones;
  }
  function jointRadiusMm(name) {
    if (name.startsWith('face_')) return 2.5;
    if (name.includes('_hand_') || name.startsWith('finger_')) return 5;
    if (name === 'contact') return 0;  // drawn by the contact marker
    return 12;
  }

  // One method's drawing: joints (instanced spheres, scale 0 where missing) and bones.
  function makeFigure(method, opacity) {
    const names = method.keypoint_names;
    const color = kColors[method.name] || 0xcccccc;
    const material = new THREE.MeshLambertMaterial({ color, transparent: opacity < 1, opacity });
    const joints = new THREE.InstancedMesh(new THREE.SphereGeometry(1, 12, 8), material, names.length);
    joints.frustumCulled = false;  // no bounding sphere of moving instances
    const index = new Map(names.map((n, i) => [n, i]));
    const pairs = boneNames().filter(([a, b]) => index.has(a) && index.has(b))
      .map(([a, b]) => [index.get(a), index.get(b)]);
    const lineGeometry = new THREE.BufferGeometry();
    lineGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pairs.length * 6), 3));
    const bones = new THREE.LineSegments(lineGeometry,
      new THREE.LineBasicMaterial({ color, transparent: opacity < 1, opacity }));
    bones.frustumCulled = false;
    const group = new THREE.Group();
    group.add(joints, bones);
    return { method, names, index, joints, bones, pairs, group, radii: names.map(jointRadiusMm) };
  }
  const tmpMatrix = new THREE.Matrix4();
  const tmpQuat = new THREE.Quaternion();
  function updateFigure(fig, frame) {
    const pts = fig.method.points;
    const frames = pts.shape[0];
    const f = Math.min(frame, frames - 1);
    for (let i = 0; i < fig.names.length; ++i) {
      const p = point(pts, f, i);
      const ok = finite3(p) && fig.radii[i] > 0;
      const r = ok ? fig.radii[i] : 0;
      tmpMatrix.compose(new THREE.Vector3(ok ? p[0] : 0, ok ? p[1] : 0, ok ? p[2] : 0), tmpQuat,
        new THREE.Vector3(r, r, r));
      fig.joints.setMatrixAt(i, tmpMatrix);
    }
    fig.joints.instanceMatrix.needsUpdate = true;
    const pos = fig.bones.geometry.attributes.position.array;
    fig.pairs.forEach(([a, b], k) => {
      const pa = point(pts, f, a), pb = point(pts, f, b);
      const ok = finite3(pa) && finite3(pb);
      for (let c = 0; c < 3; ++c) {  // a missing bone collapses to a point (draws nothing)
        pos[k * 6 + c] = ok ? pa[c] : 0;
        pos[k * 6 + 3 + c] = ok ? pb[c] : 0;
      }
    });
    fig.bones.geometry.attributes.position.needsUpdate = true;
  }

  // ---- scene -----------------------------------------------------------------------------
  let renderer, scene, camera, root, figures = [], ghostFigure = null, strings = null, contactMarker;
  const orbit = { target: new THREE.Vector3(), distance: 3, azimuth: 0.6, elevation: 0.25 };
  let homeOrbit = null;

  // The body's frame in the first frame where it is seen: up (hips -> shoulders), right
  // (left -> right shoulder) and forward = up x right (the way the player faces), as the
  // rotation that turns them to three.js's +Y, -X and +Z; and the box of that frame's
  // points in the turned axes (mm).
  function bodyFrame(method) {
    const idx = new Map(method.keypoint_names.map((n, i) => [n, i]));
    const get = (frame, name) => (idx.has(name) ? point(method.points, frame, idx.get(name)) : [NaN, NaN, NaN]);
    const vec = (p) => new THREE.Vector3(p[0], p[1], p[2]);
    const mean = (frame, names) => {
      const s = new THREE.Vector3(); let n = 0;
      for (const name of names) { const p = get(frame, name); if (finite3(p)) { s.add(vec(p)); ++n; } }
      return n ? s.divideScalar(n) : null;
    };
    const rotation = new THREE.Quaternion();
    let frame = 0;
    for (let f = 0; f < method.points.shape[0]; ++f) {
      const low = mean(f, ['left_hip', 'right_hip']), high = mean(f, ['left_shoulder', 'right_shoulder']);
      const l = get(f, 'left_shoulder'), r = get(f, 'right_shoulder');
      if (!low || !high || !finite3(l) || !finite3(r)) continue;
      const up = high.sub(low).normalize();
      const right = vec(r).sub(vec(l));
      right.addScaledVector(up, -right.dot(up)).normalize();
      const forward = new THREE.Vector3().crossVectors(up, right);
      const basis = new THREE.Matrix4().makeBasis(right.clone().negate(), up, forward).transpose();
      rotation.setFromRotationMatrix(basis);
      frame = f;
      break;
    }
    const box = new THREE.Box3();
    for (let f = frame; f < method.points.shape[0] && box.isEmpty(); ++f) {
      for (let i = 0; i < method.keypoint_names.length; ++i) {
        const p = point(method.points, f, i);
        if (finite3(p)) box.expandByPoint(vec(p).applyQuaternion(rotation));
      }
    }
    if (box.isEmpty()) box.set(new THREE.Vector3(-500, -500, -500), new THREE.Vector3(500, 500, 500));
    return { rotation, box };
  }

  function buildScene(manifest) {
    const canvas = $('canvas3d');
    renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(1);  // one CSS pixel = one canvas pixel: the test hooks' units
    scene = new THREE.Scene();
    scene.background = new THREE.Color(0x1d1f22);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 1.0));
    const sun = new THREE.DirectionalLight(0xffffff, 0.6);
    sun.position.set(1, 2, 1);
    scene.add(sun);
    camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
    root = new THREE.Group();  // data (mm, arco's axes) -> scene (m, +Y up, centred)
    scene.add(root);
    const { rotation, box } = bodyFrame(manifest.methods[0]);
    root.quaternion.copy(rotation);
    root.scale.setScalar(0.001);
    const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3());
    root.position.copy(centre).multiplyScalar(-0.001);  // the box's centre at the origin
    const grid = new THREE.GridHelper(4, 20, 0x444444, 0x333333);
    grid.position.y = -0.001 * size.y / 2;  // the floor under the lowest point
    scene.add(grid);
    const radius = 0.0005 * size.length();
    orbit.distance = 0.85 * radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2));

    figures = manifest.methods.map((m) => makeFigure(m, 1));
    figures.forEach((fig) => root.add(fig.group));
    if (manifest.strings) {
      const s = manifest.strings.shape[1];
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(s * 6), 3));
      strings = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0xf0e0a0 }));
      strings.frustumCulled = false;
      root.add(strings);
    }
    // The pressing finger's contact on the string, drawn over the hand that hides it.
    contactMarker = new THREE.Mesh(new THREE.SphereGeometry(10, 16, 12),
      new THREE.MeshBasicMaterial({ color: 0xff2040, depthTest: false, transparent: true, opacity: 0.9 }));
    contactMarker.renderOrder = 10;
    root.add(contactMarker);
    orbit.target.set(0, 0, 0);
    homeOrbit = { ...orbit, target: orbit.target.clone() };
    installOrbit(canvas);
    resize();
    window.addEventListener('resize', resize);
  }

  function placeCamera() {
    const ce = Math.cos(orbit.elevation);
    camera.position.set(orbit.target.x + orbit.distance * ce * Math.sin(orbit.azimuth),
      orbit.target.y + orbit.distance * Math.sin(orbit.elevation),
      orbit.target.z + orbit.distance * ce * Math.cos(orbit.azimuth));
    camera.lookAt(orbit.target);
    camera.updateMatrixWorld();
  }

  // Orbit (left drag), pan (right or shift drag), zoom (wheel).
  function installOrbit(canvas) {
    let drag = null;
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        const s = orbit.distance / canvas.clientHeight;
        const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
        const upv = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
        orbit.target.addScaledVector(right, -dx * s).addScaledVector(upv, dy * s);
      } else {
        orbit.azimuth -= dx * 0.008;
        orbit.elevation = Math.max(-1.5, Math.min(1.5, orbit.elevation + dy * 0.008));
      }
      render();
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      orbit.distance = Math.max(0.2, Math.min(30, orbit.distance * Math.exp(e.deltaY * 0.001)));
      render();
    }, { passive: false });
  }

  function resize() {
    const canvas = renderer.domElement;
    const w = canvas.parentElement.clientWidth, h = canvas.parentElement.clientHeight;
    renderer.setSize(w, h, false);
    render();
  }

  // Side by side: the shown method in the left half, the ghost method in the right half,
  // one camera for both (the same view of two methods).
  const sideBySide = () => view.side && ghostFigure !== null;
  // The viewport of the shown method (which 0) or of the side-by-side ghost (which 1), CSS px.
  function viewport(which) {
    const c = renderer.domElement, w = c.clientWidth, h = c.clientHeight;
    if (!sideBySide()) return { x: 0, y: 0, w, h };
    const half = Math.floor(w / 2);
    return { x: which === 0 ? 0 : half, y: 0, w: half, h };  // equal halves: one aspect
  }

  function render() {
    if (!renderer) return;
    const left = viewport(0);
    camera.aspect = left.w / Math.max(1, left.h);
    camera.updateProjectionMatrix();
    placeCamera();
    if (!sideBySide()) {
      renderer.setScissorTest(false);
      renderer.setViewport(0, 0, left.w, left.h);
      renderer.render(scene, camera);
      return;
    }
    const shown = figures[view.method].group;
    const right = viewport(1);
    renderer.setScissorTest(true);
    // WebGL viewports count from the bottom; both halves span the full height.
    ghostFigure.group.visible = false;
    renderer.setViewport(left.x, 0, left.w, left.h);
    renderer.setScissor(left.x, 0, left.w, left.h);
    renderer.render(scene, camera);
    ghostFigure.group.visible = true;
    shown.visible = false;
    const contact = contactMarker.visible;
    contactMarker.visible = false;  // the marker is the shown method's contact
    renderer.setViewport(right.x, 0, right.w, right.h);
    renderer.setScissor(right.x, 0, right.w, right.h);
    renderer.render(scene, camera);
    shown.visible = true;
    contactMarker.visible = contact;
    renderer.setScissorTest(false);
  }

  // ---- time ------------------------------------------------------------------------------
  let manifest = null, audio = null, video = null, frameCount = 0;
  const fps = () => manifest.fps;
  const audioOffset = () => (manifest.audio ? manifest.audio.offset_s : 0);
  const frameTime = (f) => f / fps();

  function showFrame(frame) {
    view.frame = Math.max(0, Math.min(frameCount - 1, frame));
    const f = view.frame;
    figures.forEach((fig, i) => {
      fig.group.visible = i === view.method;
      if (fig.group.visible) updateFigure(fig, f);
    });
    if (ghostFigure) updateFigure(ghostFigure, f);
    if (strings) {
      const a = manifest.strings, pos = strings.geometry.attributes.position.array;
      const s = a.shape[1];
      for (let k = 0; k < s * 6; ++k) {
        const v = a.data[f * s * 6 + k];
        pos[k] = Number.isFinite(v) ? v : 0;
      }
      strings.geometry.attributes.position.needsUpdate = true;
    }
    const c = manifest.methods[view.method].contacts;
    const cp = c ? Array.from(c.point_mm.data.subarray(3 * f, 3 * f + 3)) : [NaN, NaN, NaN];
    contactMarker.visible = finite3(cp) && c.state.data[f] === 2;
    if (contactMarker.visible) contactMarker.position.set(cp[0], cp[1], cp[2]);
    $('timeline').value = String(f);
    $('time').textContent = frameTime(f).toFixed(3) + ' s · frame ' + (manifest.frame_first + f);
    drawPanels(f);
    render();
    syncVideo();
  }

  // The camera video follows the page's frame: paused, it is seeked to the middle of the
  // frame's interval (WebM stores times in ms, so k / fps itself may fall just before the
  // frame's timestamp); playing, it plays by itself at the same rate and is put back when it
  // drifts more than two frames from the audio clock.
  const videoTime = (f) => (f + 0.5) / fps();
  function syncVideo() {
    if (!video || video.readyState < 1) return;
    const want = videoTime(view.frame);
    if (view.playing) {
      if (Math.abs(video.currentTime - want) > 2 / fps()) video.currentTime = want;
    } else if (video.currentTime !== want) {
      video.currentTime = want;
    }
  }
  // The media time of the frame the video element last presented (requestVideoFrameCallback
  // where the browser has it): after a seek the element may still paint the frame before,
  // and videoPixel below waits for the one that was sought.
  let presentedTime = null, watchingFrames = false;
  function watchPresentedFrames() {
    if (!video || watchingFrames || !('requestVideoFrameCallback' in video)) return;
    watchingFrames = true;
    const onFrame = (now, meta) => {
      presentedTime = meta.mediaTime;
      video.requestVideoFrameCallback(onFrame);
    };
    video.requestVideoFrameCallback(onFrame);
  }
  function setVideoCamera(i) {
    if (!video) return;
    const v = manifest.videos[i];
    presentedTime = null;
    watchPresentedFrames();
    view.videoCamera = i;
    $('videocam').value = String(i);
    $('videoname').textContent = v.camera + ' · ' + v.method + ' overlay';
    video.src = v.file;
    video.addEventListener('loadedmetadata', () => {
      video.playbackRate = Number($('speed').value);
      syncVideo();
      if (view.playing) video.play().catch(() => {});
    }, { once: true });
  }

  function seek(frame) {
    showFrame(frame);
    // The middle of the frame's interval, so that the audio clock maps back to it.
    if (audio) audio.currentTime = Math.max(0, audioOffset() + (view.frame + 0.5) / fps());
  }

  // The clock: the audio's when there is audio, else the page's (same speed control).
  let silentStart = null;
  function clockFrame() {
    if (audio) return Math.floor((audio.currentTime - audioOffset()) * fps());
    const rate = Number($('speed').value);
    return silentStart.frame + Math.floor(((performance.now() - silentStart.ms) / 1000) * rate * fps());
  }
  function tick() {
    if (view.playing) {
      const f = clockFrame();
      if (f !== view.frame) showFrame(f);
      if ((audio && audio.ended) || f >= frameCount - 1) setPlaying(false);
    }
    requestAnimationFrame(tick);
  }

  function setPlaying(on) {
    view.playing = on;
    $('play').textContent = view.playing ? 'pause' : 'play';
    if (video) {
      if (view.playing) video.play().catch(() => {});
      else { video.pause(); syncVideo(); }
    }
    if (!audio) { silentStart = { frame: view.frame, ms: performance.now() }; return; }
    if (view.playing) audio.play().catch(() => setPlaying(false));
    else {
      audio.pause();
      // Paused, the picture is the frame the sound stopped at (not the last drawn one).
      showFrame(Math.max(0, Math.min(frameCount - 1, clockFrame())));
    }
  }

  // ---- panels ----------------------------------------------------------------------------
  function noteName(midi) { return kNoteNames[((midi % 12) + 12) % 12] + (Math.floor(midi / 12) - 1); }
  function midiOf(f0, a4) { return 69 + 12 * Math.log2(f0 / a4); }

  function drawPanels(f) {
    drawPitch(f);
    drawFingerboard(f);
    const q = manifest.quality;
    if (q) {
      const rms = q.reprojection_px.data[f], v = q.views.data[f];
      $('quality').textContent = 'views used (median over points): ' + (Number.isFinite(v) ? v.toFixed(0) : '–') +
        '\nreprojection error (median): ' + (Number.isFinite(rms) ? rms.toFixed(2) + ' px' : '–');
    } else $('quality').textContent = 'no triangulation quality in this result';
    const e = manifest.methods[view.method].errors;
    if (e) {
      const mm = (v) => (Number.isFinite(v) ? v.toFixed(1) + ' mm' : '–');
      $('quality').textContent += '\nagainst the truth (' + manifest.methods[view.method].name + '): left hand ' +
        mm(e.left_hand_mm.data[f]) + ' (mean of 21 points), contact ' + mm(e.contact_mm.data[f]);
    }
  }

  function drawPitch(f) {
    const cv = $('pitch'), g = cv.getContext('2d');
    g.clearRect(0, 0, cv.width, cv.height);
    const p = manifest.pitch;
    if (!p) { $('note').textContent = 'no pitch (the result has no pitch stage)'; return; }
    const a4 = p.a4_hz, span = Math.round(3 * fps());
    const f0 = p.f0_hz.data;
    let lo = Infinity, hi = -Infinity;
    for (let k = Math.max(0, f - span); k < Math.min(frameCount, f + span); ++k) {
      if (f0[k] > 0) { const m = midiOf(f0[k], a4); lo = Math.min(lo, m); hi = Math.max(hi, m); }
    }
    if (!Number.isFinite(lo)) { lo = 48; hi = 60; }
    lo = Math.floor(lo) - 2; hi = Math.ceil(hi) + 2;
    const x = (k) => ((k - (f - span)) / (2 * span)) * cv.width;
    const y = (m) => cv.height - ((m - lo) / (hi - lo)) * cv.height;
    g.font = '10px sans-serif';
    for (let m = lo; m <= hi; ++m) {
      g.strokeStyle = m % 12 === 0 ? '#444' : '#2a2a2a';
      g.beginPath(); g.moveTo(0, y(m)); g.lineTo(cv.width, y(m)); g.stroke();
      if ((hi - lo) < 30 || m % 2 === 0) { g.fillStyle = '#777'; g.fillText(noteName(m), 2, y(m) - 1); }
    }
    g.strokeStyle = '#7fd0ff'; g.lineWidth = 1.5; g.beginPath();
    let pen = false;
    for (let k = Math.max(0, f - span); k < Math.min(frameCount, f + span); ++k) {
      if (f0[k] > 0) { const yy = y(midiOf(f0[k], a4)); pen ? g.lineTo(x(k), yy) : g.moveTo(x(k), yy); pen = true; } else pen = false;
    }
    g.stroke(); g.lineWidth = 1;
    // The notes (notes.csv) as bars at their equal-tempered note, on the same clock.
    g.fillStyle = 'rgba(255, 200, 80, 0.35)';
    for (const n of manifest.notes) {
      const a = x(n.onset_s * fps()), b = x(n.offset_s * fps());
      if (b < 0 || a > cv.width) continue;
      g.fillRect(a, y(n.midi_note) - 2, b - a, 4);
    }
    g.strokeStyle = '#ff5060'; g.beginPath(); g.moveTo(x(f), 0); g.lineTo(x(f), cv.height); g.stroke();
    const c = manifest.methods[view.method].contacts;
    let text = f0[f] > 0 ? (() => {
      const m = midiOf(f0[f], a4), n = Math.round(m);
      const cents = Math.round(100 * (m - n));
      return noteName(n) + ' ' + (cents >= 0 ? '+' : '') + cents + ' cents (' + f0[f].toFixed(1) + ' Hz)';
    })() : 'unvoiced';
    const t = frameTime(f);
    const note = manifest.notes.find((n) => n.onset_s <= t && t < n.offset_s);
    if (note) {
      text += '\nnote ' + noteName(note.midi_note) + ' (' + (note.cents >= 0 ? '+' : '') +
        note.cents.toFixed(0) + ' cents median, ' + note.onset_s.toFixed(2) + '-' + note.offset_s.toFixed(2) + ' s)';
    }
    if (c) {
      const st = c.state.data[f];
      text += '\n' + manifest.methods[view.method].name + ': ' + kStates[st] +
        (st === 2 ? ', string ' + c.string.data[f] + ', finger ' + c.finger.data[f] + ' (' + kFingers[c.finger.data[f]] + ')' : '') +
        (st === 1 ? ', string ' + c.string.data[f] : '');
    }
    $('note').textContent = text;
  }

  function drawFingerboard(f) {
    const cv = $('fingerboard'), g = cv.getContext('2d');
    g.clearRect(0, 0, cv.width, cv.height);
    const s = manifest.strings;
    const c = manifest.methods[view.method].contacts;
    if (!s) { $('contact').textContent = 'no instrument stage: no strings'; return; }
    const n = s.shape[1];
    // String length (nut -> bridge) of this frame; strings drawn left (nut) to right.
    let length = 0;
    for (let k = 0; k < n; ++k) {
      const o = (f * n + k) * 6;
      const d = Math.hypot(s.data[o + 3] - s.data[o], s.data[o + 4] - s.data[o + 1], s.data[o + 5] - s.data[o + 2]);
      if (Number.isFinite(d)) length = Math.max(length, d);
    }
    const x0 = 20, x1 = cv.width - 20, row = (k) => 20 + (k * (cv.height - 40)) / Math.max(1, n - 1);
    g.fillStyle = '#888'; g.font = '10px sans-serif';
    for (let k = 0; k < n; ++k) {  // string 1 (highest) at the top
      g.strokeStyle = '#d8c890'; g.lineWidth = 1 + 0.5 * k;
      g.beginPath(); g.moveTo(x0, row(k)); g.lineTo(x1, row(k)); g.stroke();
      g.fillText(String(k + 1), 4, row(k) + 3);
    }
    g.lineWidth = 3; g.strokeStyle = '#eee';
    g.beginPath(); g.moveTo(x0, 10); g.lineTo(x0, cv.height - 10); g.stroke(); g.lineWidth = 1;
    if (!c) { $('contact').textContent = 'no contacts for ' + manifest.methods[view.method].name; return; }
    const st = c.state.data[f], from = c.from_nut_mm.data[f], str = c.string.data[f];
    if (st === 2 && Number.isFinite(from) && length > 0 && str >= 1) {
      g.fillStyle = '#ff2040';
      g.beginPath(); g.arc(x0 + (from / length) * (x1 - x0), row(str - 1), 6, 0, 2 * Math.PI); g.fill();
      $('contact').textContent = 'string ' + str + ', finger ' + c.finger.data[f] + ', ' + from.toFixed(1) +
        ' mm from the nut (string ' + length.toFixed(0) + ' mm)';
    } else $('contact').textContent = kStates[st];
  }

  // ---- controls --------------------------------------------------------------------------
  function setMethod(i) {
    view.method = i;
    $('method').value = String(i);
    setGhost(view.ghost);
  }
  function setGhost(i) {
    if (ghostFigure) { root.remove(ghostFigure.group); ghostFigure = null; }
    view.ghost = i;
    $('ghost').value = String(i);
    if (i >= 0 && i !== view.method) {
      ghostFigure = makeFigure(manifest.methods[i], view.side ? 1 : 0.45);
      root.add(ghostFigure.group);
    }
    $('sidelabels').hidden = !sideBySide();
    if (sideBySide()) {
      $('sideleft').textContent = manifest.methods[view.method].name;
      $('sideright').textContent = manifest.methods[i].name;
    }
    showFrame(view.frame);
  }

  // Side by side needs a second method: without a ghost, the next method is taken.
  function setSide(on) {
    view.side = on;
    $('layout').value = on ? 'side' : 'ghost';
    let g = view.ghost;
    if (on && (g < 0 || g === view.method) && manifest.methods.length > 1) {
      g = (view.method + 1) % manifest.methods.length;
    }
    setGhost(g);
  }

  function installControls() {
    const methodSel = $('method'), ghostSel = $('ghost');
    manifest.methods.forEach((m, i) => {
      methodSel.add(new Option(m.name, String(i)));
      ghostSel.add(new Option(m.name, String(i)));
    });
    methodSel.addEventListener('change', () => setMethod(Number(methodSel.value)));
    ghostSel.addEventListener('change', () => setGhost(Number(ghostSel.value)));
    $('layout').addEventListener('change', () => setSide($('layout').value === 'side'));
    const timeline = $('timeline');
    timeline.max = String(frameCount - 1);
    timeline.addEventListener('input', () => seek(Number(timeline.value)));
    $('prev').addEventListener('click', () => { setPlaying(false); seek(view.frame - 1); });
    $('next').addEventListener('click', () => { setPlaying(false); seek(view.frame + 1); });
    $('play').addEventListener('click', () => setPlaying(!view.playing));
    $('reset').addEventListener('click', () => { Object.assign(orbit, homeOrbit, { target: homeOrbit.target.clone() }); render(); });
    $('speed').addEventListener('change', () => {
      if (video) video.playbackRate = Number($('speed').value);
      if (audio) audio.playbackRate = Number($('speed').value);
      else if (view.playing) silentStart = { frame: view.frame, ms: performance.now() };
    });
    document.addEventListener('keydown', (e) => {
      if (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT') return;
      if (e.key === ' ') { e.preventDefault(); setPlaying(!view.playing); }
      if (e.key === 'ArrowLeft') seek(view.frame - 1);
      if (e.key === 'ArrowRight') seek(view.frame + 1);
    });
  }

  function showMissing(missing) {
    if (!missing.length) return;
    const box = $('missing');
    box.hidden = false;
    box.textContent = 'This result is incomplete:\n' +
      missing.map((m) => '• ' + m.stage + ' is missing: ' + m.why).join('\n');
  }

  async function main() {
    const t0 = performance.now();
    try {
      manifest = await loadData();
      view.timings = { data_ms: performance.now() - t0 };
    } catch (err) {
      $('error').hidden = false;
      $('error').textContent = 'Cannot load the data: ' + err.message;
      $('status').textContent = 'error';
      return;
    }
    frameCount = manifest.frames;
    document.title = 'arco view: ' + manifest.name;
    $('title').textContent = manifest.name || 'arco view';
    showMissing(manifest.missing);
    if (manifest.audio) {
      audio = $('audio');
      audio.preservesPitch = true;  // slow playback keeps the pitch
      audio.src = manifest.audio.file;
    }
    if (manifest.videos && manifest.videos.length) {
      video = $('video');
      $('videopanel').hidden = false;
      const sel = $('videocam');
      manifest.videos.forEach((v, i) => sel.add(new Option(v.camera, String(i))));
      sel.hidden = manifest.videos.length < 2;
      sel.addEventListener('change', () => setVideoCamera(Number(sel.value)));
      setVideoCamera(0);
    }
    buildScene(manifest);
    installControls();
    seek(0);
    requestAnimationFrame(tick);
    $('status').textContent = frameCount + ' frames at ' + manifest.fps + ' fps';
    view.timings.ready_ms = performance.now() - t0;
    view.ready = true;
  }

  // ---- test hooks (tests/view/view_browser_test.js) -----------------------------------
  view.methods = () => manifest.methods.map((m) => m.name);
  view.seek = (frame) => { setPlaying(false); seek(frame); return view.frame; };
  view.setMethod = (name) => setMethod(manifest.methods.findIndex((m) => m.name === name));
  view.setGhost = (name) => setGhost(manifest.methods.findIndex((m) => m.name === name));
  // Screen position (CSS px from the canvas' top-left) of the drawn joint `name` of the
  // shown method, from the instance the renderer draws; null when hidden or absent.
  // With `ghost` true: of the ghost method (side by side: in the right half).
  view.projectKeypoint = (name, ghost) => {
    const fig = ghost ? ghostFigure : figures[view.method];
    if (!fig) return null;
    const i = fig.index.get(name);
    if (i === undefined) return null;
    const m = new THREE.Matrix4();
    fig.joints.getMatrixAt(i, m);
    const p = new THREE.Vector3().setFromMatrixPosition(m);
    root.updateMatrixWorld();
    // The visible flags change while rendering side by side, never the matrices.
    fig.joints.updateWorldMatrix(true, false);
    p.applyMatrix4(fig.joints.matrixWorld).project(camera);
    const vp = viewport(ghost ? 1 : 0);
    return { x: vp.x + (p.x + 1) / 2 * vp.w, y: vp.y + (1 - p.y) / 2 * vp.h };
  };
  // Screen position of the drawn contact marker; null when hidden.
  view.projectContact = () => {
    if (!contactMarker.visible) return null;
    root.updateMatrixWorld();
    const p = new THREE.Vector3().setFromMatrixPosition(contactMarker.matrixWorld).project(camera);
    const vp = viewport(0);
    return { x: vp.x + (p.x + 1) / 2 * vp.w, y: vp.y + (1 - p.y) / 2 * vp.h };
  };
  // projection * view * root (data mm -> clip), column-major, and the canvas size in CSS px.
  view.dataToClip = () => {
    root.updateMatrixWorld();
    const m = new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse)
      .multiply(root.matrixWorld);
    const vp = viewport(0);
    return { matrix: m.elements.slice(), width: vp.w, height: vp.h };
  };
  view.setSide = (on) => setSide(on);
  // The camera video's state (null when the page shows none).
  view.video = () => (video ? {
    camera: manifest.videos[view.videoCamera].camera, src: video.currentSrc,
    readyState: video.readyState, error: video.error ? video.error.code : null,
    duration: video.duration, currentTime: video.currentTime, paused: video.paused,
    seeking: video.seeking, width: video.videoWidth, height: video.videoHeight } : null);
  view.setVideoCamera = (name) => setVideoCamera(manifest.videos.findIndex((v) => v.camera === name));
  // The video's picture at its own pixel (x, y), once the current seek is done: [r, g, b].
  view.videoPixel = async (x, y) => {
    // The sought frame presented: its media time within one frame before currentTime.
    const shown = () => !watchingFrames || (presentedTime !== null &&
        presentedTime <= video.currentTime + 1e-3 && video.currentTime - presentedTime < 1 / fps());
    for (let i = 0; video.seeking || video.readyState < 2 || !shown(); ++i) {
      if (i > 500 || video.error) throw new Error('the video does not show a frame');
      await new Promise((r) => setTimeout(r, 20));
    }
    const c = document.createElement('canvas');
    c.width = video.videoWidth; c.height = video.videoHeight;
    const g = c.getContext('2d');
    g.drawImage(video, 0, 0);
    return Array.from(g.getImageData(x, y, 1, 1).data.subarray(0, 3));
  };
  view.audioDuration = () => (audio ? audio.duration : null);

  main();
})();
