// sunlit/three's paintMap (www/three.js) on inside maps, under Node: engine.map with `inside: true`
// on a box room (an EnergyPlus model: one zone, one south window) through the wasm bundle and the
// JS API (www/sunlit.js, engine 'exact': the inside is mapped by rays, no GPU asked), painted by
// the adapter; its cells and colours held to the native CLI's points CSV of the same map
// (`sunlit map --inside`): at an instant every cell lies on the floor (three's y-up axes, lifted
// along the floor's normal) and takes the sun's or the shadow's colour as the CLI's `lit` says;
// over a day each cell the palette's colour of the CLI's beam through the glass over the map's
// largest; for LEED ASE the cells lie on the 0.76 m work plane, coloured by the occupied hours;
// for BRE 209's No-Sky Line the CSV and the room's share are `--study bre-nsl`'s.
//
// three is a peer dependency the repository does not install (tests/browser/npm.test.mjs
// installs it in a fresh app): paintMap takes the app's three module, and here it is given the
// four constructors it calls (BufferGeometry, BufferAttribute, MeshBasicMaterial, Mesh, with
// three's signatures), which only hold what the adapter computes. What is tested is that:
// the cells' positions and vertex colours.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { colourOf } from '../../www/colour.js';
import { paintMap } from '../../www/three.js';
import { goldenEpw, roomIdf } from '../browser/room.mjs';
import { ROOT, bundleMissing } from './dawn.mjs';

const SITE = { latitude: 39.74, longitude: -105.18, timeZone: -7 };
const GRID = 0.25;
const LIFT = 0.01;

/** What paintMap calls of three, as three defines it (r152+). */
const THREE = {
  DoubleSide: 2,
  BufferAttribute: class {
    constructor(array, itemSize) {
      Object.assign(this, { array, itemSize, count: array.length / itemSize, needsUpdate: false });
    }
  },
  BufferGeometry: class {
    attributes = {};
    setAttribute(name, attribute) {
      this.attributes[name] = attribute;
      return this;
    }
  },
  MeshBasicMaterial: class {
    constructor(parameters) {
      Object.assign(this, parameters);
    }
  },
  Mesh: class {
    constructor(geometry, material) {
      Object.assign(this, { geometry, material, name: '' });
    }
  },
};

/** sRGB to linear, as three reads vertex colours (the sRGB transfer function, IEC 61966-2-1). */
const linear = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);

let work;
let api;
let engine;
let model;
let nodeFetch;

before(async () => {
  const missing = bundleMissing();
  if (missing) throw new Error(missing);
  work = mkdtempSync(join(tmpdir(), 'sunlit-three-inside-'));
  writeFileSync(join(work, 'room.idf'), roomIdf());
  writeFileSync(join(work, 'golden.epw'), goldenEpw());
  // The bundle fetches its wasm beside the module; Node's fetch refuses file: URLs.
  nodeFetch = globalThis.fetch;
  globalThis.fetch = async (input, init) => {
    const url = new URL(input instanceof Request ? input.url : String(input));
    if (url.protocol !== 'file:') return nodeFetch(input, init);
    return new Response(await readFile(url), { headers: url.pathname.endsWith('.wasm') ? { 'Content-Type': 'application/wasm' } : {} });
  };
  api = await import('../../www/sunlit.js');
  engine = await api.createEngine({ engine: 'exact', workers: 0 });
  model = engine.loadFiles([{ name: 'room.idf', bytes: readFileSync(join(work, 'room.idf')) }]);
});

after(() => {
  model?.free?.();
  engine?.close();
  if (nodeFetch) globalThis.fetch = nodeFetch;
  if (work) rmSync(work, { recursive: true, force: true });
});

/** `sunlit map room.idf --inside FLAGS --grid 0.25`'s points CSV, as rows of numbers (the
 * receiver's name dropped) and its header. */
