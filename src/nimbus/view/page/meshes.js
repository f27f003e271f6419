// nimbus view's instant preview: the scene's objects as triangle meshes (GET meshes.bin, laid out
// in view/preview_mesh.h), drawn with WebGL 2 from the page's own camera, so that a camera move
// is drawn at the display's rate without waiting for the server. Surfaces are lit by a light at
// the eye; media are see-through hulls. The path-traced image replaces it once it arrives.
'use strict';

const MESH_VERTEX_SHADER = `#version 300 es
in vec3 position;
in vec3 normal;
uniform mat4 view_projection;
uniform vec3 eye;         // perspective: the eye; orthographic: unused
uniform vec3 toward_eye;  // orthographic: the direction to the eye; perspective: zero
out vec3 n;
out vec3 to_eye;
void main() {
  n = normal;
  to_eye = dot(toward_eye, toward_eye) > 0.0 ? toward_eye : eye - position;
  gl_Position = view_projection * vec4(position, 1.0);
}`;

const MESH_FRAGMENT_SHADER = `#version 300 es
precision highp float;
in vec3 n;
in vec3 to_eye;
uniform vec4 colour;  // linear RGB, opacity
out vec4 fragment;
void main() {
  float facing = abs(dot(normalize(n), normalize(to_eye)));
  vec3 linear = colour.rgb * (0.25 + 0.75 * facing);
  fragment = vec4(pow(linear, vec3(1.0 / 2.2)), colour.a);
}`;

// Column-major 4 × 4 matrices, as WebGL takes them.
function multiply(a, b) {
  const m = new Float32Array(16);
  for (let c = 0; c < 4; ++c)
    for (let r = 0; r < 4; ++r)
      for (let k = 0; k < 4; ++k) m[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return m;
}

// The camera's view and projection matrices as nimbus's camera has them: fov is vertical, an
// orthographic width is the view's horizontal extent.
function viewProjection(c, aspect, bounds) {
  const sub3 = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const dot3 = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross3 = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const unit = (a) => { const l = Math.hypot(...a); return a.map((v) => v / l); };
  const f = unit(sub3(c.to, c.from));
  const r = unit(cross3(f, c.up));
  const u = cross3(r, f);
  const view = new Float32Array([r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0,
                                 -dot3(r, c.from), -dot3(u, c.from), dot3(f, c.from), 1]);
  // Near and far planes around the meshes' bounds.
  const centre = bounds.lo.map((v, i) => 0.5 * (v + bounds.hi[i]));
  const radius = 0.5 * Math.hypot(...sub3(bounds.hi, bounds.lo)) * 1.01 + 1e-9;
  const depth = dot3(sub3(centre, c.from), f);
  const far = Math.max(depth + radius, 1e-6);
  const near = Math.max(depth - radius, far * 1e-5);
  let projection;
  if (c.type === 'orthographic') {
    const w = c.width / 2, h = w / aspect;
    const near0 = depth - radius, far0 = depth + radius;
    projection = new Float32Array([1 / w, 0, 0, 0, 0, 1 / h, 0, 0, 0, 0, -2 / (far0 - near0), 0,
                                   0, 0, -(far0 + near0) / (far0 - near0), 1]);
  } else {
    const t = 1 / Math.tan((c.fov * Math.PI) / 360);
    projection = new Float32Array([t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, -(far + near) / (far - near), -1,
                                   0, 0, -2 * far * near / (far - near), 0]);
  }
  return {matrix: multiply(projection, view), towardEye: c.type === 'orthographic' ? f.map((v) => -v) : [0, 0, 0]};
}

// The meshes' binary: its header, and per object its colour, opacity and arrays (views into the
// buffer, no copies). Throws on a buffer that is not one.
function parseMeshes(buffer) {
  const view = new DataView(buffer);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 4));
  if (magic !== 'NMSH' || view.getUint32(4, true) !== 1) throw new Error('not a nimbus mesh file');
  const f32 = (offset, n) => Array.from(new Float32Array(buffer, offset, n));
  const count = view.getUint32(8, true);
  const scene = {background: f32(12, 3), bounds: {lo: f32(24, 3), hi: f32(36, 3)}, objects: [], triangles: 0};
  let at = 48;
  for (let i = 0; i < count; ++i) {
    const colour = f32(at, 4);
    const vertices = view.getUint32(at + 16, true), triangles = view.getUint32(at + 20, true);
    at += 24;
    const positions = new Float32Array(buffer, at, 3 * vertices);
    at += 12 * vertices;
    const normals = new Float32Array(buffer, at, 3 * vertices);
    at += 12 * vertices;
    const indices = new Uint32Array(buffer, at, 3 * triangles);
    at += 12 * triangles;
    scene.objects.push({colour, positions, normals, indices});
    scene.triangles += triangles;
  }
  if (at !== buffer.byteLength) throw new Error('a nimbus mesh file of the wrong length');
  return scene;
}

