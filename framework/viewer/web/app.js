// SPDX-License-Identifier: MIT
// binocle view: the page's logic. One WebSocket brings state (text) and frames (binary:
// 4-byte header length, JSON header, blobs); commands go back as JSON text.
'use strict';

const token = new URLSearchParams(location.search).get('token') || '';
const $ = (id) => document.getElementById(id);
// Read by the browser tests: what the page has received; drawn: the sequence number of
// the frame each image panel shows.
// showMs: from a frame's arrival until it was drawn, summed over the frames
// received (bench/view_overhead.py reads it).
window.binocle = { framesReceived: 0, drawn: {}, lastHeader: null, lastError: '', state: null, replies: [], showMs: 0 };

let ws = null;
let colorScale = [];
let controlsSignature = '';
let figuresSignature = '';
let scaleSignature = '';

function showMessage(text, info) {
  const m = $('message');
  m.textContent = text;
  m.classList.toggle('hidden', !text);
  m.classList.toggle('info', !!info);
}

function send(command) {
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(command));
}

function connect() {
  ws = new WebSocket(`ws://${location.host}/ws?token=${encodeURIComponent(token)}`);
  ws.binaryType = 'arraybuffer';
  ws.onmessage = (ev) => {
    if (typeof ev.data === 'string') onText(JSON.parse(ev.data));
    else onFrame(ev.data);
  };
  ws.onclose = () => {
    setStatus('disconnected');
    setTimeout(connect, 1500);
  };
}

function setStatus(status) {
  const b = $('status');
  b.textContent = status;
  b.className = 'badge ' + status.split(' ')[0];
}

// ---- Text messages ----------------------------------------------------------------
function onText(msg) {
  window.binocle.replies.push(msg);
  if (window.binocle.replies.length > 50) window.binocle.replies.shift();
  if (msg.type === 'hello' || msg.type === 'state') onState(msg);
  else if (msg.type === 'error') {
    window.binocle.lastError = msg.message;
    showMessage(msg.message);
    if (msg.key) markControl(msg.key, msg.message);
  } else if (msg.type === 'accepted') {
    window.binocle.lastError = '';
    showMessage('');
    if (msg.key) markControl(msg.key, '');
  } else if (msg.type === 'snapshot') {
    showMessage(`Frame ${msg.sequence} written to ${msg.dir}:\n` + msg.files.map((f) => f.split('/').pop()).join(', '), true);
  }
}

function onState(s) {
  window.binocle.state = s;
  if (s.color_scale) colorScale = s.color_scale;
  $('rig-name').textContent = s.rig.name;
  document.title = `Binocle view: ${s.rig.name}`;
  let status = s.status;
  if (s.status === 'running' && s.paused) status = 'paused';
  setStatus(status);
  $('pause').textContent = s.paused ? 'Resume' : 'Pause';
  if (s.status === 'failed' && s.error) showMessage('The pipeline stopped: ' + s.error);
  $('set-lines').value = s.set_lines;
  $('save-rig').href = `/api/rig.yaml?token=${encodeURIComponent(token)}`;
  $('save-set').href = `/api/set-lines.txt?token=${encodeURIComponent(token)}`;
  buildControls(s.blocks);
}

// ---- Controls from the plugins' settings tables ----------------------------------
function buildControls(blocks) {
  const signature = JSON.stringify(blocks.map((b) => [b.key, b.plugin, b.params.map((p) => p.name)]));
  const root = $('controls');
  if (signature !== controlsSignature) {
    controlsSignature = signature;
    root.textContent = '';
    for (const b of blocks) {
      const fs = document.createElement('fieldset');
      const legend = document.createElement('legend');
      legend.textContent = `${b.key} · ${b.plugin}`;
      fs.appendChild(legend);
      for (const p of b.params) fs.appendChild(makeControl(b.key + '.' + p.name, p));
      root.appendChild(fs);
    }
  }
  for (const b of blocks) for (const p of b.params) updateControl(b.key + '.' + p.name, p);
}

function numberStep(p) {
  if (p.type === 'int') return p.multiple_of ? p.multiple_of : (p.odd ? 2 : 1);
  if (p.min !== undefined && p.max !== undefined) return (p.max - p.min) / 200;
  return 'any';
}

