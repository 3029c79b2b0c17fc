// The page end to end in headless Chromium (WebGPU on SwiftShader), driven by Playwright: load the
// example through the Model input and through a dropped file, compute a year, download the
// EnergyPlus CSV and compare it with the native CLI's; bad files give messages that name the
// problem and the page keeps working; no request leaves the page's origin; user-supplied names
// render as text. The 3D view is saved to target/artifacts/page.png for a person to look at, and
// copied to docs/page.png, the picture README.md shows.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { copyFileSync, existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { fileURLToPath } from 'node:url';
import { serve } from '../../scripts/serve.mjs';
import { launch } from './chromium.mjs';
import { SYDNEY, syntheticEpw } from './epw.mjs';

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
  // README.md shows this picture: each run brings the committed copy up to date.
  copyFileSync(join(ARTIFACTS, 'page.png'), join(ROOT, 'docs/page.png'));
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

  // Cancel stops a long run within a progress report or so. The pixel engine makes the run long:
  // auto clips this light model exactly in a fraction of a second.
  await page.fill('#days', '53');
  await page.fill('#perday', '53');
  await page.selectOption('#engine', 'gpu');
  const cancelled = await statusAfter(async () => {
    await page.click('#compute');
    await waitForStatus(/^Counting views/);
    await page.click('#cancel');
  }, /^Cancelled|^Done|^Could not/);
  assert.equal(cancelled, 'Cancelled.');
  await page.selectOption('#engine', 'auto');

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

test('a model whose RunPeriod is a leap year gets 366 days of rows, as the CLI', { timeout: 300_000 }, async () => {
  const plain = join(WORK, 'office.idf');
  if (!existsSync(plain)) {
    execFileSync('cargo', ['run', '--quiet', '--example', 'make_office_idf', '--', plain, '--louvres', '2'], { cwd: ROOT, stdio: 'inherit' });
  }
  const text = readFileSync(plain, 'utf8');
  const leap = text.replace(/RunPeriod, YEAR, 1, 1, , 12, 31, ,/, 'RunPeriod, YEAR, 1, 1, 2020, 12, 31, 2020,');
  assert.notEqual(leap, text, 'the generated model has the RunPeriod this test edits');
  const idf = join(WORK, 'office-2020.idf');
  writeFileSync(idf, leap);
  assert.match(await statusAfter(() => page.setInputFiles('#model', idf), /^Loaded|^Could not/), /^Loaded office-2020\.idf/);
  await page.fill('#days', '6');
  await page.fill('#perday', '5');
  await page.fill('#resolution', '64');
  const done = await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 300_000);
  const rows = Number(/× ([\d,]+) timesteps/.exec(done)?.[1].replace(/,/g, ''));
  assert.ok(rows > 0 && rows % 8784 === 0, `${rows} rows are whole leap-year days (${done})`);
  const download = page.waitForEvent('download');
  await page.click('#download');
  const csv = join(WORK, 'office-2020.csv');
  await (await download).saveAs(csv);
  const lines = readFileSync(csv, 'utf8').trimEnd().split('\n');
  assert.equal(lines.length, rows + 1);
  assert.ok(lines.some((l) => l.startsWith(' 02/29 ')), 'Feb 29 is in the CSV');
  assert.match(lines.at(-1), /^ 12\/31 24:00,/);
});

