// The page's Study mode with an existing scene and the HTML report (headless Chromium, driven by
// Playwright), against the native library through the CLI (`sunlit map --study … --before MODEL
// --mask all --html REPORT.html`), run in the same folder on the same files so that the report
// names them alike: the proposal is the example office with a 12 m block 6 m to its south, the
// existing scene the office alone. The page's study CSV and its report are the CLI's byte for
// byte; its table shows each window's former value, the ratio and the relative test as the
// CLI's JSON says; a window's sky mask shown is the CLI's POINTS.mask-N.svg; an existing scene
// with none of the windows is refused naming `before`, and clearing it studies the model alone.
import assert from 'node:assert/strict';
import { copyFileSync, readFileSync, writeFileSync } from 'node:fs';
import { execFileSync } from 'node:child_process';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { ROOT, closePage, downloadText, servePage, statusAfter, sunlit, waitForStatus } from './pagetest.mjs';
import { GOLDEN, syntheticEpw } from './epw.mjs';

const WORK = join(tmpdir(), `sunlit-study-before-${process.pid}`);
const at = (name) => join(WORK, name);

let served;
let page;
let pageErrors;

/** A closed box as a .gltf (tests/planning/box_gltf.py), sunlit's axes (x east, y north, z up). */
function box(name, node, lo, hi) {
  execFileSync('python3', [join(ROOT, 'tests/planning/box_gltf.py'), at(name), node, ...lo.map(String), ...hi.map(String)]);
}

before(async () => {
  served = await servePage(WORK);
  ({ page, pageErrors } = served);
  copyFileSync(join(ROOT, 'examples/office.glb'), at('office.glb'));
  box('block.gltf', 'BLOCK', [-10, -14, 0], [40, -8, 12]);
  box('elsewhere.gltf', 'WIN_FAR', [500, 500, 0], [501, 501, 1]);
  writeFileSync(at('golden.epw'), syntheticEpw(GOLDEN));
  await page.goto(`${served.origin}/`);
  await waitForStatus(page, /^Ready/);
});

after(() => closePage(served, WORK));

/** `sunlit map office.glb block.gltf … --before office.glb --mask all --html NAME.html -o
 * NAME.csv` in the test's folder; `read(suffix)` reads a file it wrote beside NAME. */
function cli(name, args) {
  const all = ['map', 'office.glb', 'block.gltf', '--receivers', 'WIN_*', ...args, '--before', 'office.glb', '--mask', 'all'];
  sunlit([...all, '--html', `${name}.html`, '-o', `${name}.csv`], WORK, WORK);
  return (suffix) => readFileSync(at(`${name}${suffix}`), 'utf8');
}

async function runStudy(pattern = /^Study/) {
  return statusAfter(page, () => page.click('#compute'), new RegExp(`${pattern.source}|^Could not`), 120_000);
}

/** The study table as shown: its head, and per row its cells. */
const shownTable = () =>
  page.evaluate(() => ({
    head: [...document.querySelectorAll('#studytable thead th')].map((th) => th.textContent),
    rows: [...document.querySelectorAll('#studytable tbody tr')].map((tr) => [...tr.cells].map((td) => td.textContent)),
  }));

const fixed = (x, digits) => (x === null ? '–' : x.toFixed(digits));

