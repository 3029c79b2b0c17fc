// The page's Study mode: planning rules per window (engine.study, run by the worker): a rule, a
// point on each ticked window (a receiver), GB 50180's and EN 17037's parameters and the ground
// floor's level that sills are raised above (handed on as typed); the results as a table per
// window and the windows coloured pass/fail in the 3D view; the study's CSV to download, as
// `sunlit map --study NAME` writes POINTS.study-NAME.csv (the library's own writer), and its HTML
// report as `--html` writes it (with every window's sky mask, `--mask all`). An existing scene
// GB 50180's 满窗 (whole window) rule takes one sill width, each window's own sill measured from its
// geometry (`--window-width sill`), or each window's width from a table the user types, a
// `receiver,width` CSV as `--window-widths` reads it. An existing scene
// (`--before`) may be loaded beside the model: the table then shows each window's former value,
// the ratio and BRE's relative test (0.8 × former). Windows are ticked in a list or by clicking
// them in the 3D view. Nothing here
// decides a rule: the options are handed on as the user set them, and the library refuses what
// is wrong (no window ticked, a sky the rule does not take) naming the option.
import { UNCOMPUTED } from './colour.js';

/** A window that passes, fails, or is not assessed by the rule. */
export const PASS = [0.2, 0.66, 0.32];
export const FAIL = [0.84, 0.2, 0.17];
export const NOT_ASSESSED = [0.55, 0.55, 0.58];

/**
 * Wires the Study mode's controls. `page`: { $, worker, status, location() (the form's location
 * as StudyOptions keys), skyModel() (the sky control's value, '' for the default), engineOptions(),
 * viewer() (the 3D view, its model set, or null), showLegend({ max, title, tick }), setBusy(busy), download(name, text, type),
 * modelName(), modelFiles() (the model's own file names, as the CLI is given them), names() (the
 * model's receiver names), readFiles(fileList) (the chosen files' names and bytes, or null after
 * saying why not) }.
 */
