// Times the page's Map mode time slider in headless Chromium: the seconds from a move of the
// Time slider to the new instant's cells on screen (the worker maps the instant, the page
// colours the cells), for one model and grid:
//   node scripts/bench-web-map.mjs MODEL.glb [GRID] [--moves N] [--download]
// It loads MODEL.glb through the page's file input, maps 21 March 08:00 at GRID metres (default
// 0.25) with Compute, then moves the slider N times (default 12) a quarter hour at a time and
// prints one JSON line: the first map's seconds, each move's milliseconds and their median. With
// --download it then clicks both downloads and times each file's arrival. Needs
// `scripts/build-web.sh`. Location: Golden, CO (39.74, -105.18, UTC-7).
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, join } from 'node:path';
import { serve } from './serve.mjs';
import { launch } from '../tests/browser/chromium.mjs';

const args = process.argv.slice(2);
const flag = (name, fallback) => {
  const i = args.indexOf(name);
  if (i < 0) return fallback;
  const [value] = args.splice(i, 2).slice(1);
  return value;
};
const moves = Number(flag('--moves', '12'));
const downloads = args.includes('--download');
const [model, grid = '0.25'] = args.filter((a) => a !== '--download');
if (!model) {
  console.error('usage: node scripts/bench-web-map.mjs MODEL.glb [GRID] [--moves N] [--download]');
  process.exit(2);
}

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};

const server = await serve(0);
const browser = await launch();
const work = mkdtempSync(join(tmpdir(), 'sunlit-bench-map-'));
try {
  const page = await (await browser.newContext({ acceptDownloads: true })).newPage();
  // A page error ends the run (its waits would otherwise wait out their timeouts).
  page.on('pageerror', (e) => {
    console.error(`page error: ${e.message}`);
    process.exitCode = 1;
    browser.close();
  });
  await page.goto(`http://127.0.0.1:${server.address().port}/`);
  const status = (pattern, timeout = 600_000) =>
    page.waitForFunction((source) => new RegExp(source).test(document.getElementById('status').textContent), pattern.source, { timeout });
  await status(/^Ready/);
  await page.setInputFiles('#model', model);
  await status(/^Loaded|^Could not/);
  for (const [id, v] of [['latitude', '39.74'], ['longitude', '-105.18'], ['timezone', '-7']]) await page.fill(`#${id}`, v);
  await page.selectOption('#mode', 'map');
  await page.fill('#mapgrid', grid);
  await page.selectOption('#mapperiod', 'instant');
  await page.evaluate(() => {
    for (const [id, v] of [['mapday', 80], ['maptime', 8]]) {
      const input = document.getElementById(id);
      input.value = String(v);
      input.dispatchEvent(new Event('input', { bubbles: true }));
    }
  });
  const t0 = Date.now();
  await page.click('#compute');
  await status(/^Map in|^Could not/);
  const first = (Date.now() - t0) / 1000;
  const summary = await page.textContent('#status');
  // Each move: from the slider's input event to the new instant's cells (the page sets
  // data-at once it has coloured them).
  const times = [];
  for (let i = 1; i <= moves; i++) {
    const ms = await page.evaluate(
      (hour) =>
        new Promise((resolve) => {
          const view = document.getElementById('view');
          const want = `80,${hour}`;
          const t = performance.now();
          const seen = new MutationObserver(() => {
            if (view.dataset.at === want) {
              seen.disconnect();
              resolve(performance.now() - t);
            }
          });
          seen.observe(view, { attributes: true, attributeFilter: ['data-at'] });
          const input = document.getElementById('maptime');
          input.value = String(hour);
          input.dispatchEvent(new Event('input', { bubbles: true }));
        }),
      8 + i * 0.25,
    );
    times.push(Math.round(ms));
  }
  const out = { model: basename(model), grid: Number(grid), first_map_s: first, status: summary, moves_ms: times, median_move_ms: median(times) };
  if (downloads) {
    for (const id of ['downloadmap', 'downloadglb']) {
      const t = Date.now();
      const download = page.waitForEvent('download', { timeout: 600_000 });
      await page.click(`#${id}`);
      const file = join(work, id);
      await (await download).saveAs(file);
      out[`${id}_ms`] = Date.now() - t;
    }
  }
  console.log(JSON.stringify(out));
} finally {
  await browser.close();
  server.close();
  rmSync(work, { recursive: true, force: true });
}
