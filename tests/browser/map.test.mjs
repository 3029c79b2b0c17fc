// Per-point maps in the browser (headless Chromium, driven by Playwright), against the native
// library through the CLI (`sunlit map`) on the same model and options: the page's Map mode draws
// a day of sun hours on a grid over the example office and downloads a points CSV whose rows
// parse and equal the CLI's; its day/time slider maps instants (lit or not per point) equal to
// `sunlit map --at`, and moving it moves the shadow; engine.map through the JS API returns typed
// arrays, its direct irradiation under an EPW equals the CLI's, and bad options are refused naming
// the option. The map is saved to target/artifacts/map.png for a person to look at.
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, closePage, downloadText, servePage, setMapSliders, statusAfter as statusAfterOn, sunlit, waitForStatus as statusIs } from './pagetest.mjs';
import { SYDNEY, syntheticEpw } from './epw.mjs';

const EXAMPLE = join(ROOT, 'www/pkg/office.glb');
const ARTIFACTS = join(ROOT, 'target/artifacts');
const WORK = join(tmpdir(), `sunlit-map-${process.pid}`);
const LOCATION = { latitude: '39.74', longitude: '-105.18', timezone: '-7' };
const GRID = '1';

let served;
let page;
let pageErrors;

before(async () => {
  served = await servePage(WORK);
  ({ page, pageErrors } = served);
  // Records what the page's worker sends back for maps: a map's answer, and a map's file.
  await page.addInitScript(() => {
    const PageWorker = globalThis.Worker;
    globalThis.mapReplies = [];
    globalThis.Worker = class extends PageWorker {
      constructor(...args) {
        super(...args);
        this.addEventListener('message', ({ data }) => {
          if (data?.type === 'mapResult') mapReplies.push({ type: data.type, kind: data.tag.kind, keys: Object.keys(data.map).filter((k) => data.map[k] !== undefined) });
          if (data?.type === 'mapFile') mapReplies.push({ type: data.type, kind: data.kind });
        });
      }
    };
  });
  await page.goto(`${served.origin}/`);
  await waitForStatus(/^Ready/);
});

after(() => closePage(served, WORK));

const waitForStatus = (pattern, timeout) => statusIs(page, pattern, timeout);
const statusAfter = (action, pattern, timeout) => statusAfterOn(page, action, pattern, timeout);

/** `sunlit map` on the example office; its points CSV as text. */
function nativeMap(name, args) {
  const out = join(WORK, `${name}.csv`);
  sunlit(['map', EXAMPLE, '--grid', GRID, ...args, '-o', out], WORK);
  return readFileSync(out, 'utf8');
}

function parseCsv(text) {
  const lines = text.trim().split(/\r?\n/);
  return { header: lines[0].split(','), rows: lines.slice(1).map((l) => l.split(',')) };
}

/** The page's CSV against the CLI's: same header, same points in the same order (to the CSV's
 * 4 decimals), each value column within `tolerance`; returns the worst difference per column. */
function compare(webText, nativeText, tolerance) {
  const web = parseCsv(webText);
  const native = parseCsv(nativeText);
  assert.deepEqual(web.header, native.header);
  assert.equal(web.rows.length, native.rows.length, 'as many points');
  const worst = {};
  web.rows.forEach((row, i) => {
    const n = native.rows[i];
    assert.equal(row.length, web.header.length, `row ${i + 1} has every column`);
    assert.equal(row[0], n[0], `row ${i + 1}: receiver`);
    for (let c = 1; c < 7; c++) assert.ok(Math.abs(Number(row[c]) - Number(n[c])) <= 1e-4, `row ${i + 1} ${web.header[c]}: ${row[c]} vs ${n[c]}`);
    for (let c = 7; c < row.length; c++) {
      assert.ok(Number.isFinite(Number(row[c])), `row ${i + 1}: ${row[c]} is a number`);
      const d = Math.abs(Number(row[c]) - Number(n[c]));
      worst[web.header[c]] = Math.max(worst[web.header[c]] ?? 0, d);
      assert.ok(d <= tolerance, `row ${i + 1} ${web.header[c]}: page ${row[c]}, CLI ${n[c]}`);
    }
  });
  return { worst, rows: web.rows };
}

