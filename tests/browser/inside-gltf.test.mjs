// A glTF model's rooms in the page (headless Chromium, driven by Playwright) against the native
// library through the CLI: the box room as a .gltf (node `Room`, its closed shell; node `Glass`,
// the pane, whose material's extras give a transmittance curve), mapped in Map mode with "Inside
// rooms", Rooms `Room` and Glazing `Glass` (engine.map's `interior` and `glazing`). At an instant,
// over a day under an EPW and for LEED ASE, the page's points CSV equals `sunlit map room.gltf
// --inside --interior Room --glazing Glass` byte for byte, and its sun patches and rooms' shares
// the CLI's JSON. A period's progress, as the worker reports it, reaches its total; a long period
// cancelled after its first progress leaves nothing (no map drawn, nothing to download), and the
// next map runs. Through the JS API in the page: the inside scene kept on the model is made
// again when the work plane or the rooms change, and bad rooms are refused naming the option.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, closePage, downloadText, servePage, setMapSliders, statusAfter, waitForStatus } from './pagetest.mjs';
import { goldenEpw, roomGltf, roomIdf } from './room.mjs';

const WORK = join(tmpdir(), `sunlit-inside-gltf-${process.pid}`);
const LOCATION = { latitude: '39.74', longitude: '-105.18', timezone: '-7' };
const GRID = '0.25';
// A measured pane's curve (docs/maps.md): the beam's weight depends on its angle on the glass.
const CURVE = { transmittance_curve: [[0, 0.8], [30, 0.78], [50, 0.72], [70, 0.5]], visible_transmittance: 0.75 };
const ROOMS = ['--inside', '--interior', 'Room', '--glazing', 'Glass'];

let served;
let page;
let pageErrors;
let model;
let epw;

before(async () => {
  served = await servePage(WORK);
  ({ page, pageErrors } = served);
  // Records what the page's worker sends back for maps: progress, answers, errors.
  await page.addInitScript(() => {
    const PageWorker = globalThis.Worker;
    globalThis.replies = [];
    globalThis.Worker = class extends PageWorker {
      constructor(...args) {
        super(...args);
        this.addEventListener('message', ({ data }) => {
          if (data?.type === 'progress') replies.push({ type: 'progress', done: data.done, total: data.total });
          if (data?.type === 'mapResult') replies.push({ type: 'mapResult', instants: data.map.instants });
          if (data?.type === 'error') replies.push({ type: 'error', cancelled: data.cancelled, request: data.request });
        });
      }
    };
  });
  model = join(WORK, 'room.gltf');
  writeFileSync(model, roomGltf(CURVE));
  epw = join(WORK, 'golden.epw');
  writeFileSync(epw, goldenEpw());
});

after(() => closePage(served, WORK));

/** The worker's replies since the last call. */
const replies = () => page.evaluate(() => globalThis.replies.splice(0));

/** A fresh page with the glTF room loaded, the site given, Map mode with its rooms and glazing
 * marked at `grid`. */
async function roomInMapMode(grid) {
  await page.goto(`${served.origin}/`);
  await waitForStatus(page, /^Ready/);
  assert.match(await statusAfter(page, () => page.setInputFiles('#model', model), /^Loaded|^Could not/), /^Loaded room\.gltf/);
  await page.fill('#latitude', LOCATION.latitude);
  await page.fill('#longitude', LOCATION.longitude);
  await page.fill('#timezone', LOCATION.timezone);
  await page.selectOption('#mode', 'map');
  await page.fill('#mapgrid', grid);
  await page.check('#mapinside');
  await page.fill('#mapinterior', 'Room');
  await page.fill('#mapglazing', 'Glass');
  await replies();
}

/** `sunlit map room.gltf --inside --interior Room --glazing Glass FLAGS --grid 0.25`: its JSON
 * summary and its points CSV. */
function native(flags) {
  const csv = join(WORK, 'native.csv');
  const args = ['map', model, ...ROOMS, ...flags, '--grid', GRID, '--json', '-o', csv];
  const summary = JSON.parse(execFileSync(join(ROOT, 'target/debug/sunlit'), args, { cwd: ROOT, env: { ...process.env, XDG_RUNTIME_DIR: WORK } }));
  return { summary, csv: readFileSync(csv, 'utf8') };
}

/** The progress the worker reported for one map: every report counts up to the same total, the
 * last reaches it, and that total is the map's instants; returns them. */
function assertProgressReachesTotal(got) {
  const answers = got.filter((r) => r.type === 'mapResult');
  assert.equal(answers.length, 1, 'one map came back');
  const { instants } = answers[0];
  const progress = got.filter((r) => r.type === 'progress');
  assert.ok(progress.length >= 2, `progress between chunks: ${progress.length} reports`);
  assert.ok(progress.every((p, i) => p.total === instants && (i === 0 || p.done > progress[i - 1].done)), JSON.stringify(progress.slice(0, 5)));
  assert.equal(progress.at(-1).done, instants, 'the last report is the total');
  return instants;
}

