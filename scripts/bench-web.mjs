// Times one model's year in headless Chromium (WebGPU on SwiftShader) through the JS API, with
// the default engine and with each engine forced, and the same year with the native CLI:
//   node scripts/bench-web.mjs MODEL.glb [DAYSxPERDAY] [RESOLUTION] [--runs N] [--timesteps N] [--sides LIST] [--load-only] [--interleave]
// Sides (default all): default (auto, the default pool; a first visit: it probes its profile),
// default-cached (auto with the profile a first run measured, as a returning visit), default-0 (auto with no
// clipping workers: the engine's thread alone), exact, gpu, exact-1 (one clipping
// worker: the pool's speed-up is exact-1 over exact at 2+ cores), native (the CLI, auto),
// native-first (the same with an empty profile cache: it probes, as the page's first visit does;
// SUNLIT_BIN names another binary than target/release/sunlit), native-exact (the CLI with
// --engine exact: the page's `exact` side like for like), page (the page itself: open it,
// choose the model, Compute; from opening to "Done", as a new visitor waits). Each side
// runs N times (default 1) in a fresh browser and prints one JSON line per run, then one summary
// line per side with the median seconds; the browser's lines also carry the peak resident memory
// of Chromium's processes (sampled from /proc every 200 ms; in all and by process type), the wasm
// memory of the engine's instance (the page's thread here) after the load and at the end, and
// of each clipping worker once it built the model; the API's and the CLI's sides their CPU seconds (`cpu_s`:
// Chromium's processes from the API's import to the year's end; the CLI's user + system), which
// a loaded machine's wall clock hides, and Chromium's by process type and thread (`cpu_s_by_thread`); the API's
// year lines also the engine's `timings` (each first-visit step, in ms from createEngine). As the page does, the
// year does not wait for the workers to build their copies (--load-only does). The page's `auto` measures its profile in the first run (IndexedDB is fresh in
// every browser), as a first visit does. Needs `scripts/build-web.sh` and a release build.
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdtempSync, readFileSync, readdirSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, join, resolve } from 'node:path';
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
// --timesteps N: EnergyPlus timesteps an hour of the year (the refinement's views grow with it).
const timesteps = Number(flag('--timesteps', '4'));
if (!Number.isInteger(timesteps) || timesteps < 1 || timesteps > 60) {
  console.error(`bench-web: --timesteps must be a whole number of timesteps an hour from 1 to 60, got ${timesteps}`);
  process.exit(2);
}
// --load-only: the model's load and the pool's copies, no year (where the memory goes, quickly).
const loadOnly = args.includes('--load-only') && Boolean(args.splice(args.indexOf('--load-only'), 1));
// --interleave: the sides take turns run by run, for paired ratios (below).
const interleave = args.includes('--interleave') && Boolean(args.splice(args.indexOf('--interleave'), 1));
// --cpu-profile PREFIX: V8's CPU profile of the page's thread (the engine's instance) over each
// browser run, written to PREFIX-SIDE-RUN.cpuprofile (Chrome DevTools' format; a bundle built
// without --remove-name-section names the wasm's functions): where the engine's thread goes.
const cpuProfile = flag('--cpu-profile', null);
// --www DIR: serve another build of the page (e.g. main's www/, pkg/ included) instead of this
// checkout's, for A/B runs of the two bundles under scripts/paired.sh.
const WWW = resolve(flag('--www', join(ROOT, 'www')));
const sides = flag('--sides', 'default,exact,gpu,exact-1,native').split(',');
const [model, samples = '27x19', resolution = '512'] = args;
if (!model) {
  console.error('usage: node scripts/bench-web.mjs MODEL.glb [DAYSxPERDAY] [RESOLUTION] [--runs N] [--timesteps N] [--sides default,exact,gpu,exact-1,native] [--load-only]');
  process.exit(2);
}
const [days, perDay] = samples.split('x').map(Number);
const place = { latitude: 39.74, longitude: -105.18, timeZone: -7 };
const ENGINES = { default: {}, 'default-cached': {}, 'default-0': { workers: 0 }, exact: { engine: 'exact' }, gpu: { engine: 'gpu' }, 'exact-1': { engine: 'exact', workers: 1 } };

