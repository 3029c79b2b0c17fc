// The 3D view: the model's triangles on a WebGPU canvas, coloured per receiver, with an orbit
// camera (drag to turn, wheel to zoom); over them, optionally, a per-point map's cells coloured
// per vertex (setOverlay). Its shader is shaders/viewer.wgsl (copied to pkg/). A click (a press
// and release without a drag) asks `onPick(receiver)` with the receiver of the nearest triangle
// under the pointer (−1: shading geometry or nothing).
import { GREY } from './colour.js';
import { isCut } from './insidemode.js';

const FLOATS_PER_VERTEX = 9; // position, normal, colour

export class Viewer {
  static async create(canvas) {
    const adapter = await navigator.gpu.requestAdapter();
    if (!adapter) throw new Error('no WebGPU adapter for the 3D view');
    const device = await adapter.requestDevice();
    const code = await (await fetch(new URL('./pkg/viewer.wgsl', import.meta.url))).text();
    return new Viewer(canvas, device, code);
  }

  constructor(canvas, device, code) {
    this.canvas = canvas;
    this.device = device;
    this.context = canvas.getContext('webgpu');
    this.format = navigator.gpu.getPreferredCanvasFormat();
    this.context.configure({ device, format: this.format, alphaMode: 'opaque' });
    const module = device.createShaderModule({ code });
    this.pipeline = device.createRenderPipeline({
      layout: 'auto',
      vertex: {
        module,
        entryPoint: 'vs_main',
        buffers: [{
          arrayStride: FLOATS_PER_VERTEX * 4,
          attributes: [
            { shaderLocation: 0, offset: 0, format: 'float32x3' },
            { shaderLocation: 1, offset: 12, format: 'float32x3' },
            { shaderLocation: 2, offset: 24, format: 'float32x3' },
          ],
        }],
      },
      fragment: { module, entryPoint: 'fs_main', targets: [{ format: this.format }] },
      primitive: { topology: 'triangle-list', cullMode: 'none' },
      depthStencil: { format: 'depth32float', depthWriteEnabled: true, depthCompare: 'less' },
    });
    this.uniform = device.createBuffer({ size: 80, usage: GPUBufferUsage.UNIFORM | GPUBufferUsage.COPY_DST });
    this.bind = device.createBindGroup({ layout: this.pipeline.getBindGroupLayout(0), entries: [{ binding: 0, resource: { buffer: this.uniform } }] });
    this.orbit = { yaw: -0.6, pitch: 0.5, distance: 50, target: [0, 0, 0] };
    /** Called with the receiver a click lands on (−1 for none). */
    this.onPick = null;
    this.vertices = null;
    this.count = 0;
    this.listen();
  }

