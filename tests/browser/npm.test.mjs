// The npm package as a user gets it: `npm run pack`'s one tarball holds only what ships and runs
// no install scripts; a fresh app (temporary folder) installs it with three and vite from npm,
// bundles it with Vite's defaults, and in Chromium (WebGPU on SwiftShader) builds a three.js scene
// through sunlit/three (world matrices, indexed and non-indexed geometry, an InstancedMesh) whose
// fractions equal the native CLI's on the same scene exported as glb; createEngine({ device })
// counts the same on the page's own GPUDevice and leaves it alive; the worker entry counts the
// same; an EPW year gives irradiation; every JS option's bad input is refused naming the option;
// and the package README's three.js example (www/npm-readme.md, also README.md's quick start) runs
// as written, so it cannot drift from the API.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync, mkdirSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { fileURLToPath } from 'node:url';
import { launch, staticServer } from './chromium.mjs';

const ROOT = fileURLToPath(new URL('../../', import.meta.url));
const THREE_VERSION = '0.187.0';
const VITE_VERSION = '8.3.8';
const SUN = { azimuth: 200, altitude: 35 };
const RECEIVERS_NATIVE = ['--receivers', 'WALL*', '--receivers', 'ROOF', '--receivers', 'PANEL*'];

let app;
let tarball;
let server;
let browser;
let page;
const pageErrors = [];

/** The scene, in the app: receivers WALL_S, WALL_E (in a rotated group), ROOF, PANEL (instanced). */
const MAIN_JS = `
import * as THREE from 'three';
import { GLTFExporter } from 'three/examples/jsm/exporters/GLTFExporter.js';
import { createEngine, sunDirection, epwLocation } from 'sunlit';
import { fromThree, colourByValues, receivingMeshes } from 'sunlit/three';
import SunlitWorker from 'sunlit/worker?worker';

function mesh(name, geometry, x, y, z) {
  const m = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial());
  m.name = name;
  m.position.set(x, y, z);
  return m;
}

/** expand: InstancedMesh → one Mesh per instance (what a glb without instancing holds). */
export function buildScene({ expand = false } = {}) {
  const scene = new THREE.Scene();
  scene.add(mesh('WALL_S', new THREE.PlaneGeometry(4, 3), 0, 1.5, 0));
  scene.add(mesh('OVERHANG', new THREE.BoxGeometry(4, 0.1, 1.2), 0, 3.05, 0.6));
  scene.add(mesh('FIN', new THREE.BoxGeometry(0.1, 3, 1).toNonIndexed(), 2.3, 1.5, 0.5));
  const roof = mesh('ROOF', new THREE.PlaneGeometry(4, 4), 0, 3.2, -2.2);
  roof.rotation.x = -Math.PI / 2 + 0.2;
  scene.add(roof);
  const side = new THREE.Group();
  side.position.set(6, 0, -1);
  side.rotation.y = Math.PI / 2 - 0.3;
  side.scale.set(1.5, 1, 1);
  side.add(mesh('WALL_E', new THREE.PlaneGeometry(2, 2.5), 0, 1.25, 0));
  scene.add(side);
  const slat = new THREE.BoxGeometry(0.05, 0.3, 2.2);
  const panel = new THREE.PlaneGeometry(1, 1);
  panel.rotateX(-Math.PI / 2);
  const placements = [
    ['LOUVRE', slat, [0, 1, 2, 3].map((i) => new THREE.Matrix4().makeTranslation(7.2, 0.4 + i * 0.6, -1.5))],
    ['PANEL', panel, [0, 1].map((i) => new THREE.Matrix4().makeTranslation(-3 + i * 1.5, 0.01, 2.5))],
  ];
  for (const [name, geometry, matrices] of placements) {
    if (expand) {
      matrices.forEach((m, i) => {
        const one = mesh(name + '[' + i + ']', geometry, 0, 0, 0);
        one.applyMatrix4(m);
        scene.add(one);
      });
    } else {
      const inst = new THREE.InstancedMesh(geometry, new THREE.MeshStandardMaterial(), matrices.length);
      inst.name = name;
      matrices.forEach((m, i) => inst.setMatrixAt(i, m));
      scene.add(inst);
    }
  }
  // A post on the panels' south side, so they are partly shaded.
  scene.add(mesh('POST', new THREE.BoxGeometry(0.4, 2, 0.4), -2.8, 1, 3.3));
  return scene;
}

export async function exportGlb() {
  const bytes = await new GLTFExporter().parseAsync(buildScene({ expand: true }), { binary: true });
  return Array.from(new Uint8Array(bytes));
}

import { readmeExample } from './readme-example.js';

window.sunlitApp = { readmeExample, THREE, createEngine, epwLocation, sunDirection, fromThree, colourByValues, receivingMeshes, buildScene, exportGlb, SunlitWorker };
document.body.dataset.ready = '1';
`;

