// The page's per-window 满窗 (whole window) widths for GB 50180 (headless Chromium, driven by
// Playwright), against the native library through the CLI on the same model and options: each
// window's own sill measured from its geometry gives `sunlit map --window-points sill
// --window-width sill`'s CSV byte for byte, a table of widths typed in the page gives
// `--window-widths FILE.csv`'s, and both differ from one narrow width for every window (so a
// dropped option fails the test); the table shows the whole window's hours beside the point's.
// A width that is not positive in the table, the measured sill at the windows' centres, and a
// window named that is not in the model are refused naming the option, with nothing to download.
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, closePage, downloadText, readyPage, statusAfter, sunlit } from './pagetest.mjs';

const EXAMPLE = join(ROOT, 'www/pkg/office.glb');
const WORK = join(tmpdir(), `sunlit-study-widths-${process.pid}`);
const WINDOWS = ['--receivers', 'WIN_*', '--window-points', 'sill', '--location', '39.9,116.4,8', '--study', 'gb50180'];
/** Each window's own width, as a person would type them (not the windows' measured sills). */
const TABLE = 'receiver,width\nWIN_S1,0.5\nWIN_S2,4\nWIN_E,0.3\nWIN_N,2.5\nWIN_W,6\n';

let served;
let page;
let pageErrors;

before(async () => {
  ({ page, pageErrors } = served = await readyPage(WORK));
  await page.fill('#receivers', 'WIN_*');
  assert.match(await statusAfter(page, () => page.setInputFiles('#model', EXAMPLE), /^Loaded|^Could not/), /^Loaded office\.glb \(5 receivers\)/);
  await page.fill('#latitude', '39.9');
  await page.fill('#longitude', '116.4');
  await page.fill('#timezone', '8');
  await page.selectOption('#mode', 'study');
  await page.selectOption('#study', 'gb50180');
  await page.click('#studyall');
});

after(() => closePage(served, WORK));

/** `sunlit map --study gb50180` at the office's sills with `args`: its study CSV, and its JSON's
 * points and rule. */
function cli(name, args) {
  sunlit(['map', EXAMPLE, ...WINDOWS, ...args, '-o', join(WORK, `${name}.csv`)], WORK);
  const read = (suffix) => readFileSync(join(WORK, `${name}.study-gb50180.${suffix}`), 'utf8');
  const json = JSON.parse(read('json'));
  return { csv: read('csv'), points: json.points, rule: json.rule };
}

/** Runs the study shown: the page's status, its table (head and rows) and its CSV. */
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

test('each window\'s own sill in the page: measured from the geometry, or typed in a table; the CSVs are the CLI\'s', { timeout: 300_000 }, async () => {
  assert.equal(await page.inputValue('#windowpoints'), 'sill');
  assert.equal(await page.isVisible('#gbwhole'), true);
  assert.equal(await page.isVisible('#gbwidths'), false, 'the table shows only when asked for');
  await page.selectOption('#gbwhole', 'sill');
  assert.equal(await page.isVisible('#gbwidth'), false, 'a measured sill needs no width');
  const measured = await pageStudy('sill.csv');
  assert.match(measured.status, /^Study gb50180 in [\d.]+ s: 5 windows/);
  const native = cli('sill', ['--window-width', 'sill']);
  assert.equal(measured.csv, native.csv, 'the page\'s CSV is `--window-width sill`\'s byte for byte');
  assert.deepEqual(measured.table.head, ['Window', 'hours', 'hours_whole_window', 'Result']);
  assert.deepEqual(measured.table.rows.map((r) => r[2]), native.points.map((p) => p.hours_whole_window.toFixed(2)));
  const widths = native.rule.whole_window_widths_m;
  assert.equal(widths.length, 5);
  assert.ok(widths.every((w) => w > 0.3 && w < 20), `each window's measured sill: ${widths}`);
  const narrow = cli('narrow', ['--window-width', '0.05']);
  assert.notEqual(native.csv, narrow.csv, 'the measured sills change the answer (the test sees a dropped option)');

  await page.selectOption('#gbwhole', 'table');
  assert.equal(await page.isVisible('#gbwidths'), true);
  await page.fill('#gbwidths', TABLE);
  const typed = await pageStudy('table.csv');
  assert.match(typed.status, /^Study gb50180/);
  writeFileSync(join(WORK, 'widths.csv'), TABLE);
  const nativeTable = cli('table', ['--window-widths', join(WORK, 'widths.csv')]);
  assert.equal(typed.csv, nativeTable.csv, 'the page\'s CSV is `--window-widths`\'s byte for byte');
  assert.deepEqual(nativeTable.rule.whole_window_widths_m, [0.5, 4, 0.3, 2.5, 6]);
  assert.notEqual(nativeTable.csv, native.csv, 'the typed widths are not the measured ones');
  assert.deepEqual(pageErrors, []);
});

test('bad input: a width that is not positive, the measured sill at the centres, a window not in the model; refused naming the option, nothing to download', { timeout: 300_000 }, async () => {
  await page.selectOption('#gbwhole', 'table');
  await page.fill('#gbwidths', 'receiver,width\nWIN_S1,0\n');
  const zero = await pageStudy('none.csv');
  assert.match(zero.status, /^Could not run the study: windowWidths: line 2: width 0 m is not in \(0, 20\]/);
  assert.equal(await page.isDisabled('#downloadstudy'), true);
  await page.fill('#gbwidths', 'receiver,width\nWIN_S1,1\nWIN_X,1\n');
  const unknown = await pageStudy('none.csv');
  assert.match(unknown.status, /^Could not run the study: windowWidths: line 3: 'WIN_X' is not one of the model's chosen receivers/);
  await page.selectOption('#gbwhole', 'width');
  await page.fill('#gbwidth', '-1');
  const negative = await pageStudy('none.csv');
  assert.match(negative.status, /^Could not run the study: invalid windowWidth: -1 m is not in \(0, 20\]/);
  await page.selectOption('#gbwhole', 'sill');
  await page.selectOption('#windowpoints', 'centre');
  const centre = await pageStudy('none.csv');
  assert.match(centre.status, /^Could not run the study: invalid windowWidth: 'sill' measures each window's own sill line.*centres are not their sills/);
  assert.equal(await page.isDisabled('#downloadstudy'), true);
  assert.equal(await page.isDisabled('#downloadreport'), true);
  await page.selectOption('#windowpoints', 'sill');
  assert.deepEqual(pageErrors, []);
});
