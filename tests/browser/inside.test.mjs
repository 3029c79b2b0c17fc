// The page's interior view (headless Chromium, driven by Playwright) against the native library
// through the CLI: on a box room (an EnergyPlus model: one zone, one south window), Map mode at
// an instant with "Inside rooms" maps a grid on every inside face; its points CSV equals `sunlit
// map --inside --faces --at` byte for byte, its lit count and each inside face's sun patch equal
// the CLI's JSON summary; the patch the view draws on each face (its lit cells) matches the CLI's
// exact patch area within half a cell along the drawn patch's outline, at 13:00 (floor, east and
// north walls) and 15:00 (the east wall); cutting away the roof or the south wall takes exactly
// those faces out of the 3D view, and cutting the east wall its cells. The view is saved to target/artifacts/inside.png for a person to look at. Over a period
// (the beam through the glass under an EPW) and for LEED ASE (`study: 'leed-ase'`), the page's
// CSV equals `sunlit map --inside --period` and `--study leed-ase` byte for byte, and each room's
// ASE the CLI's.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, closePage, downloadText, servePage, setMapSliders, statusAfter, waitForStatus } from './pagetest.mjs';
import { goldenEpw, roomIdf } from './room.mjs';

const WORK = join(tmpdir(), `sunlit-inside-${process.pid}`);
const LOCATION = { latitude: '39.74', longitude: '-105.18', timezone: '-7' };
// 21 December (day 355), 13:00 local standard time: the beam through the window lands on the floor.
const DAY = 355;
const HOUR = 13;
const GRID = '0.25';

let served;
let page;
let pageErrors;
let model;

before(async () => {
  served = await servePage(WORK);
  ({ page, pageErrors } = served);
  model = join(WORK, 'room.idf');
  writeFileSync(model, roomIdf());
  await page.goto(`${served.origin}/`);
  await waitForStatus(page, /^Ready/);
});

after(() => closePage(served, WORK));

/** `sunlit map --inside --faces --at` on the room at `hour`: its JSON summary and its points CSV. */
function nativeInside(hour = HOUR) {
  const csv = join(WORK, 'native.csv');
  const at = `${hour}:00`.padStart(5, '0');
  const args = ['map', model, '--inside', '--faces', '--at', '12-21', at, '--grid', GRID, '--json', '-o', csv];
  args.push('--location', `${LOCATION.latitude},${LOCATION.longitude},${LOCATION.timezone}`);
  const summary = JSON.parse(execFileSync(join(ROOT, 'target/debug/sunlit'), args, { cwd: ROOT, env: { ...process.env, XDG_RUNTIME_DIR: WORK } }));
  return { summary, csv: execFileSync('cat', [csv], { encoding: 'utf8' }) };
}

test('the interior view: the floor\'s sun patch at an instant equals `sunlit map --inside --at`, and the view cuts away a roof or a wall', { timeout: 300_000 }, async () => {
  assert.match(await statusAfter(page, () => page.setInputFiles('#model', model), /^Loaded|^Could not/), /^Loaded room\.idf/);
  await page.fill('#latitude', LOCATION.latitude);
  await page.fill('#longitude', LOCATION.longitude);
  await page.fill('#timezone', LOCATION.timezone);
  await page.selectOption('#mode', 'map');
  await page.fill('#mapgrid', GRID);
  await page.selectOption('#mapperiod', 'instant');
  await setMapSliders(page, DAY, HOUR);
  await page.check('#mapinside');
  await page.fill('#mapworkplane', '0');
  const done = await statusAfter(page, () => page.click('#compute'), /^Map in|^Could not/, 240_000);
  // The floor's 320 points and the other five faces' (the south wall's around its window).
  assert.match(done, /^Map in .*: 1,456 points on 6 receivers; \d+ in the sun; sun patches: .*Floor:inside \d/);

  const native = nativeInside();
  const web = await downloadText(page, '#downloadmap', join(WORK, 'web.csv'));
  assert.equal(web.text, native.csv, 'the page\'s points CSV is the CLI\'s, byte for byte');
  assert.match(native.csv.split('\n')[0], /,lit,solar_transmittance,visible_transmittance$/);
  const lit = Number(await page.getAttribute('#view', 'data-lit'));
  assert.equal(lit, native.summary.lit_points);
  assert.ok(lit > 20 && lit < 300, `the beam lights part of the room: ${lit} of 1,456 points`);
  const patches = JSON.parse(await page.getAttribute('#view', 'data-patches'));
  assert.deepEqual(patches.map((p) => [p.surface, p.zone]), native.summary.sun_patches.map((p) => [p.surface, p.zone]));
  patches.forEach((p, i) => {
    const n = native.summary.sun_patches[i];
    assert.ok(Math.abs(p.areaM2 - n.area_m2) < 1e-5 && Math.abs(p.fraction - n.fraction) < 1e-5, `${p.surface}: ${p.areaM2} m² against ${n.area_m2} m²`);
  });

  // Cutting away: the roof's two triangles, then the south wall's (around its window) and the
  // window's, leave the view; nothing else does.
  const drawn = async () => Number(await page.getAttribute('#view', 'data-triangles'));
  const whole = await drawn();
  await page.selectOption('#mapcut', 'roof');
  assert.equal(await drawn(), whole - 2, 'the roof (one quad) is cut away');
  await page.selectOption('#mapcut', 'south');
  const south = whole - (await drawn());
  assert.ok(south >= 4, `the south wall with its window's hole and the window go: ${south} triangles`);
  await page.selectOption('#mapcut', 'roof');
  await page.locator('#view').screenshot({ path: join(ROOT, 'target/artifacts/inside.png') });
  assert.deepEqual(pageErrors, []);
});

