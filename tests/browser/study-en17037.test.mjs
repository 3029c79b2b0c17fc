// The page's Study mode for EN 17037 and the ground floor's level (headless Chromium, driven by
// Playwright), against the native library through the CLI on the same model and options: with a
// day and a minimum altitude that are not the defaults, the page's table and downloaded CSV are
// `sunlit map --study en17037 --period 02-21 --min-altitude 15`'s, and they differ from the
// defaults' (so an option the page drops fails the test); the sills raised above a floor level
// are `--window-points sill --floor-level`'s, and differ from the lowest edges'; a floor level
// without the sill, and a day outside the standard's, are refused naming the option.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, closePage, downloadText, readyPage, statusAfter, sunlit } from './pagetest.mjs';

const EXAMPLE = join(ROOT, 'www/pkg/office.glb');
const WORK = join(tmpdir(), `sunlit-study-en17037-${process.pid}`);
const LONDON = ['--location', '51.5,-0.12,0'];

let served;
let page;
let pageErrors;

before(async () => {
  ({ page, pageErrors } = served = await readyPage(WORK));
  await page.fill('#receivers', 'WIN_*');
  assert.match(await statusAfter(page, () => page.setInputFiles('#model', EXAMPLE), /^Loaded|^Could not/), /^Loaded office\.glb \(5 receivers\)/);
  await page.fill('#latitude', '51.5');
  await page.fill('#longitude', '-0.12');
  await page.fill('#timezone', '0');
  await page.selectOption('#mode', 'study');
  await page.selectOption('#study', 'en17037');
  await page.click('#studyall');
});

after(() => closePage(served, WORK));

/** `sunlit map --study en17037` on the example office with `args`: its study CSV and the JSON's
 * hours per point. */
function cli(name, args) {
  sunlit(['map', EXAMPLE, '--receivers', 'WIN_*', ...LONDON, '--study', 'en17037', ...args, '-o', join(WORK, `${name}.csv`)], WORK);
  const read = (suffix) => readFileSync(join(WORK, `${name}.study-en17037.${suffix}`), 'utf8');
  return { csv: read('csv'), hours: JSON.parse(read('json')).points.map((p) => p.hours) };
}

/** Runs the study shown and returns the page's status, its table's hours and verdicts, and its CSV. */
async function pageStudy(name) {
  const status = await statusAfter(page, () => page.click('#compute'), /^Study|^Could not/, 120_000);
  if (!status.startsWith('Study')) return { status };
  const table = await page.evaluate(() => ({
    head: [...document.querySelectorAll('#studytable thead th')].map((th) => th.textContent),
    rows: [...document.querySelectorAll('#studytable tbody tr')].map((tr) => [...tr.cells].map((td) => td.textContent)),
  }));
  const csv = (await downloadText(page, '#downloadstudy', join(WORK, name))).text;
  return { status, table, csv };
}

test('EN 17037 in the page: its day and minimum altitude reach the library; the table and CSV are the CLI\'s', { timeout: 300_000 }, async () => {
  assert.equal(await page.inputValue('#windowpoints'), 'centre', 'EN 17037 at the windows\' centres');
  assert.equal(await page.isVisible('#enperiod'), true);
  assert.equal(await page.isVisible('#gbday'), false, 'GB 50180\'s fields are hidden');
  await page.fill('#enperiod', '02-21');
  await page.fill('#enminaltitude', '15');
  const shown = await pageStudy('en.csv');
  assert.match(shown.status, /^Study en17037 in [\d.]+ s: 5 windows, \d+ pass, \d+ fail\.$/);
  const native = cli('en', ['--window-points', 'centre', '--period', '02-21', '--min-altitude', '15']);
  const defaults = cli('en-default', ['--window-points', 'centre']);
  assert.equal(shown.csv, native.csv, 'the page\'s CSV is the CLI\'s byte for byte');
  assert.notEqual(native.csv, defaults.csv, 'the day and altitude change the answer (the test sees a dropped option)');
  assert.notDeepEqual(native.hours, defaults.hours, 'and the hours themselves');
  assert.deepEqual(shown.table.head, ['Window', 'hours', 'Result']);
  assert.deepEqual(shown.table.rows.map((r) => r[1]), native.hours.map((h) => h.toFixed(2)), 'the table\'s hours are the CLI\'s');
  const level = native.hours.map((h) => (h >= 1.5 ? 'passes' : 'fails'));
  assert.ok(level.includes('passes') && level.includes('fails'), `some windows pass and some fail: ${native.hours}`);
  assert.deepEqual(shown.table.rows.map((r) => r[2]), level, 'the verdict is the minimum level, 1.5 h');
  assert.deepEqual(pageErrors, []);
});

test('the ground floor level in the page: the sills raised as `--floor-level` raises them', { timeout: 300_000 }, async () => {
  await page.fill('#enperiod', '');
  await page.fill('#enminaltitude', '');
  await page.selectOption('#windowpoints', 'sill');
  // The office's south sills are 1.0 m up, the others 1.2 m: a floor at 0.3 m raises the south
  // ones to 1.2 m.
  await page.fill('#floorlevel', '0.3');
  const shown = await pageStudy('floor.csv');
  assert.match(shown.status, /^Study en17037/);
  const native = cli('floor', ['--window-points', 'sill', '--floor-level', '0.3']);
  const lowest = cli('lowest', ['--window-points', 'sill']);
  assert.equal(shown.csv, native.csv, 'the page\'s CSV is the CLI\'s byte for byte');
  assert.notEqual(native.csv, lowest.csv, 'the floor level moves the sills (the test sees a dropped option)');
  assert.deepEqual(shown.table.rows.map((r) => r[1]), native.hours.map((h) => h.toFixed(2)));
  assert.deepEqual(pageErrors, []);
});

test('bad input: a floor level without the sill, a day outside 02-01..03-21, are refused naming the option; nothing to download', { timeout: 300_000 }, async () => {
  await page.selectOption('#windowpoints', 'centre');
  await page.fill('#floorlevel', '0.3');
  const floor = await pageStudy('none.csv');
  assert.match(floor.status, /^Could not run the study: invalid floorLevel: raises the windows' sills/);
  assert.equal(await page.isDisabled('#downloadstudy'), true);
  await page.fill('#floorlevel', '');
  await page.fill('#enperiod', '06-21');
  const day = await pageStudy('none.csv');
  assert.match(day.status, /^Could not run the study: invalid period: 06-21: EN 17037 evaluates one day from 02-01 to 03-21/);
  assert.equal(await page.isDisabled('#downloadstudy'), true);
  await page.fill('#enperiod', '');
  assert.deepEqual(pageErrors, []);
});