test('before and after: bre-vsc and bre-apsh against the existing scene; the CSV, the report and the masks are the CLI\'s, byte for byte', { timeout: 600_000 }, async () => {
  await page.fill('#receivers', 'WIN_*');
  const loaded = await statusAfter(page, () => page.setInputFiles('#model', [at('office.glb'), at('block.gltf')]), /^Loaded|^Could not/);
  assert.match(loaded, /^Loaded office\.glb, block\.gltf \(5 receivers\)/);
  await page.fill('#latitude', '39.9');
  await page.fill('#longitude', '116.4');
  await page.fill('#timezone', '8');
  await page.selectOption('#mode', 'study');
  await page.selectOption('#study', 'bre-vsc');
  assert.match(await statusAfter(page, () => page.setInputFiles('#studybefore', at('office.glb')), /^Existing scene|^Could not/), /^Existing scene read/);
  assert.match(await page.textContent('#studybeforeinfo'), /^office\.glb \(5 receivers\)/);
  await page.click('#studyall');
  assert.match(await runStudy(), /^Study bre-vsc in [\d.]+ s: 5 windows/);

  const read = cli('vsc', ['--window-points', 'centre', '--location', '39.9,116.4,8', '--study', 'bre-vsc']);
  const csv = await downloadText(page, '#downloadstudy', at('page-vsc.csv'));
  assert.equal(csv.name, 'office.study-bre-vsc.csv');
  assert.equal(csv.text, read('.study-bre-vsc.csv'), 'the before/after CSV is the CLI\'s, byte for byte');
  assert.match(csv.text.split('\n')[2], /,vsc,vsc_before,passes$/);
  const report = await downloadText(page, '#downloadreport', at('page-vsc.html'));
  assert.equal(report.name, 'office.study-bre-vsc.html');
  assert.equal(report.text, read('.html'), 'the report is `--html`\'s, byte for byte');
  assert.ok(report.text.includes('vsc before') && report.text.includes('<svg'), 'with the former values and the masks');

  // The table: each window's value, former value, ratio and relative test as the CLI's JSON.
  const json = JSON.parse(read('.study-bre-vsc.json'));
  const shown = await shownTable();
  assert.deepEqual(shown.head, ['Window', 'vsc', 'vsc before', 'vsc ratio', '0.8 × former', 'Result']);
  const expected = json.points.map((p) => [
    p.receiver,
    fixed(p.vsc, 2),
    fixed(p.vsc_before, 2),
    fixed(p.vsc_ratio, 2),
    p.passes_relative === null ? '–' : p.passes_relative ? 'kept' : 'lost',
    p.passes ? 'passes' : 'fails',
  ]);
  assert.deepEqual(shown.rows, expected);
  assert.ok(json.points.some((p) => p.vsc < p.vsc_before - 3), 'the block takes sky from some windows');

  // The first window's mask is shown; a row selected shows its own, each the CLI's SVG (both as
  // the browser's DOM writes them out: it closes empty elements its own way).
  const mask = () => page.evaluate(() => document.getElementById('studymask').innerHTML);
  const asShown = (svg) => page.evaluate((text) => Object.assign(document.createElement('div'), { innerHTML: text }).innerHTML, svg);
  assert.equal(await mask(), await asShown(read('.mask-1.svg')));
  await page.click('#studytable tbody tr:nth-child(4)');
  assert.equal(await mask(), await asShown(read('.mask-4.svg')));
  assert.notEqual(await mask(), await asShown(read('.mask-1.svg')), 'another window, another mask');
  await page.screenshot({ path: join(ROOT, 'target/artifacts/study-before.png'), fullPage: true });

  // APSH from the EPW: the 4-point loss beside 0.8 × former.
  await page.setInputFiles('#epw', at('golden.epw'));
  await page.waitForFunction(() => document.getElementById('latitude').value === '39.74', null, { timeout: 60_000 });
  await page.selectOption('#study', 'bre-apsh');
  assert.match(await runStudy(), /^Study bre-apsh in [\d.]+ s: 5 windows/);
  const apsh = cli('apsh', ['--window-points', 'centre', '--epw', 'golden.epw', '--study', 'bre-apsh']);
  assert.equal((await downloadText(page, '#downloadstudy', at('page-apsh.csv'))).text, apsh('.study-bre-apsh.csv'));
  assert.equal((await downloadText(page, '#downloadreport', at('page-apsh.html'))).text, apsh('.html'));
  const apshJson = JSON.parse(apsh('.study-bre-apsh.json'));
  const apshRows = (await shownTable()).rows;
  assert.deepEqual(
    apshRows.map((r) => r[7]),
    apshJson.points.map((p) => (p.passes_relative === null ? '–' : p.passes_relative ? 'kept' : 'lost')),
  );
  await page.setInputFiles('#epw', []);
  assert.deepEqual(pageErrors, []);
});