/** Per face, the lit cells' edges that border no lit cell of the same face (a neighbour unlit,
 * or off the face): the drawn patch's outline, in cells, from the points CSV. */
function outlineEdges(csv, spacing) {
  const lit = csv.trim().split('\n').slice(1).map((l) => l.split(',')).filter((r) => r[7] === '1');
  const out = {};
  for (const r of lit) {
    const p = r.slice(1, 4).map(Number);
    const neighbours = lit.filter((q) => q[0] === r[0] && Math.abs(Math.hypot(...q.slice(1, 4).map((v, k) => Number(v) - p[k])) - spacing) < 1e-3).length;
    out[r[0]] = (out[r[0]] ?? 0) + 4 - neighbours;
  }
  return out;
}

/** The view's drawn sun patch on each face against the CLI's exact one (`sun_patches`): within
 * half a cell along the drawn outline (edges × s² / 2); a face the CLI lights but the view draws
 * nothing on only for a patch under two cells (a sliver between cell centres). */
function assertDrawnMatches(drawn, native, spacing) {
  const edges = outlineEdges(native.csv, spacing);
  const exact = Object.fromEntries(native.summary.sun_patches.map((p) => [p.surface, p.area_m2]));
  for (const face of new Set([...Object.keys(drawn), ...Object.keys(exact)])) {
    const [d, x] = [drawn[face] ?? 0, exact[face] ?? 0];
    if (d === 0) {
      assert.ok(x < 2 * spacing * spacing, `${face}: the CLI's patch ${x} m² is drawn nowhere`);
      continue;
    }
    const tolerance = ((edges[face] ?? 0) * spacing * spacing) / 2;
    assert.ok(Math.abs(d - x) <= tolerance + 1e-4, `${face}: drawn ${d.toFixed(4)} m² against the CLI's ${x} m² (± ${tolerance} m²)`);
  }
}

test('the sun patch drawn on each inside face: its area the CLI\'s `map --inside --at` per face, the east wall lit at 15:00 and cut away with its wall', { timeout: 300_000 }, async () => {
  // The first test's map at 13:00 stands; its cut goes.
  await page.selectOption('#mapcut', '');
  const spacing = Number(GRID);
  const drawnNow = async () => JSON.parse(await page.getAttribute('#view', 'data-drawn-patches'));
  const noon = nativeInside();
  const drawn13 = await drawnNow();
  assert.ok(drawn13['East:inside'] > 0.25 && drawn13['Floor:inside'] > 4, `the floor and the east wall drawn lit at 13:00: ${JSON.stringify(drawn13)}`);
  assertDrawnMatches(drawn13, noon, spacing);

  // The slider to 15:00: the low sun through the window lands on the east wall.
  const moved = await statusAfter(page, () => setMapSliders(page, DAY, 15), /^Map in|^Could not/, 240_000);
  assert.match(moved, /sun patches: .*East:inside \d/);
  const evening = nativeInside(15);
  const web = await downloadText(page, '#downloadmap', join(WORK, 'web-15.csv'));
  assert.equal(web.text, evening.csv, 'the page\'s points CSV at 15:00 is the CLI\'s, byte for byte');
  const drawn15 = await drawnNow();
  const east = evening.summary.sun_patches.find((p) => p.surface === 'East:inside');
  assert.ok(east.area_m2 > 2, `the CLI puts the patch on the east wall: ${east.area_m2} m²`);
  assertDrawnMatches(drawn15, evening, spacing);

  // Cutting away the east wall takes its cells too; the other faces' patches stay as drawn.
  await page.selectOption('#mapcut', 'east');
  const cut = await drawnNow();
  assert.equal(cut['East:inside'], undefined, 'the east wall\'s cells go with it');
  for (const [face, area] of Object.entries(drawn15)) if (face !== 'East:inside') assert.equal(cut[face], area, face);
  // The roof cut away instead: the east wall's patch seen from above (for a person to look at).
  await page.selectOption('#mapcut', 'roof');
  await page.locator('#view').screenshot({ path: join(ROOT, 'target/artifacts/inside-east.png') });
  await page.selectOption('#mapcut', '');
  assert.deepEqual(pageErrors, []);
});