async function downloadMap(name) {
  return (await downloadText(page, '#downloadmap', join(WORK, name))).text;
}

/** The worker's map replies since the last call. */
async function mapReplies() {
  return page.evaluate(() => globalThis.mapReplies.splice(0));
}

const setSlider = (day, hour) => setMapSliders(page, day, hour);

test('the Map mode: a day of sun hours on a 1 m grid is drawn, and its points CSV equals `sunlit map`', { timeout: 300_000 }, async () => {
  assert.match(await statusAfter(() => page.setInputFiles('#model', EXAMPLE), /^Loaded|^Could not/), /^Loaded office\.glb/);
  await page.fill('#latitude', LOCATION.latitude);
  await page.fill('#longitude', LOCATION.longitude);
  await page.fill('#timezone', LOCATION.timezone);
  await page.selectOption('#mode', 'map');
  assert.equal(await page.isVisible('#days'), false, 'the year\'s sampling is hidden in Map mode');
  await page.fill('#mapgrid', GRID);
  await page.selectOption('#mapvalue', 'sunHours');
  await page.selectOption('#mapperiod', 'day');
  await page.fill('#mapstart', '03-21');
  await page.fill('#mapstep', '10');
  await page.fill('#mapfrom', '06:00');
  await page.fill('#mapto', '18:00');
  const done = await statusAfter(() => page.click('#compute'), /^Map in|^Could not/, 240_000);
  assert.match(done, /^Map in [\d.]+ s \(period\): [\d,]+ points on \d+ receivers; Sun hours from/);
  const cells = Number(await page.getAttribute('#view', 'data-cells'));
  assert.ok(cells > 50, `cells drawn: ${cells}`);
  assert.match(await page.textContent('#legend'), /Sun hours, h per point/);
  await page.locator('.results').screenshot({ path: join(ARTIFACTS, 'map.png') });

  const csv = await downloadMap('day.csv');
  const native = nativeMap('day', ['--location', `${LOCATION.latitude},${LOCATION.longitude},${LOCATION.timezone}`, '--period', '03-21', '--step', '10', '--from', '06:00', '--to', '18:00']);
  const { worst, rows } = compare(csv, native, 1e-3);
  assert.equal(rows.length, cells);
  const hours = rows.map((r) => Number(r.at(-1)));
  console.log(`map: ${rows.length} points, sun hours ${Math.min(...hours)}..${Math.max(...hours)} on 21 March; page vs CLI worst |Δ| ${JSON.stringify(worst)}`);
  assert.ok(Math.max(...hours) > 5 && hours.some((h) => h < Math.max(...hours) - 0.5), 'some points are shaded for part of the day');
});

