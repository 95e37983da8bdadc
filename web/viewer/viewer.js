// The viewer page: loads scene.json and model.bin from the server (src/lumigauss/view/), or from the page
// itself when `lumigauss export --format html` put them there (window.__lgEmbedded, viewer/standalone_page.h),
// renders with renderer.js, sorts in sort_worker.js, and wires the controls. With ?bench=N (tests, bench/viewer_bench.sh)
// it renders N frames while orbiting and reports frame-time statistics to the server instead; with
// &cam=W,H,fx,fy,cx,cy,R(9),t(3) it first renders every view from that fixed camera and reports the pixels,
// &rot=DEG turns the environment, &mode=VIEW picks the view of the orbit frames, &controls first drives every
// control and reports which worked, and &target8 forces the 8-bit render target.
import { decodePayload, packSplats } from './model.js';
import { OrbitCamera, parseCameraParam } from './orbit.js';
import { SplatRenderer } from './renderer.js';
import { MODES } from './shaders.js';
import { decodePanoramaFile, panoramaFrameForUp, parseRadianceHdr, projectPanoramaToSh } from './panorama.js';
import { parseShSkyRows, parseShText, rotateAboutUp, rotationAboutAxis, scaleSh } from './sh.js';

const NEAR = 0.2;  // render/raster_constants.h kNearPlane
const $ = (id) => document.getElementById(id);

// The sorting worker, asked for the latest view only: a request while one is running replaces the queued
// one. `sorted(view)` resolves once a sort for that view (or a later one) has been applied.
class DepthSorter {
  constructor(positions, onSorted) {
    this.worker = new Worker(sortWorkerUrl());
    this.worker.onerror = (e) => window.__lgError(`sort worker: ${e.message}`);
    this.worker.onmessage = (e) => this.received(e.data);
    this.worker.postMessage({ type: 'init', positions: positions.slice() });
    this.onSorted = onSorted;
    this.nextId = 1;
    this.busy = false;
    this.queued = null;
    this.waiters = [];
    this.times = [];
  }

  request(view) {
    const msg = { type: 'sort', id: this.nextId++, r2: view.R[2], tz: view.t[2], near: NEAR };
    if (this.busy) this.queued = msg;
    else this.send(msg);
    return msg.id;
  }

  sorted(view) {
    const id = this.request(view);
    return new Promise((resolve) => this.waiters.push({ id, resolve }));
  }

  send(msg) {
    this.busy = true;
    this.worker.postMessage(msg);
  }

  received(m) {
    this.busy = false;
    this.times.push(m.ms);
    this.onSorted(m.indices, m.count);
    this.waiters = this.waiters.filter((w) => (w.id <= m.id ? (w.resolve(), false) : true));
    if (this.queued) {
      this.send(this.queued);
      this.queued = null;
    }
  }
}

// The worker's script: the served file, or for a page with everything inside, its text as a blob.
function sortWorkerUrl() {
  const embedded = window.__lgEmbedded;
  if (!embedded) return 'sort_worker.js';
  return URL.createObjectURL(new Blob([embedded.sortWorker], { type: 'text/javascript' }));
}

function decodeBase64(text) {
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes.buffer;
}

// The version of the model the server serves (it grows with each newer snapshot of a running training).
async function serverVersion() {
  const r = await fetch('version', { cache: 'no-store' });
  if (!r.ok) throw new Error(`version: HTTP ${r.status}`);
  return (await r.json()).version;
}

// scene.json and model.bin (and the version they belong to, read first: a newer one seen later reloads),
// from the server, or from the page itself (version 0, never reloaded).
async function loadSceneAndModel() {
  const embedded = window.__lgEmbedded;
  if (embedded) return [embedded.scene, decodeBase64(embedded.model), 0];
  const version = await serverVersion();
  const [scene, buffer] = await Promise.all([
    fetchOk('scene.json').then((r) => r.json()),
    fetchWithProgress('model.bin', showLoadingProgress),
  ]);
  return [scene, buffer, version];
}

// The body of `url` as an ArrayBuffer, reporting (received, total bytes) as it arrives.
async function fetchWithProgress(url, progress) {
  const r = await fetchOk(url);
  const total = Number(r.headers.get('Content-Length')) || 0;
  if (!r.body || !total) return r.arrayBuffer();
  const bytes = new Uint8Array(total);
  const reader = r.body.getReader();
  let received = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    if (received + value.length > total) throw new Error(`${url}: more bytes than its Content-Length`);
    bytes.set(value, received);
    received += value.length;
    progress(received, total);
  }
  if (received !== total) throw new Error(`${url}: ${received} of ${total} bytes arrived`);
  return bytes.buffer;
}

