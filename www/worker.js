// The page's worker: holds the engine and the model, runs the year off the main thread, so the
// page stays responsive. Messages in: warm (make the engine now), load, loadBefore (the Study
// mode's existing scene), clearBefore, compute, map, mapFile, study, cancel, epw. Messages out:
// loaded, beforeLoaded, progress, notice, result, mapResult, mapFile, studyResult, epwLocation,
// error (with the error's `code`, and `gpu: true` when the device failed twice and a retry may
// help). Errors are told apart by their `code` (sunlit.d.ts, SunlitError), never by their message.
import { createEngine, epwLocation } from './sunlit.js';

let engine = null;
let model = null;
let files = null;
let loadOptions = null;
let running = null;
/** The Study mode's existing scene: its files, and the model read from them with the proposed
 * model's load options (read again, lazily, when the engine or those options change). */
let before = null;

/** Forgets the existing scene's model (not its files): it is read again when next needed. */
function dropBeforeModel() {
  before?.model?.free();
  if (before) before.model = null;
}

/** An engine being made: { options, promise }, so that a load arriving while the page's
 * warm-up still makes the engine waits for that one instead of making a second. */
let making = null;

const fits = (made, options) => made.resolution === options.resolution && made.engine === options.engine;

/** The engine for these options ({ resolution, engine }), made again when either changes. */
async function engineFor(options) {
  if (engine && fits(engine, options)) return engine;
  if (making && fits(making.options, options)) return making.promise;
  engine?.close();
  engine = null;
  model?.free();
  model = null;
  dropBeforeModel();
  const promise = createEngine(options).then(
    (made) => {
      // Superseded by other options while it was made: not the engine any more.
      if (making?.promise !== promise) {
        made.close();
        throw Object.assign(new Error('the engine was replaced'), { code: 'cancelled' });
      }
      making = null;
      engine = made;
      return made;
    },
    (error) => {
      if (making?.promise === promise) making = null;
      throw error;
    },
  );
  making = { options, promise };
  return promise;
}

/** Makes the engine (its GPU device, its clipping workers) before the first model arrives, while
 * the visitor picks one: the first year then waits for neither (docs/page-speed.md, "The first
 * visit"). A failure is said by the load that needs the engine, which tries again. */
function warm({ engine: options }) {
  engineFor(options).catch(() => {});
}

function modelOn(e) {
  if (!model) model = e.loadFiles(files, loadOptions);
  return model;
}

/** The existing scene on engine `e`, or null when none was chosen. */
function beforeOn(e) {
  if (!before) return null;
  if (!before.model) before.model = e.loadFiles(before.files, loadOptions);
  return before.model;
}

/** Codes after which the device cannot be trusted, but a new one may work. */
const GPU_FAILURES = new Set(['gpu', 'device-lost']);

function isGpuFailure(error) {
  return GPU_FAILURES.has(error?.code);
}

function fail(error, request) {
  const message = String(error?.message ?? error);
  const gpu = isGpuFailure(error);
  if (gpu) {
    // A lost or failed device cannot be reused; the next request makes a new one.
    engine?.close();
    engine = null;
    model = null;
    if (before) before.model = null;
  }
  postMessage({ type: 'error', request, message, code: error?.code, gpu, cancelled: error?.name === 'AbortError' });
}

async function load({ files: given, options, engine: made }) {
  const e = await engineFor(made);
  const bytes = given.reduce((sum, f) => sum + (f.bytes?.byteLength ?? 0), 0);
  postMessage({ type: 'loading', stage: 'parse', bytes });
  // Read first: a bad file leaves the last good model in place.
  const m = e.loadFiles(given, options);
  dropMapFiles();
  model?.free();
  model = m;
  files = given;
  loadOptions = options;
  // The existing scene is read with the proposed model's options: again, with these.
  dropBeforeModel();
  const positions = m.worldPositions();
  const receiversOf = m.worldReceivers();
  postMessage(
    {
      type: 'loaded',
      names: m.receiverNames,
      notes: m.notes,
      areas: m.receiverAreas,
      triangles: m.triangles,
      leaves: m.leaves,
      seeThrough: m.seeThroughTriangles,
      hasEnergyPlus: m.hasEnergyPlus,
      modelTimesteps: m.modelTimesteps,
      siteLocation: m.siteLocation,
      adapter: engine.adapter,
      positions,
      receivers: receiversOf,
    },
    [positions.buffer, receiversOf.buffer],
  );
  // The pool's workers build their own copies now, while the user sets up the year.
  if (e.workers) {
    postMessage({ type: 'loading', stage: 'workers', workers: e.workers });
    e.prepare(m).then(
      () => postMessage({ type: 'loading', stage: 'ready', workers: e.workers, poolError: e.poolError }),
      () => {}, // Said again, with its code, by the year that needs the pool.
    );
  }
}

