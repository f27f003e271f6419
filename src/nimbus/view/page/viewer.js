// nimbus view's page: polls the server's state, shows its image as it refines, and turns mouse
// drags into camera moves (orbit about the camera's target, pan, zoom) that it posts back. Until
// the server's path-traced image of the page's camera is on screen, the scene's meshes are drawn
// in its place from the page's camera (meshes.js).
'use strict';

const $ = (id) => document.getElementById(id);
const image = $('image');

// Vectors as [x, y, z].
const add = (a, b) => a.map((v, i) => v + b[i]);
const sub = (a, b) => a.map((v, i) => v - b[i]);
const scale = (a, s) => a.map((v) => v * s);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => scale(a, 1 / Math.hypot(...a));
// v rotated by angle about the unit axis k (Rodrigues).
function rotate(v, k, angle) {
  const c = Math.cos(angle), s = Math.sin(angle);
  return add(add(scale(v, c), scale(cross(k, v), s)), scale(k, dot(k, v) * (1 - c)));
}

let state = null;       // the server's last state
let camera = null;      // the camera as this page has it
let shownVersion = -1;  // the image version on screen
let loading = false;    // an image is being fetched
let drag = null;        // {x, y, pan} while the mouse is down
let posting = false, queued = null, awaited = null, awaitedSince = 0;
let shown = null;       // {camera, preview} of the image on screen
let meshVersion = 0, meshLoading = false;
let drawn = '';         // what the meshes' canvas shows: camera, size and meshes
const meshCanvas = $('meshes');
let meshPreview = null;
try {
  meshPreview = createMeshPreview(meshCanvas);
} catch (err) {
  $('mesh-stats').textContent = `no WebGL preview: ${err.message}`;
}

function sameCamera(a, b) {
  const close = (x, y) => Math.abs(x - y) <= 1e-9 * Math.max(1, Math.abs(x), Math.abs(y));
  const vec = (u, v) => u.every((x, i) => close(x, v[i]));
  return a.type === b.type && vec(a.from, b.from) && vec(a.to, b.to) && vec(a.up, b.up) &&
         close(a.fov ?? 0, b.fov ?? 0) && close(a.width ?? 0, b.width ?? 0);
}

// A camera move: posted at once, or after the one in flight, the newest replacing any waiting.
function send(c) {
  camera = c;
  $('camera-json').value = cameraText(c);
  awaited = c;
  awaitedSince = performance.now();
  if (posting) { queued = c; return; }
  posting = true;
  fetch('camera', {method: 'POST', headers: {'Content-Type': 'application/json'}, body: JSON.stringify(c)})
    .then((r) => r.ok ? null : r.json().then((j) => { $('connection').textContent = j.error; }))
    .catch(() => { $('connection').textContent = 'the server went away'; })
    .finally(() => {
      posting = false;
      if (queued) { const next = queued; queued = null; send(next); }
    });
}

function orbit(c, dx, dy) {
  const up = norm(c.up);
  let v = sub(c.from, c.to);
  v = rotate(v, up, -dx * 0.01);
  const right = norm(cross(v, up));
  const rotated = rotate(v, right, dy * 0.01);
  // Stop short of the poles, where the view would flip over the up direction.
  if (Math.abs(dot(norm(rotated), up)) < 0.995) v = rotated;
  return {...c, from: add(c.to, v)};
}

function pan(c, dx, dy) {
  const forward = norm(sub(c.to, c.from));
  const right = norm(cross(forward, c.up));
  const up = cross(right, forward);
  const perPixel = c.type === 'orthographic'
    ? c.width / state.width
    : 2 * Math.hypot(...sub(c.to, c.from)) * Math.tan((c.fov * Math.PI) / 360) / state.height;
  const offset = add(scale(right, -dx * perPixel), scale(up, dy * perPixel));
  return {...c, from: add(c.from, offset), to: add(c.to, offset)};
}

function zoom(c, wheel) {
  const factor = Math.exp(wheel * 0.001);
  if (c.type === 'orthographic') return {...c, width: c.width * factor};
  return {...c, from: add(c.to, scale(sub(c.from, c.to), factor))};
}

image.addEventListener('pointerdown', (e) => {
  if (!camera) return;
  drag = {x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey};
  image.setPointerCapture(e.pointerId);
  image.classList.add('dragging');
  e.preventDefault();
});
image.addEventListener('pointermove', (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  if (dx === 0 && dy === 0) return;
  drag.x = e.clientX;
  drag.y = e.clientY;
  send(drag.pan ? pan(camera, dx, dy) : orbit(camera, dx, dy));
});
const release = () => { drag = null; image.classList.remove('dragging'); };
image.addEventListener('pointerup', release);
image.addEventListener('pointercancel', release);
image.addEventListener('contextmenu', (e) => e.preventDefault());
image.addEventListener('wheel', (e) => {
  if (!camera) return;
  e.preventDefault();
  send(zoom(camera, e.deltaY));
}, {passive: false});

