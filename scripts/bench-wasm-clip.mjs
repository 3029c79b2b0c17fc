#!/usr/bin/env node
// The page's clipper (the wasm's `Clipper`, what each clipping worker runs) timed in Node on a
// fixed set of views, and those views written out so that `cargo run --release --example
// clip_views` times the native exact engine on exactly the same ones and compares answers.
// A benchmark, not a test: it says µs a view in wasm, and the native example says the ratio.
//
//   node scripts/bench-wasm-clip.mjs MODEL.glb [--pkg www/pkg] [--days 27] [--samples 19]
//        [--repeat 1] [--out DIR]
//
// Views: every receiver at every sun of a year's sample grid (`--days` days spread over the
// year × `--samples` hours over the day, suns above 3° only) at Golden, CO (39.74 N), all
// leaves on. --out DIR writes scene.bin, objects.bin, views.f64 (receiver, x, y, z, leaves a
// view, little-endian f64) and wasm.f64 (the fractions) for the native example.
import { readFileSync, writeFileSync, mkdirSync } from 'node:fs';
import { resolve, basename } from 'node:path';
import { pathToFileURL } from 'node:url';

function args(argv) {
  const opts = { pkg: 'www/pkg', days: 27, samples: 19, repeat: 1, out: null, model: null };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a.startsWith('--')) opts[a.slice(2)] = argv[++i];
    else opts.model = a;
  }
  if (!opts.model) throw new Error('usage: bench-wasm-clip.mjs MODEL.glb [--pkg DIR] [--days N] [--samples N] [--repeat N] [--out DIR]');
  return opts;
}

/** Unit vectors towards the sun (x east, y north, z up) over a year's sample grid. */
function suns(days, samples, latitude = 39.74) {
  const phi = (latitude * Math.PI) / 180;
  const out = [];
  for (let d = 0; d < days; d++) {
    const day = ((d + 0.5) * 365) / days;
    const decl = ((23.44 * Math.PI) / 180) * Math.sin((2 * Math.PI * (day - 81)) / 365);
    for (let s = 0; s < samples; s++) {
      const h = (((s + 0.5) / samples) * 2 - 1) * Math.PI * 0.6; // hour angle, ±108°
      const x = -Math.cos(decl) * Math.sin(h);
      const y = Math.cos(phi) * Math.sin(decl) - Math.sin(phi) * Math.cos(decl) * Math.cos(h);
      const z = Math.sin(phi) * Math.sin(decl) + Math.cos(phi) * Math.cos(decl) * Math.cos(h);
      if (z > Math.sin((3 * Math.PI) / 180)) out.push([x, y, z]);
    }
  }
  return out;
}

const opts = args(process.argv.slice(2));
const pkg = resolve(opts.pkg);
const wasm = await import(pathToFileURL(`${pkg}/sunlit_wasm.js`).href);
wasm.initSync({ module: readFileSync(`${pkg}/sunlit_wasm_bg.wasm`) });

const engine = await wasm.Engine.create(undefined, undefined, 'exact', false);
const model = engine.loadFiles([basename(opts.model)], [new Uint8Array(readFileSync(opts.model))]);
const receivers = model.receiverNames.length;
const sceneBytes = model.sceneBytes();
const objectsBytes = model.objectsBytes();

const sky = suns(Number(opts.days), Number(opts.samples));
const packed = new Float64Array(receivers * sky.length * 5);
let k = 0;
for (const [x, y, z] of sky) {
  for (let r = 0; r < receivers; r++) packed.set([r, x, y, z, 1], 5 * k++);
}

let t0 = process.hrtime.bigint();
const clipper = wasm.Clipper.fromScene(sceneBytes, objectsBytes);
const buildMs = Number(process.hrtime.bigint() - t0) / 1e6;

const times = [];
let fractions = null;
for (let r = 0; r < Number(opts.repeat); r++) {
  const cpu0 = process.cpuUsage();
  t0 = process.hrtime.bigint();
  fractions = clipper.fractions(packed);
  const wall = Number(process.hrtime.bigint() - t0) / 1e9;
  const cpu = process.cpuUsage(cpu0);
  times.push({ wall, cpu: (cpu.user + cpu.system) / 1e6 });
}
const views = packed.length / 5;
const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
const wall = median(times.map((t) => t.wall));
const cpu = median(times.map((t) => t.cpu));
let sum = 0;
for (const f of fractions) sum += f;
console.log(JSON.stringify({
  model: opts.model, pkg: opts.pkg, receivers, views, build_ms: Math.round(buildMs),
  wall_s: +wall.toFixed(3), cpu_s: +cpu.toFixed(3), us_per_view: +((cpu / views) * 1e6).toFixed(1),
  runs: times.map((t) => +t.cpu.toFixed(3)), mean_fraction: sum / views,
}));

if (opts.out) {
  mkdirSync(opts.out, { recursive: true });
  writeFileSync(`${opts.out}/scene.bin`, sceneBytes);
  writeFileSync(`${opts.out}/objects.bin`, objectsBytes);
  writeFileSync(`${opts.out}/views.f64`, new Uint8Array(packed.buffer));
  writeFileSync(`${opts.out}/wasm.f64`, new Uint8Array(fractions.buffer));
}
clipper.free();
model.free();
engine.free();