test('the Map mode\'s day/time slider maps each instant: lit points equal `sunlit map --at`, and the shadow moves', { timeout: 300_000 }, async () => {
  await page.selectOption('#mapperiod', 'instant');
  await mapReplies();
  await setSlider(80, 9.5);
  const done = await statusAfter(() => page.click('#compute'), /^Map in|^Could not/, 120_000);
  assert.match(done, /^Map in [\d.]+ s \(instant\): [\d,]+ points on \d+ receivers; [\d,]+ in the sun/);
  assert.equal(await page.getAttribute('#view', 'data-at'), '80,9.5');
  const morning = Number(await page.getAttribute('#view', 'data-lit'));
  const csv = await downloadMap('morning.csv');
  const native = nativeMap('morning', ['--location', `${LOCATION.latitude},${LOCATION.longitude},${LOCATION.timezone}`, '--at', '03-21', '09:30']);
  // Every point lit or not as the CLI says.
  const { rows } = compare(csv, native, 0);
  assert.equal(parseCsv(csv).header.at(-1), 'lit');
  assert.ok(rows.every((r) => r.at(-1) === '0' || r.at(-1) === '1'), 'lit is 0 or 1');
  assert.equal(rows.filter((r) => r.at(-1) === '1').length, morning);
  // The slider alone (no Compute) maps the new instant.
  await setSlider(80, 15.5);
  await page.waitForFunction(() => document.getElementById('view').dataset.at === '80,15.5', null, { timeout: 60_000 });
  const afternoon = Number(await page.getAttribute('#view', 'data-lit'));
  const later = parseCsv(await downloadMap('afternoon.csv')).rows.map((r) => r.at(-1));
  const moved = later.filter((v, i) => v !== rows[i].at(-1)).length;
  console.log(`map: 21 March 09:30 ${morning} of ${rows.length} points lit, 15:30 ${afternoon}; ${moved} changed`);
  assert.ok(moved >= rows.length / 20, `the shadow moves between 09:30 and 15:30 (${moved} of ${rows.length} points changed)`);
  await setSlider(80, 2);
  await page.waitForFunction(() => document.getElementById('view').dataset.at === '80,2', null, { timeout: 60_000 });
  assert.equal(await page.getAttribute('#view', 'data-lit'), '0', 'at night nothing is lit');
  // The slider's moves ask only for what the view draws: no map answer carries the points CSV or
  // the map glb; the worker writes a file only when a download asks (one CSV per download above).
  const replies = await mapReplies();
  const maps = replies.filter((r) => r.type === 'mapResult');
  assert.ok(maps.length >= 3, `the Compute and the slider's moves were mapped (${maps.length})`);
  for (const r of maps) assert.deepEqual(r.keys.filter((k) => ['csv', 'glb', 'files'].includes(k)), [], `a ${r.kind} map's answer carries no files`);
  assert.deepEqual(replies.filter((r) => r.type === 'mapFile').map((r) => r.kind), ['csv', 'csv'], 'a file only for each download');
  // The glb, on demand: the map shown's, with the glb magic.
  const download = page.waitForEvent('download');
  await page.click('#downloadglb');
  const glb = join(WORK, 'night.glb');
  await (await download).saveAs(glb);
  assert.equal(readFileSync(glb).subarray(0, 4).toString('latin1'), 'glTF');
});