function rounded(value) {
  if (Array.isArray(value)) return value.map(rounded);
  return typeof value === 'number' ? Number(value.toPrecision(7)) : value;
}

function cameraText(c) {
  const keys = ['type', 'from', 'to', 'up', 'fov', 'width'].filter((k) => k in c);
  const fields = keys.map((k) => `"${k}": ${JSON.stringify(rounded(c[k]))}`);
  return `"camera": {${fields.join(', ')}}`;
}

$('copy-camera').addEventListener('click', () => {
  const text = $('camera-json').value;
  const done = () => {
    $('notice').textContent = 'camera copied';
    setTimeout(() => { $('notice').textContent = ''; }, 2000);
  };
  if (navigator.clipboard) {
    navigator.clipboard.writeText(text).then(done, () => {
      $('camera-json').select();
      document.execCommand('copy');
      done();
    });
  } else {
    $('camera-json').select();
    document.execCommand('copy');
    done();
  }
});

function showImage(version, s) {
  loading = true;
  const next = new Image();
  const what = {camera: s.camera, preview: s.preview};
  next.onload = () => {
    image.src = next.src;
    image.dataset.version = String(version);
    shownVersion = version;
    shown = what;
    loading = false;
  };
  next.onerror = () => { loading = false; };
  next.src = `image.png?v=${version}`;
}

function show(s) {
  state = s;
  $('scene').textContent = s.scene;
  $('error').hidden = s.error === '';
  $('error').textContent = s.error;
  // With a noise target, the share of pixels whose blocks are done.
  $('spp').textContent = `${s.spp} / ${s.target_spp}` +
    (s.pixels_done >= 0 ? ` (${(100 * s.pixels_done).toFixed(0)} % of pixels done)` : '');
  $('sps').textContent = s.samples_per_second > 0 ? s.samples_per_second.toExponential(2) : '–';
  $('elapsed').textContent = `${s.elapsed.toFixed(1)} s`;
  $('noise').textContent = s.noise > 0 ? `${(100 * s.noise).toFixed(2)} %` : '–';
  $('mode').textContent = s.preview ? 'preview' : s.spp >= s.target_spp ? 'done' : 'rendering';
  image.style.width = `${s.width}px`;
  image.style.height = `${s.height}px`;
  // The server's camera, once it has taken this page's last move (or gave up on it), or when
  // the scene file's camera changed it.
  if (!drag && (!awaited || sameCamera(s.camera, awaited) || performance.now() - awaitedSince > 2000)) {
    awaited = null;
    camera = s.camera;
  }
  $('camera-json').value = cameraText(camera);
  if (s.has_image && s.version !== shownVersion && !loading) showImage(s.version, s);
  if (meshPreview && s.meshes > meshVersion && !meshLoading) loadMeshes();
}

function loadMeshes() {
  meshLoading = true;
  fetch('meshes.bin', {cache: 'no-store'})
    .then((r) => {
      if (!r.ok) throw new Error(`meshes: ${r.status}`);
      const version = Number(r.headers.get('X-Nimbus-Meshes'));
      return r.arrayBuffer().then((buffer) => {
        meshPreview.load(buffer, version);
        meshVersion = version;
        $('mesh-stats').textContent =
          `${meshPreview.stats.triangles.toLocaleString('en')} triangles in ${state.mesh_seconds.toFixed(2)} s`;
      });
    })
    .catch((err) => { $('mesh-stats').textContent = err.message; })
    .finally(() => { meshLoading = false; });
}

// The meshes stand in for the image until the path tracer's image of this camera is on screen.
function drawMeshes() {
  const wanted = meshPreview && meshPreview.ready() && camera && state &&
    (drag || !shown || shown.preview || !sameCamera(shown.camera, camera));
  meshCanvas.hidden = !wanted;
  if (wanted) {
    const key = JSON.stringify([camera, state.width, state.height, meshVersion]);
    if (key !== drawn && meshPreview.draw(camera, state.width, state.height)) drawn = key;
  }
  requestAnimationFrame(drawMeshes);
}
requestAnimationFrame(drawMeshes);

// For tests and benchmarks (bench/viewer_preview.py): the page's camera, the meshes' counters
// and the preview itself.
window.nimbusView = {camera: () => camera, meshes: () => meshPreview && meshPreview.stats,
                     preview: meshPreview};

async function poll() {
  try {
    const r = await fetch('state', {cache: 'no-store'});
    if (!r.ok) throw new Error(`state: ${r.status}`);
    show(await r.json());
    $('connection').textContent = '';
  } catch (err) {
    $('connection').textContent = 'waiting for the server';
  }
  setTimeout(poll, 100);
}
poll();