function makeControl(key, p) {
  const row = document.createElement('div');
  row.className = 'control';
  row.dataset.key = key;
  row.id = 'ctl-' + key;
  const label = document.createElement('label');
  label.textContent = p.name + (p.unit ? ` (${p.unit})` : '');
  label.title = p.help + (p.default !== null ? ` [default ${p.default}]` : '');
  row.appendChild(label);
  const commit = (value) => send({ op: 'set', key, value: String(value) });
  if ((p.type === 'int' || p.type === 'double')) {
    const num = document.createElement('input');
    num.type = 'number';
    num.step = numberStep(p);
    num.className = 'number';
    if (p.min !== undefined && p.max !== undefined) {
      const range = document.createElement('input');
      range.type = 'range';
      range.min = p.min;
      range.max = p.max;
      range.step = numberStep(p);
      range.className = 'slider';
      range.addEventListener('input', () => { num.value = range.value; });
      range.addEventListener('change', () => commit(range.value));
      row.appendChild(range);
    } else {
      num.classList.add('wide');
    }
    num.addEventListener('change', () => commit(num.value));
    row.appendChild(num);
  } else if (p.type === 'enum') {
    const sel = document.createElement('select');
    sel.className = 'wide';
    for (const c of p.choices) {
      const o = document.createElement('option');
      o.value = o.textContent = c;
      sel.appendChild(o);
    }
    sel.addEventListener('change', () => commit(sel.value));
    row.appendChild(sel);
  } else if (p.type === 'bool') {
    const sw = document.createElement('label');
    sw.className = 'switch';
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.addEventListener('change', () => commit(box.checked ? 'true' : 'false'));
    sw.appendChild(box);
    sw.appendChild(document.createElement('span'));
    row.appendChild(sw);
  } else {
    const text = document.createElement('input');
    text.type = 'text';
    text.className = 'wide';
    text.title = 'YAML text';
    text.addEventListener('change', () => commit(text.value));
    row.appendChild(text);
  }
  if (p.limit) {
    // A resource limit: shown with its value; the server refuses it from a page.
    row.classList.add('limit');
    for (const input of row.querySelectorAll('input, select')) input.disabled = true;
    label.title += ' A resource limit: set in the rig file or with --set, not from this page.';
  }
  const err = document.createElement('div');
  err.className = 'error hidden';
  row.appendChild(err);
  return row;
}

function updateControl(key, p) {
  const row = document.getElementById('ctl-' + key);
  if (!row || p.value === undefined) return;
  row.classList.toggle('explicit', !!p.explicit);
  for (const input of row.querySelectorAll('input, select')) {
    if (input === document.activeElement || row.classList.contains('invalid')) continue;
    if (input.type === 'checkbox') input.checked = p.value === 'true';
    else input.value = p.value;
  }
}

function markControl(key, message) {
  const row = document.getElementById('ctl-' + key);
  if (!row) return;
  row.classList.toggle('invalid', !!message);
  const err = row.querySelector('.error');
  err.textContent = message;
  err.classList.toggle('hidden', !message);
}

// ---- Frames -----------------------------------------------------------------------
const imageNames = ['left', 'right', 'disparity', 'top', 'front', 'side'];

// One image's bytes to something a canvas can draw, decoded off the page's thread.
// ImageDecoder (WebCodecs) reads the frame's own buffer: no Blob, no object URL, no
// round trip through the browser process (those cost more CPU than the decoding, measured
// by bench/view_overhead.py). Where it is missing (a non-local origin, another browser),
// createImageBitmap of a Blob. (One JPEG mosaic of the six images instead, decoded once,
// cost the browser more, not less: measured, and left.)
function decodeImage(bytes, type) {
  if (typeof ImageDecoder === 'function') {
    const decoder = new ImageDecoder({ data: bytes, type });
    return decoder.decode().then((r) => r.image).finally(() => decoder.close());
  }
  return createImageBitmap(new Blob([bytes], { type }));
}

function drawImage(name, image, sequence) {
  const c = $('img-' + name);
  const w = image.displayWidth || image.width, h = image.displayHeight || image.height;
  if (c.width !== w || c.height !== h) {
    c.width = w;
    c.height = h;
  }
  c.getContext('2d').drawImage(image, 0, 0);
  window.binocle.drawn[name] = sequence; // not a DOM attribute: no style work per frame
  image.close();
}