/**
 * The package README's first `js` fence as a module: its imports stay at the top, the rest becomes
 * the body of `readmeExample(scene, epwText)` (the two names the README says the reader brings),
 * which returns what the example made.
 */
export function readmeExampleModule(readme) {
  const fence = readme.match(/```js\n([\s\S]*?)```/);
  assert.ok(fence, 'www/npm-readme.md has a ```js example');
  const lines = fence[1].split('\n');
  const imports = lines.filter((l) => l.startsWith('import '));
  const body = lines.filter((l) => !l.startsWith('import '));
  for (const name of ['engine', 'model', 'now', 'year']) {
    assert.ok(body.some((l) => l.includes(`const ${name} =`)), `the README example defines ${name}`);
  }
  return `${imports.join('\n')}\n\nexport async function readmeExample(scene, epwText) {\n${body.join('\n')}\n  return { engine, model, now, year };\n}\n`;
}

function sh(cmd, args, options = {}) {
  return execFileSync(cmd, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'], ...options });
}


before(async () => {
  // Pack (the wasm bundle is built by scripts/build-web.sh before the browser tests).
  const env = { ...process.env, SUNLIT_PACK_SKIP_BUILD: existsSync(join(ROOT, 'www/pkg/sunlit_wasm_bg.wasm')) ? '1' : '0' };
  sh('bash', ['scripts/pack-npm.sh'], { cwd: ROOT, env });
  const tgz = readdirSync(join(ROOT, 'target/npm')).filter((f) => f.endsWith('.tgz'));
  assert.equal(tgz.length, 1, `exactly one tarball in target/npm: ${tgz}`);
  tarball = join(ROOT, 'target/npm', tgz[0]);
  app = mkdtempSync(join(tmpdir(), 'sunlit-npm-app-'));
  writeFileSync(
    join(app, 'package.json'),
    JSON.stringify({ name: 'sunlit-app', private: true, type: 'module', dependencies: { sunlit: `file:${tarball}`, three: THREE_VERSION, vite: VITE_VERSION } }),
  );
  writeFileSync(join(app, 'index.html'), '<!doctype html><html><body><script type="module" src="/main.js"></script></body></html>');
  writeFileSync(join(app, 'main.js'), MAIN_JS);
  writeFileSync(join(app, 'readme-example.js'), readmeExampleModule(readFileSync(join(ROOT, 'www/npm-readme.md'), 'utf8')));
  sh('npm', ['install', '--no-audit', '--no-fund', '--loglevel=error'], { cwd: app });
  sh('npx', ['vite', 'build', '--logLevel', 'warn'], { cwd: app });
  server = await staticServer(join(app, 'dist'));
  browser = await launch();
  page = await browser.newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(`http://127.0.0.1:${server.address().port}/`);
  await page.waitForSelector('body[data-ready="1"]', { state: 'attached', timeout: 60_000 });
});

after(async () => {
  await browser?.close();
  server?.close();
  if (app) rmSync(app, { recursive: true, force: true });
});

test('the tarball holds only what ships and runs no install scripts', () => {
  const [report] = JSON.parse(sh('npm', ['pack', '--dry-run', '--json', './target/npm/pkg'], { cwd: ROOT }));
  const files = report.files.map((f) => f.path).sort();
  assert.deepEqual(files, [
    'README.md',
    'clip-worker.js',
    'colour.js',
    'device.js',
    'engine-worker.js',
    'map.js',
    'package.json',
    'pkg/sunlit_wasm.js',
    'pkg/sunlit_wasm_bg.wasm',
    'pool.js',
    'profiles.js',
    'sunlit.d.ts',
    'sunlit.js',
    'three.d.ts',
    'three.js',
  ]);
  const manifest = JSON.parse(readFileSync(join(ROOT, 'target/npm/pkg/package.json'), 'utf8'));
  assert.equal(manifest.scripts, undefined, 'no scripts at all, so no install scripts');
  assert.equal(manifest.dependencies, undefined, 'three is a peer dependency only');
  assert.ok(manifest.peerDependencies.three);
  // three is not in the tarball and not imported by the package's modules.
  for (const f of ['sunlit.js', 'three.js', 'map.js', 'device.js', 'engine-worker.js', 'pool.js', 'clip-worker.js', 'profiles.js']) {
    assert.doesNotMatch(readFileSync(join(ROOT, 'target/npm/pkg', f), 'utf8'), /from ['"]three/, f);
  }
  console.log(`tarball ${report.filename}: ${report.size} bytes packed, ${report.unpackedSize} unpacked`);
});

test('sunlit/three in a Vite app: fractions equal the native CLI on the same scene', async () => {
  const js = await page.evaluate(async (sun) => {
    const { createEngine, fromThree, buildScene, colourByValues, receivingMeshes } = window.sunlitApp;
    const engine = await createEngine();
    const model = fromThree(engine, buildScene(), { receivers: 'WALL*, roof, PANEL' });
    const fractions = await engine.fractions(model, sun);
    const coloured = colourByValues(model, fractions);
    const colours = receivingMeshes(model).map(({ mesh, instance }) => (instance >= 0 ? 'instanced' : mesh.material.color.getHexString()));
    return { names: model.receiverNames, fractions: Array.from(fractions), colours, legend: !!coloured.legend, triangles: model.triangles };
  }, SUN);
  assert.deepEqual([...js.names].sort(), ['PANEL[0]', 'PANEL[1]', 'ROOF', 'WALL_E', 'WALL_S']);
  assert.ok(js.legend && js.colours.some((c) => c !== 'instanced'));
  const glb = Buffer.from(await page.evaluate(() => window.sunlitApp.exportGlb()));
  const dir = mkdtempSync(join(tmpdir(), 'sunlit-npm-native-'));
  try {
    writeFileSync(join(dir, 'scene.glb'), glb);
    if (process.env.SUNLIT_KEEP_GLB) writeFileSync(process.env.SUNLIT_KEEP_GLB, glb);
    const native = JSON.parse(
      sh(join(ROOT, 'target/debug/sunlit'), ['fraction', join(dir, 'scene.glb'), '--sun', '200,35', '--json', ...RECEIVERS_NATIVE], {
        env: { ...process.env, XDG_RUNTIME_DIR: dir },
      }),
    );
    const nativeBy = new Map(native.surfaces.map((s) => [s.name, s.fraction]));
    assert.deepEqual([...nativeBy.keys()].sort(), [...js.names].sort());
    let partly = 0;
    js.names.forEach((name, i) => {
      const n = nativeBy.get(name);
      assert.ok(Math.abs(js.fractions[i] - n) <= 0.005, `${name}: browser ${js.fractions[i]} native ${n}`);
      partly += n > 0.02 && n < 0.98;
    });
    assert.ok(partly >= 2, `some receivers are partly shaded: ${JSON.stringify(native.surfaces)}`);
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});

test('createEngine({ device }) counts on the caller\'s GPUDevice and leaves it alive; the worker entry counts the same', async () => {
  const r = await page.evaluate(async (sun) => {
    const { createEngine, fromThree, buildScene, exportGlb, SunlitWorker } = window.sunlitApp;
    const own = await createEngine({ engine: 'gpu' });
    const base = Array.from(await own.fractions(fromThree(own, buildScene(), { receivers: 'WALL*,ROOF' }), sun));
    const adapter = await navigator.gpu.requestAdapter();
    const device = await adapter.requestDevice();
    let lost = false;
    device.lost.then(() => (lost = true));
    // The pixel engine, which counts on the device (auto would clip this light scene exactly).
    const shared = await createEngine({ device, engine: 'gpu' });
    const model = fromThree(shared, buildScene(), { receivers: 'WALL*,ROOF' });
    const onDevice = Array.from(await shared.fractions(model, sun));
    const names = model.receiverNames;
    model.free();
    // The device still works for its owner.
    const buffer = device.createBuffer({ size: 16, usage: GPUBufferUsage.COPY_DST | GPUBufferUsage.MAP_READ });
    device.queue.writeBuffer(buffer, 0, new Float32Array([1, 2, 3, 4]));
    await buffer.mapAsync(GPUMapMode.READ);
    const back = Array.from(new Float32Array(buffer.getMappedRange()));
    // The worker entry, with the same scene as a glb.
    const worker = new SunlitWorker();
    let next = 0;
    const call = (msg) =>
      new Promise((resolve, reject) => {
        const id = ++next;
        const listen = ({ data }) => {
          if (data.id !== id || data.progress) return;
          worker.removeEventListener('message', listen);
          data.error ? reject(new Error(data.error)) : resolve(data.result);
        };
        worker.addEventListener('message', listen);
        worker.postMessage({ id, ...msg });
      });
    await call({ op: 'create', options: {} });
    const bytes = new Uint8Array(await exportGlb());
    const loaded = await call({ op: 'loadFiles', files: [{ name: 'scene.glb', bytes }], options: { receivers: 'WALL*,ROOF' } });
    const inWorker = Array.from(await call({ op: 'fractions', sun }));
    // A map through the worker entry (typed arrays transferred) is the page's, CSV for CSV.
    const mapOptions = { latitude: 39.74, longitude: -105.18, timeZone: -7, grid: 0.5, at: '06-21 10:00' };
    const workerMap = await call({ op: 'map', options: mapOptions, csv: true });
    const pageMap = await own.map(own.loadFiles([{ name: 'scene.glb', bytes }], { receivers: 'WALL*,ROOF' }), mapOptions, { csv: true });
    const map = {
      kinds: ['points', 'normals', 'receivers', 'values'].map((k) => workerMap[k].constructor.name),
      points: workerMap.values.length,
      lit: workerMap.values.filter((v) => v === 1).length,
      same: workerMap.csv === pageMap.csv,
    };
    worker.terminate();
    // Its owner destroys the device: sunlit, counting on it, reports the loss.
    const again = fromThree(shared, buildScene(), { receivers: 'ROOF' });
    await new Promise((resolve) => setTimeout(resolve, 100));
    const lostBefore = lost;
    device.destroy();
    await device.lost;
    const afterLoss = await shared.fractions(again, sun).then(() => 'no error', (e) => String(e?.message ?? e));
    return { base, onDevice, back, lost: lostBefore, workerNames: loaded.names, inWorker, names, afterLoss, map };
  }, SUN);
  assert.deepEqual(r.map.kinds, ['Float32Array', 'Float32Array', 'Uint32Array', 'Float32Array']);
  assert.ok(r.map.points > 20 && r.map.lit > 0 && r.map.lit < r.map.points, `worker map: ${JSON.stringify(r.map)}`);
  assert.ok(r.map.same, 'the worker\'s map CSV is the page\'s');
  assert.deepEqual(r.back, [1, 2, 3, 4]);
  assert.equal(r.lost, false, 'the caller\'s device is not destroyed');
  assert.match(r.afterLoss, /device lost/i);
  r.onDevice.forEach((f, i) => assert.ok(Math.abs(f - r.base[i]) <= 1e-6, `${r.names[i]}: on device ${f} vs own ${r.base[i]}`));
  r.workerNames.forEach((name, i) => {
    const j = r.names.indexOf(name);
    assert.ok(Math.abs(r.inWorker[i] - r.base[j]) <= 0.005, `${name}: worker ${r.inWorker[i]} vs page ${r.base[j]}`);
  });
});

/** An EPW with constant direct normal irradiance. */
function epw(dni) {
  const lines = ['LOCATION,Golden,CO,USA,test,0,39.74,-105.18,-7.0,1800', 'DESIGN CONDITIONS,0', 'TYPICAL/EXTREME PERIODS,0', 'GROUND TEMPERATURES,0',
    'HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0', 'COMMENTS 1,', 'COMMENTS 2,', 'DATA PERIODS,1,1,Data,Sunday,1/1,12/31'];
  const days = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
  days.forEach((n, m) => {
    for (let d = 1; d <= n; d++) for (let h = 1; h <= 24; h++) lines.push(`1999,${m + 1},${d},${h},60,x,10,5,50,80000,0,1300,300,500,${dni},100,0,0,0,0,0,0,0,0,0,0,9,0,0,0,0,0,0,0,0`);
  });
  return lines.join('\n');
}

test('an EPW year through the package: irradiation, fractions at an instant, the EPW location', async () => {
  const r = await page.evaluate(async (text) => {
    const { createEngine, fromThree, buildScene, epwLocation } = window.sunlitApp;
    const engine = await createEngine({ resolution: 64 });
    const model = fromThree(engine, buildScene(), { receivers: 'ROOF,WALL_S' });
    const year = await engine.annual(model, { epw: text, epwName: 'const.epw', daysPerYear: 5, samplesPerDay: 5, timestepsPerHour: 1 });
    return {
      names: year.names,
      means: Array.from(year.means),
      irradiation: Array.from(year.irradiation),
      unshaded: Array.from(year.unshadedIrradiation),
      noon: Array.from(year.fractionsAt(172, 12)),
      night: Array.from(year.fractionsAt(172, 1)),
      site: await epwLocation(text, 'const.epw'),
    };
  }, epw(700));
  assert.equal(r.irradiation.length, 2);
  r.names.forEach((name, i) => {
    assert.ok(r.unshaded[i] > 100 && r.irradiation[i] <= r.unshaded[i] + 1e-9, `${name}: ${r.irradiation[i]} of ${r.unshaded[i]} kWh/m²`);
  });
  assert.deepEqual(r.night, [0, 0]);
  assert.deepEqual([r.site.latitude, r.site.longitude, r.site.timeZone, r.site.name], [39.74, -105.18, -7, 'Golden, CO, USA']);
  assert.ok(r.noon.every((f) => f >= 0 && f <= 1) && r.noon.some((f) => f > 0));
});

test('every JS option\'s bad input is refused with an error naming the option', async () => {
  const messages = await page.evaluate(async () => {
    const { createEngine, fromThree, buildScene, colourByValues } = window.sunlitApp;
    const attempt = async (f) => {
      try {
        await f();
        return 'no error';
      } catch (e) {
        return String(e?.message ?? e);
      }
    };
    const engine = await createEngine({ resolution: 64 });
    const scene = buildScene();
    const model = fromThree(engine, scene, { receivers: 'ROOF' });
    const dup = buildScene();
    dup.getObjectByName('WALL_E').name = 'WALL_S';
    const location = { latitude: 39.74, longitude: -105.18, timeZone: -7, daysPerYear: 3, samplesPerDay: 3 };
    const year = await engine.annual(model, location);
    return {
      resolution: await attempt(() => createEngine({ resolution: 3 })),
      accuracy: await attempt(() => createEngine({ accuracy: 2 })),
      device: await attempt(() => createEngine({ device: {} })),
      engine: await attempt(() => fromThree({}, scene, { receivers: 'ROOF' })),
      object: await attempt(() => fromThree(engine, {}, { receivers: 'ROOF' })),
      receiversType: await attempt(() => fromThree(engine, scene, { receivers: 5 })),
      receiversMissing: await attempt(() => fromThree(engine, scene, {})),
      receiversNone: await attempt(() => fromThree(engine, scene, { receivers: 'NOPE*' })),
      duplicates: await attempt(() => fromThree(engine, dup, { receivers: 'WALL*' })),
      sun: await attempt(() => engine.fractions(model, [0, 0, 0])),
      latitude: await attempt(() => engine.annual(model, { ...location, latitude: 100 })),
      unknown: await attempt(() => engine.annual(model, { ...location, bogus: 1 })),
      refine: await attempt(() => engine.annual(model, { ...location, refine: 3 })),
      day: await attempt(() => year.fractionsAt(400, 1)),
      hour: await attempt(() => year.fractionsAt(100, 30)),
      values: await attempt(() => colourByValues(model, [1, 2, 3])),
      irradiation: String(year.irradiation),
    };
  });
  const expect = {
    resolution: /resolution/,
    accuracy: /accuracy/,
    device: /device/,
    engine: /engine/,
    object: /object/,
    receiversType: /receivers/,
    receiversMissing: /receivers/,
    receiversNone: /receivers matched none/,
    duplicates: /duplicates: 'WALL_S' \(2 meshes\)/,
    sun: /sun/,
    latitude: /latitude 100/,
    unknown: /settings.*bogus/,
    refine: /refine/,
    day: /day/,
    hour: /hour/,
    values: /values/,
    irradiation: /^undefined$/,
  };
  for (const [key, pattern] of Object.entries(expect)) assert.match(messages[key], pattern, `${key}: ${messages[key]}`);
  assert.deepEqual(pageErrors, []);
});

test('the package README\'s three.js example runs as written and gives the native CLI\'s fractions', async () => {
  const r = await page.evaluate(async (text) => {
    const { readmeExample, buildScene } = window.sunlitApp;
    const scene = buildScene();
    const { model, now, year } = await readmeExample(scene, text);
    const coloured = [];
    scene.traverse((o) => o.isMesh && !o.isInstancedMesh && coloured.push(o.material.color.getHexString()));
    return {
      names: model.receiverNames,
      now: Array.from(now),
      irradiation: Array.from(year.irradiation),
      unshaded: Array.from(year.unshadedIrradiation),
      colours: new Set(coloured).size,
    };
  }, epw(700));
  // 'Wall*, Roof*' matches names case-insensitively, as the CLI's --receivers does.
  assert.deepEqual([...r.names].sort(), ['ROOF', 'WALL_E', 'WALL_S']);
  const glb = Buffer.from(await page.evaluate(() => window.sunlitApp.exportGlb()));
  const dir = mkdtempSync(join(tmpdir(), 'sunlit-npm-readme-'));
  try {
    writeFileSync(join(dir, 'scene.glb'), glb);
    const args = ['fraction', join(dir, 'scene.glb'), '--sun', '200,35', '--json', '--receivers', 'Wall*', '--receivers', 'Roof*'];
    const native = JSON.parse(sh(join(ROOT, 'target/debug/sunlit'), args, { env: { ...process.env, XDG_RUNTIME_DIR: dir } }));
    const nativeBy = new Map(native.surfaces.map((s) => [s.name, s.fraction]));
    r.names.forEach((name, i) => {
      assert.ok(Math.abs(r.now[i] - nativeBy.get(name)) <= 0.005, `${name}: README example ${r.now[i]} native ${nativeBy.get(name)}`);
    });
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
  r.names.forEach((name, i) => {
    assert.ok(r.unshaded[i] > 100 && r.irradiation[i] <= r.unshaded[i] + 1e-9, `${name}: ${r.irradiation[i]} of ${r.unshaded[i]} kWh/m²`);
  });
  assert.ok(r.colours >= 2, 'colourByValues recoloured the receivers');
});