/** A year; on a lost or failed device, once more on a new one (as the CLI does). */
async function compute(request) {
  try {
    return await computeOnce(request);
  } catch (error) {
    if (!isGpuFailure(error)) throw error;
    engine?.close();
    engine = null;
    model = null;
    postMessage({ type: 'notice', text: `The GPU device failed (${error.message}); counting again on a new one…` });
    return computeOnce(request);
  }
}

async function computeOnce({ settings, engine: made, csvName }) {
  if (!files) throw Object.assign(new Error('load a model first'), { code: 'no-model' });
  const e = await engineFor(made);
  const m = modelOn(e);
  running = new AbortController();
  const started = performance.now();
  let last = 0;
  const onProgress = (done, total, counted) => {
    const now = performance.now();
    if (now - last > 100 || done === total) {
      last = now;
      postMessage({ type: 'progress', done, total, counted });
    }
  };
  const annual = await e.annual(m, settings, { onProgress, signal: running.signal });
  try {
    const columns = annual.names.length;
    const values = new Float32Array(annual.rows * columns);
    for (let c = 0; c < columns; c++) values.set(annual.column(c), c * annual.rows);
    const { irradiation, unshaded, skyDiffuse, groundReflected, total, irradiationError } = energy(annual);
    const result = {
      type: 'result',
      names: annual.names,
      means: annual.means,
      irradiation,
      unshaded,
      skyDiffuse,
      groundReflected,
      total,
      irradiationError,
      rows: annual.rows,
      timestepsPerHour: annual.timestepsPerHour,
      values,
      csv: annual.csv(),
      ...hooked(annual, m.hasEnergyPlus, csvName),
      seconds: (performance.now() - started) / 1000,
      routing: e.routing,
      workers: e.workers,
      hasGpu: e.hasGpu,
      poolError: e.poolError,
    };
    postMessage(result, [values.buffer]);
  } finally {
    annual.free();
  }
}

/** The last map's files (engine.map's `files`), written only when the page downloads them, and
 * the map they belong to. */
let mapFiles = null;
let mapSerial = 0;

function dropMapFiles() {
  mapFiles?.files.free();
  mapFiles = null;
}

/** A per-point map (engine.map) of the loaded model; its typed arrays are transferred. `tag`
 * comes back unchanged (the page tells an instant's answer from a period's). Only what the view
 * draws is sent: the points CSV and the map glb are written when the page asks for them
 * (mapFile), so a time slider pays for neither on every move. */
async function map({ options, engine: made, tag }) {
  if (!files) throw Object.assign(new Error('load a model first'), { code: 'no-model' });
  const e = await engineFor(made);
  const m = modelOn(e);
  running = new AbortController();
  const started = performance.now();
  const onProgress = (done, total) => postMessage({ type: 'progress', done, total });
  const { files: kept, ...result } = await e.map(m, options, { onProgress, signal: running.signal, files: true });
  dropMapFiles();
  mapFiles = { files: kept, id: ++mapSerial };
  const buffers = [result.points, result.normals, result.receivers, result.values, result.sunHours, result.direct].filter(Boolean).map((a) => a.buffer);
  postMessage({ type: 'mapResult', tag, id: mapFiles.id, map: result, seconds: (performance.now() - started) / 1000 }, buffers);
}

/** The Study mode's existing scene: read now (a bad file is said at once and leaves the last
 * one), with the proposed model's load options. */
