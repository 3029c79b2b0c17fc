// Times one model's year in headless Chromium (WebGPU on SwiftShader) through the JS API, with
// the default engine and with each engine forced, and the same year with the native CLI:
//   node scripts/bench-web.mjs MODEL.glb [DAYSxPERDAY] [RESOLUTION] [--runs N] [--sides LIST]
// Sides (default all): default (auto, the default pool), exact, gpu, exact-1 (one clipping
// worker: the pool's speed-up is exact-1 over exact at 2+ cores), native (the CLI, auto). Each side
// runs N times (default 1) in a fresh browser and prints one JSON line per run, then one summary
// line per side with the median seconds; the browser's lines also carry the peak resident memory
// of all of Chromium's processes (sampled from /proc every 200 ms) and the wasm memory of the
// engine's worker. The page's `auto` measures its profile in the first run (IndexedDB is fresh in
// every browser), as a first visit does. Needs `scripts/build-web.sh` and a release build.
import { execFileSync } from 'node:child_process';
import { copyFileSync, readFileSync, readdirSync, rmSync, statSync } from 'node:fs';
import { basename, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { serve } from './serve.mjs';
import { launch } from '../tests/browser/chromium.mjs';

const ROOT = fileURLToPath(new URL('../', import.meta.url));
const args = process.argv.slice(2);
const flag = (name, fallback) => {
  const i = args.indexOf(name);
  if (i < 0) return fallback;
  const [value] = args.splice(i, 2).slice(1);
  return value;
};
const runs = Number(flag('--runs', '1'));
const sides = flag('--sides', 'default,exact,gpu,exact-1,native').split(',');
const [model, samples = '27x19', resolution = '512'] = args;
if (!model) {
  console.error('usage: node scripts/bench-web.mjs MODEL.glb [DAYSxPERDAY] [RESOLUTION] [--runs N] [--sides default,exact,gpu,exact-1,native]');
  process.exit(2);
}
const [days, perDay] = samples.split('x').map(Number);
const place = { latitude: 39.74, longitude: -105.18, timeZone: -7 };
const ENGINES = { default: {}, exact: { engine: 'exact' }, gpu: { engine: 'gpu' }, 'exact-1': { engine: 'exact', workers: 1 } };

/** Resident bytes of `root` and every process below it (from /proc). */
function treeRss(root) {
  const parent = new Map();
  for (const name of readdirSync('/proc')) {
    if (!/^\d+$/.test(name)) continue;
    try {
      const stat = readFileSync(`/proc/${name}/stat`, 'utf8');
      parent.set(Number(name), Number(stat.slice(stat.lastIndexOf(')') + 2).split(' ')[1]));
    } catch {
      // Gone between the listing and the read.
    }
  }
  let total = 0;
  for (const [pid] of parent) {
    let p = pid;
    while (p > 1 && p !== root) p = parent.get(p) ?? 0;
    if (p !== root || pid === root) continue;
    try {
      const rss = /VmRSS:\s+(\d+) kB/.exec(readFileSync(`/proc/${pid}/status`, 'utf8'));
      total += rss ? Number(rss[1]) * 1024 : 0;
    } catch {
      // Gone.
    }
  }
  return total;
}

async function browserRun(side) {
  copyFileSync(model, join(ROOT, `www/pkg/bench-model-${process.pid}.glb`));
  const server = await serve(0);
  const browser = await launch();
  let peak = 0;
  const sampler = setInterval(() => {
    peak = Math.max(peak, treeRss(process.pid));
  }, 200);
  try {
    const page = await browser.newPage();
    page.on('console', (m) => m.type() === 'error' && console.error(m.text()));
    await page.goto(`http://127.0.0.1:${server.address().port}/api-example.html`);
    const result = await page.evaluate(
      async ({ name, file, days, perDay, resolution, place, options }) => {
        const { createEngine, wasmMemoryBytes } = await import('/sunlit.js');
        const engine = await createEngine({ resolution, ...options });
        const bytes = new Uint8Array(await (await fetch(`/pkg/bench-model-${file}.glb`)).arrayBuffer());
        const t0 = performance.now();
        const model = engine.loadFiles([{ name, bytes }]);
        const t1 = performance.now();
        await engine.prepare(model);
        const t2 = performance.now();
        let views = 0;
        const year = await engine.annual(model, { ...place, timestepsPerHour: 4, daysPerYear: days, samplesPerDay: perDay }, {
          onProgress: (done) => {
            views = Math.max(views, done);
          },
        });
        const t3 = performance.now();
        const out = {
          load_s: (t1 - t0) / 1000,
          workers_load_s: (t2 - t1) / 1000,
          annual_s: (t3 - t2) / 1000,
          total_s: (t3 - t0) / 1000,
          views,
          receivers: year.names.length,
          triangles: model.triangles,
          workers: engine.workers,
          profile_source: year.profileSource,
          profile: year.profile,
          wasm_bytes: await wasmMemoryBytes(),
        };
        engine.close();
        return out;
      },
      { name: basename(model), file: process.pid, days, perDay, resolution: Number(resolution), place, options: ENGINES[side] },
    );
    return { side: `page-${side}`, ...result, peak_rss_mb: Math.round(Math.max(peak, treeRss(process.pid)) / 1e6) };
  } finally {
    clearInterval(sampler);
    await browser.close();
    server.close();
    rmSync(join(ROOT, `www/pkg/bench-model-${process.pid}.glb`), { force: true });
  }
}

function nativeRun() {
  const bin = join(ROOT, 'target/release/sunlit');
  statSync(bin);
  const t0 = performance.now();
  execFileSync(bin, ['annual', model, '--location', `${place.latitude},${place.longitude},${place.timeZone}`, '--timesteps-per-hour', '4',
    '--days-per-year', String(days), '--samples-per-day', String(perDay), '--resolution', resolution, '-o', '/tmp/sunlit-bench-web.csv'], { stdio: ['ignore', 'ignore', 'inherit'] });
  return { side: 'native', total_s: (performance.now() - t0) / 1000 };
}

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
const head = { model: basename(model), samples, resolution: Number(resolution) };
for (const side of sides) {
  const times = [];
  for (let r = 0; r < runs; r++) {
    const result = side === 'native' ? nativeRun() : await browserRun(side);
    times.push(result.total_s);
    console.log(JSON.stringify({ ...head, run: r + 1, ...result }));
  }
  console.log(JSON.stringify({ ...head, side, runs, median_s: Number(median(times).toFixed(2)) }));
}
