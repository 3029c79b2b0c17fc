// The page end to end in headless Chromium (WebGPU on SwiftShader), driven by Playwright: load the
// example through the Model input and through a dropped file, compute a year, download the
// EnergyPlus CSV and compare it with the native CLI's; bad files give messages that name the
// problem and the page keeps working; no request leaves the page's origin; user-supplied names
// render as text. The 3D view is saved to target/artifacts/page.png for a person to look at.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { fileURLToPath } from 'node:url';
import { serve } from '../../scripts/serve.mjs';
import { launch } from './chromium.mjs';

const ROOT = fileURLToPath(new URL('../../', import.meta.url));
const EXAMPLE = join(ROOT, 'www/pkg/office.glb');
const ARTIFACTS = join(ROOT, 'target/artifacts');
const WORK = join(tmpdir(), `sunlit-page-${process.pid}`);
// The same settings on both sides: Golden, CO; 27×19; 256² views; hourly rows.
const SETTINGS = { latitude: '39.74', longitude: '-105.18', timezone: '-7', resolution: '256', timesteps: '1' };

let server;
let origin;
let browser;
let page;
const requests = [];
const pageErrors = [];

before(async () => {
  mkdirSync(WORK, { recursive: true });
  mkdirSync(ARTIFACTS, { recursive: true });
  server = await serve(0);
  origin = `http://127.0.0.1:${server.address().port}`;
  browser = await launch();
  page = await (await browser.newContext({ acceptDownloads: true })).newPage();
  page.on('request', (r) => requests.push(r.url()));
  page.on('pageerror', (e) => pageErrors.push(e.message));
  page.on('worker', (w) => w.on('console', () => {}));
  await page.goto(`${origin}/`);
  await waitForStatus(/^Ready/);
});

after(async () => {
  await browser?.close();
  server?.close();
});

async function waitForStatus(pattern, timeout = 120_000) {
  await page.waitForFunction(
    (source) => new RegExp(source).test(document.getElementById('status').textContent),
    pattern.source,
    { timeout },
  );
  return page.textContent('#status');
}

async function statusAfter(action, pattern, timeout) {
  await page.evaluate(() => { document.getElementById('status').textContent = ''; });
  await action();
  return waitForStatus(pattern, timeout);
}

function nativeCsv() {
  const out = join(WORK, 'native.csv');
  execFileSync('cargo', ['run', '--quiet', '--bin', 'sunlit', '--', 'annual', EXAMPLE,
    '--location', `${SETTINGS.latitude},${SETTINGS.longitude},${SETTINGS.timezone}`,
    '--timesteps-per-hour', SETTINGS.timesteps, '--resolution', SETTINGS.resolution, '-o', out], { cwd: ROOT, stdio: 'inherit' });
  return readFileSync(out, 'utf8');
}

function parseCsv(text) {
  const lines = text.trim().split(/\r?\n/);
  return { header: lines[0].split(','), rows: lines.slice(1).map((l) => l.split(',')) };
}

test('the example loads through the Model input, computes, and its CSV equals the native CLI', { timeout: 900_000 }, async () => {
  const loaded = await statusAfter(() => page.setInputFiles('#model', EXAMPLE), /^Loaded|^Could not/);
  assert.match(loaded, /^Loaded office\.glb \(10 receivers\)/);
  await page.fill('#latitude', SETTINGS.latitude);
  await page.fill('#longitude', SETTINGS.longitude);
  await page.fill('#timezone', SETTINGS.timezone);
  await page.fill('#resolution', SETTINGS.resolution);
  await page.selectOption('#timesteps', SETTINGS.timesteps);
  const done = await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 600_000);
  assert.match(done, /^Done in [\d.]+ s: 10 surfaces × 8,760 timesteps/);

  const download = page.waitForEvent('download');
  await page.click('#download');
  const file = join(WORK, 'page.csv');
  await (await download).saveAs(file);
  const web = parseCsv(readFileSync(file, 'utf8'));
  const native = parseCsv(nativeCsv());
  assert.deepEqual(web.header, native.header);
  assert.equal(web.header[0], 'Surface Name');
  assert.equal(web.rows.length, 8760 * Number(SETTINGS.timesteps));
  let worst = 0;
  let lit = 0;
  web.rows.forEach((row, r) => {
    assert.equal(row[0], native.rows[r][0], `time stamp of row ${r}`);
    for (let c = 1; c < row.length; c++) {
      const d = Math.abs(Number(row[c]) - Number(native.rows[r][c]));
      worst = Math.max(worst, d);
      lit += Number(row[c]) > 0;
    }
  });
  console.log(`page vs native CLI: max |Δ| ${worst.toFixed(5)} over ${web.rows.length} rows × ${web.header.length - 1} surfaces (${lit} lit values)`);
  assert.ok(lit > 10_000, 'the year has sun on it');
  assert.ok(worst <= 0.005, `browser and native agree within 0.005 (worst ${worst})`);

  // The coloured 3D view and the heat map, for a person to look at.
  await page.locator('.results').screenshot({ path: join(ARTIFACTS, 'page.png') });
  const legend = await page.textContent('#legend');
  assert.match(legend, /Annual mean sunlit fraction/);
  assert.equal(await page.locator('#table tbody tr').count(), 10);
  assert.equal(await page.locator('#heatfigure').isVisible(), true);
});

