// sunlit's JavaScript API: sunlit fractions of building surfaces on the browser's WebGPU.
// Types and documentation: sunlit.d.ts. Example: api-example.html.
//
// Wraps the wasm-bindgen bindings (pkg/sunlit_wasm.js, built by scripts/build-web.sh) so that
// callers get one init, plain-object settings, AbortSignal cancellation and sun angles.
import init, { Engine, epwLocation as wasmEpwLocation } from './pkg/sunlit_wasm.js';
import { onDevice } from './device.js';

let wasmReady;

/** Loads the wasm module once (later calls share it). */
function ready() {
  wasmReady ??= init({ module_or_path: new URL('./pkg/sunlit_wasm_bg.wasm', import.meta.url) });
  return wasmReady;
}

/** Bytes of the wasm linear memory (grows, never shrinks): what a leak would show in. */
export async function wasmMemoryBytes() {
  const exports = await ready();
  return exports.memory.buffer.byteLength;
}

/** Whether this browser (or worker) offers WebGPU at all. */
export function hasWebGPU() {
  return typeof navigator !== 'undefined' && !!navigator.gpu;
}

/** Unit vector towards the sun (x east, y north, z up) from azimuth (degrees clockwise from
 * north) and altitude (degrees above the horizon). */
export function sunDirection(azimuth, altitude) {
  const a = (azimuth * Math.PI) / 180;
  const h = (altitude * Math.PI) / 180;
  return [Math.sin(a) * Math.cos(h), Math.cos(a) * Math.cos(h), Math.sin(h)];
}

/** An Error with a `code` (and what it names), as the wasm side throws them (sunlit.d.ts). */
function coded(message, code, names = {}) {
  return Object.assign(new Error(message), { code }, names);
}

/** Opens the GPU device (or uses `device`, a GPUDevice the caller holds and keeps).
 * `engine`: 'auto' (default), 'gpu' or 'exact' (sunlit.d.ts). Rejects with code 'no-webgpu'
 * where WebGPU is missing, 'bad-option' (option 'engine') for another engine name. */
export async function createEngine({ resolution, accuracy, device, engine } = {}) {
  if (!hasWebGPU()) {
    throw coded('This browser offers no WebGPU (try a current Chrome or Edge, or enable WebGPU).', 'no-webgpu');
  }
  await ready();
  const open = () => Engine.create(resolution, accuracy, engine === undefined ? undefined : String(engine));
  return new SunlitEngine(device === undefined ? await open() : await onDevice(device, open));
}

/** An EPW's LOCATION record: { latitude, longitude, timeZone, elevation, name }. */
export async function epwLocation(text, name = 'EPW') {
  await ready();
  return wasmEpwLocation(String(name), String(text));
}

function toBytes(bytes, name) {
  if (bytes instanceof Uint8Array) return bytes;
  if (bytes instanceof ArrayBuffer) return new Uint8Array(bytes);
  if (ArrayBuffer.isView(bytes)) return new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  throw coded(`${name}: bytes must be a Uint8Array or ArrayBuffer`, 'bad-option', { file: name, option: 'bytes' });
}

function abortError() {
  return new DOMException('cancelled', 'AbortError');
}

class SunlitEngine {
  #engine;

  constructor(engine) {
    this.#engine = engine;
  }

  /** The GPU adapter in use. */
  get adapter() {
    return this.#engine.adapter;
  }

  /** Pixels along a view's side. */
  get resolution() {
    return this.#engine.resolution;
  }

  /** Which engine answers views: 'auto', 'gpu' or 'exact'. */
  get engine() {
    return this.#engine.engine;
  }

  /** A model from files: [{ name, bytes }]; glb, gltf (+ its .bin files), IDF or epJSON. */
  loadFiles(files, { receivers = '', north = 0, foliage = '', transmittance = '' } = {}) {
    const names = files.map((f) => String(f.name));
    const contents = files.map((f) => toBytes(f.bytes, f.name));
    return this.#engine.loadFiles(names, contents, receivers, north, foliage, transmittance);
  }

  /** A model from typed arrays (see sunlit.d.ts). */
  fromArrays({ positions, indices, triangleReceivers, names, yUp = false }) {
    return this.#engine.fromArrays(
      Float32Array.from(positions),
      Uint32Array.from(indices),
      Int32Array.from(triangleReceivers),
      names.map(String),
      !!yUp,
    );
  }

  /** A model from meshes and their placements (instancing kept; see sunlit.d.ts, and three.js). */
  fromMeshes({ positions, vertexStarts, indices, indexStarts, placementMeshes, matrices, names, receivers, yUp = false }) {
    return this.#engine.fromMeshes(
      Float32Array.from(positions),
      Uint32Array.from(vertexStarts),
      Uint32Array.from(indices),
      Uint32Array.from(indexStarts),
      Uint32Array.from(placementMeshes),
      Float64Array.from(matrices),
      names.map(String),
      Uint8Array.from(receivers, (r) => (r ? 1 : 0)),
      !!yUp,
    );
  }

  /** Every receiver's sunlit fraction for one sun: [x, y, z] or { azimuth, altitude }. */
  async fractions(model, sun) {
    const [x, y, z] = Array.isArray(sun) ? sun : sunDirection(sun.azimuth, sun.altitude);
    return this.#engine.fractions(model, x, y, z);
  }

  /** The year's schedule. Rejects with an AbortError when `signal` aborts. */
  async annual(model, settings, { onProgress, signal } = {}) {
    if (signal?.aborted) throw abortError();
    try {
      return await this.#engine.annual(model, settings, onProgress, signal);
    } catch (error) {
      if (signal?.aborted && error?.code === 'cancelled') throw abortError();
      throw error;
    }
  }

  /** Per-point values on the receivers (sunlit.d.ts, MapOptions): a plain object of typed arrays
   * (points, normals, receivers, values; transferable to and from a worker) and its legend; with
   * `csv` / `glb` true, also the points CSV (text) and the map glb (bytes) as `sunlit map` writes
   * them. Rejects with an AbortError when `signal` aborts. */
  async map(model, options, { onProgress, signal, csv = false, glb = false } = {}) {
    if (signal?.aborted) throw abortError();
    let map;
    try {
      map = await this.#engine.map(model, options, onProgress, signal);
    } catch (error) {
      if (signal?.aborted && error?.code === 'cancelled') throw abortError();
      throw error;
    }
    try {
      return {
        value: map.value,
        title: map.title,
        unit: map.unit,
        spacing: map.spacing,
        instants: map.instants,
        points: map.points,
        normals: map.normals,
        receivers: map.receivers,
        values: map.values,
        sunHours: map.sunHours,
        direct: map.direct,
        min: map.min,
        max: map.max,
        receiverNames: model.receiverNames,
        csv: csv ? map.csv() : undefined,
        glb: glb ? map.glb() : undefined,
      };
    } finally {
      map.free();
    }
  }
}
