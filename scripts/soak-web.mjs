// Soak: N consecutive computations (load the example, a small year, free) in one page session,
// printing the JS heap and the wasm memory as it goes: `node scripts/soak-web.mjs [N]`.
// Needs `scripts/build-web.sh`. Chromium is started with --enable-precise-memory-info.
import { serve } from './serve.mjs';
import { launch } from '../tests/browser/chromium.mjs';

const runs = Number(process.argv[2] ?? 200);
const server = await serve(0);
const browser = await launch({ extraArgs: ['--enable-precise-memory-info', '--js-flags=--expose-gc'] });
try {
  const page = await browser.newPage();
  // Samples are printed as they come, so a crash still leaves the trend.
  page.on('console', (m) => m.text().startsWith('{') && console.log(m.text()));
  page.on('crash', () => console.log('the page crashed'));
  await page.goto(`http://127.0.0.1:${server.address().port}/api-example.html`);
  await page.waitForFunction(() => document.getElementById('out').dataset.state !== 'running', null, { timeout: 120_000 });
  const samples = await page.evaluate(async (runs) => {
    const { createEngine, wasmMemoryBytes } = await import('/sunlit.js');
    const engine = await createEngine({ resolution: 128 });
    const bytes = new Uint8Array(await (await fetch('/pkg/office.glb')).arrayBuffer());
    const out = [];
    const t0 = performance.now();
    for (let i = 1; i <= runs; i++) {
      const model = engine.loadFiles([{ name: 'office.glb', bytes }]);
      const year = await engine.annual(model, { latitude: 39.74, longitude: -105.18, timeZone: -7, timestepsPerHour: 1, daysPerYear: 14, samplesPerDay: 9, refine: 1 });
      year.csv();
      year.free();
      model.free();
      if (i === 1 || i % 10 === 0) {
        globalThis.gc?.();
        const sample = { run: i, js_heap_mb: performance.memory.usedJSHeapSize / 2 ** 20, wasm_mb: (await wasmMemoryBytes()) / 2 ** 20, seconds: (performance.now() - t0) / 1000 };
        console.log(JSON.stringify(sample));
        out.push(sample);
      }
    }
    return out;
  }, runs);
  console.log(`${samples.length} samples; done`);
} finally {
  await browser.close();
  server.close();
}