/** Every process below `root` (not `root` itself), each with the fields of its /proc stat line
 * after its name (state, ppid, …; utime and stime are [11] and [12], in clock ticks). */
function descendants(root) {
  const stats = new Map();
  for (const name of readdirSync('/proc')) {
    if (!/^\d+$/.test(name)) continue;
    try {
      const line = readFileSync(`/proc/${name}/stat`, 'utf8');
      stats.set(Number(name), line.slice(line.lastIndexOf(')') + 2).split(' '));
    } catch {
      // Gone between the listing and the read.
    }
  }
  const below = new Map();
  for (const [pid, fields] of stats) {
    let p = pid;
    while (p > 1 && p !== root) p = Number(stats.get(p)?.[1] ?? 0);
    if (p === root && pid !== root) below.set(pid, fields);
  }
  return below;
}

/** Resident bytes of every process below `root` (from /proc), in all and by Chromium's process
 * type (`renderer`: the page and its workers, whose wasm instances are the model's copies;
 * `gpu-process`: WebGPU's buffers, on SwiftShader here; `other`: the browser and its utilities). */
function treeRss(root) {
  const out = { total: 0, renderer: 0, 'gpu-process': 0, other: 0 };
  for (const pid of descendants(root).keys()) {
    try {
      const rss = /VmRSS:\s+(\d+) kB/.exec(readFileSync(`/proc/${pid}/status`, 'utf8'));
      const bytes = rss ? Number(rss[1]) * 1024 : 0;
      const type = /--type=([\w-]+)/.exec(readFileSync(`/proc/${pid}/cmdline`, 'utf8'))?.[1];
      out.total += bytes;
      out[type in out ? type : 'other'] += bytes;
    } catch {
      // Gone.
    }
  }
  return out;
}

/** CPU seconds (user + system) spent so far by every process below `root` (from /proc): the
 * cost of a run that a loaded machine's wall clock hides. Processes that have exited are not
 * counted, so it is read before the browser closes. */
function treeCpu(root) {
  let ticks = 0;
  for (const fields of descendants(root).values()) ticks += Number(fields[11]) + Number(fields[12]);
  return ticks / 100;
}

/** CPU seconds so far of every thread below `root`, summed by Chromium's process type and the
 * thread's name (`renderer/CrRendererMain`: the page's thread, the engine's instance here;
 * `renderer/DedicatedWorker thread`: the clipping workers; `renderer/V8 DefaultWorke`: wasm
 * compiles; `gpu-process/…`: WebGPU on SwiftShader), from /proc/PID/task: where a first visit's
 * CPU goes. */
function threadCpu(root) {
  const out = {};
  for (const pid of descendants(root).keys()) {
    try {
      const type = /--type=([\w-]+)/.exec(readFileSync(`/proc/${pid}/cmdline`, 'utf8'))?.[1] ?? 'browser';
      for (const tid of readdirSync(`/proc/${pid}/task`)) {
        const line = readFileSync(`/proc/${pid}/task/${tid}/stat`, 'utf8');
        const name = line.slice(line.indexOf('(') + 1, line.lastIndexOf(')'));
        const fields = line.slice(line.lastIndexOf(')') + 2).split(' ');
        const key = `${type}/${name}`;
        out[key] = (out[key] ?? 0) + (Number(fields[11]) + Number(fields[12])) / 100;
      }
    } catch {
      // Gone.
    }
  }
  return out;
}

/** `after` less `before`, by key, rounded; keys under 0.01 s left out. */
function cpuSpent(before, after) {
  const spent = Object.entries(after).map(([k, v]) => [k, Number((v - (before[k] ?? 0)).toFixed(2))]);
  return Object.fromEntries(spent.filter(([, v]) => v >= 0.01).sort((a, b) => b[1] - a[1]));
}

/** The larger of each field. */
function peakOf(a, b) {
  return Object.fromEntries(Object.keys(b).map((k) => [k, Math.max(a[k] ?? 0, b[k])]));
}

const mb = (bytes) => Math.round(bytes / 1e6);

