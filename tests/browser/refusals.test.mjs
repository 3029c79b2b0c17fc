// What the page and the JS API refuse, and what they keep, in headless Chromium: model files too
// large for wasm32's memory are refused by their size, naming it, before they are read (through
// the API, and through the page's Model input, whose last model and year stay in place); a
// profile stored in IndexedDB that does not parse, or that was measured for another model or
// device, is refused by name, measured anew and replaced in the store. No huge download: the
// API's file is a zero-filled buffer one byte over the limit, the page's a sparse file.
import assert from 'node:assert/strict';
import { closeSync, mkdirSync, openSync, readFileSync, rmSync, ftruncateSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { serve } from '../../scripts/serve.mjs';
import { launch } from './chromium.mjs';

const WORK = join(tmpdir(), `sunlit-refusals-${process.pid}`);

let server;
let origin;
let browser;
const pageErrors = [];

before(async () => {
  mkdirSync(WORK, { recursive: true });
  server = await serve(0);
  origin = `http://127.0.0.1:${server.address().port}`;
  browser = await launch();
});

after(async () => {
  await browser?.close();
  server?.close();
  rmSync(WORK, { recursive: true, force: true });
});

async function apiPage() {
  const p = await browser.newPage();
  p.on('pageerror', (e) => pageErrors.push(e.message));
  await p.goto(`${origin}/api-example.html`);
  return p;
}

const YEAR = { latitude: 39.74, longitude: -105.18, timeZone: -7, timestepsPerHour: 1, daysPerYear: 6, samplesPerDay: 5 };

test('model files over the memory limit are refused by their size, naming it, and the last model still computes', async () => {
  const p = await apiPage();
  const r = await p.evaluate(async (year) => {
    const { createEngine, maxModelBytes, checkModelSize } = await import('/sunlit.js');
    const engine = await createEngine({ resolution: 64, engine: 'exact', workers: 0 });
    const bytes = new Uint8Array(await (await fetch('/pkg/office.glb')).arrayBuffer());
    const model = engine.loadFiles([{ name: 'office.glb', bytes }]);
    const before = (await engine.annual(model, year)).csv();
    const caught = (work) => {
      try {
        work();
        return null;
      } catch (e) {
        return { code: e.code, file: e.file, bytes: e.bytes, message: e.message };
      }
    };
    // One byte over: refused before any copy into the wasm (so no memory is spent on it).
    const huge = caught(() => engine.loadFiles([{ name: 'huge.glb', bytes: new Uint8Array(maxModelBytes + 1) }]));
    const split = caught(() => checkModelSize(['a.gltf', 'a.bin'], maxModelBytes + 1));
    const fits = caught(() => checkModelSize(['a.glb'], maxModelBytes));
    const after = (await engine.annual(model, year)).csv();
    return { maxModelBytes, huge, split, fits, same: before === after };
  }, YEAR);
  await p.close();
  assert.equal(r.maxModelBytes, Math.floor(4 * 2 ** 30 / 17));
  const mb = ((r.maxModelBytes + 1) / 1e6).toFixed(1);
  assert.equal(r.huge.code, 'too-large');
  assert.equal(r.huge.file, 'huge.glb');
  assert.equal(r.huge.bytes, r.maxModelBytes + 1);
  assert.ok(r.huge.message.startsWith(`huge.glb: ${mb} MB of model files do not fit in this page's memory`), r.huge.message);
  assert.match(r.huge.message, /the limit is about 253 MB/);
  assert.equal(r.split.code, 'too-large');
  assert.match(r.split.message, new RegExp(`^a\\.gltf, a\\.bin: ${mb} MB`));
  assert.equal(r.fits, null, 'at the limit a model is read');
  assert.ok(r.same, 'the model read before the refusal computes the same year after it');
  assert.deepEqual(pageErrors, []);
});

test('the page refuses a model file over the limit by its size, and keeps its last model and year', { timeout: 300_000 }, async () => {
  const page = await (await browser.newContext({ acceptDownloads: true })).newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(`${origin}/`);
  const waitForStatus = (pattern, timeout = 120_000) =>
    page.waitForFunction((source) => new RegExp(source).test(document.getElementById('status').textContent), pattern.source, { timeout });
  const statusAfter = async (action, pattern, timeout) => {
    await page.evaluate(() => {
      document.getElementById('status').textContent = '';
    });
    await action();
    await waitForStatus(pattern, timeout);
    return page.textContent('#status');
  };
  const downloadCsv = async (name) => {
    const download = page.waitForEvent('download');
    await page.click('#download');
    const file = join(WORK, name);
    const d = await download;
    await d.saveAs(file);
    return { name: d.suggestedFilename(), text: readFileSync(file, 'utf8') };
  };
  await waitForStatus(/^Ready/);
  assert.match(await statusAfter(() => page.click('#example'), /^Loaded|^Could not/), /^Loaded office\.glb/);
  for (const [id, v] of [['latitude', '39.74'], ['longitude', '-105.18'], ['timezone', '-7'], ['days', '6'], ['perday', '5'], ['resolution', '64']]) {
    await page.fill(`#${id}`, v);
  }
  await page.selectOption('#timesteps', '1');
  assert.match(await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 240_000), /^Done/);
  const info = await page.textContent('#modelinfo');
  const table = await page.textContent('#table tbody');
  const first = await downloadCsv('before.csv');

  // A sparse file one byte over the limit: the page refuses it by its size, without reading it.
  const limit = await page.evaluate(async () => (await import('/sunlit.js')).maxModelBytes);
  const huge = join(WORK, 'huge.glb');
  const fd = openSync(huge, 'w');
  ftruncateSync(fd, limit + 1);
  closeSync(fd);
  const refused = await statusAfter(() => page.setInputFiles('#model', huge), /^Loaded|^Could not/);
  assert.ok(refused.startsWith(`Could not read the model: huge.glb: ${((limit + 1) / 1e6).toFixed(1)} MB of model files do not fit`), refused);
  assert.doesNotMatch(refused, /\.\.$/, 'one full stop');
  // The last good model and its year are still there, under their own names.
  assert.equal(await page.textContent('#modelinfo'), info);
  assert.equal(await page.textContent('#table tbody'), table);
  assert.equal(await page.isDisabled('#download'), false);
  assert.deepEqual(await downloadCsv('kept.csv'), first);
  assert.equal(first.name, 'office-shading.csv');
  // And the model computes again.
  assert.match(await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 240_000), /^Done/);
  assert.deepEqual(await downloadCsv('again.csv'), first);
  await page.close();
  assert.deepEqual(pageErrors, []);
});

