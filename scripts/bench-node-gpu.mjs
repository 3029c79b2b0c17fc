// One year of a model through the page's JS API (www/sunlit.js and the wasm bundle in www/pkg)
// under Node, on Dawn's WebGPU (npm `webgpu`; tests/node/dawn.mjs stands in for the browser):
//   node scripts/bench-node-gpu.mjs MODEL.glb [DAYSxPERDAY] [RESOLUTION] [--engine gpu|compute|exact|auto]
//     [--timesteps N] [--refine T] [--csv OUT.csv]
// (`--refine T` as the CLI's; without it the API's default, as the page runs.) Prints one JSON
// line: the Vulkan driver and adapter Dawn chose, seconds for the engine's start (the module's
// import, the wasm's compile, the GPU device), the model's load and the year, and the views
// counted. The engine runs in this thread and clips in this thread too: Node has no Web Workers,
// so the page's pool cannot start (pool_error says so), which only matters for views routed to
// clipping (`exact`, and `auto`'s light views). Run by scripts/bench-node-gpu.sh beside the
// native CLI's same year.
import { readFileSync, writeFileSync } from 'node:fs';
import { basename } from 'node:path';
import { parseArgs } from 'node:util';
import { bundleMissing, findDriver, installDawn } from '../tests/node/dawn.mjs';

const { values: opts, positionals } = parseArgs({
  allowPositionals: true,
  options: { engine: { type: 'string', default: 'gpu' }, timesteps: { type: 'string', default: '4' }, refine: { type: 'string' }, csv: { type: 'string' } },
});
const engineName = opts.engine;
const timesteps = Number(opts.timesteps);
const [model, samples = '27x19', resolution = '512'] = positionals;
if (!model) {
  console.error('usage: node scripts/bench-node-gpu.mjs MODEL.glb [DAYSxPERDAY] [RESOLUTION] [--engine gpu|compute|exact|auto] [--timesteps N] [--refine T] [--csv OUT.csv]');
  process.exit(2);
}
const missing = bundleMissing();
if (missing) {
  console.error(`bench-node-gpu: ${missing}`);
  process.exit(2);
}
const [days, perDay] = samples.split('x').map(Number);
const place = { latitude: 39.74, longitude: -105.18, timeZone: -7 };

const driver = findDriver();
if (!driver.name) {
  console.error(`bench-node-gpu: Dawn found no Vulkan adapter: ${JSON.stringify(driver.refused)}`);
  process.exit(3);
}
const uninstall = await installDawn(driver);
const t0 = performance.now();
const { createEngine } = await import('../www/sunlit.js');
const engine = await createEngine({ resolution: Number(resolution), engine: engineName });
const t1 = performance.now();
const bytes = readFileSync(model);
const t2 = performance.now();
const loaded = engine.loadFiles([{ name: basename(model), bytes }]);
const t3 = performance.now();
let views = 0;
let stage = null;
const settings = { ...place, timestepsPerHour: timesteps, daysPerYear: days, samplesPerDay: perDay };
if (opts.refine !== undefined) settings.refine = Number(opts.refine);
const year = await engine.annual(loaded, settings, {
  onProgress: (done, total, counted) => {
    // Views an engine counted, summed over the year's stages (a new stage: another total, or
    // fewer done), as scripts/bench-web.mjs counts them.
    if (stage && (total !== stage.total || done < stage.done)) views += stage.counted ?? 0;
    stage = { total, done, counted };
  },
});
const t4 = performance.now();
views += stage?.counted ?? 0;
if (opts.csv) writeFileSync(opts.csv, year.csv());
console.log(
  JSON.stringify({
    side: `node-dawn-${engineName}`,
    model: basename(model),
    samples,
    resolution: Number(resolution),
    timesteps,
    driver: driver.name,
    adapter: engine.adapter,
    has_gpu: engine.hasGpu,
    engine: engine.engine,
    pool_error: engine.poolError,
    node: process.version,
    create_s: (t1 - t0) / 1000,
    load_s: (t3 - t2) / 1000,
    annual_s: (t4 - t3) / 1000,
    total_s: (t4 - t0) / 1000,
    views,
    receivers: year.names.length,
    triangles: loaded.triangles,
  }),
);
engine.close();
uninstall();