async function browserRun(side, run = 0) {
  copyFileSync(model, join(WWW, `pkg/bench-model-${process.pid}.glb`));
  const server = await serve(0, '127.0.0.1', WWW);
  const browser = await launch();
  let peak = {};
  const sampler = setInterval(() => {
    peak = peakOf(peak, treeRss(process.pid));
  }, 200);
  try {
    const page = await browser.newPage();
    // Progress, as the year goes (a run stopped early says how far it got): elapsed seconds,
    // views done of all, and the peak memory so far.
    const started = Date.now();
    page.on('console', (m) => {
      // The blank document's own 404 (and its favicon's) is no error of the run.
      const blank = /\/(bench-blank|favicon\.ico)$/.test(m.location()?.url ?? '');
      if (m.type() === 'error' && !blank) console.error(m.text());
      // The pool's sizing by its memory budget, and each instance's wasm once loaded.
      if (m.text().startsWith('sunlit: ') || m.text().startsWith('loaded ')) console.error(m.text());
      const at = /^progress (\d+) (\d+)$/.exec(m.text());
      if (at) {
        const so = Object.fromEntries(Object.entries(peak).map(([k, v]) => [k, mb(v)]));
        console.error(JSON.stringify({ side, elapsed_s: Math.round((Date.now() - started) / 1000), done: Number(at[1]), total: Number(at[2]), peak_rss_mb_by_process: so }));
      }
    });
    // A document of the site's origin that runs nothing of its own (a 404): api-example.html
    // makes its own engine with its own workers and year as it loads, which ran beside every
    // first visit timed here before (its adapter request, its index, its wasm compile shared).
    await page.goto(`http://127.0.0.1:${server.address().port}/bench-blank`);
    const profiler = cpuProfile ? await page.context().newCDPSession(page) : null;
    if (profiler) {
      await profiler.send('Profiler.enable');
      await profiler.send('Profiler.setSamplingInterval', { interval: 200 });
      await profiler.send('Profiler.start');
    }
    const cpuBefore = treeCpu(process.pid);
    const threadsBefore = threadCpu(process.pid);
    const result = await page.evaluate(
      async ({ name, file, days, perDay, resolution, place, options, loadOnly, timesteps }) => {
        // A first visit starts here: the module's import, the wasm's compile, the device, the pool.
        const tImport = performance.now();
        const { createEngine, wasmMemoryBytes } = await import('/sunlit.js');
        const engine = await createEngine({ resolution, ...options });
        const created = performance.now();
        const bytes = new Uint8Array(await (await fetch(`/pkg/bench-model-${file}.glb`)).arrayBuffer());
        const t0 = performance.now();
        const model = engine.loadFiles([{ name, bytes }]);
        const t1 = performance.now();
        const loadedWasm = await wasmMemoryBytes();
        // The workers build their copies while the year starts, as the page has them do
        // (worker.js); --load-only waits for them.
        const preparing = engine.prepare(model);
        if (loadOnly) await preparing;
        const t2 = performance.now();
        const mbOf = (b) => Math.round(b / 1e6);
        const loaded = { engine_wasm_mb: mbOf(await wasmMemoryBytes()), worker_wasm_mb: engine.workerMemoryBytes.map(mbOf), pool_sizing: engine.poolSizing };
        console.log(`loaded ${JSON.stringify(loaded)}`);
        console.log(`progress 0 0`);
        let views = 0;
        if (loadOnly) {
          const out = {
            load_s: (t1 - t0) / 1000,
            workers_load_s: (t2 - t1) / 1000,
            total_s: (t2 - t0) / 1000,
            triangles: model.triangles,
            workers: engine.workers,
            engine_wasm_mb_loaded: Math.round(loadedWasm / 1e6),
            engine_wasm_mb: Math.round((await wasmMemoryBytes()) / 1e6),
            worker_wasm_mb: engine.workerMemoryBytes.map((b) => Math.round(b / 1e6)),
            pool_sizing: engine.poolSizing,
          };
          engine.close();
          return out;
        }
        const year = await engine.annual(model, { ...place, timestepsPerHour: timesteps, daysPerYear: days, samplesPerDay: perDay }, {
          onProgress: (done, total, counted) => {
            // Views an engine counted (not those settled without counting), summed over the
            // year and its sky views: a new stage starts with another total or fewer done.
            if (total !== globalThis.stage?.total || done < globalThis.stage.done) {
              views += globalThis.stage?.counted ?? 0;
            }
            globalThis.stage = { total, done, counted };
            // Every 30 s to the bench's stderr (the console), and at the end.
            const now = performance.now();
            if (now - (globalThis.lastProgress ?? 0) > 30_000 || done === total) {
              globalThis.lastProgress = now;
              console.log(`progress ${done} ${total}`);
            }
          },
        });
        const t3 = performance.now();
        await preparing;
        views += globalThis.stage?.counted ?? 0;
        const out = {
          create_s: (created - tImport) / 1000,
          load_s: (t1 - t0) / 1000,
          annual_s: (t3 - t2) / 1000,
          total_s: (t3 - t0) / 1000,
          // What a first visit waits for: the engine's start, then load, workers and year (the
          // model's fetch left out: the native run reads a local file).
          first_visit_s: (created - tImport + t3 - t0) / 1000,
          views,
          receivers: year.names.length,
          triangles: model.triangles,
          workers: engine.workers,
          // Milliseconds from createEngine to each step, and who clipped (sunlit.d.ts, timings).
          timings: engine.timings,
          profile_source: year.profileSource,
          profile: year.profile,
          engine_wasm_mb_loaded: Math.round(loadedWasm / 1e6),
          engine_wasm_mb: Math.round((await wasmMemoryBytes()) / 1e6),
          worker_wasm_mb: engine.workerMemoryBytes.map((b) => Math.round(b / 1e6)),
          pool_sizing: engine.poolSizing,
        };
        engine.close();
        return out;
      },
      { name: basename(model), file: process.pid, days, perDay, resolution: Number(resolution), place, options: ENGINES[side], loadOnly, timesteps },
    );
    // Chromium's CPU seconds over the run (all its processes: the page, its workers, the GPU
    // process), from the API's import to the year's end.
    const cpu = treeCpu(process.pid) - cpuBefore;
    const cpuByThread = cpuSpent(threadsBefore, threadCpu(process.pid));
    peak = peakOf(peak, treeRss(process.pid));
    if (profiler) {
      const { profile } = await profiler.send('Profiler.stop');
      writeFileSync(`${cpuProfile}-${side}-${run + 1}.cpuprofile`, JSON.stringify(profile));
    }
    return { side: `page-${side}`, ...result, cpu_s: Number(cpu.toFixed(2)), cpu_s_by_thread: cpuByThread, peak_rss_mb: mb(peak.total), peak_rss_mb_by_process: Object.fromEntries(Object.entries(peak).map(([k, v]) => [k, mb(v)])) };
  } finally {
    clearInterval(sampler);
    await browser.close();
    server.close();
    rmSync(join(WWW, `pkg/bench-model-${process.pid}.glb`), { force: true });
  }
}

