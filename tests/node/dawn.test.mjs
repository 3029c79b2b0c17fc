// The wasm bundle and the JS API (www/sunlit.js) under Node on Dawn's WebGPU (npm `webgpu`,
// Chromium's WebGPU implementation): a year of the example office counted by the GPU engine and
// by the exact engine through `createEngine` / `loadFiles` / `annual`, each CSV against the native
// CLI's exact CSV of the same year. The exact engine's CSV must be the CLI's byte for byte (the
// same code on f64, compiled to wasm); the GPU engine's within the raster kernel's stated bound.
//
// What this covers of the page's path (tests/node/dawn.mjs says what is stood in for): the
// bundle as scripts/build-web.sh builds it, sunlit.js's engine, model and year calls, wgpu's
// WebGPU backend and the WGSL shaders on Dawn (Tint compiling them, Dawn's validation, its
// buffer mapping), the engine's own thread. Not covered: the page's DOM and its engine Web Worker
// (www/worker.js), the pool of clipping workers (Node has no Web Workers: the pool fails to start
// and the engine clips in its own thread, asserted below), IndexedDB's profile cache.
//
// Vulkan drivers: Dawn (webgpu 0.6.2) refuses Debian 12's lavapipe (Mesa 22.3.6) with "Vulkan
// shaderUniform*ArrayDynamicIndexing required.", so on this project's machines it runs on
// Chromium's SwiftShader, found through its ICD file (installed with Debian's chromium, which
// scripts/test.sh sets up). The test skips, saying why, only where Dawn finds no Vulkan adapter
// on any driver; anything else failing fails it.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, bundleMissing, findDriver, installDawn } from './dawn.mjs';

const EXAMPLE = join(ROOT, 'examples/office.glb');
// `refine: 1` interpolates every timestep between the samples (no refinement views): 252 views, so
// that SwiftShader, a CPU rasterizer, counts them in seconds; the spline year is the same code.
const YEAR = { latitude: 39.74, longitude: -105.18, timeZone: -7, timestepsPerHour: 1, daysPerYear: 6, samplesPerDay: 9, refine: 1 };
const RESOLUTION = 512;
/** The raster kernel's bound against the exact reference at 512² (README, "GPU pixels vs exact
 * clipping": max |error| 0.00062 over 288 random views; issue 32's target: every kernel within
 * 0.001 of the exact reference). */
const GPU_BOUND = 0.001;

const driver = findDriver();
const noDriver = driver.name
  ? false
  : `Dawn found no Vulkan adapter on any driver: ${driver.refused.map((r) => `${r.name}: ${r.said.replace(/\s*\n\s*/g, ' ')}`).join('; ')}`;
if (noDriver) console.log(`tests/node/dawn.test.mjs skipped: ${noDriver}`);

let work;
let uninstall;
let api;
let nativeCsv;

before(async () => {
  if (noDriver) return;
  const missing = bundleMissing();
  if (missing) throw new Error(missing);
  console.log(`Dawn on ${driver.name}: ${JSON.stringify(driver.info)}${driver.refused.map((r) => `; refused first: ${r.name}: ${r.said.replace(/\s*\n\s*/g, ' ')}`).join('')}`);
  work = mkdtempSync(join(tmpdir(), 'sunlit-dawn-'));
  uninstall = await installDawn(driver);
  api = await import('../../www/sunlit.js');
  nativeCsv = native();
});

after(() => {
  uninstall?.();
  if (work) rmSync(work, { recursive: true, force: true });
});

/** The native CLI's exact year of the same model and settings. */
function native() {
  const out = join(work, 'native.csv');
  execFileSync(join(ROOT, 'target/debug/sunlit'), ['annual', EXAMPLE, '--engine', 'exact',
    '--location', `${YEAR.latitude},${YEAR.longitude},${YEAR.timeZone}`, '--timesteps-per-hour', String(YEAR.timestepsPerHour),
    '--days-per-year', String(YEAR.daysPerYear), '--samples-per-day', String(YEAR.samplesPerDay), '--resolution', String(RESOLUTION), '--refine', String(YEAR.refine), '-o', out],
  { stdio: ['ignore', 'ignore', 'inherit'], env: { ...process.env, XDG_RUNTIME_DIR: work } });
  return readFileSync(out, 'utf8');
}

/** The year through the JS API with `engine`: its CSV and the engine's state after it. */
async function jsYear(engine) {
  const made = await api.createEngine({ resolution: RESOLUTION, engine });
  try {
    const model = made.loadFiles([{ name: 'office.glb', bytes: readFileSync(EXAMPLE) }]);
    const year = await made.annual(model, YEAR);
    return { csv: year.csv(), hasGpu: made.hasGpu, adapter: made.adapter, workers: made.workers, poolError: made.poolError };
  } finally {
    made.close();
  }
}

/** The largest |Δ| between two CSVs' values, after checking they have the same header and time
 * stamps; and how many values are lit (a year with no sun would agree trivially). */
function compare(csv, truth) {
  const rows = (text) => text.trim().split(/\r?\n/).map((line) => line.split(','));
  const [a, b] = [rows(csv), rows(truth)];
  assert.deepEqual(a[0], b[0], 'the same surfaces');
  assert.equal(a.length, b.length, 'the same timesteps');
  let worst = 0;
  let lit = 0;
  for (let r = 1; r < a.length; r++) {
    assert.equal(a[r][0], b[r][0], `time stamp of row ${r}`);
    for (let c = 1; c < a[r].length; c++) {
      worst = Math.max(worst, Math.abs(Number(a[r][c]) - Number(b[r][c])));
      lit += Number(b[r][c]) > 0 && Number(b[r][c]) < 1;
    }
  }
  return { worst, partlyLit: lit, values: (a.length - 1) * (a[0].length - 1) };
}

test("the exact engine's year through the JS API is the native CLI's CSV, byte for byte; the pool cannot start", { skip: noDriver, timeout: 300_000 }, async () => {
  const year = await jsYear('exact');
  const { worst, partlyLit, values } = compare(year.csv, nativeCsv);
  console.log(`Node exact vs native exact: max |Δ| ${worst} over ${values} values (${partlyLit} partly lit)`);
  assert.ok(partlyLit > 100, `the year has partly shaded values (${partlyLit})`);
  assert.equal(year.csv, nativeCsv);
  // Node has no Web Workers: the pool's start fails by its own path and clipping stays here.
  assert.equal(year.workers, 0);
  assert.match(year.poolError ?? '', /clipping worker 0 could not start: Worker is not defined/);
});

test("the GPU engine's year on Dawn's WebGPU is the native CLI's exact CSV within the raster kernel's bound", { skip: noDriver, timeout: 300_000 }, async () => {
  const year = await jsYear('gpu');
  assert.equal(year.hasGpu, true);
  const { worst, partlyLit, values } = compare(year.csv, nativeCsv);
  console.log(`Node gpu (${year.adapter}) vs native exact: max |Δ| ${worst.toFixed(5)} over ${values} values (${partlyLit} partly lit)`);
  assert.ok(partlyLit > 100, `the year has partly shaded values (${partlyLit})`);
  assert.ok(worst <= GPU_BOUND, `GPU engine on Dawn within ${GPU_BOUND} of the exact CSV (worst ${worst})`);
});