function showLoadingProgress(received, total) {
  const bar = $('loadingBar');
  if (!bar) return;
  bar.max = total;
  bar.value = received;
}

function hideLoading() {
  const box = $('loading');
  if (box) box.hidden = true;
}

async function fetchOk(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return r;
}

const nextFrame = () => new Promise((resolve) => requestAnimationFrame(resolve));

// A 16 x 8 Radiance .hdr panorama for the control checks (flat, or run-length coded scanlines as most
// files are), with radiance that varies across rows and columns and a brighter zenith.
function testPanoramaHdr(rle) {
  const W = 16, H = 8;
  const header = `#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y ${H} +X ${W}\n`;
  const rgbe = [];
  for (let y = 0; y < H; ++y)
    for (let x = 0; x < W; ++x) {
      const v = [0.2 + 0.1 * y, 0.5 + 0.4 * Math.sin(x), (y === 0 ? 3 : 1) + x / 16];
      const e = Math.floor(Math.log2(Math.max(...v))) + 1;
      rgbe.push(...v.map((c) => Math.floor((c * 256) / 2 ** e)), e + 128);
    }
  const out = [...header].map((ch) => ch.charCodeAt(0));
  if (!rle) return new Uint8Array(out.concat(rgbe));
  for (let y = 0; y < H; ++y) {
    out.push(2, 2, W >> 8, W & 255);
    for (let c = 0; c < 4; ++c) {
      const line = [];
      for (let x = 0; x < W; ++x) line.push(rgbe[4 * (y * W + x) + c]);
      if (line.every((v) => v === line[0])) out.push(128 + W, line[0]);  // a run
      else out.push(W, ...line);  // a literal
    }
  }
  return new Uint8Array(out);
}

function percentile(values, q) {
  if (!values.length) return null;
  const s = values.slice().sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor(q * s.length))];
}

function stats(values) {
  const mean = values.reduce((a, b) => a + b, 0) / Math.max(values.length, 1);
  return { median: percentile(values, 0.5), p90: percentile(values, 0.9), mean, count: values.length };
}