  /** New geometry: 9 floats per triangle, and per triangle its receiver (−1: shading). */
  setModel(positions, receivers) {
    this.positions = positions;
    this.cut = null;
    this.receivers = receivers;
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < positions.length; i += 3) {
      for (let k = 0; k < 3; k++) {
        lo[k] = Math.min(lo[k], positions[i + k]);
        hi[k] = Math.max(hi[k], positions[i + k]);
      }
    }
    this.orbit.target = lo.map((l, k) => (l + hi[k]) / 2);
    this.orbit.distance = 1.6 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 10;
  }

  /** Cuts away the triangles beyond a plane ({ axis, side, at }: insidemode.js's cutOf), or
   * none with `null`: a roof or a wall taken off to see the rooms' floors. */
  setCut(cut) {
    this.cut = cut;
    if (this.colourOfReceiver) this.setColours(this.colourOfReceiver);
    // A map's cells on the faces cut away go with them: the overlay is written again.
    const [cells, colours] = [this.overlayCells, this.overlayColours];
    this.overlayCells = null;
    if (cells) this.setOverlay(cells, colours);
  }

  /** Colours per receiver (RGB 0..1); shading geometry stays grey. */
  setColours(colourOfReceiver) {
    const { positions, receivers } = this;
    if (!positions) return;
    this.colourOfReceiver = colourOfReceiver;
    const kept = [];
    for (let t = 0; t < receivers.length; t++) if (!isCut(this.cut, positions, 9 * t)) kept.push(t);
    this.canvas.dataset.triangles = String(kept.length);
    const data = new Float32Array(kept.length * 3 * FLOATS_PER_VERTEX);
    for (const [k, t] of kept.entries()) {
      const p = positions.subarray(9 * t, 9 * t + 9);
      const n = normal(p);
      const c = receivers[t] >= 0 ? colourOfReceiver(receivers[t]) : GREY;
      for (let v = 0; v < 3; v++) {
        data.set([p[3 * v], p[3 * v + 1], p[3 * v + 2], n[0], n[1], n[2], c[0], c[1], c[2]], (3 * k + v) * FLOATS_PER_VERTEX);
      }
    }
    this.base = data;
    this.upload();
  }

  /** Cells drawn over the model (a map: mapCells' positions and normals, mapColours' colours,
   * 3 floats per vertex each), or none with `null`. */
  setOverlay(cells, colours) {
    if (cells === this.overlayCells && colours === this.overlayColours) return;
    const n = cells ? cells.positions.length / 3 : 0;
    // A time slider's move: the same cells, new colours. Only the colours are written, in place,
    // and only the overlay's part of the vertex buffer is sent again.
    const recolour = cells && cells === this.overlayCells && this.overlay && this.vertices;
    if (!cells) this.overlay = null;
    else if (!recolour) this.overlay = new Float32Array(n * FLOATS_PER_VERTEX);
    const data = this.overlay;
    for (let v = 0; v < n; v++) {
      const at = v * FLOATS_PER_VERTEX;
      // A cut triangle's three corners all at its first: it keeps its place (a recolour writes
      // in place) and draws nothing.
      const from = this.cut && isCut(this.cut, cells.positions, 9 * Math.floor(v / 3)) ? 9 * Math.floor(v / 3) : 3 * v;
      for (let k = 0; k < 3; k++) {
        if (!recolour) {
          data[at + k] = cells.positions[from + k];
          data[at + 3 + k] = cells.normals[3 * v + k];
        }
        data[at + 6 + k] = colours[3 * v + k];
      }
    }
    this.overlayCells = cells;
    this.overlayColours = colours;
    if (!recolour) return this.upload();
    this.device.queue.writeBuffer(this.vertices, (this.base?.length ?? 0) * 4, data);
    this.draw();
  }

  upload() {
    const base = this.base ?? new Float32Array(0);
    const over = this.overlay ?? new Float32Array(0);
    const data = new Float32Array(base.length + over.length);
    data.set(base);
    data.set(over, base.length);
    this.vertices?.destroy();
    this.vertices = this.device.createBuffer({ size: Math.max(data.byteLength, 36), usage: GPUBufferUsage.VERTEX | GPUBufferUsage.COPY_DST });
    this.device.queue.writeBuffer(this.vertices, 0, data);
    this.count = data.length / FLOATS_PER_VERTEX;
    this.draw();
  }

  listen() {
    let last = null;
    let down = null;
    this.canvas.addEventListener('pointerdown', (e) => {
      last = [e.clientX, e.clientY];
      down = last;
      this.canvas.setPointerCapture(e.pointerId);
    });
    this.canvas.addEventListener('pointerup', (e) => {
      last = null;
      // A click, not the end of a turn: what lies under the pointer.
      if (down && Math.hypot(e.clientX - down[0], e.clientY - down[1]) < 4) this.onPick?.(this.pick(e.clientX, e.clientY));
      down = null;
    });
    this.canvas.addEventListener('pointermove', (e) => {
      if (!last) return;
      this.orbit.yaw -= (e.clientX - last[0]) * 0.008;
      this.orbit.pitch = Math.min(1.5, Math.max(-1.5, this.orbit.pitch + (e.clientY - last[1]) * 0.008));
      last = [e.clientX, e.clientY];
      this.draw();
    });
    this.canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.orbit.distance *= Math.exp(e.deltaY * 0.001);
      this.draw();
    }, { passive: false });
  }

  /** The camera's position, world axes. */
  eye() {
    const { yaw, pitch, distance, target } = this.orbit;
    return [
      target[0] + distance * Math.cos(pitch) * Math.sin(yaw),
      target[1] - distance * Math.cos(pitch) * Math.cos(yaw),
      target[2] + distance * Math.sin(pitch),
    ];
  }

  /** The receiver of the nearest triangle along the view ray through client point (x, y), −1
   * when that triangle is shading geometry or the ray meets none. */
  pick(x, y) {
    const { positions, receivers } = this;
    if (!positions) return -1;
    const rect = this.canvas.getBoundingClientRect();
    const eye = this.eye();
    const view = lookAt(eye, this.orbit.target, [0, 0, 1]);
    // The view matrix's rows are the camera's axes: right, up, and back (towards the eye).
    const axis = (r) => [view[r], view[4 + r], view[8 + r]];
    const [right, up, back] = [axis(0), axis(1), axis(2)];
    const half = Math.tan(FOV / 2);
    // The drawing's aspect (its pixels'), whatever size the page shows the canvas at.
    const sx = (2 * (x - rect.left) / rect.width - 1) * half * (this.canvas.width / this.canvas.height);
    const sy = (1 - 2 * (y - rect.top) / rect.height) * half;
    const ray = normalise([0, 1, 2].map((k) => sx * right[k] + sy * up[k] - back[k]));
    let best = Infinity;
    let hit = -1;
    for (let t = 0; t < receivers.length; t++) {
      if (isCut(this.cut, positions, 9 * t)) continue;
      const d = rayTriangle(eye, ray, positions, 9 * t);
      if (d < best) {
        best = d;
        hit = receivers[t];
      }
    }
    return hit;
  }

  draw() {
    if (!this.vertices) return;
    const { width, height } = this.canvas;
    if (!this.depth || this.depth.width !== width || this.depth.height !== height) {
      this.depth?.destroy();
      this.depth = this.device.createTexture({ size: [width, height], format: 'depth32float', usage: GPUTextureUsage.RENDER_ATTACHMENT });
    }
    const { distance } = this.orbit;
    const eye = this.eye();
    const viewProj = multiply(perspective(FOV, width / height, distance / 100, distance * 10), lookAt(eye, this.orbit.target, [0, 0, 1]));
    const light = normalise([0.4, -0.6, 0.7]);
    this.device.queue.writeBuffer(this.uniform, 0, new Float32Array([...viewProj, ...light, 0]));
    const encoder = this.device.createCommandEncoder();
    const pass = encoder.beginRenderPass({
      colorAttachments: [{ view: this.context.getCurrentTexture().createView(), loadOp: 'clear', storeOp: 'store', clearValue: { r: 0.96, g: 0.96, b: 0.95, a: 1 } }],
      depthStencilAttachment: { view: this.depth.createView(), depthLoadOp: 'clear', depthStoreOp: 'store', depthClearValue: 1 },
    });
    pass.setPipeline(this.pipeline);
    pass.setBindGroup(0, this.bind);
    pass.setVertexBuffer(0, this.vertices);
    pass.draw(this.count);
    pass.end();
    this.device.queue.submit([encoder.finish()]);
  }
}