test('bad input: an existing scene with none of the windows is refused naming `before`; cleared, the model is studied alone', { timeout: 300_000 }, async () => {
  await page.selectOption('#mode', 'study');
  await page.selectOption('#study', 'bre-vsc');
  await page.click('#studyall');
  assert.match(await statusAfter(page, () => page.setInputFiles('#studybefore', at('elsewhere.gltf')), /^Existing scene|^Could not/), /^Existing scene read/);
  const refused = await runStudy();
  assert.match(refused, /^Could not run the study: invalid before: no point of the windows' centres lies on a receiver of the existing scene/);
  assert.equal(await page.isDisabled('#downloadreport'), true, 'no report of a refused study');
  await page.click('#studybeforeclear');
  assert.match(await runStudy(), /^Study bre-vsc in [\d.]+ s: 5 windows/);
  assert.deepEqual((await shownTable()).head, ['Window', 'vsc', 'Result'], 'no former values without an existing scene');
  assert.deepEqual(pageErrors, []);
});

test('picking windows: a click on a window in the 3D view ticks it (and again unticks it), a drag does not', { timeout: 300_000 }, async () => {
  // Two 2 m windows either side of the view's centre along the default camera's horizontal axis
  // (yaw −0.6 rad: right = (cos 0.6, −sin 0.6, 0)), 10 m out, so both lie on the view's
  // midline; their screen positions are the pinhole projection of their centres.
  const right = [Math.cos(0.6), -Math.sin(0.6)];
  for (const [name, sign] of [['WIN_A', -1], ['WIN_B', 1]]) {
    const [cx, cy] = right.map((r) => sign * 10 * r);
    box(`${name}.gltf`, name, [cx - 1, cy - 1, 0], [cx + 1, cy + 1, 2]);
  }
  // Receivers are still WIN_* (the first test's).
  const loaded = await statusAfter(page, () => page.setInputFiles('#model', [at('WIN_A.gltf'), at('WIN_B.gltf')]), /^Loaded|^Could not/);
  // Each box face is a receiver of its node's name (WIN_A…, WIN_B…): 12.
  assert.match(loaded, /^Loaded WIN_A\.gltf, WIN_B\.gltf \(12 receivers\)/);
  await page.selectOption('#mode', 'study');
  await page.click('#studynone');
  // The first test's table and mask may have scrolled the view away: clicks land in the viewport.
  await page.locator('#view').scrollIntoViewIfNeeded();
  const view = await page.locator('#view').boundingBox();
  const ticked = () => page.evaluate(() => [...document.querySelectorAll('#studywindows input:checked')].map((b) => b.parentElement.textContent.trim()));
  // Click along the midline, left to right: what each click ticked (or unticked).
  const hits = [];
  for (let f = 0.02; f <= 0.98; f += 0.01) {
    const before = await ticked();
    await page.mouse.click(view.x + f * view.width, view.y + view.height / 2);
    const now = await ticked();
    const changed = [...now.filter((n) => !before.includes(n)), ...before.filter((n) => !now.includes(n))];
    assert.ok(changed.length <= 1, `one click, one window at most: ${changed}`);
    assert.ok(!changed.length || /^WIN_[AB]/.test(changed[0]), changed[0]);
    hits.push([f, changed[0]]);
  }
  const centre = (name) => {
    const fs = hits.filter(([, n]) => n?.startsWith(name)).map(([f]) => f);
    assert.ok(fs.length > 0, `${name} was hit: ${JSON.stringify(hits.filter(([, n]) => n))}`);
    return (Math.min(...fs) + Math.max(...fs)) / 2;
  };
  // The pinhole projection: depth d = 1.6 × the scene's diagonal, offset 10 m, fov 0.8 rad.
  const [w, h] = await page.evaluate(() => [document.getElementById('view').width, document.getElementById('view').height]);
  const depth = 1.6 * Math.hypot(20 * right[0] + 2, 20 * Math.abs(right[1]) + 2, 2);
  const offset = 10 / (depth * Math.tan(0.4) * (w / h)) / 2;
  assert.ok(Math.abs(centre('WIN_A') - (0.5 - offset)) < 0.02, `WIN_A at ${centre('WIN_A')}, projected ${0.5 - offset}`);
  assert.ok(Math.abs(centre('WIN_B') - (0.5 + offset)) < 0.02, `WIN_B at ${centre('WIN_B')}, projected ${0.5 + offset}`);
  assert.equal(hits.find(([f]) => Math.abs(f - 0.5) < 0.005)?.[1], undefined, 'nothing between them');
  // A drag turns the view and ticks nothing.
  const before = await ticked();
  await page.mouse.move(view.x + view.width / 2, view.y + view.height / 2);
  await page.mouse.down();
  await page.mouse.move(view.x + view.width / 2 + 60, view.y + view.height / 2, { steps: 5 });
  await page.mouse.up();
  assert.deepEqual(await ticked(), before, 'a drag is not a click');
  assert.deepEqual(pageErrors, []);
});