function nativeRows(flags) {
  const out = join(work, 'native.csv');
  execFileSync(join(ROOT, 'target/debug/sunlit'), ['map', join(work, 'room.idf'), '--inside', ...flags, '--grid', String(GRID), '-o', out], {
    stdio: ['ignore', 'ignore', 'inherit'],
    env: { ...process.env, XDG_RUNTIME_DIR: work },
  });
  const [header, ...rows] = readFileSync(out, 'utf8').trim().split('\n');
  return { header: header.split(','), rows: rows.map((r) => r.split(',').slice(1).map(Number)) };
}

/** Each painted cell's 6 vertices: [x, y, z] in three's axes, and the colour of its first vertex
 * (asserting the other five share it). */
function cells(painted) {
  const { position, color } = painted.mesh.geometry.attributes;
  assert.equal(position.itemSize, 3);
  const out = [];
  for (let i = 0; i < position.array.length / 18; i++) {
    const corners = Array.from({ length: 6 }, (_, k) => Array.from(position.array.subarray(18 * i + 3 * k, 18 * i + 3 * k + 3)));
    const rgb = Array.from(color.array.subarray(18 * i, 18 * i + 3));
    for (let k = 1; k < 6; k++) assert.deepEqual(Array.from(color.array.subarray(18 * i + 3 * k, 18 * i + 3 * k + 3)), rgb, `cell ${i} is one colour`);
    out.push({ corners, rgb });
  }
  return out;
}

/** Whether two colours agree within `tolerance` per channel. */
const near = (a, b, tolerance = 1e-6) => a.every((v, j) => Math.abs(v - b[j]) <= tolerance);

test("paintMap on an inside map at an instant: the floor's cells, the sun patch in the sun's colour as the CLI's lit says", { timeout: 120_000 }, async () => {
  const map = await engine.map(model, { ...SITE, inside: true, at: '12-21 13:00', grid: GRID });
  const painted = paintMap(THREE, map, { lift: LIFT });
  const native = nativeRows(['--at', '12-21', '13:00', '--location', `${SITE.latitude},${SITE.longitude},${SITE.timeZone}`]);
  assert.equal(native.header.at(-3), 'lit');
  const painting = cells(painted);
  assert.equal(painting.length, native.rows.length, 'a cell per point of the CLI\'s map');
  assert.equal(painting.length, 320, 'a 0.25 m grid on the 4 m × 5 m floor');
  const [sun, shadow] = [colourOf(1).map(linear), colourOf(0).map(linear)];
  let lit = 0;
  painting.forEach(({ corners, rgb }, i) => {
    const [x, y, z, , , , litThere] = native.rows[i];
    // three's (x, y, z) is sunlit's (x, z, −y); the floor's normal is up, so the lift is along y.
    for (const [cx, cy, cz] of corners) {
      assert.ok(Math.abs(cy - (z + LIFT)) < 1e-6, `cell ${i} lies on the floor, lifted: y ${cy}`);
      assert.ok(Math.abs(cx - x) <= GRID / 2 + 1e-6 && Math.abs(-cz - y) <= GRID / 2 + 1e-6, `cell ${i} is centred on its point`);
    }
    assert.ok(near(rgb, litThere === 1 ? sun : shadow), `cell ${i}: lit ${litThere}, colour ${rgb}`);
    lit += litThere;
  });
  assert.ok(lit > 20 && lit < 300, `the sun patch is part of the floor: ${lit} of 320 cells`);
  assert.equal(painted.mesh.material.vertexColors, true);
  assert.equal(painted.mesh.material.side, THREE.DoubleSide, 'the floor\'s cells seen from above and below (a cut-away view)');
  assert.deepEqual([painted.min, painted.max], [0, 1]);
});

