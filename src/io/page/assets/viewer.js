// proxseg's 3D page (io/view_page.hpp): a point cloud with its layers (scene colours, labels,
// instances, recognised objects), a legend, picking and the recognised objects' boxes and axes,
// in plain WebGL. The page embeds this script, its data (#proxseg-meta, JSON) and the points
// (#proxseg-points: base64 of zlib-deflated planes, laid out by meta.arrays). No network.
"use strict";
(function () {
  const started = performance.now();
  const meta = JSON.parse(document.getElementById("proxseg-meta").textContent);
  // firstDrawMs: from this script's start; openedMs: from the navigation's start (what a user
  // waits, the page's parsing included).
  const api = { meta, firstDrawMs: null, openedMs: null, errors: [] };
  window.proxsegView = api;
  let resolveReady, rejectReady, resolveMoving;
  api.ready = new Promise((ok, fail) => ((resolveReady = ok), (rejectReady = fail)));
  // How the page draws while the view moves (planMoving): { step, fullFrameMs }.
  api.moving = new Promise((ok) => (resolveMoving = ok));

  // ---- small matrix helpers (column-major 4x4, as WebGL takes them) ----
  const M = {
    mul(a, b) {
      const o = new Float32Array(16);
      for (let c = 0; c < 4; ++c)
        for (let r = 0; r < 4; ++r) {
          let s = 0;
          for (let k = 0; k < 4; ++k) s += a[k * 4 + r] * b[c * 4 + k];
          o[c * 4 + r] = s;
        }
      return o;
    },
    perspective(fovy, aspect, near, far) {
      const f = 1 / Math.tan(fovy / 2), o = new Float32Array(16);
      o[0] = f / aspect;
      o[5] = f;
      o[10] = (far + near) / (near - far);
      o[11] = -1;
      o[14] = (2 * far * near) / (near - far);
      return o;
    },
    lookAt(eye, at, up) {
      const z = norm(sub(eye, at)), x = norm(cross(up, z)), y = cross(z, x);
      return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
        -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
    },
  };
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
    a[0] * b[1] - a[1] * b[0]];
  const norm = (a) => scale(a, 1 / (Math.hypot(a[0], a[1], a[2]) || 1));

  // ---- the data: base64 -> inflate -> planes ----
  async function inflate(id) {
    const text = document.getElementById(id).textContent.trim();
    const bin = atob(text);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }
  // A uint16 array stored as its low-byte plane then its high-byte plane.
  function planes16(blob, [offset, n]) {
    const out = new Uint16Array(n);
    for (let i = 0; i < n; ++i) out[i] = blob[offset + i] | (blob[offset + n + i] << 8);
    return out;
  }
  // Positions: per axis, uint16 steps from the previous point (mod 2^16) of the quantised
  // coordinate, min + q * step metres.
  function positions(blob) {
    const n = meta.points, out = new Float32Array(3 * n);
    for (let a = 0; a < 3; ++a) {
      const d = planes16(blob, meta.arrays.position[a]);
      let q = 0;
      for (let i = 0; i < n; ++i) {
        q = (q + d[i]) & 0xffff;
        out[3 * i + a] = meta.bounds.min[a] + q * meta.bounds.step[a];
      }
    }
    return out;
  }

  // ---- WebGL ----
  const canvas = document.getElementById("view");
  const gl = canvas.getContext("webgl", { antialias: false, preserveDrawingBuffer: true });
  if (!gl) {
    document.getElementById("notes").textContent = "This browser has no WebGL: the 3D view is off.";
    rejectReady(new Error("no WebGL"));
    return;
  }
  function program(vs, fs) {
    const p = gl.createProgram();
    for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
      const s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      gl.attachShader(p, s);
    }
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    return p;
  }
  // Points: the highlighted id (> 0) keeps its colour, the others fade.
  const pointsProgram = program(`
    attribute vec3 position; attribute vec3 colour; attribute float id;
    uniform mat4 mvp; uniform float size; uniform float highlight;
    varying vec3 v_colour;
    void main() {
      gl_Position = mvp * vec4(position, 1.0);
      gl_PointSize = max(1.0, size / gl_Position.w);
      bool other = highlight > 0.0 && abs(id - highlight) > 0.5;
      v_colour = other ? colour * 0.3 + vec3(0.05) : colour;
    }`, `
    precision mediump float; varying vec3 v_colour;
    void main() { gl_FragColor = vec4(v_colour, 1.0); }`);
  const linesProgram = program(`
    attribute vec3 position; attribute vec3 colour; uniform mat4 mvp; varying vec3 v_colour;
    void main() { gl_Position = mvp * vec4(position, 1.0); v_colour = colour; }`, `
    precision mediump float; varying vec3 v_colour;
    void main() { gl_FragColor = vec4(v_colour, 1.0); }`);

  const state = {
    layer: null, highlight: 0, xyz: null, ids: {}, colours: {}, lines: null, lineCount: 0,
    target: [0, 0, 1], distance: 1, yaw: 0, pitch: 0, pan: [0, 0, 0], home: null,
  };
  const buffers = { position: gl.createBuffer(), colour: gl.createBuffer(), id: gl.createBuffer(),
    lines: gl.createBuffer() };

  function layerOf(key) { return meta.layers.find((l) => l.key === key); }

  // Per-point colours of a layer: the scene's own, or each id's legend colour (0 = grey).
  function layerColours(layer) {
    if (layer.key === "colour") return state.colours.scene;
    const ids = state.ids[layer.key], table = new Map();
    for (const e of layer.legend) table.set(e.id, e.colour);
    const out = new Uint8Array(3 * ids.length);
    for (let i = 0; i < ids.length; ++i) {
      const c = ids[i] ? table.get(ids[i]) : null;
      out.set(c || [60, 60, 60], 3 * i);
    }
    return out;
  }

  function setLayer(key) {
    const layer = layerOf(key);
    if (!layer) throw new Error("no layer " + key);
    state.layer = layer;
    state.highlight = 0;
    gl.bindBuffer(gl.ARRAY_BUFFER, buffers.colour);
    gl.bufferData(gl.ARRAY_BUFFER, layerColours(layer), gl.STATIC_DRAW);
    const ids = state.ids[layer.idsFrom || layer.key] || new Uint16Array(meta.points);
    gl.bindBuffer(gl.ARRAY_BUFFER, buffers.id);
    gl.bufferData(gl.ARRAY_BUFFER, ids, gl.STATIC_DRAW);
    for (const input of document.querySelectorAll("#layers input"))
      input.checked = input.value === key;
    showLegend(layer);
    draw();
  }

  // ---- camera: orbit about a target, pan, zoom ----
  function eye() {
    const cp = Math.cos(state.pitch), dir = [Math.sin(state.yaw) * cp, -Math.sin(state.pitch),
      Math.cos(state.yaw) * cp];
    return sub(add(state.target, state.pan), scale(dir, state.distance));
  }
  // The camera's frame: the image's y points down, as the sensor's does.
  function view() {
    return M.lookAt(eye(), add(state.target, state.pan), [0, -1, 0]);
  }
  function mvp() {
    const aspect = canvas.width / canvas.height;
    const near = Math.max(1e-3, state.distance * 0.01), far = state.distance * 20 + 10;
    return M.mul(M.perspective(Math.PI / 4, aspect, near, far), view());
  }
  function resetView() {
    Object.assign(state, JSON.parse(JSON.stringify(state.home)));
    draw();
  }

  function resize() {
    const r = canvas.getBoundingClientRect(), dpr = window.devicePixelRatio || 1;
    canvas.width = Math.max(1, Math.round(r.width * dpr));
    canvas.height = Math.max(1, Math.round(r.height * dpr));
    draw();
  }

  // ---- while the view moves: every step-th point, when all of them would not keep up ----
  // A frame of all the points is timed once after the first draw (the quicker of two, as the first
  // frames pay for warming up; reading a pixel back waits for a frame's end);
  // when it takes longer than MOVING_FRAME_MS (software WebGL, or many points on a small GPU),
  // turning, moving and zooming draw every step-th point, a little larger, through an index
  // buffer, and all of them again once the view rests for REST_MS.
  const MOVING_FRAME_MS = 30, REST_MS = 150;
  const moving = { step: 1, count: 0, indices: null, now: false, timer: 0, fullFrameMs: null,
    drawn: [] };
  function planMoving() {
    for (let k = 0; k < 2; ++k) {
      const t0 = performance.now();
      render();
      finishFrame();
      moving.fullFrameMs = Math.min(moving.fullFrameMs ?? Infinity, performance.now() - t0);
    }
    const step = Math.ceil(moving.fullFrameMs / MOVING_FRAME_MS);
    if (step >= 2 && gl.getExtension("OES_element_index_uint")) {
      moving.step = step;
      moving.count = Math.ceil(meta.points / step);
      const indices = new Uint32Array(moving.count);
      for (let i = 0; i < moving.count; ++i) indices[i] = i * step;
      moving.indices = gl.createBuffer();
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, moving.indices);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
      const notes = document.getElementById("notes");
      notes.textContent = [notes.textContent, `While the view moves every ${step}th point is drawn` +
        ` (all ${meta.points.toLocaleString("en")} take ${Math.round(moving.fullFrameMs)} ms a frame` +
        " in this browser)."].filter(Boolean).join(" ");
    }
    resolveMoving({ step: moving.step, fullFrameMs: moving.fullFrameMs });
  }
  function startMoving() {
    if (!moving.indices) return;
    moving.now = true;
    clearTimeout(moving.timer);
    moving.timer = setTimeout(() => ((moving.now = false), draw()), REST_MS);
  }
  function finishFrame() {
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  }

  let pending = false;
  function draw() {
    if (pending || !state.xyz) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      render();
    });
  }
  function attribute(prog, name, buffer, size, type, normalized) {
    const loc = gl.getAttribLocation(prog, name);
    gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, size, type, normalized, 0, 0);
    return loc;
  }
  function render() {
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(0.07, 0.07, 0.09, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    const m = mvp();
    gl.useProgram(pointsProgram);
    const locs = [attribute(pointsProgram, "position", buffers.position, 3, gl.FLOAT, false),
      attribute(pointsProgram, "colour", buffers.colour, 3, gl.UNSIGNED_BYTE, true),
      attribute(pointsProgram, "id", buffers.id, 1, gl.UNSIGNED_SHORT, false)];
    gl.uniformMatrix4fv(gl.getUniformLocation(pointsProgram, "mvp"), false, m);
    const fewer = moving.now && moving.indices;
    gl.uniform1f(gl.getUniformLocation(pointsProgram, "size"), (canvas.height / 480) * 2.5 *
      Number(document.getElementById("size").value) * (fewer ? Math.min(2, Math.sqrt(moving.step)) : 1));
    gl.uniform1f(gl.getUniformLocation(pointsProgram, "highlight"), state.highlight);
    if (fewer) {
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, moving.indices);
      gl.drawElements(gl.POINTS, moving.count, gl.UNSIGNED_INT, 0);
    } else {
      gl.drawArrays(gl.POINTS, 0, meta.points);
    }
    if (moving.drawn.length < 1000) moving.drawn.push(fewer ? moving.count : meta.points);
    for (const l of locs) gl.disableVertexAttribArray(l);
    if (state.lineCount && document.getElementById("boxes").checked) {
      gl.useProgram(linesProgram);
      const stride = 24;
      const loc = gl.getAttribLocation(linesProgram, "position");
      const col = gl.getAttribLocation(linesProgram, "colour");
      gl.bindBuffer(gl.ARRAY_BUFFER, buffers.lines);
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, stride, 0);
      gl.enableVertexAttribArray(col);
      gl.vertexAttribPointer(col, 3, gl.FLOAT, false, stride, 12);
      gl.uniformMatrix4fv(gl.getUniformLocation(linesProgram, "mvp"), false, m);
      gl.drawArrays(gl.LINES, 0, state.lineCount);
      gl.disableVertexAttribArray(loc);
      gl.disableVertexAttribArray(col);
    }
    if (api.firstDrawMs === null) {
      finishFrame();
      api.openedMs = performance.now();
      api.firstDrawMs = api.openedMs - started;
      resolveReady(api);
      requestAnimationFrame(planMoving);
    }
  }

  // ---- the recognised objects: oriented box and axes at the estimated pose ----
  function objectLines() {
    const v = [];
    const push = (p, c) => v.push(p[0], p[1], p[2], c[0] / 255, c[1] / 255, c[2] / 255);
    for (const o of meta.objects || []) {
      if (!o.box) continue;
      const { centre, axes, extent } = o.box;  // axes as rows: axes[k] is the k-th axis
      const corner = (sx, sy, sz) => add(centre, add(scale(axes[0], sx * extent[0] / 2),
        add(scale(axes[1], sy * extent[1] / 2), scale(axes[2], sz * extent[2] / 2))));
      const c = o.colour || [255, 255, 255];
      for (const [a, b] of [[[-1, -1, -1], [1, -1, -1]], [[-1, 1, -1], [1, 1, -1]],
        [[-1, -1, 1], [1, -1, 1]], [[-1, 1, 1], [1, 1, 1]], [[-1, -1, -1], [-1, 1, -1]],
        [[1, -1, -1], [1, 1, -1]], [[-1, -1, 1], [-1, 1, 1]], [[1, -1, 1], [1, 1, 1]],
        [[-1, -1, -1], [-1, -1, 1]], [[1, -1, -1], [1, -1, 1]], [[-1, 1, -1], [-1, 1, 1]],
        [[1, 1, -1], [1, 1, 1]]]) {
        push(corner(...a), c);
        push(corner(...b), c);
      }
      if (o.pose) {  // the model's axes at the pose: x red, y green, z blue
        const t = [o.pose[0][3], o.pose[1][3], o.pose[2][3]];
        const len = Math.max(...extent) * 0.6;
        [[255, 60, 60], [60, 255, 60], [80, 140, 255]].forEach((colour, k) => {
          push(t, colour);
          push(add(t, scale([o.pose[0][k], o.pose[1][k], o.pose[2][k]], len)), colour);
        });
      }
    }
    return new Float32Array(v);
  }

  // ---- legend, picking, information ----
  const fmt = (x, d = 3) => (typeof x === "number" ? x.toFixed(d) : x === undefined ? "" : String(x));
  function showLegend(layer) {
    const list = document.getElementById("legend");
    list.textContent = "";
    document.getElementById("legend-title").textContent = layer.title;
    for (const e of layer.legend || []) {
      const li = document.createElement("li");
      li.dataset.id = e.id;
      const sw = document.createElement("span");
      sw.className = "swatch";
      sw.style.background = `rgb(${e.colour.join(",")})`;
      const text = document.createElement("span");
      text.textContent = `${e.id}  ${e.name || ""}${e.score !== undefined ? "  " + fmt(e.score) : ""}`;
      li.append(sw, text);
      li.addEventListener("mouseenter", () => highlight(e.id));
      li.addEventListener("mouseleave", () => highlight(0));
      li.addEventListener("click", () => showInfo(e.id));
      list.append(li);
    }
  }
  function highlight(id) {
    if (state.highlight === id) return;
    state.highlight = id;
    for (const li of document.querySelectorAll("#legend li"))
      li.classList.toggle("on", Number(li.dataset.id) === id);
    draw();
  }
  // The point drawn nearest the viewer within 6 pixels of (x, y) (CSS pixels in the canvas), or -1.
  function pickIndex(x, y) {
    const m = mvp(), r = canvas.getBoundingClientRect(), xyz = state.xyz;
    const px = (x / r.width) * 2 - 1, py = 1 - (y / r.height) * 2;
    const tol = (6 / r.width) * 2, toly = (6 / r.height) * 2;
    let best = -1, bestZ = Infinity;
    for (let i = 0; i < meta.points; ++i) {
      const X = xyz[3 * i], Y = xyz[3 * i + 1], Z = xyz[3 * i + 2];
      const w = m[3] * X + m[7] * Y + m[11] * Z + m[15];
      if (w <= 0) continue;
      const sx = (m[0] * X + m[4] * Y + m[8] * Z + m[12]) / w;
      if (Math.abs(sx - px) > tol) continue;
      const sy = (m[1] * X + m[5] * Y + m[9] * Z + m[13]) / w;
      if (Math.abs(sy - py) > toly) continue;
      if (w < bestZ) (bestZ = w), (best = i);
    }
    return best;
  }
  function idAt(index) {
    const ids = state.ids[state.layer.idsFrom || state.layer.key];
    return index >= 0 && ids ? ids[index] : 0;
  }
  function entryOf(id) {
    return (state.layer.legend || []).find((e) => e.id === id);
  }
  function showInfo(id) {
    const box = document.getElementById("info");
    const e = entryOf(id);
    if (!e) {
      box.textContent = id ? `id ${id}` : "nothing here";
      return null;
    }
    const rows = [["id", e.id], ["name", e.name], ["score", fmt(e.score)], ["fitness", fmt(e.fitness)],
      ["coverage", fmt(e.coverage)], ["points", e.points]].filter((r) => r[1] !== undefined && r[1] !== "");
    box.textContent = "";
    const table = document.createElement("table");
    for (const [k, v] of rows) table.insertRow().append(cell(k, "th"), cell(String(v)));
    if (e.pose) {
      const pose = e.pose.map((r) => r.map((x) => fmt(x, 3)).join("  ")).join("\n");
      table.insertRow().append(cell("pose", "th"), cell(pose, "td", "pose"));
    }
    box.append(table);
    return e;
  }
  function cell(text, tag = "td", cls = "") {
    const c = document.createElement(tag);
    c.textContent = text;
    if (cls) c.className = cls;
    return c;
  }

  // ---- mouse and keys ----
  let drag = null, moved = false;
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("mousedown", (e) => {
    drag = { x: e.clientX, y: e.clientY, pan: e.button !== 0 || e.shiftKey };
    moved = false;
  });
  window.addEventListener("mouseup", (e) => {
    if (drag && !moved && e.target === canvas) {
      const r = canvas.getBoundingClientRect();
      showInfo(idAt(pickIndex(e.clientX - r.left, e.clientY - r.top)));
    }
    drag = null;
  });
  let hoverQueued = null;
  window.addEventListener("mousemove", (e) => {
    if (!drag) {
      if (e.target !== canvas) return;
      const r = canvas.getBoundingClientRect();
      if (!hoverQueued) requestAnimationFrame(() => {
        highlight(idAt(pickIndex(hoverQueued[0], hoverQueued[1])));
        hoverQueued = null;
      });
      hoverQueued = [e.clientX - r.left, e.clientY - r.top];
      return;
    }
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (Math.abs(dx) + Math.abs(dy) > 2) moved = true;
    drag.x = e.clientX;
    drag.y = e.clientY;
    if (drag.pan) {
      const v = view(), k = state.distance * 0.0015;
      const right = [v[0], v[4], v[8]], up = [v[1], v[5], v[9]];
      state.pan = add(state.pan, add(scale(right, -dx * k), scale(up, dy * k)));
    } else {
      state.yaw -= dx * 0.005;
      state.pitch = Math.max(-1.5, Math.min(1.5, state.pitch + dy * 0.005));
    }
    startMoving();
    draw();
  });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    state.distance *= Math.exp(e.deltaY * 0.001);
    startMoving();
    draw();
  }, { passive: false });
  window.addEventListener("keydown", (e) => {
    if (e.key === "r") resetView();
    const n = Number(e.key);
    if (n >= 1 && n <= meta.layers.length) setLayer(meta.layers[n - 1].key);
  });
  window.addEventListener("resize", resize);

  // ---- start ----
  async function start() {
    document.title = "proxseg: " + meta.title;
    document.getElementById("title").textContent = meta.title;
    document.getElementById("notes").textContent = (meta.notes || []).join(" ");
    const blob = await inflate("proxseg-points");
    state.xyz = positions(blob);
    const [offset, n] = meta.arrays.colour;
    const rgb = new Uint8Array(3 * n);
    for (let i = 0; i < n; ++i)
      for (let c = 0; c < 3; ++c) rgb[3 * i + c] = blob[offset + c * n + i];
    state.colours.scene = rgb;
    for (const layer of meta.layers)
      if (meta.arrays[layer.key]) state.ids[layer.key] = planes16(blob, meta.arrays[layer.key]);
    gl.bindBuffer(gl.ARRAY_BUFFER, buffers.position);
    gl.bufferData(gl.ARRAY_BUFFER, state.xyz, gl.STATIC_DRAW);
    const lines = objectLines();
    state.lineCount = lines.length / 6;
    gl.bindBuffer(gl.ARRAY_BUFFER, buffers.lines);
    gl.bufferData(gl.ARRAY_BUFFER, lines, gl.STATIC_DRAW);
    // Seen from the sensor, about the cloud's middle.
    state.target = meta.view.target;
    state.distance = meta.view.distance;
    state.home = { target: state.target, distance: state.distance, yaw: 0, pitch: 0, pan: [0, 0, 0] };
    const layers = document.getElementById("layers");
    meta.layers.forEach((l, k) => {
      const label = document.createElement("label");
      const input = document.createElement("input");
      Object.assign(input, { type: "radio", name: "layer", value: l.key });
      input.addEventListener("change", () => setLayer(l.key));
      label.append(input, ` ${l.title} (${k + 1})`);
      layers.append(label);
    });
    document.getElementById("reset").addEventListener("click", resetView);
    document.getElementById("boxes").addEventListener("change", draw);
    document.getElementById("size").addEventListener("input", draw);
    setLayer(meta.default_layer || meta.layers[0].key);
    resize();
  }

  // ---- for tests and scripts ----
  Object.assign(api, {
    layers: () => meta.layers.map((l) => l.key),
    setLayer,
    legend: () => (state.layer.legend || []).map((e) => ({ id: e.id, name: e.name })),
    highlighted: () => state.highlight,
    // The CSS pixel of point i in the canvas, or null when it is behind the camera.
    screenOf(i) {
      const m = mvp(), r = canvas.getBoundingClientRect(), p = state.xyz.subarray(3 * i, 3 * i + 3);
      const w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
      if (w <= 0) return null;
      const sx = (m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12]) / w;
      const sy = (m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13]) / w;
      return [r.left + ((sx + 1) / 2) * r.width, r.top + ((1 - sy) / 2) * r.height];
    },
    // A point of id in the current layer that is drawn in front (none hides it), or -1.
    visiblePointOf(id) {
      const ids = state.ids[state.layer.idsFrom || state.layer.key], r = canvas.getBoundingClientRect();
      for (let i = 0; i < meta.points; i += 7) {
        if (ids[i] !== id) continue;
        const s = api.screenOf(i);
        if (!s) continue;
        if (idAt(pickIndex(s[0] - r.left, s[1] - r.top)) === id) return i;
      }
      return -1;
    },
    info: () => document.getElementById("info").textContent,
    // Mean milliseconds per frame over n frames of a turn about the cloud, each waited for:
    // how fluid turning is, with all the points (whileMoving false) or as the page draws them
    // while the view moves.
    orbitMs(n, whileMoving = false) {
      const yaw = state.yaw, t0 = performance.now();
      moving.now = whileMoving && !!moving.indices;
      for (let k = 0; k < n; ++k) {
        state.yaw = yaw + (2 * Math.PI * (k + 1)) / n;
        render();
        finishFrame();
      }
      moving.now = false;
      state.yaw = yaw;
      draw();
      return (performance.now() - t0) / n;
    },
    // The points each frame drew since the last call.
    drawnPoints: () => moving.drawn.splice(0),
  });

  start().catch((e) => {
    api.errors.push(String(e));
    document.getElementById("notes").textContent = "Could not show the cloud: " + e;
    rejectReady(e);
  });
})();
