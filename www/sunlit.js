// sunlit's JavaScript API: sunlit fractions of building surfaces on the browser's WebGPU.
// Types and documentation: sunlit.d.ts. Example: api-example.html.
//
// Wraps the wasm-bindgen bindings (pkg/sunlit_wasm.js, built by scripts/build-web.sh) so that
// callers get one init, plain-object settings, AbortSignal cancellation and sun angles.
import init, { Engine, epwLocation as wasmEpwLocation, exactIndexesBuilt } from './pkg/sunlit_wasm.js';
import { onDevice } from './device.js';
import { ClipPool, DEFAULT_MEMORY_BUDGET, defaultWorkers, wasmModule } from './pool.js';
import { cachedProfile, storeProfile, warmProfiles } from './profiles.js';

let wasmReady;

/** Starts this thread's wasm instance once (later calls share it), from the module the pool's
 * workers are given too (pool.js, `wasmModule`). */
function ready() {
  wasmReady ??= wasmModule().then((module) => init({ module_or_path: module }));
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

/** Opens the GPU device (or uses `device`, a GPUDevice the caller holds and keeps) and starts
 * the pool of clipping workers. `engine`: 'auto' (default), 'gpu', 'exact' or 'compute' (pixels
 * on WebGPU by the compute rasterizer); `workers`: the
 * pool's size (default navigator.hardwareConcurrency; 0 clips in this thread); `profile`: an
 * `auto` profile (JSON text or object, as `year.profile` gives it) to route the sun views by
 * instead of the cached or measured one (sunlit.d.ts); `skyProfile`: the same for the sky views
 * (as `year.skyProfile` gives it), which are routed by their own profile as natively. Without
 * WebGPU the engine still clips (`hasGpu` false);
 * only `engine: 'gpu'` or 'compute' is refused there, with code 'no-webgpu'. 'bad-option' (naming the option)
 * for another engine name or pool size. */
export async function createEngine({ resolution, accuracy, device, engine, workers, profile, skyProfile, memoryBudget } = {}) {
  const size = workers === undefined ? defaultWorkers() : Number(workers);
  if (!Number.isInteger(size) || size < 0) {
    throw coded(`workers: ${workers} is not a whole number of at least 0`, 'bad-option', { option: 'workers' });
  }
  const budget = memoryBudget === undefined ? DEFAULT_MEMORY_BUDGET : Number(memoryBudget);
  if (!(budget > 0) || !Number.isFinite(budget)) {
    throw coded(`memoryBudget: ${memoryBudget} is not a positive number of bytes`, 'bad-option', { option: 'memoryBudget' });
  }
  // The engines that count on WebGPU alone.
  const wantsGpu = engine !== undefined && ['gpu', 'compute'].includes(String(engine).trim().toLowerCase());
  const noGpu = () =>
    coded(
      "This browser offers no WebGPU, so the GPU engine is missing (try a current Chrome or Edge, or enable WebGPU); engine 'auto' or 'exact' clips without it.",
      'no-webgpu',
      { option: 'engine' },
    );
  if (device === undefined && !hasWebGPU() && wantsGpu) throw noGpu();
  // The pool's workers start now (each compiles the wasm and starts its instance), while this
  // thread starts its own and opens the GPU device: a first visit waits for the slower of the
  // two, not their sum (docs/page-speed.md, "The first visit"). A worker that cannot start is
  // said by the first call that needs the pool (#routing), which then clips in this thread.
  const started = performance.now();
  const since = () => Math.round(performance.now() - started);
  const timings = {};
  // The profiles' store opens now, beside the wasm's compile: a first year otherwise waits for
  // the database to be made (docs/page-speed.md, "The first visit").
  if (engine === undefined || String(engine).trim().toLowerCase() === 'auto') warmProfiles();
  const pool = size > 0 ? new ClipPool(size) : null;
  pool?.start().then(
    () => (timings.workersReady = since()),
    () => {},
  );
  ready().then(
    () => (timings.wasm ??= since()),
    () => {},
  );
  let made;
  try {
    made = await openEngine({ resolution, accuracy, device, engine, wantsGpu, noGpu });
  } catch (error) {
    pool?.terminate();
    throw error;
  }
  const text = (p) => (p === undefined || p === null ? undefined : typeof p === 'string' ? p : JSON.stringify(p));
  timings.engine = since();
  return new SunlitEngine(made, pool, { sun: text(profile), sky: text(skyProfile) }, budget, timings, since);
}

/** The wasm engine on `device`, on a device of its own, or clipping only where there is none. */
async function openEngine({ resolution, accuracy, device, engine, wantsGpu, noGpu }) {
  await ready();
  const open = (gpu) => () => Engine.create(resolution, accuracy, engine === undefined ? undefined : String(engine), gpu);
  // The caller's device is taken at once (the engine otherwise opens its device on the first
  // view routed to the GPU), while onDevice's adapter stands in and its error handler is chained.
  if (device !== undefined) return onDevice(device, () => open(true)().then(async (made) => (await made.openDevice(), made)));
  if (!hasWebGPU()) return open(false)();
  try {
    return await open(true)();
  } catch (error) {
    // WebGPU present but no adapter (a blocklisted GPU, flags off): clip without it.
    if (error?.gpu !== 'no-adapter') throw error;
    if (wantsGpu) throw noGpu();
    return open(false)();
  }
}

/** An EPW's LOCATION record: { latitude, longitude, timeZone, elevation, name }. */
export async function epwLocation(text, name = 'EPW') {
  await ready();
  return wasmEpwLocation(String(name), String(text));
}

/** Model files above this many bytes cannot be read within wasm32's 4 GiB: an instance keeps
 * its peak (wasm memory never shrinks): the file's bytes, the parsed scene, the GPU upload's
 * staging and the exact engine's index. Measured on nyt-blocks' 95 MB glb (docs/page-speed.md):
 * 1,568 MB in the engine's instance under `auto` (16.5×), 1,253 MB in each clipping worker. */
const MEMORY_PER_BYTE = 17;
const WASM32_BYTES = 4 * 2 ** 30;
const MAX_MODEL_BYTES = Math.floor(WASM32_BYTES / MEMORY_PER_BYTE);

/** The largest model files (bytes in all) a page reads: wasm32's 4 GiB over the memory a read
 * takes per byte of file (an estimate; see MEMORY_PER_BYTE). */
export const maxModelBytes = MAX_MODEL_BYTES;

/** Refuses model files of `bytes` in all (code 'too-large', naming the files and their size)
 * before any is read: a page can check a chosen file's size before reading it into memory. */
export function checkModelSize(names, bytes) {
  if (bytes > MAX_MODEL_BYTES) throw tooLarge(names.map(String), bytes);
}

function tooLarge(names, bytes, cause) {
  const mb = (bytes / 1e6).toFixed(1);
  const why = cause ? ` (reading it ran out of memory: ${cause.message})` : ` (the limit is about ${(MAX_MODEL_BYTES / 1e6).toFixed(0)} MB)`;
  return coded(
    `${names.join(', ')}: ${mb} MB of model files do not fit in this page's memory: wasm32 addresses 4 GiB, and reading a model needs about ${MEMORY_PER_BYTE}× its size${why}. Use the native CLI for this model.`,
    'too-large',
    { file: names[0], bytes },
  );
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

/** Each model's source for the pool's workers: its scene and its exact engine's convex objects,
 * encoded when the pool first needs them (Model.sceneBytes, then Model.objectsBytes, which
 * builds this instance's exact engine), so a worker decodes the scene instead of reading the
 * model files again, and takes the objects instead of grouping the triangles itself, the step
 * that set its peak memory (docs/page-speed.md). Nothing of the model's input (a glb's bytes) is
 * kept for it. */
const sources = new WeakMap();

function remember(model) {
  sources.set(model, { kind: 'scene', encode: () => [model.sceneBytes(), model.objectsBytes()] });
  return model;
}

class SunlitEngine {
  #engine;
  #pool;
  #pinned;
  #routed = null;
  #poolError = null;
  #budget;
  /** Workers asked for, and the model source the pool last took (a pool shrunk by the budget for
   * one model starts afresh at its asked size for the next). */
  #asked;
  #pooled = null;
  /** Each pool load watched once (its failure and its end are kept). */
  #watched = new WeakSet();
  #timings;
  #since;

  constructor(engine, pool, pinned, budget, timings, since) {
    this.#timings = timings;
    this.#since = since;
    this.#engine = engine;
    this.#pool = pool;
    this.#pinned = pinned;
    this.#budget = budget;
    this.#asked = pool?.size ?? 0;
  }

  /** Whether the engine holds a WebGPU adapter: false where the browser has no WebGPU (views are
   * clipped), and with engine 'exact', which never draws and asks for none. */
  get hasGpu() {
    return this.#engine.hasGpu;
  }

  /** Clipping workers in the pool (0: clipping runs in this thread). */
  get workers() {
    return this.#pool?.size ?? 0;
  }

  /** How the last `auto` run routed its sun views: { key, profile (JSON), source ('pinned',
   * 'cache', 'probe'), refused (why a profile handed in was not used), sky (the same for its sky
   * views, under their own key; null for a year without weather) }, or null before one. */
  get routing() {
    return this.#routed;
  }

  /** The wasm memory (bytes) each clipping worker holds once it built the model: its copy's
   * cost (docs/page-speed.md). Empty without a pool. */
  get workerMemoryBytes() {
    return this.#pool?.memoryBytes ?? [];
  }

  /** How the memory budget sized the pool for the last model ({ budgetBytes, engineBytes,
   * workerBytes, asked, workers }: fewer workers than asked where a copy of the model would not
   * fit, 0 clipping in this thread), or null before a model reached the pool. */
  get poolSizing() {
    return this.#pool?.sizing ?? null;
  }

  /** Why the pool could not start (clipping then runs in this thread), or null. */
  get poolError() {
    return this.#poolError;
  }

  /** Has the pool's workers build their copies of `model` now, and resolves when they hold it
   * (a year does not wait for them: this thread clips until they do). */
  async prepare(model) {
    await this.#routing(model);
    const source = sources.get(model);
    if (!this.#pool || !source || this.#pooled !== source) return;
    await this.#pool.use(source).catch((error) => {
      // Workers that cannot start are not fatal: this thread clips (`poolError` says why).
      if (error?.workerCode !== 'start') throw error;
    });
  }

  /** Milliseconds from `createEngine` to each step of a first visit: `wasm` (this thread's
   * instance started), `engine` (the adapter found: `createEngine` resolves), `workersReady`
   * (every clipping worker started its instance), `encoded` (the first model encoded for the
   * workers), `workersHold` (every worker built its copy), `yearStarted` and `yearCounted` (the
   * last year's counting began, its model encoded and its profile looked up, and ended, before
   * its profile is stored); `clipped`: views clipped in this thread (`here`) and by the
   * workers so far; and `indexesBuilt`: exact engines (indexes of a model) this thread's wasm
   * instance has built, one a model however it is used (docs/page-speed.md, "The first
   * visit"). */
  get timings() {
    return { ...this.#timings, clipped: this.#pool?.clipped ?? { here: 0, workers: 0 }, indexesBuilt: exactIndexesBuilt() };
  }

  /** Stops the pool's workers; the engine then clips in this thread. */
  close() {
    this.#pool?.terminate();
    this.#pool = null;
  }

  /** The pool and profile for a call on `model` (see src/web/choice.rs, Routing). The call does
   * not wait for the workers to hold the model: this thread clips until they do (pool.js,
   * `clip`), so a first visit's year starts at once. */
  async #routing(model, signal) {
    const source = sources.get(model);
    // A pool closed by a failed worker (its error went to the call that hit it) starts afresh.
    if (this.#pool?.broken) this.#pool = new ClipPool(this.#asked);
    // A pool the budget shrank for another model starts afresh for this one.
    if (this.#pool && source && source !== this.#pooled && this.#pool.size < this.#asked) {
      this.#pool.terminate();
      this.#pool = new ClipPool(this.#asked);
    }
    if (this.#pool && source) await this.#hand(this.#pool, source);
    // The budget left no worker: this thread clips, as with `workers: 0`.
    const pool = source && this.#pool?.size > 0 ? this.#pool : null;
    // This thread clips too, with the copy of the model its instance holds anyway
    // (Model.clipHere): until the workers hold the model, and throughout where the budget kept
    // fewer workers than asked (one clipper more for no memory).
    const local = pool ? (packed) => model.clipHere(packed) : null;
    const sizing = pool?.sizing;
    const workers = (pool?.size ?? 1) + (sizing && sizing.workers < sizing.asked ? 1 : 0);
    const auto = this.engine === 'auto';
    // Sun and sky views each have their own profile, kept under their own key (the sky's says
    // `sky views`), so a sun profile is never taken for a sky one (src/web/choice.rs).
    const key = auto ? { sun: this.#engine.profileKey(model, workers), sky: this.#engine.skyProfileKey(model, workers) } : undefined;
    const given = async (views) => {
      if (this.#pinned[views] !== undefined) return [this.#pinned[views], 'pinned'];
      return [key === undefined ? undefined : await cachedProfile(key[views]), 'cache'];
    };
    const [[profile, profileSource], [skyProfile, skyProfileSource]] = await Promise.all([given('sun'), given('sky')]);
    const routing = { workers, profile, profileSource, skyProfile, skyProfileSource };
    if (pool) routing.clip = (packed) => pool.clip(packed, signal, local);
    return { routing, key };
  }

  /** Hands `source` to `pool` (once per model); resolves once the pool is sized by the memory
   * budget, not when its workers hold the model. A pool whose workers cannot start (a CSP, a
   * missing module) is dropped, and why is kept in `poolError`: this thread clips instead. */
  async #hand(pool, source) {
    this.#pooled = source;
    const loading = pool.use(source, { bytes: this.#budget, used: wasmMemoryBytes });
    if (this.#watched.has(loading)) return pool.sized;
    this.#watched.add(loading);
    loading.then(
      () => (this.#timings.workersHold = this.#since()),
      (error) => {
        if (this.#pooled === source) this.#pooled = null;
        if (error?.workerCode !== 'start' || this.#pool !== pool) return;
        this.#poolError = error.message;
        this.#pool = null;
      },
    );
    await pool.sized;
    this.#timings.encoded = this.#since();
  }

  /** Keeps what `auto` routed by, and caches each freshly measured profile under its key. */
  async #keepRouting(year, key) {
    if (key === undefined || year.profile === undefined) return;
    const sky = year.skyProfile === undefined ? null : { key: key.sky, profile: year.skyProfile, source: year.skyProfileSource, refused: year.skyProfileRefused };
    this.#routed = { key: key.sun, profile: year.profile, source: year.profileSource, refused: year.profileRefused, sky };
    if (year.profileSource === 'probe') await storeProfile(key.sun, year.profile);
    if (sky?.source === 'probe') await storeProfile(key.sky, sky.profile);
  }

  /** The GPU adapter in use ('exact' asks for none). */
  get adapter() {
    return this.#engine.adapter;
  }

  /** Pixels along a view's side. */
  get resolution() {
    return this.#engine.resolution;
  }

  /** Which engine answers views: 'auto', 'gpu', 'exact' or 'compute'. */
  get engine() {
    return this.#engine.engine;
  }

  /** A model from files: [{ name, bytes }]; glb, gltf (+ its .bin files), IDF or epJSON. */
  loadFiles(files, { receivers = '', north = 0, foliage = '', transmittance = '' } = {}) {
    const names = files.map((f) => String(f.name));
    const contents = files.map((f) => toBytes(f.bytes, f.name));
    const bytes = contents.reduce((sum, c) => sum + c.byteLength, 0);
    checkModelSize(names, bytes);
    let model;
    try {
      model = this.#engine.loadFiles(names, contents, receivers, north, foliage, transmittance);
    } catch (error) {
      // wasm32 addresses 4 GiB; an allocation past it traps (a RuntimeError) rather than throws.
      if (error instanceof WebAssembly.RuntimeError) throw tooLarge(names, bytes, error);
      throw error;
    }
    return remember(model);
  }

  /** A model from typed arrays (see sunlit.d.ts). */
  fromArrays({ positions, indices, triangleReceivers, names, yUp = false }) {
    const args = [Float32Array.from(positions), Uint32Array.from(indices), Int32Array.from(triangleReceivers), names.map(String), !!yUp];
    return remember(this.#engine.fromArrays(...args));
  }

  /** A model from meshes and their placements (instancing kept; see sunlit.d.ts, and three.js). */
  fromMeshes({ positions, vertexStarts, indices, indexStarts, placementMeshes, matrices, names, receivers, yUp = false }) {
    const args = [
      Float32Array.from(positions),
      Uint32Array.from(vertexStarts),
      Uint32Array.from(indices),
      Uint32Array.from(indexStarts),
      Uint32Array.from(placementMeshes),
      Float64Array.from(matrices),
      names.map(String),
      Uint8Array.from(receivers, (r) => (r ? 1 : 0)),
      !!yUp,
    ];
    return remember(this.#engine.fromMeshes(...args));
  }

  /** Every receiver's sunlit fraction for one sun: [x, y, z] or { azimuth, altitude }. */
  async fractions(model, sun) {
    const [x, y, z] = Array.isArray(sun) ? sun : sunDirection(sun.azimuth, sun.altitude);
    const { routing } = await this.#routing(model);
    return this.#engine.fractions(model, x, y, z, routing);
  }

  /** The year's schedule. Rejects with an AbortError when `signal` aborts. */
  async annual(model, settings, { onProgress, signal } = {}) {
    if (signal?.aborted) throw abortError();
    try {
      const { routing, key } = await this.#routing(model, signal);
      if (signal?.aborted) throw coded('cancelled', 'cancelled');
      this.#timings.yearStarted = this.#since();
      const year = await this.#engine.annual(model, settings, onProgress, signal, routing);
      this.#timings.yearCounted = this.#since();
      await this.#keepRouting(year, key);
      return year;
    } catch (error) {
      if (signal?.aborted && error?.code === 'cancelled') throw abortError();
      throw error;
    }
  }

  /** Per-point values on the receivers (sunlit.d.ts, MapOptions): a plain object of typed arrays
   * (points, normals, receivers, values; transferable to and from a worker) and its legend; with
   * `csv` / `glb` true, also the points CSV (text) and the map glb (bytes) as `sunlit map` writes
   * them; with `files` true, `files`: the same two on demand (`csv()`, `glb()`) until `free()`, so
   * a caller that only draws the map (a time slider) pays for the files only when they are asked
   * for. Rejects with an AbortError when `signal` aborts. */
  async map(model, options, { onProgress, signal, csv = false, glb = false, files = false } = {}) {
    if (signal?.aborted) throw abortError();
    let map;
    try {
      map = await this.#engine.map(model, options, onProgress, signal);
    } catch (error) {
      if (signal?.aborted && error?.code === 'cancelled') throw abortError();
      throw error;
    }
    let answer;
    try {
      answer = {
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
        skyDiffuse: map.skyDiffuse,
        groundReflected: map.groundReflected,
        total: map.total,
        skyViewFactor: map.skyViewFactor,
        min: map.min,
        max: map.max,
        receiverNames: map.insideNames ?? model.receiverNames,
        ...insideOf(map),
        csv: csv ? map.csv() : undefined,
        glb: glb ? map.glb() : undefined,
        files: files ? mapFiles(map) : undefined,
      };
    } catch (error) {
      map.free();
      throw error;
    }
    if (!files) map.free();
    return answer;
  }

  /** The window studies (sunlit.d.ts, StudyOptions) on `model`: a plain object of typed arrays
   * (points, normals, receivers), the tables (values and pass/fail per point) and per study the
   * CSV `sunlit map --study` writes, the HTML report and the sky masks asked for; with
   * `options.before` (a Model) on the existing scene too. The studies are the library's;
   * nothing is decided here. */
  async study(model, options) {
    // The existing scene is a model, not JSON: it goes to the wasm call beside the options.
    const { before, ...rest } = options ?? {};
    const study = before ? this.#engine.studyBeforeAfter(model, before, rest) : this.#engine.study(model, options);
    try {
      const { points, normals, receivers, tables, masks } = JSON.parse(study.json());
      return {
        points: Float32Array.from(points),
        normals: Float32Array.from(normals),
        receivers: Uint32Array.from(receivers),
        tables,
        csv: Object.fromEntries(tables.map((t) => [t.study, study.csv(t.study)])),
        html: study.html(),
        masks: Object.fromEntries(masks),
      };
    } finally {
      study.free();
    }
  }
}

/** An inside map's own fields (`inside: true`): at an instant the glass's weights per point and
 * the sun patches, for a study each room's share; none for a map outside. */
function insideOf(map) {
  const [patches, areas] = [map.patches, map.areas];
  if (areas !== undefined) return { areas: JSON.parse(areas) };
  if (patches === undefined) return {};
  return { solarTransmittance: map.solarTransmittance, visibleTransmittance: map.visibleTransmittance, patches: JSON.parse(patches) };
}

/** A map's files on demand: the wasm map is kept (its values in full precision, as the CLI writes
 * them) until `free()`; after it, asking throws with code 'freed'. */
function mapFiles(map) {
  let kept = map;
  const held = () => {
    if (!kept) throw coded("this map's files were freed; map again to get them", 'freed');
    return kept;
  };
  return {
    csv: () => held().csv(),
    glb: () => held().glb(),
    free() {
      kept?.free();
      kept = null;
    },
  };
}