/** The page itself as a new visitor uses it (side `page`): open it, choose the model in its Model
 * input, press Compute as soon as it is loaded, with the form's settings set to the bench's.
 * `first_visit_s`: from opening the page to its "Done"; `compute_s`: from Compute to "Done". */
async function pageRun() {
  const server = await serve(0, '127.0.0.1', WWW);
  const browser = await launch();
  try {
    const page = await browser.newPage();
    const status = async (pattern) => {
      await page.waitForFunction((source) => new RegExp(source).test(document.getElementById('status').textContent), pattern.source, { timeout: 3_600_000 });
      return page.textContent('#status');
    };
    const t0 = performance.now();
    await page.goto(`http://127.0.0.1:${server.address().port}/`);
    await status(/^Ready/);
    const ready = performance.now();
    const fields = { latitude: place.latitude, longitude: place.longitude, timezone: place.timeZone, days, perday: perDay, resolution };
    for (const [id, value] of Object.entries(fields)) await page.fill(`#${id}`, String(value));
    await page.selectOption('#timesteps', String(timesteps));
    await page.setInputFiles('#model', model);
    const loaded = await status(/^Loaded|^Could not/);
    if (!loaded.startsWith('Loaded')) throw new Error(loaded);
    const t1 = performance.now();
    await page.click('#compute');
    const done = await status(/^Done in|^Could not/);
    if (!done.startsWith('Done in')) throw new Error(done);
    const t2 = performance.now();
    return { side: 'page', ready_s: (ready - t0) / 1000, load_s: (t1 - ready) / 1000, compute_s: (t2 - t1) / 1000, total_s: (t2 - t0) / 1000, first_visit_s: (t2 - t0) / 1000, status: done };
  } finally {
    await browser.close();
    server.close();
  }
}