test('a dropped file loads like a chosen one', async () => {
  const bytes = [...readFileSync(EXAMPLE)];
  const status = await statusAfter(async () => {
    const transfer = await page.evaluateHandle((data) => {
      const t = new DataTransfer();
      t.items.add(new File([new Uint8Array(data)], 'dropped.glb', { type: 'model/gltf-binary' }));
      return t;
    }, bytes);
    await page.dispatchEvent('#drop', 'drop', { dataTransfer: transfer });
  }, /^Loaded|^Could not/);
  assert.match(status, /^Loaded dropped\.glb \(10 receivers\)/);

  // A .gltf dropped with its external buffer finds it by name.
  const bin = [...new Uint8Array(new Float32Array([0, 0, 0, 1, 0, 0, 0, 0, -1]).buffer)];
  const gltf = JSON.stringify({
    asset: { version: '2.0' },
    buffers: [{ uri: 'tri.bin', byteLength: 36 }],
    bufferViews: [{ buffer: 0, byteLength: 36 }],
    accessors: [{ bufferView: 0, componentType: 5126, count: 3, type: 'VEC3', min: [0, 0, -1], max: [1, 0, 0] }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0 } }] }],
    nodes: [{ name: 'tri', mesh: 0 }],
    scenes: [{ nodes: [0] }],
  });
  const pair = await statusAfter(async () => {
    const transfer = await page.evaluateHandle(({ gltf, bin }) => {
      const t = new DataTransfer();
      t.items.add(new File([new Uint8Array(bin)], 'tri.bin'));
      t.items.add(new File([gltf], 'tri.gltf'));
      return t;
    }, { gltf, bin });
    await page.dispatchEvent('#drop', 'drop', { dataTransfer: transfer });
  }, /^Loaded|^Could not/);
  assert.match(pair, /^Loaded tri\.bin, tri\.gltf \(1 receiver\)/);
});

test('bad files get a message naming the problem, and the page keeps working', { timeout: 300_000 }, async () => {
  const cases = [
    ['notes.glb', Buffer.from('hello'), /notes\.glb: not a glTF file/],
    ['truncated.glb', readFileSync(EXAMPLE).subarray(0, 100), /truncated\.glb: not a valid glTF 2\.0 file/],
    ['external.gltf', Buffer.from('{"asset":{"version":"2.0"},"buffers":[{"uri":"mesh.bin","byteLength":12}]}'), /external\.gltf: .*mesh\.bin/],
  ];
  for (const [name, bytes, expected] of cases) {
    const path = join(WORK, name);
    writeFileSync(path, bytes);
    const status = await statusAfter(() => page.setInputFiles('#model', path), /^Loaded|^Could not/);
    assert.match(status, /^Could not read the model: /);
    assert.match(status, expected);
  }
  await page.fill('#receivers', 'Nothing*');
  const none = await statusAfter(() => page.setInputFiles('#model', EXAMPLE), /^Loaded|^Could not/);
  assert.match(none, /no receiving surface: no node name matches receivers Nothing\*/);
  await page.fill('#receivers', '');

  const epw = join(WORK, 'nowhere.epw');
  writeFileSync(epw, 'garbage\n');
  assert.match(await statusAfter(() => page.setInputFiles('#model', EXAMPLE), /^Loaded|^Could not/), /^Loaded/);
  await page.setInputFiles('#epw', epw);
  const noLocation = await statusAfter(() => page.click('#compute'), /^Done|^Could not/);
  assert.match(noLocation, /^Could not compute: nowhere\.epw: first line is not an EPW LOCATION record/);
  await page.setInputFiles('#epw', []);

  // Cancel stops a long run within a progress report or so.
  await page.fill('#days', '53');
  await page.fill('#perday', '53');
  const cancelled = await statusAfter(async () => {
    await page.click('#compute');
    await waitForStatus(/^Counting views/);
    await page.click('#cancel');
  }, /^Cancelled|^Done|^Could not/);
  assert.equal(cancelled, 'Cancelled.');

  // Still works: a quick year at low settings.
  await page.fill('#days', '6');
  await page.fill('#perday', '5');
  await page.fill('#resolution', '64');
  assert.match(await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 300_000), /^Done/);
});