test('a stored profile that does not parse, or was measured for another model, is refused by name, measured anew and replaced', async () => {
  const p = await apiPage();
  const r = await p.evaluate(async (year) => {
    const { createEngine } = await import('/sunlit.js');
    const { cachedProfile, storeProfile } = await import('/profiles.js');
    const bytes = new Uint8Array(await (await fetch('/pkg/office.glb')).arrayBuffer());
    const run = async () => {
      const engine = await createEngine({ resolution: 64, workers: 1 });
      const y = await engine.annual(engine.loadFiles([{ name: 'office.glb', bytes }]), year);
      const out = { csv: y.csv(), profile: y.profile, source: y.profileSource, refused: y.profileRefused, key: engine.routing.key };
      out.stored = await cachedProfile(out.key);
      engine.close();
      return out;
    };
    const measured = await run();
    await storeProfile(measured.key, '{"device": "half a profile');
    const garbled = await run();
    const foreign = JSON.parse(measured.profile);
    foreign.device = foreign.device.replace(/scene \d+ triangles/, 'scene 7 triangles');
    await storeProfile(measured.key, JSON.stringify(foreign));
    const other = await run();
    const cached = await run();
    return { measured, garbled, other, cached };
  }, YEAR);
  await p.close();
  assert.equal(r.measured.source, 'probe');
  assert.equal(r.measured.stored, r.measured.profile, 'a measured profile is stored under its key');
  for (const [name, run, why] of [
    ['garbled', r.garbled, /the profile stored in IndexedDB \(database 'sunlit', store 'engine-profiles'\) is not a profile/],
    ['foreign', r.other, /the profile stored in IndexedDB \(database 'sunlit', store 'engine-profiles'\) was measured for '.*scene 7 triangles.*', not this model and device/],
  ]) {
    assert.match(run.refused ?? '', why, `${name}: ${run.refused}`);
    assert.equal(run.source, 'probe', `${name}: measured anew`);
    assert.equal(run.stored, run.profile, `${name}: the new measurement replaces it in the store`);
    assert.equal(JSON.parse(run.profile).device, JSON.parse(r.measured.profile).device, `${name}: measured for this model and device`);
  }
  assert.equal(r.cached.source, 'cache', 'the replacement is found next time');
  assert.equal(r.cached.refused, undefined);
  assert.deepEqual(pageErrors, []);
});