/** The view's vertical field of view, radians. */
const FOV = 0.8;

/** Distance along unit `ray` from `origin` to the triangle at `p[at..at + 9]` (Möller–Trumbore),
 * Infinity when it misses. */
function rayTriangle(origin, ray, p, at) {
  const a = [p[at], p[at + 1], p[at + 2]];
  const e1 = [p[at + 3] - a[0], p[at + 4] - a[1], p[at + 5] - a[2]];
  const e2 = [p[at + 6] - a[0], p[at + 7] - a[1], p[at + 8] - a[2]];
  const cross = (u, v) => [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
  const dot = (u, v) => u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  const h = cross(ray, e2);
  const det = dot(e1, h);
  if (Math.abs(det) < 1e-12) return Infinity;
  const s = [origin[0] - a[0], origin[1] - a[1], origin[2] - a[2]];
  const u = dot(s, h) / det;
  if (u < 0 || u > 1) return Infinity;
  const q = cross(s, e1);
  const v = dot(ray, q) / det;
  if (v < 0 || u + v > 1) return Infinity;
  const t = dot(e2, q) / det;
  return t > 0 ? t : Infinity;
}

function normal(p) {
  const a = [p[3] - p[0], p[4] - p[1], p[5] - p[2]];
  const b = [p[6] - p[0], p[7] - p[1], p[8] - p[2]];
  return normalise([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]);
}

function normalise(v) {
  const l = Math.hypot(...v) || 1;
  return v.map((x) => x / l);
}

// Column-major 4×4 matrices, WebGPU clip depth 0..1.
function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, far / (near - far), -1, 0, 0, (near * far) / (near - far), 0];
}

function lookAt(eye, target, up) {
  const z = normalise(eye.map((e, i) => e - target[i]));
  const x = normalise([up[1] * z[2] - up[2] * z[1], up[2] * z[0] - up[0] * z[2], up[0] * z[1] - up[1] * z[0]]);
  const y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
}

function multiply(a, b) {
  const out = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) out[4 * c + r] += a[4 * k + r] * b[4 * c + k];
  return out;
}
