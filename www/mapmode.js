// The page's Map mode: per-point values on the receivers (engine.map, run by the worker): a grid
// at a spacing, a period or an instant, a value; the cells drawn over the 3D view with a legend;
// a day/time slider that maps the instant as it moves; the points CSV and the map glb to
// download (the library's own writers, as `sunlit map` writes them), written by the worker only
// when a download is clicked: a slider's move asks for nothing the view does not draw.
import { areaSummary, drawnPatches, insideOptions, insideStudy, patchSummary, wireInside } from './insidemode.js';
import { LIT, MAP_VALUES, mapCells, mapColours, mapRange } from './map.js';

const MONTH_DAYS = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];

/** Day of a non-leap year (1..365) as MM-DD. */
export function monthDay(day) {
  let d = Math.min(365, Math.max(1, Math.round(day)));
  for (let m = 0; m < 12; m++) {
    if (d <= MONTH_DAYS[m]) return `${String(m + 1).padStart(2, '0')}-${String(d).padStart(2, '0')}`;
    d -= MONTH_DAYS[m];
  }
  return '12-31';
}

/** Hours (0..24, quarter hours) as HH:MM. */
export function clock(hours) {
  const minutes = Math.round(hours * 60);
  return `${String(Math.floor(minutes / 60)).padStart(2, '0')}:${String(minutes % 60).padStart(2, '0')}`;
}

/**
 * Wires the Map mode's controls. `page`: { $, worker, status, location() (the form's location as
 * MapOptions keys), skyModel() (the sky control's value, '' for the default), engineOptions(), viewer() (the 3D view or null), showLegend({ max, title, tick }),
 * setBusy(busy), download(name, text, type), modelName() }.
 */
