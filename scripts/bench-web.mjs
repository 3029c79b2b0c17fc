// Times one model's year in headless Chromium (WebGPU on SwiftShader) through the JS API, and the
// same year with the native CLI on lavapipe: `node scripts/bench-web.mjs MODEL.glb [DAYSxPERDAY]
// [RESOLUTION]`. Prints one JSON line per side. Needs `scripts/build-web.sh` and a release build.
import { execFileSync } from 'node:child_process';
import { copyFileSync, statSync } from 'node:fs';
import { basename, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { serve } from './serve.mjs';
import { launch } from '../tests/browser/chromium.mjs';

const ROOT = fileURLToPath(new URL('../', import.meta.url));
const [model, samples = '27x19', resolution = '512'] = process.argv.slice(2);
if (!model) {
  console.error('usage: node scripts/bench-web.mjs MODEL.glb [DAYSxPERDAY] [RESOLUTION]');
  process.exit(2);
}
const [days, perDay] = samples.split('x').map(Number);
const place = { latitude: 39.74, longitude: -105.18, timeZone: -7 };

async function browserRun() {
  copyFileSync(model, join(ROOT, 'www/pkg/bench-model.glb'));
  const server = await serve(0);
  const browser = await launch();
  try {
    const page = await browser.newPage();
    await page.goto(`http://127.0.0.1:${server.address().port}/api-example.html`);
    return await page.evaluate(async ({ name, days, perDay, resolution, place }) => {
      const { createEngine } = await import('/sunlit.js');
      const engine = await createEngine({ resolution });
      const bytes = new Uint8Array(await (await fetch('/pkg/bench-model.glb')).arrayBuffer());
      const t0 = performance.now();
      const model = engine.loadFiles([{ name, bytes }]);
      const t1 = performance.now();
      let views = 0;
      const year = await engine.annual(model, { ...place, timestepsPerHour: 4, daysPerYear: days, samplesPerDay: perDay }, {
        onProgress: (done) => { views = Math.max(views, done); },
      });
      const t2 = performance.now();
      return { side: 'chromium-swiftshader', load_s: (t1 - t0) / 1000, annual_s: (t2 - t1) / 1000, views, receivers: year.names.length, triangles: model.triangles };
    }, { name: basename(model), days, perDay, resolution: Number(resolution), place });
  } finally {
    await browser.close();
    server.close();
  }
}

function nativeRun() {
  const bin = join(ROOT, 'target/release/sunlit');
  statSync(bin);
  const t0 = performance.now();
  execFileSync(bin, ['annual', model, '--location', `${place.latitude},${place.longitude},${place.timeZone}`, '--timesteps-per-hour', '4',
    '--days-per-year', String(days), '--samples-per-day', String(perDay), '--resolution', resolution, '-o', '/tmp/sunlit-bench-web.csv'], { stdio: ['ignore', 'ignore', 'inherit'] });
  return { side: 'native-lavapipe', total_s: (performance.now() - t0) / 1000 };
}

console.log(JSON.stringify({ model: basename(model), samples, resolution: Number(resolution), ...(await browserRun()) }));
console.log(JSON.stringify({ model: basename(model), samples, resolution: Number(resolution), ...nativeRun() }));
