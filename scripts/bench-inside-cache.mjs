// What the kept inside scene saves: `engine.map` with `inside: true` at one instant, CALLS times
// on the same model and options, through the wasm bundle under Node (www/pkg, built by
// scripts/build-web.sh; the exact engine, one thread, as in the page's worker). The first call
// builds the inside scene (the building with its glazing left out, the rooms, the grid, the
// shadow-ray index); the later ones find it kept on the model. With --fresh each call's grid
// spacing differs by a nanometre, so every call builds it again: the cost the cache saves.
//
//   node scripts/bench-inside-cache.mjs MODEL [--grid G] [--calls N] [--fresh] [--interior GLOB --glazing GLOB --glass T]
//
// Prints each call's milliseconds and the points mapped. For whole-process figures pair a run
// with and without --fresh: scripts/paired.sh 5 "node scripts/bench-inside-cache.mjs M --calls 5" "… --fresh".
import { readFileSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { basename } from 'node:path';

const args = process.argv.slice(2);
const flag = (name, fallback) => {
  const at = args.indexOf(name);
  return at < 0 ? fallback : args[at + 1];
};
const file = args[0];
if (!file || file.startsWith('--')) {
  console.error('usage: node scripts/bench-inside-cache.mjs MODEL [--grid G] [--calls N] [--fresh] [--interior GLOB --glazing GLOB --glass T]');
  process.exit(2);
}
const grid = Number(flag('--grid', '0.25'));
const calls = Number(flag('--calls', '2'));
const fresh = args.includes('--fresh');

// The bundle fetches its wasm beside the module; Node's fetch refuses file: URLs.
const nodeFetch = globalThis.fetch;
globalThis.fetch = async (input, init) => {
  const url = new URL(input instanceof Request ? input.url : String(input));
  if (url.protocol !== 'file:') return nodeFetch(input, init);
  return new Response(await readFile(url), { headers: url.pathname.endsWith('.wasm') ? { 'Content-Type': 'application/wasm' } : {} });
};
const { createEngine } = await import('../www/sunlit.js');
const engine = await createEngine({ engine: 'exact', workers: 0 });
const model = engine.loadFiles([{ name: basename(file), bytes: readFileSync(file) }]);
const options = { latitude: 39.74, longitude: -105.18, timeZone: -7, at: '12-21 13:00', inside: true };
if (flag('--interior')) Object.assign(options, { interior: flag('--interior'), glazing: flag('--glazing') });
if (flag('--glass')) options.glassTransmittance = Number(flag('--glass'));
for (let k = 0; k < calls; k++) {
  const started = performance.now();
  const map = await engine.map(model, { ...options, grid: fresh ? grid + k * 1e-9 : grid });
  const ms = performance.now() - started;
  const lit = map.values.reduce((n, v) => n + v, 0);
  console.log(`call ${k + 1}: ${ms.toFixed(1)} ms, ${map.values.length} points, ${lit} lit`);
}
engine.close();
