// sunlit/worker: the engine in a module Web Worker, so a viewer's main thread stays free.
// Start it with `new Worker(new URL('sunlit/worker', import.meta.url), { type: 'module' })` (or a
// bundler's worker import) and post requests; each gets one reply with the same `id`:
//   { id, op: 'create', options }                  → { id, result: { adapter, resolution } }
//   { id, op: 'fromMeshes', input }                → { id, result: { names, areas } }   (fromThree's arrays)
//   { id, op: 'loadFiles', files, options }        → { id, result: { names, areas } }
//   { id, op: 'fractions', sun }                   → { id, result: Float64Array }
//   { id, op: 'annual', settings }                 → { id, result: { names, means, irradiation, csv } }
//   { id, op: 'map', options, csv, glb }           → { id, result: SunlitMap }  (engine.map's typed arrays, transferred)
//   { id, op: 'cancel' }                           → aborts a running annual or map
// Errors come back as { id, error: message, code }; progress of an annual as { id, progress: [done, total, counted] }.
// The engine clips on its own pool of workers and routes `auto` by a measured profile, as
// createEngine does anywhere (create's options take `workers`, `profile` and `skyProfile` too).
import { createEngine } from './sunlit.js';

let engine = null;
let model = null;
let running = null;

function replaceModel(next) {
  model?.free();
  model = next;
  return { names: next.receiverNames, areas: next.receiverAreas };
}

const ops = {
  async create({ options }) {
    engine?.close();
    engine = await createEngine(options ?? {});
    return { adapter: engine.adapter, resolution: engine.resolution };
  },
  fromMeshes: ({ input }) => replaceModel(need(engine, 'create').fromMeshes(input)),
  loadFiles: ({ files, options }) => replaceModel(need(engine, 'create').loadFiles(files, options)),
  fractions: ({ sun }) => need(engine, 'create').fractions(need(model, 'fromMeshes or loadFiles'), sun),
  async annual({ id, settings }) {
    running = new AbortController();
    const onProgress = (done, total, counted) => postMessage({ id, progress: [done, total, counted] });
    const year = await need(engine, 'create').annual(need(model, 'fromMeshes or loadFiles'), settings, { onProgress, signal: running.signal });
    try {
      return { names: year.names, means: year.means, irradiation: year.irradiation, csv: year.csv(), profile: year.profile, profileSource: year.profileSource, skyProfile: year.skyProfile, skyProfileSource: year.skyProfileSource };
    } finally {
      year.free();
    }
  },
};

/** engine.map's answer, its arrays moved (not copied) to the caller. */
async function map({ id, options, csv, glb }) {
  running = new AbortController();
  const onProgress = (done, total) => postMessage({ id, progress: [done, total] });
  const result = await need(engine, 'create').map(need(model, 'fromMeshes or loadFiles'), options, { onProgress, signal: running.signal, csv, glb });
  const arrays = [result.points, result.normals, result.receivers, result.values, result.sunHours, result.direct, result.glb];
  return transfer(result, arrays.filter(Boolean).map((a) => a.buffer));
}

const transfers = new WeakMap();

function transfer(result, buffers) {
  transfers.set(result, buffers);
  return result;
}

ops.map = map;

function need(value, step) {
  if (!value) throw new Error(`sunlit worker: call '${step}' first`);
  return value;
}

onmessage = async ({ data }) => {
  if (data?.op === 'cancel') return running?.abort();
  const op = ops[data?.op];
  try {
    if (!op) throw new Error(`sunlit worker: unknown op '${data?.op}' (create, fromMeshes, loadFiles, fractions, annual, map, cancel)`);
    const result = await op(data);
    postMessage({ id: data.id, result }, transfers.get(result) ?? []);
  } catch (error) {
    postMessage({ id: data?.id, error: String(error?.message ?? error), code: error?.code });
  }
};
