// EnergyPlus shading transmittance schedules in the page (issue 36): the JS API's year of an IDF
// whose shades let light through by schedule (tests/browser/fixtures/transmitting-shades.idf: a
// tree of constant τ 0.2, a tree whose τ changes with the seasons, a screen whose τ changes by the
// hour) against the native CLI's year of the same file with the same engine and settings. The
// truth is the native engine, which tests/energyplus_models.rs holds to EnergyPlus 25.2's own
// clipping; here the page must give the same fractions. The same IDF with its schedules taken
// off (every shade opaque) gives fractions far from both, so a page that ignored the schedules
// would fail.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { after, before, test } from 'node:test';
import { serve } from '../../scripts/serve.mjs';
import { launch } from './chromium.mjs';

const ROOT = fileURLToPath(new URL('../../', import.meta.url));
const FIXTURE = join(ROOT, 'tests/browser/fixtures/transmitting-shades.idf');
// The CLI built by `cargo test` (SUNLIT_BIN names another, e.g. a release build).
const SUNLIT = process.env.SUNLIT_BIN ?? join(ROOT, 'target/debug/sunlit');
// Chicago, as the IDF's Site:Location; few samples so the year takes seconds.
const PLACE = { latitude: 41.98, longitude: -87.92, timeZone: -6 };
const PLAN = { daysPerYear: 12, samplesPerDay: 9 };

let server;
let browser;
let work;

before(async () => {
  server = await serve(0);
  browser = await launch();
  work = mkdtempSync(join(tmpdir(), 'sunlit-schedules-'));
});

after(async () => {
  await browser?.close();
  server?.close();
  if (work) rmSync(work, { recursive: true, force: true });
});

/** The IDF with every shade's Transmittance Schedule Name blanked: each shade opaque. */
function opaque(idf) {
  return idf.replace(/^(Shading:Site:Detailed, \w+), \w+,$/gm, '$1, ,');
}

/** An EnergyPlus shading CSV as { names, rows: [[fraction per surface]] }. */
function parse(csv) {
  const [head, ...lines] = csv.trim().split('\n');
  const names = head.split(',').slice(1).filter(Boolean);
  const rows = lines.map((line) => line.split(',').slice(1, 1 + names.length).map(Number));
  return { names, rows };
}

function nativeYear(idf) {
  const out = join(work, 'native.csv');
  execFileSync(
    SUNLIT,
    ['annual', idf, '--location', `${PLACE.latitude},${PLACE.longitude},${PLACE.timeZone}`, '--engine', 'exact',
      '--days-per-year', String(PLAN.daysPerYear), '--samples-per-day', String(PLAN.samplesPerDay), '-o', out],
    { stdio: ['ignore', 'ignore', 'pipe'] },
  );
  return parse(readFileSync(out, 'utf8'));
}

/** The page's years of each IDF text, through the JS API with the exact engine (its pool). */
async function pageYears(texts) {
  const page = await browser.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(`http://127.0.0.1:${server.address().port}/api-example.html`);
  const csvs = await page.evaluate(
    async ({ texts, settings }) => {
      const { createEngine } = await import('/sunlit.js');
      const engine = await createEngine({ engine: 'exact' });
      const out = [];
      for (const text of texts) {
        const model = engine.loadFiles([{ name: 'transmitting-shades.idf', bytes: new TextEncoder().encode(text) }]);
        out.push((await engine.annual(model, settings)).csv());
      }
      engine.close();
      return out;
    },
    { texts, settings: { ...PLACE, ...PLAN } },
  );
  await page.close();
  assert.deepEqual(errors, []);
  return csvs.map(parse);
}

/** Each surface's mean fraction over the year. */
function means({ names, rows }) {
  return Object.fromEntries(names.map((name, c) => [name, rows.reduce((s, r) => s + r[c], 0) / rows.length]));
}

test("the page honours shades' transmittance schedules as the native CLI does", { timeout: 300_000 }, async () => {
  const text = readFileSync(FIXTURE, 'utf8');
  assert.notEqual(opaque(text), text, 'the fixture names transmittance schedules');
  const native = nativeYear(FIXTURE);
  const [page, pageOpaque] = await pageYears([text, opaque(text)]);

  // The same surfaces and timesteps, and the same fraction at every one.
  assert.deepEqual(page.names, native.names);
  assert.equal(page.rows.length, native.rows.length);
  let worst = { delta: 0 };
  for (const [r, row] of page.rows.entries()) {
    for (const [c, value] of row.entries()) {
      const delta = Math.abs(value - native.rows[r][c]);
      if (delta > worst.delta) worst = { delta, row: r + 1, surface: page.names[c] };
    }
  }
  assert.ok(worst.delta <= 1e-6, `the page's fractions differ from the native CLI's by up to ${worst.delta} (${worst.surface}, row ${worst.row})`);

  // The schedules matter: with every shade opaque the windows behind them are far darker, so a
  // page that took the shades as opaque would have failed above.
  const lit = means(page);
  const dark = means(pageOpaque);
  for (const window of ['WIN_W', 'WIN_S', 'WIN_E']) {
    assert.ok(lit[window] - dark[window] > 0.02, `${window}: mean ${lit[window].toFixed(4)} with its shade's schedule, ${dark[window].toFixed(4)} with the shade opaque`);
  }
});