export function mapMode(page) {
  const { $ } = page;
  const state = { map: null, id: null, pending: null, inFlight: false };

  const mode = () => $('mode').value;
  // An inside study sets its own period: never an instant, so the sliders do not rerun it.
  const instant = () => !insideStudy($) && ($('mapperiod').value === 'instant' || $('mapvalue').value === 'lit');

  function showFields() {
    const map = mode() === 'map';
    for (const el of document.querySelectorAll('.yearonly')) el.hidden = mode() !== 'year';
    $('mapfields').hidden = !map;
    const period = instant() ? 'instant' : $('mapperiod').value;
    for (const el of document.querySelectorAll('[data-period]')) el.hidden = !el.dataset.period.split(' ').includes(period);
    $('mapday').nextElementSibling.textContent = `${monthDay(Number($('mapday').value))} ${clock(Number($('maptime').value))}`;
    $('compute').textContent = map ? 'Compute map' : 'Compute';
    page.viewer()?.setOverlay(map && state.map ? cellsOf(state.map) : null, map && state.map ? state.colours : null);
    if (!map) page.showLegend(null);
  }

  async function options() {
    const o = { ...(await page.location()), grid: Number($('mapgrid').value) };
    if (page.skyModel()) o.skyModel = page.skyModel();
    if (insideStudy($)) return { ...o, ...insideOptions($) };
    if (instant()) return { ...o, at: `${monthDay(Number($('mapday').value))} ${clock(Number($('maptime').value))}`, value: 'lit', ...insideOptions($, true) };
    Object.assign(o, { value: $('mapvalue').value, ...insideOptions($) });
    const period = $('mapperiod').value;
    if (period === 'range') o.period = `${$('mapstart').value.trim()}..${$('mapend').value.trim()}`;
    else if (period === 'day') {
      Object.assign(o, { period: $('mapstart').value.trim(), step: Number($('mapstep').value), from: $('mapfrom').value, to: $('mapto').value });
    } else o.period = 'annual';
    return o;
  }

  /** One map request at a time: a slider moved during one sends only its latest instant after.
   * The tag (what was asked, and for an instant the sliders' day and time) comes back with the
   * answer. */
  async function request(kind) {
    const tag = { kind, day: $('mapday').value, time: $('maptime').value };
    const message = { type: 'map', options: await options(), engine: page.engineOptions(), tag };
    if (state.inFlight) {
      state.pending = message;
      return;
    }
    state.inFlight = true;
    page.worker.postMessage(message);
  }

  const cellsCache = new WeakMap();
  function cellsOf(map) {
    if (!cellsCache.has(map)) cellsCache.set(map, mapCells(map.points, map.normals, { size: map.spacing || Number($('mapgrid').value) || 0.5, lift: 0.02 }));
    return cellsCache.get(map);
  }

  /** The worker's answer: drawn, summarised, ready to download (the worker keeps map `id`'s
   * files until the next map). */
  function shown({ map, seconds, tag, id }) {
    state.inFlight = false;
    if (state.pending) {
      const next = state.pending;
      state.pending = null;
      state.inFlight = true;
      page.worker.postMessage(next);
    } else page.setBusy(false);
    // An instant's map reuses the last cells when it has the same points.
    const last = state.map;
    if (last && last.points.length === map.points.length && last.points.every((v, i) => v === map.points[i])) cellsCache.set(map, cellsOf(last));
    state.map = map;
    const range = mapRange(map.values, map.value);
    state.colours = mapColours(map.values, { ...range, value: map.value });
    const info = MAP_VALUES[map.value];
    showFields();
    page.showLegend(legendOf(map, range, tag));
    const lit = map.value === 'lit' ? map.values.reduce((n, v) => n + (v >= 0.5), 0) : null;
    const view = $('view');
    view.dataset.cells = String(map.values.length);
    view.dataset.lit = lit === null ? '' : String(lit);
    view.dataset.at = map.value === 'lit' ? `${tag.day},${tag.time}` : '';
    view.dataset.patches = map.patches ? JSON.stringify(map.patches) : '';
    showDrawn();
    view.dataset.areas = map.areas ? JSON.stringify(map.areas) : '';
    state.id = id;
    $('downloadmap').disabled = false;
    $('downloadglb').disabled = false;
    const receivers = new Set(map.receivers).size;
    const summary =
      lit === null
        ? `${info.title} from ${map.min.toFixed(2)} to ${map.max.toFixed(2)}${info.unit ? ` ${info.unit}` : ''} over ${map.instants.toLocaleString()} instants${areaSummary(map.areas)}`
        : `${lit.toLocaleString()} in the sun${patchSummary(map.patches)}`;
    page.status(`Map in ${seconds.toFixed(1)} s (${tag.kind}): ${map.values.length.toLocaleString()} points on ${receivers} receivers; ${summary}.`);
  }

  /** An inside instant's sun patch as drawn, per face (m² of the lit cells in the view's own
   * overlay, the cut's collapsed ones counting nothing): `data-drawn-patches` on the view, for a
   * person's check and the browser test. */
  function showDrawn() {
    const map = state.map;
    const overlay = page.viewer()?.overlay;
    const drawn = map?.patches && map.value === 'lit' && overlay;
    const stride = drawn ? overlay.length / (6 * map.values.length) : 0;
    $('view').dataset.drawnPatches = drawn ? JSON.stringify(drawnPatches(overlay, stride, map.receivers, map.receiverNames, LIT)) : '';
  }

  function legendOf(map, range, tag) {
    const info = MAP_VALUES[map.value];
    if (map.value === 'lit') {
      const at = `${monthDay(Number(tag.day))} ${clock(Number(tag.time))}`;
      return { max: 1, title: `Sunlit at ${at} (yellow: sun, blue: shadow)`, tick: (v) => (v === 0 ? 'shadow' : v === 1 ? 'sun' : '') };
    }
    return { max: range.max, title: `${info.title}${info.unit ? `, ${info.unit}` : ''} per point`, tick: (v) => (range.max >= 10 ? v.toFixed(0) : v.toFixed(2)) };
  }

  /** A file of the map shown, written by the worker on a download's click: saved. */
  function fileArrived({ id, kind, data }) {
    if (id !== state.id) return;
    const base = page.modelName().replace(/\.[^.]*$/, '') || 'model';
    if (kind === 'glb') page.download(`${base}-map.glb`, data, 'model/gltf-binary');
    else page.download(`${base}-points.csv`, data, 'text/csv');
  }

  function failed() {
    state.inFlight = false;
    state.pending = null;
  }

  function wire() {
    for (const id of ['mode', 'mapperiod', 'mapvalue']) $(id).addEventListener('change', showFields);
    for (const id of ['mapday', 'maptime']) {
      $(id).addEventListener('input', () => {
        showFields();
        // The slider maps the instant as it moves, once a map of this model exists.
        if (mode() === 'map' && instant() && state.map && !page.busy()) request('instant');
      });
    }
    // The files are written by the worker when asked for, of the map shown (fileArrived saves them).
    const ask = (kind) => state.map && page.worker.postMessage({ type: 'mapFile', id: state.id, kind });
    $('downloadmap').addEventListener('click', () => ask('csv'));
    $('downloadglb').addEventListener('click', () => ask('glb'));
    wireInside(page);
    // After the view's own cut (wireInside's listener runs first): what it now draws.
    $('mapcut').addEventListener('change', showDrawn);
    showFields();
  }

  return {
    wire,
    active: () => mode() === 'map',
    compute: () => request(instant() ? 'instant' : 'period'),
    shown,
    fileArrived,
    failed,
    /** A new model: its old map is gone. */
    reset() {
      state.map = null;
      state.id = null;
      $('downloadmap').disabled = true;
      $('downloadglb').disabled = true;
      $('mapcut').value = '';
      $('view').dataset.cut = '';
      showFields();
    },
  };
}