test('an EnergyPlus model too old to hook still gets its year, and the page says why there is no hooked IDF', { timeout: 300_000 }, async () => {
  const old = join(ROOT, 'tests', 'energyplus_testfiles', '4ZoneWithShading_Simple_1_V8-4.idf');
  const loaded = await statusAfter(() => page.setInputFiles('#model', old), /^Loaded|^Could not/);
  assert.match(loaded, /^Loaded 4ZoneWithShading_Simple_1_V8-4\.idf \(\d+ receivers\)/);
  await page.fill('#days', '6');
  await page.fill('#perday', '5');
  await page.fill('#resolution', '64');
  const done = await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 300_000);
  assert.match(done, /^Done in .* No hooked model: .*Version 8\.4.*9\.3/);
  assert.equal(await page.locator('#downloadidf').isDisabled(), true);
  assert.equal(await page.locator('#download').isDisabled(), false);
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

test('compressed glTF loads in the page, and many default receivers come with a note', async () => {
  // The Draco and meshopt office that glTF Transform writes (kept as fuzz seeds).
  for (const name of ['office-draco.glb', 'office-meshopt.glb']) {
    const path = join(ROOT, 'fuzz/seeds/gltf', name);
    const status = await statusAfter(() => page.setInputFiles('#model', path), /^Loaded|^Could not/);
    assert.match(status, new RegExp(`^Loaded ${name.replace('.', '\\.')} \\(10 receivers\\)`));
    assert.doesNotMatch(status, /Note:/);
  }
  // A CAD-like export: 250 named nodes, no receiver marks.
  const positions = Buffer.from(new Float32Array([0, 0, 0, 1, 0, 0, 0, 0, -1]).buffer);
  const count = 250;
  const gltf = {
    asset: { version: '2.0' },
    buffers: [{ byteLength: 36, uri: `data:application/octet-stream;base64,${positions.toString('base64')}` }],
    bufferViews: [{ buffer: 0, byteLength: 36 }],
    accessors: [{ bufferView: 0, componentType: 5126, count: 3, type: 'VEC3', min: [0, 0, -1], max: [1, 0, 0] }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0 } }] }],
    nodes: Array.from({ length: count }, (_, i) => ({ name: `part${i}`, mesh: 0, translation: [2 * i, 0, 0] })),
    scenes: [{ nodes: Array.from({ length: count }, (_, i) => i) }],
  };
  const path = join(WORK, 'cad.gltf');
  writeFileSync(path, JSON.stringify(gltf));
  const status = await statusAfter(() => page.setInputFiles('#model', path), /^Loaded|^Could not/);
  assert.match(status, /^Loaded cad\.gltf \(250 receivers\)/);
  assert.match(status, /Note: 250 receivers \(250 nodes: part0, part1, part2, part3, part4, …\) were chosen by the default rule/);
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

test('a dense year has no fitted surfaces: splineFractionsAt is refused naming dense', { timeout: 300_000 }, async () => {
  const p = await page.context().newPage();
  p.on('request', (r) => requests.push(r.url()));
  p.on('pageerror', (e) => pageErrors.push(e.message));
  await p.goto(`${origin}/`);
  const r = await p.evaluate(async () => {
    const sunlit = await import('/sunlit.js');
    const engine = await sunlit.createEngine({ resolution: 32 });
    const model = engine.fromArrays({ positions: [0, 0, 0, 1, 0, 0, 0, 1, 0], indices: [0, 1, 2], triangleReceivers: [0], names: ['ROOF'] });
    const year = await engine.annual(model, { latitude: 40, longitude: -105, timeZone: -7, timestepsPerHour: 1, dense: true });
    let refused = null;
    try {
      year.splineFractionsAt(172, 12);
    } catch (e) {
      refused = { code: e.code, option: e.option, message: e.message };
    }
    return { refused, linear: Array.from(year.fractionsAt(172, 12)) };
  });
  await p.close();
  assert.deepEqual([r.refused?.code, r.refused?.option], ['bad-option', 'dense']);
  assert.match(r.refused.message, /no fitted surfaces; use fractionsAt/);
  assert.deepEqual(r.linear, [1], 'fractionsAt still answers');
});