function base64(bytes) {
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

// A light of scene.json as the page keeps it (sky_residual: null unless the light has one).
function lightOfScene(l) {
  return { name: l.name, kind: l.kind, sh: l.sh, sky_residual: l.sky_residual || null };
}

class Viewer {
  constructor(scene, model, version) {
    this.scene = scene;
    this.version = version;
    this.reloads = 0;
    this.lights = scene.lights.map(lightOfScene);
    this.lightIndex = scene.initial_light || 0;
    this.rotation = 0;
    this.exposure = 0;
    this.mode = 'shadowed';
    this.ball = { mode: 0, size: 110 };
    this.sky = !!scene.sky_background;  // runs trained with the sky behind their surfels show it
    this.renderer = new SplatRenderer($('canvas'));
    this.renderer.setModel(packSplats(model, this.renderer.maxTextureSize));
    this.camera = new OrbitCamera(scene);
    this.sorter = this.makeSorter(model);
    this.count = model.count;
    this.dirty = true;
    this.updateEnvironment();
  }

  // exposure * light SH, turned about the up axis, as the shader's uniform; the same for the light's sky
  // residual, turned in the shader (the rows of R^T), as rotateAboutUp turns the light.
  updateEnvironment() {
    const light = this.lights[this.lightIndex];
    const scale = 2 ** this.exposure;
    const sh = rotateAboutUp(scaleSh(light.sh, scale), this.scene.up, this.rotation);
    this.env = new Float32Array(sh.flat());
    this.skyResidual = null;
    if (light.sky_residual) {
      const R = rotationAboutAxis(this.scene.up, (this.rotation * Math.PI) / 180);
      this.skyResidual = { coeffs: new Float32Array(scaleSh(light.sky_residual, scale).flat()),
                           turn: [0, 1, 2].map((i) => [R[0][i], R[1][i], R[2][i]]) };
    }
    this.dirty = true;
  }

  // The depth sorter of `model`; its results are dropped once another sorter has replaced it.
  makeSorter(model) {
    const sorter = new DepthSorter(model.xyz, (indices, count) => {
      if (this.sorter !== sorter) return;
      this.renderer.setOrder(indices, count);
      this.dirty = true;
    });
    return sorter;
  }

  // A newer model from the server (a running training's snapshot): the view, the controls and the chosen
  // light (by name) stay as they are.
  replaceModel(scene, model, version) {
    const lightName = this.lights[this.lightIndex].name;
    const added = this.lights.filter((l) => l.local);  // SH files loaded in this page: keep them
    this.scene = Object.assign(scene, { up: this.scene.up, e1: this.scene.e1, e2: this.scene.e2 });
    this.lights = scene.lights.map(lightOfScene).concat(added);
    const same = this.lights.findIndex((l) => l.name === lightName);
    this.lightIndex = same >= 0 ? same : scene.initial_light || 0;
    // The old worker first: no order for the old model may reach the new one's buffers.
    this.sorter.worker.terminate();
    this.sorter = this.makeSorter(model);
    this.renderer.setModel(packSplats(model, this.renderer.maxTextureSize));
    this.count = model.count;
    this.version = version;
    this.reloads += 1;
    this.needsSort = true;
    if ($('light').options.length) this.fillLightMenu();
    this.updateEnvironment();
  }

  // Polls the server's model version every `ms` and reloads when it grows.
  watchServer(ms) {
    let busy = false;
    setInterval(async () => {
      if (busy) return;
      busy = true;
      try {
        const version = await serverVersion();
        if (version > this.version) {
          const [scene, buffer] = await Promise.all([
            fetchOk('scene.json').then((r) => r.json()),
            fetchOk('model.bin').then((r) => r.arrayBuffer()),
          ]);
          this.replaceModel(scene, decodePayload(buffer), version);
          $('message').textContent = '';
        }
      } catch (err) {
        $('message').textContent = `reloading the model: ${err.message}`;  // the server may be gone
      }
      busy = false;
    }, ms);
  }

  canvasSize() {
    const c = this.renderer.canvas, dpr = window.devicePixelRatio || 1;
    return [Math.max(1, Math.round(c.clientWidth * dpr)), Math.max(1, Math.round(c.clientHeight * dpr))];
  }

  draw(view, withBall = true) {
    this.renderer.render(view, this.env, this.mode, withBall && this.ball.mode !== 'off' ? this.ball : null,
                         this.sky, this.scene.sky_horizon || null, this.scene.side_rule || null,
                         this.skyResidual);
  }

  // --- interactive use ---

  start() {
    this.bindControls();
    let lastKey = '';
    const frame = () => {
      const [w, h] = this.canvasSize();
      const view = this.camera.view(w, h);
      const key = JSON.stringify([view.R, view.t]);
      if (key !== lastKey || this.needsSort) {
        this.needsSort = false;
        this.sorter.request(view);
        lastKey = key;
        this.dirty = true;
      }
      if (this.dirty) {
        const t0 = performance.now();
        this.draw(view);
        this.dirty = false;
        const sort = this.sorter.times.length ? this.sorter.times[this.sorter.times.length - 1] : 0;
        $('stats').textContent = `${this.count} splats (${this.renderer.instances} in front)\n` +
          `sort ${sort.toFixed(1)} ms (worker)\ndraw calls ${(performance.now() - t0).toFixed(1)} ms (CPU)\n` +
          `${this.renderer.floatTarget ? 'float' : '8-bit'} target, ${this.renderer.rendererName}`;
      }
      requestAnimationFrame(frame);
    };
    requestAnimationFrame(frame);
  }

  fillLightMenu() {
    const select = $('light');
    select.textContent = '';
    this.lights.forEach((l, i) => {
      const o = document.createElement('option');
      o.value = String(i);
      o.textContent = l.kind === 'training photo' || l.kind === l.name ? l.name : `${l.name} (${l.kind})`;
      select.appendChild(o);
    });
    select.value = String(this.lightIndex);
  }

  bindControls() {
    this.fillLightMenu();
    // The side panel: hidden with the toggle, and from the start on small windows.
    if (window.innerWidth < 700) document.body.classList.add('collapsed');
    $('panelToggle').onclick = () => {
      document.body.classList.toggle('collapsed');
      this.dirty = true;
    };
    // An SH file or a panorama dropped on the view lights the model, as the file input does.
    const view = $('view');
    view.addEventListener('dragover', (e) => {
      e.preventDefault();
      view.classList.add('dropping');
    });
    view.addEventListener('dragleave', () => view.classList.remove('dropping'));
    view.addEventListener('drop', (e) => {
      e.preventDefault();
      view.classList.remove('dropping');
      if (e.dataTransfer && e.dataTransfer.files.length) this.loadLightFile(e.dataTransfer.files[0]);
    });
    const touch = () => (this.dirty = true);
    $('light').onchange = (e) => { this.lightIndex = Number(e.target.value); this.updateEnvironment(); };
    $('rotation').oninput = (e) => {
      this.rotation = Number(e.target.value);
      $('rotationValue').textContent = e.target.value;
      this.updateEnvironment();
    };
    $('exposure').oninput = (e) => {
      this.exposure = Number(e.target.value);
      $('exposureValue').textContent = e.target.value;
      this.updateEnvironment();
    };
    $('mode').onchange = (e) => { this.mode = e.target.value; touch(); };
    $('ball').onchange = (e) => { this.ball.mode = e.target.value === 'off' ? 'off' : Number(e.target.value); touch(); };
    $('background').value = this.sky ? 'sky' : 'black';
    $('background').onchange = (e) => { this.sky = e.target.value === 'sky'; touch(); };
    $('reset').onclick = () => { this.camera.reset(); touch(); };
    $('shfile').onchange = (e) => this.loadLightFile(e.target.files[0]);
    this.bindPointer($('canvas'));
    window.addEventListener('resize', touch);
  }

  // An SH text file, or a panorama (.hdr, .png, .jpg) projected to SH about the scene's up as the C++ does.
  async loadLightFile(file) {
    if (!file) return;
    try {
      const panorama = /\.(hdr|exr|png|jpe?g)$/i.test(file.name);
      const text = panorama ? null : await file.text();
      const sh = panorama ? projectPanoramaToSh(await decodePanoramaFile(file), panoramaFrameForUp(this.scene.up))
                          : parseShText(text);
      const skyResidual = panorama ? null : parseShSkyRows(text);
      this.lights.push({ name: file.name, kind: panorama ? 'panorama' : 'SH file', sh, sky_residual: skyResidual,
                         local: true });
      this.lightIndex = this.lights.length - 1;
      this.fillLightMenu();
      this.updateEnvironment();
      $('message').textContent = '';
    } catch (err) {
      $('message').textContent = `${file.name}: ${err.message}`;
    }
  }

  bindPointer(canvas) {
    let last = null;
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('pointerdown', (e) => {
      try {
        canvas.setPointerCapture(e.pointerId);  // keeps the drag when the pointer leaves the canvas
      } catch (err) {
        // not an active pointer (a synthetic event): dragging works without capture
      }
      last = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.button === 1 || e.shiftKey };
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!last) return;
      const dx = e.clientX - last.x, dy = e.clientY - last.y;
      last.x = e.clientX, last.y = e.clientY;
      if (last.pan) this.camera.pan(dx, dy, canvas.clientHeight);
      else this.camera.orbit(dx, dy, canvas.clientHeight);
    });
    const end = () => (last = null);
    canvas.addEventListener('pointerup', end);
    canvas.addEventListener('pointercancel', end);
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.camera.zoom(Math.exp(e.deltaY * 0.0015));
    }, { passive: false });
    canvas.addEventListener('dblclick', () => this.camera.reset());
  }

  // --- bench and test mode ---

  // Every view from a fixed camera, without the ball, as RGB rows from the top.
  async shots(view) {
    const canvas = this.renderer.canvas;
    canvas.classList.add('fixed');
    canvas.style.width = `${view.width}px`;
    canvas.style.height = `${view.height}px`;
    await this.sorter.sorted(view);
    const out = {};
    for (const mode of MODES) {
      this.mode = mode;
      this.draw(view, false);
      const img = this.renderer.readRgb();
      out[mode] = { width: img.width, height: img.height, rgb: base64(img.rgb) };
    }
    this.mode = 'shadowed';
    canvas.classList.remove('fixed');
    canvas.style.width = canvas.style.height = '';
    return out;
  }

  // N frames turning the orbit camera once around; each frame is drawn and waited for (GPU included).
  async orbitFrames(frames) {
    await nextFrame();
    const [w, h] = this.canvasSize();
    await this.sorter.sorted(this.camera.view(w, h));
    this.sorter.times = [];
    const frameMs = [], intervals = [];
    let previous = null;
    for (let i = 0; i < frames; ++i) {
      const stamp = await nextFrame();
      if (previous !== null) intervals.push(stamp - previous);
      previous = stamp;
      const t0 = performance.now();
      this.camera.azimuth += (2 * Math.PI) / frames;
      const view = this.camera.view(w, h);
      this.sorter.request(view);
      this.draw(view);
      this.renderer.finish();
      frameMs.push(performance.now() - t0);
    }
    await this.sorter.sorted(this.camera.view(w, h));
    this.draw(this.camera.view(w, h));
    const img = this.renderer.readRgb();
    let lit = 0;
    for (let p = 0; p < img.rgb.length; p += 3) if (img.rgb[p] + img.rgb[p + 1] + img.rgb[p + 2] > 6) ++lit;
    return {
      width: w, height: h, frame_ms: stats(frameMs), raf_interval_ms: stats(intervals),
      sort_ms: stats(this.sorter.times), nonblank_fraction: lit / (img.width * img.height),
    };
  }

  // Drives every control the way a user would (events on the real elements) and reports whether each one
  // changed the viewer's state: the tests' check that the page is wired up.
  async checkControls() {
    const fire = (id, type, value) => {
      const el = $(id);
      if (value !== undefined) el.value = value;
      el.dispatchEvent(new Event(type));
    };
    const checks = {};
    const env0 = this.env.slice();
    fire('rotation', 'input', '90');
    checks.rotation = this.rotation === 90 && this.env.some((v, i) => v !== env0[i]);
    fire('exposure', 'input', '1');
    checks.exposure = this.exposure === 1;
    fire('mode', 'change', 'albedo');
    checks.mode = this.mode === 'albedo';
    fire('ball', 'change', 'off');
    checks.ball = this.ball.mode === 'off';
    fire('light', 'change', String(this.lights.length - 1));
    checks.light = this.lightIndex === this.lights.length - 1;
    const file = new DataTransfer();
    file.items.add(new File(['1 1 1\n0 0 0\n0.5 0.5 0.5\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n'], 'test_sh.txt'));
    $('shfile').files = file.files;
    await this.loadLightFile($('shfile').files[0]);
    checks.sh_file = this.lights[this.lightIndex].name === 'test_sh.txt' && this.env[6] === 0.5 * 2;
    // A fitted light's file: its 25 "#sky" rows are the light's sky residual; a damaged row is refused.
    const nine = '1 1 1\n' + '0 0 0\n'.repeat(8);
    const skyRows = Array.from({ length: 25 }, (_, k) => (k === 1 ? '#sky 0.5 0.25 0.125\n' : '#sky 0 0 0\n')).join('');
    await this.loadLightFile(new File([nine + skyRows], 'fitted_sh.txt'));
    checks.sh_file_sky_rows = this.lights[this.lightIndex].name === 'fitted_sh.txt' &&
      this.skyResidual !== null && this.skyResidual.coeffs[4] === 0.25 * 2;
    this.lights.pop();
    await this.loadLightFile(new File([nine + '#sky 1 2\n'], 'damaged_sh.txt'));
    checks.sh_file_bad_sky_row = this.lights[this.lights.length - 1].name !== 'damaged_sh.txt' &&
      $('message').textContent.includes('line 10');
    this.lightIndex = this.lights.length - 1;
    this.updateEnvironment();
    const canvas = $('canvas'), az = this.camera.azimuth, dist = this.camera.distance;
    const pointer = (type, x, extra = {}) =>
      canvas.dispatchEvent(new PointerEvent(type, { pointerId: 1, clientX: x, clientY: 10, button: 0, buttons: 1, ...extra }));
    pointer('pointerdown', 10);
    pointer('pointermove', 60);
    pointer('pointerup', 60);
    checks.orbit = this.camera.azimuth !== az;
    canvas.dispatchEvent(new WheelEvent('wheel', { deltaY: 100, cancelable: true }));
    checks.zoom = this.camera.distance > dist;
    canvas.dispatchEvent(new MouseEvent('dblclick'));
    checks.reset = this.camera.azimuth === az && this.camera.distance === dist;
    // An SH file dropped on the view.
    const dropped = new DataTransfer();
    dropped.items.add(new File(['0.5 0.5 0.5\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n'], 'dropped_sh.txt'));
    $('view').dispatchEvent(new DragEvent('drop', { dataTransfer: dropped, cancelable: true }));
    for (let i = 0; i < 50 && this.lights[this.lightIndex].name !== 'dropped_sh.txt'; ++i) await nextFrame();
    checks.drop_sh_file = this.lights[this.lightIndex].name === 'dropped_sh.txt';
    this.lights.pop();
    this.lightIndex = this.lights.length - 1;
    // A panorama dropped on the view, the same pixels in a flat and a run-length coded .hdr file.
    const flat = testPanoramaHdr(false), rle = testPanoramaHdr(true);
    const pano = new DataTransfer();
    pano.items.add(new File([rle], 'test_sky.hdr'));
    $('view').dispatchEvent(new DragEvent('drop', { dataTransfer: pano, cancelable: true }));
    for (let i = 0; i < 50 && this.lights[this.lightIndex].name !== 'test_sky.hdr'; ++i) await nextFrame();
    const light = this.lights[this.lightIndex];
    checks.drop_panorama = light.name === 'test_sky.hdr' && light.kind === 'panorama';
    const a = parseRadianceHdr(flat).pixels, b = parseRadianceHdr(rle).pixels;
    checks.hdr_flat_equals_rle = a.length === b.length && a.every((v, i) => v === b[i]);
    const ups = [this.scene.up, [0, -1, 0], [0.2, -0.9, 0.3], [-1, 0.1, 0]];
    this.panoramaCheck = {
      up: this.scene.up, sh: light.sh, hdr_base64: btoa(String.fromCharCode(...rle)),
      frames: ups.map((up) => ({ up, frame: panoramaFrameForUp(up) })),
    };
    this.lights.pop();
    this.lightIndex = this.lights.length - 1;  // the SH file loaded above, removed below
    // The panel toggle, twice; the loading indicator is gone once the viewer runs.
    const panelShown = () => getComputedStyle($('panel')).display !== 'none';
    const before = panelShown();
    $('panelToggle').click();
    const toggled = panelShown() !== before;
    $('panelToggle').click();
    checks.panel_toggle = toggled && panelShown() === before;
    checks.loading_hidden = $('loading').hidden === true;
    // Back to the state the rest of the bench expects.
    fire('rotation', 'input', '0');
    fire('exposure', 'input', '0');
    fire('mode', 'change', 'shadowed');
    fire('ball', 'change', '0');
    this.lights.pop();
    this.lightIndex = this.scene.initial_light || 0;
    this.fillLightMenu();
    this.updateEnvironment();
    return checks;
  }

  async bench(params) {
    // &reload=N: first wait (30 s at most) for the server to serve a model of N splats, polling often.
    if (params.has('reload')) {
      const want = Number(params.get('reload'));
      this.watchServer(100);
      const until = performance.now() + 30000;
      while (this.count !== want && performance.now() < until) await new Promise((r) => setTimeout(r, 50));
    }
    const report = {
      splats: this.count, renderer: this.renderer.rendererName, float_target: this.renderer.floatTarget,
      user_agent: navigator.userAgent, reloads: this.reloads, version: this.version,
    };
    if (params.has('controls')) {
      this.bindControls();
      report.controls = await this.checkControls();
      report.panorama_check = this.panoramaCheck;
    }
    if (params.has('sky')) this.sky = true;  // the light's sky behind the surfels, whatever the run
    const degrees = Number(params.get('rot') || 0);
    this.rotation = degrees;
    this.updateEnvironment();
    // The page's SH rotation, for the test to compare with the C++ rotate_about_up.
    report.rotation_check = { up: this.scene.up, degrees: 37, sh: this.lights[this.lightIndex].sh,
                              rotated: rotateAboutUp(this.lights[this.lightIndex].sh, this.scene.up, 37) };
    const cam = params.get('cam');
    if (cam) {
      const view = parseCameraParam(cam);
      if (!view) throw new Error(`cam=${cam}: expected 18 numbers W,H,fx,fy,cx,cy,R(9),t(3)`);
      report.shots = await this.shots(view);
    }
    if (MODES.includes(params.get('mode'))) this.mode = params.get('mode');
    report.mode = this.mode;
    Object.assign(report, await this.orbitFrames(Math.max(1, Number(params.get('bench')))));
    await window.__lgReport(report);
    $('stats').textContent = `bench done: median ${report.frame_ms.median.toFixed(1)} ms`;
  }
}

async function main() {
  const params = new URLSearchParams(location.search);
  const [scene, buffer, version] = await loadSceneAndModel();
  const viewer = new Viewer(scene, decodePayload(buffer), version);
  hideLoading();
  if (params.has('bench')) await viewer.bench(params);
  else {
    viewer.start();
    if (!window.__lgEmbedded) viewer.watchServer(3000);
  }
}

main().catch((err) => window.__lgError(err && err.stack ? err.stack : err));
