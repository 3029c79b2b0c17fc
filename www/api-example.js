// sunlit's JavaScript API in a few lines: see sunlit.d.ts for every option.
import { createEngine, sunDirection } from './sunlit.js';

const out = document.getElementById('out');
const print = (line) => { out.textContent += `${line}\n`; };

async function main() {
  out.textContent = '';
  const engine = await createEngine({ resolution: 256 });
  print(`engine on ${engine.adapter}`);

  // A south-facing window 2 m × 1.5 m (receiver 0) under a 0.5 m overhang (-1: shading only).
  // Axes: x east, y north, z up (pass yUp: true for glTF's).
  const model = engine.fromArrays({
    positions: [
      0, 0, 0, 2, 0, 0, 2, 0, 1.5, 0, 0, 1.5, // window
      -3, -0.5, 1.5, 5, -0.5, 1.5, 5, 0, 1.5, -3, 0, 1.5, // overhang
    ],
    indices: [0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7],
    triangleReceivers: [0, 0, -1, -1],
    names: ['window'],
  });

  // Sun due south at 35°: the overhang shades the top 0.5·tan 35° = 0.35 m of 1.5 m.
  const [fraction] = await engine.fractions(model, sunDirection(180, 35));
  print(`window: ${fraction.toFixed(3)} sunlit (analytic ${(1 - (0.5 * Math.tan((35 * Math.PI) / 180)) / 1.5).toFixed(3)})`);

  // A year for Golden, Colorado, hourly, with progress; abort() would reject with an AbortError.
  const controller = new AbortController();
  const progress = document.getElementById('progress');
  const annual = await engine.annual(
    model,
    { latitude: 39.74, longitude: -105.18, timeZone: -7, timestepsPerHour: 1, daysPerYear: 14, samplesPerDay: 9 },
    { onProgress: (done, total) => { progress.max = total; progress.value = done; }, signal: controller.signal },
  );
  print(`year: ${annual.rows} rows, mean sunlit fraction over sun-up hours ${annual.means[0].toFixed(3)}`);
  print(annual.csv().split('\n').slice(0, 3).join('\n'));
  annual.free();
  model.free();
}

main().then(
  () => { out.dataset.state = 'done'; },
  (error) => { print(`error: ${error.message}`); out.dataset.state = 'failed'; },
);
