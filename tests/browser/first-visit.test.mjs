// What a first visit pays on the engine's thread, in headless Chromium through the JS API
// (sunlit.js): the engine's thread indexes a model once for all it does with it (the convex
// objects handed to the clipping workers, the year's certificates, its own clipping), and
// `engine: 'exact'`, which never draws, asks the browser for no GPU adapter; the answers are
// those of the engines that did (docs/page-speed.md, "The first visit").
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';
import { serve } from '../../scripts/serve.mjs';
import { launch } from './chromium.mjs';
import { SCENE } from './louvred.mjs';

let server;
let origin;
let browser;

before(async () => {
  server = await serve(0);
  origin = `http://127.0.0.1:${server.address().port}`;
  browser = await launch();
});

after(async () => {
  await browser?.close();
  server?.close();
});

/** A document of the site's origin (its CSP is the site's) that runs nothing of its own, to
 * import the API in: api-example.html makes an engine of its own as it loads, whose adapter
 * request and index would be counted here. */
async function apiPage() {
  const p = await browser.newPage();
  const errors = [];
  p.on('pageerror', (e) => errors.push(e.message));
  await p.goto(`${origin}/nothing-here`);
  return { p, errors };
}

// Refined timesteps to certify (refine below 1): the year's certificates run on the engine's
// thread, where they took an index of their own.
const YEAR = { latitude: 39.74, longitude: -105.18, timeZone: -7, timestepsPerHour: 1, daysPerYear: 12, samplesPerDay: 9 };

test("the engine's thread indexes a model once in a pooled year: its certificates share the index the workers' objects came from", async () => {
  const { p, errors } = await apiPage();
  const r = await p.evaluate(
    async ({ scene, year }) => {
      eval(scene);
      const { createEngine } = await import('/sunlit.js');
      const out = {};
      for (const [name, options] of [
        ['auto', { workers: 2 }],
        ['exact', { engine: 'exact', workers: 2 }],
        ['alone', { engine: 'exact', workers: 0 }],
      ]) {
        const engine = await createEngine({ resolution: 128, ...options });
        const before = engine.timings.indexesBuilt;
        const model = engine.fromArrays(louvredBlock());
        // The workers hold the model before the year, as the page has them (worker.js): they
        // clip its views, whatever the machine's load.
        await engine.prepare(model);
        const y = await engine.annual(model, year);
        out[name] = { built: engine.timings.indexesBuilt - before, csv: y.csv(), means: Array.from(y.means), clipped: engine.timings.clipped };
        engine.close();
      }
      return out;
    },
    { scene: `${SCENE}; globalThis.louvredBlock = louvredBlock;`, year: YEAR },
  );
  await p.close();
  assert.deepEqual(errors, []);
  // The workers clipped (a year the engine's thread clipped alone would not be the pooled case).
  assert.ok(r.exact.clipped.workers > 0 && r.auto.clipped.workers > 0, JSON.stringify([r.auto.clipped, r.exact.clipped]));
  assert.equal(r.auto.built, 1, "auto: one index on the engine's thread");
  assert.equal(r.exact.built, 1, "exact: one index on the engine's thread");
  assert.equal(r.alone.built, 1, "no workers: one index on the engine's thread");
  // Shadows were cast, and the answers do not depend on where the index came from.
  assert.ok(r.alone.means[0] > 0.05 && r.alone.means[0] < 0.95, `south wall's mean ${r.alone.means[0]}`);
  assert.equal(r.exact.csv, r.alone.csv);
  assert.equal(r.auto.csv, r.alone.csv);
});

test("engine 'exact' asks the browser for no GPU adapter, and answers as auto does", async () => {
  const { p, errors } = await apiPage();
  const r = await p.evaluate(
    async ({ scene, year }) => {
      eval(scene);
      // Every adapter request the engine makes (wgpu asks navigator.gpu), counted.
      const gpu = navigator.gpu;
      const request = gpu.requestAdapter.bind(gpu);
      let asked = 0;
      gpu.requestAdapter = (...args) => (asked++, request(...args));
      const { createEngine } = await import('/sunlit.js');
      const run = async (options) => {
        const from = asked;
        const engine = await createEngine({ resolution: 128, workers: 2, ...options });
        const y = await engine.annual(engine.fromArrays(louvredBlock()), year);
        const out = { asked: asked - from, hasGpu: engine.hasGpu, adapter: engine.adapter, csv: y.csv() };
        engine.close();
        return out;
      };
      return { exact: await run({ engine: 'exact' }), auto: await run({}) };
    },
    { scene: `${SCENE}; globalThis.louvredBlock = louvredBlock;`, year: YEAR },
  );
  await p.close();
  assert.deepEqual(errors, []);
  // auto asks (its profiles are keyed by the adapter): the count sees the engine's requests.
  assert.ok(r.auto.asked >= 1, `auto asked for ${r.auto.asked} adapters`);
  assert.equal(r.auto.hasGpu, true);
  assert.equal(r.exact.asked, 0, "exact asked for an adapter");
  assert.equal(r.exact.hasGpu, false);
  assert.match(r.exact.adapter, /none \(engine 'exact' clips every view, without a GPU\)/);
  assert.equal(r.exact.csv, r.auto.csv);
});