test('engine.map: typed arrays; direct irradiation under an EPW equals `sunlit map --epw`; bad options are refused naming them', { timeout: 300_000 }, async () => {
  const epw = syntheticEpw(SYDNEY);
  const epwPath = join(WORK, 'sydney.epw');
  writeFileSync(epwPath, epw);
  const api = await page.evaluate(async ({ text, grid }) => {
    const sunlit = await import('/sunlit.js');
    const engine = await sunlit.createEngine({ resolution: 64 });
    const bytes = new Uint8Array(await (await fetch('/pkg/office.glb')).arrayBuffer());
    const model = engine.loadFiles([{ name: 'office.glb', bytes }]);
    const map = await engine.map(model, { epw: text, epwName: 'sydney.epw', grid: Number(grid), period: '12-01..12-07', value: 'direct' }, { csv: true, glb: true });
    const kinds = ['points', 'normals', 'receivers', 'values'].map((k) => map[k].constructor.name);
    const refused = async (options) => {
      try {
        await engine.map(model, options);
        return null;
      } catch (e) {
        return { code: e.code, option: e.option, message: e.message };
      }
    };
    const where = { latitude: 40, longitude: -105, timeZone: -7 };
    const errors = {
      grid: await refused({ ...where, grid: 0 }),
      period: await refused({ ...where, period: '02-30' }),
      from: await refused({ ...where, period: '03-21', from: '15:00', to: '09:00' }),
      step: await refused({ ...where, period: '03-21', step: 7 }),
      value: await refused({ ...where, value: 'direct' }),
      lit: await refused({ ...where, value: 'lit' }),
      points: await refused({ ...where, points: [0, 0, 100, 0, 0, 1] }),
      normal: await refused({ ...where, points: [0, 0, 0, 0, 0, 0] }),
    };
    // The files on demand (files: true) are those asked for up front; freed, they are refused.
    const kept = await engine.map(model, { epw: text, epwName: 'sydney.epw', grid: Number(grid), period: '12-01..12-07', value: 'direct' }, { files: true });
    const glbLater = kept.files.glb();
    const onDemand = {
      csv: kept.files.csv() === map.csv,
      glb: glbLater.length === map.glb.length && glbLater.every((b, i) => b === map.glb[i]),
      upFront: [kept.csv === undefined, kept.glb === undefined],
    };
    kept.files.free();
    try {
      kept.files.csv();
    } catch (e) {
      onDemand.freed = e.code;
    }
    const same = map.values.every((v, i) => v === map.direct[i]);
    const glb = String.fromCharCode(...map.glb.subarray(0, 4));
    // Total: the values are the total, each the sum of its parts (f32 arrays).
    const total = await engine.map(model, { epw: text, grid: Number(grid), period: '12-01..12-07', value: 'total' });
    const sums = total.values.every((v, i) => v === total.total[i]
      && Math.abs(v - (total.direct[i] + total.skyDiffuse[i] + total.groundReflected[i])) <= 1e-3 * Math.max(1, v));
    const totalOf = { value: total.value, title: total.title, sums, sky: total.skyDiffuse.every((v) => v > 0), views: total.skyViewFactor.every((v) => v > 0 && v <= 1) };
    return { kinds, csv: map.csv, glb, same, onDemand, count: map.values.length, max: map.max, value: map.value, unit: map.unit, instants: map.instants, errors, totalOf };
  }, { text: epw, grid: GRID });
  assert.deepEqual(api.kinds, ['Float32Array', 'Float32Array', 'Uint32Array', 'Float32Array']);
  assert.deepEqual([api.value, api.unit, api.instants], ['direct', 'kWh/m²', 7 * 24]);
  assert.equal(api.glb, 'glTF', 'the map glb has the glb magic');
  assert.deepEqual(api.onDemand, { csv: true, glb: true, upFront: [true, true], freed: 'freed' }, 'files on demand are the files asked for up front');
  assert.ok(api.same, 'values are the direct irradiation asked for');
  assert.deepEqual(api.totalOf, { value: 'total', title: 'Total irradiation', sums: true, sky: true, views: true }, 'value total: the sum of its parts');
  const native = nativeMap('direct', ['--epw', epwPath, '--period', '12-01..12-07']);
  // The CLI's columns: sun_hours and, with an EPW, the irradiation's parts and the sky view
  // factor; the API's CSV is the same (every column compared below).
  assert.deepEqual(parseCsv(native).header.slice(7), [
    'sun_hours', 'direct_kwh_m2', 'sky_diffuse_kwh_m2', 'ground_reflected_kwh_m2', 'total_kwh_m2', 'sky_view_factor',
  ]);
  const { worst } = compare(api.csv, native, 1e-3);
  console.log(`engine.map: ${api.count} points, direct up to ${api.max.toFixed(2)} kWh/m² over a week of Sydney's summer; vs CLI worst |Δ| ${JSON.stringify(worst)}`);
  assert.ok(api.max > 1, 'a week of summer sun');
  const { errors } = api;
  for (const [name, option] of [['grid', 'grid'], ['period', 'period'], ['from', 'from'], ['step', 'step'], ['value', 'value'], ['lit', 'value']]) {
    assert.equal(errors[name]?.code, 'bad-option', `${name}: ${JSON.stringify(errors[name])}`);
    assert.equal(errors[name].option, option, `${name}: ${errors[name].message}`);
  }
  assert.match(errors.points.message, /lies on no chosen receiver/);
  assert.match(errors.normal.message, /zero length/);
  assert.deepEqual(pageErrors, []);
});
