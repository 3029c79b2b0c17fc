// The page's interior view (headless Chromium, driven by Playwright) against the native library
// through the CLI: on a box room (an EnergyPlus model: one zone, one south window), Map mode at
// an instant with "Inside rooms" maps a grid on the floor; its points CSV equals `sunlit map
// --inside --at` byte for byte, its lit count and each inside face's sun patch equal the CLI's
// JSON summary; cutting away the roof or the south wall takes exactly those faces out of the 3D
// view. The view is saved to target/artifacts/inside.png for a person to look at.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, closePage, downloadText, servePage, setMapSliders, statusAfter, waitForStatus } from './pagetest.mjs';

const WORK = join(tmpdir(), `sunlit-inside-${process.pid}`);
const LOCATION = { latitude: '39.74', longitude: '-105.18', timezone: '-7' };
// 21 December (day 355), 13:00 local standard time: the beam through the window lands on the floor.
const DAY = 355;
const HOUR = 13;
const GRID = '0.25';

/** A 4 m × 5 m × 3 m room, its window x 1–3 m, z 1–2.5 m in the south wall (y = 0), as
 * tests/inside.rs builds it. */
function roomIdf() {
  const surface = (name, kind, boundary, corners) =>
    `BuildingSurface:Detailed,${name},${kind},Opaque,Office,,${boundary},,${boundary === 'Outdoors' ? 'SunExposed,WindExposed' : 'NoSun,NoWind'},,${corners.length},${corners.flat().join(',')};\n`;
  return [
    'Version,25.2;\nBuilding,Box,0,Suburbs,0.04,0.4,FullInteriorAndExterior,25,6;\n',
    'GlobalGeometryRules,UpperLeftCorner,Counterclockwise,Relative;\nZone,Office,0,0,0,0;\n',
    'Construction,Opaque,Layer;\nConstruction,Glass,SimpleGlass;\nWindowMaterial:SimpleGlazingSystem,SimpleGlass,2.0,0.6,0.7;\n',
    surface('South', 'Wall', 'Outdoors', [[0, 0, 3], [0, 0, 0], [4, 0, 0], [4, 0, 3]]),
    surface('North', 'Wall', 'Outdoors', [[4, 5, 3], [4, 5, 0], [0, 5, 0], [0, 5, 3]]),
    surface('East', 'Wall', 'Outdoors', [[4, 0, 3], [4, 0, 0], [4, 5, 0], [4, 5, 3]]),
    surface('West', 'Wall', 'Outdoors', [[0, 5, 3], [0, 5, 0], [0, 0, 0], [0, 0, 3]]),
    surface('Floor', 'Floor', 'Ground', [[4, 0, 0], [0, 0, 0], [0, 5, 0], [4, 5, 0]]),
    surface('Roof', 'Roof', 'Outdoors', [[0, 0, 3], [4, 0, 3], [4, 5, 3], [0, 5, 3]]),
    'FenestrationSurface:Detailed,Win,Window,Glass,South,,,,1,4,1,0,2.5,1,0,1,3,0,1,3,0,2.5;\n',
  ].join('');
}

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

/** `sunlit map --inside --at` on the room: its JSON summary and its points CSV. */
function nativeInside() {
  const csv = join(WORK, 'native.csv');
  const at = `${HOUR}:00`.padStart(5, '0');
  const args = ['map', model, '--inside', '--at', '12-21', at, '--grid', GRID, '--json', '-o', csv];
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
  assert.match(done, /^Map in .*: 320 points on 1 receivers; \d+ in the sun; sun patches: .*Floor:inside \d/);

  const native = nativeInside();
  const web = await downloadText(page, '#downloadmap', join(WORK, 'web.csv'));
  assert.equal(web.text, native.csv, 'the page\'s points CSV is the CLI\'s, byte for byte');
  assert.match(native.csv.split('\n')[0], /,lit,solar_transmittance,visible_transmittance$/);
  const lit = Number(await page.getAttribute('#view', 'data-lit'));
  assert.equal(lit, native.summary.lit_points);
  assert.ok(lit > 20 && lit < 300, `the beam lights part of the floor: ${lit} of 320 points`);
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