test('an EnergyPlus IDF loads, and the hooked IDF downloads with its CSV named', { timeout: 300_000 }, async () => {
  const idf = join(WORK, 'office.idf');
  execFileSync('cargo', ['run', '--quiet', '--example', 'make_office_idf', '--', idf, '--louvres', '2'], { cwd: ROOT, stdio: 'inherit' });
  const loaded = await statusAfter(() => page.setInputFiles('#model', idf), /^Loaded|^Could not/);
  assert.match(loaded, /^Loaded office\.idf \(\d+ receivers\)/);
  assert.equal(await page.locator('#downloadidf').isVisible(), true);
  await page.fill('#days', '6');
  await page.fill('#perday', '5');
  await page.fill('#resolution', '64');
  assert.match(await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 300_000), /^Done/);
  const download = page.waitForEvent('download');
  await page.click('#downloadidf');
  const saved = join(WORK, 'hooked.idf');
  await (await download).saveAs(saved);
  assert.equal((await download).suggestedFilename(), 'office-sunlit.idf');
  const text = readFileSync(saved, 'utf8');
  assert.match(text, /Schedule:File,/);
  assert.match(text, /office-shading\.csv/);
  assert.match(text, /SurfaceProperty:LocalEnvironment,/);
  assert.match(text, /Scheduled/);
});

test('trees shade by season: bare in winter, and evergreen keeps them', { timeout: 600_000 }, async () => {
  const trees = join(WORK, 'trees.glb');
  execFileSync('cargo', ['run', '--quiet', '--example', 'make_trees', '--', '3000', trees], { cwd: ROOT, stdio: 'inherit' });
  const loaded = await statusAfter(() => page.setInputFiles('#model', trees), /^Loaded|^Could not/);
  assert.match(loaded, /^Loaded trees\.glb \(3 receivers\)/);
  assert.match(await page.textContent('#modelinfo'), /3,000 leaves/);
  await page.fill('#days', '14');
  await page.fill('#perday', '9');
  await page.fill('#resolution', '128');
  await page.selectOption('#timesteps', '1');
  const year = async (evergreen) => {
    await page.setChecked('#evergreen', evergreen);
    assert.match(await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 300_000), /^Done/);
    const download = page.waitForEvent('download');
    await page.click('#download');
    const file = join(WORK, `trees-${evergreen}.csv`);
    await (await download).saveAs(file);
    return parseCsv(readFileSync(file, 'utf8'));
  };
  const deciduous = await year(false);
  const evergreen = await year(true);
  await page.setChecked('#evergreen', false);
  // Mean of the ground storey (column 1) over a month's daylight rows.
  const mean = (csv, firstDay, days) => {
    const rows = csv.rows.slice(24 * firstDay, 24 * (firstDay + days)).map((r) => Number(r[1])).filter((v) => v > 0);
    return rows.reduce((a, b) => a + b, 0) / rows.length;
  };
  const [winterBare, winterLeafy] = [mean(deciduous, 0, 31), mean(evergreen, 0, 31)];
  const [summerBare, summerLeafy] = [mean(deciduous, 181, 31), mean(evergreen, 181, 31)];
  console.log(`STOREY_1 January: deciduous ${winterBare.toFixed(3)}, evergreen ${winterLeafy.toFixed(3)}; July: ${summerBare.toFixed(3)}, ${summerLeafy.toFixed(3)}`);
  assert.ok(winterBare > winterLeafy + 0.02, 'bare winter trees let more sun through than evergreen ones');
  assert.ok(Math.abs(summerBare - summerLeafy) < 0.005, 'in full leaf both agree');
});