// Told to the server once the frame is drawn: it sends the next frame only then, so this
// page never gets more frames than it can show (server.hpp). Not after a
// requestAnimationFrame: a headless or busy browser may hold those back for seconds.
function onFrame(buffer) {
  const arrived = performance.now();
  const view = new DataView(buffer);
  const length = view.getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, length)));
  let base = 4 + length;
  base += (4 - (base % 4)) % 4;
  const blob = {};
  for (const b of header.blobs) blob[b.name] = { b, start: base + b.offset };
  const names = imageNames.filter((name) => blob[name]);
  const decoded = names.map((name) => decodeImage(new Uint8Array(buffer, blob[name].start, blob[name].b.size), blob[name].b.type));
  // Everything the frame changes is changed in one task, once its images are decoded: the
  // browser lays out, paints and composites once per frame, not once per image.
  Promise.allSettled(decoded).then((results) => {
    results.forEach((r, i) => {
      if (r.status === 'fulfilled') drawImage(names[i], r.value, header.sequence);
      else console.warn(`frame ${header.sequence}: image ${names[i]} not decoded: ${r.reason}`);
    });
    // The 3D view is drawn again only here, when a new cloud has come (the server sends
    // one at most --cloud-fps times a second) or on a drag.
    if (blob.cloud_xyz) {
      const xyz = new Float32Array(buffer.slice(blob.cloud_xyz.start, blob.cloud_xyz.start + blob.cloud_xyz.b.size));
      cloudView.setPoints(xyz, header.cloud.frame);
    }
    window.binocle.framesReceived += 1;
    window.binocle.lastHeader = header;
    drawScale(header.disparity_scale);
    showText(header);
    window.binocle.showMs += performance.now() - arrived;
    send({ op: 'shown' });
  });
}

// The text (counters, figures, source statistics) changes at most twice a second, in a
// frame's task: faster numbers cannot be read, and every change of the side panel costs
// the browser a layout and a paint (measured by bench/view_overhead.py). The last frame's
// text is shown anyway once frames stop coming (pause, end).
const TEXT_INTERVAL_MS = 500;
let textShownAt = -Infinity;
let textTimer = null;
function showText(header) {
  clearTimeout(textTimer);
  const due = textShownAt + TEXT_INTERVAL_MS - performance.now();
  if (due > 0) {
    textTimer = setTimeout(() => showText(header), due + 250);
    return;
  }
  textShownAt = performance.now();
  setText($('frame-counter'), String(header.frames_processed));
  setText($('sequence'), String(header.sequence));
  setText($('frames-shown'), String(window.binocle.framesReceived));
  setText($('fps'), header.pipeline_fps !== null ? `${header.pipeline_fps.toFixed(1)} fps` : '');
  showFigures(header);
  setText($('source-stats'), header.source_statistics || '(the source reports none)');
}

// Changes the DOM only where the text changed: less for the browser to lay out and paint.
function setText(element, text) {
  if (element.textContent !== text) element.textContent = text;
}

function fmt(v, digits) {
  if (v === null || v === undefined) return 'n/a';
  if (typeof v !== 'number') return String(v);
  const d = digits !== undefined ? digits : (Math.abs(v) >= 100 ? 1 : Math.abs(v) >= 1 ? 3 : 4);
  return v.toFixed(d);
}

function showFigures(h) {
  const rows = [['group', 'Pipeline']];
  rows.push(['pipeline', `${fmt(h.pipeline_fps, 1)} fps`]);
  rows.push(['frame time', `${fmt(h.frame_ms, 1)} ms`]);
  for (const [stage, ms] of Object.entries(h.stage_ms)) {
    rows.push([`· ${stage}`, `${fmt(ms, 2)} ms (${ms > 0 ? fmt(1000 / ms, 0) : '∞'} fps)`]);
  }
  rows.push(['valid pixels', `${fmt(100 * h.valid_pixel_ratio, 1)} %`]);
  rows.push(['points', String(h.points)]);
  rows.push(['matcher range', `${h.matcher.min_disparity_px} + ${h.matcher.num_disparities} px`]);
  for (const [evaluator, figures] of Object.entries(h.metrics)) {
    rows.push(['group', evaluator]);
    for (const [name, value] of Object.entries(figures)) {
      if (name.endsWith('_unit') || name === 'view_overlays') continue;
      if (name === 'objects' && typeof value === 'string') {
        let list = [];
        try { list = JSON.parse(value); } catch (e) { list = []; }
        rows.push(['objects', list.map((o) => `#${o.id} ${fmt(o.range_mm / 1000, 2)} m`).join(', ') || 'none']);
        continue;
      }
      const unit = figures[name + '_unit'] ? ' ' + figures[name + '_unit'] : '';
      rows.push([name, fmt(value) + unit]);
    }
  }
  const body = $('figures').tBodies[0];
  // Same rows as the last frame: only the values change.
  const signature = JSON.stringify(rows.map(([k, v]) => (k === 'group' ? 'group:' + v : k)));
  if (signature === figuresSignature) {
    rows.forEach(([k, v], i) => { if (k !== 'group') setText(body.rows[i].cells[1], v); });
    return;
  }
  figuresSignature = signature;
  body.textContent = '';
  for (const [k, v] of rows) {
    const tr = body.insertRow();
    if (k === 'group') {
      tr.className = 'group';
      const td = tr.insertCell();
      td.colSpan = 2;
      td.textContent = v;
    } else {
      tr.dataset.figure = k;
      tr.insertCell().textContent = k;
      const td = tr.insertCell();
      td.className = 'value';
      td.textContent = v;
    }
  }
}