// Whether WebGL draws in software (no GPU: SwiftShader, llvmpipe), where multisampling costs
// about three times the frame (docs/benchmarks.md, "Viewer preview").
function softwareWebGL() {
  const probe = document.createElement('canvas').getContext('webgl2');
  if (!probe) return false;
  const info = probe.getExtension('WEBGL_debug_renderer_info');
  const name = String(probe.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : probe.RENDERER));
  const lose = probe.getExtension('WEBGL_lose_context');
  if (lose) lose.loseContext();
  return /swiftshader|llvmpipe|softpipe|software/i.test(name);
}

// The preview on a canvas; null where the browser has no WebGL 2.
function createMeshPreview(canvas) {
  const gl = canvas.getContext('webgl2', {antialias: !softwareWebGL(), premultipliedAlpha: false});
  if (!gl) return null;
  const compile = (type, source) => {
    const s = gl.createShader(type);
    gl.shaderSource(s, source);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  };
  const program = gl.createProgram();
  gl.attachShader(program, compile(gl.VERTEX_SHADER, MESH_VERTEX_SHADER));
  gl.attachShader(program, compile(gl.FRAGMENT_SHADER, MESH_FRAGMENT_SHADER));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(program));
  const at = (name) => gl.getUniformLocation(program, name);
  const uniforms = {viewProjection: at('view_projection'), eye: at('eye'), towardEye: at('toward_eye'), colour: at('colour')};
  const attributes = {position: gl.getAttribLocation(program, 'position'), normal: gl.getAttribLocation(program, 'normal')};

  let scene = null;    // the parsed meshes, with their GPU buffers
  let objects = [];    // {colour, count, vao, buffers}
  const stats = {frames: 0, triangles: 0, meshes: 0, firstFrameMs: null, lastFrameMs: null};

  function release() {
    for (const o of objects) {
      gl.deleteVertexArray(o.vao);
      for (const b of o.buffers) gl.deleteBuffer(b);
    }
    objects = [];
  }

  function load(buffer, version) {
    const parsed = parseMeshes(buffer);
    release();
    for (const o of parsed.objects) {
      const vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      const buffers = [];
      for (const [location, data] of [[attributes.position, o.positions], [attributes.normal, o.normals]]) {
        const b = gl.createBuffer();
        gl.bindBuffer(gl.ARRAY_BUFFER, b);
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
        gl.enableVertexAttribArray(location);
        gl.vertexAttribPointer(location, 3, gl.FLOAT, false, 0, 0);
        buffers.push(b);
      }
      const ib = gl.createBuffer();
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, o.indices, gl.STATIC_DRAW);
      buffers.push(ib);
      gl.bindVertexArray(null);
      objects.push({colour: o.colour, count: o.indices.length, vao, buffers});
    }
    scene = parsed;
    stats.triangles = parsed.triangles;
    stats.meshes = version;
  }

  // Draws the meshes from camera c into a width × height (CSS pixels) canvas.
  function draw(c, width, height) {
    if (!scene) return false;
    const ratio = window.devicePixelRatio || 1;
    canvas.style.width = `${width}px`;
    canvas.style.height = `${height}px`;
    const w = Math.round(width * ratio), h = Math.round(height * ratio);
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    gl.viewport(0, 0, w, h);
    const srgb = scene.background.map((v) => Math.pow(Math.min(Math.max(v, 0), 1), 1 / 2.2));
    gl.clearColor(srgb[0], srgb[1], srgb[2], 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.useProgram(program);
    const vp = viewProjection(c, width / height, scene.bounds);
    gl.uniformMatrix4fv(uniforms.viewProjection, false, vp.matrix);
    gl.uniform3fv(uniforms.eye, c.from);
    gl.uniform3fv(uniforms.towardEye, vp.towardEye);
    gl.enable(gl.DEPTH_TEST);
    // Surfaces first; then the see-through hulls over them, blended, without hiding each other.
    for (const pass of ['opaque', 'translucent']) {
      const translucent = pass === 'translucent';
      gl.depthMask(!translucent);
      // A hull is seen through once, at its front faces (counter-clockwise from outside).
      if (translucent) {
        gl.enable(gl.BLEND);
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
        gl.enable(gl.CULL_FACE);
      } else {
        gl.disable(gl.BLEND);
        gl.disable(gl.CULL_FACE);
      }
      for (const o of objects) {
        if ((o.colour[3] < 1) !== translucent) continue;
        gl.uniform4fv(uniforms.colour, o.colour);
        gl.bindVertexArray(o.vao);
        gl.drawElements(gl.TRIANGLES, o.count, gl.UNSIGNED_INT, 0);
      }
    }
    gl.bindVertexArray(null);
    gl.depthMask(true);
    const now = performance.now();
    if (stats.firstFrameMs === null) stats.firstFrameMs = now;
    stats.lastFrameMs = now;
    ++stats.frames;
    return true;
  }

  // Waits for the GPU to finish what was drawn (a one-pixel read): for timing draws.
  function finish() {
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  }

  return {load, draw, finish, stats, ready: () => scene !== null};
}
