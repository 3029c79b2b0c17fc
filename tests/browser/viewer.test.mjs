// The example viewer (examples/three-viewer) as a user runs it: `npm run pack`'s tarball, three
// and vite from npm installed into a copy of the example, `vite build`, and in Chromium (WebGPU
// on SwiftShader): load the example office through three's GLTFLoader, compute the year, move the
// time-of-year sliders; the surfaces' shown values are Annual.splineFractionsAt's at that instant,
// their colours are the palette's colour of those values, and both change with the slider. The
// page at 21 December 09:30 is saved to target/artifacts/viewer.png. The shadow pattern painted
// on the receivers is sunlit's own (engine.map lit per point at the slider's instant, equal to a
// call of the API), its cells coloured sun or shadow, and it moves on screen with the slider
// (target/artifacts/viewer-shadows-*.png).
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { cpSync, existsSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { fileURLToPath } from 'node:url';
import { colourOf } from '../../www/colour.js';
import { LIT, SHADED } from '../../www/map.js';
import { launch, staticServer } from './chromium.mjs';

const ROOT = fileURLToPath(new URL('../../', import.meta.url));

let base;
let server;
let browser;
let page;
const pageErrors = [];

function sh(cmd, args, options = {}) {
  return execFileSync(cmd, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'], ...options });
}


before(async () => {
  // Packed into this test's own folder, so that the npm package test may pack beside it.
  base = mkdtempSync(join(tmpdir(), 'sunlit-viewer-'));
  const packed = join(base, 'npm');
  const env = { ...process.env, SUNLIT_PACK_DIR: packed, SUNLIT_PACK_SKIP_BUILD: existsSync(join(ROOT, 'www/pkg/sunlit_wasm_bg.wasm')) ? '1' : '0' };
  sh('bash', ['scripts/pack-npm.sh'], { cwd: ROOT, env });
  const tgz = readdirSync(packed).filter((f) => f.endsWith('.tgz'));
  assert.equal(tgz.length, 1);
  // The example as it sits in the repository (examples/three-viewer beside examples/office.glb),
  // its sunlit dependency pointed at the tarball by absolute path.
  const app = join(base, 'three-viewer');
  cpSync(join(ROOT, 'examples/three-viewer'), app, { recursive: true, filter: (p) => !/node_modules|dist$/.test(p) });
  cpSync(join(ROOT, 'examples/office.glb'), join(base, 'office.glb'));
  const manifest = JSON.parse(readFileSync(join(app, 'package.json'), 'utf8'));
  assert.match(manifest.dependencies.sunlit, /^file:\.\.\/\.\.\/target\/npm\/sunlit-.*\.tgz$/, 'the example installs the packed tarball');
  manifest.dependencies.sunlit = `file:${join(packed, tgz[0])}`;
  writeFileSync(join(app, 'package.json'), JSON.stringify(manifest));
  sh('npm', ['install', '--no-audit', '--no-fund', '--loglevel=error'], { cwd: app });
  sh('npx', ['vite', 'build', '--logLevel', 'warn'], { cwd: app });
  server = await staticServer(join(app, 'dist'));
  mkdirSync(join(ROOT, 'target/artifacts'), { recursive: true });
  browser = await launch();
  page = await browser.newPage({ viewport: { width: 1200, height: 800 } });
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(`http://127.0.0.1:${server.address().port}/`);
  await page.waitForFunction(() => /^Ready/.test(document.getElementById('status').textContent), null, { timeout: 60_000 });
});

after(async () => {
  await browser?.close();
  server?.close();
  if (base) rmSync(base, { recursive: true, force: true });
});

async function waitForStatus(pattern, timeout = 300_000) {
  await page.waitForFunction((source) => new RegExp(source).test(document.getElementById('status').textContent), pattern.source, { timeout });
  return page.textContent('#status');
}

/** What the page shows at its slider's instant, and what the API and the meshes say. */
async function shown() {
  return page.evaluate(() => {
    const rows = [...document.querySelectorAll('#values tbody tr')].map((r) => ({ name: r.dataset.name, value: Number(r.dataset.value) }));
    const [day, hour] = document.body.dataset.instant.split(',').map(Number);
    const { year, model } = window.sunlitViewer;
    return {
      day,
      hour,
      rows,
      names: model.receiverNames,
      api: Array.from(year.splineFractionsAt(day, hour)),
      linear: Array.from(year.fractionsAt(day, hour)),
      colours: window.sunlitViewer.colours(),
    };
  });
}

function check(s) {
  assert.deepEqual(s.rows.map((r) => r.name), s.names);
  s.rows.forEach((r, i) => assert.equal(r.value, s.api[i], `${r.name} at day ${s.day} hour ${s.hour}: shown = splineFractionsAt`));
  const byName = new Map(s.colours.map((c) => [c.name, c.rgb]));
  s.names.forEach((name, i) => {
    const want = colourOf(s.api[i]);
    byName.get(name).forEach((c, k) => assert.ok(Math.abs(c - want[k]) < 1e-4, `${name}: colour ${byName.get(name)} vs ${want}`));
  });
}

async function slide(day, hour) {
  await page.evaluate(([d, h]) => {
    for (const [id, v] of [['day', d], ['hour', h]]) {
      const input = document.getElementById(id);
      input.value = String(v);
      input.dispatchEvent(new Event('input', { bubbles: true }));
    }
  }, [day, hour]);
}

test('the example viewer: glTF in, the year computed, the slider recolours by the spline at each instant', { timeout: 900_000 }, async () => {
  await page.click('#example');
  assert.match(await waitForStatus(/^Loaded|^Could not/), /^Loaded office\.glb: 10 receiving surfaces/);
  await page.fill('#days', '14');
  await page.fill('#perday', '9');
  await page.click('#compute');
  assert.match(await waitForStatus(/^Year computed|^Could not/), /^Year computed/);

  const first = await shown();
  assert.deepEqual([first.day, first.hour], [172, 12]);
  check(first);
  // At a row's instant (hourly rows hold at h:30) the surfaces give the schedule's value, except
  // where the run counted that timestep directly (refinement).
  await slide(172, 12.5);
  const noon = await shown();
  assert.deepEqual([noon.day, noon.hour], [172, 12.5]);
  check(noon);
  await slide(355, 9.5);
  const winter = await shown();
  assert.deepEqual([winter.day, winter.hour], [355, 9.5]);
  check(winter);
  const changed = winter.api.filter((v, i) => Math.abs(v - noon.api[i]) > 0.05).length;
  assert.ok(changed >= 3, `the slider moves the values (${changed} of ${noon.api.length} changed by > 0.05)`);
  for (const s of [noon, winter]) {
    const same = s.api.filter((v, i) => Math.abs(v - s.linear[i]) < 1e-5).length;
    const mean = s.api.reduce((a, v, i) => a + Math.abs(v - s.linear[i]), 0) / s.api.length;
    console.log(`day ${s.day} hour ${s.hour}: spline ${s.api.map((v) => v.toFixed(3))} vs rows ${s.linear.map((v) => v.toFixed(3))}`);
    assert.ok(same >= s.api.length / 2 && mean < 0.05, `day ${s.day} hour ${s.hour}: ${same} equal to the row, mean |Δ| ${mean}`);
  }
  // Instants outside the year are refused naming the argument, as every JS API error.
  const refused = await page.evaluate(() => {
    const attempt = (f) => {
      try {
        f();
        return null;
      } catch (e) {
        return { code: e.code, option: e.option, message: e.message };
      }
    };
    const { year } = window.sunlitViewer;
    return { day: attempt(() => year.splineFractionsAt(400, 1)), hour: attempt(() => year.splineFractionsAt(100, 30)) };
  });
  assert.deepEqual([refused.day.code, refused.day.option], ['bad-option', 'day']);
  assert.match(refused.day.message, /400 is outside/);
  assert.deepEqual([refused.hour.code, refused.hour.option], ['bad-option', 'hour']);
  await page.screenshot({ path: join(ROOT, 'target/artifacts/viewer.png') });
  await slide(172, 2);
  const night = await shown();
  check(night);
  assert.ok(night.api.every((v) => v === 0), 'night: every surface dark');
  const partly = noon.api.filter((v) => v > 0.02 && v < 0.98).length;
  console.log(`viewer: ${partly} of ${noon.api.length} surfaces partly shaded on 21 June 12:30`);
  assert.deepEqual(pageErrors, []);
});

/** The painted shadow pattern at the slider's instant, and engine.map's own answer for it. */
async function shadowsAt(day, hour) {
  await slide(day, hour);
  await page.waitForFunction((at) => document.body.dataset.shadowAt === at, `${day},${hour}`, { timeout: 60_000 });
  return page.evaluate(async ([d, h]) => {
    const v = window.sunlitViewer;
    const painted = v.shadows();
    const two = (n) => String(n).padStart(2, '0');
    const date = new Date(Date.UTC(2001, 0, d));
    const at = `${two(date.getUTCMonth() + 1)}-${two(date.getUTCDate())} ${two(Math.floor(h))}:${two(Math.round((h % 1) * 60))}`;
    const map = await v.engine.map(v.model, { latitude: 39.74, longitude: -105.18, timeZone: -7, grid: 0.25, at });
    return { painted, api: Array.from(map.values), at };
  }, [day, hour]);
}

/** Screen pixels within a few levels of `rgb` (0..1): the painted cells are unlit, so exact. */
function pixelsNear(png, rgb) {
  return page.evaluate(async ([b64, want]) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = new OffscreenCanvas(img.width, img.height);
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const data = g.getImageData(0, 0, img.width, img.height).data;
    const target = want.map((x) => Math.round(x * 255));
    let n = 0;
    for (let i = 0; i < data.length; i += 4) if (Math.abs(data[i] - target[0]) <= 3 && Math.abs(data[i + 1] - target[1]) <= 3 && Math.abs(data[i + 2] - target[2]) <= 3) n++;
    return n;
  }, [png.toString('base64'), rgb]);
}

test('the viewer paints sunlit\'s own shadow pattern at the slider\'s instant, and the slider moves it', { timeout: 300_000 }, async () => {
  // Shadows need no year: a loaded model is enough (loaded here when this test runs alone).
  if (!(await page.evaluate(() => !!window.sunlitViewer.model))) {
    await page.click('#example');
    assert.match(await waitForStatus(/^Loaded|^Could not/), /^Loaded office\.glb/);
  }
  const shots = [];
  const seen = [];
  for (const [day, hour] of [[80, 9.5], [80, 15.5]]) {
    const s = await shadowsAt(day, hour);
    assert.deepEqual(s.painted.at, [day, hour]);
    assert.deepEqual(s.painted.values, s.api, `${s.at}: the painted values are engine.map's`);
    s.painted.cells.forEach((rgb, i) => {
      const want = s.api[i] >= 0.5 ? LIT : SHADED;
      rgb.forEach((c, k) => assert.ok(Math.abs(c - want[k]) < 2e-3, `${s.at} cell ${i}: ${rgb} vs ${want}`));
    });
    const lit = s.api.filter((v) => v >= 0.5).length;
    assert.ok(lit > 0 && lit < s.api.length, `${s.at}: part of the receivers in shadow (${lit} of ${s.api.length} lit)`);
    const png = await page.locator('#view').screenshot({ path: join(ROOT, `target/artifacts/viewer-shadows-${hour}.png`) });
    shots.push({ at: s.at, lit, sun: await pixelsNear(png, LIT), shade: await pixelsNear(png, SHADED) });
    seen.push(s.api);
  }
  const moved = seen[1].filter((v, i) => v !== seen[0][i]).length;
  console.log(`viewer shadows: ${JSON.stringify(shots)}; ${moved} of ${seen[0].length} cells changed`);
  assert.ok(moved >= seen[0].length / 20, `the shadow moves: ${moved} cells changed`);
  assert.ok(shots.every((s) => s.sun > 100 && s.shade > 100), 'sun and shadow cells are on screen');
  assert.notEqual(shots[0].sun, shots[1].sun, 'the sunlit pixels on screen change with the slider');
  assert.deepEqual(pageErrors, []);
});