async function loadBefore({ files: given, engine: made }) {
  if (!files) throw Object.assign(new Error('load the proposed model first'), { code: 'no-model' });
  const e = await engineFor(made);
  const m = e.loadFiles(given, loadOptions);
  before?.model?.free();
  before = { files: given, model: m };
  postMessage({ type: 'beforeLoaded', receivers: m.receiverNames.length });
}

function clearBefore() {
  dropBeforeModel();
  before = null;
}

/** The window studies (engine.study) of the loaded model, and of the existing scene when one
 * was chosen: its tables, CSVs and report, all at once (a study is small: one point a window). */
async function study({ options, engine: made }) {
  if (!files) throw Object.assign(new Error('load a model first'), { code: 'no-model' });
  const e = await engineFor(made);
  const m = modelOn(e);
  const existing = beforeOn(e);
  const started = performance.now();
  const result = await e.study(m, existing ? { ...options, before: existing } : options);
  postMessage({ type: 'studyResult', study: result, seconds: (performance.now() - started) / 1000 });
}

/** The points CSV ('csv') or the map glb ('glb') of map `id`, as `sunlit map` writes them. */
function mapFile({ id, kind }) {
  if (!mapFiles || mapFiles.id !== id) {
    throw Object.assign(new Error('the map shown is no longer the last one mapped; map again to download it'), { code: 'freed' });
  }
  const data = kind === 'glb' ? mapFiles.files.glb() : mapFiles.files.csv();
  postMessage({ type: 'mapFile', id, kind, data }, kind === 'glb' ? [data.buffer] : []);
}

/** The EnergyPlus model with the CSV hooked in, or why it cannot be hooked (e.g. its Version is
 * too old): the year is counted either way, only the model's download needs the hook. */
function hooked(annual, hasEnergyPlus, csvName) {
  if (!hasEnergyPlus) return { hooked: null, hookError: undefined };
  try {
    return { hooked: annual.hookedModel(csvName), hookError: undefined };
  } catch (error) {
    return { hooked: null, hookError: String(error?.message ?? error) };
  }
}

/** The year's direct irradiation and its unshaded twin, sky diffuse, ground-reflected and total
 * (kWh/m²), all undefined without an EPW; an EPW whose hourly records are unreadable gives the
 * reason instead. */
function energy(annual) {
  try {
    return {
      irradiation: annual.irradiation,
      unshaded: annual.unshadedIrradiation,
      skyDiffuse: annual.skyDiffuse,
      groundReflected: annual.groundReflected,
      total: annual.total,
      irradiationError: undefined,
    };
  } catch (error) {
    return { irradiation: undefined, unshaded: undefined, skyDiffuse: undefined, groundReflected: undefined, total: undefined, irradiationError: String(error?.message ?? error) };
  }
}

/** An EPW's LOCATION, for the page's form. */
async function epw({ name, text }) {
  try {
    postMessage({ type: 'epwLocation', name, location: await epwLocation(text, name) });
  } catch (error) {
    postMessage({ type: 'epwLocation', name, location: null, message: String(error?.message ?? error) });
  }
}

onmessage = async ({ data }) => {
  if (data.type === 'cancel') {
    running?.abort();
    return;
  }
  try {
    if (data.type === 'load') await load(data);
    else if (data.type === 'compute') await compute(data);
    else if (data.type === 'map') await map(data);
    else if (data.type === 'mapFile') mapFile(data);
    else if (data.type === 'study') await study(data);
    else if (data.type === 'loadBefore') await loadBefore(data);
    else if (data.type === 'clearBefore') clearBefore();
    else if (data.type === 'epw') await epw(data);
    else if (data.type === 'warm') warm(data);
  } catch (error) {
    fail(error, data.type);
  } finally {
    if (data.type === 'compute' || data.type === 'map') running = null;
  }
};
/** Whether this browser offers a WebGPU adapter (navigator.gpu alone may offer none). */
async function webgpu() {
  try {
    return !!(await self.navigator?.gpu?.requestAdapter());
  } catch {
    return false;
  }
}
postMessage({ type: 'ready', webgpu: await webgpu() });
