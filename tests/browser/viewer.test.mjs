// The example viewer (examples/three-viewer) as a user runs it: `npm run pack`'s tarball, three
// and vite from npm installed into a copy of the example, `vite build`, and in Chromium (WebGPU
// on SwiftShader): load the example office through three's GLTFLoader, compute the year, move the
// time-of-year sliders; the surfaces' shown values are Annual.splineFractionsAt's at that instant,
// their colours are the palette's colour of those values, and both change with the slider. The
// page at 21 December 09:30 is saved to target/artifacts/viewer.png.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { cpSync, existsSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { fileURLToPath } from 'node:url';
import { colourOf } from '../../www/colour.js';
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