export function studyMode(page) {
  const { $ } = page;
  const state = { study: null, asked: null, before: null, reading: null };

  const mode = () => $('mode').value;

  function showFields() {
    const study = mode() === 'study';
    $('studyfields').hidden = !study;
    // The colour bar is a value scale; the windows' colours are verdicts, named in the title.
    document.querySelector('#legend .bar').hidden = study;
    for (const el of document.querySelectorAll('[data-study]')) el.hidden = !el.dataset.study.split(' ').includes($('study').value);
    // The 满窗 width's own fields, for the way it is asked.
    for (const el of document.querySelectorAll('[data-whole]')) el.hidden ||= el.dataset.whole !== $('gbwhole').value;
    if (study) $('compute').textContent = 'Run study';
    $('studywrap').hidden = !study || !state.study;
    recolour();
  }

  /** The 3D view's receivers: each studied window by its verdict, the others uncomputed. */
  function recolour() {
    if (mode() !== 'study') return;
    page.showLegend({ max: 1, title: 'Study per window (green: passes, red: fails, grey: not assessed)', tick: () => '' });
    const verdicts = state.study ? verdictsByReceiver(state.study) : new Map();
    // What the view paints, for a reader (and the tests): each studied window's verdict.
    $('view').dataset.verdicts = [...verdicts].map(([r, v]) => `${page.names()[r]}:${v}`).join(',');
    const viewer = page.viewer();
    if (!viewer) return;
    viewer.setColours((r) => {
      const v = verdicts.get(r);
      return v === undefined ? UNCOMPUTED : v === true ? PASS : v === false ? FAIL : NOT_ASSESSED;
    });
  }

  /** Each studied receiver's verdict: true if all its points pass, false if one fails, null if
   * none is assessed (as the report's `areas`). */
  function verdictsByReceiver({ receivers, tables }) {
    const passes = tables[0].passes;
    const out = new Map();
    receivers.forEach((r, i) => {
      const p = passes[i];
      const was = out.get(r);
      if (p === null) out.set(r, was ?? null);
      else out.set(r, was === false ? false : p);
    });
    return out;
  }

  /** The ticked windows' receiver indices, in the model's order. */
  function windows() {
    return [...$('studywindows').querySelectorAll('input:checked')].map((el) => Number(el.value));
  }

  async function options() {
    const o = { ...(await page.location()), study: $('study').value, windows: windows(), windowPoints: $('windowpoints').value };
    // What the report states and draws, as the CLI's MODEL..., --before MODEL... and --mask all.
    o.modelNames = page.modelFiles();
    if (state.before) o.beforeNames = state.before;
    if ($('studymasks').checked) o.masks = 'all';
    const sky = page.skyModel();
    if (sky) o.skyModel = sky;
    // A floor level is handed on whenever one is typed: the library refuses it without the sill.
    if ($('floorlevel').value.trim() !== '') o.floorLevel = Number($('floorlevel').value);
    if (o.study === 'gb50180') {
      o.day = $('gbday').value;
      for (const [id, key] of [['gbhours', 'requiredHours'], ['gbminperiod', 'minPeriod'], ['gbmaxperiods', 'maxPeriods']]) {
        if ($(id).value.trim() !== '') o[key] = Number($(id).value);
      }
      // 满窗: one width (as typed, empty refused by the library as no number), each window's own
      // sill ('sill'), or the table's text as the CSV `--window-widths` reads.
      const whole = $('gbwhole').value;
      if (whole === 'width') o.windowWidth = $('gbwidth').value.trim() === '' ? '' : Number($('gbwidth').value);
      if (whole === 'sill') o.windowWidth = 'sill';
      if (whole === 'table') o.windowWidths = $('gbwidths').value;
    }
    if (o.study === 'en17037') {
      if ($('enperiod').value.trim() !== '') o.period = $('enperiod').value.trim();
      if ($('enminaltitude').value.trim() !== '') o.minAltitude = Number($('enminaltitude').value);
    }
    return o;
  }

  /** Forgets the last study: its table, colours and download (a new study, a failed one, a new
   * model), so no download is ever of another study than the one shown. */
  function clear() {
    state.study = null;
    state.asked = null;
    $('downloadstudy').disabled = true;
    $('downloadreport').disabled = true;
    $('studymaskfigure').hidden = true;
    $('studymask').replaceChildren();
    $('studytable').tHead.replaceChildren();
    $('studytable').tBodies[0].replaceChildren();
    $('studytable').removeAttribute('data-verdicts');
    showFields();
  }

  async function compute() {
    clear();
    page.worker.postMessage({ type: 'study', options: await options(), engine: page.engineOptions() });
  }

  function shown({ study, seconds }) {
    page.setBusy(false);
    state.study = study;
    fillTable(study);
    $('downloadstudy').disabled = false;
    $('downloadreport').disabled = false;
    showMask(0);
    showFields();
    const t = study.tables[0];
    const count = (v) => t.passes.filter((p) => p === v).length;
    const na = count(null) ? `, ${count(null)} not assessed` : '';
    page.status(`Study ${t.study} in ${seconds.toFixed(1)} s: ${t.passes.length} windows, ${count(true)} pass, ${count(false)} fail${na}.`);
  }

  /** Per window: its values, and with an existing scene each value's former one and the ratio,
   * and the relative test (BRE's 0.8 × former; APSH's also the 4-point loss), then the verdict. */
  function fillTable({ receivers, tables }) {
    const table = tables[0];
    const names = page.names();
    const keys = Object.keys(table.values);
    const former = table.before;
    const columns = keys.flatMap((key) => (former ? [key, `${key} before`, `${key} ratio`] : [key]));
    const head = $('studytable').tHead.insertRow();
    for (const title of ['Window', ...columns, ...(former ? ['0.8 × former'] : []), 'Result']) {
      const th = document.createElement('th');
      th.scope = 'col';
      th.textContent = title;
      head.append(th);
    }
    const body = $('studytable').tBodies[0];
    const verdicts = [];
    const number = (x, digits) => (x === null || x === undefined ? '–' : x.toFixed(digits));
    receivers.forEach((r, i) => {
      const row = body.insertRow();
      const pass = table.passes[i];
      row.className = pass === null ? 'na' : pass ? 'pass' : 'fail';
      row.dataset.point = String(i);
      // textContent, never innerHTML: names come from the user's file.
      row.insertCell().textContent = names[r];
      for (const key of keys) {
        const cells = [number(table.values[key][i], 2), ...(former ? [number(former[key][i], 2), number(table.ratio[key][i], 2)] : [])];
        for (const text of cells) {
          const cell = row.insertCell();
          cell.textContent = text;
          cell.className = 'num';
        }
      }
      if (former) {
        const relative = table.relative[i];
        row.insertCell().textContent = relative === null ? '–' : relative ? 'kept' : 'lost';
      }
      const verdict = row.insertCell();
      verdict.className = 'verdict';
      verdict.textContent = pass === null ? 'not assessed' : pass ? 'passes' : 'fails';
      verdicts.push(verdict.textContent);
    });
    $('studycaption').textContent = `${table.study}: ${table.source}${former ? ' (against the existing scene)' : ''}`;
    $('studytable').dataset.verdicts = verdicts.join(',');
  }

  /** Point `i`'s sky mask under the table, if it was drawn. The SVG is the library's (every
   * text in it escaped there), the same as the report's. */
  function showMask(i) {
    const svg = state.study?.masks?.[i];
    $('studymaskfigure').hidden = !svg;
    if (!svg) return;
    $('studymask').innerHTML = svg;
    $('studymaskcaption').textContent = `Sky mask of ${page.names()[state.study.receivers[i]]} (point ${i + 1}): stereographic, north up; dark: obstructed sky; orange: sun paths.`;
    $('studymaskfigure').dataset.point = String(i);
  }

  /** Ticks or unticks window `r` (a receiver index), as a click on it in the 3D view asks. */
  function toggleWindow(r) {
    const box = $('studywindows').querySelector(`input[value="${r}"]`);
    if (!box) return false;
    box.checked = !box.checked;
    return true;
  }

  /** The existing scene, chosen in the file field: read by the worker with the model's options. */
  async function chooseBefore() {
    const files = await page.readFiles($('studybefore').files);
    if (!files?.length) return;
    const names = files.map((f) => f.name).filter((n) => !/\.(bin|png|jpe?g|webp|ktx2)$/i.test(n));
    state.reading = names;
    $('studybeforeinfo').textContent = `Reading ${names.join(', ')}…`;
    page.worker.postMessage({ type: 'loadBefore', files, engine: page.engineOptions() });
  }

  function clearBefore() {
    state.before = null;
    state.reading = null;
    $('studybefore').value = '';
    $('studybeforeclear').disabled = true;
    $('studybeforeinfo').textContent = 'None: the model above is studied alone.';
    page.worker.postMessage({ type: 'clearBefore' });
    clear();
  }

  /** The model's receivers as windows to tick (none ticked: the user picks them). */
  function listWindows(names) {
    const boxes = names.map((name, i) => {
      const label = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.value = String(i);
      label.append(box, ` ${name}`);
      return label;
    });
    $('studywindows').replaceChildren(...boxes);
  }

  function wire() {
    for (const id of ['mode', 'study', 'gbwhole']) $(id).addEventListener('change', showFields);
    // GB 50180 counts at the sill, BRE at the window's centre: the picker follows the rule.
    $('study').addEventListener('change', () => {
      $('windowpoints').value = $('study').value === 'gb50180' ? 'sill' : 'centre';
    });
    const tickAll = (on) => {
      for (const box of $('studywindows').querySelectorAll('input')) box.checked = on;
    };
    $('studyall').addEventListener('click', () => tickAll(true));
    $('studynone').addEventListener('click', () => tickAll(false));
    const base = () => page.modelFiles()[0]?.replace(/\.[^.]*$/, '') || 'model';
    $('downloadstudy').addEventListener('click', () => {
      if (!state.study) return;
      const name = state.study.tables[0].study;
      page.download(`${base()}.study-${name}.csv`, state.study.csv[name], 'text/csv');
    });
    $('downloadreport').addEventListener('click', () => {
      if (!state.study) return;
      page.download(`${base()}.study-${state.study.tables[0].study}.html`, state.study.html, 'text/html');
    });
    $('studytable').tBodies[0].addEventListener('click', (e) => {
      const row = e.target.closest('tr');
      if (row?.dataset.point) showMask(Number(row.dataset.point));
    });
    $('studybefore').addEventListener('change', chooseBefore);
    $('studybeforeclear').addEventListener('click', clearBefore);
    showFields();
  }

  return {
    wire,
    active: () => mode() === 'study',
    compute,
    shown,
    failed: clear,
    recolour,
    toggleWindow,
    /** Whether window `r` is ticked. */
    ticked: (r) => !!$('studywindows').querySelector(`input[value="${r}"]`)?.checked,
    /** The existing scene was read: it is compared from the next study on. */
    beforeLoaded({ receivers }) {
      state.before = state.reading;
      state.reading = null;
      $('studybeforeclear').disabled = false;
      $('studybeforeinfo').textContent = `${state.before.join(', ')} (${receivers} receivers): each window is compared with it.`;
      clear();
    },
    /** The existing scene could not be read: the last one (if any) stays. */
    beforeFailed(message) {
      state.reading = null;
      $('studybefore').value = '';
      $('studybeforeinfo').textContent = state.before ? `${state.before.join(', ')} (kept): ${message}` : `None: ${message}`;
    },
    /** A new model: its windows to tick, and no study. */
    reset(names) {
      listWindows(names ?? []);
      clear();
    },
  };
}
