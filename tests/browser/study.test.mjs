// The page's Study mode and its sky model control (headless Chromium, driven by Playwright),
// against the native library through the CLI (`sunlit map --study`, `--sky-model`) on the same
// model and options: a study's CSV downloaded from the page is the CLI's POINTS.study-NAME.csv
// byte for byte, its table and the view's colours say each window's verdict as the CSV does; the
// sky model control changes a map's request as `--sky-model` changes the CLI's; a study with no
// window ticked, or with a sky the rule does not take, is refused naming the option, and leaves
// nothing to download. The view is saved to target/artifacts/study.png for a person to look at.
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, closePage, downloadText, servePage, statusAfter, sunlit, waitForStatus } from './pagetest.mjs';
import { GOLDEN, syntheticEpw } from './epw.mjs';

const EXAMPLE = join(ROOT, 'www/pkg/office.glb');
const ARTIFACTS = join(ROOT, 'target/artifacts');
const WORK = join(tmpdir(), `sunlit-study-${process.pid}`);
const BEIJING = { latitude: '39.9', longitude: '116.4', timezone: '8' };

let served;
let page;
let pageErrors;

before(async () => {
  served = await servePage(WORK);
  ({ page, pageErrors } = served);
  await page.goto(`${served.origin}/`);
  await waitForStatus(page, /^Ready/);
});

after(() => closePage(served, WORK));

const downloaded = (button, name) => downloadText(page, button, join(WORK, name));

/** `sunlit map` on the example office; `read(suffix)` reads one of the files it wrote beside
 * `NAME.csv`. */
function cli(name, args) {
  sunlit(['map', EXAMPLE, ...args, '-o', join(WORK, `${name}.csv`)], WORK);
  return (suffix = '') => readFileSync(join(WORK, `${name}${suffix}.csv`), 'utf8');
}

/** Ticks exactly the windows named. */
async function tick(names) {
  await page.click('#studynone');
  for (const name of names) await page.check(`#studywindows label:has-text("${name}") input`);
}

/** The verdict column of a study CSV (after its two comment lines and header), as the page
 * writes verdicts. */
function verdictsOf(csv) {
  const [, , header, ...rows] = csv.trim().split('\n');
  const column = header.split(',').indexOf('passes');
  const word = { true: 'passes', false: 'fails', 'not-assessed': 'not assessed' };
  return { receivers: rows.map((r) => r.split(',')[0]), verdicts: rows.map((r) => word[r.split(',')[column]]) };
}

test('the Study mode: gb50180 at the sills and bre-vsc at the centres of ticked windows; the CSV is `sunlit map --study`\'s, byte for byte', { timeout: 300_000 }, async () => {
  await page.fill('#receivers', 'WIN_*');
  assert.match(await statusAfter(page, () => page.setInputFiles('#model', EXAMPLE), /^Loaded|^Could not/), /^Loaded office\.glb \(5 receivers\)/);
  await page.fill('#latitude', BEIJING.latitude);
  await page.fill('#longitude', BEIJING.longitude);
  await page.fill('#timezone', BEIJING.timezone);
  await page.selectOption('#mode', 'study');
  assert.equal(await page.isVisible('#days'), false, 'the year\'s sampling is hidden in Study mode');
  assert.equal(await page.isVisible('#mapgrid'), false, 'so is the map\'s grid');
  await page.selectOption('#study', 'gb50180');
  assert.equal(await page.inputValue('#windowpoints'), 'sill', 'GB 50180 counts at the sill');
  assert.equal(await page.isVisible('#gbday'), true);
  await page.click('#studyall');
  const status = await statusAfter(page, () => page.click('#compute'), /^Study|^Could not/, 120_000);
  assert.match(status, /^Study gb50180 in [\d.]+ s: 5 windows, \d+ pass, \d+ fail\.$/);
  const gb = await downloaded('#downloadstudy', 'gb.csv');
  assert.equal(gb.name, 'office.study-gb50180.csv');
  const native = cli('gb', ['--receivers', 'WIN_*', '--window-points', 'sill', '--location', '39.9,116.4,8', '--study', 'gb50180']);
  assert.equal(gb.text, native('.study-gb50180'), 'the page\'s study CSV is the CLI\'s, byte for byte');
  const truth = verdictsOf(gb.text);
  assert.ok(truth.verdicts.includes('passes') && truth.verdicts.includes('fails'), `some windows pass and some fail: ${truth.verdicts}`);
  const shown = await page.evaluate(() => ({
    head: [...document.querySelectorAll('#studytable thead th')].map((th) => th.textContent),
    rows: [...document.querySelectorAll('#studytable tbody tr')].map((tr) => [tr.className, ...[...tr.cells].map((td) => td.textContent)]),
    view: document.getElementById('view').dataset.verdicts,
  }));
  assert.deepEqual(shown.head, ['Window', 'hours', 'Result']);
  assert.deepEqual(shown.rows.map((r) => r[1]), truth.receivers);
  assert.deepEqual(shown.rows.map((r) => r[3]), truth.verdicts, 'the table says what the CSV says');
  assert.deepEqual(shown.rows.map((r) => r[0]), truth.verdicts.map((v) => (v === 'passes' ? 'pass' : 'fail')), 'rows coloured by verdict');
  const painted = truth.receivers.map((name, i) => `${name}:${truth.verdicts[i] === 'passes'}`).join(',');
  assert.equal(shown.view, painted, 'the view paints each window by its verdict');
  await page.screenshot({ path: join(ARTIFACTS, 'study.png'), fullPage: true });

  // VSC on the two south windows only, at their centres: the CLI with just those as receivers.
  await page.selectOption('#study', 'bre-vsc');
  assert.equal(await page.inputValue('#windowpoints'), 'centre');
  await page.selectOption('#skymodel', 'cie-overcast');
  await tick(['WIN_S1', 'WIN_S2']);
  assert.match(await statusAfter(page, () => page.click('#compute'), /^Study|^Could not/, 120_000), /^Study bre-vsc in [\d.]+ s: 2 windows/);
  const vsc = await downloaded('#downloadstudy', 'vsc.csv');
  const nativeVsc = cli('vsc', ['--receivers', 'WIN_S*', '--window-points', 'centre', '--study', 'bre-vsc', '--sky-model', 'cie-overcast']);
  assert.equal(vsc.text, nativeVsc('.study-bre-vsc'));
  assert.equal(verdictsOf(vsc.text).receivers.join(), 'WIN_S1,WIN_S2');
  await page.selectOption('#skymodel', '');
  assert.deepEqual(pageErrors, []);
});