/** `sunlit map` on the room with `flags`: its JSON summary and its points CSV. */
function native(flags) {
  const csv = join(WORK, 'native-inside.csv');
  const args = ['map', model, '--inside', ...flags, '--grid', GRID, '--json', '-o', csv];
  const summary = JSON.parse(execFileSync(join(ROOT, 'target/debug/sunlit'), args, { cwd: ROOT, env: { ...process.env, XDG_RUNTIME_DIR: WORK } }));
  return { summary, csv: readFileSync(csv, 'utf8') };
}

test('the interior over a period and LEED ASE: the page\'s CSV and rooms equal `sunlit map --inside --period` and `--study leed-ase`', { timeout: 600_000 }, async () => {
  const epw = join(WORK, 'golden.epw');
  writeFileSync(epw, goldenEpw());
  // The first test's model and "Inside rooms" stay; the EPW gives the site and the beam.
  await page.setInputFiles('#epw', epw);
  await page.fill('#mapworkplane', '');
  await page.selectOption('#mapperiod', 'day');
  await page.fill('#mapstart', '12-21');
  await page.fill('#mapstep', '10');
  await page.fill('#mapfrom', '08:00');
  await page.fill('#mapto', '16:00');
  await page.selectOption('#mapvalue', 'direct');
  const period = await statusAfter(page, () => page.click('#compute'), /^Map in|^Could not/, 240_000);
  assert.match(period, /^Map in .*: 320 points on 1 receivers; Direct irradiation from 0\.00 to \d/);
  const day = native(['--epw', epw, '--period', '12-21', '--step', '10', '--from', '08:00', '--to', '16:00']);
  const web = await downloadText(page, '#downloadmap', join(WORK, 'web-period.csv'));
  assert.match(day.csv.split('\n')[0], /,sun_hours,beam_kwh_m2,direct_klux_h$/);
  assert.equal(web.text, day.csv, 'the page\'s period CSV is `--inside --period`\'s, byte for byte');
  const beams = day.csv.trim().split('\n').slice(1).map((l) => Number(l.split(',').at(-2)));
  assert.ok(beams.some((b) => b > 0) && beams.some((b) => b === 0), 'the beam lights part of the floor over the day');

  await page.selectOption('#mapinsidestudy', 'leed-ase');
  const ase = await statusAfter(page, () => page.click('#compute'), /^Map in|^Could not/, 400_000);
  assert.match(ase, /^Map in .*: 320 points on 1 receivers; Occupied hours over 1000 lux of direct sun .* over 3,650 instants; OFFICE \d+(\.\d)? %\.$/);
  const year = native(['--epw', epw, '--study', 'leed-ase']);
  const webAse = await downloadText(page, '#downloadmap', join(WORK, 'web-ase.csv'));
  assert.match(year.csv.split('\n')[0], /,hours_over_1000_lux$/);
  assert.match(year.csv.split('\n')[1], /^Floor:work-plane,/, 'the grid lies on the work plane (0.76 m, the study\'s)');
  assert.equal(webAse.text, year.csv, 'the page\'s ASE CSV is `--study leed-ase`\'s, byte for byte');
  const areas = JSON.parse(await page.getAttribute('#view', 'data-areas'));
  const expected = year.summary.studies[0].areas;
  assert.deepEqual(areas.map((a) => [a.zone, a.points]), expected.map((a) => [a.zone, a.points]));
  areas.forEach((a, i) => assert.ok(Math.abs(a.ase - expected[i].ase) < 1e-3, `${a.zone}: ASE ${a.ase} % against ${expected[i].ase} %`));
  assert.ok(expected[0].ase > 0 && expected[0].ase < 100, `ASE between 0 and 100 %: ${expected[0].ase}`);
  await page.selectOption('#mapinsidestudy', '');
  assert.deepEqual(pageErrors, []);
});