// The disparity colour scale, labelled in pixels above and in metres (Z = f·B/d) below.
function drawScale(s) {
  const signature = JSON.stringify(s) + colorScale.length;
  if (signature === scaleSignature) return;
  scaleSignature = signature;
  const c = $('disparity-scale');
  const g = c.getContext('2d');
  g.clearRect(0, 0, c.width, c.height);
  const x0 = 12, w = c.width - 24, y0 = 14, h = 12;
  for (let i = 0; i < w; i++) {
    const k = Math.min(255, Math.floor((256 * i) / w));
    const rgb = colorScale[k] || [k, k, k];
    g.fillStyle = `rgb(${rgb[0]},${rgb[1]},${rgb[2]})`;
    g.fillRect(x0 + i, y0, 1, h);
  }
  g.fillStyle = '#222';
  g.font = '10px sans-serif';
  g.textAlign = 'center';
  const ticks = 5;
  for (let t = 0; t <= ticks; t++) {
    const d = s.lo_px + ((s.hi_px - s.lo_px) * t) / ticks;
    const x = x0 + (w * t) / ticks;
    g.fillRect(x, y0 + h, 1, 3);
    g.fillText(`${d.toFixed(0)} px`, x, y0 - 3);
    const z = d > 0 && s.focal_length_px && s.baseline_mm ? (s.focal_length_px * s.baseline_mm) / d / 1000 : null;
    g.fillText(z === null ? '∞' : `${z.toFixed(z < 10 ? 1 : 0)} m`, x, y0 + h + 13);
  }
}