/** The CLI's year; `fresh`: with an empty profile cache, so `auto` probes as on a first run. */
function nativeRun(fresh, engine = null) {
  const bin = process.env.SUNLIT_BIN ?? join(ROOT, 'target/release/sunlit');
  statSync(bin);
  const cache = fresh ? mkdtempSync(join(tmpdir(), 'sunlit-bench-cache-')) : undefined;
  const env = cache ? { ...process.env, XDG_CACHE_HOME: cache } : process.env;
  const times = join(tmpdir(), `sunlit-bench-web-time-${process.pid}`);
  const t0 = performance.now();
  // /usr/bin/time for the CLI's CPU seconds (user + system), as Chromium's are read from /proc.
  execFileSync('/usr/bin/time', ['-f', '%U %S', '-o', times, bin, 'annual', model, '--location', `${place.latitude},${place.longitude},${place.timeZone}`, '--timesteps-per-hour', String(timesteps),
    '--days-per-year', String(days), '--samples-per-day', String(perDay), '--resolution', resolution, ...(engine ? ['--engine', engine] : []), '-o', '/tmp/sunlit-bench-web.csv'], { stdio: ['ignore', 'ignore', 'inherit'], env });
  const total = (performance.now() - t0) / 1000;
  const cpu = readFileSync(times, 'utf8').trim().split(/\s+/).map(Number).reduce((a, b) => a + b, 0);
  rmSync(times, { force: true });
  if (cache) rmSync(cache, { recursive: true, force: true });
  return { side: engine ? `native-${engine}` : fresh ? 'native-first' : 'native', total_s: total, cpu_s: Number(cpu.toFixed(2)) };
}

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
const head = { model: basename(model), samples, resolution: Number(resolution) };
// With --interleave the sides take turns run by run (A B A B …), and each side's first-visit
// (or total) seconds are also divided by the last side's total of the same round: a paired
// ratio, which a machine whose speed drifts (a shared one) does not skew as much.
const bySide = Object.fromEntries(sides.map((side) => [side, { times: [], visits: [] }]));
for (const side of sides) {
  if (side === 'default-cached') {
    // A returning visitor: the profile is already in IndexedDB. One unmeasured run probes it;
    // every timed run then routes by it (pinned), so the probe's cost is left out as a cache hit.
    const first = await browserRun('default');
    ENGINES['default-cached'] = { profile: first.profile };
  }
}
const rounds = Array.from({ length: runs }, (_, r) => r);
const order = interleave ? rounds.flatMap((r) => sides.map((side) => [side, r])) : sides.flatMap((side) => rounds.map((r) => [side, r]));
for (const [side, r] of order) {
  const result = side.startsWith('native') ? nativeRun(side === 'native-first', side === 'native-exact' ? 'exact' : null) : side === 'page' ? await pageRun() : await browserRun(side, r);
  bySide[side].times.push(result.total_s);
  bySide[side].visits.push(result.first_visit_s ?? result.total_s);
  console.log(JSON.stringify({ ...head, run: r + 1, ...result }));
}
const yardstick = bySide[sides[sides.length - 1]].times;
for (const side of sides) {
  const { times, visits } = bySide[side];
  const firstVisit = side.startsWith('native') ? {} : { median_first_visit_s: Number(median(visits).toFixed(2)) };
  const paired = interleave && side !== sides[sides.length - 1] ? { median_ratio_to_last: Number(median(visits.map((v, i) => v / yardstick[i])).toFixed(2)) } : {};
  console.log(JSON.stringify({ ...head, side, runs, median_s: Number(median(times).toFixed(2)), ...firstVisit, ...paired }));
}