test('a glTF room in the page: at an instant, over a day and for LEED ASE its CSV is `sunlit map --inside --interior --glazing`\'s', { timeout: 600_000 }, async () => {
  await roomInMapMode(GRID);
  await page.selectOption('#mapperiod', 'instant');
  await setMapSliders(page, 355, 13);
  await page.fill('#mapworkplane', '0');
  const done = await statusAfter(page, () => page.click('#compute'), /^Map in|^Could not/, 240_000);
  // At an instant the grid covers every inside face (--faces): the floor's 320 points and the
  // other five faces'.
  assert.match(done, /^Map in .*: 1,456 points on 6 receivers; \d+ in the sun; sun patches: .*Room#\d+:inside \d/);
  const at = native(['--at', '12-21', '13:00', '--faces', '--location', `${LOCATION.latitude},${LOCATION.longitude},${LOCATION.timezone}`]);
  const web = await downloadText(page, '#downloadmap', join(WORK, 'web-at.csv'));
  assert.equal(web.text, at.csv, 'the page\'s points CSV is the CLI\'s, byte for byte');
  const rows = at.csv.trim().split('\n').slice(1).map((l) => l.split(','));
  const lit = rows.filter((r) => r.at(-3) === '1');
  assert.equal(Number(await page.getAttribute('#view', 'data-lit')), at.summary.lit_points);
  assert.ok(lit.length > 20 && lit.length < 300, `the beam lights part of the room: ${lit.length} of 1,456 points`);
  // The pane's material gives the glass: a lit point's weight is the curve's at the beam's angle.
  const solar = new Set(lit.map((r) => r.at(-2)));
  assert.equal(solar.size, 1, 'one pane, one angle');
  assert.ok(Number([...solar][0]) > 0.5 && Number([...solar][0]) < 0.8, `the curve's weight below its normal 0.8: ${[...solar][0]}`);
  const patches = JSON.parse(await page.getAttribute('#view', 'data-patches'));
  assert.deepEqual(patches.map((p) => [p.surface, p.zone]), at.summary.sun_patches.map((p) => [p.surface, p.zone]));
  patches.forEach((p, i) => {
    const n = at.summary.sun_patches[i];
    assert.ok(Math.abs(p.areaM2 - n.area_m2) < 1e-5 && Math.abs(p.fraction - n.fraction) < 1e-5, `${p.surface}: ${p.areaM2} m² against ${n.area_m2} m²`);
  });

  // Over a day under the EPW: the beam through the glass, summed in chunks with progress.
  await page.setInputFiles('#epw', epw);
  await page.fill('#mapworkplane', '');
  await page.selectOption('#mapperiod', 'day');
  await page.fill('#mapstart', '12-21');
  await page.fill('#mapstep', '10');
  await page.fill('#mapfrom', '08:00');
  await page.fill('#mapto', '16:00');
  await page.selectOption('#mapvalue', 'direct');
  await replies();
  const period = await statusAfter(page, () => page.click('#compute'), /^Map in|^Could not/, 240_000);
  const instants = assertProgressReachesTotal(await replies());
  assert.match(period, new RegExp(`^Map in .*: 320 points on 1 receivers; Direct irradiation from 0\\.00 to \\d.* over ${instants} instants`));
  assert.ok(instants >= 48, `every 10 minutes from 08:00 to 16:00: ${instants} instants`);
  const day = native(['--epw', epw, '--period', '12-21', '--step', '10', '--from', '08:00', '--to', '16:00']);
  assert.match(day.csv.split('\n')[0], /,sun_hours,beam_kwh_m2,direct_klux_h$/);
  assert.equal((await downloadText(page, '#downloadmap', join(WORK, 'web-day.csv'))).text, day.csv, 'the day\'s CSV is the CLI\'s, byte for byte');

  await page.selectOption('#mapinsidestudy', 'leed-ase');
  const ase = await statusAfter(page, () => page.click('#compute'), /^Map in|^Could not/, 400_000);
  assert.match(ase, /^Map in .*: 320 points on 1 receivers; Occupied hours over 1000 lux of direct sun .* over 3,650 instants; Room \d+(\.\d)? %\.$/);
  assert.equal(assertProgressReachesTotal(await replies()), 3650);
  const year = native(['--epw', epw, '--study', 'leed-ase']);
  assert.match(year.csv.split('\n')[1], /^Room#\d+:work-plane,/, 'the grid lies on the work plane (0.76 m, the study\'s)');
  assert.equal((await downloadText(page, '#downloadmap', join(WORK, 'web-ase.csv'))).text, year.csv, 'the ASE CSV is the CLI\'s, byte for byte');
  const areas = JSON.parse(await page.getAttribute('#view', 'data-areas'));
  const expected = year.summary.studies[0].areas;
  assert.deepEqual(areas.map((a) => [a.zone, a.points]), expected.map((a) => [a.zone, a.points]));
  areas.forEach((a, i) => assert.ok(Math.abs(a.ase - expected[i].ase) < 1e-3, `${a.zone}: ASE ${a.ase} % against ${expected[i].ase} %`));
  assert.ok(expected[0].ase > 0 && expected[0].ase < 100, `ASE between 0 and 100 %: ${expected[0].ase}`);
  assert.deepEqual(pageErrors, []);
});

test('an inside period cancelled after its first progress leaves nothing, and the next map runs', { timeout: 600_000 }, async () => {
  // The whole year's sun hours on a 5 cm grid: 8,000 points over 8,760 instants, long enough
  // to be cancelled between chunks.
  await roomInMapMode('0.05');
  await page.selectOption('#mapperiod', 'annual');
  await page.selectOption('#mapvalue', 'sunHours');
  await page.click('#compute');
  await page.waitForFunction(() => globalThis.replies.some((r) => r.type === 'progress'), null, { timeout: 240_000 });
  const cancelled = await statusAfter(page, () => page.click('#cancel'), /^Cancelled|^Map in|^Could not/, 240_000);
  assert.equal(cancelled, 'Cancelled.');
  const got = await replies();
  const progress = got.filter((r) => r.type === 'progress');
  assert.ok(progress.at(-1).done < progress.at(-1).total, `stopped before the end: ${progress.at(-1).done} of ${progress.at(-1).total}`);
  assert.deepEqual(got.filter((r) => r.type !== 'progress'), [{ type: 'error', cancelled: true, request: 'map' }], 'no map came back');
  assert.equal(await page.getAttribute('#view', 'data-cells'), null, 'no cells drawn');
  assert.ok((await page.isDisabled('#downloadmap')) && (await page.isDisabled('#downloadglb')), 'nothing to download');
  // The worker is free again, and its kept inside scene answers the next map.
  await page.selectOption('#mapperiod', 'instant');
  await setMapSliders(page, 355, 13);
  const next = await statusAfter(page, () => page.click('#compute'), /^Map in|^Could not/, 240_000);
  assert.match(next, /^Map in .*: 36,400 points on 6 receivers; [\d,]+ in the sun/);
  assert.deepEqual(pageErrors, []);
});

test('engine.map in the page: the kept inside scene follows the work plane and the rooms; bad rooms are refused naming the option', { timeout: 300_000 }, async () => {
  const got = await page.evaluate(async ({ gltf, idf }) => {
    const sunlit = await import('/sunlit.js');
    const engine = await sunlit.createEngine({ engine: 'exact' });
    const bytes = new TextEncoder().encode(gltf);
    const room = engine.loadFiles([{ name: 'room.gltf', bytes }]);
    const site = { latitude: 39.74, longitude: -105.18, timeZone: -7, at: '12-21 13:00', grid: 0.5, inside: true, interior: 'Room', glazing: 'Glass', glassTransmittance: 0.6 };
    const heights = async (extra) => {
      const map = await engine.map(room, { ...site, ...extra });
      return [...new Set(Array.from(map.points).filter((_, i) => i % 3 === 2).map((z) => z.toFixed(3)))];
    };
    const out = { heights: [await heights({}), await heights({ workPlane: 0.76 }), await heights({})] };
    // The pane left as a caster: no glazing marked, the window is glass no more but a wall.
    const shut = await engine.map(room, { ...site, glazing: undefined });
    const open = await engine.map(room, site);
    out.lit = [open, shut].map((m) => m.values.reduce((n, v) => n + v, 0));
    const refused = async (model, options) => {
      try {
        await engine.map(model, { ...site, ...options });
        return null;
      } catch (e) {
        return { code: e.code, option: e.option, message: e.message };
      }
    };
    const zones = engine.loadFiles([{ name: 'room.idf', bytes: new TextEncoder().encode(idf) }]);
    const arrays = engine.fromArrays({ positions: [0, 0, 0, 1, 0, 0, 0, 1, 0], indices: [0, 1, 2], triangleReceivers: [0], names: ['Tri'] });
    out.errors = {
      unmatched: await refused(room, { glazing: 'Pane*' }),
      noRoom: await refused(room, { interior: 'Glass', glazing: undefined }),
      glass: await refused(room, { glassTransmittance: 1.5 }),
      zones: await refused(zones, {}),
      arrays: await refused(arrays, {}),
      noInterior: await refused(room, { interior: undefined, glazing: undefined }),
    };
    engine.close();
    return out;
  }, { gltf: roomGltf(), idf: roomIdf() });
  assert.deepEqual(got.heights, [['0.000'], ['0.760'], ['0.000']], 'the floor, the work plane, the floor again');
  assert.ok(got.lit[0] > 0 && got.lit[1] === 0, `lit through the opening ${got.lit[0]}, with the pane a caster ${got.lit[1]}`);
  const { errors } = got;
  assert.deepEqual([errors.unmatched.code, errors.unmatched.option], ['bad-option', 'glazing']);
  assert.match(errors.unmatched.message, /Pane\*/);
  assert.match(errors.noRoom.message, /Glass.*not a closed room/);
  // Without a material's glass, the pane takes glassTransmittance, refused outside 0..1.
  assert.deepEqual([errors.glass.option, /1\.5/.test(errors.glass.message)], ['glassTransmittance', true]);
  assert.match(errors.zones.message, /EnergyPlus model's zones are its rooms/);
  assert.deepEqual([errors.arrays.option, errors.noInterior.option], ['interior', 'inside']);
  assert.deepEqual(pageErrors, []);
});