test('a browser without WebGPU is told only the GPU engine is missing, and still computes', { timeout: 600_000 }, async () => {
  const plain = await launch({ webgpu: false });
  try {
    const p = await plain.newPage();
    const errors = [];
    p.on('pageerror', (e) => errors.push(e.message));
    await p.goto(`${origin}/`);
    await p.waitForSelector('#nowebgpu:not([hidden])', { timeout: 60_000 });
    assert.match(await p.textContent('#nowebgpu'), /no WebGPU, so only the GPU engine is missing/);
    await p.setInputFiles('#model', EXAMPLE);
    await p.waitForFunction(() => /^Loaded/.test(document.getElementById('status').textContent), null, { timeout: 120_000 });
    assert.match(await p.textContent('#status'), /on none \(no WebGPU/);
    await p.fill('#days', '6');
    await p.fill('#perday', '7');
    await p.click('#compute');
    await p.waitForFunction(() => /^Done|^Could not/.test(document.getElementById('status').textContent), null, { timeout: 300_000 });
    assert.match(await p.textContent('#status'), /^Done in [\d.]+ s: 10 surfaces/);
    assert.match(await p.textContent('#routingsource'), /no GPU/);
    assert.deepEqual(errors, []);
  } finally {
    await plain.close();
  }
});

test('with an EPW: its location in the form, irradiation columns and colours, equal to the API', { timeout: 600_000 }, async () => {
  assert.match(await statusAfter(() => page.setInputFiles('#model', EXAMPLE), /^Loaded|^Could not/), /^Loaded office\.glb/);
  const epwText = syntheticEpw(SYDNEY);
  const epwPath = join(WORK, 'sydney.epw');
  writeFileSync(epwPath, epwText);
  await page.setInputFiles('#epw', epwPath);
  await page.waitForFunction(() => document.getElementById('latitude').value === '-33.87', null, { timeout: 60_000 });
  const fields = await page.evaluate(() => ['latitude', 'longitude', 'timezone'].map((id) => [document.getElementById(id).value, document.getElementById(id).readOnly]));
  assert.deepEqual(fields, [['-33.87', true], ['151.21', true], ['10', true]]);
  assert.match(await page.textContent('#locationnote'), /From sydney\.epw: Sydney, NSW, AUS/);
  await page.fill('#days', '6');
  await page.fill('#perday', '5');
  await page.fill('#resolution', '64');
  await page.selectOption('#timesteps', '1');
  assert.match(await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 300_000), /^Done in [\d.]+ s: 10 surfaces/);

  const table = await page.evaluate(() => ({
    head: [...document.querySelectorAll('#table thead th')].filter((th) => !th.hidden).map((th) => th.textContent),
    rows: [...document.querySelectorAll('#table tbody tr')].map((tr) => [...tr.cells].map((td) => td.textContent)),
  }));
  assert.deepEqual(table.head, ['Surface', 'Area m²', 'Mean fraction', 'Irradiation kWh/m²', 'Unshaded kWh/m²', 'Sky diffuse kWh/m²', 'Ground kWh/m²', 'Total kWh/m²']);
  // The same year through the JS API (its own engine, on the page's thread).
  const api = await page.evaluate(async (text) => {
    const sunlit = await import('/sunlit.js');
    const engine = await sunlit.createEngine({ resolution: 64 });
    const bytes = new Uint8Array(await (await fetch('/pkg/office.glb')).arrayBuffer());
    const model = engine.loadFiles([{ name: 'office.glb', bytes }]);
    const year = await engine.annual(model, { epw: text, epwName: 'sydney.epw', daysPerYear: 6, samplesPerDay: 5, timestepsPerHour: 1 });
    const out = {
      names: year.names,
      means: Array.from(year.means),
      irradiation: Array.from(year.irradiation),
      unshaded: Array.from(year.unshadedIrradiation),
      sky: Array.from(year.skyDiffuse),
      ground: Array.from(year.groundReflected),
      total: Array.from(year.total),
    };
    year.free();
    model.free();
    return out;
  }, epwText);
  assert.equal(table.rows.length, api.names.length);
  table.rows.forEach(([name, , mean, irradiation, unshaded, sky, ground, total], i) => {
    assert.equal(name, api.names[i]);
    assert.ok(Math.abs(Number(mean) - api.means[i]) <= 0.0015, `${name}: mean ${mean} vs API ${api.means[i]}`);
    assert.ok(Math.abs(Number(irradiation) - api.irradiation[i]) <= 0.05 + 0.002 * api.irradiation[i], `${name}: ${irradiation} vs API ${api.irradiation[i]}`);
    assert.ok(Math.abs(Number(unshaded) - api.unshaded[i]) <= 0.051, `${name}: unshaded ${unshaded} vs API ${api.unshaded[i]}`);
    assert.ok(Math.abs(Number(sky) - api.sky[i]) <= 0.05 + 0.002 * api.sky[i], `${name}: sky ${sky} vs API ${api.sky[i]}`);
    assert.ok(Math.abs(Number(ground) - api.ground[i]) <= 0.051, `${name}: ground ${ground} vs API ${api.ground[i]}`);
    assert.ok(Math.abs(Number(total) - api.total[i]) <= 0.05 + 0.002 * api.total[i], `${name}: total ${total} vs API ${api.total[i]}`);
    assert.ok(Math.abs(api.total[i] - api.irradiation[i] - api.sky[i] - api.ground[i]) <= 1e-6 * api.total[i], `${name}: total is the sum`);
  });
  assert.ok(api.irradiation.some((v) => v > 100), 'the year has sun on it');

  // Colour by (total) irradiation: the legend's title and top tick (the most irradiated surface),
  // and the view changes.
  const byMean = await page.locator('#view').screenshot();
  assert.match(await page.textContent('#legendtitle'), /mean sunlit fraction/);
  assert.deepEqual(await page.$$eval('#legendticks span', (s) => s.map((x) => x.textContent)), ['0', '0.25', '0.5', '0.75', '1']);
  await page.selectOption('#colourby', 'irradiation');
  assert.match(await page.textContent('#legendtitle'), /irradiation, kWh\/m²/);
  const ticks = await page.$$eval('#legendticks span', (s) => s.map((x) => Number(x.textContent)));
  const top = Math.max(...api.total);
  assert.ok(Math.abs(ticks[4] - top) <= 1 + 0.002 * top, `legend top ${ticks[4]} vs the largest total irradiation ${top}`);
  assert.ok(Math.abs(ticks[2] - top / 2) <= 1 + 0.002 * top);
  const byIrradiation = await page.locator('#view').screenshot();
  assert.notDeepEqual(byIrradiation, byMean, 'the 3D view is recoloured');
  await page.locator('.results').screenshot({ path: join(ARTIFACTS, 'page-irradiation.png') });
  await page.selectOption('#colourby', 'mean');

  // Without the EPW the fields are the user's again, and a year without one has no columns.
  await page.setInputFiles('#epw', []);
  assert.equal(await page.evaluate(() => document.getElementById('latitude').readOnly), false);
  await page.fill('#latitude', SETTINGS.latitude);
  await page.fill('#longitude', SETTINGS.longitude);
  await page.fill('#timezone', SETTINGS.timezone);
  assert.match(await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 300_000), /^Done/);
  assert.equal(await page.locator('#table thead th:not([hidden])').count(), 3);
  assert.equal(await page.isDisabled('#colourby option[value=irradiation]'), true);
});