test('names from a file render as text, never as markup', async () => {
  const name = '<img src=x onerror="window.pwned=1">';
  const positions = Buffer.from(new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]).buffer);
  const gltf = {
    asset: { version: '2.0' },
    buffers: [{ byteLength: 12 * 3, uri: `data:application/octet-stream;base64,${positions.toString('base64')}` }],
    bufferViews: [{ buffer: 0, byteLength: 36 }],
    accessors: [{ bufferView: 0, componentType: 5126, count: 3, type: 'VEC3', min: [0, 0, 0], max: [1, 1, 0] }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0 } }] }],
    nodes: [{ name, mesh: 0 }],
    scenes: [{ nodes: [0] }],
  };
  const path = join(WORK, 'crafted.gltf');
  writeFileSync(path, JSON.stringify(gltf));
  const status = await statusAfter(() => page.setInputFiles('#model', path), /^Loaded|^Could not/);
  assert.match(status, /^Loaded crafted\.gltf \(1 receiver\)/);
  assert.equal(await page.textContent('#table tbody tr td'), name);
  assert.equal(await page.locator('#table img').count(), 0);
  assert.equal(await page.evaluate(() => window.pwned), undefined);
});

test('the API example runs', { timeout: 300_000 }, async () => {
  const example = await page.context().newPage();
  example.on('request', (r) => requests.push(r.url()));
  await example.goto(`${origin}/api-example.html`);
  await example.waitForFunction(() => /^done/.test(document.getElementById('out').dataset.state ?? ''), null, { timeout: 240_000 });
  const out = await example.textContent('#out');
  assert.match(out, /window: 0\.\d{3}/);
  assert.match(out, /8760 rows/);
  await example.close();
});

test('API errors carry a stable code and name what they are about as the API spells it', { timeout: 120_000 }, async () => {
  const p = await page.context().newPage();
  p.on('request', (r) => requests.push(r.url()));
  p.on('pageerror', (e) => pageErrors.push(e.message));
  await p.goto(`${origin}/`);
  const errors = await p.evaluate(async () => {
    const sunlit = await import('/sunlit.js');
    const engine = await sunlit.createEngine({ resolution: 64 });
    const shape = (e) => ({ code: e.code, file: e.file, object: e.object, option: e.option, message: e.message, isError: e instanceof Error });
    const thrown = (f) => {
      try {
        f();
      } catch (e) {
        return shape(e);
      }
      return null;
    };
    const bytes = new Uint8Array(await (await fetch('/pkg/office.glb')).arrayBuffer());
    const model = engine.loadFiles([{ name: 'office.glb', bytes }]);
    let settings = null;
    try {
      await engine.annual(model, { latitude: 40, longitude: -105, timeZone: -7, timestepsPerHour: 7 });
    } catch (e) {
      settings = shape(e);
    }
    return {
      file: thrown(() => engine.loadFiles([{ name: 'notes.glb', bytes: new TextEncoder().encode('hello') }])),
      receivers: thrown(() => engine.loadFiles([{ name: 'office.glb', bytes }], { receivers: 'Nothing*' })),
      settings,
    };
  });
  await p.close();
  assert.equal(errors.file.isError, true);
  assert.equal(errors.file.code, 'model');
  assert.equal(errors.file.file, 'notes.glb');
  assert.equal(errors.receivers.code, 'no-receivers');
  assert.equal(errors.receivers.option, 'receivers');
  assert.match(errors.receivers.message, /no node name matches receivers Nothing\*/);
  assert.equal(errors.settings.code, 'bad-option');
  assert.equal(errors.settings.option, 'timestepsPerHour');
  assert.match(errors.settings.message, /^invalid timestepsPerHour: 7 is not one EnergyPlus accepts/);
});

test('a browser without WebGPU is told so', async () => {
  const plain = await launch({ webgpu: false });
  try {
    const p = await plain.newPage();
    await p.goto(`${origin}/`);
    await p.waitForSelector('#nowebgpu:not([hidden])', { timeout: 60_000 });
    assert.match(await p.textContent('#nowebgpu'), /no WebGPU, which sunlit needs/);
    assert.equal(await p.isDisabled('#compute'), true);
  } finally {
    await plain.close();
  }
});

test('no request left the origin and no script error happened', () => {
  const outside = requests.filter((u) => !u.startsWith(origin) && !u.startsWith('blob:') && !u.startsWith('data:'));
  assert.deepEqual(outside, []);
  assert.ok(requests.length > 5, 'requests were seen');
  assert.deepEqual(pageErrors, []);
});