// ---- Cloud view (WebGL) --------------------------------------------------------------
const cloudView = (() => {
  const canvas = $('cloud');
  const gl = canvas.getContext('webgl', { antialias: false });
  let count = 0, lineCount = 0, yaw = -0.6, pitch = 0.45, distance = 14;
  let target = [0, 7, 0.8];
  if (!gl) {
    $('cloud-note').textContent = 'WebGL is not available in this browser: no 3D view.';
    return { setPoints() {} };
  }
  const vs = 'attribute vec3 p; attribute vec3 c; uniform mat4 m; varying vec3 v;' +
    'void main(){ gl_Position = m * vec4(p, 1.0); gl_PointSize = 2.0; v = c; }';
  const fs = 'precision mediump float; varying vec3 v; void main(){ gl_FragColor = vec4(v, 1.0); }';
  const shader = (type, src) => { const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s); return s; };
  const prog = gl.createProgram();
  gl.attachShader(prog, shader(gl.VERTEX_SHADER, vs));
  gl.attachShader(prog, shader(gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(prog);
  const aP = gl.getAttribLocation(prog, 'p'), aC = gl.getAttribLocation(prog, 'c'), uM = gl.getUniformLocation(prog, 'm');
  const points = { p: gl.createBuffer(), c: gl.createBuffer() };
  const lines = { p: gl.createBuffer(), c: gl.createBuffer() };
  // Ground grid every metre, and the axes (X red, Y green, Z blue) at the origin.
  const lp = [], lc = [];
  for (let x = -6; x <= 6; x++) { lp.push(x, 0, 0, x, 20, 0); lc.push(.3, .33, .4, .3, .33, .4); }
  for (let y = 0; y <= 20; y++) { lp.push(-6, y, 0, 6, y, 0); lc.push(.3, .33, .4, .3, .33, .4); }
  lp.push(0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1);
  lc.push(1, .2, .2, 1, .2, .2, .2, 1, .2, .2, 1, .2, .3, .5, 1, .3, .5, 1);
  gl.bindBuffer(gl.ARRAY_BUFFER, lines.p); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(lp), gl.STATIC_DRAW);
  gl.bindBuffer(gl.ARRAY_BUFFER, lines.c); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(lc), gl.STATIC_DRAW);
  lineCount = lp.length / 3;

  function matrix() {
    const aspect = canvas.width / canvas.height, f = 1 / Math.tan(0.45), n = 0.1, fa = 200;
    const eye = [target[0] + distance * Math.cos(pitch) * Math.sin(yaw), target[1] - distance * Math.cos(pitch) * Math.cos(yaw),
      target[2] + distance * Math.sin(pitch)];
    const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    const norm = (a) => { const l = Math.hypot(...a); return [a[0] / l, a[1] / l, a[2] / l]; };
    const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const zf = norm(sub(eye, target)), xs = norm(cross([0, 0, 1], zf)), ys = cross(zf, xs);
    const view = [xs[0], ys[0], zf[0], 0, xs[1], ys[1], zf[1], 0, xs[2], ys[2], zf[2], 0, -dot(xs, eye), -dot(ys, eye), -dot(zf, eye), 1];
    const proj = [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (fa + n) / (n - fa), -1, 0, 0, (2 * fa * n) / (n - fa), 0];
    const out = new Array(16).fill(0);
    for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) out[c * 4 + r] += proj[k * 4 + r] * view[c * 4 + k];
    return new Float32Array(out);
  }
  function bind(buffers) {
    gl.bindBuffer(gl.ARRAY_BUFFER, buffers.p); gl.enableVertexAttribArray(aP); gl.vertexAttribPointer(aP, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, buffers.c); gl.enableVertexAttribArray(aC); gl.vertexAttribPointer(aC, 3, gl.FLOAT, false, 0, 0);
  }
  function draw() {
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(0.06, 0.07, 0.1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(prog);
    gl.uniformMatrix4fv(uM, false, matrix());
    bind(lines); gl.drawArrays(gl.LINES, 0, lineCount);
    if (count) { bind(points); gl.drawArrays(gl.POINTS, 0, count); }
  }
  let dragging = null;
  canvas.addEventListener('mousedown', (e) => { dragging = [e.clientX, e.clientY]; });
  window.addEventListener('mouseup', () => { dragging = null; });
  window.addEventListener('mousemove', (e) => {
    if (!dragging) return;
    yaw += (e.clientX - dragging[0]) * 0.01;
    pitch = Math.max(-1.4, Math.min(1.4, pitch + (e.clientY - dragging[1]) * 0.01));
    dragging = [e.clientX, e.clientY];
    draw();
  });
  canvas.addEventListener('wheel', (e) => { e.preventDefault(); distance = Math.max(1, Math.min(80, distance * Math.exp(e.deltaY * 0.001))); draw(); }, { passive: false });
  draw();
  return {
    setPoints(xyz, frame) {
      count = xyz.length / 3;
      // Coloured by height in the ground frame (by range in the camera frame), with the
      // disparity's colour map: 0 .. 3 m.
      const colors = new Float32Array(xyz.length);
      for (let i = 0; i < count; i++) {
        const v = frame === 'ground' ? xyz[3 * i + 2] / 3 : xyz[3 * i + 2] / 20;
        const rgb = colorScale[Math.max(0, Math.min(255, Math.floor(v * 255)))] || [200, 200, 200];
        colors[3 * i] = rgb[0] / 255; colors[3 * i + 1] = rgb[1] / 255; colors[3 * i + 2] = rgb[2] / 255;
      }
      gl.bindBuffer(gl.ARRAY_BUFFER, points.p); gl.bufferData(gl.ARRAY_BUFFER, xyz, gl.DYNAMIC_DRAW);
      gl.bindBuffer(gl.ARRAY_BUFFER, points.c); gl.bufferData(gl.ARRAY_BUFFER, colors, gl.DYNAMIC_DRAW);
      $('cloud-note').textContent = `${count} points shown` + (frame === 'ground' ? ' (ground frame, m; colour: height 0–3 m)' : ' (camera frame: the rig has no ground transform)');
      draw();
    },
  };
})();

// ---- Buttons ----------------------------------------------------------------------
$('pause').addEventListener('click', () => send({ op: window.binocle.state && window.binocle.state.paused ? 'resume' : 'pause' }));
$('step').addEventListener('click', () => send({ op: 'step' }));
$('snapshot').addEventListener('click', () => send({ op: 'snapshot' }));
$('restart').addEventListener('click', () => send({ op: 'restart' }));
$('reset').addEventListener('click', () => send({ op: 'reset' }));

if (!token) {
  showMessage('This page needs the URL that `binocle view` printed at start (it carries a token).');
  setStatus('disconnected');
} else {
  connect();
}