test('a GPU device lost during a computation: the worker counts again on a new one, with the same result', { timeout: 600_000 }, async () => {
  assert.match(await statusAfter(() => page.setInputFiles('#model', EXAMPLE), /^Loaded|^Could not/), /^Loaded office\.glb/);
  await page.fill('#days', '14');
  await page.fill('#perday', '9');
  await page.selectOption('#timesteps', '1');
  const csv = async (name) => {
    const download = page.waitForEvent('download');
    await page.click('#download');
    const file = join(WORK, name);
    await (await download).saveAs(file);
    return parseCsv(readFileSync(file, 'utf8'));
  };
  // The worker's devices, as wgpu opens them (the engine is made again for a new resolution).
  const [worker] = page.workers();
  assert.ok(worker, 'the page runs its engine in a worker');
  await worker.evaluate(() => {
    self.devices = [];
    const request = GPUAdapter.prototype.requestDevice;
    GPUAdapter.prototype.requestDevice = async function (...args) {
      const device = await request.apply(this, args);
      self.devices.push(device);
      return device;
    };
  });
  await page.fill('#resolution', '80');
  // The loss of a device is the pixel engine's failure: auto would clip this light model exactly.
  await page.selectOption('#engine', 'gpu');
  assert.match(await statusAfter(() => page.click('#compute'), /^Done|^Could not/, 300_000), /^Done/);
  const clean = await csv('clean.csv');
  assert.equal(await worker.evaluate(() => self.devices.length), 1, 'one device for the new resolution');

  // Every status line, to see the notice the retry gives.
  await page.evaluate(() => {
    window.statuses = [];
    new MutationObserver(() => window.statuses.push(document.getElementById('status').textContent)).observe(document.getElementById('status'), {
      childList: true,
      characterData: true,
      subtree: true,
    });
  });
  const done = await statusAfter(async () => {
    await page.click('#compute');
    await waitForStatus(/^Counting views: [1-9]/);
    await worker.evaluate(() => self.devices.at(-1).destroy());
  }, /^Done|^Could not/, 300_000);
  assert.match(done, /^Done/);
  const statuses = await page.evaluate(() => window.statuses);
  assert.ok(statuses.some((t) => /^The GPU device failed \(.*\); counting again on a new one/.test(t)), `the retry is told: ${statuses.filter((t) => !/^Counting/.test(t))}`);
  assert.equal(await worker.evaluate(() => self.devices.length), 2, 'a second device was opened');
  assert.equal(await page.isHidden('#retry'), true);
  const recovered = await csv('recovered.csv');
  assert.deepEqual(recovered.header, clean.header);
  let worst = 0;
  recovered.rows.forEach((row, r) => row.slice(1).forEach((v, c) => (worst = Math.max(worst, Math.abs(Number(v) - Number(clean.rows[r][c + 1]))))));
  console.log(`after a device loss: max |Δ| ${worst} against the uninterrupted year`);
  assert.ok(worst <= 1e-6, `the recovered year equals the uninterrupted one (max |Δ| ${worst})`);
});

test('no request left the origin and no script error happened', () => {
  const outside = requests.filter((u) => !u.startsWith(origin) && !u.startsWith('blob:') && !u.startsWith('data:'));
  assert.deepEqual(outside, []);
  assert.ok(requests.length > 5, 'requests were seen');
  assert.deepEqual(pageErrors, []);
});