test('paintMap on an inside map over a day: each cell the palette\'s colour of the CLI\'s beam through the glass', { timeout: 120_000 }, async () => {
  const epw = readFileSync(join(work, 'golden.epw'), 'utf8');
  const map = await engine.map(model, { epw, inside: true, period: '12-21', from: '08:00', to: '16:00', value: 'direct', grid: GRID });
  assert.equal(map.value, 'direct');
  const painted = paintMap(THREE, map, { lift: LIFT });
  const native = nativeRows(['--epw', join(work, 'golden.epw'), '--period', '12-21', '--from', '08:00', '--to', '16:00']);
  const column = native.header.indexOf('beam_kwh_m2') - 1;
  assert.ok(column > 0, native.header.join());
  const beams = native.rows.map((r) => r[column]);
  const top = Math.max(...beams);
  assert.ok(top > 0 && beams.some((b) => b === 0), 'the beam reaches part of the floor');
  // The legend's top is the largest value the map holds (Float32), the CLI's to its 4 decimals.
  assert.ok(Math.abs(painted.max - top) < 1e-4, `legend max ${painted.max} against ${top}`);
  cells(painted).forEach(({ rgb }, i) => {
    const expected = colourOf(beams[i] / top).map(linear);
    assert.ok(near(rgb, expected, 2e-3), `cell ${i}: beam ${beams[i]} kWh/m², colour ${rgb} against ${expected}`);
  });
});

test('paintMap on an inside study (LEED ASE): the cells lie on the 0.76 m work plane, coloured by the occupied hours', { timeout: 300_000 }, async () => {
  const epw = readFileSync(join(work, 'golden.epw'), 'utf8');
  const map = await engine.map(model, { epw, inside: true, study: 'leed-ase', grid: GRID });
  assert.equal(map.value, 'aseHours');
  const painted = paintMap(THREE, map, { lift: LIFT });
  const native = nativeRows(['--epw', join(work, 'golden.epw'), '--study', 'leed-ase']);
  assert.equal(native.header.at(-1), 'hours_over_1000_lux');
  const hours = native.rows.map((r) => r.at(-1));
  const top = Math.max(...hours);
  assert.ok(top > 250, `some points pass ASE's 250 h: ${top} h`);
  cells(painted).forEach(({ corners, rgb }, i) => {
    for (const [, cy] of corners) assert.ok(Math.abs(cy - (0.76 + LIFT)) < 1e-6, `cell ${i} lies on the work plane: y ${cy}`);
    assert.ok(near(rgb, colourOf(hours[i] / top).map(linear), 2e-3), `cell ${i}: ${hours[i]} h, colour ${rgb}`);
  });
  assert.equal(map.areas.length, 1);
  assert.equal(map.areas[0].zone.toLowerCase(), 'office');
});

test("an inside study of the No-Sky Line (bre-nsl): the CSV is `--study bre-nsl`'s, the room's share its report's, each cell painted by its value", { timeout: 300_000 }, async () => {
  const map = await engine.map(model, { ...SITE, inside: true, study: 'bre-nsl', grid: GRID }, { csv: true });
  assert.equal(map.value, 'seesSky');
  const out = join(work, 'nsl.csv');
  const summary = JSON.parse(
    execFileSync(join(ROOT, 'target/debug/sunlit'), ['map', join(work, 'room.idf'), '--inside', '--study', 'bre-nsl', '--grid', String(GRID), '--location', `${SITE.latitude},${SITE.longitude},${SITE.timeZone}`, '--json', '-o', out], {
      env: { ...process.env, XDG_RUNTIME_DIR: work },
      encoding: 'utf8',
    }),
  );
  assert.equal(map.csv, readFileSync(out, 'utf8'), 'the CSV is the CLI\'s, byte for byte');
  const [native] = summary.studies[0].areas;
  assert.equal(map.areas[0].points, native.points);
  assert.ok(Math.abs(map.areas[0].seesSky - native.sees_sky) < 1e-3, `${map.areas[0].seesSky} % against ${native.sees_sky} %`);
  // Nothing stands outside: every point of the 0.85 m work plane, below the window's 2.5 m head,
  // sees sky through it (the line lies beyond the back wall; tests/inside.rs draws it by hand
  // behind an obstruction).
  assert.equal(native.sees_sky, 100);
  const painted = paintMap(THREE, map, { lift: LIFT });
  cells(painted).forEach(({ rgb }, i) => assert.ok(near(rgb, colourOf(map.values[i]).map(linear)), `cell ${i}`));
});