test('bad input: no window ticked, or a sky bre-vsc does not take, is refused naming the option; nothing is left to download', { timeout: 300_000 }, async () => {
  await page.selectOption('#mode', 'study');
  await page.selectOption('#study', 'bre-vsc');
  await page.click('#studyall');
  assert.match(await statusAfter(page, () => page.click('#compute'), /^Study|^Could not/, 120_000), /^Study bre-vsc/);
  assert.equal(await page.isDisabled('#downloadstudy'), false);
  let downloads = 0;
  page.on('download', () => downloads++);

  await page.click('#studynone');
  const none = await statusAfter(page, () => page.click('#compute'), /^Study|^Could not/, 120_000);
  assert.match(none, /^Could not run the study: invalid windows: no window selected/);
  await page.selectOption('#skymodel', 'perez-all-weather');
  await page.click('#studyall');
  const sky = await statusAfter(page, () => page.click('#compute'), /^Study|^Could not/, 120_000);
  assert.match(sky, /^Could not run the study: invalid skyModel: 'perez-all-weather': bre-vsc is defined under the CIE standard overcast sky/);
  await page.selectOption('#skymodel', '');
  const left = await page.evaluate(() => ({
    disabled: document.getElementById('downloadstudy').disabled,
    rows: document.querySelectorAll('#studytable tbody tr').length,
    view: document.getElementById('view').dataset.verdicts,
  }));
  assert.deepEqual(left, { disabled: true, rows: 0, view: '' }, 'the last good study is gone with its download');
  await page.click('#downloadstudy', { force: true });
  await page.waitForTimeout(500);
  assert.equal(downloads, 0, 'no download');
  assert.deepEqual(pageErrors, []);
});

/** Each numeric cell of two points CSVs within 1e-3 (relative above 1), same header and rows;
 * the receivers equal. */
function sameMap(pageText, cliText) {
  const rows = (t) => t.trim().split('\n').map((l) => l.split(','));
  const [a, b] = [rows(pageText), rows(cliText)];
  assert.deepEqual(a[0], b[0], 'same columns');
  assert.equal(a.length, b.length, 'same points');
  for (let i = 1; i < a.length; i++) {
    assert.equal(a[i][0], b[i][0]);
    for (let c = 1; c < a[i].length; c++) {
      const [x, y] = [Number(a[i][c]), Number(b[i][c])];
      assert.ok(Math.abs(x - y) <= 1e-3 * Math.max(1, Math.abs(y)), `row ${i} ${a[0][c]}: page ${x}, CLI ${y}`);
    }
  }
  return a;
}

test('the sky model control: a day\'s total irradiation map under perez-all-weather equals `sunlit map --sky-model perez-all-weather`, and differs from the default sky', { timeout: 600_000 }, async () => {
  // The office as the first test loaded it: its five windows are the receivers.
  const epwPath = join(WORK, 'golden.epw');
  writeFileSync(epwPath, syntheticEpw(GOLDEN));
  await page.setInputFiles('#epw', epwPath);
  await page.waitForFunction(() => document.getElementById('latitude').value === '39.74', null, { timeout: 60_000 });
  await page.selectOption('#mode', 'map');
  await page.fill('#mapgrid', '0.5');
  await page.selectOption('#mapvalue', 'total');
  await page.selectOption('#mapperiod', 'day');
  await page.fill('#mapstart', '06-21');
  await page.fill('#mapstep', '60');
  await page.fill('#mapfrom', '05:00');
  await page.fill('#mapto', '19:00');
  const day = ['--receivers', 'WIN_*', '--grid', '0.5', '--epw', epwPath, '--period', '06-21', '--step', '60', '--from', '05:00', '--to', '19:00'];
  const maps = {};
  for (const sky of ['perez-all-weather', '']) {
    await page.selectOption('#skymodel', sky);
    assert.match(await statusAfter(page, () => page.click('#compute'), /^Map in|^Could not/, 300_000), /^Map in [\d.]+ s/);
    const { text } = await downloaded('#downloadmap', `sky-${sky || 'default'}.csv`);
    const native = cli(`sky-${sky || 'default'}`, [...day, ...(sky ? ['--sky-model', sky] : [])])();
    maps[sky || 'default'] = sameMap(text, native);
  }
  const diffuse = maps.default[0].indexOf('sky_diffuse_kwh_m2');
  const changed = maps.default.slice(1).filter((row, i) => row[diffuse] !== maps['perez-all-weather'][i + 1][diffuse]).length;
  assert.ok(changed > 0, 'the sky model changes the sky-diffuse irradiation');
  console.log(`sky model control: ${maps.default.length - 1} points, ${changed} with another sky-diffuse value under perez-all-weather`);
  await page.setInputFiles('#epw', []);
  assert.deepEqual(pageErrors, []);
});
